"""The static explorers in a browser: every position of the slider and the menu shows another
picture, caption and text alternative; the pictures are HiDPI; each explorer page stays small; on
a 390 px phone the explorer fits the column (the picture drawn for the phone, its text at least
9 CSS pixels, the controls stacked and usable), at 1280 px it keeps its one-row layout, and the
explorer keeps its height while the slider moves.

Each explorer's static HTML (what the book embeds) is opened from a file in headless Chromium
(Debian's ``/usr/bin/chromium``, driven by Playwright), with every request that leaves the page
blocked. The explorer pages of the built book (the run's one build, ``built_book`` in
``tests/conftest.py``) are measured as well.
"""

from __future__ import annotations

import functools
import itertools
from pathlib import Path

import pytest
from browsers import in_chromium

import uio_teach as ut
from uio_teach.explorers import ExplorerFigure, make_scenario, scenario_of
from uio_teach.explorers.static import (
    NARROW_DPI,
    NARROW_FONTSCALE,
    WIDE_FONTSCALE,
    static_explorer,
)
from uio_teach.worked import WORKED

MAX_PAGE = 2 * 1024 * 1024
MAX_BUILT_PAGE = 512 * 1024  # a page of the book with an explorer, its pictures files

pytestmark = [pytest.mark.browser, pytest.mark.timeout(900)]


def _own():
    plant = ut.Plant([[0, 1], [-0.08, 0.6]], [[-0.5, 1]], E=[[0], [1]], dt=1)
    return make_scenario(plant, "uio", name="own")


# every worked example of the registry, and a plant of one's own
SCENARIOS = {
    **{name: functools.partial(scenario_of, name) for name in WORKED},
    "existence": _own,
}


# the tests of one explorer on one worker, which renders its frames once (explorer_page)
NAMES = [
    pytest.param(name, marks=pytest.mark.xdist_group(f"static explorer {name}"), id=name)
    for name in sorted(SCENARIOS)
]


@functools.cache
def explorer_page(name: str):
    """The static explorer of ``name``, rendered once per worker for every test that reads it.

    Rendering every frame of an explorer is most of the cost of these tests; the page is the
    same for each (nothing here changes it), so it is made once."""
    return static_explorer(SCENARIOS[name]())


_STATE_JS = """() => {
  const img = document.querySelector('img.uio-frame');
  return {src: img.src, alt: img.alt, width: img.naturalWidth,
          shown: img.getBoundingClientRect().width, current: img.currentSrc,
          caption: document.querySelector('.uio-caption').textContent,
          live: document.querySelector('.uio-caption').getAttribute('aria-live'),
          status: document.querySelector('.uio-status').getAttribute('aria-live')};
}"""

_SET_JS = """([i, j]) => {
  const form = document.querySelector('.uio-static-explorer form');
  form.main.value = String(i); form.dist.value = String(j);
  form.main.dispatchEvent(new Event('input', {bubbles: true}));
}"""


@pytest.mark.parametrize("name", NAMES)
def test_every_position_changes_picture_caption_and_alt(name, tmp_path):
    page_data = explorer_page(name)
    html = f"<!doctype html><html lang='en'><body>{page_data.html}</body></html>"
    path = tmp_path / f"{name}.html"
    path.write_text(html, encoding="utf-8")
    assert path.stat().st_size <= MAX_PAGE
    values = 1 + max(f.index[0] for f in page_data.frames)
    kinds = 1 + max(f.index[1] for f in page_data.frames)
    seen = []
    by_index = {f.index: f for f in page_data.frames}

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
                assert state["width"] >= 1.5 * state["shown"], state["width"]  # HiDPI
                # the caption is not read at every step; the status is, once the control rests
                assert state["live"] is None and state["status"] == "polite"
                seen.append(state)
            said = by_index[(values - 1, j)].said
            page.wait_for_function(
                "(s) => document.querySelector('.uio-status').textContent === s", arg=said
            )
        page.close()

    in_chromium(work)
    assert len(seen) == values * kinds
    for key in ("src", "current", "alt", "caption"):
        assert len({s[key] for s in seen}) == len(seen), f"{key} repeats between positions"


@pytest.mark.book
@pytest.mark.parametrize("chapter", sorted(SCENARIOS))
def test_built_explorer_pages_are_small(chapter, built_book):
    page = built_book / "book" / f"{chapter}.html"
    text = page.read_text(encoding="utf-8")
    assert "uio-static-explorer" in text
    assert "widget-state+json" not in text  # the unused widget state is left out
    # the frames are files of the site (_ext/figure_files.py), fetched when the slider shows
    # them: the page holds their addresses, captions and text alternatives only (what a reader
    # downloads with the pictures is measured by test_page_weight.py)
    assert "data:image" not in text
    assert page.stat().st_size <= MAX_BUILT_PAGE, page.stat().st_size


# --- a phone: 390 x 844 CSS pixels ---------------------------------------------------------------

PHONE = {"viewport": {"width": 390, "height": 844}, "is_mobile": True, "has_touch": True}
DESKTOP = {"viewport": {"width": 1280, "height": 900}}
VIEWPORT_META = '<meta name="viewport" content="width=device-width, initial-scale=1">'

# Where each part of the k-th explorer is drawn (CSS pixels), the column it sits in (its parent's
# content box) and how wide the document is.
_LAYOUT_JS = """(k) => {
  const root = document.querySelectorAll('.uio-static-explorer')[k];
  const rect = (e) => { const r = e.getBoundingClientRect();
    return {left: r.left, right: r.right, top: r.top, bottom: r.bottom,
            width: r.width, height: r.height}; };
  const shown = (e) => { const r = e.getBoundingClientRect(), s = getComputedStyle(e);
    return r.width > 0 && r.height > 0 && s.visibility !== 'hidden' && s.display !== 'none'; };
  const parent = root.parentElement, ps = getComputedStyle(parent);
  const column = parent.clientWidth - parseFloat(ps.paddingLeft) - parseFloat(ps.paddingRight);
  const picture = root.querySelector('.uio-picture'), img = root.querySelector('img.uio-frame');
  const parts = {slider: 'input[type=range]', value: 'output', select: 'select',
                 caption: '.uio-caption'};
  const controls = {};
  for (const [name, sel] of Object.entries(parts)) {
    const e = root.querySelector(sel);
    controls[name] = Object.assign(rect(e), {shown: shown(e)});
  }
  return {inner: window.innerWidth, doc: document.documentElement.scrollWidth,
          box: rect(root), column, img: rect(img),
          natural: img.naturalWidth, naturalHeight: img.naturalHeight,
          picture: {client: picture.clientWidth, scroll: picture.scrollWidth},
          captions: rect(root.querySelector('.uio-captions')), height: rect(root).height,
          // the caption's own height: its lines (runs of text less than half a line apart count
          // as one) times the line height, and its margins
          text: (() => {
            const p = root.querySelector('.uio-caption'), t = document.createRange();
            t.selectNodeContents(p);
            const cs = getComputedStyle(p), size = parseFloat(cs.fontSize);
            const lh = cs.lineHeight === 'normal' ? 1.2 * size : parseFloat(cs.lineHeight);
            const tops = [...t.getClientRects()].map((r) => r.top).sort((a, b) => a - b);
            let lines = 0, last = -Infinity;
            for (const top of tops) { if (top - last > lh / 2) { lines += 1; last = top; } }
            return lines * lh + parseFloat(cs.marginTop) + parseFloat(cs.marginBottom); })(),
          controls, current: img.currentSrc,
          state: {src: img.currentSrc, alt: img.alt,
                  value: root.querySelector('input[type=range]').value,
                  caption: root.querySelector('.uio-caption').textContent}};
}"""


def _block_the_network(page) -> None:
    page.route("**/*", lambda r: r.continue_() if r.request.url.startswith("file:") else r.abort())


def _smallest_text_px(m: dict, narrow: bool) -> float:
    """The smallest text of the shown picture in CSS pixels (its size in points is the figure's)."""
    scenario = scenario_of("pa9")  # the same fonts in every explorer
    if narrow:
        figure = ExplorerFigure(scenario, dpi=NARROW_DPI, fontscale=NARROW_FONTSCALE, narrow=True)
    else:
        figure = ExplorerFigure(scenario, dpi=144, fontscale=WIDE_FONTSCALE)
    points = figure.smallest_text_pt()
    return points * figure.fig.dpi / 72 * m["img"]["width"] / m["natural"]


def _check_phone_layout(m: dict, where: str) -> None:
    """The explorer fits a 390 px screen: nothing wider than the viewport, the picture drawn for
    the phone fills the column with text of at least 9 CSS pixels, every control on screen and
    stacked."""
    inner = m["inner"]
    assert m["box"]["left"] >= -0.5 and m["box"]["right"] <= inner + 0.5, (where, m["box"])
    assert m["box"]["width"] <= m["column"] + 0.5, (where, m["box"], m["column"])
    assert m["doc"] <= inner, f"{where}: the page scrolls sideways ({m['doc']} > {inner} px)"
    assert m["img"]["width"] <= min(m["column"], m["box"]["width"]) + 0.5, (where, m["img"])
    assert m["img"]["width"] > 300, (where, m["img"])
    assert m["picture"]["scroll"] <= m["picture"]["client"], (where, m["picture"])
    assert m["natural"] >= 1.5 * m["img"]["width"], (where, m["natural"])  # HiDPI
    assert m["natural"] < m["naturalHeight"], f"{where}: not the phone picture"
    assert _smallest_text_px(m, narrow=True) >= 9, (where, m["img"])
    for name, c in m["controls"].items():
        if name == "select" and not c["shown"]:
            continue  # one disturbance type only: no menu
        assert c["shown"], f"{where}: the {name} is not shown"
        assert c["left"] >= -0.5 and c["right"] <= inner + 0.5, (where, name, c)
    slider = m["controls"]["slider"]
    assert slider["width"] >= 0.7 * m["box"]["width"], (where, slider)  # the whole row: easy to hit
    assert slider["height"] >= 30, (where, slider)  # a finger-sized target
    c = m["controls"]
    # stacked: the menu below the slider, the picture below both
    rows = [c["slider"], c["select"]] if c["select"]["shown"] else [c["slider"]]
    for upper, lower in itertools.pairwise([*rows, m["img"]]):
        assert lower["top"] >= upper["bottom"] - 0.5, (where, upper, lower)
    _check_aspect(m, where)


def _check_aspect(m: dict, where: str) -> None:
    """The picture keeps its aspect ratio (to a pixel of rounding)."""
    shown = m["img"]["height"] / m["img"]["width"]
    drawn = m["naturalHeight"] / m["natural"]
    assert shown == pytest.approx(drawn, abs=1 / m["img"]["width"]), (where, shown, drawn)


_FRAME_SHOWN_JS = """
(k) => {
  const img = document.querySelectorAll(".uio-static-explorer")[k].querySelector("img.uio-frame");
  return img.complete && img.naturalWidth > 0;
}
"""


def _phone_walk(page, k: int, where: str, kinds: int) -> list[dict]:
    """Drive the k-th explorer as a reader would, by mouse and keyboard: slider to either end,
    the other disturbance type. Returns the states seen."""
    root = page.locator(".uio-static-explorer").nth(k)
    root.scroll_into_view_if_needed()
    slider = root.locator("input[type=range]")
    top = int(slider.get_attribute("max"))
    # the frame is a picture file the browser fetches when it comes into view (lazily)
    page.wait_for_function(_FRAME_SHOWN_JS, arg=k)
    seen = [page.evaluate(_LAYOUT_JS, k)]
    _check_phone_layout(seen[0], where)
    box = slider.bounding_box()
    for x, want in ((2, 0), (box["width"] - 2, top)):
        slider.click(position={"x": x, "y": box["height"] / 2})
        page.wait_for_function(_FRAME_SHOWN_JS, arg=k)
        m = page.evaluate(_LAYOUT_JS, k)
        assert m["state"]["value"] == str(want), (where, m["state"]["value"], want)
        seen.append(m)
    slider.focus()
    page.keyboard.press("ArrowLeft")
    page.wait_for_function(_FRAME_SHOWN_JS, arg=k)
    seen.append(page.evaluate(_LAYOUT_JS, k))
    assert seen[-1]["state"]["value"] == str(top - 1), where
    if kinds > 1:
        root.locator("select").select_option(index=1 - int(root.locator("select").input_value()))
        page.wait_for_function(_FRAME_SHOWN_JS, arg=k)
        seen.append(page.evaluate(_LAYOUT_JS, k))
    for m in seen:
        _check_phone_layout(m, where)
    # the slider and the menu change the picture, its text alternative and the caption
    for a, b in itertools.pairwise(seen[1:]):
        for key in ("src", "alt", "caption"):
            assert a["state"][key] != b["state"][key], (where, key, a["state"]["value"])
    # the page opens with no empty space under the caption (its box holds its text and the
    # paragraph's margins); from the first move on, the explorer keeps its height while the
    # slider and the menu move (the box holds the longest caption): the page never jumps
    first = seen[0]
    assert abs(first["captions"]["height"] - first["text"]) <= 3, (where, first["text"])
    heights = {round(m["height"], 1) for m in seen[1:]}
    assert len(heights) == 1, (where, heights)
    assert len({round(m["captions"]["height"], 1) for m in seen[1:]}) == 1, where
    assert first["height"] <= seen[1]["height"] + 0.5, where
    return seen


def _standalone(name: str, tmp_path: Path) -> tuple[Path, int]:
    data = explorer_page(name)
    html = (
        f"<!doctype html><html lang='en'><head>{VIEWPORT_META}</head>"
        f"<body><p>Before the explorer.</p>{data.html}</body></html>"
    )
    path = tmp_path / f"{name}.html"
    path.write_text(html, encoding="utf-8")
    return path, 1 + max(f.index[1] for f in data.frames)


@pytest.mark.parametrize("name", NAMES)
def test_phone_layout_reflows_and_stays_operable(name, tmp_path):
    path, kinds = _standalone(name, tmp_path)
    measured = {}

    def work(browser) -> None:
        context = browser.new_context(**PHONE)
        page = context.new_page()
        _block_the_network(page)
        page.goto(path.as_uri())
        measured["seen"] = _phone_walk(page, 0, name, kinds)
        context.close()

    in_chromium(work)
    first = measured["seen"][0]
    print(
        f"{name} at 390 px: explorer {first['box']['width']:.0f} px, picture "
        f"{first['img']['width']:.0f} x {first['img']['height']:.0f} px; under the caption "
        f"{first['captions']['height'] - first['text']:.0f} px at first, the box "
        f"{first['captions']['height']:.0f} px, {measured['seen'][1]['captions']['height']:.0f} px "
        "after the first move"
    )


@pytest.mark.parametrize("name", NAMES)
def test_wide_layout_is_kept(name, tmp_path):
    """At 1280 px the controls share one row above a 780 px picture, drawn wide, with text of at
    least 9 CSS pixels."""
    path, kinds = _standalone(name, tmp_path)
    measured = {}

    def work(browser) -> None:
        context = browser.new_context(**DESKTOP)
        page = context.new_page()
        _block_the_network(page)
        page.goto(path.as_uri())
        measured["m"] = page.evaluate(_LAYOUT_JS, 0)
        context.close()

    in_chromium(work)
    m = measured["m"]
    assert m["box"]["width"] == 780 and m["img"]["width"] == 780, m
    assert m["natural"] > m["naturalHeight"]  # the wide picture
    assert _smallest_text_px(m, narrow=False) >= 9
    c = m["controls"]
    if kinds > 1:  # one row: the menu right of the slider, on the same middle line
        assert c["slider"]["right"] < c["select"]["left"], c
        middle = [(c[k]["top"] + c[k]["bottom"]) / 2 for k in ("slider", "select")]
        assert abs(middle[0] - middle[1]) < 4, c
    assert abs(c["slider"]["height"] - 16) < 8 and c["select"]["height"] < 30
    _check_aspect(m, name)


@pytest.mark.book
@pytest.mark.parametrize("chapter", sorted(SCENARIOS))
def test_built_explorer_pages_read_on_a_phone(chapter, built_book):
    page_file = built_book / "book" / f"{chapter}.html"
    seen = {}

    def work(browser) -> None:
        context = browser.new_context(**PHONE)
        page = context.new_page()
        _block_the_network(page)
        page.goto(page_file.as_uri())
        count = page.locator(".uio-static-explorer").count()
        assert count >= 1
        for k in range(count):
            kinds = page.locator(".uio-static-explorer").nth(k).locator("option").count()
            seen[k] = _phone_walk(page, k, f"{chapter} explorer {k + 1}", kinds)[0]
        context.close()

    in_chromium(work)
    for k, m in seen.items():
        print(
            f"{chapter} explorer {k + 1} at 390 px: column {m['column']:.0f} px, picture "
            f"{m['img']['width']:.0f} x {m['img']['height']:.0f} px"
        )


# Each control of the explorer as a keyboard and screen-reader user meets it: its accessible name,
# whether it has focus, the width of its focus ring, its value as read out, the picture's text
# alternative and the live region that announces the caption.
_CONTROLS_JS = """
(k) => {
  const root = document.querySelectorAll(".uio-static-explorer")[k];
  const el = document.activeElement;
  const label = el.labels && el.labels.length ? el.labels[0].textContent.trim() : "";
  const ring = getComputedStyle(el);
  // the region that speaks (the value beside the slider is shown, not spoken: aria-live off)
  const live = root.querySelector("[aria-live]:not([aria-live='off'])");
  return {
    inside: root.contains(el), tag: el.tagName, name: el.getAttribute("aria-label") || label,
    ring: ring.outlineStyle !== "none" ? parseFloat(ring.outlineWidth) : 0,
    valuetext: el.getAttribute("aria-valuetext"),
    shown: (root.querySelector("output") || {}).value,
    alt: root.querySelector("img.uio-frame").alt,
    live: live ? live.getAttribute("aria-live") + ": " + live.textContent : "",
    group: root.getAttribute("role") + " " + root.getAttribute("aria-label"),
  };
}
"""


# Whether the explorer's status has said something new since ``before``.
_SPOKEN_JS = """([k, before]) => {
  const root = document.querySelectorAll(".uio-static-explorer")[k];
  const live = root.querySelector("[aria-live]:not([aria-live='off'])");
  return live && (live.getAttribute("aria-live") + ": " + live.textContent) !== before;
}"""


@pytest.mark.parametrize("name", NAMES)
def test_controls_work_from_the_keyboard_with_focus_labels_and_announcements(name, tmp_path):
    """Tab reaches the slider and the disturbance menu; each shows a focus ring and has a name;
    the arrow keys move the slider, whose value is read out as shown (not as its index), and the
    picture's text alternative and the announced caption change with it."""
    path, kinds = _standalone(name, tmp_path)
    seen = []

    def work(browser) -> None:
        context = browser.new_context(viewport={"width": 1280, "height": 900})
        page = context.new_page()
        _block_the_network(page)
        page.goto(path.as_uri())
        page.keyboard.press("Tab")  # from the top of the page to the slider
        seen.append(page.evaluate(_CONTROLS_JS, 0))
        page.keyboard.press("End")
        page.keyboard.press("ArrowLeft")
        moved = page.evaluate(_CONTROLS_JS, 0)
        if moved["shown"] == seen[0]["shown"]:  # the slider starts one short of its end
            page.keyboard.press("ArrowLeft")
            moved = page.evaluate(_CONTROLS_JS, 0)
        # the status speaks once the control has rested on its frame
        page.wait_for_function(_SPOKEN_JS, arg=[0, seen[0]["live"]])
        seen.append(page.evaluate(_CONTROLS_JS, 0))
        if kinds > 1:
            page.keyboard.press("Tab")  # the disturbance menu
            page.keyboard.press("ArrowDown")
            page.wait_for_function(_SPOKEN_JS, arg=[0, seen[-1]["live"]])
            seen.append(page.evaluate(_CONTROLS_JS, 0))
        context.close()

    in_chromium(work)
    first, moved = seen[0], seen[1]
    assert first["group"].startswith("group ") and "explorer" in first["group"], first
    for state in seen:
        assert state["inside"], (name, state)
        assert state["name"], f"{name}: a control without a name: {state}"
        assert state["ring"] >= 2, f"{name}: no visible focus on {state['tag']}: {state}"
        assert state["live"].startswith("polite: ") and len(state["live"]) > 20, state
    assert first["tag"] == "INPUT" and moved["tag"] == "INPUT", seen
    assert first["valuetext"] == first["shown"] and moved["valuetext"] == moved["shown"], seen
    assert moved["shown"] != first["shown"] and moved["alt"] != first["alt"], seen
    assert moved["live"] != first["live"], seen
    if kinds > 1:
        menu = seen[2]
        assert menu["tag"] == "SELECT" and "disturbance" in menu["name"], menu
        assert menu["alt"] != moved["alt"] and menu["live"] != moved["live"], menu
