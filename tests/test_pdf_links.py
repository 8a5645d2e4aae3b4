"""The built pages link their PDFs only in a build that prints them (``_ext/downloads.py``).

A build with ``UIO_TEACH_PDF=1`` (``make pdf``) puts a link to the page's PDF and to the whole
book's in the download menu (in place of the theme's "print this page") and under the title,
after the notebook's link; the names are those the printer (``_ext/pdf_print.py``) gives the
files. A build without it links none and leaves the theme's menu as it was.
"""

from __future__ import annotations

import posixpath
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "_ext"))

import downloads  # noqa: E402
import pdf_print  # noqa: E402

BODY = (
    '<section><h1>4. PA9<a class="headerlink" href="#pa9">#</a></h1>'
    '<p class="chapter-notebook"><a href="../_notebooks/pa9.ipynb">notebook</a></p><p>Text</p>'
)


def _app(pdf: bool, edition: str = "student") -> SimpleNamespace:
    config = SimpleNamespace(uio_teach_pdf=pdf, root_doc="book/index", uio_teach_edition=edition)
    return SimpleNamespace(config=config, builder=SimpleNamespace(format="html"))


def _context(pagename: str) -> dict:
    here = posixpath.dirname(pagename)

    def pathto(target: str, resource: int = 0) -> str:
        return posixpath.relpath(target, here or ".")

    theme_print = {"type": "javascript", "javascript": "window.print()", "text": ".pdf"}
    theme_print["label"] = "download-pdf-button"
    menu = {"label": "download-buttons", "buttons": [{"label": "x"}, theme_print]}
    return {"pathto": pathto, "header_buttons": [menu], "body": BODY}


def test_a_printing_build_links_the_page_and_the_book_in_the_menu_and_under_the_title():
    context = _context("book/pa9")
    downloads.page_downloads(_app(True), "book/pa9", "page.html", context, None)
    buttons = context["header_buttons"][0]["buttons"]
    urls = {b["label"]: b.get("url") for b in buttons}
    assert urls["download-pdf-button"] == "../_pdf/pa9.pdf"
    assert urls["download-book-pdf-button"] == "../_pdf/uio-teach.pdf"
    assert not any(b.get("type") == "javascript" for b in buttons)  # the theme's print is gone
    body = context["body"]
    notebook, pdfs = body.index('class="chapter-notebook"'), body.index('class="page-downloads"')
    assert body.index("</h1>") < notebook < pdfs < body.index("<p>Text</p>")
    assert 'href="../_pdf/pa9.pdf"' in body and 'href="../_pdf/uio-teach.pdf"' in body


def test_the_links_name_the_files_the_printer_writes():
    assert pdf_print.pdf_name("book/index", "book/pa9") == "pa9"
    assert pdf_print.pdf_name("book/index", "book/index") == "index"
    assert pdf_print.pdf_name("index", "labs/one") == "labs-one"
    app = _app(True, "instructor")
    assert downloads.book_pdf_name(app) == f"{pdf_print.BOOK_NAME}-instructor"
    context = _context("book/index")
    downloads.page_downloads(app, "book/index", "page.html", context, None)
    assert 'href="../_pdf/uio-teach-instructor.pdf"' in context["body"]


def test_a_build_that_does_not_print_links_no_pdf():
    context = _context("book/pa9")
    downloads.page_downloads(_app(False), "book/pa9", "page.html", context, None)
    assert context["body"] == BODY
    assert context["header_buttons"][0]["buttons"][1]["javascript"] == "window.print()"


@pytest.mark.parametrize("value", ["2", "maybe"])
def test_a_bad_setting_of_the_printing_is_refused(monkeypatch, value):
    monkeypatch.setenv(downloads.PDF_VAR, value)
    config = SimpleNamespace()
    app = SimpleNamespace(confdir=str(ROOT))
    with pytest.raises(Exception, match=f"{downloads.PDF_VAR}="):
        downloads.read_pdf_setting(app, config)


def test_the_wheel_is_named_from_the_project():
    name = downloads.wheel_name(ROOT)
    assert name.startswith("uio_teach-") and name.endswith("-py3-none-any.whl")
