"""The evaluation core shared by `python -m mjcffi.accuracy` and `mjcffi.tune`.

One place for what both need to judge a setting of a model's options:

- `settings`: a `Setting` (integrator, timestep, solver options, disable flags),
  how to apply it to a model and how to name it;
- `measures`: position error per joint type, energy and penetration;
- `reference`: the fine reference a setting is compared with;
- `states`: initial states, random controls, and the states sampled along
  trajectories at each control period;
- `timing`: steps per second, speed ratios measured interleaved, and the
  solver's work (iterations, line-search evaluations) counted.
"""

from .measures import JOINT_KINDS, local_error, position_error, quat_angle
from .reference import REF_FACTOR, reference_setting
from .settings import Setting
from .timing import speed_ratio, steps_per_second

__all__ = ["JOINT_KINDS", "REF_FACTOR", "Setting", "local_error", "position_error",
           "quat_angle", "reference_setting", "speed_ratio", "steps_per_second"]
