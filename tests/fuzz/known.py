"""KNOWN_OPEN: findings whose fixes are under way, each with the issue item it belongs to.

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


_ITEM3 = "item 3 (corrupted pickles)"
_TYPES = "exception types (the documented set only)"

KNOWN_OPEN = [
    Known("load:*|assets|*", _TYPES + ": the MjModel loaders' `assets` that is not a dict "
          "(a list, a str, an int) raises AttributeError ('items'), not TypeError",
          "undocumented", "load:from_xml_string|assets|list"),
    Known("minimize:least_squares|*|2**1100", _TYPES + ": least_squares(eps=2**1100) "
          "(or mu_min) raises OverflowError from float()", "undocumented",
          "minimize:least_squares|eps|2**1100"),
    Known("fn:mjs_*|*|raw: *", "raw handles: mjs_setString/setDouble/appendString/... take "
          "any cffi pointer for their mjString*/mjDoubleVec*/... handle (MuJoCo's typedefs "
          "make them all void); another handle's type, or an mjData stack pointer, crashes "
          "(SIGSEGV/SIGABRT), or (mjs_getDouble) reads a garbage size: MemoryError",
          "crash|undocumented", "fn:mjs_setString|dest|raw: wrong handle type"),
    Known("fn:mjs_findElement|type|*", "ids: mjs_findElement(s, type, name) follows `type` "
          "unchecked (10**9, 2**31-1, 2**31 crash; mjs_firstElement has a check)", "crash",
          "fn:mjs_findElement|type|10**9"),
    Known("case:pickle:flip|-|mjb flip*", _ITEM3 + ": an MjModel pickle (MJB bytes) with "
          "byte 2881 xor 255 loads, then MjData(m) segfaults in mj_makeData", "crash",
          "case:pickle:flip|-|mjb flip@2881^255"),
    Known("case:pickle:flip|-|data stream flip*", _ITEM3 + ": an MjData pickle stream with "
          "one byte of its model's MJB changed (MJB offset 13766, 0x09 -> 0xf4) loads, then "
          "mj_forward segfaults or never returns", "crash|timeout",
          "case:pickle:flip|-|data stream flip@767424^253"),
    Known("case:load:corrupt|-|mjb flip*", "loaders: from_binary_path of an MJB with a "
          "flipped size (byte 456 xor 67) ends the process: 'ERROR: Could not allocate "
          "memory', exit 1 (mju_error outside a guard)", "crash",
          "case:load:corrupt|-|mjb flip@421292^67"),
    Known("cb:set_mjcb_*|callback|steps the same data", "item 5 (re-entry): a contactfilter "
          "callback that calls mj_step on the same data segfaults", "crash",
          "cb:set_mjcb_contactfilter|callback|steps the same data"),
    Known("cb:set_mjcb_*|callback|steps the same data", "item 5 (re-entry): a control or "
          "passive callback that calls mj_step on the same data recurses until "
          "RecursionError, instead of a documented error at the first re-entry",
          "undocumented", "cb:set_mjcb_control|callback|steps the same data"),
    Known("new:MjrContext|*|*", "FatalError out of C++: MjrContext(m, 100) without an "
          "OpenGL context raises FatalError, and a second MjrContext(m, ...) then aborts the "
          "process (libc++abi: __cxa_guard_acquire detected recursive initialization): the "
          "longjmp left a function-local static's guard taken", "crash",
          "new:MjrContext|-|valid ; new:MjrContext|-|valid"),
    Known("probe:mjr_context_twice|-|-", "FatalError out of C++: as new:MjrContext", "crash"),
    Known("load:from_xml_string|xml|huge hfield", "out of memory: a model whose XML asks "
          "for a 100000 x 100000 height field aborts the process (MuJoCo's compiler lets "
          "std::bad_alloc escape through the C API, under the fuzzer's 4 GB address-space "
          "cap; uncapped it swaps for minutes, and 65536 x 65536 overflows int and "
          "segfaults at once)", "crash"),
    Known("fn:mjs_makeFlex|count|*", "out of memory: mjs_makeFlex(count=[2**31-1]*3) aborts "
          "the process (std::bad_alloc out of C++; uncapped it grows by gigabytes a second)",
          "crash", "fn:mjs_makeFlex|count|ints 2**31-1"),
    Known("probe:two_threads_one_data|-|-", "threads: one MjData stepped from several Python "
          "threads at once segfaults (mj_step runs without the GIL, and nothing keeps two "
          "steps of one data apart)", "crash"),
    Known("case:lifetime:misuse|-|two threads step one data", "threads: as the probe "
          "two_threads_one_data", "crash"),
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
