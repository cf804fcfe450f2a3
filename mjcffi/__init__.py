"""mjcffi: a cffi binding of the MuJoCo physics engine.

Generated from the headers of the mujoco-core wheel.  `mjcffi.ffi` and
`mjcffi.lib` give the raw C API; MuJoCo's enums (mjtObj, ...) and #define
constants (mjPI, mjMINVAL, ...) are attributes of this package.
"""

from ._constants import *  # noqa: F401,F403
from ._enums import *  # noqa: F401,F403
from ._errors import FatalError  # noqa: F401
from ._library import ffi, lib  # noqa: F401

__version__ = "0.1.0"
