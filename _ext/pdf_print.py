"""Print the built book as tagged, accessible PDFs: one per page, and the whole book.

Run from the top folder of the repository (``make pdf`` does it through the book build, see
``_ext/downloads.py``)::

    python _ext/pdf_print.py _build/html _build/pdf           # every page and the whole book
    python _ext/pdf_print.py _build/html out --only pa9 lab_pa9 --no-book

The built HTML site is served on 127.0.0.1 (every request that leaves this server is refused:
the printing is offline) and printed by Debian's Chromium through Playwright, as many pages at a
time as there are cores. Each page is printed once MathJax has typeset it, with the print
stylesheet ``_static/print.css`` (no site navigation, buttons or sidebars; code wrapped at the
margin; figures and tables kept whole), its hidden cells opened, and page numbers in the margin.
Chromium writes a tagged PDF (structure tree, ``/MarkInfo``, ``/Lang`` from the page's ``lang``,
a ``/Figure`` with ``/Alt`` for every image) with an outline from the headings; this module then
adds, as an incremental update that keeps all of that, the title of the document (the page's
title, not its address) to the metadata and asks viewers to show it.

The whole book (``uio-teach.pdf``) is one HTML document assembled in the browser from the site's
pages in the order of its navigation: a title page, a table of contents with page numbers (the
book is printed a second time with the numbers the first printing gave), and every page as a
chapter, its links to other pages turned into links inside the book. Links of a single page's
PDF to other pages of the site are printed as plain text (they would point at the local server).
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import functools
import html
import os
import posixpath
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from html.parser import HTMLParser
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import urljoin, urlsplit

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
BOOK_NAME = "uio-teach"  # the whole book: <BOOK_NAME>.pdf
# A4, with room in the top and bottom margins for the running head and the page number.
PDF_OPTIONS = {
    "format": "A4",
    "margin": {"top": "18mm", "bottom": "18mm", "left": "16mm", "right": "16mm"},
    "print_background": True,
    "display_header_footer": True,
    "tagged": True,
    "outline": True,
}
# The sheet's printable width in CSS pixels (A4, 210 mm less the margins): the pages are laid out
# at this width before printing, so what does not fit on paper is found (and scaled) first.
VIEWPORT = {"width": round((210 - 32) / 25.4 * 96), "height": 1100}
# Seconds a page may take to load and typeset, and a print to finish: a limit, not a timing.
PAGE_LIMIT = 300


class PrintError(RuntimeError):
    """A page could not be printed as it should (math left untypeset, a request refused...)."""


@dataclass(frozen=True)
class Page:
    """One page of the site: its file (relative to the site), PDF name, title and part."""

    path: str
    name: str
    title: str
    part: str = ""


@dataclass
class Printed:
    """What was printed: the PDF files, and the seconds the whole printing took."""

    pdfs: list[Path] = field(default_factory=list)
    seconds: float = 0.0
    pages: int = 0  # sheets of paper, over every PDF
    # per PDF, what reaches past the margins of the sheet (cut off on paper): nothing, we hope
    overflow: dict[str, list[str]] = field(default_factory=dict)


# --- the site's pages, in the order of its navigation --------------------------------------------


class _NavParser(HTMLParser):
    """The root page's title and the links of the site's main navigation, with their parts."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.title = ""
        self.links: list[tuple[str, str, str]] = []  # (href, text, part)
        self._in_title = False
        self._nav_depth = 0
        self._caption = False
        self._part = ""
        self._href: str | None = None
        self._text: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        classes = (a.get("class") or "").split()
        if tag == "title":
            self._in_title = True
        if tag == "nav" and "bd-docs-nav" in classes:
            self._nav_depth = 1
        elif tag == "nav" and self._nav_depth:
            self._nav_depth += 1
        if not self._nav_depth:
            return
        if tag == "p" and "caption" in classes:
            self._caption, self._part = True, ""
        if tag == "a" and "reference" in classes and "internal" in classes:
            self._href, self._text = a.get("href") or "", []

    def handle_endtag(self, tag: str) -> None:
        if tag == "title":
            self._in_title = False
        if not self._nav_depth:
            return
        if tag == "nav":
            self._nav_depth -= 1
        if tag == "p":
            self._caption = False
        if tag == "a" and self._href is not None:
            text = " ".join("".join(self._text).split())
            self.links.append((self._href, text, self._part))
            self._href = None

    def handle_data(self, data: str) -> None:
        if self._in_title:
            self.title += data
        if self._caption:
            self._part += data.strip()
        if self._href is not None:
            self._text.append(data)


def pdf_name(root_doc: str, docname: str) -> str:
    """The PDF of a page (without ``.pdf``): its name relative to the root page's folder.

    ``book/pa9`` of a book whose root is ``book/index`` prints to ``pa9.pdf``; a page in a
    folder of its own to ``folder-page.pdf``.
    """
    folder = posixpath.dirname(root_doc)
    return (posixpath.relpath(docname, folder) if folder else docname).replace("/", "-")


def root_page(site: Path) -> str:
    """The site's first page, relative to the site (``index.html`` may only redirect to it)."""
    index = site / "index.html"
    if not index.is_file():
        raise PrintError(f"{index} not found: build the book first (make book)")
    text = index.read_text(encoding="utf-8")
    marker = 'http-equiv="Refresh" content="0; url='
    if marker in text:
        return text.split(marker, 1)[1].split('"', 1)[0]
    return "index.html"


def site_pages(site: Path) -> list[Page]:
    """Every page of the built site, in the order of its navigation, the root page first."""
    root = root_page(site)
    parser = _NavParser()
    parser.feed((site / root).read_text(encoding="utf-8"))
    if not parser.links:
        raise PrintError(f"{site / root} has no navigation (.bd-docs-nav): not a built book?")
    pages, seen = [], set()
    for href, text, part in parser.links:
        path = urljoin(root, href.split("#", 1)[0]) if href not in ("", "#") else root
        if path in seen or urlsplit(href).scheme:
            continue
        seen.add(path)
        name = pdf_name(root.removesuffix(".html"), path.removesuffix(".html"))
        pages.append(Page(path=path, name=name, title=text, part=part))
    return pages


# --- serving the site ----------------------------------------------------------------------------


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:
        pass


@contextmanager
def serve(site: Path) -> Iterator[str]:
    """Serve ``site`` on 127.0.0.1 at a free port; yield its base URL (ending in ``/``)."""
    handler = functools.partial(_QuietHandler, directory=str(site))
    server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()


# --- in the browser ------------------------------------------------------------------------------

# Wait for MathJax (loaded with `defer`) to typeset the page; the math it could not typeset.
TYPESET_JS = """
async () => {
  await document.fonts.ready;
  const math = document.querySelectorAll('span.math, div.math');
  if (!math.length) return [];
  if (!window.MathJax || !window.MathJax.startup || !window.MathJax.startup.promise) {
    return ['MathJax did not load'];
  }
  await window.MathJax.startup.promise;
  if (window.MathJax.typesetPromise) await window.MathJax.typesetPromise();
  const bad = [...document.querySelectorAll('span.math, div.math')]
    .filter((e) => !e.querySelector('mjx-container') || e.querySelector('mjx-merror'))
    .map((e) => e.textContent.slice(0, 80));
  await document.fonts.ready;
  return bad;
}
"""

# The page on paper: hidden cells and notes open; links to other pages of the site (which would
# point at this local server) printed as text, links inside the page and to the web kept.
PREPARE_JS = """
async (opts) => {
  for (const d of document.querySelectorAll('details')) d.open = true;
  // a figure's picture for narrow screens gives way to its full-size one, as in the whole book
  // the image is the PDF's figure, with its text alternative; an HTML <figure> around it is a
  // box only (tagged as a figure of its own it would be one without a text alternative, and a
  // reader of the PDF would skip what it holds, the description in words included)
  for (const f of document.querySelectorAll('figure')) {
    if (f.querySelector('img[alt]') && !f.hasAttribute('role')) f.setAttribute('role', 'none');
  }
  const sources = [...document.querySelectorAll('picture > source[media]')];
  for (const s of sources) s.remove();
  // every picture loaded before printing, those the page leaves until the reader scrolls too
  const lazy = [...document.images].filter((img) => img.loading === 'lazy');
  for (const img of lazy) img.loading = 'eager';
  if (sources.length || lazy.length) {
    await Promise.all([...document.images].map((img) => img.decode().catch(() => null)));
  }
  for (const e of document.querySelectorAll('.toggle-hidden')) e.classList.remove('toggle-hidden');
  if (opts.title) document.title = opts.title;
  if (!opts.keepLinks) {
    const here = location.href.split('#')[0];
    for (const a of document.querySelectorAll('a[href]')) {
      const url = new URL(a.getAttribute('href'), location.href);
      const local = url.origin === location.origin;
      if (local && url.href.split('#')[0] === here) continue;
      if (!local && ['http:', 'https:', 'mailto:'].includes(url.protocol)) continue;
      a.removeAttribute('href');
    }
  }
  // what is wider than the sheet: a display equation or a table scaled down to fit, then
  // whatever still reaches past the margin (it would be cut off on paper)
  const article = document.querySelector('article.bd-article') || document.body;
  const width = article.getBoundingClientRect().width;
  const fit = 'mjx-container[display="true"], table, .uio-static-explorer, div.output > pre';
  for (const e of article.querySelectorAll(fit)) {
    const room = e.parentElement.getBoundingClientRect().width;
    if (e.scrollWidth > room + 1 && room > 0) e.style.zoom = String(room / e.scrollWidth);
  }
  const right = article.getBoundingClientRect().right + 1;
  const overflow = [];
  for (const e of article.querySelectorAll('pre, img, table, mjx-container, code, p, li, svg')) {
    const box = e.getBoundingClientRect();
    if (box.width > 0 && box.right > right) {
      const where = e.closest('section[id]');
      overflow.push(`${e.tagName.toLowerCase()} ${Math.round(box.right - right + 1)}px past ` +
        `the margin in #${where ? where.id : ''}: ${e.textContent.trim().slice(0, 60)}`);
    }
  }
  // the headings that will be printed, in order: the PDF's outline is made from them
  const headings = [...document.querySelectorAll('h1, h2, h3, h4, h5, h6')]
    .filter((h) => h.getClientRects().length > 0)
    .map((h) => {
      const copy = h.cloneNode(true);
      for (const e of copy.querySelectorAll('a.headerlink')) e.remove();
      for (const m of copy.querySelectorAll('mjx-container')) {  // math: as its MathML reads
        const mml = m.querySelector('mjx-assistive-mml');
        m.replaceWith(document.createTextNode(mml ? mml.textContent : ''));
      }
      return {level: Number(h.tagName[1]), text: copy.textContent.replace(/\\s+/g, ' ').trim()};
    });
  // the formulas: over each, a transparent image as large as the formula whose text
  // alternative is its TeX, which Chromium tags as a /Figure with that /Alt where the formula
  // stands in the text; finish_pdf makes each a /Formula. The formula's glyphs stay as
  // printed; its hidden MathML copy (for screen readers of the web page) is left out of the
  // print: the PDF's reader reads the /Alt.
  const items = window.MathJax && window.MathJax.startup && window.MathJax.startup.document
    ? Array.from(window.MathJax.startup.document.math) : [];
  const shown = items.filter((item) => item.typesetRoot && item.typesetRoot.isConnected &&
    item.typesetRoot.getClientRects().length > 0);
  shown.sort((a, b) => a.typesetRoot.compareDocumentPosition(b.typesetRoot) &
    Node.DOCUMENT_POSITION_FOLLOWING ? -1 : 1);
  const formulas = [];
  const BLANK = 'data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR4' +
    '2mP8/5+hHgAHggJ/PchI7wAAAABJRU5ErkJggg==';
  for (const item of shown) {
    const root = item.typesetRoot;
    const tex = String(item.math).replace(/\\s+/g, ' ').trim();
    for (const m of root.querySelectorAll('mjx-assistive-mml')) m.remove();
    const img = document.createElement('img');
    img.className = 'print-formula';
    img.alt = tex;
    img.src = BLANK;
    img.style.cssText = 'position:absolute;left:0;top:0;width:100%;height:100%;' +
      'margin:0;padding:0;border:0;opacity:0.01';
    root.style.position = 'relative';
    root.insertBefore(img, root.firstChild);
    formulas.push(tex);
  }
  const author = document.querySelector('p.component-author');
  return {
    headings,
    formulas,
    overflow,
    width,
    author: author ? author.textContent.trim().replace(/^By\\s+/, '') : '',
  };
}
"""

# The whole book in one document, built in the root page: a title page, the contents, then every
# page of the site as a chapter. Ids get the page's name as a prefix (they would clash between
# pages), links between pages become links inside the book, images keep their files.
ASSEMBLE_JS = """
async (book) => {
  const article = document.querySelector('article.bd-article');
  const byline = document.querySelector('p.component-author');
  book.author = byline ? byline.textContent.trim() : '';
  const licence = document.querySelector('.extra_footer');
  book.licence = licence ? licence.innerHTML : '';
  const pages = new Map(book.pages.map((p) => [new URL(p.path, book.base).href, p]));
  const parts = [];
  const idAttrs = ['aria-labelledby', 'aria-describedby', 'for', 'headers'];
  for (const page of book.pages) {
    const url = new URL(page.path, book.base).href;
    const response = await fetch(url);
    if (!response.ok) throw new Error(`${url}: ${response.status}`);
    const doc = new DOMParser().parseFromString(await response.text(), 'text/html');
    const source = doc.querySelector('article.bd-article');
    if (!source) throw new Error(`${url}: no article`);
    const chapter = document.createElement('section');
    chapter.className = 'print-chapter';
    chapter.id = `${page.name}--top`;
    for (const s of source.querySelectorAll('script, p.chapter-notebook, p.page-downloads')) {
      s.remove();
    }
    for (const e of source.querySelectorAll('[id]')) e.id = `${page.name}--${e.id}`;
    for (const e of source.querySelectorAll(idAttrs.map((a) => `[${a}]`).join(','))) {
      for (const a of idAttrs) {
        if (e.hasAttribute(a)) {
          e.setAttribute(a, e.getAttribute(a).split(/\\s+/).map((v) => `${page.name}--${v}`)
            .join(' '));
        }
      }
    }
    for (const img of source.querySelectorAll('img[src]')) {
      img.setAttribute('src', new URL(img.getAttribute('src'), url).href);
      img.removeAttribute('loading');  // every image loaded before printing, not when seen
    }
    for (const s of source.querySelectorAll('source[srcset]')) s.remove();
    for (const a of source.querySelectorAll('a[href]')) {
      const target = new URL(a.getAttribute('href'), url);
      const other = pages.get(target.href.split('#')[0]);
      if (other) {
        const hash = decodeURIComponent(target.hash.slice(1));
        a.setAttribute('href', `#${other.name}--${hash || 'top'}`);
      } else if (target.origin === location.origin) {
        a.removeAttribute('href');  // a download of the site: nothing to follow on paper
      }
    }
    while (source.firstChild) chapter.appendChild(source.firstChild);
    // a heading's content for the contents: its links dropped (no link inside a link)
    const inner = (h) => {
      const copy = h.cloneNode(true);
      for (const a of copy.querySelectorAll('a.headerlink')) a.remove();
      for (const a of copy.querySelectorAll('a')) a.replaceWith(...a.childNodes);
      for (const e of copy.querySelectorAll('[id]')) e.removeAttribute('id');
      return copy.innerHTML;
    };
    // the contents point at the headings themselves: a section's box may begin at the foot of
    // the sheet before the one its heading is printed on
    const h1 = chapter.querySelector('h1');
    if (h1 && !h1.id) h1.id = `${page.name}--title`;
    const sections = [...chapter.querySelectorAll('h2')].map((h, i) => {
      if (!h.id) h.id = `${page.name}--heading-${i + 1}`;
      return {id: h.id, html: inner(h)};
    });
    parts.push({page, chapter, h1: h1 ? inner(h1) : page.title, h1id: h1 ? h1.id : chapter.id,
                sections});
  }
  // the title page and the contents
  const cover = document.createElement('section');
  cover.className = 'print-cover';
  cover.innerHTML = `<p class="print-cover-title">${book.title}</p>` +
    (book.subtitle ? `<p class="print-cover-subtitle">${book.subtitle}</p>` : '') +
    (book.author ? `<p class="print-cover-subtitle">${book.author}</p>` : '') +
    `<p class="print-cover-meta">${book.meta}</p>` +
    (book.licence ? `<div class="print-cover-licence">${book.licence}</div>` : '');
  const toc = document.createElement('nav');
  toc.className = 'print-toc';
  toc.setAttribute('aria-labelledby', 'print-toc-title');
  let list = '<h1 id="print-toc-title">Contents</h1>';
  let part = null;
  for (const p of parts) {
    if (p.page.part !== part) {
      if (part !== null) list += '</ol>';
      part = p.page.part;
      list += (part ? `<p class="print-toc-part">${part}</p>` : '') + '<ol>';
    }
    const entry = (id, inner, level) =>
      `<li class="print-toc-${level}"><a href="#${id}"><span class="print-toc-text">` +
      `${inner}</span><span class="print-toc-page" data-target="${id}">000</span></a></li>`;
    list += entry(p.h1id, p.h1, 'chapter');
    const subs = p.sections.filter((s) => s.id).map((s) => entry(s.id, s.html, 'section'));
    if (subs.length) list += `<li class="print-toc-sections"><ol>${subs.join('')}</ol></li>`;
  }
  list += '</ol>';
  toc.innerHTML = list;
  article.replaceChildren(cover, toc, ...parts.map((p) => p.chapter));
  // the layout, and so the page numbers, are final only once every image has its size
  await Promise.all([...document.images].map((img) => img.complete ? null :
    new Promise((resolve) => { img.addEventListener('load', resolve);
                               img.addEventListener('error', resolve); })));
  const broken = [...document.images].filter((img) => !img.naturalWidth).map((img) => img.src);
  if (broken.length) throw new Error(`images that do not load: ${broken.slice(0, 3)}`);
  document.title = book.title;
  for (const e of document.querySelectorAll('#jb-print-docs-body, .bd-sidebar-secondary')) {
    e.remove();
  }
  return parts.length;
}
"""

# Every font the page declares loaded (MathJax's are loaded as glyphs first appear: a cell opened
# for printing may need one that the screen did not, and a late font changes the layout).
FONTS_JS = """
async () => {
  await Promise.all([...document.fonts].map((f) => f.load().catch(() => null)));
  await document.fonts.ready;
}
"""

# Page numbers into the contents (from the first printing), and what they read.
SET_TOC_PAGES_JS = """
(numbers) => {
  for (const e of document.querySelectorAll('.print-toc-page')) {
    const n = numbers[e.dataset.target];
    e.textContent = n === undefined ? '' : String(n);
  }
}
"""

# Styles of the assembled book only (the title page and the contents).
BOOK_CSS = """
@media print {
  .print-cover { break-after: page; text-align: center; padding-top: 28%; }
  .print-cover p { margin: 0 0 0.6em; }
  .print-cover-title { font-size: 2.6em; font-weight: 600; margin-bottom: 0.4em !important; }
  .print-cover-subtitle { font-size: 1.25em; }
  .print-cover-meta { margin-top: 5em !important; font-size: 0.95em; }
  .print-cover-licence { margin-top: 2em !important; font-size: 0.85em; }
  nav.print-toc { break-after: page; display: block !important; }
  nav.print-toc ol { list-style: none !important; padding-left: 0 !important; margin: 0; }
  nav.print-toc li.print-toc-sections > ol { padding-left: 1.8em !important; }
  nav.print-toc li { display: block !important; break-inside: avoid; margin: 0; }
  nav.print-toc li > a { display: flex !important; align-items: baseline; gap: 0.5em;
                         color: #000 !important; text-decoration: none !important; }
  nav.print-toc .print-toc-part { font-weight: 600; margin: 0.9em 0 0.2em; }
  nav.print-toc li.print-toc-chapter { margin-top: 0.35em; font-weight: 600; }
  nav.print-toc li.print-toc-section { font-size: 0.9em; line-height: 1.35; }
  nav.print-toc .print-toc-text { flex: 0 1 auto; }
  nav.print-toc .print-toc-page { margin-left: auto; flex: none; min-width: 2.2em;
                                  text-align: right; font-variant-numeric: tabular-nums; }
  section.print-chapter { break-before: page; }
}
"""


def _header(left: str, right: str) -> str:
    style = (
        "font-size:7.5pt;color:#333;width:100%;margin:0 16mm;display:flex;"
        "justify-content:space-between;font-family:sans-serif"
    )
    return (
        f'<div style="{style}"><span>{html.escape(left)}</span>'
        f"<span>{html.escape(right)}</span></div>"
    )


FOOTER = (
    '<div style="font-size:8pt;color:#333;width:100%;text-align:center;font-family:sans-serif">'
    '<span class="pageNumber"></span> / <span class="totalPages"></span></div>'
)


def _running_head(job: Job) -> str:
    """The book's name at the top of a page's sheets, with its edition when it has one."""
    return f"{job.book_title} \u2014 {job.subtitle}" if job.subtitle else job.book_title


def _page_title(title: str, book: str) -> str:
    """A page's title without the book's name that Sphinx appends (``Page — Book``)."""
    for sep in (" \u2014 ", " - "):
        if title.endswith(sep + book):
            return title[: -len(sep + book)]
    return title


# --- finishing a PDF -----------------------------------------------------------------------------


def outline_items(root) -> list:  # noqa: ANN001 (a pypdf dictionary)
    """The items of a PDF outline (``/Outlines``), depth first, in reading order."""
    items = []

    def walk(item) -> None:  # noqa: ANN001
        while item is not None:
            item = item.get_object()
            items.append(item)
            walk(item.get("/First"))
            item = item.get("/Next")

    walk(root.get_object().get("/First"))
    return items


def finish_pdf(
    path: Path,
    title: str,
    author: str = "",
    headings: Sequence[str] | None = None,
    formulas: Sequence[str] | None = None,
) -> int:
    """Write the title (and author) into the PDF's metadata and ask viewers to show the title.

    With ``headings`` (the printed headings' texts, in order), the outline's entries are
    named by them: Chromium takes their text from the printed lines, where a heading broken over
    two lines loses the space between them and one broken across two pages is named twice.

    With ``formulas`` (the printed formulas' TeX, in the page's order), each is tagged as a
    ``/Formula`` with its TeX as ``/Alt``: Chromium writes a formula printed as an image of its
    TeX as a ``/Figure`` with that ``/Alt``, in the structure's reading order; they are found
    in that order, and a formula missing there (untagged, or read out of the page's order)
    fails the printing.

    An incremental update: Chromium's structure tree, outline (destinations) and language stay
    as written. Returns the number of pages.
    """
    from pypdf import PdfWriter
    from pypdf.generic import BooleanObject, DictionaryObject, NameObject, TextStringObject

    writer = PdfWriter(path, incremental=True)
    metadata = {"/Title": title, "/Creator": "uio-teach (_ext/pdf_print.py, Chromium)"}
    if author:
        metadata["/Author"] = author
    writer.add_metadata(metadata)
    prefs = writer.root_object.get("/ViewerPreferences")
    prefs = prefs.get_object() if prefs is not None else DictionaryObject()
    prefs[NameObject("/DisplayDocTitle")] = BooleanObject(True)
    writer.root_object[NameObject("/ViewerPreferences")] = prefs
    if headings is not None:
        outline = writer.root_object.get("/Outlines")
        items = outline_items(outline) if outline is not None else []
        if len(items) != len(headings):
            raise PrintError(
                f"{path.name}: {len(items)} outline entries for {len(headings)} headings"
            )
        for item, text in zip(items, headings, strict=True):
            item[NameObject("/Title")] = TextStringObject(text)
    if formulas:
        tagged = tag_formulas(writer.root_object, formulas)
        if tagged < len(formulas):
            raise PrintError(
                f"{path.name}: {tagged} of {len(formulas)} formulas tagged in the page's order; "
                f"the first not found: {formulas[tagged]!r}"
            )
    pages = len(writer.pages)
    with open(path, "wb") as out:
        writer.write(out)
    return pages


def _struct_elements(root) -> Iterator:  # noqa: ANN001 (a pypdf dictionary)
    """The structure elements under ``root`` (a catalog), in reading order (depth first)."""
    from pypdf.generic import ArrayObject, DictionaryObject

    tree = root.get("/StructTreeRoot")
    if tree is None:
        return

    def walk(node):  # noqa: ANN001, ANN202
        node = node.get_object()
        if isinstance(node, ArrayObject):
            for kid in node:
                yield from walk(kid)
            return
        if not isinstance(node, DictionaryObject) or "/S" not in node:
            return
        yield node
        if "/K" in node:
            yield from walk(node["/K"])

    tree = tree.get_object()
    if "/K" in tree:
        yield from walk(tree["/K"])


def tag_formulas(root, formulas: Sequence[str]) -> int:  # noqa: ANN001 (a pypdf dictionary)
    """Tag the figures whose ``/Alt`` is a formula's TeX, in order, as ``/Formula``; how many of
    ``formulas`` were found (a figure of another alternative text, a picture, is left alone)."""
    from pypdf.generic import NameObject

    found = 0
    for node in _struct_elements(root):
        if found == len(formulas):
            break
        if node["/S"] in ("/Figure", "/Formula") and " ".join(
            str(node.get("/Alt", "")).split()
        ) == " ".join(formulas[found].split()):
            node[NameObject("/S")] = NameObject("/Formula")
            found += 1
    return found


def destination_pages(pdf: bytes, names: Sequence[str]) -> dict[str, int]:
    """The page (from 1) of each named destination of ``pdf`` among ``names``."""
    import io

    from pypdf import PdfReader

    reader = PdfReader(io.BytesIO(pdf))
    wanted = set(names)
    out = {}
    for key, dest in reader.named_destinations.items():
        name = key.removeprefix("/")  # the keys of a /Dests dictionary are PDF names
        if name in wanted:
            out[name] = reader.get_destination_page_number(dest) + 1
    return out


def structure(reader) -> dict[str, list]:  # noqa: ANN001 (a pypdf PdfReader)
    """The structure tree of a tagged PDF: its element types in reading order, and the
    alternative text (``/Alt``, or None) of every ``/Figure`` and every ``/Formula``."""
    from pypdf.generic import ArrayObject, DictionaryObject

    root = reader.trailer["/Root"].get("/StructTreeRoot")
    types: list[str] = []
    alts: list[str | None] = []
    formulas: list[str | None] = []

    def walk(node) -> None:  # noqa: ANN001
        node = node.get_object()
        if isinstance(node, ArrayObject):
            for kid in node:
                walk(kid)
            return
        if not isinstance(node, DictionaryObject) or "/S" not in node:
            return  # a marked-content reference, an object reference or a number
        types.append(str(node["/S"]))
        if node["/S"] in ("/Figure", "/Formula"):
            alt = node.get("/Alt")
            (alts if node["/S"] == "/Figure" else formulas).append(
                str(alt) if alt is not None else None
            )
        if "/K" in node:
            walk(node["/K"])

    if root is not None and "/K" in root.get_object():
        walk(root.get_object()["/K"])
    return {"types": types, "figure_alts": alts, "formula_alts": formulas}


def audit_pdf(path: Path) -> list[str]:
    """What a PDF lacks to be accessible: tags, language, outline, title, figures' texts."""
    from pypdf import PdfReader

    reader = PdfReader(path)
    catalog = reader.trailer["/Root"]
    problems = []
    tree = structure(reader)
    if not tree["types"]:
        problems.append("no structure tree (not tagged)")
    mark = catalog.get("/MarkInfo")
    if mark is None or not mark.get_object().get("/Marked"):
        problems.append("not marked as tagged (/MarkInfo /Marked)")
    if not str(catalog.get("/Lang", "")).strip():
        problems.append("no language (/Lang)")
    if not reader.outline:
        problems.append("no outline")
    title = str((reader.metadata or {}).get("/Title", "")).strip()
    if not title or "://" in title or title.endswith((".html", ".pdf")):
        problems.append(f"no title in the metadata (/Title {title!r})")
    prefs = catalog.get("/ViewerPreferences")
    if prefs is None or not prefs.get_object().get("/DisplayDocTitle"):
        problems.append("viewers are not asked to show the title (/DisplayDocTitle)")
    missing = sum(1 for alt in tree["figure_alts"] if not (alt or "").strip())
    if missing:
        problems.append(f"{missing} figure(s) without a text alternative (/Alt)")
    missing = sum(1 for alt in tree["formula_alts"] if not (alt or "").strip())
    if missing:
        problems.append(f"{missing} formula(s) without a text alternative (/Alt)")
    return [f"{path.name}: {p}" for p in problems]


# --- printing ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Job:
    """What to print: the served site, its pages, where the PDFs go, and the book's names."""

    base: str
    pages: tuple[Page, ...]
    out: Path
    book_title: str
    book_name: str = BOOK_NAME
    subtitle: str = ""
    meta: str = ""


async def _open(context, url: str):  # noqa: ANN001, ANN202 (Playwright's BrowserContext, Page)
    tab = await context.new_page()
    tab.set_default_timeout(PAGE_LIMIT * 1000)
    errors: list[str] = []
    tab.on("pageerror", lambda exc: errors.append(str(exc)))
    response = await tab.goto(url, wait_until="load", timeout=PAGE_LIMIT * 1000)
    if response is None or not response.ok:
        raise PrintError(f"{url}: {response.status if response else 'no response'}")
    bad = await tab.evaluate(TYPESET_JS)
    if bad:
        raise PrintError(f"{url}: math not typeset: {bad[:3]}")
    if errors:
        raise PrintError(f"{url}: script errors: {errors[:3]}")
    return tab


async def print_page(context, job: Job, page: Page) -> tuple[Path, list[str]]:  # noqa: ANN001
    """Print one page of the site to ``<out>/<name>.pdf``; what reaches past its margins."""
    tab = await _open(context, job.base + page.path)
    try:
        title = _page_title(await tab.title(), job.book_title)
        await tab.emulate_media(media="print")
        await tab.evaluate(FONTS_JS)
        prepared = await tab.evaluate(PREPARE_JS, {"title": title, "keepLinks": False})

        target = job.out / f"{page.name}.pdf"
        await tab.pdf(
            path=target,
            header_template=_header(_running_head(job), title),
            footer_template=FOOTER,
            **PDF_OPTIONS,
        )
        headings = [h["text"] for h in prepared["headings"]]
        finish_pdf(target, title, prepared["author"], headings, prepared["formulas"])
        return target, prepared["overflow"]
    finally:
        await tab.close()


async def print_book(context, job: Job) -> tuple[Path, list[str]]:  # noqa: ANN001
    """Print the whole book, with its contents' page numbers, to ``<out>/<book_name>.pdf``;
    what reaches past its margins."""
    tab = await _open(context, job.base + job.pages[0].path)
    try:
        await tab.add_style_tag(content=BOOK_CSS)
        book = {
            "base": job.base,
            "pages": [
                {"path": p.path, "name": p.name, "title": p.title, "part": p.part}
                for p in job.pages
            ],
            "title": html.escape(job.book_title),
            "subtitle": html.escape(job.subtitle),
            "meta": html.escape(job.meta),
        }
        await tab.evaluate(ASSEMBLE_JS, book)
        bad = await tab.evaluate(TYPESET_JS)
        if bad:
            raise PrintError(f"the whole book: math not typeset: {bad[:3]}")
        await tab.emulate_media(media="print")
        await tab.evaluate(FONTS_JS)
        prepared = await tab.evaluate(PREPARE_JS, {"title": _running_head(job), "keepLinks": True})

        targets = await tab.evaluate(
            "() => [...document.querySelectorAll('.print-toc-page')].map(e => e.dataset.target)"
        )
        options = dict(
            header_template=_header(job.book_title, job.subtitle),
            footer_template=FOOTER,
            **PDF_OPTIONS,
        )
        # Print until the sheets the headings land on are those the contents say. Chromium's
        # layout of a long document can alternate between two printings (a heading by a page
        # break goes to one sheet or the next): the contents are changed only when two
        # printings in a row agree, and the first printing that matches them is kept.
        numbers: dict[str, int] | None = None
        previous: dict[str, int] | None = None
        for _ in range(6):
            pdf = await tab.pdf(**options)
            found = destination_pages(pdf, targets)
            missing = sorted(set(targets) - set(found))
            if missing:
                raise PrintError(f"the whole book: no destination for {missing[:5]}")
            if found == numbers:
                break
            if numbers is None or found == previous:
                numbers = found
                await tab.evaluate(SET_TOC_PAGES_JS, numbers)
            previous = found
        else:
            moved = {k: (numbers[k], v) for k, v in found.items() if numbers[k] != v}
            some = dict(list(moved.items())[:5])
            raise PrintError(f"the whole book: the contents' page numbers do not settle: {some}")
        target = job.out / f"{job.book_name}.pdf"
        target.write_bytes(pdf)
        headings = [h["text"] for h in prepared["headings"]]
        finish_pdf(target, _running_head(job), prepared["author"], headings, prepared["formulas"])
        return target, prepared["overflow"]
    finally:
        await tab.close()


async def _print_all(job: Job, jobs: int, book: Job | None) -> list[tuple[Path, list[str]]]:
    """Print ``job``'s pages and, if given, the whole book of ``book``'s pages."""
    from playwright.async_api import async_playwright

    if not CHROMIUM.exists():
        raise PrintError(f"{CHROMIUM} not found: apt-get install chromium")
    local = urlsplit(job.base).netloc
    async with async_playwright() as playwright:
        browser = await playwright.chromium.launch(
            executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True
        )
        refused: list[str] = []

        async def offline(route) -> None:  # noqa: ANN001
            url = route.request.url
            if urlsplit(url).scheme in ("data", "blob") or urlsplit(url).netloc == local:
                await route.continue_()
            else:
                refused.append(url)
                await route.abort()

        try:
            context = await browser.new_context(color_scheme="light", viewport=VIEWPORT)
            await context.route("**/*", offline)
            gate = asyncio.Semaphore(jobs)

            async def limited(coro):  # noqa: ANN001, ANN202
                async with gate:
                    return await coro

            # the longest first: the whole book, then the pages
            work = [print_book(context, book)] if book is not None else []
            work += [print_page(context, job, page) for page in job.pages]
            results = await asyncio.gather(*(limited(w) for w in work))
        finally:
            await browser.close()
        if refused:
            raise PrintError(f"requests outside the site refused (offline): {refused[:5]}")
    return list(results)


def _run(coroutine):  # noqa: ANN001, ANN202 (any coroutine, its result)
    """Run ``coroutine`` to its end, also when the caller's thread already runs an event loop
    (Playwright's synchronous API keeps one running): then in a thread of its own."""
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return asyncio.run(coroutine)
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        return pool.submit(asyncio.run, coroutine).result()


def print_site(
    site: Path,
    out: Path,
    *,
    only: Sequence[str] = (),
    book: bool = True,
    jobs: int | None = None,
    book_name: str = BOOK_NAME,
    subtitle: str = "",
) -> Printed:
    """Print the pages of the built site ``site`` (all, or those named in ``only``) into ``out``,
    and (``book``) the whole book of them; as many at a time as ``jobs`` (default: the number of
    cores)."""
    start = time.perf_counter()
    site = Path(site).resolve()
    out = Path(out)
    pages = site_pages(site)
    names = [p.name for p in pages]
    unknown = sorted(set(only) - set(names))
    if unknown:
        raise PrintError(f"no page named {unknown} in {site}; pages: {', '.join(names)}")
    selected = [p for p in pages if not only or p.name in only]
    root_title = _NavParser()
    root_title.feed((site / pages[0].path).read_text(encoding="utf-8"))
    title = " ".join(root_title.title.split())
    book_title = title.split(" \u2014 ")[-1] if " \u2014 " in title else title
    out.mkdir(parents=True, exist_ok=True)
    with serve(site) as base:
        job = Job(
            base=base,
            pages=tuple(selected),
            out=out,
            book_title=book_title,
            book_name=book_name,
            subtitle=subtitle,
            meta=f"Printed on {time.localtime().tm_mday} {time.strftime('%B %Y')} from the "
            "book's web pages",
        )
        results = _run(_print_all(job, jobs or os.cpu_count() or 1, job if book else None))
    pdfs = [path for path, _ in results]
    problems = [line for path in pdfs for line in audit_pdf(path)]
    if problems:
        raise PrintError("printed, but not accessible:\n" + "\n".join(problems))
    if not only:  # a page no longer in the book leaves no PDF behind
        for stale in set(out.glob("*.pdf")) - set(pdfs):
            stale.unlink()
    from pypdf import PdfReader

    sheets = sum(len(PdfReader(p).pages) for p in pdfs)
    overflow = {path.name: lines for path, lines in results if lines}
    return Printed(pdfs, time.perf_counter() - start, sheets, overflow)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("site", type=Path, help="the built HTML site, e.g. _build/html")
    parser.add_argument("out", type=Path, help="where the PDFs go, e.g. _build/pdf")
    parser.add_argument("--only", nargs="+", default=(), metavar="PAGE", help="print these pages")
    parser.add_argument("--no-book", action="store_true", help="do not print the whole book")
    parser.add_argument("--jobs", type=int, default=None, help="pages at a time (default: cores)")
    parser.add_argument("--book-name", default=BOOK_NAME, help="file name of the whole book")
    parser.add_argument("--subtitle", default="", help="under the title on the title page")
    args = parser.parse_args(argv)
    try:
        printed = print_site(
            args.site,
            args.out,
            only=args.only,
            book=not args.no_book,
            jobs=args.jobs,
            book_name=args.book_name,
            subtitle=args.subtitle,
        )
    except PrintError as err:
        print(f"pdf_print: {err}", file=sys.stderr)
        return 1
    for name, lines in printed.overflow.items():
        for line in lines[:10]:
            print(f"pdf_print: warning: {name}: {line}", file=sys.stderr)
    print(
        f"printed {len(printed.pdfs)} PDF(s), {printed.pages} pages, into {args.out} in "
        f"{printed.seconds:.1f} s"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
