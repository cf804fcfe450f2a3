"""Model editing: `MjSpec`, MuJoCo's mjSpec with the official Python API.

- `spec.py`: the MjSpec class (parse, compile, save, copy, lookups, delete, defaults);
- `elements.py`: the element classes' hand-written methods (tree traversal,
  attach_body, make_* meshes and flexes, actuator shortcuts), registered over
  the generated ones;
- `attach.py`: attaching a child spec at a frame or site, with its assets;
- `bind.py`: `m.bind(element)` / `d.bind(element)`, an element's compiled values;
- `lifetime.py`: what becomes of wrappers and views when MuJoCo frees elements;
- the element kinds (list and lookup names, mjtObj) are in mjcffi/_support/spec_kinds.py;
- `assets.py`: `assets` dicts as the VFS MuJoCo reads.
"""

from . import elements  # noqa: F401  (registers the element subclasses)
from .elements import *  # noqa: F401,F403
from .elements import __all__ as _element_names
from .spec import MjSpec

from_zip = MjSpec.from_zip
to_zip = MjSpec.to_zip

__all__ = ["MjSpec", "from_zip", "to_zip", *_element_names]
