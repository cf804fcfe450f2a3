"""The subprocess that makes the calls: `python -m tests.fuzz.worker FD KEYS_FILE`.

For each key of the JSON list in KEYS_FILE it writes to file descriptor FD
`S <i>` before the call and `R <i> <outcome> <type> <message> <description>`
(tab-separated) after it, so that the parent knows which call was under way
when the process died of a signal, exited, or stopped answering.  `S END`
comes before the final collection and interpreter exit, `R END` after the
collection.  MuJoCo's own printing goes to this process's stdout.

Outcomes: ok; raised (an exception of the documented set, or of the entry
point's own documented exceptions); undocumented (any other exception: a
finding); na (the variation does not apply); setup (the fuzzer could not build
the call's valid arguments; the fuzzer's own problem, counted apart).
"""

import gc
import json
import os
import sys
import tempfile
import traceback


def _clean(text, limit=300):
    text = " ".join(str(text).split())
    return text[:limit]


def _reset_globals():
    """Undo what a call may have left process-wide: callbacks, handlers, warnings as errors."""
    import mjcffi
    from mjcffi._support import callbacks
    for name in ("passive", "control", "contactfilter", "sensor", "time", "act_dyn",
                 "act_gain", "act_bias"):
        try:
            getattr(mjcffi, f"set_mjcb_{name}")(None)
        except Exception:
            pass
    for name in ("warning", "malloc", "free"):
        try:
            getattr(mjcffi, f"set_mju_user_{name}")(None)
        except Exception:
            pass
    try:
        mjcffi.set_warnings_as_errors(False)
    except Exception:
        pass
    try:
        callbacks.raise_pending_callback_error()      # drop an error no call raised
    except BaseException:
        pass


class Runner:
    """Rebuilds calls from their keys and classifies what they do."""

    def __init__(self, workdir):
        from .target import documented
        self.workdir = workdir
        self.targets = {}
        self.documented = documented()
        self.warm = False

    def _warm_up(self):
        """Before the first real call: load everything once, then freeze it out of the
        collector, so that the collection after each call scans only what it made."""
        from . import env as envmod
        from . import registry
        self.warm = True
        envmod.write_files(self.workdir)
        self.targets = registry.targets_by_name()
        self.run("fn:mj_forward|-|valid")
        gc.collect()
        gc.freeze()

    def run(self, key):
        """(outcome, exception type, message, description) of the call named `key`."""
        from . import env as envmod
        from . import registry
        from .values import NotApplicable
        name, param, label = key.split("|", 2)
        if not self.warm and not name.startswith("case:selftest"):
            self._warm_up()
        target = self.targets.get(name) or registry.find(name)
        if target is None:
            return "setup", "KeyError", f"no target {name}", key
        env = envmod.Env(self.workdir)
        description = key
        try:
            try:
                thunk, description = target.make(param, label, env)
            except NotApplicable as exc:
                return "na", "", _clean(exc), key
            except Exception as exc:            # the fuzzer could not build the call
                return "setup", type(exc).__name__, _clean(_last_line(exc)), key
            try:
                thunk()
            except NotApplicable as exc:
                return "na", "", _clean(exc), description
            except BaseException as exc:        # noqa: B902 (SystemExit is a finding too)
                allowed = tuple(target.allowed) + thunk.keep.get("allowed", ())
                return self._classify(target, exc, allowed) + (description,)
            return "ok", "", "", description
        finally:
            if target.group != "function":
                _reset_globals()
            env.close()
            del env
            gc.collect()
            gc.freeze()             # what survives is the worker's (lazy imports, caches)

    def _classify(self, target, exc, allowed):
        message = _clean(_last_line(exc))
        if getattr(target, "foreign_ok", False) and not _through_mjcffi(exc):
            return "raised", type(exc).__name__, message        # pickle's own error
        if isinstance(exc, allowed):
            return "raised", type(exc).__name__, message
        if isinstance(exc, self.documented):
            binding = isinstance(exc, TypeError) and "argument" in str(exc)  # f(None) refused
            if _innermost_is_fuzzer(exc) and not isinstance(exc, self.documented[-1]) \
                    and not binding and not target.name.startswith("case:selftest"):
                # the fuzzer's own code failed (a pickle format it does not know, ...):
                # counted apart, so that it cannot pass for mjcffi refusing the call
                return "setup", type(exc).__name__, message
            return "raised", type(exc).__name__, message
        if _raised_by_fuzzer(exc):
            return "setup", type(exc).__name__, message
        return "undocumented", _qualname(exc), message


_FUZZ_DIR = os.path.dirname(os.path.abspath(__file__))


def _innermost_is_fuzzer(exc):
    """Whether the innermost Python frame of the exception is the fuzzer's own code."""
    tb = exc.__traceback__
    last = None
    while tb is not None:
        last = tb.tb_frame.f_code.co_filename
        tb = tb.tb_next
    return last is not None and os.path.dirname(os.path.abspath(last)) == _FUZZ_DIR


def _raised_by_fuzzer(exc):
    """An AttributeError or NameError whose innermost Python frame is the fuzzer's own
    code: a bug of the fuzzer, not a finding.  (A TypeError there is usually a call into
    C refusing its arguments, which is what the fuzzer is after.)"""
    if not isinstance(exc, (AttributeError, NameError)):
        return False
    if type(exc).__module__.startswith("mjcffi"):
        return False
    return _innermost_is_fuzzer(exc)


_MJCFFI_DIR = os.path.join(os.path.dirname(os.path.dirname(_FUZZ_DIR)), "mjcffi")


def _through_mjcffi(exc):
    """Whether mjcffi's code is on the exception's traceback."""
    tb = exc.__traceback__
    while tb is not None:
        if os.path.abspath(tb.tb_frame.f_code.co_filename).startswith(_MJCFFI_DIR):
            return True
        tb = tb.tb_next
    return False


def _die_with_parent():
    """Linux: end this worker when the fuzzer that started it ends."""
    try:
        import ctypes
        import signal
        ctypes.CDLL(None).prctl(1, int(signal.SIGKILL))      # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def limit_memory():
    """Cap this process's address space (MJCFFI_FUZZ_MEMORY_GB, default 4), so that a
    call asking for terabytes fails at once, the same way on every machine, instead of
    swapping until a timeout or the OOM killer."""
    import resource
    gb = float(os.environ.get("MJCFFI_FUZZ_MEMORY_GB", "4"))
    if gb > 0:
        limit = int(gb * (1 << 30))
        try:
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        except (ValueError, OSError):
            pass


def _qualname(exc):
    cls = type(exc)
    module = cls.__module__
    return cls.__name__ if module in ("builtins", "__main__") else f"{module}.{cls.__name__}"


def _last_line(exc):
    text = "".join(traceback.format_exception_only(type(exc), exc)).strip()
    return text.split("\n")[-1] if text else type(exc).__name__


def main(argv):
    _die_with_parent()
    limit_memory()
    fd = int(argv[1])
    with open(argv[2]) as f:
        keys = json.load(f)
    out = os.fdopen(fd, "w", buffering=1, encoding="utf-8", errors="backslashreplace")
    with tempfile.TemporaryDirectory(prefix="mjcffi-fuzz-") as workdir:
        os.chdir(workdir)
        runner = Runner(workdir)
        for i, key in enumerate(keys):
            out.write(f"S\t{i}\n")
            out.flush()
            try:
                outcome, etype, message, description = runner.run(key)
            except Exception as exc:        # the fuzzer's own failure (an import mid-edit)
                outcome, etype, message, description = (
                    "setup", type(exc).__name__, _clean(_last_line(exc)), key)
            out.write("\t".join(["R", str(i), outcome, etype, message.replace("\t", " "),
                                 _clean(description, 400)]) + "\n")
            out.flush()
        out.write("S\tEND\n")
        out.flush()
        runner = None
        gc.collect()
        out.write("R\tEND\n")
        out.flush()
        os.chdir("/")


if __name__ == "__main__":
    main(sys.argv)
