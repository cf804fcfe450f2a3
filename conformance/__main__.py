"""python -m conformance: the same as python -m conformance.report.

`python -m conformance mujoco_py ...` runs mujoco-py's own tests against
mjcffi.sim instead (conformance/mujoco_py.py); `python -m conformance mjx ...`
checks MJX on mjcffi's objects against the official's (conformance/mjx.py).
"""

import sys

if sys.argv[1:2] == ["mujoco_py"]:
    from .mujoco_py import main

    main(sys.argv[2:])
elif sys.argv[1:2] == ["mjx"]:
    from .mjx import main

    sys.exit(main(sys.argv[2:]))
else:
    from .report import main

    main()
