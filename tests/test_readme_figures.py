"""The README quotes benchmarks/RESULTS.md exactly (benchmarks/readme.py writes its figures)."""

import pathlib

import pytest

from benchmarks import readme

RESULTS = pathlib.Path(readme.README).parent / "benchmarks" / "RESULTS.md"


def test_the_readme_figures_are_those_of_results_md():
    text = readme.README.read_text()
    assert readme.update(text, RESULTS.read_text()) == text


def test_every_figure_block_is_filled_from_results():
    figures = readme.figures(RESULTS.read_text())
    text = readme.README.read_text()
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
