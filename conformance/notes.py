"""Why each remaining failure of the official tests fails: a gap, or a deliberate difference.

Each entry matches test ids ('file::Class::test', fnmatch patterns) and says
what kind of failure it is and why:
- GAP: mjcffi lacks something it should have; the reason says what, and
  which issue owns it.
- DELIBERATE: mjcffi differs on purpose, because its way is better for its
  users; the reason says why.
- NOT_APPLICABLE: the test checks the official package itself (its files,
  its private internals) and cannot pass for any other package.

A failure that no entry matches is reported as an unclassified gap.
"""

import fnmatch
from typing import NamedTuple

GAP = "gap"
DELIBERATE = "deliberate difference"
NOT_APPLICABLE = "not applicable"


class Note(NamedTuple):
    patterns: tuple
    kind: str
    reason: str


NOTES = (
)


def classify(file, test):
    """The Note for test `test` of `file`, or None."""
    test_id = f"{file}::{test}"
    for note in NOTES:
        if any(fnmatch.fnmatchcase(test_id, pattern) for pattern in note.patterns):
            return note
    return None
