"""Scenario probes: issue 11's triggers as reusable checks.

Each probe is a small function registered with `@probe(item, expect)`.  They
run in a subprocess (`run_all`, `run(name)`), one after the other; a probe that
crashes it fails, and the rest go on in a fresh one, so that a crash fails the
probe instead of the caller.  `expect`:
- "no crash": the scenario completes, or raises an exception of the
  documented set (TypeError, ValueError, IndexError, KeyError, FatalError);
- "raises": it must raise an exception of the documented set;
- "clean": it must complete without any exception.
A probe may also raise ProbeFailure itself for a check of its own (a lost
exception, a value silently corrupted).

    python -m tests.fuzz --probes            # every probe, a markdown table
    python -c "from tests.fuzz import probes; print(probes.run('camera_frame_null_forward'))"
"""

import gc
import os
import subprocess
import sys
import threading
from dataclasses import dataclass

from .runner import ROOT, _describe_status, worker_env

PROBES = {}


class ProbeFailure(AssertionError):
    """The scenario ran, but did something the promise forbids (a lost exception, ...)."""


@dataclass
class Probe:
    name: str
    item: str
    expect: str
    function: object

    @property
    def doc(self):
        return " ".join((self.function.__doc__ or "").split())


def probe(item, expect="no crash"):
    def register(function):
        PROBES[function.__name__] = Probe(function.__name__, item, expect, function)
        return function
    return register


# ---------------------------------------------------------------- helpers

def _model():
    import mjcffi
    from .env import XML
    m = mjcffi.MjModel.from_xml_string(XML)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    return m, d


def _zeros(n):
    import numpy as np
    from . import guard
    return guard.zeros((n,), np.float64)


def _documented():
    """The documented set, and NotImplementedError: the functions mjcffi does not wrap
    (codegen's UNSUPPORTED, listed in the README) raise it."""
    from .target import documented
    return documented() + (NotImplementedError,)


def _attempt(function, *args):
    """Call `function`; a documented exception is fine (returned), any other propagates."""
    try:
        function(*args)
    except _documented() as exc:
        return exc
    return None


# ------------------------------------------------------------ the probes

@probe("item 1")
def camera_frame_null_forward():
    """mjv_cameraFrame(headpos, None, up, right, d, MjvCamera())"""
    import mjcffi
    m, d = _model()
    mjcffi.mjv_cameraFrame(_zeros(3), None, _zeros(3), _zeros(3), d, mjcffi.MjvCamera())


@probe("item 1")
def camera_frame_all_null():
    """mjv_cameraFrame(None, None, None, None, d, MjvCamera()), and each output None alone"""
    import mjcffi
    m, d = _model()
    for i in range(4):
        outs = [_zeros(3) for _ in range(4)]
        outs[i] = None
        _attempt(mjcffi.mjv_cameraFrame, *outs, d, mjcffi.MjvCamera())
    mjcffi.mjv_cameraFrame(None, None, None, None, d, mjcffi.MjvCamera())


def _count_fields(cname):
    from mjcffi._generated.structinfo import STRUCTS
    return [f.name for f in STRUCTS[cname]
            if f.kind == "scalar" and f.elem in ("int", "mjtSize")
            and (f.name.startswith("n") or f.name.startswith("max"))]


@probe("item 2")
def scene_count_nflex():
    """scn.nflex = 10**9; scn.flexvertadr.sum()"""
    import mjcffi
    m, d = _model()
    scn = mjcffi.MjvScene(m, maxgeom=10)
    scn.nflex = 10**9
    scn.flexvertadr.sum()


@probe("item 2")
def scene_every_count():
    """every writable count of MjvScene, MjvFigure, MjuiState set to 10**9, -1, 2**31-1,
    then every field read"""
    import mjcffi
    from .entries import _read_all
    m, d = _model()
    for cname, make in (("mjvScene", lambda: mjcffi.MjvScene(m, maxgeom=10)),
                        ("mjvFigure", mjcffi.MjvFigure), ("mjuiState", mjcffi.MjuiState),
                        ("mjvPerturb", mjcffi.MjvPerturb)):
        for field in _count_fields(cname):
            for value in (10**9, -1, 2**31 - 1):
                obj = make()
                if _attempt(setattr, obj, field, value) is None:
                    _read_all(obj, cname)


def _header(d):
    """The header bytes of an MjData's pickle (entries.PARTS)."""
    from .entries import _reduced
    return _reduced(d)[1][1]


def _data_pickle(m, d, header):
    import pickle
    from .entries import _reduced
    func, args = _reduced(d)
    args[1] = header

    class Reduced:
        def __reduce__(self):
            return func, tuple(args)
    return pickle.dumps(Reduced())


def _use(m, d):
    import mjcffi
    from .entries import _read_all
    _read_all(d, "mjData")
    mjcffi.mj_forward(m, d)
    mjcffi.mj_step(m, d)
    _read_all(d, "mjData")


def _unpickle_and_use(m, raw):
    import pickle
    try:
        d2 = pickle.loads(raw)
    except _documented():
        return
    _use(m, d2)


@probe("item 3")
def pickle_ncon_huge():
    """an MjData pickle with ncon = 10**7 in its header"""
    from mjcffi import ffi
    m, d = _model()
    raw = bytearray(_header(d))
    off = ffi.offsetof("mjData", "ncon")
    raw[off:off + 4] = (10**7).to_bytes(4, "little")
    _unpickle_and_use(m, _data_pickle(m, d, bytes(raw)))


@probe("item 3")
def pickle_qvel_pointer_flip():
    """an MjData pickle with one byte of its qvel pointer flipped (each of the 8 bytes);
    where the pickle holds no pointers (mjcffi's format keeps offsets in a `layout`
    part), each of the layout's first 256 bytes flipped instead"""
    import pickle
    from mjcffi import ffi
    from .entries import PARTS, _reduced
    m, d = _model()
    func, args = _reduced(d)
    off = ffi.offsetof("mjData", "qvel")
    if off + 8 <= len(args[1]):
        for byte in range(8):
            raw = bytearray(args[1])
            raw[off + byte] ^= 0x10
            _unpickle_and_use(m, _data_pickle(m, d, bytes(raw)))
        return
    index = PARTS.index("layout")
    layout = args[index]
    for byte in range(min(256, len(layout))):
        changed = list(args)
        raw = bytearray(layout)
        raw[byte] ^= 0x10
        changed[index] = bytes(raw)

        class Reduced:
            def __reduce__(self, changed=changed):
                return func, tuple(changed)
        _unpickle_and_use(m, pickle.dumps(Reduced()))


@probe("item 3")
def pickle_random_flips():
    """200 MjData pickles, each with one random byte of the header's sizes and pointers
    flipped (seeded)"""
    import random
    from mjcffi import ffi
    m, d = _model()
    h = _header(d)
    rng = random.Random(11)
    regions = [(0, min(len(h), ffi.offsetof("mjData", "solver"))),
               (min(len(h) - 8, ffi.offsetof("mjData", "buffer")), len(h))]
    for _ in range(200):
        lo, hi = rng.choice(regions)
        raw = bytearray(h)
        raw[rng.randrange(lo, hi)] ^= rng.randrange(1, 256)
        _unpickle_and_use(m, _data_pickle(m, d, bytes(raw)))


@probe("item 4", expect="clean")
def raising_callback_then_rollout():
    """a raising control callback, a 2-thread rollout, then set_mjcb_control(None):
    mj_step must not raise"""
    import numpy as np
    import mjcffi
    from mjcffi import rollout

    def control(m, d):
        raise RuntimeError("from the control callback")

    m, d = _model()
    mjcffi.set_mjcb_control(control)
    state = np.zeros((2, mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)))
    try:
        rollout.rollout([m, m], [d, mjcffi.MjData(m)], state, nstep=3)
    except Exception:
        pass
    try:
        mjcffi.mj_step(m, d)
    except Exception:
        pass
    mjcffi.set_mjcb_control(None)
    mjcffi.mj_step(m, d)
    mjcffi.mj_step(m, mjcffi.MjData(m))


@probe("item 5")
def reentrant_step_raises():
    """a control callback that calls mj_step on the same data: the outer mj_step must
    raise, not swallow"""
    import mjcffi
    m, d = _model()
    seen = []

    def control(model, data):
        seen.append(1)
        mjcffi.mj_step(model, data)

    mjcffi.set_mjcb_control(control)
    try:
        mjcffi.mj_step(m, d)
    except _documented() + (RuntimeError,):
        return
    finally:
        mjcffi.set_mjcb_control(None)
    if seen:
        raise ProbeFailure("mj_step re-entered from its own control callback did not raise")


@probe("item 6")
def sim_pool_same_sim():
    """MjSimPool([sim, sim]).step()"""
    import mjcffi
    from mjcffi import sim
    m, d = _model()
    s = sim.MjSim(m)
    sim.MjSimPool([s, s]).step()
    del mjcffi


@probe("item 7")
def scene_geom_after_free():
    """g = scn.geoms[0]; mjv_freeScene(scn) / mjv_makeScene(m, scn, 10); then read/write g"""
    import mjcffi
    m, d = _model()
    scn = mjcffi.MjvScene(m, maxgeom=100)
    mjcffi.mjv_updateScene(m, d, mjcffi.MjvOption(), None, mjcffi.MjvCamera(), 7, scn)
    g = scn.geoms[0]
    mjcffi.mjv_freeScene(scn)
    _attempt(repr, g)
    _attempt(setattr, g, "size", [1.0, 2.0, 3.0])
    mjcffi.mjv_makeScene(m, scn, 10)
    _attempt(repr, g)
    _attempt(setattr, g, "size", [1.0, 2.0, 3.0])
    g2 = scn.geoms[9]
    mjcffi.mjv_makeScene(m, scn, 2)
    _attempt(repr, g2)
    _attempt(setattr, g2, "rgba", [1.0, 1.0, 1.0, 1.0])


@probe("item 8")
def spec_deleted_element():
    """mjs_delete of a spec element, then reading and writing its wrapper"""
    from mjcffi import functions as F
    s = F.mj_makeSpec()
    body = F.mjs_addBody(F.mjs_findBody(s, "world"), None)
    geom = F.mjs_addGeom(body, None)
    F.mjs_delete(s, geom.element)
    _attempt(repr, geom)
    _attempt(setattr, geom, "size", [1.0, 1.0, 1.0])
    F.mjs_delete(s, body.element)
    _attempt(repr, body)
    _attempt(F.mjs_addGeom, body, None)


@probe("item 8")
def spec_delete_world():
    """mjs_delete of the world body, then freeing the spec"""
    from mjcffi import functions as F
    s = F.mj_makeSpec()
    world = F.mjs_findBody(s, "world")
    _attempt(F.mjs_delete, s, world.element)
    del s, world
    gc.collect()


@probe("item 9")
def vfs_mount_then_drop():
    """mj_mountVFS(vfs, 'x', MjpResourceProvider()); del vfs; gc (MALLOC_PERTURB_=165)"""
    import mjcffi
    vfs = mjcffi.MjVfs()
    _attempt(mjcffi.mj_mountVFS, vfs, "x", mjcffi.MjpResourceProvider())
    del vfs
    gc.collect()
    m, d = _model()
    mjcffi.mj_step(m, d)


@probe("item 10")
def get_sdf_int_min():
    """mjc_getSDF(m, -2**31)"""
    import mjcffi
    m, d = _model()
    for value in (-2**31, -1, 2**31 - 1, m.nplugin, m.ngeom):
        _attempt(mjcffi.mjc_getSDF, m, value)


@probe("MuJoCo")
def local2global_body_max():
    """mj_local2Global(d, ..., body=2**31-1, ...)"""
    import mjcffi
    import numpy as np
    m, d = _model()
    for body in (2**31 - 1, -1, -2**31, m.nbody):
        _attempt(mjcffi.mj_local2Global, d, _zeros(3), np.zeros(9), _zeros(3),
                 np.array([1.0, 0, 0, 0]), body, 0)


@probe("MuJoCo")
def ray_flex_id_max():
    """mj_rayFlex(..., flexid=2**31-1, ...)"""
    import mjcffi
    import numpy as np
    m, d = _model()
    for flexid in (2**31 - 1, -1, -2**31, m.nflex):
        _attempt(mjcffi.mj_rayFlex, m, d, 0, 1, 1, 1, 1, flexid, _zeros(3),
                 np.array([0.0, 0.0, -1.0]), np.zeros(1, np.int32), _zeros(3))


@probe("FatalError")
def mjr_context_twice():
    """MjrContext(m, 100) twice without an OpenGL context: each must raise FatalError,
    and the process go on"""
    import mjcffi
    m, d = _model()
    for _ in range(2):
        _attempt(mjcffi.MjrContext, m, 100)


@probe("threads")
def two_threads_one_data():
    """the same MjData stepped from two Python threads at once (started together, each
    stepping 500 steps per call in C, so that the calls overlap on every run)"""
    import mjcffi
    m, d = _model()
    errors = []
    start = threading.Barrier(2)

    def run():
        start.wait()
        try:
            for _ in range(20):
                mjcffi.mj_step(m, d, 500)
        except _documented():
            pass
        except BaseException as exc:
            errors.append(exc)
    for _ in range(5):                  # a race may end in a FatalError instead
        mjcffi.mj_resetData(m, d)
        threads = [threading.Thread(target=run) for _ in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    if errors:
        raise errors[0]


@probe("lifetimes")
def view_outlives_model():
    """a model's array view, and a data's, read and written after both are collected"""
    import mjcffi
    m, d = _model()
    pos, qpos = m.body_pos, d.qpos
    del m, d
    gc.collect()
    pos.sum()
    qpos[:] = 1.0


@probe("lifetimes")
def accessor_outlives_data():
    """a named accessor, a contact and a warning struct read after their data is collected"""
    m, d = _model()
    joint, contact, warning = d.joint("hinge"), d.contact[0], d.warning[0]
    del d
    gc.collect()
    joint.qpos.sum()
    repr(joint)
    repr(contact)
    repr(warning)


@probe("rollout", expect="raises")
def rollout_nthread_2_31():
    """Rollout(nthread=2**31)"""
    from mjcffi import rollout
    rollout.Rollout(nthread=2**31).close()


@probe("rollout", expect="raises")
def rollout_nthread_10_9():
    """Rollout(nthread=10**9) must be refused, not attempted"""
    from mjcffi import rollout
    rollout.Rollout(nthread=10**9).close()


@probe("batch", expect="raises")
def batch_step_nstep_2_31():
    """Batch.step(nstep=2**31)"""
    from mjcffi import batch
    m, d = _model()
    with batch.Batch(m, 2) as b:
        b.step(nstep=2**31)


@probe("structs", expect="raises")
def warning_number_2_40():
    """d.warning[0].number = 2**40"""
    m, d = _model()
    d.warning[0].number = 2**40


@probe("sim", expect="raises")
def sim_pool_closed_step():
    """MjSimPool.close() then step()"""
    from mjcffi import sim
    m, d = _model()
    pool = sim.MjSimPool([sim.MjSim(m)])
    pool.close()
    pool.step()


@probe("batch")
def batch_expand_parentid():
    """Batch.expand('body_parentid'), then step"""
    from mjcffi import batch
    m, d = _model()
    with batch.Batch(m, 2) as b:
        _attempt(b.expand, "body_parentid")
        b.step()


@probe("rollout")
def rollout_bad_inputs():
    """rollout with mismatched models, short states, read-only outputs, nstep=2**31"""
    import numpy as np
    import mjcffi
    from mjcffi import rollout
    from .env import OTHER_XML
    m, d = _model()
    other = mjcffi.MjModel.from_xml_string(OTHER_XML)
    n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    state = np.zeros((2, n))
    ro = np.zeros((2, 3, n))
    ro.flags.writeable = False
    for kwargs in ({"model": [m, other], "data": d, "initial_state": state, "nstep": 3},
                   {"model": m, "data": d, "initial_state": state[:, :-1], "nstep": 3},
                   {"model": m, "data": d, "initial_state": state, "nstep": 3, "state": ro},
                   {"model": m, "data": d, "initial_state": state, "nstep": 2**31},
                   {"model": m, "data": d, "initial_state": state, "nstep": -1},
                   {"model": m, "data": [d, d], "initial_state": state, "nstep": 3},
                   {"model": m, "data": mjcffi.MjData(other), "initial_state": state,
                    "nstep": 3}):
        _attempt(lambda: rollout.rollout(**kwargs))


# -------------------------------------------------------------- running



# ------------------------------------------- issue 27: const, pointers, specs, pools

def _const_results():
    """(name, result) of every function the metadata says returns a const struct pointer,
    called validly (the fuzzer's own valid call), and the plugin table's every slot."""
    import mjcffi
    from mjcffi._generated.funcinfo import FUNCTIONS
    from .env import Env
    from .functions import FunctionTarget
    env, found = Env(), []
    for name, info in sorted(FUNCTIONS.items()):
        if not (info.restype.startswith("const mj") and info.restype.endswith("*")):
            continue
        try:
            target = FunctionTarget(name)
            found.append((name, target.call(env, target.valid(env))))
        except _documented():
            pass
    for slot in range(mjcffi.mjp_pluginCount()):
        found.append(("mjp_getPluginAtSlot", mjcffi.mjp_getPluginAtSlot(slot)))
    return [(name, result) for name, result in found if hasattr(result, "_cname")]


@probe("issue 27", expect="clean")
def const_results_written():
    """every field of every const struct a function returns (the global plugin table,
    found from the metadata) written with 0, -5 and 10**6; then a pid model loads"""
    import mjcffi
    results = _const_results()
    if not any(name == "mjp_getPluginAtSlot" for name, _ in results):
        raise ProbeFailure("no plugin table to write into")
    for name, result in results:
        size = mjcffi.ffi.sizeof(result._cname)
        before = bytes(mjcffi.ffi.buffer(result._ptr, size))
        for field in result._fields:
            for value in (0, -5, 10**6):
                try:
                    setattr(result, field, value)
                except AttributeError:
                    continue
                raise ProbeFailure(f"{name}(): {result._cname}.{field} = {value} was written")
        if bytes(mjcffi.ffi.buffer(result._ptr, size)) != before:
            raise ProbeFailure(f"{name}(): MuJoCo's const {result._cname} changed")
    mjcffi.MjModel.from_xml_string(
        "<mujoco><extension><plugin plugin='mujoco.pid'/></extension><worldbody><body>"
        "<joint name='j'/><geom size='.1' mass='1'/></body></worldbody><actuator><plugin "
        "plugin='mujoco.pid' joint='j'><config key='kp' value='1'/></plugin></actuator>"
        "</mujoco>")


@probe("issue 27", expect="clean")
def pointer_results_indexed():
    """every function returning a pointer to numbers, called validly, its result indexed
    at its size, 10**9 and -10**9 (read and write), and again after the call that
    releases it"""
    import numpy as np
    import mjcffi
    from mjcffi._generated.funcinfo import FUNCTIONS
    from .env import Env
    from .functions import FunctionTarget
    env = Env()
    numbers = ("mjtNum *", "int *", "void *", "const mjtNum *", "const int *",
               "const double *")
    for name, info in sorted(FUNCTIONS.items()):
        if info.restype not in numbers or name in ("mju_malloc",):
            continue
        try:
            target = FunctionTarget(name)
            result = target.call(env, target.valid(env))
        except _documented():
            continue
        if result is None:
            continue
        if not isinstance(result, np.ndarray):
            raise ProbeFailure(f"{name}() returned {type(result).__name__}, not an array")
        for index in (result.size, 10**9, -10**9):
            for access in (lambda: result[index], lambda: result.__setitem__(index, 1)):
                try:
                    access()
                except IndexError:
                    continue
                raise ProbeFailure(f"{name}()[{index}] reached memory past the array")
    m, d = _model()
    mjcffi.mj_markStack(d)
    array = mjcffi.mj_stackAllocNum(d, 4)
    mjcffi.mj_freeStack(d)
    try:
        array[0] = 1.0
    except ValueError:
        return
    raise ProbeFailure("a released stack array was still writable")


@probe("issue 27", expect="clean")
def spec_two_threads():
    """compile, to_xml, copy and element edits of one spec on three threads at once, 20
    rounds each: every call completes or raises RuntimeError"""
    import mjcffi
    from .env import XML
    spec = mjcffi.MjSpec.from_string(XML)
    unexpected = []

    def edit(spec):
        spec.worldbody.add_body(name=None).add_geom(size=[.1, 0, 0])
        spec.bodies[-1].name = "b"
        spec.delete(spec.bodies[-1])

    def work(action):
        for _ in range(20):
            try:
                action(spec)
            except RuntimeError:
                pass
            except BaseException as exc:
                unexpected.append(exc)
    actions = (lambda s: s.compile(), lambda s: s.to_xml(), lambda s: (s.copy(), edit(s)))
    threads = [threading.Thread(target=work, args=(a,)) for a in actions]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if unexpected:
        raise unexpected[0]


@probe("issue 27", expect="clean")
def pool_reentered_from_callback():
    """a control callback calling its own Rollout (0 and 2 threads) and MjSimPool, and a
    Python warning handler calling its own Batch: each re-entry raises RecursionError,
    and nothing waits forever"""
    import numpy as np
    import mjcffi
    from mjcffi import batch, rollout, sim
    m, d = _model()
    n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    outcomes = []

    def reenter(call):
        def callback(m_, d_):
            if len(outcomes) < 50:
                try:
                    call()
                    outcomes.append("completed")
                except RecursionError:
                    outcomes.append("refused")
        return callback
    try:
        for nthread in (0, 2):
            pool = rollout.Rollout(nthread=nthread)
            datas = [mjcffi.MjData(m) for _ in range(max(nthread, 1))]
            mjcffi.set_mjcb_control(reenter(lambda: pool.rollout(m, datas, np.zeros((1, n)),
                                                                 nstep=1)))
            pool.rollout(m, datas, np.zeros((4, n)), nstep=2)
        sims = sim.MjSimPool([sim.MjSim(m) for _ in range(2)], nthreads=2)
        mjcffi.set_mjcb_control(reenter(sims.step))
        sims.step()
        mjcffi.set_mjcb_control(None)
        with batch.Batch(m, 2, nthread=2) as b:
            mjcffi.set_mju_user_warning(lambda text: reenter(b.step)(None, None))
            b.state[:, 1] = np.nan
            b.step()
    finally:
        mjcffi.set_mjcb_control(None)
        mjcffi.set_mju_user_warning(None)
    if not outcomes or set(outcomes) != {"refused"}:
        raise ProbeFailure(f"re-entries gave {sorted(set(outcomes))}, not only RecursionError")


def _interrupt_points(code, k):
    """A trace function raising KeyboardInterrupt at the k-th point of `code` where
    CPython checks for signals (its entry, after a call returns, a backward jump), and
    a list that counts the points seen."""
    import dis
    calls = {dis.opmap[n] for n in ("CALL", "CALL_FUNCTION_EX") if n in dis.opmap}
    seen, last = [0], {}

    def point():
        seen[0] += 1
        if seen[0] == k:
            raise KeyboardInterrupt("injected")

    def local(frame, event, arg):
        if event == "opcode":
            before = last.get(id(frame))
            last[id(frame)] = frame.f_lasti
            if before is not None and (frame.f_code.co_code[before] in calls
                                       or frame.f_lasti < before):
                point()
        elif event == "return":
            last.pop(id(frame), None)
        return local

    def tracer(frame, event, arg):
        if frame.f_code is not code:
            return None
        frame.f_trace_opcodes, frame.f_trace_lines = True, False
        point()
        return local
    return tracer, seen


@probe("claims", expect="clean")
def claim_interrupted_after_taken():
    """a KeyboardInterrupt at each point where CPython raises one in Rollout._call and
    in the spec claim (holding.__enter__): afterwards the pool rolls out and another
    thread compiles the spec"""
    import inspect
    import sys
    import numpy as np
    import mjcffi
    from mjcffi import rollout
    from mjcffi._support import spec_claims
    from .env import XML
    m, _ = _model()
    n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    pool = rollout.Rollout(nthread=2)
    datas = [mjcffi.MjData(m) for _ in range(2)]
    spec = mjcffi.MjSpec.from_string(XML)
    holding = spec_claims.holding     # a class; a generator function before the fix
    enter = holding.__enter__ if isinstance(holding, type) else inspect.unwrap(holding)
    cases = ((rollout.Rollout._call, lambda: pool.rollout(m, datas, np.zeros((2, n)), nstep=1)),
             (enter, spec.compile))
    for function, call in cases:
        for k in range(1, 40):
            tracer, seen = _interrupt_points(function.__code__, k)
            sys.settrace(tracer)
            try:
                call()
            except KeyboardInterrupt:
                pass
            finally:
                sys.settrace(None)
            errors = []
            thread = threading.Thread(target=lambda: _attempt_into(errors, spec.compile))
            thread.start()
            thread.join(60)
            if errors:
                raise ProbeFailure(f"after an interrupt at point {k} of "
                                   f"{function.__qualname__}: {errors[0]}")
            if pool._callers:
                raise ProbeFailure(f"point {k} of {function.__qualname__} left the caller "
                                   f"registered: {pool._callers}")
            pool.rollout(m, datas, np.zeros((2, n)), nstep=1)
            if seen[0] < k:
                break
    pool.close()


def _attempt_into(errors, call):
    try:
        call()
    except Exception as exc:        # noqa: BLE001 (the probe reports it)
        errors.append(exc)


@probe("prepared", expect="clean")
def prepared_after_stack_release():
    """mju_fill.prepare(a stack array, 7), then mj_freeStack and a new stack array: prepare
    refuses the stack array, or the call leaves the new array alone"""
    import mjcffi
    m, d = _model()
    mjcffi.mj_markStack(d)
    a = mjcffi.mj_stackAllocNum(d, 3)
    try:
        fill = mjcffi.mju_fill.prepare(a, 7.0)
    except _documented():
        fill = None
    mjcffi.mj_freeStack(d)
    mjcffi.mj_markStack(d)
    b = mjcffi.mj_stackAllocNum(d, 3)
    b[:] = 1.0
    if fill is not None:
        fill()
    if b.tolist() != [1.0] * 3:
        raise ProbeFailure(f"a prepared call wrote into a newer stack array: {b.tolist()}")
    mjcffi.mj_freeStack(d)


@probe("prepared", expect="clean")
def prepared_after_resize_without_refcheck():
    """mju_fill.prepare(out, 5), out.resize(10**5, refcheck=False), then the call: NumPy
    refuses the resize while the prepared call binds the array"""
    import numpy as np
    import mjcffi
    out = np.zeros(3)
    fill = mjcffi.mju_fill.prepare(out, 5.0)
    try:
        out.resize(10**5, refcheck=False)
    except ValueError:
        fill()
        if out.tolist() != [5.0] * 3:
            raise ProbeFailure(f"the prepared call wrote {out.tolist()}")
        return
    raise ProbeFailure("the bound array was resized: the prepared call's pointer is freed")


@probe("official objects", expect="clean")
def official_objects_passed():
    """an official MjModel, MjData, MjvOption and MjvScene passed to mj_step, mj_forward,
    MjData, mj_jac.prepare, rollout and mjv_updateScene: a TypeError naming the official
    class with its module"""
    import numpy as np
    import mujoco
    import mjcffi
    from .env import XML
    m = mujoco.MjModel.from_xml_string(XML)
    d = mujoco.MjData(m)
    mm, md = _model()
    calls = {
        "mj_step": lambda: mjcffi.mj_step(m, d),
        "mj_forward": lambda: mjcffi.mj_forward(mm, d),
        "MjData": lambda: mjcffi.MjData(m),
        "mj_jac.prepare": lambda: mjcffi.mj_jac.prepare(m, md, None, None, np.zeros(3), 0),
        "rollout": lambda: mjcffi.rollout.rollout(m, md, np.zeros((1, 3))),
        "mjv_updateScene": lambda: mjcffi.mjv_updateScene(
            mm, md, mujoco.MjvOption(), None, mjcffi.MjvCamera(), 0, mjcffi.MjvScene(mm, 10)),
    }
    for name, call in calls.items():
        try:
            call()
        except TypeError as exc:
            if "mujoco._structs." not in str(exc) or "official bindings" not in str(exc):
                raise ProbeFailure(f"{name}: the message does not name the official class: "
                                   f"{exc}")
        else:
            raise ProbeFailure(f"{name} took an official object")

@dataclass
class ProbeResult:
    name: str
    item: str
    passed: bool
    status: str           # ok, raised X, crash (SIGSEGV), timeout, failed: ...
    detail: str = ""

    @property
    def known(self):
        from .known import match
        return match(f"probe:{self.name}|-|-") is not None


def _verdict(name):
    """Run probe `name` in this process: its verdict line."""
    p = PROBES[name]
    try:
        p.function()
    except ProbeFailure as exc:
        return f"FAIL {exc}"
    except _documented() as exc:
        from .worker import _innermost_is_fuzzer
        if _innermost_is_fuzzer(exc):
            return f"FAIL the probe's own code raised {type(exc).__name__}: {_one_line(exc)}"
        verdict = "FAIL" if p.expect == "clean" else "OK"
        return f"{verdict} raised {type(exc).__name__}: {_one_line(exc)}"
    except BaseException as exc:     # noqa: B902 (an undocumented type is the finding)
        return (f"FAIL undocumented {type(exc).__module__}.{type(exc).__name__}: "
                f"{_one_line(exc)}")
    gc.collect()
    if p.expect == "raises":
        return "FAIL completed, but it must raise"
    return "OK completed"


def _one_line(exc):
    return " ".join(str(exc).split())[:200]


def _run_many(names, fd):
    """The subprocess's side: each probe in turn, `START name` before it and
    `DONE name verdict` after it, on file descriptor `fd`."""
    from .worker import _reset_globals, limit_memory
    limit_memory()
    out = os.fdopen(fd, "w", buffering=1, encoding="utf-8", errors="backslashreplace")
    for name in names:
        out.write(f"START\t{name}\n")
        out.flush()
        verdict = _verdict(name)
        _reset_globals()
        gc.collect()
        out.write(f"DONE\t{name}\t{verdict}\n")
        out.flush()


def _run_batch(names, timeout):
    """Run `names` in one subprocess: ({name: verdict}, (crashed name, status, stderr) or None)."""
    import json
    import select
    import signal
    import tempfile
    import time
    read_fd, write_fd = os.pipe()
    with tempfile.TemporaryFile() as err:
        code = (f"from tests.fuzz import probes; "
                f"probes._run_many({json.dumps(list(names))}, {write_fd})")
        proc = subprocess.Popen([sys.executable, "-X", "faulthandler", "-c", code],
                                pass_fds=(write_fd,), stdin=subprocess.DEVNULL,
                                stdout=subprocess.DEVNULL, stderr=err, env=worker_env(),
                                cwd=str(ROOT), start_new_session=True)
        os.close(write_fd)
        verdicts, current, buffer, hung = {}, None, b"", False
        with os.fdopen(read_fd, "rb", buffering=0) as pipe:
            last = time.monotonic()
            while True:
                ready, _, _ = select.select([pipe], [], [], 0.5)
                if ready:
                    chunk = pipe.read(65536)
                    if not chunk:
                        break
                    buffer += chunk
                    *lines, buffer = buffer.split(b"\n")
                    for line in lines:
                        parts = line.decode("utf-8", "replace").split("\t")
                        if parts[0] == "START":
                            current = parts[1]
                        elif parts[0] == "DONE":
                            verdicts[parts[1]] = parts[2]
                            current = None
                    last = time.monotonic()
                elif time.monotonic() - last > timeout:
                    hung = True
                    break
        if hung:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        rc = proc.wait()
        err.seek(0)
        tail = err.read()[-1500:].decode("utf-8", "replace")
    if current is not None:
        return verdicts, (current, "timeout" if hung else _describe_status(rc), tail)
    if not verdicts and names:
        raise RuntimeError(f"the probe process did not start ({_describe_status(rc)}):\n{tail}")
    return verdicts, None


def run_all(names=None, timeout=60):
    """Run the probes (all by default) in as few subprocesses as crashes allow: a list of
    ProbeResult in the order of `names`."""
    names = list(names or PROBES)
    results = {}
    pending = list(names)
    while pending:
        verdicts, crash = _run_batch(pending, timeout)
        for name, verdict in verdicts.items():
            passed = verdict.startswith("OK")
            results[name] = ProbeResult(name, PROBES[name].item, passed,
                                        verdict.split(" ", 1)[1] if " " in verdict else "")
        if crash is not None:
            name, status, tail = crash
            label = "timeout" if status == "timeout" else f"crash ({status})"
            results[name] = ProbeResult(name, PROBES[name].item, False, label, tail)
        pending = [n for n in pending if n not in results]
    return [results[n] for n in names]


def run(name, timeout=60):
    """Run probe `name` alone in a subprocess: a ProbeResult."""
    return run_all([name], timeout)[0]


def markdown(results):
    if not results:
        return ""
    lines = ["", "## Scenario probes", "",
             "| probe | item | scenario | result |", "| --- | --- | --- | --- |"]
    for r in results:
        verdict = "pass" if r.passed else ("known: " if r.known else "FAIL: ")
        if not r.passed:
            verdict += r.status
        lines.append(f"| {r.name} | {r.item} | {PROBES[r.name].doc} | {verdict} |")
    failing = [r for r in results if not r.passed and r.detail]
    for r in failing:
        lines += ["", f"### {r.name}: {r.status}", "", "```", r.detail.strip()[-1200:], "```"]
    return "\n".join(lines) + "\n"
