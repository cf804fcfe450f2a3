"""A KeyboardInterrupt wherever Python can raise one leaves nothing held.

Python takes claims of its own: a Rollout's set of calling threads, the contract's
scopes (whose callbacks' exceptions are whose), an MjSimPool's running flag, spec
claims (mjcffi/_support/spec_claims.py).  A SIGINT's KeyboardInterrupt surfaces at
CPython's next eval-breaker check, which may fall between taking a claim and the
`try` that releases it; the object was then refused forever ("this Rollout is
running the call whose callback made this one", "this spec is in a MuJoCo call on
another thread").

Here a trace function raises KeyboardInterrupt at each such point of the claiming
functions in turn, one per run, and the object must be usable afterwards.  The
points are those where CPython checks its eval breaker: a function's entry, right
after a call returns, a backward jump.  (A trace raising at every *line* would also
raise where CPython never does, such as at the no-op of a `try:` line, which no
handler covers.)
"""

import dis
import inspect
import sys
import threading

import numpy as np
import pytest

import mjcffi
from mjcffi import rollout as rollout_module
from mjcffi._support import contract, spec_claims
from mjcffi.sim import MjSim, MjSimPool

XML = """<mujoco><worldbody><body><joint name="j"/><geom size=".1" mass="1"/></body>
         </worldbody><actuator><motor joint="j"/></actuator></mujoco>"""

_CALLS = {dis.opmap[name] for name in ("CALL", "CALL_FUNCTION_EX") if name in dis.opmap}
_BACKWARD = {dis.opmap[name] for name in ("JUMP_BACKWARD",) if name in dis.opmap}


class Injected(KeyboardInterrupt):
    """The KeyboardInterrupt the trace function raises."""


def _following(code):
    """offset -> the offset of the next instruction (inline caches skipped)."""
    offsets = [i.offset for i in dis.get_instructions(code)]
    return dict(zip(offsets, offsets[1:]))


def _sweep(functions, call, check):
    """For k = 1, 2, ...: run `call()` with KeyboardInterrupt raised at the k-th
    eval-breaker point reached in `functions`, then `check()`; until a run reaches
    no k-th point.  Returns how many runs were interrupted."""
    following = {f.__code__: _following(f.__code__) for f in functions}
    interrupted = 0
    k = 1
    while True:
        seen = [0]
        last = {}       # id(frame) -> offset of the instruction it ran last (no frame kept)

        def point(frame):
            seen[0] += 1
            if seen[0] == k:
                raise Injected(f"injected in {frame.f_code.co_name} at offset "
                               f"{frame.f_lasti}")

        def local(frame, event, arg):
            if event == "return":
                last.pop(id(frame), None)
            elif event == "opcode":
                before = last.get(id(frame))
                last[id(frame)] = frame.f_lasti
                if before is not None:
                    op = frame.f_code.co_code[before]
                    after_call = op in _CALLS and \
                        following[frame.f_code].get(before) == frame.f_lasti
                    if after_call or (op in _BACKWARD and frame.f_lasti < before):
                        point(frame)
            return local

        def tracer(frame, event, arg):
            if frame.f_code not in following:
                return None
            frame.f_trace_opcodes = True
            frame.f_trace_lines = False
            point(frame)           # the entry: RESUME checks the eval breaker
            return local

        sys.settrace(tracer)
        try:
            call()
        except Injected:
            interrupted += 1
        finally:
            sys.settrace(None)
            last.clear()
        check()
        if seen[0] < k:
            return interrupted
        k += 1


@pytest.fixture
def model():
    return mjcffi.MjModel.from_xml_string(XML)


def test_a_rollout_interrupted_anywhere_stays_usable(model):
    nstate = mjcffi.mj_stateSize(model, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    state0 = np.zeros((4, nstate))
    pool = rollout_module.Rollout(nthread=2)
    datas = [mjcffi.MjData(model) for _ in range(2)]
    expected, _ = pool.rollout(model, datas, state0, nstep=3)
    # a Python callback: the call then also claims its callbacks' exceptions (a scope)
    mjcffi.set_mjcb_control(lambda m, d: None)
    try:
        def check():
            assert pool._callers == set()
            assert contract._scopes == []
            state, _ = pool.rollout(model, datas, state0, nstep=3)
            assert np.array_equal(state, expected)

        helpers = [getattr(contract, name) for name in ("scope", "claim")
                   if hasattr(contract, name)]
        n = _sweep([rollout_module.Rollout._call] + helpers,
                   lambda: pool.rollout(model, datas, state0, nstep=3), check)
    finally:
        mjcffi.set_mjcb_control(None)
        pool.close()
    assert n >= 5


def _compile_on_another_thread(spec):
    """Compile `spec` on a new thread: the exception it raised, or None."""
    out = []

    def run():
        try:
            spec.compile()
            out.append(None)
        except Exception as exc:    # noqa: BLE001 (the test reports it)
            out.append(exc)
    thread = threading.Thread(target=run)
    thread.start()
    thread.join(60)
    return out[0]


def _claim_functions():
    """The functions of spec_claims, and of contextlib where `holding` is a generator."""
    functions = [value for value in vars(spec_claims).values()
                 if inspect.isfunction(value) and value.__module__ == spec_claims.__name__]
    holding = spec_claims.holding
    if inspect.isclass(holding):
        # not __del__: the fallback, where Python prints and drops an exception
        functions += [value for name, value in vars(holding).items()
                      if inspect.isfunction(value) and name != "__del__"]
    else:
        import contextlib
        functions += [inspect.unwrap(holding), contextlib._GeneratorContextManager.__enter__,
                      contextlib._GeneratorContextManager.__exit__]
    return functions


def test_a_spec_method_interrupted_anywhere_leaves_the_spec_free(model):
    spec = mjcffi.MjSpec.from_string(XML)

    def check():
        assert spec_claims._HOLDS[0] == 0
        assert _compile_on_another_thread(spec) is None

    n = _sweep([mjcffi.MjSpec.compile] + _claim_functions(), spec.compile, check)
    assert n >= 3


def test_a_holding_block_interrupted_anywhere_leaves_the_spec_free():
    spec = mjcffi.MjSpec.from_string(XML)

    def hold():
        with spec_claims.holding(spec._ptr, b"a block"):
            pass

    def check():
        assert spec_claims._HOLDS[0] == 0
        assert _compile_on_another_thread(spec) is None

    n = _sweep([hold] + _claim_functions(), hold, check)
    assert n >= 2


def test_a_refused_holding_block_takes_nothing():
    spec = mjcffi.MjSpec.from_string(XML)
    holds = spec_claims._HOLDS[0]
    inside, done = threading.Event(), threading.Event()

    def other():
        with spec_claims.holding(spec._ptr, b"the other thread"):
            inside.set()
            done.wait(30)
    thread = threading.Thread(target=other)
    thread.start()
    assert inside.wait(30)
    try:
        with pytest.raises(RuntimeError, match="another thread"):
            with spec_claims.holding(spec._ptr, b"this thread"):
                pass
        with pytest.raises(RuntimeError, match="another thread"):
            spec.compile()
    finally:
        done.set()
        thread.join()
    assert spec_claims._HOLDS[0] == holds
    assert _compile_on_another_thread(spec) is None


def test_an_mjsimpool_step_interrupted_anywhere_stays_usable(model):
    pool = MjSimPool([MjSim(model) for _ in range(2)], nthreads=2)
    try:
        def check():
            assert not pool._running
            before = [sim.data.time for sim in pool.sims]
            pool.step()
            assert all(sim.data.time > t for sim, t in zip(pool.sims, before))

        n = _sweep([MjSimPool._run], pool.step, check)
    finally:
        pool.close()
    assert n >= 2


@pytest.mark.parametrize("context", ["warning_errors", "sim"])
def test_an_interrupted_ignore_block_stops_ignoring(context):
    """A block's count goes back as the block ends, or as the generator of an
    interrupted one is collected."""
    import contextlib
    if context == "warning_errors":
        from mjcffi import warning_errors as module
        block, local = module.ignore_warnings, module._local
    else:
        from mjcffi.sim import _warnings as module
        block, local = module.ignore_mujoco_warnings, module._local

    def enter():
        with block():
            pass

    def check():
        assert not getattr(local, "ignoring", 0)

    _sweep([enter, inspect.unwrap(block), contextlib._GeneratorContextManager.__enter__,
            contextlib._GeneratorContextManager.__exit__], enter, check)


def _as_current_scenario():
    """(In a subprocess with MUJOCO_GL=egl.)  ctx.as_current() interrupted anywhere: the
    context is current nowhere after, and another thread can make it current."""
    import contextlib
    import json
    from mjcffi.rendering._base import GLContextBase
    from mjcffi.gl_context import GLContext
    ctx = GLContext(16, 16)
    problems = []

    def block():
        with ctx.as_current():
            pass

    def check():
        if ctx._thread is not None:
            problems.append("left current")
        error = []

        def other():
            try:
                with ctx.as_current():
                    pass
            except Exception as exc:    # noqa: BLE001 (reported)
                error.append(str(exc))
        thread = threading.Thread(target=other)
        thread.start()
        thread.join(60)
        problems.extend(error)

    n = _sweep([inspect.unwrap(GLContextBase.as_current),
                contextlib._GeneratorContextManager.__enter__,
                contextlib._GeneratorContextManager.__exit__], block, check)
    ctx.free()
    print(json.dumps({"interrupted": n, "problems": problems[:3]}))


def test_an_interrupted_as_current_leaves_the_context_free():
    from tests import _gl
    out = _gl.run("tests.test_claims_interrupt_safe", "egl", "_as_current_scenario")
    assert out["interrupted"] >= 3 and out["problems"] == [], out
