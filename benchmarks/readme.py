"""The speed figures of the README and the docs, written from RESULTS.md so that they
cannot disagree.

The README holds the headline block between marker comments, and two pages of the
documentation (docs/) one block each; `update` rewrites a file's blocks from the text
of RESULTS.md, and `python -m benchmarks.compare --write` calls `write` after
writing RESULTS.md.  tests/test_readme_figures.py checks that each committed file
equals what `update` makes of the committed RESULTS.md.
"""

import pathlib
import re
import textwrap

REPO = pathlib.Path(__file__).resolve().parent.parent
README = REPO / "README.md"

_BLOCKS = ("headline", "per-call cost", "spec speed")

# Each file that quotes RESULTS.md -> (its blocks, the link to RESULTS.md from there).
FILES = {README: (("headline",), "benchmarks/RESULTS.md"),
         REPO / "docs" / "drop-in.md": (("per-call cost",), "results.md"),
         REPO / "docs" / "mjspec.md": (("spec speed",), "results.md")}


def _marks(block):
    return (f"<!-- {block}: written from benchmarks/RESULTS.md by "
            f"python -m benchmarks.compare --write -->", f"<!-- end of {block} -->")


# ----------------------------------------------------------------- reading

def _rows(results):
    """The cells of every table row of RESULTS.md, in order."""
    rows = []
    for line in results.splitlines():
        if line.startswith("| ") and not set(line) <= set("|-: "):
            rows.append([cell.strip() for cell in line.strip().strip("|").split("|")])
    return rows


def _row(rows, label):
    """The first row whose first cell is `label`."""
    for cells in rows:
        if cells[0] == label:
            return cells
    raise ValueError(f"RESULTS.md has no row {label!r}")


def _float(text):
    return float(re.sub(r"[^0-9.\-]", "", text.replace(",", "")))


def figures(results):
    """The figures the README quotes, read from the text of RESULTS.md."""
    rows = _rows(results)
    date = re.search(r"^- date: (\S+)", results, re.M)
    humanoid = [cells for cells in rows if cells[0] == "humanoid"]
    rollout = [_float(cells[-1]) for cells in humanoid if cells[1] == "16 × 50"]
    batch = [_float(cells[6]) for cells in humanoid if len(cells) == 8]
    step0 = _row(rows, "`mj_step(m, d, 0)`: the call alone, no physics (target ≤ 0.8)")
    return {
        "date": date.group(1) if date else "(no date)",
        "import_ms": _float(_row(rows, "`import mjcffi`")[1]),
        "import_official_ms": _float(_row(rows, "`import mujoco` (official)")[1]),
        "import_ratio": _float(_row(rows, "`import mjcffi`")[2]),
        "qpos": _float(_row(rows, "`d.qpos`")[3]),
        "named": _float(_row(rows, "`d.joint('hinge').qpos`")[3]),
        "make_data": _float(_row(rows, "`MjData(m)`")[3]),
        "fields": _row(rows, "all"),       # the field reads: all, count, mean, highest, above
        "loops": sorted(rollout + batch),
        "short_rollout": _float([c for c in rows if c[0] == "pendulum, short (per-call cost)"
                                 and c[2] == "2"][0][-1]),
        "scaling": _row(rows, "1 → 2")[1],
        "step0_ratio": _float(step0[3]),
        "step0_extra_ns": _float(step0[1]) - _float(step0[2]),
        "pendulum_step": _float(_row(rows, "`mj_step(m, d)`, one-hinge pendulum")[3]),
        "default_step": _float(_row(rows, "`mj_step(m, d)`, default scene")[3]),
        "spec_build": _float(_row(rows, "`build(module).compile()`")[3]),
        "spec_attrs": sorted(_float(_row(rows, f"`{s}`")[3]) for s in _SPEC_ATTRIBUTES),
        "spec_name": _float(_row(rows, "`g.name`")[3]),
        "calls_plain": _float(_row(rows, "plain calls: geometric mean of the ratios")[1]),
        "calls_plain_max": _float(_row(rows, "plain calls: highest ratio")[1]),
        "calls_floor": _float(_row(rows, "floor (no checks): geometric mean of the ratios")[1]),
        "calls_prepared": _float(_row(rows, "prepared calls taking arrays: geometric mean")[1]),
        "calls_prepared_max": _float(_row(rows, "prepared calls taking arrays: highest ratio")[1]),
        "name2id": _float(_row(rows, "`mj_name2id(m, 1, 'b2')`")[6]),
        "jac_plain": _float(_row(rows, "`mj_jac(m, d, jacp, jacr, pt, 1)`")[6]),
        "jac_prepared": _float(_row(rows, "`mj_jac(m, d, jacp, jacr, pt, 1)`")[7]),
    }


# the element attribute rows of bench_spec that the README sums up
_SPEC_ATTRIBUTES = ("g.size", "g.size = size", "b.pos[2] = 0.3", "g.type", "b.userdata")


# ----------------------------------------------------------------- writing

def _bullet(text, depth=0):
    """One Markdown bullet, wrapped as the README's prose is."""
    indent = "  " * depth
    return textwrap.fill(text, 96, initial_indent=indent + "- ",
                         subsequent_indent=indent + "  ", break_on_hyphens=False)


def _percent(ratio):
    return f"{round(100 * (ratio - 1))} %"


def headline(f):
    low, high = f["loops"][0], f["loops"][-1]
    fields = f["fields"]
    return "\n".join([
        textwrap.fill(f"Measured on {f['date']} ([benchmarks/RESULTS.md]({f['link']}); "
                      f"ratios are mjcffi / official, in one process):", 96),
        _bullet(f"**Imports in milliseconds**: `import mjcffi` took {f['import_ms']:.1f} ms, "
                f"against {f['import_official_ms']:.1f} ms for `import mujoco` "
                f"({f['import_ratio']:.2f}×)."),
        _bullet(f"**Cheap structs.** `d.qpos` reads in {f['qpos']:.2f}× the official time, "
                f"`d.joint('hinge').qpos` in {f['named']:.2f}×, and `MjData(m)` is built in "
                f"{f['make_data']:.2f}×, because views are made when first used rather than "
                f"all at once."),
        _bullet(f"Of the {fields[1]} public fields of MjModel, MjData, MjOption, the contacts, "
                f"MjvScene and MjrContext, {fields[4]} read slower than the official's "
                f"(geometric mean {fields[2]}×, highest {fields[3]}×), the contact and "
                f"constraint arrays included: scalars and the views of moving memory are "
                f"read in C.", 1),
        _bullet("**Native hot loops.** `mjcffi.rollout` and `mjcffi.batch.Batch` run their "
                "loops in C with the GIL released."),
        _bullet(f"On the humanoid, where physics dominates, they match the official ones: "
                f"time ratios of {low:.2f}–{high:.2f} at 1 and 2 threads, the spread being "
                f"this shared machine's noise.", 1),
        _bullet(f"They are faster where the call itself dominates: {f['short_rollout']:.2f} "
                f"on short rollouts with 2 threads.", 1),
        _bullet(f"The humanoid rollout scales {f['scaling']} from 1 to 2 threads.", 1),
        _bullet(f"**Function calls: slower plain, faster prepared.** Over 16 common calls, a "
                f"plain call costs {f['calls_plain']:.2f}× the official one (geometric mean; "
                f"up to {f['calls_plain_max']:.2f}×, `mj_jac` {f['jac_plain']:.2f}×). The "
                f"guarded cffi call alone, with a `from_buffer` per array and no check, "
                f"already costs {f['calls_floor']:.2f}×; mjcffi's checks of each array "
                f"(class, dtype, shape, layout), of ids and of the model/data pair add the "
                f"rest. A prepared call (`p = mjcffi.mj_jac.prepare(...)`, then `p()`) of a "
                f"function that takes arrays costs {f['calls_prepared']:.2f}× the official "
                f"call (up to {f['calls_prepared_max']:.2f}×; `mj_jac` "
                f"{f['jac_prepared']:.2f}×), and a repeated `mj_name2id` {f['name2id']:.2f}×."),
    ])


def per_call(f):
    return "\n".join([_bullet(
        f"**Per-call cost.** `mj_step(m, d, 0)`, which runs no physics and so measures the "
        f"call alone, took {f['step0_ratio']:.2f}× as long as the official call "
        f"({f['date']}): {f['step0_extra_ns']:.0f} ns more. Part of it is the guard that "
        f"turns `mju_error` into FatalError and the claim that keeps one call per MjData "
        f"(about 20 ns), and part is that a Python function around a cffi "
        f"call cannot be as cheap as one pybind11 call. On a one-hinge pendulum this made a "
        f"step {_percent(f['pendulum_step'])} slower, and {_percent(f['default_step'])} on "
        f"the default scene. Use `nstep` to loop in C."), _bullet(
        f"**Plain function calls** cost {f['calls_plain']:.2f}× the official ones (geometric "
        f"mean of 16 common calls, up to {f['calls_plain_max']:.2f}×). The guarded cffi call "
        f"with a `from_buffer` per array and no check already costs {f['calls_floor']:.2f}×; "
        f"the checks of exact arrays (class, dtype, shape, layout) and of ids add the rest. "
        f"In a loop that repeats a call, prepare it: {f['calls_prepared']:.2f}× for the "
        f"calls that take arrays (up to {f['calls_prepared_max']:.2f}×).")])


def spec_speed(f):
    low, high = f["spec_attrs"][0], f["spec_attrs"][-1]
    return _bullet(
        f"**Speed.** Building a 100-body tree with keyword `add_*` calls and compiling it "
        f"took {f['spec_build']:.2f}× the official time ({f['date']}); element attribute "
        f"reads and writes {low:.2f}–{high:.2f}×, a name read {f['spec_name']:.2f}× "
        f"([benchmarks/RESULTS.md]({f['link']})).")


_WRITERS = {"headline": headline, "per-call cost": per_call, "spec speed": spec_speed}


def update(readme, results, blocks=FILES[README][0], link="benchmarks/RESULTS.md"):
    """The text of a file with its figure `blocks` written from the RESULTS.md text,
    `link` being the path to RESULTS.md from that file."""
    f = dict(figures(results), link=link)
    for block in blocks:
        start, end = _marks(block)
        pattern = re.compile(re.escape(start) + r"\n.*?\n" + re.escape(end), re.S)
        if not pattern.search(readme):
            raise ValueError(f"the text has no {block!r} block between its markers")
        readme = pattern.sub(lambda _: f"{start}\n{_WRITERS[block](f)}\n{end}", readme)
    return readme


def write(results_path):
    """Rewrite every file's figure blocks from the RESULTS.md at `results_path`."""
    results = pathlib.Path(results_path).read_text()
    for path, (blocks, link) in FILES.items():
        path.write_text(update(path.read_text(), results, blocks, link))
