"""mjcffi.distributed: rollouts on Ray actors, checked bit for bit against the local rollout."""

import copy
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import mjcffi
from mjcffi import distributed
from mjcffi import rollout as local
from mjcffi.evaluation import periods, states

FULLPHYSICS = int(mjcffi.mjtState.mjSTATE_FULLPHYSICS)

BOX = """
<mujoco>
  <worldbody>
    <geom type="plane" size="2 2 .1"/>
    <body pos="0 0 .1"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
    <body pos=".5 0 .3"><joint name="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 .2 0 0" size=".03"/></body>
  </worldbody>
  <actuator><motor joint="hinge"/></actuator>
</mujoco>
"""


@pytest.fixture(scope="module")
def ray():
    try:
        import ray
    except ImportError:
        pytest.skip(f"Ray is not installed: {distributed.EXTRA_HINT}")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield ray
    distributed.shutdown()
    ray.shutdown()


@pytest.fixture(scope="module")
def cluster(ray):
    with distributed.RolloutCluster(2) as c:
        yield c


@pytest.fixture(scope="module")
def humanoid():
    import gymnasium
    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/humanoid.xml")
    return mjcffi.MjModel.from_xml_path(path)


def inputs(m, nbatch, nstep, seed=0):
    """Perturbed initial states, warm starts and controls for `nbatch` rollouts."""
    rng = np.random.default_rng(seed)
    initial = states.initial_states(m, nbatch, rng)
    warmstart = rng.normal(0, 0.1, (nbatch, m.nv))
    control = rng.uniform(-0.4, 0.4, (nbatch, nstep, m.nu))
    return initial, warmstart, control


def local_rollout(model, initial, control, **kwargs):
    first = model[0] if isinstance(model, list) else model
    return local.rollout(model, [mjcffi.MjData(first) for _ in range(2)], initial, control,
                         **kwargs)


def assert_same(expected, got):
    for e, g in zip(expected, got):
        assert e.shape == g.shape
        np.testing.assert_array_equal(g, e, strict=True)


# ------------------------------------------------------------ bit for bit

@pytest.mark.parametrize("shard_size", [None, 3])
def test_humanoid_matches_the_local_rollout(cluster, humanoid, shard_size):
    initial, warmstart, control = inputs(humanoid, 10, 40)
    expected = local_rollout(humanoid, initial, control, initial_warmstart=warmstart)
    got = cluster.rollout(humanoid, initial, control, initial_warmstart=warmstart,
                          shard_size=shard_size)
    assert_same(expected, got)
    assert np.isfinite(got[0]).all() and got[0][:, -1, 0].min() > got[0][:, 0, 0].max()


def test_a_list_of_models_and_repeated_rows(cluster, humanoid):
    models = []
    for dt in (0.002, 0.003, 0.004, 0.005, 0.006):
        m = copy.copy(humanoid)
        m.opt.timestep = dt
        models.append(m)
    initial, _, control = inputs(humanoid, 1, 20)          # one row: repeated for each model
    expected = local_rollout(models, initial, control)
    got = cluster.rollout(models, initial, control, shard_size=2)
    assert_same(expected, got)
    # each model stepped with its own timestep
    np.testing.assert_allclose(got[0][:, 0, 0], [0.002, 0.003, 0.004, 0.005, 0.006])


def test_outputs_written_in_place_and_nstep_without_control(cluster, humanoid):
    initial, _, _ = inputs(humanoid, 4, 1)
    nstate = mjcffi.mj_stateSize(humanoid, FULLPHYSICS)
    state = np.zeros((4, 7, nstate))
    sensordata = np.zeros((4, 7, humanoid.nsensordata))
    got = cluster.rollout(humanoid, initial, nstep=7, state=state, sensordata=sensordata)
    assert got[0] is state or np.shares_memory(got[0], state)
    assert_same(local_rollout(humanoid, initial, None, nstep=7), (state, sensordata))


def test_skip_checks_takes_full_size_arrays(cluster, humanoid):
    initial, warmstart, control = inputs(humanoid, 5, 6, seed=2)
    models = [humanoid] * 5
    expected = local_rollout(models, initial, control, initial_warmstart=warmstart)
    nstate = initial.shape[1]
    state = np.empty((5, 6, nstate))
    sensordata = np.empty((5, 6, humanoid.nsensordata))
    cluster.rollout(models, initial, control, skip_checks=True, nstep=6,
                    initial_warmstart=warmstart, state=state, sensordata=sensordata,
                    shard_size=2)
    assert_same(expected, (state, sensordata))


def test_the_module_level_rollout_uses_a_default_cluster(ray, humanoid):
    initial, _, control = inputs(humanoid, 6, 10, seed=1)
    got = distributed.rollout(humanoid, initial, control, num_workers=2, progress=True)
    assert_same(local_rollout(humanoid, initial, control), got)
    first = distributed.default_cluster()
    distributed.rollout(humanoid, initial, control)
    assert distributed.default_cluster() is first and first.num_workers == 2


def test_nothing_to_roll_out(cluster, humanoid):
    initial, _, _ = inputs(humanoid, 3, 5)
    state, sensordata = cluster.rollout(humanoid, initial, nstep=0)
    assert state.shape == (3, 0, initial.shape[1]) and sensordata.shape[:2] == (3, 0)


# ------------------------------------------------ a stand-in for a local Rollout

def test_end_states_takes_a_cluster_for_a_pool(cluster, humanoid):
    rng = np.random.default_rng(3)
    initial = states.initial_states(humanoid, 2, rng)
    controls = states.random_controls(humanoid, rng, (2, 4)) * 0.3
    samples, _ = states.sample(humanoid, initial, controls, 5, 6)
    with local.Rollout(nthread=2) as pool:
        expected = periods.end_states(pool, humanoid, samples, 5, 2)
    got = periods.end_states(cluster, humanoid, samples, 5, 2)
    assert_same(expected, got)
    assert got[1].all()


# --------------------------------------------------------------- failures

def test_a_worker_that_exits_mid_call_is_replaced(cluster, humanoid):
    initial, warmstart, control = inputs(humanoid, 8, 15, seed=4)
    expected = local_rollout(humanoid, initial, control, initial_warmstart=warmstart)
    doomed = cluster.workers[0]
    cluster._ray.get(doomed.exit_on_shard.remote(2))      # dies on its second shard
    got = cluster.rollout(humanoid, initial, control, initial_warmstart=warmstart,
                          shard_size=1)
    assert_same(expected, got)
    assert doomed not in cluster.workers and cluster.num_workers == 2


def test_a_killed_worker_is_replaced(cluster, humanoid, ray):
    initial, _, control = inputs(humanoid, 4, 10, seed=5)
    doomed = cluster.workers[1]
    ray.kill(doomed)
    got = cluster.rollout(humanoid, initial, control)
    assert_same(local_rollout(humanoid, initial, control), got)
    assert doomed not in cluster.workers and cluster.num_workers == 2


def _boxes():
    """Eight boxes on the floor and a stack too small for their contacts: a step in contact
    raises mju_error (stack overflow), a step in the air does not."""
    bodies = "".join(f'<body pos="{0.25 * (i % 4)} {0.25 * (i // 4)} .1"><freejoint/>'
                     f'<geom type="box" size=".1 .1 .1"/></body>' for i in range(8))
    return mjcffi.MjModel.from_xml_string(
        f'<mujoco><size memory="20K"/><worldbody><geom type="plane" size="2 2 .1"/>'
        f'{bodies}</worldbody><sensor><framepos objtype="body" objname="world"/></sensor>'
        f'</mujoco>')


def test_a_fatal_error_fails_its_rollouts_only(cluster):
    m = _boxes()
    d = mjcffi.MjData(m)
    nstate = mjcffi.mj_stateSize(m, FULLPHYSICS)
    initial = np.empty((7, nstate))
    for r in range(7):
        mjcffi.mj_resetData(m, d)
        if r not in (2, 5):
            d.qpos[2::7] += 5.0                # in the air: no contact
        mjcffi.mj_getState(m, d, initial[r], FULLPHYSICS)
    with pytest.raises(mjcffi.FatalError) as theirs:
        local_rollout(m, initial, None, nstep=6)
    state = np.zeros((7, 6, nstate))
    sensordata = np.zeros((7, 6, m.nsensordata))
    with pytest.raises(mjcffi.FatalError) as ours:
        cluster.rollout(m, initial, None, nstep=6, state=state, sensordata=sensordata,
                        shard_size=2)
    assert list(ours.value.failed) == list(theirs.value.failed) == [2, 5]
    assert str(ours.value) == str(theirs.value)
    assert "out of memory" in str(ours.value)
    good = [0, 1, 3, 4, 6]
    expected = local_rollout(m, initial[good], None, nstep=6)
    np.testing.assert_array_equal(state[good], expected[0], strict=True)
    np.testing.assert_array_equal(sensordata[good], expected[1], strict=True)
    assert np.isnan(state[[2, 5]]).all()


def test_a_model_the_workers_cannot_load_raises_its_problem(cluster, humanoid):
    bad = copy.copy(humanoid)
    bad.opt.solver = 10                        # no mjtSolver: MJB bytes that do not load
    with pytest.raises(ValueError, match="opt.solver is 10"):
        cluster.rollout(bad, inputs(humanoid, 2, 1)[0])


# --------------------------------------------------------------- bad input

@pytest.mark.parametrize("case", ["width", "nbatch", "spec", "nstep", "model", "output"])
def test_bad_input_raises_as_locally(cluster, humanoid, case):
    initial, _, control = inputs(humanoid, 3, 4)
    kwargs = {}
    if case == "width":
        initial = initial[:, :-1]
    elif case == "nbatch":
        control = control[:2]
    elif case == "spec":
        kwargs["control_spec"] = 1 << 20
    elif case == "nstep":
        kwargs["nstep"] = -1
    elif case == "model":
        humanoid = "humanoid.xml"
    else:
        kwargs["state"] = np.zeros((3, 4, 5), np.float32)
    with pytest.raises((ValueError, TypeError)) as theirs:
        local.rollout(humanoid, mjcffi.MjData(mjcffi.MjModel.from_xml_string(BOX))
                      if case == "model" else mjcffi.MjData(humanoid), initial, control,
                      **kwargs)
    with pytest.raises(type(theirs.value)) as ours:
        cluster.rollout(humanoid, initial, control, **kwargs)
    assert str(ours.value) == str(theirs.value)


def test_bad_cluster_arguments(ray, cluster, humanoid):
    with pytest.raises(ValueError, match="num_workers must be positive"):
        distributed.RolloutCluster(0)
    with pytest.raises(ValueError, match="shard_size must be a positive integer"):
        cluster.rollout(humanoid, inputs(humanoid, 1, 1)[0], shard_size=0)
    closed = distributed.RolloutCluster(1)
    closed.close()
    with pytest.raises(RuntimeError, match="closed RolloutCluster"):
        closed.rollout(humanoid, inputs(humanoid, 1, 1)[0])


# ----------------------------------------------------------- without Ray

def test_without_ray_calls_name_the_extra(monkeypatch, humanoid):
    monkeypatch.setitem(sys.modules, "ray", None)            # import ray -> ImportError
    with pytest.raises(ImportError, match=r"pip install 'mjcffi\[distributed\]'"):
        distributed.RolloutCluster(1)
    with pytest.raises(ImportError, match=r"pip install 'mjcffi\[distributed\]'"):
        distributed.map_calls(print, [()])


def test_without_ray_the_package_imports_and_rollout_names_the_extra():
    script = textwrap.dedent("""
        import sys
        sys.modules["ray"] = None
        import numpy as np
        import mjcffi.distributed as distributed
        m = mjcffi = __import__("mjcffi").MjModel.from_xml_string("<mujoco/>")
        try:
            distributed.rollout(m, np.zeros((1, 1)))
        except ImportError as exc:
            print(exc)
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert "pip install 'mjcffi[distributed]'" in out.stdout


# ------------------------------------------------------------- accuracy --ray

def _errors(path):
    """{setting: its error cells} of ACCURACY.md's double_pendulum table (timing dropped)."""
    section = open(path).read().split("## double_pendulum")[1]
    table = section[section.index("| setting |"):].split("\n\n")[0].splitlines()[2:]
    rows = {}
    for line in table:
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        rows[cells[0]] = cells[3:-1]           # pos err, energy drift
    return rows


def test_accuracy_on_ray_gets_the_same_errors(ray, tmp_path):
    from mjcffi import accuracy
    for name, extra in (("local", []), ("ray", ["--ray"])):
        assert accuracy.main(["double_pendulum", "--quick", "--out", str(tmp_path / name)]
                             + extra) == 0
    here, there = _errors(tmp_path / "local/ACCURACY.md"), _errors(tmp_path / "ray/ACCURACY.md")
    assert len(here) >= 6 and here == there


def test_tune_with_ray_finds_the_same_errors_as_locally(ray):
    # the search's errors come from rollouts, which are bit-identical on Ray: every setting
    # both runs evaluated has the same local error (which one wins may differ with timing)
    m = mjcffi.MjModel.from_xml_string(mjcffi.scenes.HARD_CASES["double_pendulum"])
    here = mjcffi.tune(m, 1e-4, control_period=0.01, progress=False)
    there = mjcffi.tune(m, 1e-4, control_period=0.01, progress=False, ray=True)
    assert there.error.original_local == here.error.original_local
    local_errors = {c.setting: c.error for c in here.candidates}
    shared = [c for c in there.candidates if c.setting in local_errors]
    assert len(shared) >= 10
    for c in shared:
        assert c.error == local_errors[c.setting], c.setting
