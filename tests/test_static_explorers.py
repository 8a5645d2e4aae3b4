"""The static explorers in a browser: every position of the slider and the menu shows another
picture, caption and text alternative; the pictures are HiDPI; each explorer page stays small.

Each explorer's static HTML (what the book embeds) is opened from a file in headless Chromium
(Debian's ``/usr/bin/chromium``, driven by Playwright), with every request that leaves the page
blocked. When the book has been built (``_build/html``, by ``tests/test_book.py`` in the same run),
its explorer pages are measured as well.
"""

from __future__ import annotations

import os
import threading
from pathlib import Path

import pytest

import uio_teach as ut
from uio_teach.explorers import case_study_scenario, make_scenario, missile_scenario, pa9_scenario
from uio_teach.explorers.static import static_explorer

ROOT = Path(__file__).resolve().parents[1]
HTML = ROOT / "_build" / "html"
CHROMIUM = Path("/usr/bin/chromium")
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking"]
MAX_PAGE = 2 * 1024 * 1024

pytestmark = [pytest.mark.browser, pytest.mark.timeout(900)]


def _own():
    plant = ut.Plant([[0, 1], [-0.08, 0.6]], [[-0.5, 1]], E=[[0], [1]], dt=1)
    return make_scenario(plant, "uio", name="own")


SCENARIOS = {
    "pa9": pa9_scenario,
    "case_study": case_study_scenario,
    "missile": missile_scenario,
    "existence": _own,
}


def _in_chromium(work) -> None:
    """Run ``work(browser)`` in headless Chromium, in a thread of its own (an earlier test may
    leave an asyncio loop running in the main thread, where Playwright's sync API will not
    start)."""
    if not CHROMIUM.exists():
        message = f"chromium missing: {CHROMIUM} not found (apt-get install chromium)"
        if os.environ.get("CI") == "true":
            pytest.fail(message, pytrace=False)
        pytest.skip(message)
    from playwright.sync_api import sync_playwright

    failure: list[BaseException] = []

    def drive() -> None:
        try:
            with sync_playwright() as playwright:
                browser = playwright.chromium.launch(
                    executable_path=str(CHROMIUM), args=ARGS, headless=True
                )
                try:
                    work(browser)
                finally:
                    browser.close()
        except BaseException as exc:  # re-raised in the test's thread
            failure.append(exc)

    thread = threading.Thread(target=drive)
    thread.start()
    thread.join()
    if failure:
        raise failure[0]


_STATE_JS = """() => {
  const img = document.querySelector('img.uio-frame');
  return {src: img.src, alt: img.alt, width: img.naturalWidth,
          caption: document.querySelector('.uio-caption').textContent,
          live: document.querySelector('.uio-caption').getAttribute('aria-live')};
}"""

_SET_JS = """([i, j]) => {
  const form = document.querySelector('.uio-static-explorer form');
  form.main.value = String(i); form.dist.value = String(j);
  form.main.dispatchEvent(new Event('input', {bubbles: true}));
}"""


@pytest.mark.parametrize("name", sorted(SCENARIOS))
def test_every_position_changes_picture_caption_and_alt(name, tmp_path):
    page_data = static_explorer(SCENARIOS[name]())
    html = f"<!doctype html><html lang='en'><body>{page_data.html}</body></html>"
    path = tmp_path / f"{name}.html"
    path.write_text(html, encoding="utf-8")
    assert path.stat().st_size <= MAX_PAGE
    values = 1 + max(f.index[0] for f in page_data.frames)
    kinds = 1 + max(f.index[1] for f in page_data.frames)
    seen = []

    def work(browser) -> None:
        page = browser.new_page(viewport={"width": 390, "height": 844})  # a phone
        page.route(
            "**/*", lambda r: r.continue_() if r.request.url.startswith("file:") else r.abort()
        )
        page.goto(path.as_uri())
        for j in range(kinds):
            for i in range(values):
                page.evaluate(_SET_JS, [i, j])
                page.wait_for_function("() => document.querySelector('img.uio-frame').complete")
                state = page.evaluate(_STATE_JS)
                assert state["width"] >= 1200, state["width"]
                assert state["live"] == "polite"
                seen.append(state)
        page.close()

    _in_chromium(work)
    assert len(seen) == values * kinds
    for key in ("src", "alt", "caption"):
        assert len({s[key] for s in seen}) == len(seen), f"{key} repeats between positions"


@pytest.mark.parametrize("chapter", sorted(SCENARIOS))
def test_built_explorer_pages_are_small(chapter):
    page = HTML / "book" / f"{chapter}.html"
    if not page.exists():
        pytest.skip("the book is not built (tests/test_book.py builds it)")
    text = page.read_text(encoding="utf-8")
    assert "uio-static-explorer" in text
    assert "widget-state+json" not in text  # the unused widget state is left out
    assert page.stat().st_size <= MAX_PAGE, page.stat().st_size
