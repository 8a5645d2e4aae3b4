"""The printed book: every PDF tagged, with its language, an outline of its headings, a text
alternative for every figure, its title in the metadata, page numbers, nothing past the margins.

``make pdf`` prints every page of the book and the whole book (``_ext/pdf_print.py``, which
refuses to finish when a PDF lacks any of the first five). These tests print, with the same
printer, a representative part of the test run's one book build: the landing page, a chapter
with figures, hidden cells and an explorer, a lab, the references, and the whole book of them
(title page, contents with page numbers); ``UIO_TEACH_PDF_PAGES=all`` prints every page instead
(several minutes on two cores). Each PDF is then read with pypdf and compared with the built page
it was printed from: the outline holds each heading's text, in order; the tags hold a heading
element for each heading and a figure, with the page's own alternative text, for each image.
"""

from __future__ import annotations

import os
import re
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest
from pypdf import PdfReader

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "_ext"))

import pdf_print  # noqa: E402

pytestmark = [pytest.mark.book, pytest.mark.browser, pytest.mark.slow]

# the landing page; a chapter with figures, hidden cells and an explorer; a lab; the references
PAGES = ("index", "pa9", "lab_pa9", "references")
MATH = "\x00"  # where a heading has mathematics (its text differs between TeX and the PDF)


class _Article(HTMLParser):
    """The headings (text, math marked) and images (alternative texts) of a page's article."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.title = ""
        self.headings: list[tuple[int, str]] = []
        self.alts: list[str] = []
        self._depth = 0  # inside <article class="bd-article">
        self._heading: list[str] | None = None
        self._level = 0
        self._skip = 0  # inside a heading's link mark or its math
        self._in_title = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        classes = (a.get("class") or "").split()
        if tag == "title":
            self._in_title = True
        if tag == "article" and "bd-article" in classes:
            self._depth = 1
            return
        if not self._depth:
            return
        if tag == "article":
            self._depth += 1
        if tag == "img":
            self.alts.append(a.get("alt") or "")
        if re.fullmatch(r"h[1-6]", tag):
            self._heading, self._level = [], int(tag[1])
        elif self._heading is not None:
            if self._skip:
                self._skip += 1
            elif "headerlink" in classes or "math" in classes:
                self._skip = 1
                if "math" in classes:
                    self._heading.append(MATH)

    def handle_endtag(self, tag: str) -> None:
        if tag == "title":
            self._in_title = False
        if not self._depth:
            return
        if tag == "article":
            self._depth -= 1
        if re.fullmatch(r"h[1-6]", tag) and self._heading is not None:
            text = " ".join("".join(self._heading).split())
            self.headings.append((self._level, text))
            self._heading = None
        elif self._heading is not None and self._skip:
            self._skip -= 1

    def handle_data(self, data: str) -> None:
        if self._in_title:
            self.title += data
        if self._heading is not None and not self._skip:
            self._heading.append(data)


def article(html_file: Path) -> _Article:
    parser = _Article()
    parser.feed(html_file.read_text(encoding="utf-8"))
    return parser


def heading_pattern(text: str) -> re.Pattern[str]:
    """A heading's text as printed: its words as on the page, its mathematics any text."""
    parts = [re.escape(part.strip()) for part in text.split(MATH)]
    return re.compile(r"\s*.+?\s*".join(parts).replace(r"\ ", r"\s+"))


@pytest.fixture(scope="module")
def printed(built_book: Path, tmp_path_factory) -> tuple[pdf_print.Printed, list]:
    everything = os.environ.get("UIO_TEACH_PDF_PAGES") == "all"
    out = tmp_path_factory.mktemp("pdf")
    result = pdf_print.print_site(built_book, out, only=() if everything else PAGES)
    pages = [p for p in pdf_print.site_pages(built_book) if everything or p.name in PAGES]
    return result, pages


def outline(reader: PdfReader) -> list[tuple[str, int]]:
    """The outline's entries, depth first: title and page (from 1)."""
    entries = []

    def walk(items: list) -> None:
        for item in items:
            if isinstance(item, list):
                walk(item)
            else:
                entries.append((str(item.title), reader.get_destination_page_number(item) + 1))

    walk(reader.outline)
    return entries


def _pdf(printed, name: str) -> Path:
    result, _ = printed
    (path,) = [p for p in result.pdfs if p.name == f"{name}.pdf"]
    return path


def test_every_page_and_the_whole_book_are_printed(printed) -> None:
    result, pages = printed
    names = sorted(p.name for p in result.pdfs)
    assert names == sorted([f"{p.name}.pdf" for p in pages] + [f"{pdf_print.BOOK_NAME}.pdf"])
    assert all(path.stat().st_size > 0 for path in result.pdfs)


def test_every_pdf_is_tagged_with_language_outline_title_and_figure_texts(printed) -> None:
    result, _ = printed
    problems = [line for path in result.pdfs for line in pdf_print.audit_pdf(path)]
    assert not problems, "\n".join(problems)
    for path in result.pdfs:
        catalog = PdfReader(path).trailer["/Root"]
        assert str(catalog["/Lang"]) == "en", path.name  # the pages' <html lang="en">


def test_nothing_reaches_past_the_margins(printed) -> None:
    result, _ = printed
    assert not result.overflow, result.overflow


@pytest.mark.parametrize("name", PAGES)
def test_a_page_pdf_is_its_page(printed, built_book: Path, name: str) -> None:
    """Title, outline, heading tags and figures of a page's PDF are those of its page."""
    page = next(p for p in printed[1] if p.name == name)
    source = article(built_book / page.path)
    reader = PdfReader(_pdf(printed, name))
    title = " ".join(source.title.split()).removesuffix(" \u2014 Unknown Input Observers")
    assert reader.metadata.title == title
    entries = [title for title, _ in outline(reader)]
    assert len(entries) == len(source.headings), (entries, source.headings)
    for (_, text), entry in zip(source.headings, entries, strict=True):
        assert heading_pattern(text).fullmatch(entry), (text, entry)
    tree = pdf_print.structure(reader)
    tags = [t for t in tree["types"] if re.fullmatch(r"/H[1-6]", t)]
    assert tags == [f"/H{level}" for level, _ in source.headings]
    assert tree["figure_alts"] == source.alts


@pytest.mark.parametrize("name", PAGES)
def test_every_sheet_has_its_page_number(printed, name: str) -> None:
    reader = PdfReader(_pdf(printed, name))
    total = len(reader.pages)
    for number, sheet in enumerate(reader.pages, start=1):
        assert f"{number} / {total}" in sheet.extract_text(), (name, number)


def _uris(reader: PdfReader) -> list[str]:
    uris = []
    for sheet in reader.pages:
        for annot in sheet.get("/Annots") or []:
            action = annot.get_object().get("/A")
            if action is not None and "/URI" in action.get_object():
                uris.append(str(action.get_object()["/URI"]))
    return uris


def test_no_link_points_at_the_printing_server(printed) -> None:
    """Links to other pages of the site (which would point at the local server) are text."""
    result, _ = printed
    for path in result.pdfs:
        for uri in _uris(PdfReader(path)):
            assert uri.startswith(("https://", "http://", "mailto:")), (path.name, uri)
            assert not re.match(r"https?://(127\.|localhost)", uri), (path.name, uri)


def test_the_whole_book_has_every_page_and_a_table_of_contents(printed, built_book: Path):
    """The book's outline: the contents, then every page's headings in order; each chapter
    listed in the contents with the page it starts on."""
    result, pages = printed
    reader = PdfReader(_pdf(printed, pdf_print.BOOK_NAME))
    assert reader.metadata.title == "Unknown Input Observers"
    entries = outline(reader)
    expected = [(1, "Contents")]
    for page in pages:
        expected += article(built_book / page.path).headings
    assert len(entries) == len(expected)
    for (_, text), (title, _) in zip(expected, entries, strict=True):
        assert heading_pattern(text).fullmatch(title), (text, title)
    starts = {
        title: first
        for (title, first), (level, _) in zip(entries, expected, strict=True)
        if level == 1
    }
    contents_end = min(n for title, n in starts.items() if title != "Contents")
    contents = "".join(
        "".join(reader.pages[i].extract_text().split())
        for i in range(starts["Contents"] - 1, contents_end - 1)
    )
    for title, first in starts.items():
        if title != "Contents":
            assert "".join(title.split()) + str(first) in contents, (title, first)
    tree = pdf_print.structure(reader)
    alts = [alt for page in pages for alt in article(built_book / page.path).alts]
    assert tree["figure_alts"] == alts


_FORMULA = re.compile(
    r'<(?P<tag>span|div) class="math notranslate nohighlight"[^>]*>\s*'
    r'(?:<span class="eqno">.*?</span>)?\s*(?:\\\(|\\\[|\$\$?)?'  # an equation's number first
    r"(?P<tex>.*?)(?:\\\)|\\\]|\$\$?)?\s*</(?P=tag)>",
    flags=re.S,
)


def page_formulas(html_file: Path) -> list[str]:
    """The TeX of every formula of a page's article, in the page's order."""
    import html as html_module

    text = html_file.read_text(encoding="utf-8")
    start = text.find('<article class="bd-article"')
    end = text.find("</article>", start)
    return [
        " ".join(html_module.unescape(m["tex"]).split()) for m in _FORMULA.finditer(text[start:end])
    ]


@pytest.mark.parametrize("name", PAGES)
def test_every_formula_is_tagged_as_a_formula_with_its_tex_in_the_pages_order(
    printed, built_book: Path, name: str
) -> None:
    page = next(p for p in printed[1] if p.name == name)
    wanted = page_formulas(built_book / page.path)
    tree = pdf_print.structure(PdfReader(_pdf(printed, name)))
    said = [" ".join((alt or "").split()) for alt in tree["formula_alts"]]
    assert said == wanted, (name, len(said), len(wanted))
    # and none is left a loose figure: every figure is a picture of the page
    assert not set(tree["figure_alts"]) & set(wanted)
