"""KNOWN_OPEN: findings whose fixes are under way, each with the issue item it belongs
to, and MuJoCo's own limits that no binding can catch (out of memory inside
MuJoCo's C++ compiler: the official binding ends the same way), which docs/reliability.md
names as outside the promise.

While an entry is here, tests/test_fuzz.py accepts its finding, so that CI stays
green while the fix lands.  The table cannot go stale: the test replays every
entry's witness and fails when it no longer fails ("fixed: remove the entry").
Remove an entry as soon as its fix arrives.

An entry: `pattern` (a call key `target|param|label`, where a segment `*` matches
any value and a segment ending in `*` matches by prefix), the item it
belongs to, the outcome it shows ('crash', 'timeout' or 'undocumented', or
alternatives such as 'crash|timeout'), and a
`witness` (a key the pattern matches, or `a ; b` for a sequence whose last key it
matches; the pattern itself when it has no wildcard), which the staleness check
replays in one fresh worker.
"""

from typing import NamedTuple


class Known(NamedTuple):
    pattern: str
    item: str
    outcome: str
    witness: str = ""

    @property
    def outcomes(self):
        """The outcomes it may show: `crash|timeout` where a fix in progress moves it."""
        return tuple(self.outcome.split("|"))

    @property
    def replay(self):
        """The keys to replay, in order, in one worker (`a ; b` in `witness`)."""
        return (self.witness or self.pattern).split(" ; ")


_OOM = "MuJoCo's limit, outside the promise (docs/reliability.md): out of memory"

KNOWN_OPEN = [
    Known("load:from_xml_string|xml|huge hfield", _OOM + ": a model whose XML asks "
          "for a 100000 x 100000 height field aborts the process (MuJoCo's compiler lets "
          "std::bad_alloc escape through the C API, under the fuzzer's 4 GB address-space "
          "cap; uncapped it swaps for minutes, and 65536 x 65536 overflows int and "
          "segfaults at once)", "crash"),
    Known("fn:mjs_makeFlex|count|*", _OOM + ": mjs_makeFlex(count=[2**31-1]*3) aborts "
          "the process (std::bad_alloc out of C++; uncapped it grows by gigabytes a second)",
          "crash", "fn:mjs_makeFlex|count|ints 2**31-1"),
]


def _segment(pattern, value):
    if pattern == "*" or pattern == value:
        return True
    return pattern.endswith("*") and value.startswith(pattern[:-1])


def matches(pattern, key):
    parts, values = pattern.split("|", 2), key.split("|", 2)
    return len(parts) == len(values) and all(map(_segment, parts, values))


def match(key, outcome=None):
    """The KNOWN_OPEN entry that covers `key` (showing `outcome`, when given), or None:
    a crash under a pattern known for an undocumented exception is a new finding."""
    for entry in KNOWN_OPEN:
        if matches(entry.pattern, key) and (outcome is None or outcome in entry.outcomes):
            return entry
    return None
