# Type stub of the mjcffi package: the names its __getattr__ loads on first use.
from ._constants import *
from ._enums import *
from ._errors import (ArgumentError as ArgumentError, FatalError as FatalError,
                      IdError as IdError)
from ._functions import *
from ._library import ffi as ffi, lib as lib
from ._overrides import *
from . import batch as batch, minimize as minimize, rollout as rollout, sim as sim
from .callbacks import *
# MjLogConfig is log_config's subclass (get, set), not the generated base that structs exports
from .log_config import MjLogConfig as MjLogConfig
from .structs import *  # type: ignore[assignment]
from .data import MjData as MjData
from .model import MjModel as MjModel
from .spec import MjSpec as MjSpec
from .user_handlers import *
from .vfs import MjVfs as MjVfs
from .plugins import HEADERS_DIR as HEADERS_DIR, PLUGINS_DIR as PLUGINS_DIR
from .warning_errors import (MjWarningError as MjWarningError,
                             get_warnings_as_errors as get_warnings_as_errors,
                             ignore_warnings as ignore_warnings,
                             set_warnings_as_errors as set_warnings_as_errors)

__version__: str

# mjcffi/plugins.py: the bundled plugin libraries, loaded on first use
import ctypes as _ctypes
PLUGIN_HANDLES: list[_ctypes.CDLL]

# mjcffi/_stringtables.py: MuJoCo's string tables, read from libmujoco
mjDISABLESTRING: tuple[str, ...]
mjENABLESTRING: tuple[str, ...]
mjTIMERSTRING: tuple[str, ...]
mjLABELSTRING: tuple[str, ...]
mjFRAMESTRING: tuple[str, ...]
mjVISSTRING: tuple[tuple[str, str, str], ...]
mjRNDSTRING: tuple[tuple[str, str, str], ...]
mjTOPICSTRING: tuple[str, ...]

# mjcffi/gl_context.py: the OpenGL context class of the backend MUJOCO_GL names
from .rendering._base import GLContextBase as _GLContextBase
GLContext: type[_GLContextBase]

# mjcffi/renderer.py: offscreen rendering of scenes into NumPy arrays
from .rendering.renderer import Renderer as Renderer
