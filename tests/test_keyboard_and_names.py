"""Every page as a keyboard-only and a blind student meets it, in headless Chromium.

Each page of the one book build (``book_server``, every page ``_toc.yml`` lists, whatever new
chapters it gains) is opened once per colour scheme at 1280 px, and its Tab order walked to the
end, pressing Tab as a reader does:

* the Tab stops are the links, the controls and the frames that scroll: no formula is one (the
  key M reaches them), and the number of presses before each explorer's first control is the
  number of those before it on the page (printed, for the record);
* every Tab stop shows a focus ring (a solid outline 2 px or wider) whose colour is 3:1 or more
  against the page's background, in the light and the dark theme.

The accessibility tree of the page (Chromium's own, through the DevTools protocol) is walked and
fails on a node that needs a name and has none (headings, links, buttons, images, controls,
named groups), on a control whose name does not hold the words it shows (WCAG 2.5.3), on a
heading or a contents link whose name left its formula out (the names the build gives them,
``_ext/a11y.py``, must be the names the browser reads), on a frame that scrolls announced as a
landmark or under a name another frame has, and on a code cell not announced as code with its
number of lines. The key M is tried on the first formula of the page.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from test_book import PAGES, _open_local

ROOT = Path(__file__).resolve().parents[1]
pytestmark = [pytest.mark.book, pytest.mark.browser, pytest.mark.timeout(1800)]

# Roles (as Chromium's accessibility tree names them) that say nothing without a name.
NEEDS_NAME = {
    "heading", "link", "button", "image", "img", "slider", "combobox", "textbox", "checkbox",
    "radio", "spinbutton", "switch", "tab", "menuitem", "region", "form", "searchbox",
}  # fmt: skip
# Roles whose name comes from what they show: the name must hold those words (WCAG 2.5.3).
LABEL_IN_NAME = {"button", "link", "menuitem", "tab", "checkbox", "radio", "switch"}

_STOP_JS = """
(el) => {
  const luminance = (rgb) => {
    const [r, g, b] = rgb.map((v) => { v /= 255;
      return v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4); });
    return 0.2126 * r + 0.7152 * g + 0.0722 * b;
  };
  const rgb = (css) => (css.match(/[\\d.]+/g) || ["0", "0", "0"]).slice(0, 3).map(Number);
  const back = (e0) => {
    for (let e = e0.parentElement; e; e = e.parentElement) {
      const c = getComputedStyle(e).backgroundColor;
      const parts = c.match(/[\\d.]+/g);
      if (parts && (parts.length < 4 || Number(parts[3]) > 0.5)) return rgb(c);
    }
    const b = getComputedStyle(document.body).backgroundColor;
    return rgb(b && !b.endsWith(", 0)") ? b : "rgb(255, 255, 255)");
  };
  const ratio = (a, b) => {
    const [x, y] = [luminance(a), luminance(b)].sort((p, q) => q - p);
    return (x + 0.05) / (y + 0.05);
  };
  const s = getComputedStyle(el);
  const ring = s.outlineStyle !== "none" && parseFloat(s.outlineWidth) >= 2;
  const text = (el.getAttribute("aria-label") || el.innerText || el.getAttribute("title") || "")
    .replace(/\\s+/g, " ").trim().slice(0, 60);
  return {
    tag: el.tagName.toLowerCase(), text,
    formula: el.tagName === "MJX-CONTAINER" && !el.hasAttribute("data-uio-scroll"),
    explorer: !!el.closest(".uio-static-explorer"),
    ring, ringWidth: s.outlineWidth, ringColour: s.outlineColor,
    contrast: ring ? ratio(rgb(s.outlineColor), back(el)) : 0,
  };
}
"""


def tab_walk(tab, most: int = 2000) -> list[dict]:
    """Press Tab from the top of the page until the focus leaves the page or comes back to an
    element seen before; what each stop is and its focus ring."""
    tab.evaluate("() => { document.activeElement && document.activeElement.blur(); "
                 "window.scrollTo(0, 0); }")  # fmt: skip
    stops: list[dict] = []
    tab.evaluate("() => { window.__uioSeen = new Set(); }")
    for _ in range(most):
        tab.keyboard.press("Tab")
        handle = tab.evaluate_handle("() => document.activeElement")
        fresh = tab.evaluate(
            "(el) => { if (!el || el === document.body || window.__uioSeen.has(el)) return false;"
            " window.__uioSeen.add(el); return true; }",
            handle,
        )
        if not fresh:
            break
        stops.append(tab.evaluate(_STOP_JS, handle))
    return stops


# Facts read in the browser: the formulas in headings and links with the names the build gave
# them, the code cells, the frames that scroll, the first formula and what M does.
_FACTS_JS = """
() => {
  const visible = (el) => el.getClientRects().length > 0;
  const named = Array.from(document.querySelectorAll("h1, h2, h3, h4, h5, h6, a"))
    .filter((el) => el.querySelector("mjx-container") && visible(el))
    .map((el) => ({tag: el.tagName.toLowerCase(), label: el.getAttribute("aria-label") || "",
                   text: el.innerText.replace(/\\s+/g, " ").trim()}));
  const every = Array.from(document.querySelectorAll("main div.cell"));
  const cells = Array.from(document.querySelectorAll("main div.cell div.cell_input")).map((el) => {
    const pre = el.querySelector("pre");
    const number = every.indexOf(el.closest("div.cell")) + 1;
    const lines = pre ? pre.textContent.replace(/\\n+$/, "").split("\\n").length : 0;
    return {role: el.getAttribute("role"), description: el.getAttribute("aria-roledescription"),
            label: el.getAttribute("aria-label") || "", lines, number, code: !!pre};
  });
  const frames = Array.from(document.querySelectorAll("[data-uio-scroll]")).map((el) => ({
    role: el.getAttribute("role"), label: el.getAttribute("aria-label") || "",
    tabindex: el.getAttribute("tabindex")}));
  return {named, cells, frames,
          formulas: document.querySelectorAll("main mjx-container[jax]").length};
}
"""

_PRESS_M_JS = """
() => { const f = document.activeElement;
  const first = Array.from(document.querySelectorAll("main mjx-container[jax]"))
    .find((c) => c.getClientRects().length > 0);
  return f === first; }
"""


def ax_tree(tab) -> list[dict]:
    """Chromium's accessibility tree of the page (every node the tree keeps)."""
    session = tab.context.new_cdp_session(tab)
    try:
        return session.send("Accessibility.getFullAXTree")["nodes"]
    finally:
        session.detach()


def _value(node: dict, key: str) -> str:
    return str((node.get(key) or {}).get("value") or "")


def _words(text: str) -> list[str]:
    """The words of a text, without the letters of formulas (mathematical italic, Greek)."""
    text = re.sub("[\U0001d400-\U0001d7ff\u0370-\u03ff]+\\w*", " ", text)
    return re.sub(r"[^\w ]+", " ", text).lower().split()


def _in_order(shown: list[str], name: list[str]) -> bool:
    """Every word shown is in the name, in the order shown (a formula between them is said in
    words in the name, and left out of what is shown)."""
    rest = iter(name)
    return all(word in rest for word in shown)


def ax_problems(nodes: list[dict]) -> list[str]:
    """The nodes of an accessibility tree that need a name and have none, and the controls whose
    name leaves out the words they show."""
    by_id = {n["nodeId"]: n for n in nodes}

    def shown(node: dict) -> str:
        words: list[str] = []
        for child in node.get("childIds", []):
            c = by_id.get(child)
            if c is None or c.get("ignored"):
                continue
            if _value(c, "role") == "math" or _value(c, "role").startswith("MathML"):
                continue  # a formula: the name says it in words
            if _value(c, "role") in ("StaticText", "InlineTextBox"):
                words.append(_value(c, "name"))
            else:
                words.append(shown(c))
        return " ".join(" ".join(words).split())

    found = []
    for node in nodes:
        if node.get("ignored"):
            continue
        role, name = _value(node, "role"), " ".join(_value(node, "name").split())
        if role in NEEDS_NAME and not name:
            found.append(f"{role} without a name (shows {shown(node)[:60]!r})")
        if role in LABEL_IN_NAME and name:
            text = shown(node)
            if len(_words(text)) >= 2 and not _in_order(_words(text), _words(name)):
                found.append(f"{role} named {name!r} shows {text!r}")
        if role == "region" and "scrolls sideways" in name:
            found.append(f"a frame that scrolls is a landmark: {name!r}")
    return found


_PAGE: dict[tuple[str, str], dict] = {}


def page_walk(browser, book_server: str, page: str, scheme: str) -> dict:
    """One load of ``page`` in ``scheme`` at 1280 px: its Tab walk, facts and tree."""
    key = (page, scheme)
    if key in _PAGE:
        return _PAGE[key]
    context, tab = _open_local(browser, book_server, page, 1280, scheme=scheme)
    try:
        facts = tab.evaluate(_FACTS_JS)
        facts["stops"] = tab_walk(tab)
        if scheme == "light":
            facts["tree"] = ax_problems(ax_tree(tab))
            facts["names"] = {
                " ".join(_value(n, "name").split())
                for n in ax_tree(tab)
                if _value(n, "role") in ("heading", "link")
            }
            tab.evaluate(
                "() => { document.activeElement && document.activeElement.blur(); "
                "window.scrollTo(0, 0); }"
            )
            facts["m_reaches_first_formula"] = None
            if facts["formulas"]:
                tab.keyboard.press("m")
                facts["m_reaches_first_formula"] = tab.evaluate(_PRESS_M_JS)
    finally:
        context.close()
    _PAGE[key] = facts
    return facts


@pytest.mark.parametrize("page", PAGES)
def test_tab_reaches_links_and_controls_not_formulas(page: str, book_server: str, browser) -> None:
    facts = page_walk(browser, book_server, page, "light")
    stops = facts["stops"]
    formulas = [s for s in stops if s["formula"]]
    assert not formulas, f"{page}: {len(formulas)} formulas are Tab stops of {len(stops)}"
    first = next((i for i, s in enumerate(stops) if s["explorer"]), None)
    if first is not None:
        print(f"{page}: {first} Tab stops before the first explorer's first control")
        print("  " + "\n  ".join(f"{s['tag']} {s['text']!r}" for s in stops[:first]))
        before = stops[:first]
        assert all(s["tag"] in ("a", "button", "input", "select", "summary", "label", "textarea")
                   or s["text"] for s in before), before  # fmt: skip
    if facts["formulas"]:
        assert facts["m_reaches_first_formula"], f"{page}: M does not reach the first formula"


@pytest.mark.parametrize("scheme", ["light", pytest.param("dark", marks=pytest.mark.slow)])
@pytest.mark.parametrize("page", PAGES)
def test_every_tab_stop_shows_a_focus_ring(
    page: str, scheme: str, book_server: str, browser
) -> None:
    stops = page_walk(browser, book_server, page, scheme)["stops"]
    assert stops, f"{page}: Tab reaches nothing"
    bad = [
        f"{s['tag']} {s['text']!r}: outline {s['ringWidth']} {s['ringColour']}, "
        f"contrast {s['contrast']:.2f}"
        for s in stops
        if not s["ring"] or s["contrast"] < 3.0
    ]
    assert not bad, f"{page} ({scheme}): Tab stops without a visible focus ring:\n" + "\n".join(bad)


@pytest.mark.parametrize("page", PAGES)
def test_the_accessibility_tree_names_every_node(page: str, book_server: str, browser) -> None:
    facts = page_walk(browser, book_server, page, "light")
    assert not facts["tree"], f"{page}: nodes of the accessibility tree:\n" + "\n".join(
        dict.fromkeys(facts["tree"])
    )
    # headings and contents links with a formula: named with it in words, as the browser reads
    for el in facts["named"]:
        assert el["label"], f"{page}: {el['tag']} {el['text']!r} holds a formula and no name"
        assert el["label"] in facts["names"], (
            f"{page}: {el['tag']} {el['text']!r}: the browser does not read {el['label']!r}"
        )
    # code cells: code, with their lines
    for cell in facts["cells"]:
        if not cell["code"]:
            continue
        assert cell["role"] == "group" and cell["description"] == "code", (page, cell)
        lines = f"{cell['lines']} line" + ("" if cell["lines"] == 1 else "s")
        assert cell["label"] == f"code cell {cell['number']}, {lines}", (page, cell)
    _check_frames(page, facts["frames"])


def _check_frames(page: str, frames: list[dict]) -> None:
    """Frames that scroll: tab stops named by what they hold, none a landmark, no two alike."""
    labels = [f["label"] for f in frames if f["label"]]
    assert all(f["tabindex"] == "0" for f in frames), (page, frames)
    assert not [f for f in frames if f["role"] == "region"], (page, frames)
    twice = sorted({x for x in labels if labels.count(x) > 1})
    assert not twice, f"{page}: frames that scroll under one name: {twice}"


@pytest.mark.slow  # every page opened again, at a phone's width
@pytest.mark.parametrize("page", PAGES)
def test_frames_that_scroll_on_a_phone_are_named_groups(
    page: str, book_server: str, browser
) -> None:
    context, tab = _open_local(browser, book_server, page, 390)
    try:
        frames = tab.evaluate(_FACTS_JS)["frames"]
    finally:
        context.close()
    _check_frames(page, frames)
