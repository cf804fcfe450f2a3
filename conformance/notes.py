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


_PLUGIN_CONFIG = (
    "`MjsPlugin.config` is MuJoCo's `mjs_setPluginAttributes` / `mjs_getPluginAttributes`, "
    "which take and give a C++ `std::map<std::string, std::string>` behind a `void *`. "
    "Building or reading one needs C++ code compiled against MuJoCo's C++ standard library; "
    "mjcffi builds with a C compiler only, which is what lets it install where the official "
    "bindings' C++17 toolchain is missing. A plugin instance's config is set in MJCF "
    "(`<instance><config key=... value=.../></instance>`), which `MjSpec.from_string` parses.")

NOTES = (
    Note(("bindings_test.py::*::test_timer_installed_by_default",
          "bindings_test.py::*::test_mjcb_time_restore_default"), DELIBERATE,
         "mjcffi puts no timer in `mjcb_time` at import, and `set_mjcb_time(None)` clears it. "
         "MuJoCo's profiler calls the timer 32 times per step of a one-hinge pendulum: with a C "
         "timer such a step took 1.73-1.80x as long in two measurements (816 against 1412 ns, "
         "778 against 1401 ns), and 2-3 % longer on the humanoid. `mjcffi.install_timer()` "
         "installs a C timer in one call, with no GIL per call, for whoever wants `d.timer` "
         "filled."),
    Note(("bindings_test.py::*::test_array_keeps_struct_alive",), DELIBERATE,
         "The test counts references to the `.base` object that all of a model's views share in "
         "the official bindings. Each mjcffi view has a base of its own that keeps the model's "
         "memory alive by itself, so a view never depends on the wrapper or on other views; the "
         "part of the test that checks that the memory outlives the model passes."),
    Note(("specs_test.py::*::testPluginAssignment", "specs_test.py::*::test_plugin"),
         DELIBERATE, _PLUGIN_CONFIG),
    Note(("specs_test.py::*::test_kwarg",), DELIBERATE,
         "Every assertion passes but the last: `add_body(plugin=p)` followed by "
         "`body.plugin.info == 'info'`. The official keyword copies the plugin's `mjString` "
         "pointers into the body, so the body reads the plugin element's own string, and reads "
         "freed memory once that element is deleted. mjcffi copies the values instead (name, "
         "plugin name, active); MuJoCo makes no `info` string for a body's plugin, so it reads "
         "'' and refuses writes rather than sharing another element's memory."),
    Note(("render_test.py::ExternalGLContextLazyImportTest::*",), NOT_APPLICABLE,
         "These tests read `rendering/classic/gl_context.py` beside the imported package's "
         "`__init__.py`: a file of the official package's own layout."),
    Note(("render_test.py::EglDisplayTest::*",), NOT_APPLICABLE,
         "These tests check that `GLContext.__module__` is `mujoco.egl` and use that module's "
         "PyOpenGL internals (its `EGL_DISPLAY`, `_terminate_display`); mjcffi's EGL binding "
         "is cffi (mjcffi/rendering/_egl.py)."),
    Note(("egl_test.py::*",), NOT_APPLICABLE,
         "The tests load the official package's own `egl/__init__.py` by file path, with a fake "
         "PyOpenGL, to test its device selection; mjcffi's EGL binding (issue 12) is cffi, "
         "not PyOpenGL."),
)


def classify(file, test):
    """The Note for test `test` of `file` ('' for a file that cannot be collected), or None."""
    test_id = f"{file}::{test}"
    for note in NOTES:
        if any(fnmatch.fnmatchcase(test_id, pattern) for pattern in note.patterns):
            return note
    return None
