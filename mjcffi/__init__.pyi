# Type stub of the mjcffi package: the names its __getattr__ loads on first use.
from ._constants import *
from ._enums import *
from ._errors import FatalError as FatalError
from ._functions import *
from ._library import ffi as ffi, lib as lib
from ._overrides import *
from . import batch as batch, rollout as rollout, sim as sim
from .callbacks import *
from .structs import *
from .data import MjData as MjData
from .model import MjModel as MjModel
from .warning_errors import (MjWarningError as MjWarningError,
                             get_warnings_as_errors as get_warnings_as_errors,
                             ignore_warnings as ignore_warnings,
                             set_warnings_as_errors as set_warnings_as_errors)

__version__: str
