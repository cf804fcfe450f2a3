"""Issue 27, finding 3: one thread at a time per MjSpec.

A call on a spec, or on one of its elements, while another thread is inside a MuJoCo
call on the same spec raises RuntimeError: it neither waits nor crashes
(mjcffi/_c/claims.c, mjcffi/_support/spec_claims.py).  Two specs are independent.
"""

import threading

import numpy as np
import pytest

import mjcffi
from mjcffi._support import spec_claims

from .conftest import gymnasium_assets

HUMANOID = next(p for p in gymnasium_assets() if p.name == "humanoid.xml")


@pytest.fixture
def holder():
    """hold(spec): the spec held by another thread's call until the test ends."""
    events = []

    def hold(spec):
        inside, done = threading.Event(), threading.Event()

        def run():
            with spec_claims.holding(spec._ptr, b"a long call"):
                inside.set()
                done.wait(30)

        thread = threading.Thread(target=run)
        thread.start()
        assert inside.wait(30)
        events.append((done, thread))
        return spec
    yield hold
    for done, thread in events:
        done.set()
        thread.join()


@pytest.fixture
def held(holder):
    return holder(mjcffi.MjSpec.from_file(str(HUMANOID)))


# each takes the spec and (a geom, a body) fetched before the spec was held, so that the
# access itself is what is refused
ACCESSES = {
    "compile": lambda s, g, b: s.compile(),
    "to_xml": lambda s, g, b: s.to_xml(),
    "copy": lambda s, g, b: s.copy(),
    "list the geoms": lambda s, g, b: s.geoms,
    "add a body": lambda s, g, b: b.add_body(name="new"),
    "find a body": lambda s, g, b: s.body("torso"),
    "delete": lambda s, g, b: s.delete(g),
    "rename a geom": lambda s, g, b: setattr(g, "name", "renamed"),
    "write a string": lambda s, g, b: setattr(g, "material", "steel"),
    "read a string": lambda s, g, b: g.info,
    "write a vector": lambda s, g, b: setattr(b, "userdata", [1.0, 2.0]),
    "read a vector": lambda s, g, b: list(b.userdata),
    "a function on an element": lambda s, g, b: mjcffi.mjs_getParent(g.element),
    "a function on the spec": lambda s, g, b: mjcffi.mjs_findBody(s, "torso"),
    "mj_compile": lambda s, g, b: mjcffi.mj_compile(s, None),
}


@pytest.mark.parametrize("access", ACCESSES)
def test_a_call_on_a_spec_another_thread_holds_raises_runtime_error(holder, access):
    spec = mjcffi.MjSpec.from_file(str(HUMANOID))
    geom, body = spec.geoms[0], spec.bodies[1]
    geom.info = "a string longer than the twenty-two bytes kept in place"
    holder(spec)
    with pytest.raises(RuntimeError, match="another thread"):
        ACCESSES[access](spec, geom, body)


def test_the_plain_fields_are_views_and_not_refused(holder):
    """A NumPy view of the spec's memory makes no call: nothing can refuse it."""
    spec = mjcffi.MjSpec.from_file(str(HUMANOID))
    geom = spec.geoms[0]
    before = geom.size.copy()
    holder(spec)
    assert np.array_equal(geom.size, before)
    with pytest.raises(RuntimeError):
        geom.name = "refused"


def test_another_spec_is_free_and_the_spec_is_free_again_after_the_call(held):
    other = mjcffi.MjSpec.from_file(str(HUMANOID))
    assert other.compile().nbody > 1


def test_the_holding_thread_may_nest():
    spec = mjcffi.MjSpec.from_file(str(HUMANOID))
    with spec_claims.holding(spec._ptr, b"outer"):
        assert spec.compile().nbody > 1
        spec.geoms[0].name = "still mine"
    assert spec.to_xml()


def test_a_released_spec_serves_any_thread():
    spec = mjcffi.MjSpec.from_file(str(HUMANOID))
    results = []
    thread = threading.Thread(target=lambda: results.append(spec.compile().nbody))
    thread.start()
    thread.join()
    assert results and spec.compile().nbody == results[0]
    assert spec_claims._HOLDS[0] == 0


def test_two_threads_on_one_spec_never_wait_for_each_other():
    """Each call returns or raises; none blocks on the other."""
    spec = mjcffi.MjSpec.from_file(str(HUMANOID))
    outcomes = {"done": 0, "refused": 0}
    lock = threading.Lock()

    def work(action):
        for _ in range(10):
            try:
                action(spec)
                key = "done"
            except RuntimeError:
                key = "refused"
            with lock:
                outcomes[key] += 1

    threads = [threading.Thread(target=work, args=(a,)) for a in
               (lambda s: s.compile(), lambda s: s.to_xml())]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
        assert not t.is_alive()
    assert outcomes["done"] + outcomes["refused"] == 20 and outcomes["done"] > 0


def test_reproducer_compile_and_to_xml_on_two_threads_cannot_crash(run_python):
    """Finding 3: compile() on one thread and to_xml() or compile() on the other gave
    SIGSEGV or "double free or corruption" within 1-3 tries."""
    code, out = run_python(f"""
        import threading
        import mjcffi
        spec = mjcffi.MjSpec.from_file({str(HUMANOID)!r})
        refused = []

        def work(action):
            for _ in range(25):
                try:
                    action()
                except RuntimeError:
                    refused.append(1)

        threads = [threading.Thread(target=work, args=(spec.compile,)),
                   threading.Thread(target=work, args=(spec.to_xml,)),
                   threading.Thread(target=work, args=(spec.compile,))]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        print("survived", len(refused) > 0)
        """, timeout=300)
    assert code == 0, out
    assert "survived True" in out
