"""The explorers in the static book: pre-computed frames, a slider and a few lines of JavaScript.

Without a Python kernel an ipywidgets explorer shows a still picture at best.
:func:`static_html` therefore renders a small grid of frames -- the explorer's
main control (the first movable pole, or the disturbance amplitude when no
pole can be moved) times the disturbance types -- as small palette PNGs
embedded in plain HTML (``data:`` URLs), with an ``<input type="range">``
slider, a ``<select>`` for the disturbance type and one inline ``oninput``
handler that swaps the displayed picture. No external script, stylesheet or
URL is involved, so the page works offline and from ``file://``.

The layout reflows with the screen (a few CSS rules in the HTML itself): on a
wide screen the controls share a row above a picture at most 780 px wide; on a
phone each control takes a row of its own and the picture shrinks to the
column, keeping its aspect ratio, so the page never scrolls sideways. There,
"enlarge the picture" (or a tap on the picture) shows it at the size its text
is drawn for, scrolling sideways inside its own box.

Each frame is computed by :func:`uio_teach.explorers.compute_frame` and drawn by
:class:`uio_teach.explorers.ExplorerFigure`, exactly as in the live explorer.

Examples
--------
>>> from uio_teach.explorers import case_study_scenario
>>> from uio_teach.explorers.static import static_explorer
>>> page = static_explorer(case_study_scenario(), values=(0.0, 0.5), disturbances=("sinusoid",))
>>> page.count
2
>>> "http" in page.html
False
"""

from __future__ import annotations

import base64
import html
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._display import format_complex, format_poles
from ._figure import ExplorerFigure
from .frames import Frame, compute_frame
from .model import DISTURBANCES, Scenario, Settings

__all__ = ["StaticFrame", "StaticExplorer", "frame_settings", "static_explorer", "static_html"]

_IDS = itertools.count(1)


@dataclass(frozen=True)
class StaticFrame:
    """One pre-computed picture of a static explorer.

    Attributes
    ----------
    index : tuple of int
        ``(i, j)``: position of the main control's value and of the
        disturbance type in the grid.
    settings : Settings
        The control values of the picture.
    png : bytes
        The picture.
    caption : str
        The observer poles and any message of the frame.
    label : str
        The main control's value as shown next to the slider.
    alt : str
        The picture's text alternative: what its curves do.

    Examples
    --------
    >>> from uio_teach.explorers import pa9_scenario
    >>> from uio_teach.explorers.static import static_explorer
    >>> page = static_explorer(pa9_scenario(), values=(-1.0,), disturbances=("sinusoid",))
    >>> page.frames[0].png[:4], page.frames[0].label
    (b'\\x89PNG', '-1')
    """

    index: tuple[int, int]
    settings: Settings
    png: bytes
    caption: str
    label: str
    alt: str = ""

    @property
    def data_url(self) -> str:
        """The picture as a ``data:image/png;base64`` URL."""
        return "data:image/png;base64," + base64.b64encode(self.png).decode("ascii")


@dataclass(frozen=True)
class StaticExplorer:
    """A static explorer: its frames and its HTML (``_repr_html_`` shows it in a notebook).

    Attributes
    ----------
    html : str
        The self-contained HTML.
    frames : tuple of StaticFrame
        The pre-computed pictures.
    element_id : str
        The id of the outer ``<div>`` (unique per explorer in a session).

    Examples
    --------
    >>> from uio_teach.explorers import case_study_scenario
    >>> from uio_teach.explorers.static import static_explorer
    >>> page = static_explorer(case_study_scenario(), values=(0.0,), disturbances=("sinusoid",))
    >>> page.element_id in page.html, page.count
    (True, 1)
    """

    html: str
    frames: tuple[StaticFrame, ...]
    element_id: str

    @property
    def count(self) -> int:
        """The number of frames."""
        return len(self.frames)

    def _repr_html_(self) -> str:
        return self.html


def main_control_label(scenario: Scenario, settings: Settings) -> str:
    """The label of the static slider (internal helper)."""
    if scenario.static_control == "amplitude":
        return "disturbance amplitude"
    name = scenario.observer_name
    others = [format_complex(p, 3) for p in settings.poles[1:]]
    if not others:
        return f"{name} pole"
    return f"{name} pole 1 (other movable poles {', '.join(others)})"


def frame_settings(
    scenario: Scenario, settings: Settings, value: float, disturbance: str
) -> Settings:
    """The settings of one static frame: the main control set to ``value``.

    Parameters
    ----------
    scenario : Scenario
        The scenario; its ``static_control`` names the main control.
    settings : Settings
        The other control values.
    value : float
        The value of the main control (the first movable pole, or the amplitude).
    disturbance : str
        The disturbance type.

    Returns
    -------
    Settings

    Examples
    --------
    >>> from uio_teach.explorers import pa9_scenario
    >>> from uio_teach.explorers.static import frame_settings
    >>> s = pa9_scenario()
    >>> frame_settings(s, s.defaults, -4.0, "random steps").poles
    (-4.0, -2.0, -3.0)
    """
    if scenario.static_control == "amplitude":
        return settings.replace(amplitude=float(value), disturbance=disturbance, mode="poles")
    poles = (float(value), *settings.poles[1:])
    return settings.replace(poles=poles, disturbance=disturbance, mode="poles")


def _caption(frame: Frame) -> str:
    name = frame.scenario.observer_name
    parts = [f"disturbance: {frame.disturbance}"] if frame.disturbance else []
    if frame.poles.size:
        parts.append(f"{name} poles: {format_poles(frame.poles, 3)}")
    parts += frame.all_messages
    text = " ".join(p[:1].upper() + p[1:] + "." for p in parts)
    if frame.explanation:
        text = (text + " " if text else "") + frame.explanation
    return text


def _alt(frame: Frame, label: str, value: str) -> str:
    """What the picture shows, in a few sentences: what each observer's error does.

    The words come from the frame's verdicts on the simulated errors, as do the
    messages in the caption and the footer, so the three never disagree.
    """
    sc = frame.scenario
    parts = [f"{sc.title} explorer at {label} {value}."]
    rows = (
        (sc.observer_name, frame.observer, frame.verdict, frame.observer_message),
        (
            "Luenberger observer",
            frame.luenberger,
            frame.luenberger_verdict,
            frame.luenberger_message,
        ),
    )
    for who, observer, verdict, message in rows:
        if verdict is not None:
            parts.append(f"{who}: the error size |e| {verdict.words()}.")
        elif observer is None:
            parts.append(f"{who}: no curve (no design).")
        elif "overflows" in message:
            parts.append(f"{who}: no curve (the error overflows).")
        else:
            parts.append(f"{who}: no curve (the simulation failed).")
    if frame.poles.size:
        parts.append(f"Pole map: {sc.observer_name} poles {format_poles(frame.poles, 3)}.")
    return " ".join(parts)


def static_explorer(
    scenario: Scenario,
    settings: Settings | None = None,
    *,
    values: Sequence[float] | None = None,
    disturbances: Sequence[str] | None = None,
    dpi: float = 144,
    colors: int = 64,
    element_id: str | None = None,
) -> StaticExplorer:
    """Pre-compute the frames of a static explorer and write its HTML.

    Parameters
    ----------
    scenario : Scenario
        What to explore.
    settings : Settings, optional
        The values of the other controls; the scenario's defaults by default.
    values : sequence of float, optional
        The values of the main control (``scenario.static_values`` by
        default); the slider starts at the value closest to the settings'
        own.
    disturbances : sequence of str, optional
        The disturbance types offered (default: the settings' own type and
        one that contrasts with it, random steps or a sinusoid; any of
        :data:`~uio_teach.explorers.DISTURBANCES`); the select starts at the
        settings' type when it is offered.
    dpi : float
        Resolution of the pictures (144: about 1300 pixels wide, twice the
        density at which they are shown).
    colors : int
        Palette size of the PNGs (smaller files).
    element_id : str, optional
        The id of the outer element; a unique ``uio-explorer-<name>-<k>``
        by default.

    Returns
    -------
    StaticExplorer

    Raises
    ------
    ValueError
        No values or no disturbance types, or an unknown disturbance type.

    Examples
    --------
    >>> from uio_teach.explorers import pa9_scenario
    >>> from uio_teach.explorers.static import static_explorer
    >>> page = static_explorer(pa9_scenario(), values=(-1.0, -2.0),
    ...                        disturbances=("sinusoid", "random steps"))
    >>> page.count, page.html.count('data-k="')
    (4, 4)
    """
    base = scenario.defaults if settings is None else settings
    # ascending: the slider moves right toward larger values, as the pole map's real axis
    values = tuple(sorted(scenario.static_values if values is None else values))
    if disturbances is None:
        other = "sinusoid" if base.disturbance == "random steps" else "random steps"
        disturbances = (base.disturbance, other)
    disturbances = tuple(disturbances)
    if not values or not disturbances:
        raise ValueError("a static explorer needs at least one value and one disturbance type")
    bad = [d for d in disturbances if d not in DISTURBANCES]
    if bad:
        raise ValueError(f"unknown disturbance type(s) {bad}; choose from {DISTURBANCES}")
    current = base.amplitude if scenario.static_control == "amplitude" else _first_pole(base)
    i0 = int(np.argmin([abs(v - current) for v in values]))
    j0 = disturbances.index(base.disturbance) if base.disturbance in disturbances else 0

    figure = ExplorerFigure(scenario, dpi=dpi, sticky=False, fontscale=1.45)
    frames = []
    for j, kind in enumerate(disturbances):
        for i, value in enumerate(values):
            s = frame_settings(scenario, base, value, kind)
            frame = compute_frame(scenario, s)
            figure.update(frame)
            frames.append(
                StaticFrame(
                    index=(i, j),
                    settings=s,
                    png=_png(figure, colors),
                    caption=_caption(frame),
                    label=f"{value:g}",
                    alt=_alt(frame, main_control_label(scenario, base), f"{value:g}"),
                )
            )
    eid = element_id or f"uio-explorer-{scenario.name}-{next(_IDS)}"
    text = _html(scenario, base, frames, values, disturbances, i0, j0, eid)
    return StaticExplorer(html=text, frames=tuple(frames), element_id=eid)


def _png(figure: ExplorerFigure, colors: int) -> bytes:
    """The frame's PNG, re-encoded if its base64 text happens to contain "http".

    Base64 text is random-looking: a page of frames would otherwise contain
    the letters "http" somewhere now and then, which a check for external
    URLs would flag. Another compression level gives other bytes.
    """
    png = figure.to_png(colors=colors)
    for level in (9, 8, 7, 5, 4, 3, 2, 1):
        if "http" not in base64.b64encode(png).decode("ascii").lower():
            break
        png = figure.to_png(colors=colors, draw=False, compress_level=level)
    return png


def _first_pole(settings: Settings) -> float:
    return float(complex(settings.poles[0]).real) if settings.poles else 0.0


def static_html(
    scenario: Scenario,
    settings: Settings | None = None,
    *,
    values: Sequence[float] | None = None,
    disturbances: Sequence[str] | None = None,
    dpi: float = 144,
    colors: int = 64,
    element_id: str | None = None,
) -> str:
    """The HTML of :func:`static_explorer` (same parameters).

    Parameters
    ----------
    scenario : Scenario
        What to explore.
    settings : Settings, optional
        The values of the other controls.
    values : sequence of float, optional
        The values of the main control.
    disturbances : sequence of str, optional
        The disturbance types offered.
    dpi : float
        Resolution of the pictures.
    colors : int
        Palette size of the PNGs.
    element_id : str, optional
        The id of the outer element.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorers import case_study_scenario
    >>> from uio_teach.explorers.static import static_html
    >>> text = static_html(case_study_scenario(), values=(0.0,), disturbances=("sinusoid",),
    ...                    element_id="demo")
    >>> text.startswith('<div id="demo"'), 'type="range"' in text
    (True, True)
    """
    return static_explorer(
        scenario,
        settings,
        values=values,
        disturbances=disturbances,
        dpi=dpi,
        colors=colors,
        element_id=element_id,
    ).html


# The one handler of the form (``this`` is the form): pick the frame of the slider's and the
# select's values, show its picture, caption and value; the check box enlarges the picture.
_JS = (
    "var r=this.parentNode,f=r.querySelector('[data-k=\"'+this.main.value+'-'+this.dist.value"
    "+'\"]');if(f){r.querySelector('img.uio-frame').src=f.getAttribute('data-src');"
    "r.querySelector('img.uio-frame').alt=f.getAttribute('data-alt');"
    "r.querySelector('.uio-caption').textContent=f.getAttribute('data-caption');"
    "this.mainval.value=f.getAttribute('data-label');}"
    "r.classList.toggle('uio-zoomed',this.zoom.checked);"
)

# The check box's words (also its accessible name: the picture is a second label of it).
_ZOOM_TEXT = "enlarge the picture (it then scrolls sideways)"

# Narrower than this (a phone), the controls stack and the picture may be enlarged.
_NARROW = 700

# The layout: on a wide screen the controls share a row above a picture at most 780 px wide; on a
# narrow one each control takes a row of its own, the slider the full width, and the picture
# shrinks to the column. "Enlarge the picture" (or a tap on it) shows it at half its pixel width,
# the size its text is drawn for, scrolling sideways inside its own box, never the page.
_CSS = """
.uio-static-explorer{max-width:780px;box-sizing:border-box}
.uio-static-explorer *{box-sizing:border-box}
.uio-static-explorer form{display:flex;flex-wrap:wrap;gap:0.3em 1.5em;align-items:center;
margin:0.3em 0}
.uio-static-explorer .uio-main{display:flex;flex-wrap:wrap;align-items:center;gap:0 0.5em;
max-width:100%}
.uio-static-explorer .uio-slider{display:inline-flex;align-items:center;gap:0.5em}
.uio-static-explorer input[type=range]{margin:0;vertical-align:middle}
.uio-static-explorer .uio-zoom-label{display:none;align-items:center;gap:0.5em}
.uio-static-explorer .uio-picture{max-width:100%;overflow-x:auto;overflow-y:hidden;
scrollbar-width:thin}
.uio-static-explorer img.uio-frame{display:block;width:100%;max-width:none;height:auto;margin:0}
.uio-static-explorer.uio-zoomed img.uio-frame{width:max(100%, @ZOOM@px)}
.uio-static-explorer .uio-caption{font-size:0.85em;margin:0.2em 0}
.uio-static-explorer .uio-note{font-size:0.8em;opacity:0.75;margin:0.2em 0}
@media (max-width:@NARROW@px){
.uio-static-explorer form{flex-direction:column;align-items:stretch;gap:0.6em}
.uio-static-explorer .uio-main,.uio-static-explorer .uio-dist{display:flex;flex-direction:column;
align-items:stretch;gap:0.2em}
.uio-static-explorer .uio-slider{display:flex;width:100%}
.uio-static-explorer input[type=range]{flex:1 1 auto;min-width:0;width:100%;height:2.5em}
.uio-static-explorer output{min-width:3em;text-align:right}
.uio-static-explorer select{width:100%;min-height:2.5em;font-size:max(16px, 1em)}
.uio-static-explorer .uio-zoom-label{display:flex;min-height:2.5em}
.uio-static-explorer .uio-zoom{width:1.4em;height:1.4em;margin:0}
.uio-static-explorer img.uio-frame{cursor:zoom-in}
.uio-static-explorer.uio-zoomed img.uio-frame{cursor:zoom-out}
.uio-static-explorer .uio-caption{font-size:0.95em}
}
"""


def _png_width(png: bytes) -> int:
    """The width in pixels of a PNG (from its header)."""
    return int.from_bytes(png[16:20], "big")


def _html(
    scenario: Scenario,
    base: Settings,
    frames: list[StaticFrame],
    values: tuple[float, ...],
    disturbances: tuple[str, ...],
    i0: int,
    j0: int,
    eid: str,
) -> str:
    esc = html.escape
    by_index = {f.index: f for f in frames}
    first = by_index[(i0, j0)]
    options = "".join(
        f'<option value="{j}"{" selected" if j == j0 else ""}>{esc(kind)}</option>'
        for j, kind in enumerate(disturbances)
    )
    store = "".join(
        f'<span data-k="{f.index[0]}-{f.index[1]}" data-src="{f.data_url}" '
        f'data-caption="{esc(f.caption)}" data-alt="{esc(f.alt)}" '
        f'data-label="{esc(f.label)}"></span>'
        for f in frames
    )
    label = esc(main_control_label(scenario, base))
    handler = esc(_JS, quote=True)
    alt = esc(first.alt)
    hidden_select = "" if len(disturbances) > 1 else ' style="display:none"'
    # enlarged, the picture is shown at half its pixel width: 2 pixels a CSS pixel, as designed
    css = _CSS.replace("@ZOOM@", str(_png_width(first.png) // 2)).replace("@NARROW@", str(_NARROW))
    css = "".join(line.strip() for line in css.splitlines())
    zoom = f"{eid}-zoom"
    return (
        f'<div id="{eid}" class="uio-static-explorer">'
        f"<style>{css}</style>"
        f'<form onsubmit="return false" oninput="{handler}" onchange="{handler}">'
        f'<label class="uio-main"><span>{label}:</span> <span class="uio-slider">'
        f'<input type="range" name="main" min="0" max="{len(values) - 1}" '
        f'step="1" value="{i0}" aria-label="{label}"> '
        f'<output name="mainval">{esc(first.label)}</output></span></label>'
        f'<label class="uio-dist"{hidden_select}><span>disturbance:</span> '
        f'<select name="dist" aria-label="disturbance type">{options}</select></label>'
        f'<label class="uio-zoom-label"><input type="checkbox" name="zoom" id="{zoom}" '
        f'class="uio-zoom" aria-label="{_ZOOM_TEXT}"> {_ZOOM_TEXT}</label>'
        "</form>"
        # a tap on the picture ticks or clears "enlarge the picture" (its label)
        f'<div class="uio-picture"><label for="{zoom}">'
        f'<img class="uio-frame" src="{first.data_url}" alt="{alt}"></label></div>'
        f'<p class="uio-caption" aria-live="polite">{esc(first.caption)}</p>'
        '<p class="uio-note">Pre-computed pictures: move the '
        "slider or pick a disturbance. Open this page as a notebook with a Python kernel for "
        "the live explorer, where every control can be set.</p>"
        f'<div hidden style="display:none">{store}</div>'
        "</div>"
    )
