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
phone each control takes a row of its own and every frame is shown as drawn for
the phone (:data:`NARROW_PX`): the two observers side by side, one row of panels
per kind of curve, text no smaller than about 9 CSS pixels, so the page never
scrolls sideways and nothing needs enlarging. The caption's box is as tall as the
caption the page opens with; from the first move of a control on, it keeps the
height of the longest caption, so the page does not jump while the slider moves.

Each frame is computed by :func:`uio_teach.explorers.compute_frame` and drawn by
:class:`uio_teach.explorers.ExplorerFigure`, exactly as in the live explorer.

Examples
--------
>>> from uio_teach.explorers import scenario_of
>>> from uio_teach.explorers.static import static_explorer
>>> page = static_explorer(scenario_of("case_study"), values=(0.0, 0.5), disturbances=("sinusoid",))
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
from ..errors import InputError
from ..linalg import is_stable
from ._figure import ExplorerFigure
from .frames import Frame, compute_frame
from .messages import pace_words
from .model import DISTURBANCES, Scenario, Settings

__all__ = [
    "StaticFrame",
    "StaticExplorer",
    "frame_settings",
    "frame_caption",
    "frame_alt",
    "frame_status",
    "static_explorer",
    "static_html",
]

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
    png_narrow : bytes
        The same frame drawn for a phone (two columns, larger text); empty
        when the explorer has no phone layout.
    said : str
        What a screen reader hears once the control has come to rest on this
        frame (:func:`frame_status`): what each observer's error does, and how fast.

    Examples
    --------
    >>> from uio_teach.explorers import scenario_of
    >>> from uio_teach.explorers.static import static_explorer
    >>> page = static_explorer(scenario_of("pa9"), values=(-1.0,), disturbances=("sinusoid",))
    >>> page.frames[0].png[:4], page.frames[0].label
    (b'\\x89PNG', '-1')
    """

    index: tuple[int, int]
    settings: Settings
    png: bytes
    caption: str
    label: str
    alt: str = ""
    png_narrow: bytes = b""
    said: str = ""

    @property
    def data_url(self) -> str:
        """The picture as a ``data:image/png;base64`` URL."""
        return "data:image/png;base64," + base64.b64encode(self.png).decode("ascii")

    @property
    def narrow_url(self) -> str:
        """The phone picture as a ``data:`` URL (the wide one if there is none)."""
        if not self.png_narrow:
            return self.data_url
        return "data:image/png;base64," + base64.b64encode(self.png_narrow).decode("ascii")


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
    >>> from uio_teach.explorers import scenario_of
    >>> from uio_teach.explorers.static import static_explorer
    >>> page = static_explorer(scenario_of("case_study"), values=(0.0,), disturbances=("sinusoid",))
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
    plant = scenario.static_plant_control
    if plant is not None:
        others = [f"{c.label} {c.value:g}" for c in scenario.plant_controls if c is not plant]
        return plant.label + (f" ({', '.join(others)})" if others else "")
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
    >>> from uio_teach.explorers import scenario_of
    >>> from uio_teach.explorers.static import frame_settings
    >>> s = scenario_of("pa9")
    >>> frame_settings(s, s.defaults, -4.0, "random steps").poles
    (-4.0, -2.0, -3.0)
    """
    if scenario.static_control == "amplitude":
        return settings.replace(amplitude=float(value), disturbance=disturbance, mode="poles")
    if scenario.static_plant_control is not None:  # the plant changes, the controls stay
        return settings.replace(disturbance=disturbance, mode="poles")
    poles = (float(value), *settings.poles[1:])
    return settings.replace(poles=poles, disturbance=disturbance, mode="poles")


def frame_caption(frame: Frame) -> str:
    """The caption of a static frame: the plant's note, the disturbance, the poles, every message,
    the explanation.

    Parameters
    ----------
    frame : Frame
        The frame.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorers import compute_frame, scenario_of
    >>> from uio_teach.explorers.static import frame_caption
    >>> frame_caption(compute_frame(scenario_of("pa9")))[:38]
    'Disturbance: sinusoid, amplitude 1, fr'
    """
    name = frame.scenario.observer_name
    parts = [f"disturbance: {frame.disturbance}"] if frame.disturbance else []
    if frame.poles.size:
        parts.append(f"{name} poles: {format_poles(frame.poles, 3)}")
    parts += frame.all_messages
    text = " ".join(p[:1].upper() + p[1:] + "." for p in parts)
    if frame.scenario.note:  # a sentence on this plant, as written (it may start with a symbol)
        text = f"{frame.scenario.note}. {text}"
    if frame.explanation:
        text = (text + " " if text else "") + frame.explanation
    return text


def frame_alt(frame: Frame, label: str, value: str) -> str:
    """The text alternative of a static frame: its settings, what each error does, its panels.

    The words come from the frame's verdicts on the simulated errors, as do the
    messages in the caption and the footer, so the three never disagree. A
    curve that is missing says why in one line: no design, an overflow, or a
    failed simulation. The first sentence names the disturbance and the main
    control's value (before the other controls' values); the last ones say what
    the picture holds: which panel shows what, the guide lines over the error and
    the marks of the pole map, so that the words stand for the whole picture.

    Parameters
    ----------
    frame : Frame
        The frame.
    label, value : str
        The main control's name (other controls' values in brackets after it) and value.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorers import compute_frame, scenario_of
    >>> from uio_teach.explorers.static import frame_alt
    >>> words = frame_alt(compute_frame(scenario_of("pa9")), "UIO pole 1 (others -2, -3)", "-1")
    >>> words.split(". ")[0]
    'PA9 explorer, sinusoid, amplitude 1, frequency 2 rad/s, at UIO pole 1 = -1 (others -2, -3)'
    >>> words.split(". ")[1]
    'UIO: the error size |e| decays from 1.5 to 1.5e-05'
    """
    sc = frame.scenario
    name, _, others = label.partition(" (")
    setting = f"{name} = {value}" + (f" ({others}" if others else "")
    parts = [f"{sc.title} explorer, {frame.disturbance}, at {setting}."]
    rows = (
        (sc.observer_name, frame.observer, frame.verdict, frame.observer_message, frame.poles),
        (
            "Luenberger observer",
            frame.luenberger,
            frame.luenberger_verdict,
            frame.luenberger_message,
            frame.luenberger_poles,
        ),
    )
    for who, observer, verdict, message, poles in rows:
        if verdict is not None:
            stable = bool(np.all(is_stable(poles, sc.discrete))) if poles.size else True
            parts.append(f"{who}: the error size |e| {verdict.words(stable)}.")
        elif observer is None:
            parts.append(f"{who}: no curve (no design).")
        elif "overflows" in message:
            parts.append(f"{who}: no curve (the error overflows).")
        else:
            parts.append(f"{who}: no curve (the simulation failed).")
    marks = []
    if frame.poles.size:
        marks.append(f"{sc.observer_name} poles {format_poles(frame.poles, 3)} (crosses)")
    if frame.luenberger_poles.size:
        marks.append(f"Luenberger poles {format_poles(frame.luenberger_poles, 3)} (plus signs)")
    zeros = np.asarray(sc.invariant_zeros)
    if zeros.size:
        marks.append(f"invariant zeros {format_poles(zeros, 3)} (open circles)")
    if marks:
        parts.append(f"Pole map: {'; '.join(marks)}.")
    parts.append(_frame_panels(frame))
    return " ".join(parts)


def frame_status(frame: Frame, label: str, value: str) -> str:
    """What the explorer's live region says once a control has come to rest on a frame.

    The setting, then for each observer what its error does (the frame's verdict on the
    simulated error: "decays from 1.5 to 1.5e-05", "grows from 1 to 32.8") and how fast, on
    average over the window (:func:`~uio_teach.explorers.messages.pace_words`): the outcome
    that the picture shows, in a few words, where the caption lists the poles and the notes.

    Parameters
    ----------
    frame : Frame
        The frame.
    label, value : str
        The main control's name (other controls' values in brackets after it) and value.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorers import compute_frame, scenario_of
    >>> from uio_teach.explorers.static import frame_status
    >>> said = frame_status(compute_frame(scenario_of("pa9")), "UIO pole 1", "-1")
    >>> print(said.replace(". ", ".\\n").replace(", ten", ",\\n  ten"))
    UIO pole 1 = -1, sinusoid, amplitude 1, frequency 2 rad/s.
    UIO: the error decays from 1.5 to 1.5e-05,
      ten times smaller every 2 s on average.
    Luenberger observer: the error decays from 1.5 to 0.0754,
      ten times smaller every 7.7 s on average.
    """
    sc = frame.scenario
    name = label.partition(" (")[0]
    unit_step = sc.plant.dt is True or (sc.discrete and float(sc.plant.dt) == 1.0)
    t = np.asarray(frame.time, dtype=float)
    span = float(t[-1] - t[0]) if t.size else 0.0
    unit = "steps" if unit_step else "s"
    parts = [f"{name} = {value}, {frame.disturbance}."]
    rows = (
        (sc.observer_name, frame.observer, frame.verdict, frame.observer_message, frame.poles),
        ("Luenberger observer", frame.luenberger, frame.luenberger_verdict,
         frame.luenberger_message, frame.luenberger_poles),
    )  # fmt: skip
    for who, observer, verdict, message, poles in rows:
        if verdict is not None:
            stable = bool(np.all(is_stable(poles, sc.discrete))) if poles.size else True
            pace = pace_words(verdict, span, unit)
            parts.append(
                f"{who}: the error {verdict.words(stable)}" + (f", {pace}." if pace else ".")
            )
        elif observer is None:
            parts.append(f"{who}: no design.")
        elif "overflows" in message:
            parts.append(f"{who}: the error overflows.")
        else:
            parts.append(f"{who}: the simulation failed.")
    return " ".join(parts)


_GUIDE_STYLE = {"certified": "dash-dotted", "rate of slowest moved": "dashed",
                "rate of slowest fixed": "dotted"}  # fmt: skip
"""The line style of each guide over ``|e|`` (as ``_figure`` draws them), by its label's start."""


def _frame_panels(frame: Frame) -> str:
    """What a frame's panels show, in a sentence or two (the end of its text alternative)."""
    sc = frame.scenario
    plant = sc.plant
    time = "the step k" if sc.discrete else "time"
    below = "the residual r" + (
        f" and the reconstructed unknown input {sc.input_symbol}-hat (the true input a wide grey "
        "line under it)"
        if sc.reconstruct
        else ""
    )
    text = (
        f"Panels: for the {sc.observer_name} and for the Luenberger observer, the size of each "
        f"of the {plant.n} error channels against {time} on a logarithmic axis, above "
        f"{below}; then the pole map and the unknown inputs against {time}."
    )
    guides = [
        f"{label} ({style})"
        for label in frame.guides
        for start, style in _GUIDE_STYLE.items()
        if label.startswith(start)
    ]
    if guides:
        text += f" Over the {sc.observer_name}'s error: " + "; ".join(guides) + "."
    return text


def static_explorer(
    scenario: Scenario,
    settings: Settings | None = None,
    *,
    values: Sequence[float] | None = None,
    disturbances: Sequence[str] | None = None,
    dpi: float = 144,
    colors: int = 32,
    element_id: str | None = None,
    narrow: bool = True,
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
        Palette size of the PNGs (smaller files; 32 keeps the curves' colours and the
        text's antialiasing).
    element_id : str, optional
        The id of the outer element; a unique ``uio-explorer-<name>-<k>``
        by default.
    narrow : bool
        Also draw every frame for a phone (:data:`NARROW_PX` CSS pixels or
        less): two columns and larger text, so that no text is smaller than
        about 9 CSS pixels at a 390 px screen's width. The browser picks the
        picture that fits (``<picture>`` with a media query).

    Returns
    -------
    StaticExplorer

    Raises
    ------
    ValueError
        No values or no disturbance types, or an unknown disturbance type.

    Examples
    --------
    >>> from uio_teach.explorers import scenario_of
    >>> from uio_teach.explorers.static import static_explorer
    >>> page = static_explorer(scenario_of("pa9"), values=(-1.0, -2.0),
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
        raise InputError("a static explorer needs at least one value and one disturbance type")
    bad = [d for d in disturbances if d not in DISTURBANCES]
    if bad:
        raise InputError(f"unknown disturbance type(s) {bad}; choose from {DISTURBANCES}")
    plant_control = scenario.static_plant_control
    if scenario.static_control == "amplitude":
        current = base.amplitude
    elif plant_control is not None:
        current = plant_control.value
    else:
        current = _first_pole(base)
    i0 = int(np.argmin([abs(v - current) for v in values]))
    j0 = disturbances.index(base.disturbance) if base.disturbance in disturbances else 0

    def figures(sc: Scenario) -> tuple[ExplorerFigure, ExplorerFigure | None]:
        # static frames never use the LMI mode: the certified envelope is not in their legend
        wide = ExplorerFigure(sc, dpi=dpi, sticky=False, fontscale=WIDE_FONTSCALE, lmi=False)
        if not narrow:
            return wide, None
        small = ExplorerFigure(
            sc, dpi=NARROW_DPI, sticky=False, fontscale=NARROW_FONTSCALE, narrow=True, lmi=False
        )
        return wide, small

    # a plant control remakes the plant and its zeros for each value (and the figures when
    # their panels or legends differ)
    remake = plant_control is not None and scenario.rebuild is not None
    made: dict[tuple[int, int], StaticFrame] = {}
    figure, phone = figures(scenario)
    for i, value in enumerate(values):
        plant_scenario = scenario
        if remake:
            plant_scenario = scenario.rebuild(**{plant_control.name: value})
            same = figure.replace_scenario(plant_scenario)
            if phone is not None:
                same = phone.replace_scenario(plant_scenario) and same
            if not same:  # other panels or legends
                figure, phone = figures(plant_scenario)
        for j, kind in enumerate(disturbances):
            s = frame_settings(scenario, base, value, kind)
            frame = compute_frame(plant_scenario, s)
            figure.update(frame)
            small = b""
            if phone is not None:
                phone.update(frame)
                small = _png(phone, colors)
            made[(i, j)] = StaticFrame(
                index=(i, j),
                settings=s,
                png=_png(figure, colors),
                caption=frame_caption(frame),
                label=f"{value:g}",
                alt=frame_alt(frame, main_control_label(scenario, base), f"{value:g}"),
                png_narrow=small,
                said=frame_status(frame, main_control_label(scenario, base), f"{value:g}"),
            )
    frames = [made[(i, j)] for j in range(len(disturbances)) for i in range(len(values))]
    eid = element_id or f"uio-explorer-{scenario.name}-{next(_IDS)}"
    text = _html(scenario, base, frames, values, disturbances, i0, j0, eid)
    return StaticExplorer(html=text, frames=tuple(frames), element_id=eid)


def _png(figure: ExplorerFigure, colors: int) -> bytes:
    """The frame's PNG, rendered whole, re-encoded if its base64 text happens to contain "http".

    Base64 text is random-looking: a page of frames would otherwise contain
    the letters "http" somewhere now and then, which a check for external
    URLs would flag. Another compression level gives other bytes.
    """
    # a whole render for every frame: a picture of the book depends on nothing drawn before it
    figure.fig.canvas.draw()
    png = figure.to_png(colors=colors, draw=False)
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
    colors: int = 32,
    element_id: str | None = None,
    narrow: bool = True,
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
    narrow : bool
        Also draw the frames for a phone.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorers import scenario_of
    >>> from uio_teach.explorers.static import static_html
    >>> text = static_html(scenario_of("case_study"), values=(0.0,), disturbances=("sinusoid",),
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
        narrow=narrow,
    ).html


# The one handler of the form (``this`` is the form): pick the frame of the slider's and the
# select's values, show its pictures (wide and phone), caption, text alternative and value.
_JS = (
    "var r=this.parentNode,f=r.querySelector('[data-k=\"'+this.main.value+'-'+this.dist.value"
    "+'\"]');if(f){var i=r.querySelector('img.uio-frame'),n=r.querySelector('source');"
    "if(n){n.srcset=f.getAttribute('data-narrow');}i.src=f.getAttribute('data-src');"
    "i.alt=f.getAttribute('data-alt');"
    "r.querySelector('.uio-caption').textContent=f.getAttribute('data-caption');"
    "this.mainval.value=f.getAttribute('data-label');"
    "this.main.setAttribute('aria-valuetext',f.getAttribute('data-label'));"
    "r.classList.add('uio-live');"
    "var o=r.querySelector('.uio-status'),s=f.getAttribute('data-said');clearTimeout(r.uioSaid);"
    "r.uioSaid=setTimeout(function(){if(o.textContent!==s)o.textContent=s;"
    "},@REST@);}"
)

SETTLE_MS = 700
"""The live region speaks once a control has rested this long (milliseconds) on a frame, so
that a slider dragged or held down over many frames is announced once, where it stops."""

NARROW_PX = 700
"""At this width (CSS pixels) or less (a phone), the controls stack and the phone pictures show."""

WIDE_FONTSCALE = 1.5
"""Font scale of the wide pictures, drawn 1296 px wide and shown 688 px wide in the book's column
on a desktop, their smallest text (legends and ticks, 7 pt times this scale) is 11.1 CSS px."""

NARROW_FONTSCALE = 1.25
"""Font scale of the phone pictures (4.4 inches shown 330 px wide or more keep text >= 9 px)."""

NARROW_DPI = 136
"""Resolution of the phone pictures (about 1.6 times the CSS pixels of a phone's column)."""

# The layout: on a wide screen the controls share a row above a picture at most 780 px wide; on a
# narrow one each control takes a row of its own, the slider the full width, and the picture drawn
# for the phone fills the column. The page opens with the caption's box as tall as its caption
# (no empty space under it); from the first move of a control on, the box is as tall as the
# longest caption (every caption is laid out, invisibly, in the same grid cell): the text below
# moves once, at the first move, and never while scrubbing.
_CSS = """
.uio-static-explorer{max-width:780px;box-sizing:border-box}
.uio-static-explorer *{box-sizing:border-box}
.uio-static-explorer form{display:flex;flex-wrap:wrap;gap:0.3em 1.5em;align-items:center;
margin:0.3em 0}
.uio-static-explorer .uio-main{display:flex;flex-wrap:wrap;align-items:center;gap:0 0.5em;
max-width:100%}
.uio-static-explorer .uio-slider{display:inline-flex;align-items:center;gap:0.5em}
.uio-static-explorer input[type=range]{margin:0;vertical-align:middle}
.uio-static-explorer :focus-visible{outline:3px solid #c2185b;outline-offset:2px}
.uio-static-explorer .uio-picture{max-width:100%}
.uio-static-explorer img.uio-frame{display:block;width:100%;max-width:none;height:auto;margin:0}
.uio-static-explorer .uio-captions{display:grid}
.uio-static-explorer .uio-captions>p{grid-area:1/1;font-size:0.85em;margin:0.2em 0}
.uio-static-explorer .uio-sizer{visibility:hidden;display:none}
.uio-static-explorer.uio-live .uio-sizer{display:block}
.uio-static-explorer .uio-status{position:absolute;width:1px;height:1px;overflow:hidden;
clip:rect(0,0,0,0);white-space:nowrap;margin:-1px;padding:0;border:0}
.uio-static-explorer{position:relative}
.uio-static-explorer .uio-note{font-size:0.8em;opacity:0.75;margin:0.2em 0}
@media (max-width:@NARROW@px){
.uio-static-explorer form{flex-direction:column;align-items:stretch;gap:0.6em}
.uio-static-explorer .uio-main,.uio-static-explorer .uio-dist{display:flex;flex-direction:column;
align-items:stretch;gap:0.2em}
.uio-static-explorer .uio-slider{display:flex;width:100%}
.uio-static-explorer input[type=range]{flex:1 1 auto;min-width:0;width:100%;height:2.5em}
.uio-static-explorer output{min-width:3em;text-align:right}
.uio-static-explorer select{width:100%;min-height:2.5em;font-size:max(16px, 1em)}
.uio-static-explorer .uio-captions>p{font-size:0.95em}
}
"""


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
    phone = bool(first.png_narrow)
    store = "".join(
        f'<span data-k="{f.index[0]}-{f.index[1]}" data-src="{f.data_url}" '
        + (f'data-narrow="{f.narrow_url}" ' if phone else "")
        + f'data-caption="{esc(f.caption)}" data-alt="{esc(f.alt)}" '
        f'data-said="{esc(f.said)}" data-label="{esc(f.label)}"></span>'
        for f in frames
    )
    # every caption, invisible, in the caption's grid cell: once a control has moved, the box is
    # as tall as the longest
    sizers = "".join(
        f'<p class="uio-sizer" aria-hidden="true">{esc(c)}</p>'
        for c in dict.fromkeys(f.caption for f in frames)
    )
    label = esc(main_control_label(scenario, base))
    handler = esc(_JS.replace("@REST@", str(SETTLE_MS)), quote=True)
    alt = esc(first.alt)
    hidden_select = "" if len(disturbances) > 1 else ' style="display:none"'
    css = _CSS.replace("@NARROW@", str(NARROW_PX))
    css = "".join(line.strip() for line in css.splitlines())
    source = (
        f'<source media="(max-width:{NARROW_PX}px)" srcset="{first.narrow_url}">' if phone else ""
    )
    return (
        f'<div id="{eid}" class="uio-static-explorer" role="group" '
        f'aria-label="{esc(scenario.title)} explorer">'
        f"<style>{css}</style>"
        f'<form onsubmit="return false" oninput="{handler}" onchange="{handler}" '
        f'aria-label="controls of the {esc(scenario.title)} explorer">'
        f'<label class="uio-main"><span>{label}:</span> <span class="uio-slider">'
        f'<input type="range" name="main" min="0" max="{len(values) - 1}" '
        f'step="1" value="{i0}" aria-label="{label}" aria-valuetext="{esc(first.label)}"> '
        f'<output name="mainval" aria-live="off">{esc(first.label)}</output></span></label>'
        f'<label class="uio-dist"{hidden_select}><span>disturbance:</span> '
        f'<select name="dist" aria-label="disturbance type">{options}</select></label>'
        "</form>"
        f'<div class="uio-picture"><picture>{source}'
        f'<img class="uio-frame" src="{first.data_url}" alt="{alt}"></picture></div>'
        f'<div class="uio-captions"><p class="uio-caption">'
        f"{esc(first.caption)}</p>{sizers}</div>"
        f'<p class="uio-status" role="status" aria-live="polite" aria-atomic="true">'
        f"{esc(first.said)}</p>"
        '<p class="uio-note">Pre-computed pictures: move the '
        "slider or pick a disturbance. Open this page as a notebook with a Python kernel for "
        "the live explorer, where every control can be set.</p>"
        f'<div hidden style="display:none">{store}</div>'
        "</div>"
    )
