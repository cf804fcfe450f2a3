"""The tutorial notebook as git keeps it: no outputs, code that parses, nothing outside Python.

The notebook is executed by the documentation build (`.ci/run`: `MUJOCO_GL=egl mkdocs build
--strict`, with mkdocs-jupyter's `execute: true` and `allow_errors: false`), not here: these
checks only read the file, so they are fast and need neither Jupyter nor OpenGL.
"""

import ast
import json
import pathlib
import re

import pytest

NOTEBOOK = pathlib.Path(__file__).resolve().parent.parent / "docs" / "tutorial.ipynb"


@pytest.fixture(scope="module")
def notebook():
    return json.loads(NOTEBOOK.read_text(encoding="utf-8"))


def _source(cell):
    source = cell["source"]
    return "".join(source) if isinstance(source, list) else source


def _code_cells(notebook):
    return [(i, _source(c)) for i, c in enumerate(notebook["cells"])
            if c["cell_type"] == "code"]


def test_format_and_kernel(notebook):
    assert notebook["nbformat"] == 4
    assert notebook["metadata"]["kernelspec"]["name"] == "python3"
    assert len(_code_cells(notebook)) >= 8


def test_no_outputs_are_committed(notebook):
    """Outputs (images, videos, timings) belong to the executed copy the docs build makes;
    clear them with `jupyter nbconvert --clear-output --inplace docs/tutorial.ipynb`."""
    kept = [i for i, c in enumerate(notebook["cells"]) if c["cell_type"] == "code"
            and (c.get("outputs") or c.get("execution_count") is not None)]
    assert kept == [], f"cells {kept} keep outputs or an execution count"


def test_every_code_cell_parses(notebook):
    for i, source in _code_cells(notebook):
        try:
            ast.parse(source, filename=f"tutorial.ipynb, cell {i}")
        except SyntaxError as exc:
            pytest.fail(f"cell {i} is not Python: {exc}")


def test_no_magics_shell_or_network(notebook):
    """Plain Python only (so the cells parse as such, and run as a script), and nothing
    fetched: the docs build runs the notebook with no network and no files besides the
    installed packages."""
    for i, source in _code_cells(notebook):
        magic = [line for line in source.splitlines() if re.match(r"\s*[%!]", line)]
        assert magic == [], f"cell {i}: IPython magic or shell escape {magic}"
        assert not re.search(r"\bget_ipython\b|\burlopen\b|\brequests\b|https?://", source), \
            f"cell {i} reaches outside Python or onto the network"


def test_sections_in_order(notebook):
    """The tutorial's outline: numbered sections, each with a Markdown explanation."""
    headings = [int(m) for c in notebook["cells"] if c["cell_type"] == "markdown"
                for m in re.findall(r"^## (\d+)\. ", _source(c), re.M)]
    assert headings == list(range(1, 9))
