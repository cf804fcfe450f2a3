"""Real clients whose code branches on `mujoco.__version__`, run with `mujoco` = mjcffi
and with the official bindings, each in a fresh interpreter, compared bit for bit.

gymnasium is the client here: its MuJoCo utilities refuse versions before 2.3.6, and
its renderer picks legacy marker and camera code from the version.  (Its set_state
passes `spec=` to mj_setState, whose MuJoCo 4 argument is `sig`: both bindings raise
TypeError there, and the test checks that they agree.)
"""

import json
import subprocess
import sys

import numpy as np
import pytest

from tests import _gl

SCENARIO = """
import json, sys
import numpy as np
if sys.argv[1] == "mjcffi":
    import mjcffi
    sys.modules["mujoco"] = mjcffi
import gymnasium as gym
from gymnasium.envs.mujoco import mujoco_rendering, utils

env = gym.make("Hopper-v5")
env.reset(seed=1)
rng = np.random.default_rng(1)
actions = rng.uniform(-1, 1, (30,) + env.action_space.shape).astype(np.float32)
for action in actions[:10]:
    env.step(action)
state = utils.get_state(env)                      # refuses a mujoco older than 2.3.6
first = [env.step(action)[0].tolist() for action in actions[10:]]
try:
    # gymnasium passes `spec=`, which MuJoCo 4's mj_setState calls `sig`: both refuse it
    utils.set_state(env, state)
    refused = None
except TypeError as error:
    refused = "TypeError"
mujoco = sys.modules["mujoco"]
mujoco.mj_setState(env.unwrapped.model, env.unwrapped.data, state,
                   mujoco.mjtState.mjSTATE_FULLPHYSICS)
again = [env.step(action)[0].tolist() for action in actions[10:]]
print(json.dumps({"state": state.tolist(), "first": first, "again": again, "refused": refused,
                  "legacy": [mujoco_rendering._MUJOCO_MARKER_LEGACY_MODE,
                             mujoco_rendering._MUJOCO_CAMERA_LEGACY_MODE],
                  "binding": sys.modules["mujoco"].__name__}))
"""


def _run(binding):
    done = subprocess.run([sys.executable, "-c", SCENARIO, binding], capture_output=True,
                          text=True, timeout=300, cwd=_gl.ROOT, env=_gl.env("egl"))
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_gymnasium_s_version_gated_state_utilities_match_the_official():
    pytest.importorskip("gymnasium")
    ours, theirs = _run("mjcffi"), _run("official")
    assert (ours.pop("binding"), theirs.pop("binding")) == ("mjcffi", "mujoco")
    assert ours["legacy"] == theirs["legacy"] == [False, False]
    assert ours["refused"] == theirs["refused"] == "TypeError"
    assert ours["first"] == ours["again"]                 # set_state replays the steps
    for key in ("state", "first"):
        assert np.array_equal(np.array(ours[key]), np.array(theirs[key])), key
