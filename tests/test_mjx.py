"""MJX (mujoco-mjx) on mjcffi's objects gives the official's bits (conformance/mjx.py).

Skipped where jax and mujoco-mjx are not installed (pip install 'mjcffi[mjx]'); the
optional CI step (.ci/run, MJCFFI_CI_MJX=1) installs them and runs the full check,
`python -m conformance mjx`, on four models.
"""

import pytest

from conformance import mjx

pytestmark = pytest.mark.skipif(bool(mjx.available()), reason=mjx.MISSING)


def test_put_step_and_get_data_into_are_bit_identical_to_the_officials():
    times, results = mjx.run(models=("hopper",), steps=100)
    differences = {name: {group: diffs for group, (_, diffs) in groups.items() if diffs}
                   for name, groups in results.items()}
    assert differences == {"hopper": {}}
    counts = {group: count for group, (count, _) in results["hopper"].items()}
    # every part was compared: the model, the data before and after, the MjData
    assert counts["model"] > 300 and counts["data0"] > 80 and counts["data100"] > 80
    assert counts["mjdata"] > 200 and counts["forward"] > 200
    assert times["mjcffi"]["#official compiled modules"] == []


def test_the_comparison_sees_a_difference():
    import numpy as np
    same = {"data0.qpos": np.zeros(3), "mjdata/qpos": np.zeros(2)}
    changed = {"data0.qpos": np.array([0.0, -0.0, 0.0]), "mjdata/qpos": np.zeros(2, np.float32)}
    groups = mjx._compare(changed, same)
    assert groups["data0"][1] == [("data0.qpos", "different values")]
    assert groups["mjdata"][1] == [("mjdata/qpos", "float32(2,) against float64(2,)")]
