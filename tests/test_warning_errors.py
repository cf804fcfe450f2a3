"""Opt-in MuJoCo warnings as errors, and the context manager that ignores them."""

import threading

import numpy as np
import pytest

import mjcffi
from mjcffi import warning_errors

PENDULUM = """
<mujoco>
  <worldbody>
    <body><joint type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/></body>
  </worldbody>
</mujoco>
"""


@pytest.fixture
def pendulum():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    return m, mjcffi.MjData(m)


@pytest.fixture(autouse=True)
def switched_off_after():
    yield
    mjcffi.set_warnings_as_errors(False)


def _step_checked(m, d):
    """One raw step between the checks the function layer makes around mj_step."""
    before = warning_errors.before_call(d)
    mjcffi._support.errors.check(mjcffi.lib.mjcffi_guard_mj_step(m._ptr, d._ptr))
    warning_errors.after_call(d, before)


def test_warnings_are_counted_but_not_raised_by_default(pendulum):
    m, d = pendulum
    d.qvel[0] = np.nan
    _step_checked(m, d)
    assert d.warning[mjcffi.mjtWarning.mjWARN_BADQVEL].number == 1
    assert not mjcffi.get_warnings_as_errors()


def test_opted_in_a_new_warning_raises(pendulum):
    m, d = pendulum
    mjcffi.set_warnings_as_errors(True)
    _step_checked(m, d)                              # a clean step raises nothing
    d.qvel[0] = np.nan
    with pytest.raises(mjcffi.MjWarningError, match="mjWARN_BADQVEL") as info:
        _step_checked(m, d)
    assert info.value.warning is mjcffi.mjtWarning.mjWARN_BADQVEL
    assert info.value.info == 0 and info.value.count == 1
    assert "qvel at dof 0" in str(info.value).lower()


def test_ignore_warnings_suspends_raising_on_this_thread_only(pendulum):
    m, d = pendulum
    mjcffi.set_warnings_as_errors(True)
    with mjcffi.ignore_warnings():
        d.qvel[0] = np.nan
        _step_checked(m, d)
        seen = []

        def other_thread():
            m2 = mjcffi.MjModel.from_xml_string(PENDULUM)
            d2 = mjcffi.MjData(m2)
            d2.qvel[0] = np.nan
            try:
                _step_checked(m2, d2)
            except mjcffi.MjWarningError as exc:
                seen.append(exc)
        worker = threading.Thread(target=other_thread)
        worker.start()
        worker.join()
        assert len(seen) == 1                      # the other thread still raises
    assert d.warning[mjcffi.mjtWarning.mjWARN_BADQVEL].number == 1
    mjcffi.lib.mj_resetData(m._ptr, d._ptr)
    d.qvel[0] = np.nan
    with pytest.raises(mjcffi.MjWarningError):
        _step_checked(m, d)                        # raising is back after the block


def test_the_switch_takes_only_bools():
    with pytest.raises(TypeError, match="bool"):
        mjcffi.set_warnings_as_errors(1)


def test_counts_survive_a_fatal_error_in_a_checked_call():
    # five boxes piled up overflow a 6K stack in mj_step: a real mju_error
    bodies = "".join('<body pos="0 0 1"><freejoint/><geom type="box" size=".1 .1 .1"/></body>'
                     for _ in range(5))
    m = mjcffi.MjModel.from_xml_string(
        f'<mujoco><size memory="6K"/><worldbody>{bodies}</worldbody></mujoco>')
    d = mjcffi.MjData(m)
    d.warning[mjcffi.mjtWarning.mjWARN_INERTIA].number = 2     # counts the user holds
    mjcffi.set_warnings_as_errors(True)
    with pytest.raises(mjcffi.FatalError):
        mjcffi.mj_step(m, d)
    assert d.warning[mjcffi.mjtWarning.mjWARN_INERTIA].number == 2
