"""Did each page render as its Markdown source says? Compare the built HTML with the source.

Python-Markdown (MkDocs) reads some GitHub-style Markdown differently: a list nested by two
spaces flattens, a list with no blank line before it stays a paragraph that starts with a
literal "- " or "1.", and a fence inside such a list becomes inline text. For every page
written by hand (docs/*.md, and the reports shown as they are), this checks that

- every fenced code block of the source is a highlighted code block in the HTML, and no
  code block is left unhighlighted (an indented block made by mistake);
- every list item nested in the source is nested in the HTML;
- no paragraph of the HTML begins with a literal list marker, on its first line or on
  any other (a list glued to the text above it stays inside that paragraph).

It reads the HTML with the standard library's parser. `check_site` is run by the docs
hook after every build (a problem fails the build) and by tests/test_docs.py.
"""

import html.parser
import pathlib
import re

_VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source",
         "track", "wbr"}
_FENCE = re.compile(r"^(`{3,}|~{3,})")
_ITEM = re.compile(r"^([-*+]|\d+[.)])\s+\S")
_MARKER = re.compile(r"^([-*+]|\d+[.)])\s")


class Node:
    def __init__(self, tag, attrs, parent):
        self.tag, self.attrs, self.parent = tag, dict(attrs), parent
        self.children, self.text = [], []

    def classes(self):
        return (self.attrs.get("class") or "").split()

    def iter(self):
        yield self
        for child in self.children:
            yield from child.iter()

    def ancestors(self):
        node = self.parent
        while node is not None:
            yield node
            node = node.parent

    def content(self):
        """The text inside, children included, in order."""
        return "".join(part if isinstance(part, str) else part.content()
                       for part in self.text)


class _Tree(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.root = self.node = Node("document", [], None)

    def handle_starttag(self, tag, attrs):
        node = Node(tag, attrs, self.node)
        self.node.children.append(node)
        self.node.text.append(node)
        if tag not in _VOID:
            self.node = node

    def handle_startendtag(self, tag, attrs):
        node = Node(tag, attrs, self.node)
        self.node.children.append(node)
        self.node.text.append(node)

    def handle_endtag(self, tag):
        node = self.node
        while node is not None and node.tag != tag:
            node = node.parent
        if node is not None and node.parent is not None:
            self.node = node.parent

    def handle_data(self, data):
        self.node.text.append(data)


def parse(text):
    tree = _Tree()
    tree.feed(text)
    tree.close()
    return tree.root


def article(root):
    """The page's own content (Material's article), not the navigation around it."""
    for node in root.iter():
        if node.tag == "article" and "md-content__inner" in node.classes():
            return node
    return root


def source_facts(markdown):
    """(fenced code blocks, nested list items) that the Markdown source holds."""
    fences, nested = 0, 0
    fence = None
    items = []                  # indentation of the list items open above this line
    blank = False
    container = 0               # the indentation of an admonition's body
    for line in markdown.splitlines():
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if fence:
            if stripped.startswith(fence) and not stripped[len(fence):].strip():
                fence = None
            continue
        opened = _FENCE.match(stripped)
        if opened:
            fences += 1
            fence = opened.group(1)
            continue
        if not stripped:
            blank = True
            continue
        if stripped.startswith(("!!!", "???")):
            container, items = indent + 4, []
            blank = False
            continue
        if container and indent < container:
            container = 0
        indent -= container
        if stripped.startswith(("#", "|", "<")) and indent == 0:
            items = []
        elif _ITEM.match(stripped):
            while items and indent <= items[-1]:
                items.pop()
            if items:
                nested += 1
            items.append(indent)
        elif indent == 0 and blank:
            items = []                  # a paragraph at the margin ends the lists
        blank = False
    return fences, nested


def html_facts(root):
    """(highlighted code blocks, code blocks without highlighting, nested list items,
    paragraphs that begin with a list marker) of a built page."""
    page = article(root)
    highlighted, plain, nested, literal = 0, 0, 0, []
    for node in page.iter():
        classes = node.classes()
        if node.tag == "div" and "highlight" in classes:
            highlighted += 1
        elif node.tag == "pre" and not any(
                "highlight" in a.classes() for a in node.ancestors()):
            plain += 1
        elif node.tag == "li" and any(a.tag == "li" for a in node.ancestors()):
            nested += 1
        elif node.tag == "p" and not any(a.tag == "pre" for a in node.ancestors()):
            # a list that follows a line of text with no blank line stays in the paragraph
            for line in node.content().splitlines():
                if _MARKER.match(line.lstrip()):
                    literal.append(line.strip()[:60])
    return highlighted, plain, nested, literal


def built_page(site, page):
    """The HTML file MkDocs writes for docs page `page` ('drop-in.md')."""
    stem = page[:-len(".md")]
    if stem == "index":
        return site / "index.html"
    return site / stem / "index.html"


def check_page(name, markdown, html_text):
    """The problems of one page, as sentences (empty: it rendered as written)."""
    fences, nested = source_facts(markdown)
    highlighted, plain, html_nested, literal = html_facts(parse(html_text))
    problems = []
    if highlighted < fences:
        problems.append(f"{name}: {fences} fenced code blocks in the source, "
                        f"{highlighted} highlighted in the HTML")
    if plain:
        problems.append(f"{name}: {plain} code blocks without highlighting (an indented "
                        "block, or a fence Python-Markdown did not see)")
    if html_nested < nested:
        problems.append(f"{name}: {nested} nested list items in the source, {html_nested} "
                        "nested in the HTML (nest by 4 spaces)")
    for text in literal:
        problems.append(f"{name}: a paragraph begins with a list marker: {text!r} "
                        "(a blank line before the list?)")
    return problems


def reindent_lists(markdown):
    """GitHub-style Markdown as Python-Markdown reads it the same way: a nested list item
    indented 4 spaces past its parent's marker, and the blocks inside an item (a second
    paragraph, a fenced block) with it; a blank line before a list that follows a
    paragraph. Lists already nested by 4 stay as they are; so do the continuation lines
    of a paragraph, which Python-Markdown takes at any indentation."""
    out, items, fence = [], [], None      # items: (source marker, source content, target)
    shift = 0                             # how far the open fence's lines move
    previous = ""
    for line in markdown.splitlines():
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if fence:
            out.append(" " * max(0, indent + shift) + stripped if stripped else "")
            if stripped.startswith(fence) and not stripped[len(fence):].strip():
                fence = None
            previous = line
            continue
        if not stripped:
            out.append("")
            previous = ""
            continue
        item = _ITEM.match(stripped)
        opened = _FENCE.match(stripped)
        if item:
            starts = not items
            while items and indent < items[-1][1]:
                items.pop()
            target = items[-1][2] + 4 if items else indent
            if starts and previous and not previous.lstrip().startswith(("#", "|", "<", "!!!")):
                out.append("")            # a list needs a blank line above it
            items.append((indent, indent + len(item.group(1)) + 1, target))
            out.append(" " * target + stripped)
        elif items and indent and (not previous or opened):
            # a block of its own inside an item: 4 past the item's marker
            owner = next((i for i in reversed(items) if indent >= i[1]), items[0])
            target = owner[2] + 4 + max(0, indent - max(owner[1], owner[0] + 4))
            out.append(" " * target + stripped)
            if opened:
                fence, shift = opened.group(1), target - indent
        elif items and indent and any(indent >= i[1] for i in items):
            # a paragraph's next line: aligned with its item's text, as it was
            owner = next(i for i in reversed(items) if indent >= i[1])
            out.append(" " * (owner[2] + owner[1] - owner[0] + indent - owner[1]) + stripped)
        else:
            if not previous or indent == 0 and not items:
                items = [] if not previous else items
            out.append(line)
            if opened:
                fence, shift = opened.group(1), 0
        previous = line
    return "\n".join(out) + ("\n" if markdown.endswith("\n") else "")


def hand_written(docs):
    """{page: Markdown source} of the pages written by hand: docs/*.md and the reports."""
    pages = {p.name: p.read_text() for p in sorted(docs.glob("*.md"))}
    root = docs.parent
    for page, source in (("results.md", "benchmarks/RESULTS.md"),
                         ("accuracy-report.md", "benchmarks/ACCURACY.md"),
                         ("conformance-report.md", "CONFORMANCE.md")):
        if (root / source).is_file():        # shown through reindent_lists (the hook)
            pages[page] = reindent_lists((root / source).read_text())
    return pages


def check_site(docs, site):
    """Every problem of every hand-written page of the site built into `site`."""
    problems = []
    for page, markdown in hand_written(pathlib.Path(docs)).items():
        path = built_page(pathlib.Path(site), page)
        if not path.is_file():
            problems.append(f"{page}: not built ({path.name} missing)")
            continue
        problems += check_page(page, markdown, path.read_text())
    return problems
