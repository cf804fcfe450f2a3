"""Field reads against the official bindings: every public attribute of MjModel,
MjData, MjOption, `d.contact`, `d.contact[0]`, MjvScene and MjrContext.

Gymnasium's humanoid after 200 steps (contacts and constraint rows live), both
bindings in one process.  Each read is timed with `timeit` under the calling
thread's CPU time (wall time measures noise on a loaded machine), the two
bindings alternating within every round; figures are medians.  The MjrContexts
are made in one EGL context (mjcffi's, current for both; Mesa's llvmpipe does
without a GPU); where EGL is missing, MjrContext is left out and the section says so.

    python -m benchmarks.bench_fields            # print the section
    python -m benchmarks.bench_fields --write    # also replace it in RESULTS.md
"""

import argparse
import math
import os
import statistics
import sys
import time
import timeit

import mujoco

import mjcffi

from .common import interleaved, write_section

HEADING = "## Field reads"
STEPS = 200
# Reads that the issue (35) names, shown whatever their rank.
NAMED = ("d.contact", "d.contact.dist", "d.contact.geom", "d.contact[0].dist", "d.efc_force",
         "d.efc_AR", "d.island_nefc", "scn.geoms")


def _humanoid_path():
    import gymnasium
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        "humanoid.xml")


def _namespace(module, with_gl):
    """The objects whose fields are read: the humanoid after STEPS steps, a scene
    updated from it, and an MjrContext (when `with_gl`: an OpenGL context is current)."""
    m = module.MjModel.from_xml_path(_humanoid_path())
    d = module.MjData(m)
    for _ in range(STEPS):
        module.mj_step(m, d)
    scn = module.MjvScene(m, 1000)
    module.mjv_updateScene(m, d, module.MjvOption(), module.MjvPerturb(), module.MjvCamera(),
                           module.mjtCatBit.mjCAT_ALL, scn)
    space = {"m": m, "d": d, "opt": m.opt, "scn": scn}
    if with_gl:
        space["con"] = module.MjrContext(m, module.mjtFontScale.mjFONTSCALE_150)
    return space


# (label, the expression whose attributes are read, the official object)
def _objects(theirs):
    out = [("MjModel", "m", theirs["m"]), ("MjData", "d", theirs["d"]),
           ("MjOption", "opt", theirs["opt"]), ("`d.contact`", "d.contact", theirs["d"].contact),
           ("`d.contact[0]`", "d.contact[0]", theirs["d"].contact[0]),
           ("MjvScene", "scn", theirs["scn"])]
    if "con" in theirs:
        out.append(("MjrContext", "con", theirs["con"]))
    return out


def _fields(obj):
    """The public attributes of `obj` that are fields (properties), not methods."""
    cls = type(obj)
    return [name for name in dir(obj)
            if not name.startswith("_") and isinstance(getattr(cls, name, None), property)]


def _readable(statement, space):
    try:
        eval(statement, space)
    except Exception as exc:        # noqa: BLE001 -- reported, not timed
        return f"{type(exc).__name__}: {exc}"
    return None


def _timer(statement, space, calls):
    timer = timeit.Timer(statement, globals=space, timer=time.thread_time)

    def run():
        return timer.timeit(calls) / calls
    return run


def _gl_context():
    """An mjcffi EGL context made current, or (None, why not)."""
    try:
        from mjcffi.egl import GLContext
        context = GLContext(64, 64)
        context.make_current()
        return context, None
    except Exception as exc:        # noqa: BLE001 -- no EGL here: skip MjrContext
        return None, f"{type(exc).__name__}: {exc}"


def measure(rounds=9, calls=400):
    """{'rows': [(group, statement, mjcffi s, official s)], 'skipped': [(statement, why)],
    'ncon', 'nefc', 'gl': None or why MjrContext was skipped}."""
    context, no_gl = _gl_context()
    try:
        ours = _namespace(mjcffi, context is not None)
        theirs = _namespace(mujoco, context is not None)
        rows, skipped = [], []
        for group, expr, official in _objects(theirs):
            for name in _fields(official):
                statement = f"{expr}.{name}"
                why = _readable(statement, ours) or _readable(statement, theirs)
                if why is not None:
                    skipped.append((statement, why))
                    continue
                medians = interleaved({"mjcffi": _timer(statement, ours, calls),
                                       "official": _timer(statement, theirs, calls)}, rounds)
                rows.append((group, statement, medians["mjcffi"], medians["official"]))
        return {"rows": rows, "skipped": skipped, "ncon": int(ours["d"].ncon),
                "nefc": int(ours["d"].nefc), "gl": no_gl}
    finally:
        if context is not None:
            context.free()


def _fmt(seconds):
    return f"{seconds * 1e9:.0f} ns" if seconds < 1e-6 else f"{seconds * 1e6:.2f} µs"


def _geomean(values):
    return math.exp(statistics.fmean(math.log(v) for v in values)) if values else float("nan")


def run(rounds=9, calls=400):
    result = measure(rounds, calls)
    rows = result["rows"]
    ratio = {statement: a / b for _, statement, a, b in rows}
    times = {statement: (a, b) for _, statement, a, b in rows}
    over = [s for s in ratio if ratio[s] > 1.0]
    lines = [HEADING, "",
             f"Every public field of MjModel, MjData, MjOption, `d.contact`, `d.contact[0]`, "
             f"MjvScene and MjrContext, read as `obj.field` (`d.contact.field` and "
             f"`d.contact[0].field` in full), on gymnasium's humanoid after {STEPS} steps "
             f"(ncon = {result['ncon']}, nefc = {result['nefc']}) and a scene updated from it. "
             f"Median of {rounds} interleaved rounds of {calls} reads, timed in thread CPU time. "
             f"Targets: no field above 1.0, geometric mean at most 0.5, `d.contact.dist` and "
             f"`d.efc_force` at most 0.5.", ""]
    if result["gl"]:
        lines += [f"MjrContext skipped: no OpenGL context ({result['gl']}).", ""]
    lines += ["| group | fields | geometric mean | highest | above 1.0 |",
              "|---|---:|---:|---:|---:|"]
    groups = []
    for group, _, _, _ in rows:
        if group not in groups:
            groups.append(group)
    for group in groups + ["all"]:
        mine = [ratio[s] for g, s, _, _ in rows if group in (g, "all")]
        lines.append(f"| {group} | {len(mine)} | {_geomean(mine):.2f} | {max(mine):.2f} | "
                     f"{sum(r > 1.0 for r in mine)} |")
    worst = sorted(ratio, key=ratio.get, reverse=True)[:10]
    shown = worst + [s for s in NAMED if s in ratio and s not in worst]
    lines += ["", "The 10 highest ratios, then the reads issue 35 names:", "",
              "| read | mjcffi | official | ratio |", "|---|---:|---:|---:|"]
    for statement in shown:
        a, b = times[statement]
        lines.append(f"| `{statement}` | {_fmt(a)} | {_fmt(b)} | {ratio[statement]:.2f} |")
    lines += ["", f"**{len(rows)} fields; geometric mean {_geomean(list(ratio.values())):.2f}; "
              f"{len(over)} above 1.0.**"]
    if result["skipped"]:
        lines += ["", "Not timed (not readable on one side): " + ", ".join(
            f"`{s}` ({why})" for s, why in result["skipped"]) + "."]
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m benchmarks.bench_fields",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true",
                        help="replace (or append) this section in RESULTS.md")
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--calls", type=int, default=400)
    args = parser.parse_args(argv)
    lines = run(args.rounds, args.calls)
    print("\n".join(lines))
    if args.write:
        path = write_section(HEADING, lines)
        print(f"wrote the section into {path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
