"""The package's type information lets a checker follow typical user code."""

import pathlib
import subprocess
import sys

import mypy  # noqa: F401  (a test dependency: fail loudly if missing)

USER_CODE = '''
import numpy as np
import mjcffi as mujoco

m = mujoco.MjModel.from_xml_string("<mujoco/>")
d = mujoco.MjData(m)
mujoco.mj_step(m, d, nstep=2)
step = mujoco.mj_step.prepare(m, d, nstep=2)
step()
jac = mujoco.mj_jac.prepare(m, d, np.zeros((3, m.nv)), None, np.zeros(3), 0)
jac()
body_id: int = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "world")
t: float = d.time + m.opt.timestep
q: np.ndarray = d.qpos
body: int = mujoco.mjtObj.mjOBJ_BODY
mujoco.set_mjcb_control(None)
scene = mujoco.MjvScene(m, maxgeom=10)
try:
    mujoco.mj_forward(m, d)
except mujoco.FatalError:
    pass
spec = mujoco.MjSpec.from_string("<mujoco/>")
geom = spec.worldbody.add_geom(size=[1, 1, 1])
compiled = spec.compile()
xpos: np.ndarray = mujoco.MjData(compiled).bind(geom).xpos
bodies: list = spec.bodies
from mjcffi.tune import TuneResult
result: TuneResult = mujoco.tune(m, 1e-3, control_period=0.01, objective="accurate")
speedup: float = result.speedup
'''

BAD_CODE = '''
import mjcffi
mjcffi.MjModel.from_xml_strin("<mujoco/>")
'''


def _mypy(tmp_path, code):
    path = tmp_path / "user.py"
    path.write_text(code)
    repo = pathlib.Path(__file__).resolve().parent.parent
    return subprocess.run([sys.executable, "-m", "mypy", "--no-error-summary",
                           "--cache-dir", str(tmp_path / "cache"), str(path)],
                          capture_output=True, text=True, cwd=repo)


def test_user_code_type_checks(tmp_path):
    result = _mypy(tmp_path, USER_CODE)
    assert result.returncode == 0, result.stdout + result.stderr


def test_a_misspelt_name_is_caught(tmp_path):
    result = _mypy(tmp_path, BAD_CODE)
    assert result.returncode == 1 and "from_xml_strin" in result.stdout
