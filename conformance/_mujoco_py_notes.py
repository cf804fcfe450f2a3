"""mujoco-py's own tests that no binding of MuJoCo 4 can pass, and why.

Each entry matches test ids ('file::test' or 'file::Class::test', fnmatch
patterns).  The runner skips these tests (they are not run: some delete
build files or sleep for 20 s) and the report lists them apart, outside the
pass rate.  Two kinds:
- tests of mujoco-py's own build and source tree, which the wheel does not
  ship and which mjcffi, a binding built once at install, has no counterpart of;
- tests of MJCF features that MuJoCo 4 removed or changed, and tests whose
  own model MuJoCo 4's parser or compiler refuses; these claims are checked
  against the official bindings by tests/test_conformance_mujoco_py.py.
"""

import fnmatch
from typing import NamedTuple


class NotApplicable(NamedTuple):
    patterns: tuple
    reason: str


_NCONMAX = (
    "The test needs a MuJoCo warning from stepping two spheres on a plane under "
    "`<size nconmax=\"1\"/>`; MuJoCo 4 still parses `nconmax` but no longer caps a "
    "step's contacts with it: the step makes 3 contacts and no warning (checked with the "
    "official bindings).")

NOT_APPLICABLE = (
    NotApplicable(("test_gen_wrappers.py::*",),
                  "The test runs `scripts/gen_wrappers.py` from mujoco-py's source tree "
                  "(not in the wheel) and compares its output with mujoco-py's Cython "
                  "`generated/wrappers.pxi`; mjcffi has no Cython wrappers and generates "
                  "its code with `python -m codegen`."),
    NotApplicable(("test_cymj.py::test_multiprocess",
                   "test_cymj.py::test_multiprocess_with_killing"),
                  "The test deletes mujoco-py's compiled Cython extension and its lock file, "
                  "then rebuilds it from several processes with `builder.load_cython_ext`; "
                  "mjcffi is compiled once, at install, and has no build at import."),
    NotApplicable(("test_examples.py::*",),
                  "The test runs the scripts in mujoco-py's `examples/` folder, which is in "
                  "mujoco-py's source tree but not in the wheel."),
    NotApplicable(("test_composite.py::*",),
                  "The test loads `<composite type=\"particle\">`; MuJoCo 4's parser has no "
                  "`<composite>` element at all (\"Schema violation: unrecognized element\", "
                  "checked with the official bindings)."),
    NotApplicable(("test_cymj.py::test_mj_warning_raises",
                   "test_cymj.py::test_ignore_mujoco_warnings"), _NCONMAX),
    NotApplicable(("test_pid.py::test_mj_proportional_only",),
                  "The test's reference model, `<position ... kp=200 .../>`, leaves an "
                  "attribute value unquoted, which MuJoCo 4's XML parser refuses "
                  "(XML_ERROR_PARSING_ATTRIBUTE, checked with the official bindings)."),
    NotApplicable(("test_pid.py::test_mjsize_exception",),
                  "The test expects `set_pid_control` to refuse an actuator with `user` values "
                  "under `nuser_actuator=\"0\"`; MuJoCo 4's compiler already refuses that model "
                  "(\"user has more values than nuser_actuator\", checked with the official "
                  "bindings), before the call the test checks."),
)


def classify(file, test):
    """The NotApplicable entry for test `test` of `file`, or None when it applies."""
    test_id = f"{file}::{test}"
    for note in NOT_APPLICABLE:
        if any(fnmatch.fnmatchcase(test_id, pattern) for pattern in note.patterns):
            return note
    return None


def skips(file):
    """[(test pattern, reason)] of `file`'s tests that are not applicable, for the skip plugin."""
    prefix = file + "::"
    return [(pattern[len(prefix):], "not applicable: " + note.reason)
            for note in NOT_APPLICABLE for pattern in note.patterns
            if pattern.startswith(prefix)]
