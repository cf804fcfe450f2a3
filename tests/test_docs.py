"""The documentation: every public name is in the API reference, the README stays short,
and the site's sources are in order.  The site itself is built (and the tutorial notebook
executed) by `.ci/run`: `MUJOCO_GL=egl mkdocs build --strict`."""

import importlib.util
import pathlib
import re

import pytest

import mjcffi
import mjcffi.sim

REPO = pathlib.Path(__file__).resolve().parent.parent
DOCS = REPO / "docs"


@pytest.fixture(scope="module")
def pages():
    spec = importlib.util.spec_from_file_location("_docs_pages", DOCS / "hooks" / "pages.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.api_pages()


def _named(text):
    """Names a page documents: mkdocstrings targets (last part) and table rows."""
    names = {line.split()[1].rsplit(".", 1)[-1] for line in text.splitlines()
             if line.startswith("::: ")}
    names |= set(re.findall(r"^\| `([^`]+)` \|", text, re.M))
    return names


@pytest.mark.parametrize("module", [mjcffi, mjcffi.sim], ids=lambda m: m.__name__)
def test_every_public_name_is_in_the_api_reference(pages, module):
    page = "api/mjcffi-sim.md" if module is mjcffi.sim else None
    documented = set().union(*(_named(text) for path, text in pages.items()
                               if page is None and path != "api/mjcffi-sim.md"
                               or path == page))
    # a class re-exported under another name is documented under its own
    missing = [name for name in module.__all__
               if name not in documented and getattr(getattr(module, name), "__name__", name)
               not in documented]
    assert missing == []


def test_all_is_the_public_names_without_submodules():
    names = mjcffi.__all__
    assert names == sorted(set(names)) and len(names) > 800
    assert {"MjModel", "MjData", "mj_step", "mjtObj", "mjPI", "ffi", "lib", "MjSpec",
            "Renderer", "FatalError"} <= set(names)
    assert not {"rollout", "batch", "sim", "tune", "egl", "functions"} & set(names)


def test_the_nav_lists_every_page(pages):
    nav = (REPO / "mkdocs.yml").read_text()
    written = {p.relative_to(DOCS).as_posix() for p in DOCS.glob("*.md")}
    for page in sorted(written | set(pages)):
        assert re.search(rf"(: |- ){re.escape(page)}$", nav, re.M), page
    assert "tutorial.ipynb" in nav


def test_the_readme_is_short_and_points_into_the_docs():
    text = (REPO / "README.md").read_text()
    assert len(text.splitlines()) < 200
    for link in re.findall(r"\]\((docs/[^)#]+)", text):
        assert (REPO / link).exists(), link


def test_links_between_pages_point_at_pages(pages):
    names = {p.relative_to(DOCS).as_posix() for p in DOCS.glob("*.md")} | set(pages) | {
        "tutorial.ipynb", "results.md", "accuracy-report.md", "conformance-report.md"}
    for path in DOCS.glob("*.md"):
        for link in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", path.read_text()):
            assert link in names, (path.name, link)
