"""What a reader downloads for a page of the built book, on a phone and on a desktop.

The figures' pictures are files of the site (``_ext/figure_files.py``): no page carries a
picture inline. Each page of ``_toc.yml`` is opened in headless Chromium (Debian's
``/usr/bin/chromium``, driven by Playwright) at 390 px (a phone) and at 1280 px, served on
127.0.0.1 like the other browser tests; the browser's own count of the bytes it received (body
and headers, ``Request.sizes()``) for the page's HTML and every picture it fetches is summed,
before the reader scrolls and after the page has been scrolled to its end with every picture
shown. The budgets hold for both widths:

* the HTML and every picture a reader fetches: :data:`PAGE_BUDGET` (today the largest is the
  API page, about 1.2 MiB of text and no picture; the largest chapter, the missile's with eight
  figures and an explorer, about 0.8 MiB on a phone; it was 3.4 MiB with the pictures inline);
* the pictures alone: :data:`PICTURE_BUDGET` (today at most about 0.65 MiB, the missile at
  1280 px).

A picture is fetched only when shown: a phone fetches the phone version of a figure and not the
wide one, a desktop the wide one only, an explorer only the frame on screen, and a picture far
below the first screen only once the reader scrolls to it (``loading="lazy"``). The style
sheets, scripts and fonts every page shares (cached after the first page) are not counted.
Moving an explorer's slider fetches the frame it shows, and nothing else; a chapter opened from
the site's folder on disk (``file://``) shows every picture.
"""

from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import urlsplit

import pytest
from test_book import BROWSER_TIMEOUT_MS, PAGES

from uio_teach.worked import WORKED

MIB = 1024 * 1024
PAGE_BUDGET = int(1.25 * MIB)
PICTURE_BUDGET = int(0.75 * MIB)
# Chromium starts a lazy picture's download when it comes within 1250 px of the screen (2500 px
# on a slow connection): a picture further down than this has not been fetched before the reader
# scrolls.
LAZY_DISTANCE = 2500
WIDTHS = {390: {"width": 390, "height": 844}, 1280: {"width": 1280, "height": 900}}

pytestmark = [pytest.mark.book, pytest.mark.browser]


@pytest.mark.parametrize("page", PAGES)
def test_no_picture_inline(page: str, built_book: Path) -> None:
    text = (built_book / f"{page}.html").read_text(encoding="utf-8")
    inline = re.findall(r"data:image/[a-z+]+;base64,.{0,40}", text)
    assert not inline, f"{page}: {len(inline)} pictures inline, not files: {inline[:3]}"


# Scroll to the end one screen at a time (two frames each, for the lazy pictures' observer),
# then bring every picture not yet loaded into view and wait for it: the page as read to its end.
_READ_TO_END_JS = """
async () => {
  const frames = () => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
  const se = document.scrollingElement;
  for (let y = 0; y < se.scrollHeight; y += window.innerHeight / 2) {
    window.scrollTo(0, y);
    await frames();
  }
  for (const img of document.images) {
    if (img.complete || !img.checkVisibility()) continue;
    img.scrollIntoView();
    await new Promise((resolve) => {
      img.addEventListener("load", resolve, {once: true});
      img.addEventListener("error", resolve, {once: true});
    });
  }
}
"""

# Each shown picture: the file it shows, whether the phone version was on offer and picked, and
# how far below the top of the page it is.
_PICTURES_JS = """
() => Array.from(document.images).filter((img) => img.checkVisibility()).map((img) => {
  const source = img.parentElement.tagName === "PICTURE"
    ? img.parentElement.querySelector("source[media]") : null;
  return {
    current: img.currentSrc, src: img.src,
    narrow: source ? new URL(source.getAttribute("srcset"), location.href).href : null,
    narrowMatches: source ? matchMedia(source.media).matches : false,
    top: img.getBoundingClientRect().top + window.scrollY,
    lazy: img.loading === "lazy",
  };
})
"""


def _weigh(browser, book_server: str, page: str, width: int) -> dict:
    """Open ``page`` at ``width``: the bytes and pictures fetched before scrolling and after."""
    options = {"viewport": WIDTHS[width]}
    if width < 600:
        options.update(is_mobile=True, has_touch=True)
    context = browser.new_context(**options)
    context.set_default_timeout(BROWSER_TIMEOUT_MS)
    tab = context.new_page()
    host = urlsplit(book_server).hostname
    tab.route(
        "**/*",
        lambda route: (
            route.continue_() if urlsplit(route.request.url).hostname == host else route.abort()
        ),
    )
    finished: list = []
    tab.on("requestfinished", lambda request: finished.append(request))
    try:
        tab.goto(f"{book_server}/{page}.html", wait_until="load")
        tab.evaluate("async () => { await document.fonts.ready; }")
        first = list(finished)
        tab.evaluate(_READ_TO_END_JS)
        pictures = tab.evaluate(_PICTURES_JS)
        height = WIDTHS[width]["height"]

        def count(requests: list) -> dict:
            html = pics = 0
            urls = []
            for request in requests:
                size = request.sizes()
                received = size["responseBodySize"] + size["responseHeadersSize"]
                if request.resource_type == "document":
                    html += received
                elif request.resource_type == "image":
                    pics += received
                    urls.append(request.url)
            return {"html": html, "pictures": pics, "urls": urls}

        return {"first": count(first), "read": count(finished), "shown": pictures, "fold": height}
    finally:
        context.close()


def _kib(n: int) -> str:
    return f"{n / 1024:.0f} KiB"


# the phone is where the weight counts and where the narrow pictures must be chosen: in
# `make test`; the desktop's pass runs in the slow set, which CI runs after it
@pytest.mark.parametrize(
    "width", [pytest.param(w, marks=pytest.mark.slow) if w > 600 else w for w in sorted(WIDTHS)]
)
@pytest.mark.parametrize("page", PAGES)
def test_a_reader_downloads_only_what_is_shown(
    page: str, width: int, book_server: str, browser
) -> None:
    weight = _weigh(browser, book_server, page, width)
    read = weight["read"]
    shown = weight["shown"]
    total = read["html"] + read["pictures"]
    assert total <= PAGE_BUDGET, (
        f"{page} at {width} px: {_kib(read['html'])} of HTML and {_kib(read['pictures'])} of "
        f"pictures, more than {_kib(PAGE_BUDGET)}"
    )
    assert read["pictures"] <= PICTURE_BUDGET, (
        f"{page} at {width} px: {_kib(read['pictures'])} of pictures, more than "
        f"{_kib(PICTURE_BUDGET)}"
    )
    # each picture is fetched once, and only the version the screen shows
    fetched = read["urls"]
    assert len(fetched) == len(set(fetched)), f"{page} at {width} px: a picture fetched twice"
    on_screen = {p["current"] for p in shown}
    extra = sorted(set(fetched) - on_screen)
    assert not extra, f"{page} at {width} px: pictures fetched but not shown: {extra[:3]}"
    missing = sorted(on_screen - set(fetched) - {""})
    assert not missing, f"{page} at {width} px: pictures shown, never fetched: {missing[:3]}"
    for picture in shown:
        if picture["narrow"] is None:
            continue
        if width < 600:
            assert picture["narrowMatches"], f"{page}: a figure offers no phone version at {width}"
        chosen = picture["narrow"] if picture["narrowMatches"] else picture["src"]
        assert picture["current"] == chosen, (page, width, picture)
    # a picture far below the first screen waits until the reader scrolls to it
    far = [p for p in shown if p["top"] > weight["fold"] + LAZY_DISTANCE]
    assert all(p["lazy"] for p in far), f"{page} at {width} px: pictures below not lazy: {far}"
    early = {p["current"] for p in far} & set(weight["first"]["urls"])
    assert not early, f"{page} at {width} px: fetched before the reader scrolled: {early}"


# the chapters with a static explorer: every worked example's, and the existence chapter's
EXPLORER_PAGES = [p for p in PAGES if p.split("/")[-1] in {*WORKED, "existence"}]

# Move the page's first explorer to each position of its slider in turn; after each move, once
# the picture has loaded, what it shows.
_SLIDE_JS = """
async () => {
  const root = document.querySelector(".uio-static-explorer");
  const form = root.querySelector("form"), img = root.querySelector("img.uio-frame");
  img.scrollIntoView();
  const seen = [];
  for (let i = 0; i <= Number(form.main.max); i++) {
    form.main.value = String(i);
    form.main.dispatchEvent(new Event("input", {bubbles: true}));
    if (!img.complete) {
      await new Promise((resolve) => {
        img.addEventListener("load", resolve, {once: true});
        img.addEventListener("error", resolve, {once: true});
      });
    }
    seen.push({current: img.currentSrc, width: img.naturalWidth, alt: img.alt});
  }
  return seen;
}
"""


@pytest.mark.parametrize("width", sorted(WIDTHS))
@pytest.mark.parametrize("page", EXPLORER_PAGES)
def test_explorer_fetches_each_frame_when_shown(
    page: str, width: int, book_server: str, browser
) -> None:
    options = {"viewport": WIDTHS[width]}
    context = browser.new_context(**options)
    context.set_default_timeout(BROWSER_TIMEOUT_MS)
    tab = context.new_page()
    try:
        tab.goto(f"{book_server}/{page}.html", wait_until="load")
        seen = tab.evaluate(_SLIDE_JS)
        fetched = tab.evaluate(
            "() => performance.getEntriesByType('resource').map((e) => e.name)"
            ".filter((u) => u.includes('/_images/'))"
        )
        figures = tab.evaluate(
            "() => Array.from(document.images).filter((i) => !i.closest('.uio-static-explorer'))"
            ".map((i) => i.currentSrc)"
        )
    finally:
        context.close()
    assert len(seen) > 1
    assert all(s["width"] > 0 for s in seen), f"{page} at {width} px: a frame did not load"
    frames = {s["current"] for s in seen}
    assert len(frames) == len(seen), f"{page} at {width} px: frames repeat"
    assert frames <= set(fetched), f"{page} at {width} px: frames shown but not fetched"
    # nothing else: neither the frames of the menu's other entries nor the other screen's
    other = sorted(set(fetched) - frames - set(figures))
    assert not other, f"{page} at {width} px: pictures fetched but never shown: {other[:3]}"


def test_pages_work_from_a_folder_on_disk(built_book: Path, browser) -> None:
    """A copy of the site opened from disk (``file://``) shows every picture of a chapter."""
    page = next(p for p in PAGES if p.endswith("missile"))
    context = browser.new_context(viewport=WIDTHS[390], is_mobile=True)
    context.set_default_timeout(BROWSER_TIMEOUT_MS)
    tab = context.new_page()
    try:
        tab.route(
            "**/*",
            lambda route: (
                route.continue_() if route.request.url.startswith("file:") else route.abort()
            ),
        )
        tab.goto((built_book / f"{page}.html").as_uri(), wait_until="load")
        tab.evaluate(_READ_TO_END_JS)
        shown = tab.evaluate(
            "() => Array.from(document.images).filter((i) => i.checkVisibility())"
            ".map((i) => [i.currentSrc, i.naturalWidth])"
        )
    finally:
        context.close()
    assert shown and all(url.startswith("file:") for url, _ in shown)
    broken = [url for url, width in shown if not width]
    assert not broken, f"pictures that do not load from disk: {broken}"
