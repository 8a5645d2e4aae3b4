"""The student edition, page by page: nothing of a solution anywhere, and readable on any screen.

The book that ``make book`` builds (the student edition, ``_build/html``) is checked for every
page of ``_toc.yml``:

* **what a student receives**: no page shows a lab's model solutions, the tutors' notes or an
  output computed from a solution (a lab's check cells are shown unrun); no visible text names
  the other edition or dropdowns; the page's notebook (``_notebooks/``) and its words in the
  search index hold nothing the page leaves out; every local link and download of the page
  resolves (the sources are not copied into the site, and no link points to them);
* **the screen**, in headless Chromium at 390 px (a phone) and 1280 px (a desktop): the page
  never scrolls sideways, whatever is wider than the column scrolls in its own frame with a
  visible cue, figure text is at least 9 CSS px on the phone and 11 px on the desktop, and a
  figure is shown with its own aspect ratio (round circles stay round).

What the pages hide is read from their MyST sources: code cells tagged ``solution`` or
``instructor``, the text of ``{solution-start}`` ... ``{solution-end}`` blocks and of the
"Instructor notes" sections. The book is built once per test run (``built_book``).
"""

from __future__ import annotations

import copy
import json
import re
import unicodedata
from html import unescape
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest
from test_book import PAGES, ROOT, page_facts

# the book (conftest's built_book), its local server and the browser (conftest: one each per run)

pytestmark = [pytest.mark.book]

SOURCES = {page: ROOT / f"{page}.md" for page in PAGES}
LABS = [page for page in PAGES if Path(page).name.startswith("lab_")]
HIDDEN_TAGS = ("solution", "instructor")
# Words no student page may show: the other edition and the dropdowns it has.
FORBIDDEN = ("instructor edition", "book-instructor", "dropdown")

# The smallest text of a figure drawn by a chapter (points) and the resolution it is drawn at:
# book/matplotlibrc and uio_teach.plotting.FONT_SIZE; test_fonts_of_the_chapters_figures keeps the
# chapters' own font sizes at or above it.
FIGURE_FONT_PT = 11
FIGURE_DPI = 100
PHONE, DESKTOP = 390, 1280
SMALLEST_TEXT_PX = {PHONE: 9.0, DESKTOP: 11.0}


# --- what the sources hide ---------------------------------------------------------------------


def _fence_blocks(lines: list[str]) -> list[tuple[int, int, str, list[str]]]:
    """Each ```` ```{name} ```` block: (first line, last line, name, tags)."""
    blocks = []
    i = 0
    while i < len(lines):
        m = re.match(r"^(`{3,})\{([\w-]+)\}", lines[i])
        if not m:
            i += 1
            continue
        fence, name, start = m.group(1), m.group(2), i
        tags: list[str] = []
        i += 1
        while i < len(lines) and lines[i].rstrip() != fence:
            t = re.match(r"^:tags:\s*\[(.*)\]", lines[i])
            if t:
                tags = [s.strip().strip("'\"") for s in t.group(1).split(",")]
            i += 1
        blocks.append((start, i, name, tags))
        i += 1
    return blocks


def hidden_and_shown(source: Path) -> tuple[list[str], set[str]]:
    """The lines of a page's source the student edition leaves out, and the lines it keeps.

    Hidden: code cells tagged ``solution``/``instructor``, everything between a
    ``{solution-start}`` and its ``{solution-end}``, and an "Instructor notes" section (to the
    next heading of its level or higher). Lines are stripped; only lines of 25 characters or
    more that the shown part does not also contain (blanks ignored) are returned as hidden
    (distinctive probes).
    """
    lines = source.read_text(encoding="utf-8").splitlines()
    hidden = [False] * len(lines)
    blocks = _fence_blocks(lines)
    for start, end, name, tags in blocks:
        if name == "code-cell" and any(tag in HIDDEN_TAGS for tag in tags):
            for k in range(start, end + 1):
                hidden[k] = True
    inside = False
    for k, line in enumerate(lines):
        if line.startswith("```{solution-start}"):
            inside = True
        if inside:
            hidden[k] = True
        if line.startswith("```{solution-end}"):
            inside = False
    level = 0
    for k, line in enumerate(lines):
        m = re.match(r"^(#+)\s+(.*)$", line)
        if m and not any(s <= k <= e for s, e, name, _ in blocks if name == "code-cell"):
            depth = len(m.group(1))
            if level and depth <= level:
                level = 0
            if m.group(2).strip().lower().startswith("instructor"):
                level = depth
        if level:
            hidden[k] = True
    shown = {line.strip() for line, h in zip(lines, hidden, strict=True) if not h}
    everything_shown = _squash("".join(shown))
    probes = [
        line.strip()
        for line, h in zip(lines, hidden, strict=True)
        if h and len(line.strip()) >= 25 and _squash(line) not in everything_shown
    ]
    return probes, shown


class _Text(HTMLParser):
    """The text of a page (scripts and styles left out), and its local links."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.parts: list[str] = []
        self.links: list[str] = []
        self._skip = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag in ("script", "style"):
            self._skip += 1
        for name, value in attrs:
            if name in ("href", "src") and value:
                self.links.append(value)

    def handle_endtag(self, tag: str) -> None:
        if tag in ("script", "style") and self._skip:
            self._skip -= 1

    def handle_data(self, data: str) -> None:
        if not self._skip:
            self.parts.append(data)


def _squash(text: str) -> str:
    return re.sub(r"\s+", "", unescape(text))


def page_text(html_file: Path) -> tuple[str, list[str]]:
    parser = _Text()
    parser.feed(html_file.read_text(encoding="utf-8"))
    return " ".join(parser.parts), parser.links


def _main_text(html_file: Path) -> str:
    """The text of the page's article (the part written from its source)."""
    html = html_file.read_text(encoding="utf-8")
    start = html.find('<article class="bd-article">')
    end = html.find("</article>", start)
    parser = _Text()
    parser.feed(html[start:end] if start >= 0 and end > start else html)
    return " ".join(parser.parts)


# --- what a student receives -------------------------------------------------------------------


def test_the_probes_find_what_a_lab_hides():
    """The reader of hidden lines finds the lab's solutions and tutors' notes (else the
    artefact tests below would pass on nothing)."""
    for lab in LABS:
        probes, _ = hidden_and_shown(SOURCES[lab])
        assert len(probes) > 20, (lab, len(probes))
        assert any("ut." in p or "np." in p for p in probes), lab  # solution code
        assert any(re.search(r"[a-z]{4,} [a-z]{4,} [a-z]{4,}", p) for p in probes), lab  # prose


@pytest.mark.parametrize("page", PAGES)
def test_no_page_shows_what_its_source_hides(page: str, built_book: Path) -> None:
    html = built_book / f"{page}.html"
    text = _squash(_main_text(html))
    probes, _ = hidden_and_shown(SOURCES[page])
    shown = [p for p in probes if _squash(p) in text]
    assert not shown, f"{page}: the page shows hidden lines: {shown[:5]}"
    visible = page_text(html)[0].lower()
    named = [w for w in FORBIDDEN if w in visible]
    assert not named, f"{page}: names {named}"


def _tutor_headings(source: Path) -> list[str]:
    """The headings of a page's source that open a section for the tutors."""
    lines = source.read_text(encoding="utf-8").splitlines()
    blocks = [(s, e) for s, e, name, _ in _fence_blocks(lines) if name == "code-cell"]
    out = []
    for k, line in enumerate(lines):
        m = re.match(r"^(#{2,})\s+(.*)$", line)
        if m and not any(s <= k <= e for s, e in blocks):
            if m.group(2).strip().lower().startswith("instructor"):
                out.append(m.group(2).strip())
    return out


TUTOR_PAGES = [page for page in PAGES if _tutor_headings(SOURCES[page])]


def test_the_pages_with_tutors_sections_are_found():
    """The labs and the API page have sections for the tutors (else the test below tests
    nothing)."""
    assert set(LABS) <= set(TUTOR_PAGES) and any(p.startswith("book/api") for p in TUTOR_PAGES)


@pytest.mark.parametrize("page", TUTOR_PAGES)
def test_tutors_sections_are_left_out_whole_heading_and_all(page: str, built_book: Path) -> None:
    """No heading of a tutors' section, no stub text in its place, no entry in the page's
    table of contents, no dead anchor: the section is not on the student page at all."""
    html = (built_book / f"{page}.html").read_text(encoding="utf-8")
    headings = [
        re.sub(r"<[^>]+>", "", h).replace("#", "").strip()
        for h in re.findall(r"<h[1-6][^>]*>(.*?)</h[1-6]>", html, flags=re.S)
    ]
    for title in _tutor_headings(SOURCES[page]):
        assert not any(h.startswith(title) for h in headings), (page, title, headings)
        assert f">{title}<" not in html, (page, title)
    assert "This section is for the tutors" not in html
    assert not re.search(r'id="[^"]*-instructor"', html), page


@pytest.mark.parametrize("page", LABS)
def test_lab_checks_are_shown_unrun(page: str, built_book: Path) -> None:
    """A lab's check cells have no output (their verdicts would come from the model solution)
    and say why; no ✓/✗ verdict and no "checks passed" is on the page."""
    html = (built_book / f"{page}.html").read_text(encoding="utf-8")
    # a cell's tags are classes of its box (``cell tag_check docutils container``)
    cells = re.split(r'<div class="cell(?: [\w-]+)* docutils container', html)[1:]
    checks = [c for c in cells if 'checks</span><span class="o">.</span>' in c.split("</pre>")[0]]
    assert checks, f"{page}: no check cell found"
    with_output = [c[:200] for c in checks if 'class="cell_output' in c]
    assert not with_output, f"{page}: check cells with an output: {with_output[:2]}"
    assert all("student-unrun" in c for c in checks), page
    # no verdict anywhere: not in any cell's output, and no summary line of a check's report in
    # the text (its prose speaks of ✓ and ✗ as marks: "your mark is the number of ✓")
    outputs = [c.split('class="cell_output', 1)[1] for c in cells if 'class="cell_output' in c]
    verdicts = [o[:300] for o in outputs if re.search(r"[✓✗]|checks (passed|failed)", o)]
    assert not verdicts, f"{page}: outputs with a check's verdict: {verdicts[:2]}"
    text = _main_text(built_book / f"{page}.html")
    summary = re.search(r"=>\s*(All \d+ checks passed|\d+ of \d+ checks failed)", text)
    assert not summary, f"{page}: {summary.group(0)!r}"


@pytest.mark.parametrize("page", PAGES)
def test_the_notebook_holds_nothing_the_page_leaves_out(page: str, built_book: Path) -> None:
    """The page's notebook (``_notebooks/``): no hidden line, and every line of code in it is
    on the page: a lab's ``# TODO`` cells are its starting code. The cells that only test the
    page's stated numbers (tagged ``remove-cell``, never inside a solution) stay in the notebook,
    so that it runs as the page did."""
    notebook = built_book / "_notebooks" / f"{Path(page).name}.ipynb"
    html = built_book / f"{page}.html"
    text, links = page_text(html)
    linked = [link for link in links if "_notebooks/" in link]
    if not notebook.exists():
        assert not linked, f"{page}: links a notebook that is not in the site: {linked}"
        return
    assert linked, f"{page}: its notebook is in the site but the page does not link it"
    cells = json.loads(notebook.read_text(encoding="utf-8"))["cells"]
    body = "\n".join("".join(c["source"]) for c in cells)
    probes, _ = hidden_and_shown(SOURCES[page])
    squashed = _squash(body)
    leaked = [p for p in probes if _squash(p) in squashed]
    assert not leaked, f"{page}: the notebook holds hidden lines: {leaked[:5]}"
    on_page = _squash(text)
    code = [
        line.strip()
        for c in cells
        if c["cell_type"] == "code" and "remove-cell" not in c["metadata"].get("tags", [])
        for line in "".join(c["source"]).splitlines()
        if line.strip() and not line.strip().startswith("#")
    ]
    missing = [line for line in code if _squash(line) not in on_page]
    assert not missing, f"{page}: the notebook has code the page does not show: {missing[:5]}"


def test_the_search_index_holds_only_words_of_the_pages(built_book: Path) -> None:
    """Every word the search index files under a page is a word of that page."""
    from sphinx.search.en import SearchEnglish

    stem = SearchEnglish({}).stem
    raw = (built_book / "searchindex.js").read_text(encoding="utf-8")
    index = json.loads(raw[raw.index("(") + 1 : raw.rindex(")")])
    docs = index["docnames"]
    words: dict[int, set[str]] = {i: set() for i in range(len(docs))}
    for key in ("terms", "titleterms"):
        for term, where in index[key].items():
            for i in where if isinstance(where, list) else [where]:
                words[i].add(term)
    for i, doc in enumerate(docs):
        html = built_book / f"{doc}.html"
        if not html.exists():
            continue
        # the page's text, and (for raw HTML outputs, indexed as written) its markup
        source = html.read_text(encoding="utf-8")
        text = " ".join([page_text(html)[0], source, re.sub(r"<[^>]+>", "", source)])
        text += " " + unicodedata.normalize("NFC", unescape(text))
        found = set(re.findall(r"\w+", text)) | set(re.findall(r"\w+", text.lower()))
        # words split where a letter is not ASCII ("André" indexed as "andr", "é")
        found |= set(re.findall(r"[a-z0-9_]+", text.lower())) | set(
            re.findall(r"[^\W\x00-\x7f]+", text)
        )
        stems = found | {stem(w) for w in found}
        extra = sorted(words[i] - stems)
        assert not extra, f"{doc}: the search index has words that are not on the page: {extra}"


def _local_target(built_book: Path, page_file: Path, link: str) -> Path | None:
    parts = urlsplit(link)
    if parts.scheme or parts.netloc or link.startswith(("#", "data:", "javascript:", "mailto:")):
        return None
    if not parts.path:
        return None
    return (page_file.parent / unquote(parts.path)).resolve()


@pytest.mark.parametrize("page", PAGES)
def test_every_local_link_and_download_resolves(page: str, built_book: Path) -> None:
    html = built_book / f"{page}.html"
    _, links = page_text(html)
    missing = []
    for link in links:
        target = _local_target(built_book, html, link)
        if target is not None and not target.exists():
            missing.append(link)
    assert not missing, f"{page}: links to files not in the site: {sorted(set(missing))}"
    assert not (built_book / "_sources").exists(), "the pages' sources are copied into the site"


class _Anchors(HTMLParser):
    """The ids a page defines (anchors a link may point to) and the links it holds."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.ids: set[str] = set()
        self.links: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if name in ("id", "name") and value:
                self.ids.add(value)
            if name in ("href", "src") and value:
                self.links.append(value)


def dead_links(site: Path) -> list[str]:
    """Every local link of every HTML page of ``site`` to a file that is not there, or to an
    anchor (``#id``) its page does not define: ``page -> link``."""
    pages: dict[Path, _Anchors] = {}
    for html in sorted(site.rglob("*.html")):
        if "_static" in html.relative_to(site).parts:
            continue  # the theme's template macros shipped as files, not pages of the book
        parser = _Anchors()
        parser.feed(html.read_text(encoding="utf-8", errors="replace"))
        pages[html.resolve()] = parser
    dead = []
    for html, parser in pages.items():
        for link in sorted(set(parser.links)):
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith(("data:", "javascript:", "mailto:")):
                continue
            target = (html.parent / unquote(parts.path)).resolve() if parts.path else html
            if not target.exists():
                dead.append(f"{html.relative_to(site.resolve())} -> {link}")
                continue
            fragment = unquote(parts.fragment)
            if fragment and target in pages and fragment not in pages[target].ids:
                dead.append(f"{html.relative_to(site.resolve())} -> {link}")
    return dead


def test_the_link_check_finds_a_missing_file_and_a_missing_anchor(tmp_path: Path) -> None:
    (tmp_path / "api.html").write_text('<h2 id="kept">x</h2><a href="#kept">ok</a>')
    (tmp_path / "lab.html").write_text(
        '<a href="api.html#kept">ok</a> <a href="api.html#uio_teach.grading.grade.grade">gone</a>'
        ' <a href="gone.html">gone</a> <a href="https://example.org/#x">out</a>'
    )
    assert dead_links(tmp_path) == [
        "lab.html -> api.html#uio_teach.grading.grade.grade",
        "lab.html -> gone.html",
    ]


def test_links_to_the_objects_of_a_dropped_section_become_their_text() -> None:
    from docutils import nodes
    from editions import unlink_dropped

    para = nodes.paragraph()
    para += nodes.reference("", "grade()", refuri="api.html#uio_teach.grading.grade.grade")
    para += nodes.reference("", "simulate()", refuri="api.html#uio_teach.simulate")
    para += nodes.reference("", "here", refid="uio_teach.grading.merge.merge")
    assert (
        unlink_dropped(para, {"uio_teach.grading.grade.grade", "uio_teach.grading.merge.merge"})
        == 2
    )
    assert [r["refuri"] for r in para.findall(nodes.reference)] == ["api.html#uio_teach.simulate"]
    assert para.astext() == "grade()simulate()here"


def test_the_objects_of_a_dropped_section_leave_the_module_index() -> None:
    """The module index and the inventory are written from the domain's records, not from the
    pages: a module documented in a dropped section must leave them, or they link a dead anchor."""
    from types import SimpleNamespace

    from editions import forget_objects
    from sphinx.domains.python import ModuleEntry, ObjectEntry

    data = {
        "objects": {
            "uio_teach.grading.merge.merge": ObjectEntry(
                "book/api_tools", "uio_teach.grading.merge.merge", "function", False
            ),
            "uio_teach.simulate": ObjectEntry(
                "book/api_observers", "uio_teach.simulate", "function", False
            ),
        },
        "modules": {
            "uio_teach.grading.merge": ModuleEntry(
                "book/api_tools", "module-uio_teach.grading.merge", "", "", False
            ),
            "uio_teach.linalg": ModuleEntry(
                "book/api_tools", "module-uio_teach.linalg", "", "", False
            ),
        },
    }
    env = SimpleNamespace(get_domain=lambda name: SimpleNamespace(data=data))
    dropped = {"uio_teach.grading.merge.merge", "module-uio_teach.grading.merge"}
    assert forget_objects(env, "book/api_tools", dropped) == 2
    assert list(data["objects"]) == ["uio_teach.simulate"]
    assert list(data["modules"]) == ["uio_teach.linalg"]
    # the same anchor on another page is another object
    assert forget_objects(env, "book/api_detection", {"module-uio_teach.linalg"}) == 0


def test_a_label_written_before_a_heading_marks_its_section() -> None:
    """MyST leaves ``(sec-x-instructor)=`` before ``## Heading`` as the last child of the
    section before: that section is not the tutors', the next one is."""
    from docutils import nodes
    from editions import is_instructor_section, trailing_labels

    def section(title: str, *children: nodes.Node) -> nodes.section:
        node = nodes.section()
        node += nodes.title(title, title)
        for child in children:
            node += child
        return node

    page = nodes.section()
    label = nodes.target(names=["sec-api-grader-instructor"], ids=["sec-api-grader-instructor"])
    tools = section("Linear algebra", nodes.paragraph("", "rank"), label)
    grader = section("The grader")
    plain = section("Test signals")
    page += [tools, grader, plain]
    assert [is_instructor_section(s) for s in (tools, grader, plain)] == [False, True, False]
    # the label closes the section before, however deep its last subsection
    nested = section("Explorers", section("Sliders", nodes.paragraph("", "x"), label.deepcopy()))
    assert trailing_labels(nested)[0]["names"] == ["sec-api-grader-instructor"]
    assert not trailing_labels(grader)


def test_a_reference_to_a_forgotten_object_is_recognised() -> None:
    """References to the objects of a dropped section find no target any more: they are read as
    their text (by name, by a name relative to the current module, or as a module)."""
    from docutils import nodes
    from editions import dropped_object

    anchors = {"uio_teach.grading.merge.merge", "module-uio_teach.instructor.variants"}

    def ref(target: str, reftype: str = "func", module: str | None = None) -> nodes.Element:
        node = nodes.reference(reftarget=target, reftype=reftype, refdomain="py")
        node["py:module"] = module
        return node

    assert dropped_object(anchors, ref("uio_teach.grading.merge.merge"))
    assert dropped_object(anchors, ref("merge", module="uio_teach.grading.merge"))
    assert dropped_object(anchors, ref("uio_teach.instructor.variants", "mod"))
    assert not dropped_object(anchors, ref("uio_teach.simulate"))
    # a member of a class left out (a lab's parameter class in the student edition)
    assert dropped_object(
        {"uio_teach.worked.pa9.PA9Params"}, ref("uio_teach.worked.pa9.PA9Params.draw")
    )
    assert not dropped_object(anchors, ref("uio_teach.grading", "mod"))


def test_the_self_study_edition_folds_a_solution_behind_its_summary() -> None:
    from docutils import nodes
    from editions import FOLD_SUMMARY, fold_away

    section = nodes.section()
    section += nodes.paragraph("", "Exercise")
    solution = nodes.container("", nodes.literal_block("H = E @ pinv(C @ E)", "H = ..."))
    section += solution
    fold_away(solution)
    (box,) = [c for c in section.children if isinstance(c, nodes.container)]
    opening, inner, closing = box.children
    assert inner is solution and solution.parent is box
    assert (
        opening.astext().startswith("<details") and f"<summary>{FOLD_SUMMARY}" in opening.astext()
    )
    assert closing.astext() == "</details>" and " open" not in opening.astext()


def test_no_link_of_the_student_edition_is_dead(built_book: Path) -> None:
    """No page of the student edition links a page, a file or an anchor the edition leaves
    out (the API page's tutor-only sections are left out with every link into them)."""
    dead = dead_links(built_book)
    assert not dead, f"{len(dead)} dead links in the student edition: {dead[:20]}"


@pytest.mark.parametrize("page", [p for p in PAGES if p.startswith("book/api")])
def test_the_student_api_pages_hold_no_tutor_only_text(page: str, built_book: Path) -> None:
    text = _main_text(built_book / f"{page}.html")
    for words in ("answer key", "sandbox", "copies between groups", "uio_teach.grading"):
        assert words not in text, f"the student edition's {page} speaks of {words!r}"


@pytest.mark.slow  # a second build of the book (the instructor edition)
@pytest.mark.subprocess
def test_no_link_of_the_instructor_edition_is_dead(built_book: Path) -> None:
    import os
    import shutil
    import subprocess

    from conftest import jupyter_book

    out = ROOT / "_build" / "instructor"
    html = out / "_build" / "html"
    if not (
        html / "book" / "api.html"
    ).is_file():  # the accessibility test may have built it already
        cache = out / "_build" / ".jupyter_cache"
        shutil.rmtree(cache, ignore_errors=True)
        shutil.copytree(ROOT / "_build" / ".jupyter_cache", cache)
        command = [jupyter_book(), "build", ".", "--all", "-W", "-n", "--keep-going"]
        proc = subprocess.run(
            [*command, "--path-output", str(out)],
            cwd=ROOT,
            env={**os.environ, "UIO_TEACH_EDITION": "instructor"},
            capture_output=True,
            text=True,
            timeout=3600,
        )
        assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    dead = dead_links(html)
    assert not dead, f"{len(dead)} dead links in the instructor edition: {dead[:20]}"


def test_fonts_of_the_chapters_figures() -> None:
    """The figures' smallest text: the book's Matplotlib settings and every font size a chapter
    or the plotting module sets are at least FIGURE_FONT_PT."""
    from uio_teach import plotting

    assert plotting.FONT_SIZE >= FIGURE_FONT_PT
    rc = (ROOT / "book" / "matplotlibrc").read_text(encoding="utf-8")
    sizes = {k: float(v) for k, v in re.findall(r"^([\w.]*size):\s*([\d.]+)", rc, re.M)}
    assert sizes.get("font.size", 0) >= FIGURE_FONT_PT, sizes
    assert min(sizes.values()) >= FIGURE_FONT_PT, sizes
    small = []
    for page, source in SOURCES.items():
        for m in re.finditer(r"(fontsize|labelsize)\s*=\s*([\d.]+)", source.read_text("utf-8")):
            if float(m.group(2)) < FIGURE_FONT_PT:
                small.append(f"{page}: {m.group(0)}")
    assert not small, small


# --- the screen --------------------------------------------------------------------------------


def _explorer_text_px(image: dict, width: int) -> float:
    """The smallest text of an explorer picture as shown, in CSS pixels."""
    from uio_teach.explorers import scenario_of
    from uio_teach.explorers._figure import ExplorerFigure
    from uio_teach.explorers.static import (
        NARROW_DPI,
        NARROW_FONTSCALE,
        NARROW_PX,
        WIDE_FONTSCALE,
    )

    narrow = width <= NARROW_PX
    figure = ExplorerFigure(
        scenario_of("pa9"),
        dpi=NARROW_DPI if narrow else 144,
        fontscale=NARROW_FONTSCALE if narrow else WIDE_FONTSCALE,
        narrow=narrow,
    )
    return figure.smallest_text_pt() * figure.fig.dpi / 72 * image["width"] / image["natural"]


def measure(browser, book_server: str, page: str, width: int) -> dict:
    m = copy.deepcopy(page_facts(browser, book_server, page, width)["screen"])
    for image in m["images"]:
        if image["explorer"]:
            image["text_px"] = _explorer_text_px(image, width)
        elif image["output"]:
            image["text_px"] = FIGURE_FONT_PT * FIGURE_DPI / 72 * image["width"] / image["natural"]
    return m


@pytest.mark.browser
@pytest.mark.parametrize("width", [PHONE, DESKTOP])
@pytest.mark.parametrize("page", PAGES)
def test_readable_on_a_phone_and_a_desktop(page: str, width: int, book_server, browser) -> None:
    m = measure(browser, book_server, page, width)
    assert m["page"] <= m["viewport"], f"{page} at {width} px scrolls sideways: {m['loose'][:5]}"
    assert not m["loose"], f"{page} at {width} px: unframed, too wide: {m['loose'][:5]}"
    no_cue = [f["what"] for f in m["frames"] if not f["cue"]]
    assert not no_cue, f"{page} at {width} px: frames that scroll with no visible cue: {no_cue}"
    least = SMALLEST_TEXT_PX[width]
    small = [
        f"{i['src']} shown {i['width']:.0f} of {i['natural']} px: text {i['text_px']:.1f} px"
        for i in m["images"]
        if "text_px" in i and i["text_px"] < least - 0.05
    ]
    assert not small, f"{page} at {width} px: figure text under {least} px: {small}"
    squeezed = [
        i["src"]
        for i in m["images"]
        if abs(i["height"] / i["width"] - i["naturalHeight"] / i["natural"]) > 1.5 / i["width"]
    ]
    assert not squeezed, f"{page} at {width} px: pictures not at their aspect ratio: {squeezed}"
