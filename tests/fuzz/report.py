"""The fuzz report: calls by outcome, findings grouped by class with their triggers."""

import collections
import platform
import time

from .known import match as known_match


def finding_class(r):
    """'signal SIGSEGV', 'timeout', 'undocumented OverflowError', ..."""
    if r.outcome == "crash":
        return f"crash ({r.etype})"
    if r.outcome == "timeout":
        return "timeout"
    return f"undocumented {r.etype}"


def _by_label(items):
    """Findings of one class grouped by their variation (the key's last part) and
    message head: one root cause usually shows as one group."""
    out = collections.OrderedDict()
    for r in items:
        label = r.key.split("|")[-1]
        if r.key.startswith("case:"):
            label = r.key.split("|")[0] + "|" + label.split("@")[0]
        head = " ".join(r.message.split()[:3])
        out.setdefault((label, head), []).append(r)
    return out


def _stack(stderr):
    """The innermost Python frame of a faulthandler dump."""
    for line in (stderr or "").splitlines():
        line = line.strip()
        if line.startswith("File "):
            return line
    return ""


def summarize(results):
    counts = collections.Counter(r.outcome for r in results)
    findings = [r for r in results if r.finding]
    return counts, findings


def group(findings):
    """{(class, target, param-or-label-family): [Result, ...]} for the report, in key order."""
    out = collections.OrderedDict()
    for r in sorted(findings, key=lambda r: r.key):
        out.setdefault(finding_class(r), []).append(r)
    return out


def markdown(results, *, command, seed, elapsed, jobs):
    counts, findings = summarize(results)
    calls = sum(v for k, v in counts.items() if k not in ("na", "setup"))
    lines = [
        "# mjcffi fuzz report",
        "",
        f"- command: `{command}`",
        f"- seed: {seed}; {len(results)} keys, {calls} calls made "
        f"({counts.get('na', 0)} variations not applicable, "
        f"{counts.get('setup', 0)} not built)",
        f"- {elapsed:.0f} s on {jobs} workers; {time.strftime('%Y-%m-%d')}, "
        f"Python {platform.python_version()}",
        "",
        "| outcome | calls |",
        "| --- | ---: |",
    ]
    for outcome in ("ok", "raised", "undocumented", "crash", "timeout", "na", "setup"):
        if counts.get(outcome):
            lines.append(f"| {outcome} | {counts[outcome]} |")
    lines += ["", f"## Findings: {len(findings)}", ""]
    if not findings:
        lines.append("None.")
    for cls, items in group(findings).items():
        lines += ["", f"### {cls}: {len(items)}", ""]
        for label, same in _by_label(items).items():
            first = same[0]
            known = known_match(first.key, first.outcome)
            tag = f" — known: {known.item}" if known else ""
            more = f" (and {len(same) - 1} more with this variation)" if len(same) > 1 else ""
            lines.append(f"- `{first.key}`{tag}{more}")
            if first.description and first.description != first.key:
                lines.append(f"  - call: `{first.description}`")
            if first.message:
                lines.append(f"  - {first.message}")
            if first.outcome in ("crash", "timeout"):
                trig = " ; ".join(first.trigger) if first.trigger else "not reproduced alone"
                lines.append(f"  - minimal trigger: `{trig}`")
                replay = first.trigger[-1] if first.trigger else first.key
                lines.append(f"  - replay: `python -m tests.fuzz --replay '{replay}'`")
                stack = _stack(first.stderr)
                if stack:
                    lines.append(f"  - innermost frame: `{stack}`")
            if len(same) > 1:
                others = ", ".join(
                    f"`{r.key}`" + (" (known)" if known_match(r.key, r.outcome) else "")
                    for r in same[1:40])
                lines.append(f"  - also: {others}" + (" ..." if len(same) > 40 else ""))
    refused = [r for r in results if r.key.endswith("|-|valid") and r.outcome == "raised"
               and r.etype != "NotImplementedError"]
    if refused:
        lines += ["", "## Valid calls that raised (the fuzzer's limits, or regressions: "
                      "their variations test less)", ""]
        for r in sorted(refused, key=lambda r: r.key):
            lines.append(f"- `{r.key}`: {r.etype}: {r.message[:160]}")
    setups = [r for r in results if r.outcome == "setup"]
    if setups:
        lines += ["", "## Calls the fuzzer could not build (its own limits, not findings)", ""]
        by = collections.Counter((r.key.split("|")[0], r.etype, r.message[:80]) for r in setups)
        for (target, etype, message), n in sorted(by.items()):
            lines.append(f"- {target}: {n} × {etype}: {message}")
    return "\n".join(lines) + "\n"
