"""python -m conformance mjx [--models NAME ...] [--steps N] [--write]: MJX on mjcffi.

MJX (the mujoco-mjx package, JAX) reads MjModel and MjData through the official
bindings' classes: `mjx.put_model`, `mjx.put_data` and `mjx.get_data_into`.  This
runs the same script twice, each in its own process: once on the official bindings
(`import mujoco`), once under the swap (`sys.modules['mujoco'] = mjcffi`, so that
`from mujoco import mjx` is mjcffi.mjx, the official MJX source on mjcffi).  For each
of a few of gymnasium's models it

1. loads the model and an MjData (controls set, mj_forward), and puts both on the
   device: every leaf of the mjx.Model and mjx.Data;
2. runs `jax.jit(mjx.step)` N times: every leaf of the final mjx.Data;
3. copies the result back with `mjx.get_data_into` into a fresh MjData: every field;

and saves them.  The parent process compares them bit for bit (dtype, shape, bytes).
Both processes share JAX's persistent compilation cache, so the second one compiles
nothing when both traced the same program.  `--write` writes the MJX section of
CONFORMANCE.md.  Needs jax and mujoco-mjx: pip install 'mjcffi[mjx]'.
"""

import argparse
import importlib.util
import json
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

TITLE = "# MJX on mjcffi's objects"
MODELS = ("hopper", "half_cheetah", "walker2d", "ant")
STEPS = 100
MISSING = ("MJX needs jax and mujoco-mjx, which are not installed: pip install 'mjcffi[mjx]'")


def available():
    """'' when jax and mujoco-mjx are installed; else what is missing."""
    from .runner import official_dir
    if importlib.util.find_spec("jax") is None or not (official_dir() / "mjx").is_dir():
        return MISSING
    return ""


def model_path(name):
    """gymnasium's MJCF file of model `name` (hopper, ...), read where pip put it."""
    spec = importlib.util.find_spec("gymnasium")
    if spec is None:
        raise RuntimeError("gymnasium is not installed: pip install gymnasium")
    path = pathlib.Path(spec.origin).parent / "envs" / "mujoco" / "assets" / f"{name}.xml"
    if not path.exists():
        raise RuntimeError(f"gymnasium has no model {name!r} ({path})")
    return path


# ------------------------------------------------------------------ the child

def _leaves(prefix, tree, out):
    """Every field of MJX's dataclass `tree`, the device arrays (the pytree's leaves)
    and the static ones (host arrays, counts, enums) alike, as NumPy arrays under
    `prefix.<path>`."""
    import dataclasses
    if dataclasses.is_dataclass(tree) and not isinstance(tree, type):
        for field in dataclasses.fields(tree):
            _leaves(f"{prefix}.{field.name}", getattr(tree, field.name), out)
    elif isinstance(tree, (list, tuple)):
        for i, item in enumerate(tree):
            _leaves(f"{prefix}[{i}]", item, out)
    elif isinstance(tree, dict):
        for key in sorted(tree):
            _leaves(f"{prefix}[{key!r}]", tree[key], out)
    elif tree is None:
        out[f"{prefix}#None"] = np.zeros(0)
    elif isinstance(tree, (bytes, str)):
        out[prefix] = np.frombuffer(tree.encode() if isinstance(tree, str) else tree,
                                    dtype=np.uint8)
    else:
        out[prefix] = np.asarray(getattr(tree, "value", tree))     # enums by value


# efc_J's sparse structure: MuJoCo fills it only for a sparse Jacobian
_SPARSE_ONLY = ("efc_J_rownnz", "efc_J_rowadr", "efc_J_rowsuper", "efc_J_colind")


def _left_alone(mjx, m):
    """The MjData arrays in the arena that `mjx.get_data_into` lays out but does not
    fill (contact.H, efc_R, ...): they hold whatever the arena held, in either binding."""
    from mjcffi._generated.structinfo import STRUCTS
    from mjcffi._support.official_pickle import ARENA
    from mujoco.mjx._src import support, types
    written = {f.name for f in types.Data.fields() + types.DataJAX.fields()}
    if support.is_sparse(m):
        written |= {"efc_J_rownnz", "efc_J_rowadr", "efc_J_colind"}
    contact = {f.name for f in types.Contact.fields()}
    left = {f"contact.{f.name}" for f in STRUCTS["mjContact"] if f.name not in contact}
    left |= {name for name in ARENA["SOLVER"] if name not in written}
    return left


def _data_fields(d, out, prefix="mjdata", left=()):
    """Every field of MjData `d` whose value is numbers (contact and the statistics
    field by field) but those of `left`, under `<prefix>/<name>`."""
    from mjcffi._generated.structinfo import STRUCTS
    records = {"contact": "mjContact", "solver": "mjSolverStat", "timer": "mjTimerStat",
               "warning": "mjWarningStat"}
    for field in STRUCTS["mjData"]:
        if field.name == "timer" or field.name in left:
            continue                # timings: mjcffi installs no timer (CONFORMANCE.md)
        if field.name in records:
            rows = getattr(d, field.name)
            for inner in STRUCTS[records[field.name]]:
                if f"{field.name}.{inner.name}" not in left:
                    out[f"{prefix}/{field.name}.{inner.name}"] = \
                        np.asarray(getattr(rows, inner.name))
        elif field.kind == "pointer" and field.elem == "void":
            continue                            # an address (buffer, arena, threadpool)
        else:
            try:
                value = getattr(d, field.name)
            except AttributeError:
                continue                        # a field the binding does not show
            out[f"{prefix}/{field.name}"] = np.asarray(value)


def child(target, models, steps, out_dir, cache):
    """Run the check on `target` ('official' or 'mjcffi'), saving to `out_dir`."""
    if target == "mjcffi":
        import mjcffi
        sys.modules["mujoco"] = mjcffi
    import jax
    jax.config.update("jax_compilation_cache_dir", cache)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0)
    import mujoco
    from mujoco import mjx

    times = {}
    for name in models:
        out, started = {}, time.perf_counter()
        m = mujoco.MjModel.from_xml_path(str(model_path(name)))
        d = mujoco.MjData(m)
        d.ctrl[:] = 0.5 * np.sin(np.arange(1, m.nu + 1))
        mujoco.mj_forward(m, d)
        mx, dx = mjx.put_model(m), mjx.put_data(m, d)
        _leaves("model", mx, out)
        _leaves("data0", dx, out)
        put = time.perf_counter()
        step = jax.jit(mjx.step)
        dx = jax.block_until_ready(step(mx, dx))
        compiled = time.perf_counter()
        for _ in range(steps - 1):
            dx = step(mx, dx)
        dx = jax.block_until_ready(dx)
        stepped = time.perf_counter()
        _leaves(f"data{steps}", dx, out)
        result = mujoco.MjData(m)
        mjx.get_data_into(result, m, dx)
        left = _left_alone(mjx, m)
        _data_fields(result, out, "mjdata", left)
        out["#left alone"] = np.frombuffer(" ".join(sorted(left)).encode(), dtype=np.uint8)
        mujoco.mj_forward(m, result)        # the state it holds, carried on by MuJoCo
        from mujoco.mjx._src import support
        sparse_only = () if support.is_sparse(m) else _SPARSE_ONLY
        _data_fields(result, out, "forward", sparse_only)
        done = time.perf_counter()
        np.savez(pathlib.Path(out_dir) / f"{name}.npz", **out)
        times[name] = {"put": put - started, "first step (compile)": compiled - put,
                       f"{steps - 1} steps": stepped - compiled,
                       "get_data_into": done - stepped, "total": done - started,
                       "nq": int(m.nq), "nv": int(m.nv), "nu": int(m.nu)}
    official = [n for n, mod in sys.modules.items() if n.startswith("mujoco._")
                and (getattr(mod, "__file__", None) or "").endswith(".so")]
    times["#official compiled modules"] = sorted(official)
    (pathlib.Path(out_dir) / "times.json").write_text(json.dumps(times))


# ------------------------------------------------------------------ the parent

def _compare(ours, theirs):
    """(keys compared, [(key, why)] that differ), per group of keys."""
    groups = {}
    for key in sorted(set(ours) | set(theirs)):
        group = key.split("/", 1)[0].split("[", 1)[0].split("#", 1)[0].split(".", 1)[0]
        count, diffs = groups.setdefault(group, [0, []])
        groups[group][0] = count + 1
        if key not in theirs and group in ("mjdata", "forward"):
            groups[group][0] -= 1
            continue                # a field the official MjData does not show (threadlock)
        if key not in ours or key not in theirs:
            diffs.append((key, "only under " + ("the official" if key in theirs else "mjcffi")))
            continue
        a, b = ours[key], theirs[key]
        if a.dtype != b.dtype or a.shape != b.shape:
            diffs.append((key, f"{a.dtype}{a.shape} against {b.dtype}{b.shape}"))
        elif a.tobytes() != b.tobytes():
            diffs.append((key, "different values"))
    return groups


def run(models=MODELS, steps=STEPS, timeout=1800):
    """{target: times} and {model: groups} (see _compare), running both children."""
    with tempfile.TemporaryDirectory(prefix="conformance-mjx-") as folder:
        folder = pathlib.Path(folder)
        cache = folder / "jax-cache"
        times = {}
        for target in ("official", "mjcffi"):
            out = folder / target
            out.mkdir()
            command = [sys.executable, "-m", "conformance.mjx", "--child", target,
                       "--out", str(out), "--cache", str(cache), "--steps", str(steps),
                       "--models", *models]
            started = time.perf_counter()
            done = subprocess.run(command, capture_output=True, text=True, timeout=timeout,
                                  cwd=pathlib.Path(__file__).resolve().parent.parent)
            if done.returncode:
                raise RuntimeError(f"the {target} run failed ({done.returncode}):\n"
                                   f"{(done.stdout + done.stderr)[-3000:]}")
            times[target] = json.loads((out / "times.json").read_text())
            times[target]["#seconds"] = time.perf_counter() - started
        results = {}
        for name in models:
            with np.load(folder / "mjcffi" / f"{name}.npz") as ours, \
                    np.load(folder / "official" / f"{name}.npz") as theirs:
                results[name] = _compare(dict(ours), dict(theirs))
    return times, results


_GROUPS = (("model", "mjx.put_model leaves"), ("data0", "mjx.put_data leaves"),
           (None, "mjx.Data leaves after the steps"),
           ("mjdata", "MjData fields after mjx.get_data_into"),
           ("forward", "MjData fields after get_data_into and mj_forward"))


def render(times, results, steps):
    from mjcffi._support.machine import environment
    lines = [TITLE, "",
             "Written by `python -m conformance mjx --write` (conformance/mjx.py). MJX "
             "(mujoco-mjx, on JAX's CPU backend) runs on gymnasium's models twice, each in "
             "its own process: on the official bindings' objects, and on mjcffi's under "
             "`sys.modules['mujoco'] = mjcffi`, where `from mujoco import mjx` is "
             "mjcffi.mjx, the official MJX source run on mjcffi. Each run puts the model "
             "and its data on the device (`mjx.put_model`, `mjx.put_data`), runs "
             f"`jax.jit(mjx.step)` {steps} times, and copies the result into a fresh MjData "
             "with `mjx.get_data_into`. Every leaf and every MjData field is compared bit "
             "for bit (dtype, shape, bytes): the leaves and static fields of MJX's Model and "
             "Data; the MjData's fields after get_data_into, but for the arena arrays it "
             "lays out and leaves unfilled (contact.H, efc_R, ...: what the arena held "
             "before, in either binding); and every field again after `mj_forward` on "
             "that MjData. The timer is left out: mjcffi installs no timer callback by "
             "default (see above).", ""]
    lines += environment(("mjcffi", "mujoco-core", "mujoco-mjx", "jax", "jaxlib",
                          "numpy")) + [""]
    lines += ["| model | nq, nv, nu | " + " | ".join(label for _, label in _GROUPS)
              + " | mjcffi run (s) |", "|---|---|" + "---:|" * (len(_GROUPS) + 1)]
    differences = []
    for name, groups in results.items():
        cells = []
        for key, _ in _GROUPS:
            key = key or f"data{steps}"
            count, diffs = groups.get(key, [0, []])
            cells.append(f"{count - len(diffs)} of {count} identical")
            differences += [f"- {name}: `{k}`: {why}" for k, why in diffs]
        info = times["mjcffi"][name]
        lines.append(f"| {name} | {info['nq']}, {info['nv']}, {info['nu']} | "
                     + " | ".join(cells) + f" | {info['total']:.1f} |")
    lines += [""]
    official = times["mjcffi"].get("#official compiled modules")
    lines += [f"Official compiled modules imported in the mjcffi run: "
              f"{', '.join(official) if official else 'none'}.",
              f"Whole runs, with JAX's compilation (the second reuses the first's "
              f"compiled programs from the persistent cache where they are the same): "
              f"official {times['official']['#seconds']:.0f} s, "
              f"mjcffi {times['mjcffi']['#seconds']:.0f} s.", ""]
    lines += (["Differences:", ""] + differences) if differences else \
        ["No differences: every leaf and field is bit-identical."]
    return "\n".join(lines).rstrip("\n") + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m conformance mjx",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--models", nargs="+", default=list(MODELS),
                        help=f"gymnasium model names (default: {' '.join(MODELS)})")
    parser.add_argument("--steps", type=int, default=STEPS)
    parser.add_argument("--write", action="store_true",
                        help="write the MJX section of CONFORMANCE.md")
    parser.add_argument("--child", choices=("official", "mjcffi"), help=argparse.SUPPRESS)
    parser.add_argument("--out", help=argparse.SUPPRESS)
    parser.add_argument("--cache", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.child, args.models, args.steps, args.out, args.cache)
        return 0
    missing = available()
    if missing:
        print(missing, file=sys.stderr)
        return 2
    times, results = run(args.models, args.steps)
    text = render(times, results, args.steps)
    if args.write:
        from . import _mujoco_py_report
        from .report import CONFORMANCE
        text_now = CONFORMANCE.read_text() if CONFORMANCE.exists() else ""
        CONFORMANCE.write_text(_mujoco_py_report.replace_section(text_now, text, TITLE))
        print(f"wrote {CONFORMANCE}", file=sys.stderr)
    print(text)
    same = all(not diffs for groups in results.values() for _, diffs in groups.values())
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
