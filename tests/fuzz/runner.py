"""The parent side: calls run in batches in worker subprocesses; a crash is a signal.

A batch is a list of call keys run by one worker (worker.py), which reports
each call before and after it.  When the worker dies (a signal, an exit) or
stops answering for `timeout` seconds, the call under way is the suspect: it
is replayed alone in a fresh worker; if it does not crash alone, the batch's
calls before it are bisected (the shortest run of calls ending at the suspect
that still crashes, then each of those calls paired with the suspect), so that
every finding comes with the smallest sequence of calls found to trigger it.
The rest of the batch then runs in a new worker.

Workers run with MALLOC_PERTURB_ set (freed memory is overwritten, so a
use-after-free reads garbage) and faulthandler on (a crash prints the Python
stack, kept in the finding).
"""

import json
import os
import pathlib
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

from .known import match as known_match

ROOT = pathlib.Path(__file__).resolve().parents[2]

# Outcomes that are findings, besides a crash or a timeout.
FINDING_OUTCOMES = ("undocumented",)


class WorkerError(RuntimeError):
    """A worker died before its first call: the fuzzer's (or the import's) failure."""


@dataclass
class Result:
    key: str
    outcome: str            # ok, raised, na, setup, undocumented, crash, timeout
    etype: str = ""         # exception type, signal name, or exit status
    message: str = ""
    description: str = ""
    trigger: tuple = ()     # for a crash: the smallest sequence of keys found to crash
    stderr: str = ""

    @property
    def finding(self):
        return self.outcome in FINDING_OUTCOMES + ("crash", "timeout")


def worker_env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    env.setdefault("MALLOC_PERTURB_", "165")
    env["PYTHONFAULTHANDLER"] = "1"
    env.setdefault("MUJOCO_GL", "disable")
    return env


def _describe_status(rc):
    if rc is None:
        return "timeout"
    if rc < 0:
        try:
            return signal.Signals(-rc).name
        except ValueError:
            return f"signal {-rc}"
    return f"exit {rc}"


def run_batch(keys, timeout=20.0):
    """Run `keys` in one worker: (results by index, crash) where crash is None or
    (index or 'END', status text, stderr tail)."""
    with tempfile.TemporaryDirectory(prefix="mjcffi-fuzz-parent-") as tmp:
        keys_file = os.path.join(tmp, "keys.json")
        with open(keys_file, "w") as f:
            json.dump(list(keys), f)
        err_path = os.path.join(tmp, "stderr")
        read_fd, write_fd = os.pipe()
        with open(err_path, "wb") as err:
            proc = subprocess.Popen(
                [sys.executable, "-X", "faulthandler", "-m", "tests.fuzz.worker",
                 str(write_fd), keys_file],
                pass_fds=(write_fd,), stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                stderr=err, env=worker_env(), cwd=str(ROOT), start_new_session=True)
        os.close(write_fd)
        results, started, buffer, hung, heard = {}, None, b"", False, False
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
                        heard = True
                        started = _take(line.decode("utf-8", "replace"), results, started)
                    last = time.monotonic()
                elif time.monotonic() - last > timeout + (30 if started is None else 0):
                    hung = True                 # (the first call also pays the imports)
                    break
        if hung:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        rc = proc.wait()
        with open(err_path, "rb") as err:
            tail = err.read()[-3000:].decode("utf-8", "replace")
    crash = None
    if not heard and keys:
        raise WorkerError(f"the fuzz worker did not start ({_describe_status(rc)}):\n{tail}")
    if hung:
        crash = (started, "timeout", tail)
    elif rc != 0 or started is not None:
        crash = (started if started is not None else "END", _describe_status(rc), tail)
    return results, crash


def _take(line, results, started):
    """Record one line of the worker's report; return the call now under way."""
    parts = line.split("\t")
    if parts[0] == "S":
        return parts[1] if parts[1] == "END" else int(parts[1])
    if parts[0] == "R":
        if parts[1] == "END":
            return None
        i = int(parts[1])
        parts += [""] * (6 - len(parts))
        results[i] = tuple(parts[2:6])
        return None
    return started


def crashes(keys, timeout=20.0):
    """Whether running `keys` in one worker crashes (or hangs)."""
    _, crash = run_batch(keys, timeout)
    return crash is not None


def minimize(keys, index, timeout=20.0):
    """The smallest sequence of `keys[:index + 1]` found that still crashes, ending at
    keys[index]; () if even the whole sequence no longer crashes (a flaky crash)."""
    suspect = keys[index]
    if crashes([suspect], timeout):
        return (suspect,)
    before = list(keys[:index])
    if not crashes(before + [suspect], timeout):
        return ()
    lo, hi = 0, len(before)           # before[lo:] + suspect crashes; find the largest lo
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if crashes(before[mid:] + [suspect], timeout):
            lo = mid
        else:
            hi = mid
    first = before[lo]
    if crashes([first, suspect], timeout):
        return (first, suspect)
    return tuple(before[lo:]) + (suspect,)


def run_keys(keys, timeout=20.0, batch=200, on_result=None):
    """Run `keys` in batches, bisecting each crash; a list of Result, one per key."""
    keys = list(keys)
    out = []
    start = 0
    while start < len(keys):
        chunk = keys[start:start + batch]
        results, crash = run_batch(chunk, timeout)
        done = len(chunk) if crash is None or crash[0] == "END" else crash[0]
        for i in range(done):
            if i in results:
                outcome, etype, message, description = results[i]
                r = Result(chunk[i], outcome, etype, message, description)
            else:
                r = Result(chunk[i], "setup", "", "no report from the worker")
            out.append(r)
            if on_result:
                on_result(r)
        if crash is not None:
            index, status, tail = crash
            if index == "END":
                index = len(chunk) - 1
                trigger = minimize_exit(chunk, timeout)
                key = trigger[-1] if trigger else chunk[-1]
                r = Result(key, "crash", status, "at the worker's final collection",
                           key, trigger, tail)
                out.append(r)
                if on_result:
                    on_result(r)
                done = len(chunk)
            else:
                outcome = "timeout" if status == "timeout" else "crash"
                if known_match(chunk[index], outcome):   # replayed alone by the staleness check
                    trigger = (chunk[index],)
                else:
                    trigger = minimize(chunk, index, timeout)
                r = Result(chunk[index], outcome, status, "", chunk[index], trigger, tail)
                out.append(r)
                if on_result:
                    on_result(r)
                done = index + 1
        start += done
    return out


def minimize_exit(chunk, timeout):
    """For a crash after the batch's last call (the final collection): bisect the batch."""
    if not crashes(chunk, timeout):
        return ()
    calls = list(chunk)
    while len(calls) > 1:
        half = len(calls) // 2
        if crashes(calls[:half], timeout):
            calls = calls[:half]
        elif crashes(calls[half:], timeout):
            calls = calls[half:]
        else:
            break
    return tuple(calls)


def run_parallel(keys, jobs=None, timeout=20.0, batch=200, on_result=None):
    """run_keys over `jobs` workers at once; results in the order of `keys`."""
    jobs = jobs or max(1, os.cpu_count() or 1)
    keys = list(keys)
    size = max(1, min(batch, -(-len(keys) // jobs)))
    chunks = [keys[i:i + size] for i in range(0, len(keys), size)]
    lock = threading.Lock()

    def locked(r):
        if on_result:
            with lock:
                on_result(r)

    with ThreadPoolExecutor(jobs) as pool:
        parts = list(pool.map(lambda c: run_keys(c, timeout, size, locked), chunks))
    return [r for part in parts for r in part]
