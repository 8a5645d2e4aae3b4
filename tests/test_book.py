"""The book builds without warnings, loads nothing from the internet and renders in a browser.

The book is built once per test run into the repository's ``_build/html`` with the command of
``make book``. The browser test serves that folder on 127.0.0.1, opens every page of ``_toc.yml``
in headless Chromium (Debian's ``/usr/bin/chromium``, driven by Playwright), blocks every request
that leaves the local server, and checks that the mathematics is typeset, every image loaded, no
output cell shows an error and the console stays clean; each page is opened once per width and
every check reads that load (``page_facts``), which saves a full-page screenshot in
``_build/screenshots/`` when ``UIO_TEACH_SCREENSHOTS`` is set. At 1280 px every display
equation, every visible code line and every printed output fits its column. At both widths the
page meets WCAG 2.1 A and AA as axe-core checks it (every dropdown opened; in the dark theme as
well, where the text of the cells' HTML outputs, in a light box, is checked for contrast by the
test itself), every picture says
what it shows, the headings go down one level at a time, every table has header cells and every
formula carries MathJax's assistive MathML for screen readers. The browser tests
wait on events and page state (the load event, fonts, images, MathJax), never on a fixed
duration, and assert nothing about how long anything took.
"""

from __future__ import annotations

import os
import re
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import urlsplit

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
SCREENSHOTS = ROOT / "_build" / "screenshots"
BUILD_TIMEOUT = 1800  # seconds, for a clean build that executes every chapter
# Playwright's own limit for one navigation, wait or screenshot (its default is 30 s). The
# browser tests wait on events and page state (load, fonts, images, MathJax); this limit is only
# a safety net against a hung browser, generous enough for a machine whose cores are all busy.
# No assertion depends on how long anything took.
BROWSER_TIMEOUT_MS = 20 * 60 * 1000

pytestmark = [pytest.mark.book, pytest.mark.timeout(BUILD_TIMEOUT)]


def toc_pages(toc_file: Path = ROOT / "_toc.yml") -> list[str]:
    """Every document of the table of contents, in reading order, without suffix."""
    toc = yaml.safe_load(toc_file.read_text(encoding="utf-8"))
    pages: list[str] = [toc["root"]]

    def walk(node: object) -> None:
        if isinstance(node, dict):
            if "file" in node:
                pages.append(node["file"])
            for key in ("parts", "chapters", "sections"):
                for child in node.get(key, []):
                    walk(child)
        elif isinstance(node, list):
            for child in node:
                walk(child)

    walk({key: toc[key] for key in ("parts", "chapters", "sections") if key in toc})
    return [re.sub(r"\.(md|ipynb)$", "", page) for page in pages]


PAGES = toc_pages()


def test_book_builds(built_book: Path) -> None:
    missing = [page for page in PAGES if not (built_book / f"{page}.html").is_file()]
    assert not missing, f"pages of _toc.yml missing from the build: {missing}"


class _ExternalResources(HTMLParser):
    """Collect the URLs of scripts, stylesheets, images and frames loaded from other hosts."""

    ATTRIBUTES = {"script": "src", "link": "href", "img": "src", "iframe": "src"}

    def __init__(self) -> None:
        super().__init__()
        self.found: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        name = self.ATTRIBUTES.get(tag)
        if name is None:
            return
        url = dict(attrs).get(name) or ""
        if re.match(r"^(https?:)?//", url.strip(), flags=re.IGNORECASE):
            self.found.append(f"<{tag} {name}={url!r}>")


def test_no_external_resources(built_book: Path) -> None:
    offenders: dict[str, list[str]] = {}
    pages = sorted(built_book.rglob("*.html"))
    assert pages
    for page in pages:
        if "_static" in page.relative_to(built_book).parts:
            continue
        parser = _ExternalResources()
        parser.feed(page.read_text(encoding="utf-8"))
        if parser.found:
            offenders[str(page.relative_to(built_book))] = parser.found
    assert not offenders, f"pages that load resources from the internet: {offenders}"


# --- the browser test -----------------------------------------------------------------------


# Text nodes outside code, in visible elements: raw TeX left there means MathJax did not run.
_VISIBLE_PROSE_JS = """
() => {
  const skip = new Set(["PRE", "CODE", "SCRIPT", "STYLE", "TEXTAREA", "NOSCRIPT"]);
  const root = document.querySelector("main") || document.body;
  const walker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
  const parts = [];
  for (let node = walker.nextNode(); node; node = walker.nextNode()) {
    let el = node.parentElement, hidden = false;
    for (let e = el; e; e = e.parentElement) {
      if (skip.has(e.tagName)) { hidden = true; break; }
    }
    if (hidden || !el.checkVisibility()) continue;
    parts.push(node.textContent);
  }
  return parts.join("");
}
"""

_WAIT_FOR_IMAGES_JS = """
async () => {
  const images = Array.from(document.images);
  for (const img of images) { if (img.loading === "lazy") img.loading = "eager"; }
  await Promise.all(images.map((img) => img.complete ? null : new Promise((resolve) => {
    img.addEventListener("load", resolve, {once: true});
    img.addEventListener("error", resolve, {once: true});
  })));
  return images.filter((img) => !(img.complete && img.naturalWidth > 0))
               .map((img) => img.getAttribute("src"));
}
"""

_WAIT_FOR_MATHJAX_JS = """
async () => {
  if (!window.MathJax || !window.MathJax.startup) return false;
  await window.MathJax.startup.promise;
  return true;
}
"""

_WAIT_FOR_FONTS_JS = """
async () => { await document.fonts.ready; return document.fonts.status; }
"""


# The layout at a width (read by test_student_edition.py): whether the page scrolls sideways,
# the elements that reach past the viewport outside a frame, the frames that scroll and whether
# they show a cue, and each picture's natural and shown size.
SCREEN_JS = """
() => {
  const se = document.scrollingElement;
  // the article: the side bars are drawers off screen on a phone
  const main = document.querySelector("article.bd-article") || document.body;
  const out = {page: se.scrollWidth, viewport: se.clientWidth, loose: [], frames: [], images: []};
  const scrolls = (el) => ["auto", "scroll"].includes(getComputedStyle(el).overflowX);
  for (const el of main.querySelectorAll("*")) {
    if (!el.checkVisibility()) continue;
    const r = el.getBoundingClientRect();
    if (r.width === 0 || r.right <= se.clientWidth + 0.5) continue;
    let framed = false;
    for (let a = el.parentElement; a && a !== main; a = a.parentElement) {
      if (["auto", "scroll", "hidden", "clip"].includes(getComputedStyle(a).overflowX)) {
        framed = true; break;
      }
    }
    if (!framed) {
      const name = `${el.tagName}.${String(el.className).slice(0, 30)}`;
      out.loose.push(`${name} to ${Math.round(r.right)}`);
    }
  }
  const boxes = "pre, table, .output, .cell_output, .table-wrapper, mjx-container";
  for (const el of main.querySelectorAll(boxes)) {
    if (!el.checkVisibility() || el.scrollWidth <= el.clientWidth + 1 || !scrolls(el)) continue;
    const s = getComputedStyle(el);
    const cue = /gradient/.test(s.backgroundImage) || s.scrollbarWidth === "thin"
      || el.closest(".uio-static-explorer") !== null;
    out.frames.push({what: `${el.tagName}.${String(el.className).slice(0, 30)}`, cue});
  }
  for (const img of main.querySelectorAll("img")) {
    if (!img.checkVisibility() || !img.naturalWidth) continue;
    const r = img.getBoundingClientRect();
    out.images.push({
      explorer: img.closest(".uio-static-explorer") !== null,
      output: img.closest(".cell_output") !== null,
      natural: img.naturalWidth, naturalHeight: img.naturalHeight,
      width: r.width, height: r.height,
      src: (img.getAttribute("src") || "").slice(0, 60),
    });
  }
  return out;
}
"""


def _new_context(browser, width: int, scheme: str = "light"):
    """A browser context of the given viewport width and colour scheme (the reader's system
    setting, which the theme follows), with the safety-net timeouts."""
    context = browser.new_context(viewport={"width": width, "height": 900}, color_scheme=scheme)
    context.set_default_timeout(BROWSER_TIMEOUT_MS)
    context.set_default_navigation_timeout(BROWSER_TIMEOUT_MS)
    return context


def _open_local(
    browser,
    book_server: str,
    page: str,
    width: int,
    listen: dict | None = None,
    scheme: str = "light",
):
    """Open a page of the book (requests to other hosts aborted) once it is fully rendered.

    Waits on events and page state only: the load event, then the web fonts, every image and
    MathJax's typesetting. ``listen`` collects what went wrong while loading (requests blocked,
    failed responses, console errors); ``scheme`` is the reader's colour setting, light or dark.
    Returns the context (close it) and the tab.
    """
    context = _new_context(browser, width, scheme)
    tab = context.new_page()
    host = urlsplit(book_server).hostname
    found = listen if listen is not None else {}
    for key in ("blocked", "failed", "console"):
        found.setdefault(key, [])

    def route(route) -> None:
        if urlsplit(route.request.url).hostname == host:
            route.continue_()
        else:
            found["blocked"].append(route.request.url)
            route.abort()

    tab.route("**/*", route)
    console = found["console"]
    tab.on(
        "console",
        lambda msg: console.append(f"console: {msg.text}") if msg.type == "error" else None,
    )
    tab.on("pageerror", lambda exc: console.append(f"page error: {exc}"))
    tab.on(
        "response",
        lambda r, failed=found["failed"]: (
            failed.append(f"{r.status} {r.url}") if r.status >= 400 else None
        ),
    )
    response = tab.goto(f"{book_server}/{page}.html", wait_until="load")
    found["loaded"] = response is not None and response.ok
    found["broken_images"] = tab.evaluate(_WAIT_FOR_IMAGES_JS)
    found["typeset"] = tab.evaluate(_WAIT_FOR_MATHJAX_JS)
    tab.evaluate(_WAIT_FOR_FONTS_JS)
    return context, tab


# Each page is opened once per width in a test process (the tests of one page run on one
# worker: tests/conftest.py), and everything the checks look at is read from that one load.
_FACTS: dict[tuple[str, int], dict] = {}


def page_facts(browser, book_server: str, page: str, width: int) -> dict:
    """What the browser shows of ``page`` at ``width`` px: load errors, the typeset mathematics,
    the visible prose, the outputs, the display equations, the code lines and the layout.

    A full-page screenshot is saved in ``_build/screenshots/`` when the environment variable
    ``UIO_TEACH_SCREENSHOTS`` is set (``make test UIO_TEACH_SCREENSHOTS=1``).
    """
    key = (page, width)
    if key in _FACTS:
        return _FACTS[key]
    facts: dict = {}
    context, tab = _open_local(browser, book_server, page, width, listen=facts)
    try:
        facts["has_math"] = tab.locator("main .math").count() > 0
        facts["rendered_math"] = tab.locator("mjx-container").count()
        facts["prose"] = tab.evaluate(_VISIBLE_PROSE_JS)
        facts["error_outputs"] = tab.locator(_ERROR_OUTPUTS).all_inner_texts()
        facts["cell_outputs"] = "\n".join(tab.locator(".cell_output").all_inner_texts())
        facts["equations"] = tab.evaluate(_DISPLAY_EQUATIONS_JS)
        facts["wide_code"] = tab.evaluate(_WIDE_CODE_JS)
        facts["screen"] = tab.evaluate(SCREEN_JS)
        if os.environ.get("UIO_TEACH_SCREENSHOTS"):
            SCREENSHOTS.mkdir(parents=True, exist_ok=True)
            name = _screenshot_name(page).removesuffix(".png")
            tab.screenshot(path=str(SCREENSHOTS / f"{name}-{width}px.png"), full_page=True)
        facts["wide_outputs"] = tab.evaluate(_WIDE_OUTPUTS_JS)  # it opens the dropdowns
        # with every dropdown open, so that what a reader opens is checked too
        facts["structure"] = tab.evaluate(_STRUCTURE_JS)
        # what the page itself requested; axe-core then fetches the style sheets again to read
        # them (its CSSOM), with URLs of its own making that the page never asks for
        facts["failed"] = list(facts["failed"])  # copies: later requests are not the page's
        facts["console"] = list(facts["console"])
        facts["axe"] = axe_violations(tab)
    finally:
        context.close()
    _FACTS[key] = facts
    return facts


# --- WCAG 2.1 AA: axe-core, and what it does not check -----------------------------------------

AXE_TAGS = ["wcag2a", "wcag2aa", "wcag21a", "wcag21aa"]  # WCAG 2.0 and 2.1, levels A and AA
_AXE: list = []  # axe-core's script, read once per test process


def axe_violations(tab) -> list[dict]:
    """axe-core's WCAG 2.1 A and AA violations on the open page (axe-playwright-python)."""
    if not _AXE:
        from axe_playwright_python.sync_playwright import Axe

        _AXE.append(Axe())
    options = {"runOnly": {"type": "tag", "values": AXE_TAGS}, "resultTypes": ["violations"]}
    found = _AXE[0].run(tab, options=options).response["violations"]
    return [
        {
            "id": v["id"],
            "help": v["help"],
            "count": len(v["nodes"]),
            "where": [" ".join(map(str, n["target"])) for n in v["nodes"][:4]],
            "why": (v["nodes"][0].get("failureSummary") or "").replace("\n", " ")[:240],
        }
        for v in found
    ]


# The text of the cells' HTML outputs (the figures' words, the explorers' controls and captions)
# whose contrast with the box it sits on is under 4.5:1 (3:1 for large text), the colours mixed
# with the element's opacity, and a box whose scroll shadows' covers (phone.css) are not its own
# colour. In the dark theme the box is light: axe-core reports such text as undecided ("partially
# obscured", "background gradient"), not as a violation, so the ratio is computed here.
_OUTPUT_BOX_CONTRAST_JS = """
() => {
  const rgba = (c) => { const m = c.match(/rgba?\\(([^)]+)\\)/); if (!m) return null;
    const p = m[1].split(/[ ,\\/]+/).filter(Boolean).map(Number);
    return [p[0], p[1], p[2], p.length > 3 ? p[3] : 1]; };
  const lum = (c) => { const f = (v) => { v /= 255;
    return v <= 0.03928 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4; };
    return 0.2126 * f(c[0]) + 0.7152 * f(c[1]) + 0.0722 * f(c[2]); };
  const box = (el) => { for (let e = el; e; e = e.parentElement) {
    const c = rgba(getComputedStyle(e).backgroundColor); if (c && c[3] > 0.5) return c; }
    return [255, 255, 255, 1]; };
  const faint = [];
  for (const out of document.querySelectorAll("main div.cell_output .text_html")) {
    // the covers of the box's scroll shadows (phone.css) are the box's own colour
    const style = getComputedStyle(out), own = rgba(style.backgroundColor);
    const cover = rgba(style.backgroundImage);
    if (own && own[3] > 0.5 && cover && cover.slice(0, 3).join() !== own.slice(0, 3).join()) {
      faint.push(`the scroll shadows' covers, rgb(${cover.slice(0, 3)}), on the output box, ` +
                 `rgb(${own.slice(0, 3)}): bands over the text at its edges`);
    }
    const walker = document.createTreeWalker(out, NodeFilter.SHOW_TEXT);
    for (let n = walker.nextNode(); n; n = walker.nextNode()) {
      const el = n.parentElement;
      if (!n.textContent.trim() || !el.checkVisibility() || el.closest("select, option")) continue;
      if (el.closest("mjx-assistive-mml")) continue;
      const s = getComputedStyle(el), fg = rgba(s.color), bg = box(el);
      let alpha = fg[3];
      for (let e = el; e; e = e.parentElement) alpha *= Number(getComputedStyle(e).opacity);
      const mixed = [0, 1, 2].map((i) => fg[i] * alpha + bg[i] * (1 - alpha));
      const [lo, hi] = [lum(mixed), lum(bg)].sort((a, b) => a - b);
      const ratio = (hi + 0.05) / (lo + 0.05);
      const size = parseFloat(s.fontSize), bold = Number(s.fontWeight) >= 700;
      const needed = size >= 24 || (bold && size >= 18.66) ? 3 : 4.5;
      if (ratio < needed) {
        faint.push(`${el.tagName.toLowerCase()} "${n.textContent.trim().slice(0, 30)}": ` +
                   `${ratio.toFixed(2)}:1 (${s.color} on rgb(${bg.slice(0, 3)}))`);
      }
    }
  }
  return faint;
}
"""


@pytest.mark.browser
# the dark theme is a second palette for the same pages: its scans run in the slow set, which CI
# runs after `make test` (the light theme is scanned at both widths in `make test`)
@pytest.mark.slow
@pytest.mark.parametrize("width", [1280, 390])
@pytest.mark.parametrize("page", PAGES)
def test_dark_theme_meets_wcag_21_aa(page: str, width: int, book_server: str, browser) -> None:
    """The page in the dark theme (a reader whose system is set to dark: the book follows it),
    its dropdowns open: no WCAG 2.1 A or AA violation, as in the light theme."""
    context, tab = _open_local(browser, book_server, page, width, scheme="dark")
    try:
        theme = tab.evaluate("document.documentElement.dataset.theme")
        tab.evaluate("document.querySelectorAll('main details').forEach(d => d.open = true)")
        violations = axe_violations(tab)
        faint = tab.evaluate(_OUTPUT_BOX_CONTRAST_JS)
    finally:
        context.close()
    assert theme == "dark", f"{page}: the theme is {theme!r} for a reader who chose dark"
    assert not faint, f"{page} at {width} px, dark theme: text under 4.5:1 in output boxes: {faint}"
    assert not violations, f"{page} at {width} px, dark theme, WCAG 2.1 A/AA (axe-core):\n" + (
        "\n".join(
            f"{v['id']} ({v['count']}): {v['help']}; {v['where']}; {v['why']}" for v in violations
        )
    )


# The page's structure for a screen reader: its language, its headings in order, its tables'
# header cells, each formula's assistive MathML, each picture's text alternative, and the
# course figures whose curves only a hue tells apart (uio_teach.figure_text marks them).
_STRUCTURE_JS = """
() => {
  const main = document.querySelector("main") || document.body;
  const shown = (el) => el.checkVisibility() || el.closest("details") !== null;
  const headings = Array.from(main.querySelectorAll("h1, h2, h3, h4, h5, h6"))
    .filter(shown).map((h) => ({level: +h.tagName[1], text: h.textContent.trim().slice(0, 50)}));
  const tables = Array.from(main.querySelectorAll("table"))
    .filter((t) => t.getAttribute("role") !== "presentation" && !t.querySelector("th"))
    .map((t) => t.textContent.trim().replace(/\\s+/g, " ").slice(0, 60));
  const formulas = Array.from(main.querySelectorAll("mjx-container"));
  const pictures = Array.from(main.querySelectorAll("img"))
    .filter((img) => img.getAttribute("role") !== "presentation"
      && img.getAttribute("aria-hidden") !== "true")
    .map((img) => ({src: (img.currentSrc || img.src || "").slice(-60),
                    alt: img.getAttribute("alt") || ""}));
  return {
    lang: document.documentElement.getAttribute("lang") || "",
    headings, tables,
    formulas: formulas.length,
    without_mathml: formulas.filter((c) => !c.querySelector("mjx-assistive-mml")).length,
    pictures,
    hue_alone: Array.from(main.querySelectorAll("[data-hue-alone]"))
      .map((f) => f.getAttribute("data-hue-alone")),
  };
}
"""


@pytest.mark.browser
@pytest.mark.parametrize("width", [1280, 390])
@pytest.mark.parametrize("page", PAGES)
def test_meets_wcag_21_aa(page: str, width: int, book_server: str, browser) -> None:
    violations = page_facts(browser, book_server, page, width)["axe"]
    assert not violations, f"{page} at {width} px, WCAG 2.1 A/AA violations (axe-core):\n" + (
        "\n".join(
            f"{v['id']} ({v['count']}): {v['help']}; {v['where']}; {v['why']}" for v in violations
        )
    )


# A text alternative that is a file name, a path or a word or two says nothing of the picture.
_NAMELESS = re.compile(r"(\.(png|jpe?g|svg|gif)$)|(^[\w./-]*$)|(^data:)", re.IGNORECASE)


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES)
def test_every_picture_says_what_it_shows(page: str, book_server: str, browser) -> None:
    structure = page_facts(browser, book_server, page, 1280)["structure"]
    silent = [
        f"{p['src']}: alt={p['alt'][:60]!r}"
        for p in structure["pictures"]
        if len(p["alt"].split()) < 6 or _NAMELESS.search(p["alt"].strip())
    ]
    assert not silent, f"{page}: pictures without a text alternative that says what they show: " + (
        "; ".join(silent)
    )
    assert not structure["hue_alone"], (
        f"{page}: curves told apart by hue alone: {structure['hue_alone']}"
    )


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES)
def test_structure_for_a_screen_reader(page: str, book_server: str, browser) -> None:
    structure = page_facts(browser, book_server, page, 1280)["structure"]
    assert structure["lang"] == "en", f"{page}: the page's language is {structure['lang']!r}"
    levels = [h["level"] for h in structure["headings"]]
    assert levels and levels[0] == 1 and levels.count(1) == 1, f"{page}: headings {levels}"
    jumps = [
        f"h{a['level']} {a['text']!r} -> h{b['level']} {b['text']!r}"
        for a, b in zip(structure["headings"], structure["headings"][1:], strict=False)
        if b["level"] > a["level"] + 1
    ]
    assert not jumps, f"{page}: headings that skip a level: {jumps}"
    assert not structure["tables"], f"{page}: tables without header cells: {structure['tables']}"
    assert structure["without_mathml"] == 0, (
        f"{page}: {structure['without_mathml']} of {structure['formulas']} formulas without "
        "MathJax's assistive MathML"
    )


_ERROR_OUTPUTS = ".output.error, .output.traceback, .output.stderr"
_EXCEPTION_LINE = re.compile(
    r"Traceback \(most recent call last\)|^[A-Z]\w*(Error|Exception): ", re.M
)


def _screenshot_name(page: str) -> str:
    relative = Path(page)
    if relative.parts and relative.parts[0] == "book":
        relative = Path(*relative.parts[1:])
    return "-".join(relative.parts) + ".png"


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES)
def test_page_in_browser(page: str, book_server: str, browser) -> None:
    facts = page_facts(browser, book_server, page, 1280)
    assert facts["loaded"], f"{page}.html did not load"
    assert not facts["blocked"], f"{page}: requests that leave the local server: {facts['blocked']}"
    assert not facts["failed"], f"{page}: failed requests: {facts['failed']}"
    if facts["has_math"]:
        assert facts["typeset"], f"{page}: has math but MathJax did not start"
        assert facts["rendered_math"] > 0, f"{page}: has math but no mjx-container was rendered"
    raw = [delimiter for delimiter in ("\\(", "\\[", "$$") if delimiter in facts["prose"]]
    assert not raw, f"{page}: raw TeX delimiters {raw} left in the visible text"
    assert not facts["broken_images"], f"{page}: images that did not load: {facts['broken_images']}"
    errors = facts["error_outputs"]
    assert not errors, f"{page}: error or stderr output cells: {errors}"
    match = _EXCEPTION_LINE.search(facts["cell_outputs"])
    assert match is None, f"{page}: an output cell shows an exception: {match.group(0)!r}"
    assert not facts["console"], f"{page}: browser console errors: {facts['console']}"


# --- every display equation visible -------------------------------------------------------------

# For each display equation of the page: the width of the formula plus its equation number, the
# width of the box it sits in (div.math, the text column), and whether it or an ancestor up to
# that box scrolls sideways (computed overflow-x auto or scroll).
_DISPLAY_EQUATIONS_JS = """
() => Array.from(document.querySelectorAll("main mjx-container[display='true']")).map((c, i) => {
  const box = c.closest("div.math") || c.parentElement;
  const math = c.querySelector("mjx-math") || c;
  const eqno = box.querySelector(".eqno");
  const width = math.getBoundingClientRect().width
    + (eqno ? eqno.getBoundingClientRect().width : 0);
  let scrolls = false;
  for (let e = c; e && e !== box.parentElement; e = e.parentElement) {
    const overflow = getComputedStyle(e).overflowX;
    if (overflow === "auto" || overflow === "scroll") { scrolls = true; break; }
  }
  const number = eqno ? eqno.textContent.replace("#", "").trim() : "";
  const label = box.id || (box.closest("section[id]") || {}).id || "";
  const tex = (c.getAttribute("aria-label") || c.textContent || "").replace(/\\s+/g, " ");
  return {index: i + 1, number, label, width, box: box.clientWidth, scrolls,
          text: tex.slice(0, 70)};
})
"""


def _display_equations(browser, book_server: str, page: str, width: int) -> list[dict]:
    return page_facts(browser, book_server, page, width)["equations"]


def _describe(page: str, equation: dict) -> str:
    name = equation["number"] or f"display equation {equation['index']}"
    where = f" (#{equation['label']})" if equation["label"] else ""
    return (
        f"{page}: {name}{where} is {equation['width']:.0f} px wide in a"
        f" {equation['box']} px column: {equation['text']!r}"
    )


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES)
def test_display_equations_fit_at_1280px(page: str, book_server: str, browser) -> None:
    equations = _display_equations(browser, book_server, page, 1280)
    too_wide = [_describe(page, eq) for eq in equations if eq["width"] > eq["box"] + 0.5]
    assert not too_wide, "display equations wider than their column:\n" + "\n".join(too_wide)


# --- every visible line of code visible at 1280 px -----------------------------------------------

# The code cells the reader sees (not those in a collapsed toggle): the lines whose text is wider
# than the block's box, measured with a range over each line (the block scrolls sideways instead).
_WIDE_CODE_JS = """
() => {
  const wide = [];
  document.querySelectorAll("main div.cell_input pre").forEach((pre, i) => {
    if (!pre.checkVisibility() || pre.closest(".tag_hide-input, .tag_hide-cell")) return;
    const style = getComputedStyle(pre);
    const inner = pre.clientWidth - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight);
    const lines = pre.textContent.split("\\n");
    const probe = document.createElement("span");
    probe.style.font = style.font;
    probe.style.whiteSpace = "pre";
    probe.style.position = "absolute";
    probe.style.visibility = "hidden";
    document.body.appendChild(probe);
    lines.forEach((line) => {
      probe.textContent = line;
      const width = probe.getBoundingClientRect().width;
      if (width > inner + 0.5) {
        wide.push({cell: i + 1, width: Math.round(width), box: Math.round(inner),
                   text: line.trim().slice(0, 60)});
      }
    });
    probe.remove();
  });
  return wide;
}
"""


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES)
def test_visible_code_lines_fit_at_1280px(page: str, book_server: str, browser) -> None:
    wide = page_facts(browser, book_server, page, 1280)["wide_code"]
    assert not wide, f"{page}: code lines wider than their column at 1280 px:\n" + "\n".join(
        f"code cell {w['cell']}: {w['width']} px in {w['box']} px: {w['text']!r}" for w in wide
    )


# --- every printed output visible at 1280 px ---------------------------------------------------

# Every output of a code cell, with the solution dropdowns opened (a reader opens them): the text
# blocks (pre), the output boxes and their tables, whose content is wider than their box
# (scrollWidth > clientWidth: the end of a line is cut off or needs sideways scrolling), and the
# output boxes wider than the cell that holds them. Figures are scaled to the column by the theme.
_WIDE_OUTPUTS_JS = """
() => {
  document.querySelectorAll("main details").forEach((d) => { d.open = true; });
  const wide = [];
  document.querySelectorAll("main div.cell_output").forEach((out, i) => {
    const cell = out.closest("div.cell") || out;
    const blocks = [out, ...out.querySelectorAll("pre, div.output, table")];
    blocks.forEach((el) => {
      if (!el.checkVisibility()) return;
      const overflow = el.scrollWidth - el.clientWidth;
      const outside = el.getBoundingClientRect().right - cell.getBoundingClientRect().right;
      if (overflow > 1 || outside > 1) {
        const lines = (el.textContent || "").split("\\n");
        const longest = lines.reduce((a, l) => (l.length > a.length ? l : a), "");
        wide.push({output: i + 1, tag: el.tagName.toLowerCase(), width: el.scrollWidth,
                   box: el.clientWidth, text: longest.trim().slice(0, 72)});
      }
    });
  });
  return wide;
}
"""


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES)
def test_printed_outputs_fit_at_1280px(page: str, book_server: str, browser) -> None:
    wide = page_facts(browser, book_server, page, 1280)["wide_outputs"]
    assert not wide, f"{page}: outputs wider than their column at 1280 px:\n" + "\n".join(
        f"output {w['output']} ({w['tag']}): {w['width']} px in {w['box']} px: {w['text']!r}"
        for w in wide
    )


@pytest.mark.browser
@pytest.mark.parametrize("page", PAGES)
def test_long_equations_scroll_on_a_phone(page: str, book_server: str, browser) -> None:
    equations = _display_equations(browser, book_server, page, 390)
    stuck = [
        _describe(page, eq)
        for eq in equations
        if eq["width"] > eq["box"] + 0.5 and not eq["scrolls"]
    ]
    assert not stuck, "equations cut off at 390 px (no sideways scrolling):\n" + "\n".join(stuck)


def test_equation_css_gives_a_visible_scroll_cue() -> None:
    css = (ROOT / "_static" / "equations.css").read_text(encoding="utf-8")
    assert re.search(r"mjx-container[^{]*\{[^}]*overflow-x:\s*auto", css, flags=re.S)
    assert "scrollbar" in css and "radial-gradient" in css


# --- each chapter as a notebook -----------------------------------------------------------------


def _is_chapter(page: str) -> bool:
    source = ROOT / f"{page}.md"
    if page == PAGES[0] or not source.is_file():
        return False
    text = source.read_text(encoding="utf-8")
    return text.startswith("---") and "kernelspec:" in text.split("\n---", 1)[0]


CHAPTER_PAGES = [page for page in PAGES if _is_chapter(page)]


class _Links(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.links: list[tuple[str, str]] = []
        self._href: str | None = None
        self._text: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "a":
            self._href = dict(attrs).get("href") or ""
            self._text = []

    def handle_data(self, data: str) -> None:
        if self._href is not None:
            self._text.append(data)

    def handle_endtag(self, tag: str) -> None:
        if tag == "a" and self._href is not None:
            self.links.append((self._href, "".join(self._text).strip()))
            self._href = None


def test_chapters_are_listed() -> None:
    assert len(CHAPTER_PAGES) >= 6, CHAPTER_PAGES


@pytest.mark.parametrize("page", CHAPTER_PAGES)
def test_chapter_page_links_its_notebook(page: str, built_book: Path) -> None:
    import nbformat

    html = built_book / f"{page}.html"
    parser = _Links()
    parser.feed(html.read_text(encoding="utf-8"))
    notebooks = [
        (href, text)
        for href, text in parser.links
        if urlsplit(href).path.endswith(f"{Path(page).name}.ipynb")
    ]
    if "student-stub" in html.read_text(encoding="utf-8"):  # a stub of the student edition
        assert not notebooks, f"{page}: a stub page links a notebook"
        return
    assert notebooks, f"{page}.html has no link to its notebook (.ipynb)"
    # the link under the title (the download menu's entry, ".ipynb", points to the same file)
    href, text = next(((h, s) for h, s in notebooks if "notebook" in s.lower()), notebooks[0])
    assert "notebook" in text.lower(), f"{page}: the notebook link says {text!r}"
    assert {urlsplit(h).path for h, _ in notebooks} == {urlsplit(href).path}, notebooks
    target = (html.parent / urlsplit(href).path).resolve()
    assert target.is_file(), f"{page}: the linked notebook {target} does not exist"
    notebook = nbformat.read(target, as_version=4)
    nbformat.validate(notebook)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    assert code, f"{target.name}: no code cells"
    with_outputs = [i for i, cell in enumerate(code) if cell.outputs or cell.execution_count]
    assert not with_outputs, f"{target.name}: code cells with outputs: {with_outputs}"
    assert notebook.metadata.get("kernelspec", {}).get("name") == "python3"


def test_landing_page_and_readme_list_the_chapters_in_reading_order() -> None:
    """The landing page and the README name every page of _toc.yml in the order of the contents."""
    toc = [page.split("/")[-1] for page in PAGES if page != "book/index"]
    index = (ROOT / "book" / "index.md").read_text(encoding="utf-8")
    # the list, not a link from the opening paragraphs to a chapter they lean on
    heading = "## What the course builds"
    assert heading in index
    index = index[index.index(heading) :]
    linked = [name for name in re.findall(r"\{doc\}`(?:[^`<]*<)?([\w/]+)>?`", index)]
    in_order = [name for name in dict.fromkeys(linked) if name in toc]
    assert in_order == toc, f"book/index.md lists {in_order}, the contents say {toc}"
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    chapters = [name for name in toc if name not in {"references", "status"}]
    named = re.findall(r"`(\w+)\.md`", readme)
    in_order = [name for name in dict.fromkeys(named) if name in chapters]
    assert in_order == chapters, f"README.md lists {in_order}, the contents say {chapters}"


# --- the instructor edition --------------------------------------------------------------------

INSTRUCTOR = ROOT / "_build" / "instructor"  # as `make book-instructor` writes it


@pytest.mark.slow  # a second build of the book, every page opened at two widths
@pytest.mark.browser
def test_the_instructor_edition_meets_wcag_21_aa(built_book: Path, browser) -> None:
    """The instructor edition (the labs' solutions, the tutors' notes, the instructors' page) at
    1280 and 390 px: no WCAG 2.1 A or AA violation, every picture described.

    Both editions execute the same notebooks (``_ext/editions.py``), so the build reads the
    execution cache of the student edition built for this run (``built_book``): no chapter runs
    again, and the build costs the writing of the pages only.
    """
    import shutil
    import subprocess

    from conftest import jupyter_book
    from pdf_print import serve

    cache = INSTRUCTOR / "_build" / ".jupyter_cache"
    shutil.rmtree(cache, ignore_errors=True)
    shutil.copytree(ROOT / "_build" / ".jupyter_cache", cache)
    command = [jupyter_book(), "build", ".", "--all", "-W", "-n", "--keep-going"]
    proc = subprocess.run(
        [*command, "--path-output", str(INSTRUCTOR)],
        cwd=ROOT,
        env={**os.environ, "UIO_TEACH_EDITION": "instructor"},
        capture_output=True,
        text=True,
        timeout=BUILD_TIMEOUT,
    )
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    html = INSTRUCTOR / "_build" / "html"
    found = {}
    with serve(html) as url:
        base = url.rstrip("/")
        for page in PAGES:
            for width in (1280, 390):
                context, tab = _open_local(browser, base, page, width)
                try:
                    tab.evaluate(
                        "document.querySelectorAll('main details').forEach(d => d.open = true)"
                    )
                    violations = axe_violations(tab)
                    pictures = tab.evaluate(_STRUCTURE_JS)["pictures"]
                finally:
                    context.close()
                silent = [p["src"] for p in pictures if _NAMELESS.search(p["alt"].strip())]
                if violations or silent:
                    found[f"{page} at {width} px"] = [
                        f"{v['id']} ({v['count']}): {v['where']}" for v in violations
                    ] + [f"picture without words: {s}" for s in silent]
    assert not found, "instructor edition: " + "\n".join(f"{k}: {v}" for k, v in found.items())
