"""mujoco-py's `mujoco_py.const`: MuJoCo's constants under mujoco-py's names.

`const.OBJ_BODY`, `const.GEOM_BOX`, `const.CAT_ALL`, `const.MINVAL`, ...: each
MuJoCo #define and enum member without its `mj` prefix, with MuJoCo 4's
values (generated into mjcffi/sim/generated/const.py by `python -m codegen`).
"""

from .generated import const as _generated
from .generated.const import *  # noqa: F401,F403  (the constants are this module's API)

__all__ = sorted(name for name in vars(_generated) if name.isupper())
