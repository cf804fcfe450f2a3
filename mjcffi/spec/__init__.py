"""Model editing: `MjSpec`, MuJoCo's mjSpec with the official Python API.

`spec.py` holds the class; `kinds.py` the element kinds (mjtObj, the cast from
mjsElement, the wrapper class); `lifetime.py` the wrappers a spec handed out and
their invalidation when MuJoCo frees their elements; `assets.py` the VFS built
from an `assets` dict.
"""

from .spec import MjSpec

__all__ = ["MjSpec"]
