"""Notebook display: MjModel, MjSpec and TuneResult answer IPython's display protocol
(`_repr_html_`, `_repr_markdown_`) with escaped, bounded HTML, never raise, and cost
`import mjcffi` nothing (mjcffi/_support/display.py is imported on first display)."""

import base64
import copy
import html.parser
import os
import re
import subprocess
import sys
import threading
import time

import pytest

import mjcffi
from mjcffi import scenes
from mjcffi._support import display, spec_claims
from mjcffi.tune import Change

NASTY = "<b>&amp;\"x'"           # what a name must not inject into the HTML
NASTY_XML = "&lt;b&gt;&amp;amp;&quot;x&apos;"


def humanoid_path():
    import gymnasium
    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        "humanoid.xml")
    if not os.path.exists(path):
        pytest.skip("gymnasium's humanoid.xml is not installed")
    return path


def fastest(call, n=5):
    best = float("inf")
    for _ in range(n):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best


class _Tree(html.parser.HTMLParser):
    """(list depth, first text) of each <li>, in document order; checks tags balance."""

    def __init__(self):
        super().__init__()
        self.items, self.depth, self.open, self.pending = [], 0, [], False

    def handle_starttag(self, tag, attrs):
        if tag in ("ul", "li", "table", "tr", "td", "th", "div", "small", "b", "i"):
            self.open.append(tag)
        if tag == "ul":
            self.depth += 1
        elif tag == "li":
            self.pending = True

    def handle_endtag(self, tag):
        assert self.open and self.open[-1] == tag, (tag, self.open)
        self.open.pop()
        if tag == "ul":
            self.depth -= 1

    def handle_data(self, data):
        if self.pending and data.strip():
            self.items.append((self.depth, data.strip()))
            self.pending = False


def tree_of(text):
    parser = _Tree()
    parser.feed(text)
    parser.close()
    assert parser.open == [] and parser.depth == 0
    return parser.items


# ------------------------------------------------------------------ import cost

def test_import_loads_no_display_code():
    code = ("import sys, mjcffi, mjcffi.model, mjcffi.spec, mjcffi.tune\n"
            "m = mjcffi.MjModel.from_xml_string('<mujoco/>')\n"
            "print('mjcffi._support.display' in sys.modules)\n"
            "m._repr_html_()\n"
            "print('mjcffi._support.display' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "True"]


# ------------------------------------------------------------------ MjModel

def test_model_shows_its_sizes_and_options():
    m = mjcffi.MjModel.from_xml_path(humanoid_path())
    text = m._repr_html_()
    assert isinstance(text, str) and text.startswith("<div><b>MjModel</b> &#x27;humanoid&#x27;")
    header = text.split("</table>")[0]
    names = re.findall(r"<th[^>]*>([^<]*)</th>", header)
    values = re.findall(r"<td[^>]*>([^<]*)</td>", header)
    sizes = dict(zip(names, values))
    assert sizes["nq"] == str(m.nq) == "24" and sizes["nv"] == str(m.nv)
    assert sizes["nu"] == str(m.nu) and sizes["nbody"] == str(m.nbody)
    assert sizes["ngeom"] == str(m.ngeom) and sizes["ntendon"] == str(m.ntendon)
    assert "nsensor" not in sizes and "nsite" not in sizes        # zero: left out
    options = dict(zip(re.findall(r"<th[^>]*>([^<]*)</th>", text.split("</table>")[1]),
                       re.findall(r"<td[^>]*>([^<]*)</td>", text.split("</table>")[1])))
    assert options == {"timestep": "0.003", "integrator": "RK4", "solver": "PGS",
                       "iterations": "50", "cone": "pyramidal", "gravity": "0 0 -9.81"}
    tree_of(text)                                                  # well formed


def test_model_display_is_fast():
    m = mjcffi.MjModel.from_xml_path(humanoid_path())
    m._repr_html_()                      # the module's import is not the display's cost
    assert fastest(m._repr_html_) < 0.01


def test_model_name_and_options_are_escaped_and_named():
    m = mjcffi.MjModel.from_xml_string(
        f'<mujoco model="{NASTY_XML}"><option integrator="implicitfast" solver="Newton" '
        f'cone="elliptic" timestep="0.0025"/></mujoco>')
    text = m._repr_html_()
    assert "&lt;b&gt;&amp;amp;&quot;x" in text and NASTY not in text and "<b>&" not in text
    for word in (">implicitfast<", ">Newton<", ">elliptic<", ">0.0025<", ">nbody<"):
        assert word in text


def test_model_display_never_raises(monkeypatch):
    m = mjcffi.MjModel.from_xml_string("<mujoco/>")

    def broken(_):
        raise ValueError("<broken>")

    monkeypatch.setattr(display, "model_html", broken)
    text = m._repr_html_()
    assert text.startswith("<pre>&lt;MjModel nq=0") and text.endswith("&gt;</pre>")


# ------------------------------------------------------------------ MjSpec

NESTED = f"""<mujoco model="tree"><option timestep="0.004"/><worldbody>
  <geom size="1"/>
  <body name="a"><joint/><geom size=".1"/><geom size=".1"/><site/>
    <body name="a1"><frame><body name="in_frame"><geom size=".1"/></body></frame></body>
    <body name="a2"/>
  </body>
  <body name="{NASTY_XML}"><joint/><joint/></body>
</worldbody></mujoco>"""


def test_spec_shows_name_counts_and_the_body_tree_in_order():
    spec = mjcffi.MjSpec.from_string(NESTED)
    text = spec._repr_html_()
    assert text.startswith("<div><b>MjSpec</b> &#x27;tree&#x27; timestep 0.004")
    counts = text.split("</table>")[0]
    names = re.findall(r"<th[^>]*>([^<]*)</th>", counts)
    values = re.findall(r"<td[^>]*>([^<]*)</td>", counts)
    assert dict(zip(names, values)) == {"bodies": "6", "frames": "1", "geoms": "4",
                                        "joints": "3", "sites": "1"}
    assert tree_of(text) == [(1, "world"), (2, "a"), (3, "a1"), (4, "in_frame"), (3, "a2"),
                             (2, NASTY)]
    assert "a <small>(2 geoms, 1 joint, 1 site)</small>" in text
    assert "world <small>(1 geom)</small>" in text and "a2</li>" in text
    assert "&lt;b&gt;&amp;amp;&quot;x&#x27; <small>(2 joints)</small>" in text
    assert NASTY not in text and "<b>&" not in text


def test_spec_of_humanoid_lists_every_body_in_tree_order_quickly():
    spec = mjcffi.MjSpec.from_file(humanoid_path())
    text = spec._repr_html_()
    assert [name for _, name in tree_of(text)] == [b.name for b in spec.bodies]
    assert fastest(spec._repr_html_) < 0.05


def test_an_empty_spec_shows_the_world_alone():
    text = mjcffi.MjSpec()._repr_html_()
    assert tree_of(text) == [(1, "world")] and "bodies" in text


@pytest.mark.parametrize("shape", ["flat", "chain"])
def test_a_big_spec_is_cut_at_the_limit(shape):
    spec = mjcffi.MjSpec()
    parent = spec.worldbody
    for i in range(display.BODY_LIMIT + 150):
        body = parent.add_body(name=f"b{i}")
        if shape == "chain":
            parent = body
    text = spec._repr_html_()
    items = tree_of(text)
    assert len(items) == 1 + display.BODY_LIMIT
    assert [name for _, name in items[1:]] == [f"b{i}" for i in range(display.BODY_LIMIT)]
    assert "… and 150 more bodies" in text
    assert f"b{display.BODY_LIMIT}<" not in text
    assert len(text) < 100 * display.BODY_LIMIT + 2000


def test_a_spec_another_thread_holds_shows_a_note():
    spec = mjcffi.MjSpec.from_string(NESTED)
    held, release = threading.Event(), threading.Event()

    def hold():
        with spec_claims.holding(spec._ptr, b"the test's other thread"):
            held.set()
            release.wait(30)

    other = threading.Thread(target=hold)
    other.start()
    try:
        assert held.wait(30)
        text = spec._repr_html_()
        assert text == "<pre>&lt;MjSpec: in use by another thread; no summary&gt;</pre>"
    finally:
        release.set()
        other.join()
    assert tree_of(spec._repr_html_())[0] == (1, "world")     # and again once released


def test_spec_display_never_raises(monkeypatch):
    spec = mjcffi.MjSpec()

    def broken(_):
        raise RuntimeError("<broken>")

    monkeypatch.setattr(display, "_spec_summary", broken)
    text = spec._repr_html_()
    assert text.startswith("<pre>&lt;MjSpec ") and text.endswith("&gt;</pre>")


# ------------------------------------------------------------------ TuneResult

@pytest.fixture(scope="module")
def tuned():
    m = mjcffi.MjModel.from_xml_string(scenes.HARD_CASES["double_pendulum"])
    return mjcffi.tune(m, 1e-3, control_period=0.01, horizon=0.2, progress=False)


def test_tune_result_markdown_is_its_report(tuned):
    text = tuned._repr_markdown_()
    assert text == tuned.report() and text.startswith("# Tuned settings")


def test_tune_result_html_shows_the_report(tuned):
    text = tuned._repr_html_()
    assert text.startswith("<h3>Tuned settings (budget: 0.001, objective: cheapest)</h3>")
    assert f"Result: {tuned.speedup:.2f}× the original&#x27;s speed</b>" in text
    for change in tuned.settings.values():
        assert f">{change.name}</td>" in text
    assert ">hinge</td>" in text and ">rad</td>" in text
    # tables: changes, held-out error, the 0.5 s distance, candidates (a header row each)
    assert text.count("<tr>") == (1 + len(tuned.settings) + 1 + len(tuned.error.local)
                                  + 1 + len(tuned.error.divergence.tuned)
                                  + 1 + len(tuned.candidates))
    assert "|" not in re.sub(r"<img[^>]*>", "", text)


def test_tune_result_html_holds_the_plot(tuned):
    pytest.importorskip("matplotlib")
    text = tuned._repr_html_()
    found = re.findall(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)"', text)
    assert len(found) == 1
    png = base64.b64decode(found[0])
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and len(png) > 1000
    # before the candidates' table, after the held-out figures
    assert text.index("<img") < text.index("Candidates (search-set error")
    assert text.index("<img") > text.index("Held-out trajectories over the whole horizon")


def test_tune_result_html_without_matplotlib_is_the_report_alone(tuned, monkeypatch):
    for name in ("matplotlib", "matplotlib.figure"):
        monkeypatch.setitem(sys.modules, name, None)     # import raises ImportError
    text = tuned._repr_html_()
    assert "<img" not in text and text.startswith("<h3>Tuned settings")
    assert "Candidates (search-set error" in text


def test_tune_result_html_escapes_and_never_raises(tuned, monkeypatch):
    result = copy.copy(tuned)
    result.settings = dict(tuned.settings, timestep=Change("timestep", 0.01, 0.005, NASTY))
    text = result._repr_html_()
    assert "&lt;b&gt;&amp;amp;&quot;x&#x27;</td>" in text and NASTY not in text
    assert result._repr_markdown_().count(NASTY) == 1

    monkeypatch.setattr(type(result), "_errors", lambda self: 1 / 0)
    assert result._repr_html_() == f"<pre>{display.escape(repr(result))}</pre>"
    assert result._repr_markdown_() is None


# ------------------------------------------------------------ around the display

def test_a_change_shows_enum_values_by_name_as_the_report_does():
    from mjcffi.tune._result import Change
    assert str(Change("integrator", 0, 1, "why")) == "integrator: Euler → RK4 (why)"
    assert str(Change("timestep", 0.01, 0.005, "why")) == "timestep: 0.01 → 0.005 (why)"


def test_the_progress_bar_is_tqdm_s_text_bar_without_ipywidgets(monkeypatch):
    # tqdm.auto would pick the notebook bar and warn "IProgress not found" in notebooks
    tqdm_std = pytest.importorskip("tqdm.std")
    import sys
    from mjcffi._support import progress
    monkeypatch.setitem(sys.modules, "ipywidgets", None)
    with progress.bar(3, "x", "it") as bar:
        assert type(bar) is tqdm_std.tqdm
