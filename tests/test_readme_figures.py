"""The README quotes benchmarks/RESULTS.md exactly (benchmarks/readme.py writes its figures)."""

import pathlib
import re

import pytest

from benchmarks import readme

RESULTS = pathlib.Path(readme.README).parent / "benchmarks" / "RESULTS.md"


@pytest.mark.parametrize("path", sorted(readme.FILES), ids=lambda p: p.name)
def test_the_figures_of_the_readme_and_docs_are_those_of_results_md(path):
    blocks, link = readme.FILES[path]
    text = path.read_text()
    assert readme.update(text, RESULTS.read_text(), blocks, link) == text


def test_the_readme_has_no_figure_outside_its_generated_block():
    # every measured figure in the README is generated: a ratio (×) or a time outside
    # the block would be one typed by hand
    text = readme.README.read_text()
    start, end = readme._marks("headline")
    outside = text[:text.index(start)] + text[text.index(end):]
    assert "×" not in outside
    assert not re.search(r"\d(\.\d+)? ?(ms|µs|ns)\b", outside)


def test_every_figure_block_is_filled_from_results():
    figures = readme.figures(RESULTS.read_text())
    text = "".join(path.read_text() for path in readme.FILES)
    assert f"{figures['qpos']:.2f}×" in text and f"{figures['step0_ratio']:.2f}×" in text
    assert figures["date"] in text


def test_a_changed_figure_in_results_changes_the_readme():
    results = RESULTS.read_text()
    row = next(line for line in results.splitlines() if line.startswith("| `d.qpos` |"))
    cells = row.split("|")
    cells[4] = " 0.99 "
    changed = readme.update(readme.README.read_text(), results.replace(row, "|".join(cells)))
    assert "`d.qpos` reads in 0.99×" in changed


def test_a_readme_without_its_markers_is_refused():
    with pytest.raises(ValueError, match="headline"):
        readme.update("no markers here", RESULTS.read_text())
