# Type stub of the mjcffi package: the names its __getattr__ loads on first use.
from ._generated.constants import *
from ._generated.enums import *
from ._support.errors import (ArgumentError as ArgumentError, FatalError as FatalError,
                      IdError as IdError)
from ._functions import *
from ._support.library import ffi as ffi, lib as lib
from .functions._overrides import *
from . import batch as batch, minimize as minimize, rollout as rollout, sim as sim
# mjcffi.tune is a module that calls as the function tune
from .tune import tune as tune
from ._support.callbacks import *
# MjLogConfig is log_config's subclass (get, set), not the generated base that structs exports
from .log_config import MjLogConfig as MjLogConfig
from .structs.mjtype import *  # type: ignore[assignment]
from .structs.mjmodel import *  # type: ignore[assignment]
from .structs.mjdata import *  # type: ignore[assignment]
from .structs.mjvisualize import *  # type: ignore[assignment]
from .structs.mjplugin import *  # type: ignore[assignment]
from .structs.mjrender import *  # type: ignore[assignment]
from .structs.mjui import *  # type: ignore[assignment]
from .structs.mjbatch import *  # type: ignore[assignment]
# mjspec's element classes come from spec/elements.py (their hand-written methods)
from .structs.mjspec import (MjsElement as MjsElement, MjsCompiler as
                             MjsCompiler, MjsAuthored as MjsAuthored,
                             MjsOrientation as MjsOrientation,
                             MjsDefault as MjsDefault, MjStruct as
                             MjStruct)
from .data import MjData as MjData
from .model import MjModel as MjModel
# the element classes with their hand-written methods (spec/elements.py)
from .spec.elements import (MjsActuator as MjsActuator, MjsBody as
                            MjsBody, MjsCamera as MjsCamera,
                            MjsEquality as MjsEquality, MjsExclude as
                            MjsExclude, MjsFlex as MjsFlex, MjsFrame as
                            MjsFrame, MjsGeom as MjsGeom, MjsHField as
                            MjsHField, MjsJoint as MjsJoint, MjsKey as
                            MjsKey, MjsLight as MjsLight, MjsMaterial
                            as MjsMaterial, MjsMesh as MjsMesh,
                            MjsNumeric as MjsNumeric, MjsPair as
                            MjsPair, MjsPlugin as MjsPlugin, MjsSensor
                            as MjsSensor, MjsSite as MjsSite, MjsSkin
                            as MjsSkin, MjsTendon as MjsTendon,
                            MjsTendonPath as MjsTendonPath, MjsText as
                            MjsText, MjsTexture as MjsTexture, MjsTuple
                            as MjsTuple, MjsWrap as MjsWrap)
from ._support.element_fields import MjCharVec as MjCharVec
from ._support.element_vectors import (MjDoubleVec as MjDoubleVec, MjFloatVec as MjFloatVec,
                                       MjIntVec as MjIntVec, MjStringVec as MjStringVec)
from .user_handlers import *
from .vfs import MjVfs as MjVfs
from ._support.plugins import HEADERS_DIR as HEADERS_DIR, PLUGINS_DIR as PLUGINS_DIR
from .warning_errors import (MjWarningError as MjWarningError,
                             get_warnings_as_errors as get_warnings_as_errors,
                             ignore_warnings as ignore_warnings,
                             set_warnings_as_errors as set_warnings_as_errors)

from .spec import MjSpec as MjSpec, from_zip as from_zip, to_zip as to_zip

__version__: str
__mjcffi_version__: str
__all__: list[str]

# mjcffi/_support/plugins.py: the bundled plugin libraries, loaded on first use
import ctypes as _ctypes
PLUGIN_HANDLES: list[_ctypes.CDLL]

# mjcffi/_support/stringtables.py: MuJoCo's string tables, read from libmujoco
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
