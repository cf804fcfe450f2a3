"""MjLogConfig: the configuration of MuJoCo's default log handler, as a struct
class that can also read and set the process-wide configuration.

The fields come from the generated class (mjcffi/structs/mjtype.py):
`logto_console`, `logto_file`, `logfile` (the path written to when logging to a
file) and `topics` (a bit mask; bit `t - 1` enables the info messages of
mjtLogTopic `t`, such as mjTOPIC_TIME_CMP's compile times).  As in the official
bindings, `MjLogConfig.get()` returns a copy of the current configuration and
`config.set()` makes a configuration current:

    config = mjcffi.MjLogConfig.get()
    config.topics |= 1 << (mjcffi.mjtLogTopic.mjTOPIC_TIME_CMP - 1)
    config.set()

The configuration belongs to the one libmujoco of the process, shared with the
official bindings when both are imported.  `MjLogConfig()` is all zeros (no
console, no file, no topics), as in the official bindings.
"""

from ._support.library import lib
from ._support.marshal import struct_copy, struct_value
from ._support.views import guarded, guarded_result
from .structs import mjtype


class MjLogConfig(mjtype.MjLogConfig):
    """mjLogConfig: the default log handler's configuration (where messages go, which
    info topics pass).  `MjLogConfig.get()` reads the current one; `config.set()`
    installs this one (mju_getLogConfig / mju_setLogConfig)."""

    @staticmethod
    def get() -> "MjLogConfig":
        """A copy of the current configuration of MuJoCo's default log handler."""
        return struct_copy(MjLogConfig, guarded_result(lib.mjcffi_guard_mju_getLogConfig))

    def set(self) -> None:
        """Make this the configuration of MuJoCo's default log handler."""
        guarded(lib.mjcffi_guard_mju_setLogConfig, struct_value(self, "mjLogConfig", "config"))
