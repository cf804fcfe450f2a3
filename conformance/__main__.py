"""python -m conformance: the same as python -m conformance.report.

`python -m conformance mujoco_py ...` runs mujoco-py's own tests against
mjcffi.sim instead (conformance/mujoco_py.py).
"""

import sys

if sys.argv[1:2] == ["mujoco_py"]:
    from .mujoco_py import main

    main(sys.argv[2:])
else:
    from .report import main

    main()
