"""Numerical stability on the hard cases of mjcffi/scenes.py.

Each bound is stated where it is asserted, with its reason: the physics of the
case, the order of the integrator, or a margin over the value measured here.
The measured values are in the comments (x86-64, MuJoCo 4.0.0); a chaotic
trajectory differs in its last bits across CPUs and libm versions, which moves
such values by small factors, never by orders of magnitude.

The scenes are stepped in chunks (mj_step with nstep, looped in C), and the
state is read between chunks.
"""

import numpy as np
import pytest

import mjcffi
from mjcffi import scenes

INT = mjcffi.mjtIntegrator
WARN = mjcffi.mjtWarning
FULLPHYSICS = int(mjcffi.mjtState.mjSTATE_FULLPHYSICS)


def load(xml, integrator=None, timestep=None, energy=False):
    m = mjcffi.MjModel.from_xml_string(xml)
    if integrator is not None:
        m.opt.integrator = integrator
    if timestep is not None:
        m.opt.timestep = timestep
    if energy:
        m.opt.enableflags |= int(mjcffi.mjtEnableBit.mjENBL_ENERGY)
    return m


def start(m, key=None):
    d = mjcffi.MjData(m)
    if key is not None:
        mjcffi.mj_resetDataKeyframe(m, d, m.key(key).id)
    mjcffi.mj_forward(m, d)
    return d


def total_energy(m, d):
    """Potential + kinetic energy of the current state.

    mj_forward recomputes it: after an RK4 step, d.energy holds the energy of
    the last intermediate stage, not of the state the step ends in.  mj_forward
    changes no state that the next step reads here (no constraints warm-start
    in these scenes, and the step recomputes the rest)."""
    mjcffi.mj_forward(m, d)
    return float(d.energy[0] + d.energy[1])


def energy_trace(m, d, seconds, every):
    """Total energy at t = 0, every, 2*every, ... seconds (every: whole steps)."""
    chunk = round(every / m.opt.timestep)
    energies = [total_energy(m, d)]
    for _ in range(round(seconds / every)):
        mjcffi.mj_step(m, d, nstep=chunk)
        energies.append(total_energy(m, d))
    return np.array(energies)


def state_of(m, d):
    state = np.empty(mjcffi.mj_stateSize(m, FULLPHYSICS))
    mjcffi.mj_getState(m, d, state, FULLPHYSICS)
    return state


# ------------------------------------------------------------ double pendulum

def pendulum_drift(integrator, timestep, seconds=20.0):
    """Largest |E(t) - E(0)| over `seconds`, sampled every 0.1 s, and the swing
    energy E(0) - E(rest) that sets the scale of the motion."""
    m = load(scenes.DOUBLE_PENDULUM, integrator, timestep, energy=True)
    rest = total_energy(m, mjcffi.MjData(m))          # qpos0: hanging at rest
    d = start(m, "start")
    energies = energy_trace(m, d, seconds, every=0.1)
    assert np.isfinite(energies).all() and not d.warning.number.any()
    return float(np.abs(energies - energies[0]).max()), energies[0] - rest


def test_double_pendulum_energy_drift_rk4_bounded_and_smaller_than_euler():
    rk4, swing = pendulum_drift(INT.mjINT_RK4, 0.001)
    rk4_coarse, _ = pendulum_drift(INT.mjINT_RK4, 0.002)
    euler, _ = pendulum_drift(INT.mjINT_EULER, 0.001)
    assert swing > 10.0                    # released from 2 rad / 1 rad: 15.3 J above rest

    # RK4 at 1 ms over 20 s: measured 5.8e-7 J, 3.8e-8 of the swing energy.
    # Bound 1e-6 of the swing energy (1.5e-5 J), a 26x margin: enough for
    # the chaotic trajectory to differ in its last bits across platforms,
    # while halving the order of the method (error x ~1e3 at this step) or
    # losing energy conservation would fail it.
    assert rk4 <= 1e-6 * swing
    # Fourth order: doubling the step multiplies the energy error by about
    # 2**4 = 16 (measured 25x: 1.4e-5 J at 2 ms).  At least 8 = 2**3 shows an
    # order above three, with room for the chaotic motion's scatter.
    assert rk4_coarse >= 8 * rk4
    # Euler (semi-implicit, first order) at the same step: measured 2.6 J,
    # 4e6 times RK4's error.  The error ratio of a first- and a fourth-order
    # method is of order (omega*h)**-3: 2e4 even at the fastest joint speed
    # reached (38 rad/s); 1000x is a floor below it that still shows the
    # ordering.
    assert euler >= 1000 * rk4
    # Semi-implicit Euler is symplectic on this undamped system: its energy
    # error oscillates rather than grows, and stays a fraction of the swing
    # energy (measured 0.17); half of it would mean energy being pumped in.
    assert euler <= 0.5 * swing


# ---------------------------------------------------------------- Dzhanibekov

def body_inertia_tensor(m, body):
    """The body's inertia tensor about its centre of mass, in the body frame."""
    rot = np.empty(9)
    mjcffi.mju_quat2Mat(rot, m.body_iquat[body])
    rot = rot.reshape(3, 3)
    return rot @ np.diag(m.body_inertia[body]) @ rot.T


def world_angular_momentum(m, d, body):
    """Angular momentum of the body's subtree about its centre of mass, world frame."""
    mjcffi.mj_subtreeVel(m, d)
    return d.subtree_angmom[body].copy()


def test_dzhanibekov_tee_flips_and_conserves_angular_momentum():
    m = load(scenes.DZHANIBEKOV, energy=True)
    body = m.body("tee").id
    d = start(m, "spin")

    # The case itself: the spin is about the body y axis, a principal axis
    # whose moment of inertia lies strictly between the other two.
    spin = d.qvel[3:6] / np.linalg.norm(d.qvel[3:6])
    assert abs(spin[1]) > 0.9999                 # 0.1 % off-axis perturbation
    inertia = body_inertia_tensor(m, body)
    assert np.allclose(inertia[1, [0, 2]], 0, atol=1e-12)   # y is principal
    others = sorted(inertia[[0, 2], [0, 2]])
    assert others[0] < inertia[1, 1] < others[1]             # and intermediate
    np.testing.assert_array_equal(m.body_ipos[body], 0)      # spun about the COM

    momentum0 = world_angular_momentum(m, d, body)
    axis = momentum0 / np.linalg.norm(momentum0)
    energy0 = total_energy(m, d)
    chunk, nchunk = 10, 400                      # 4 s sampled every 10 ms
    alignment, momentum, energy = [], [], []
    for _ in range(nchunk):
        mjcffi.mj_step(m, d, nstep=chunk)
        # the body y axis (column 1 of xmat) against the fixed momentum axis
        alignment.append(d.xmat[body].reshape(3, 3)[:, 1] @ axis)
        momentum.append(world_angular_momentum(m, d, body))
        energy.append(total_energy(m, d))
    alignment, times = np.array(alignment), np.arange(1, nchunk + 1) * chunk * m.opt.timestep
    assert not d.warning.number.any()

    # The flip: the y axis turns from along the momentum to against it.  It
    # stays aligned (> 0.99) for the first 0.5 s, while the perturbation grows
    # from 0.1 % at the rate omega*sqrt((I2-I1)(I3-I2)/(I1*I3)) = 5.6 /s;
    # then it reverses to < -0.99 (measured: first sign change at 1.54 s, down
    # to -0.9999993) within the 4 s horizon.
    assert (alignment[times <= 0.5] > 0.99).all()
    assert alignment.min() < -0.99
    flip = times[np.argmax(alignment < 0)]
    assert 0.5 < flip < 4.0

    # Conservation: no external torque and no energy source.  RK4's local
    # error is of order (omega*h)**5 = 1e-10 per step at 10 rad/s and 1 ms;
    # summed over 4000 steps without any cancellation that is 4e-7 of the
    # conserved quantity.  Bound 1e-6 relative (measured: momentum 7e-11,
    # energy 5e-12).
    momentum_error = np.linalg.norm(np.array(momentum) - momentum0, axis=1).max()
    assert momentum_error <= 1e-6 * np.linalg.norm(momentum0)
    assert np.abs(np.array(energy) - energy0).max() <= 1e-6 * energy0


# ------------------------------------------------------------------ box stack

def test_box_stack_stays_stacked_for_10_seconds():
    m = load(scenes.BOX_STACK)
    d = start(m)
    boxes = [m.body(f"box{i}").id for i in range(1, 5)]
    start_pos = d.xpos[boxes].copy()
    deepest, drift = 0.0, np.zeros(len(boxes))
    for _ in range(500):                         # 10 s sampled every 20 ms
        mjcffi.mj_step(m, d, nstep=10)
        assert d.ncon > 0
        deepest = min(deepest, d.contact.dist.min())
        moved = np.linalg.norm(d.xpos[boxes, :2] - start_pos[:, :2], axis=1)
        drift = np.maximum(drift, moved)
    assert not d.warning.number.any()
    assert np.isfinite(d.qpos).all()

    # Horizontal drift: the soft, pyramidal friction cones let off-centre
    # loads creep (measured at 10 s: 0.06, 0.6, 1.2, 1.7 mm, box 1 to 4, at
    # a steady 0.03-0.07 mm/s).  Bound 1 cm per box, a 6x margin: a box tips
    # only when its centre leaves the top face below it, 6 cm or more away.
    assert (drift <= 0.01).all(), drift
    # Penetration: the default soft contact (solref 0.02 s, solimp 0.9-0.95)
    # rests at a depth of order (1 - d) g / (d k), with k = 1/(0.95 * 0.02 s)**2:
    # 0.2-0.4 mm.  Measured deepest 0.55 mm, in the first settling.  Bound
    # 1 mm, the solimp width where the impedance saturates: deeper would be a
    # contact giving way, not resting.
    assert deepest >= -1e-3, deepest
    # Height: each box sinks by the contact depths beneath it, at most four
    # contacts of 1 mm (measured 0.4 to 1.3 mm).
    sunk = start_pos[:, 2] - d.xpos[boxes, 2]
    assert (np.abs(sunk) <= 4e-3).all(), sunk


# ------------------------------------------------------------ mass-ratio chain

def hanging_energy(m):
    """Energy of the chain hanging straight down at rest: the least it can have."""
    d = mjcffi.MjData(m)
    d.qpos[0] = np.pi / 2                        # the hinge about y turns +x to -z
    return total_energy(m, d)


def test_mass_ratio_chain_stable_with_implicitfast():
    m = load(scenes.MASS_RATIO_CHAIN, energy=True)
    assert m.opt.integrator == INT.mjINT_IMPLICITFAST
    assert m.body_mass[1:].max() / m.body_mass[1:].min() == pytest.approx(1000)
    d = start(m)
    energies = energy_trace(m, d, seconds=5.0, every=0.02)
    assert not d.warning.number.any()
    assert np.isfinite(state_of(m, d)).all()
    assert abs(d.time - 5.0) < 1e-9            # no auto-reset happened

    # Energy: joint damping only takes energy out, so the chain's energy lies
    # between that of hanging at rest and the energy it was released with.
    # Allowance 1 % of that 14.7 J range for the first-order integrator's
    # O(h) oscillation (measured: the energy never rose above its start, and
    # the lowest, at 5 s, was 7.8 J above hanging).  A blow-up leaves the range at once.
    low, high = hanging_energy(m), energies[0]
    allowance = 0.01 * (high - low)
    assert energies.max() <= high + allowance
    assert energies.min() >= low - allowance
    # and it does move: it is no equilibrium that trivially stays put
    assert energies[-1] < high - 0.1 * (high - low)


@pytest.mark.parametrize("integrator", [INT.mjINT_RK4, INT.mjINT_EULER])
def test_mass_ratio_chain_blows_up_with_explicit_damping(integrator):
    """The control: the scene is hard.  With the damping integrated explicitly
    (RK4, or Euler without its implicit damping) the stiff damping mode, at
    7x the timestep's inverse, diverges within 0.1 s."""
    m = load(scenes.MASS_RATIO_CHAIN, integrator)
    m.opt.disableflags |= int(mjcffi.mjtDisableBit.mjDSBL_EULERDAMP)
    d = start(m)
    mjcffi.mj_step(m, d, nstep=50)
    assert d.warning.number.any()


# ----------------------------------------------------------------- divergence
#
# Three ways to drive a scene to blow up, and the warning MuJoCo 4.0 raises for
# each (measured): a velocity past mjMAXVAL is caught at the start of the next
# step (BADQVEL); a 10 s timestep throws the pendulum's angles past mjMAXVAL
# in one step, caught at the start of the second (BADQPOS); and the chain under
# RK4, unstable at its timestep, grows until its velocity is caught (BADQVEL,
# at the 8th step).  On a warning mj_step resets the data (mj_resetData) and
# carries on: the step ends one timestep after qpos0.

def huge_velocity():
    m = load(scenes.DOUBLE_PENDULUM)
    d = start(m, "start")
    d.qvel[0] = 10 * mjcffi.mjMAXVAL
    d.time = 3.0
    return m, d


def absurd_timestep():
    m = load(scenes.DOUBLE_PENDULUM, timestep=10.0)
    return m, start(m, "start")


def explicit_chain():
    m = load(scenes.MASS_RATIO_CHAIN, INT.mjINT_RK4)
    return m, start(m)


DRIVES = {"huge_velocity": (huge_velocity, WARN.mjWARN_BADQVEL),
          "absurd_timestep": (absurd_timestep, WARN.mjWARN_BADQPOS),
          "explicit_chain": (explicit_chain, WARN.mjWARN_BADQVEL)}


@pytest.fixture
def warnings_restored():
    yield
    mjcffi.set_warnings_as_errors(False)


@pytest.mark.parametrize("drive", DRIVES)
def test_divergence_warns_and_resets(drive, warnings_restored):
    make, warning = DRIVES[drive]
    m, d = make()
    for _ in range(100):
        time_before = d.time
        mjcffi.mj_step(m, d)
        if d.warning.number.any():
            break
    # exactly the expected warning, once
    expected = np.zeros(len(d.warning.number), dtype=d.warning.number.dtype)
    expected[warning] = 1
    np.testing.assert_array_equal(d.warning.number, expected)
    # the auto-reset: time did not advance (it restarted from 0, so the step
    # ends at one timestep), and the state is that of a fresh data stepped
    # once from qpos0, bit for bit: the same step from the same state
    assert d.time <= time_before and d.time == m.opt.timestep
    fresh = mjcffi.MjData(m)
    mjcffi.mj_step(m, fresh)
    np.testing.assert_array_equal(state_of(m, d), state_of(m, fresh))

    # mjcffi's warning mechanism: the same drive raises MjWarningError
    m, d = make()
    mjcffi.set_warnings_as_errors(True)
    with pytest.raises(mjcffi.MjWarningError) as raised:
        mjcffi.mj_step(m, d, nstep=100)
    assert raised.value.warning == warning
    mjcffi.set_warnings_as_errors(False)
    # and with warnings as errors off again, the same drive only counts
    m, d = make()
    mjcffi.mj_step(m, d, nstep=100)
    assert d.warning.number[warning] == 1


def test_a_second_divergence_of_the_same_data_raises_too(warnings_restored):
    m, d = explicit_chain()
    mjcffi.mj_step(m, d, nstep=8)              # the first divergence, counted
    assert d.warning.number[WARN.mjWARN_BADQVEL] == 1
    mjcffi.set_warnings_as_errors(True)
    with pytest.raises(mjcffi.MjWarningError):
        mjcffi.mj_step(m, d, nstep=8)          # diverges and resets again


@pytest.mark.parametrize("nthread", [0, 2])
def test_rollout_fills_a_diverged_trajectory_and_spares_the_other(nthread):
    """A rollout of the chain under RK4 diverges at its 8th step; beside it in
    the same call the chain under implicitfast does not.  As documented in
    mjcffi/rollout.py, the diverged rollout's rows from the warning on repeat
    its last state, and its time stops increasing there."""
    from mjcffi import rollout
    unstable = load(scenes.MASS_RATIO_CHAIN, INT.mjINT_RK4)
    stable = load(scenes.MASS_RATIO_CHAIN)
    d = mjcffi.MjData(stable)
    initial = state_of(stable, d)[None, :]
    nstep = 100
    datas = [mjcffi.MjData(stable) for _ in range(max(nthread, 1))]
    with rollout.Rollout(nthread=nthread) as pool:
        states, _ = pool.rollout([unstable, stable], datas, initial, nstep=nstep, chunk_size=1)
        alone, _ = pool.rollout([stable], datas, initial, nstep=nstep)

    # each rollout against the same steps taken one at a time
    for r, m in enumerate([unstable, stable]):
        d = mjcffi.MjData(m)
        warned_at = None
        for t in range(nstep):
            mjcffi.mj_step(m, d)
            if warned_at is None:
                np.testing.assert_array_equal(states[r, t], state_of(m, d))
                if d.warning.number.any():
                    warned_at = t
        if r == 0:
            assert warned_at == 7
            # the rest repeat the last state: the reset one
            assert (states[0, warned_at:] == states[0, warned_at]).all()
            time = states[0, :, 0]
            assert (np.diff(time[:warned_at]) > 0).all()
            assert time[warned_at] < time[warned_at - 1]
        else:
            assert warned_at is None
    # the diverged rollout does not touch the other: bit-equal to rolling it alone
    np.testing.assert_array_equal(states[1], alone[0])
    assert np.isfinite(states).all()


# -------------------------------------------------- bit-identity with mujoco
#
# Every case above, stepped through the official binding and through mjcffi
# in the same process on the same libmujoco: the full physics state and the
# warning counters agree to the last bit at every chunk.  (Tolerance zero: both
# make the same C calls on the same inputs.)

IDENTITY_CASES = {
    # name: (scene, keyframe, options, steps per chunk, chunks)
    "double_pendulum_rk4": (scenes.DOUBLE_PENDULUM, "start", {}, 100, 50),
    "double_pendulum_euler": (scenes.DOUBLE_PENDULUM, "start",
                              {"integrator": "mjINT_EULER"}, 100, 50),
    "double_pendulum_absurd_timestep": (scenes.DOUBLE_PENDULUM, "start",
                                        {"timestep": 10.0}, 1, 5),
    "dzhanibekov": (scenes.DZHANIBEKOV, "spin", {}, 100, 40),
    "box_stack": (scenes.BOX_STACK, None, {}, 100, 50),
    "mass_ratio_chain": (scenes.MASS_RATIO_CHAIN, None, {}, 100, 25),
    "mass_ratio_chain_rk4_diverging": (scenes.MASS_RATIO_CHAIN, None,
                                       {"integrator": "mjINT_RK4"}, 5, 20),
}


def trajectory(binding, scene, key, options, chunk, nchunk):
    m = binding.MjModel.from_xml_string(scene)
    if "integrator" in options:
        m.opt.integrator = getattr(binding.mjtIntegrator, options["integrator"])
    if "timestep" in options:
        m.opt.timestep = options["timestep"]
    m.opt.enableflags |= int(binding.mjtEnableBit.mjENBL_ENERGY)
    d = binding.MjData(m)
    if key is not None:
        binding.mj_resetDataKeyframe(m, d, m.key(key).id)
    spec = int(binding.mjtState.mjSTATE_FULLPHYSICS)
    rows = []
    for _ in range(nchunk):
        binding.mj_step(m, d, nstep=chunk)
        state = np.empty(binding.mj_stateSize(m, spec))
        binding.mj_getState(m, d, state, spec)
        rows.append(np.concatenate([state, d.energy, d.warning.number]))
    return np.array(rows)


@pytest.mark.parametrize("case", IDENTITY_CASES)
def test_bit_identical_to_the_official_binding(case, mujoco):
    ours = trajectory(mjcffi, *IDENTITY_CASES[case])
    theirs = trajectory(mujoco, *IDENTITY_CASES[case])
    assert ours.tobytes() == theirs.tobytes()
    warnings = ours[-1, -int(mjcffi.mjtWarning.mjNWARNING):]
    diverges = case.endswith(("diverging", "absurd_timestep"))
    assert warnings.any() == diverges              # the resets were compared too
