"""Live explorers: ipywidgets controls wired to :mod:`uio_teach.explorers`.

One explorer per example of the course, and one for any plant::

    from uio_teach.explorers import widgets
    widgets.pa9_explorer()            # PA9 decoupling UIO, three movable poles
    widgets.case_study_explorer()     # discrete case study: one pole, or the LMI bound
    widgets.missile_explorer()        # missile autopilot: PMO, reconstructed inputs
    widgets.tank_explorer()           # quadruple tank: UIO poles and a slider per valve
    widgets.explorer(plant, "pmo")    # your own plant

Each shows the unknown input observer next to a plain Luenberger observer with
the same poles: the error, the residual (and, for the missile, the
reconstructed unknown inputs), a pole map and the applied unknown signals.
This module only wires controls: the computing and drawing are the pure
functions of :mod:`uio_teach.explorers`. Every slider has
``continuous_update=False`` (a slow redraw never queues up), and the figure
is updated in place and shown as a PNG in an ``ipywidgets.Image``.

In the static book (no kernel) the same object shows pre-computed frames
with a slider (:mod:`uio_teach.explorers.static`): its
``_repr_mimebundle_`` holds both the widget view and that HTML, and the
book prefers the HTML.

Examples
--------
>>> from uio_teach.explorers import widgets
>>> ex = widgets.pa9_explorer(static=False)
>>> sorted(ex.controls)[:4]
['amplitude', 'disturbance', 'frequency', 'noise']
>>> ex.set(**{"pole 1": -4.0})
>>> ex.settings.poles
(-4.0, -2.0, -3.0)
"""

from __future__ import annotations

import cmath
import dataclasses
import html
import math
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

try:
    import ipywidgets as W
except ImportError as err:  # the live explorers are an extra: say so in one line
    raise ImportError(
        f"the live explorers need {err.name or 'ipywidgets'}, which is not installed: "
        "pip install 'uio-teach[explorers]' (the static explorers of uio_teach.explorers "
        "need no extra)"
    ) from None

from .. import tolerances as tols
from .._display import format_poles
from ..errors import InputError
from ..plant import Plant
from ._drag import DragPoles, drag_available, in_kernel
from ._figure import ExplorerFigure
from .frames import Frame, compute_frame
from .model import DISTURBANCES, STARTS, Scenario, Settings
from .scenarios import (
    make_scenario,
    scenario_of,
)
from .static import frame_alt, frame_status, static_html

__all__ = [
    "Explorer",
    "pa9_explorer",
    "case_study_explorer",
    "missile_explorer",
    "tank_explorer",
    "worked_explorer",
    "explorer",
    "drag_available",
]

# The explorer on display for each scenario name: re-running a cell closes the previous one,
# so its figure and widgets are freed instead of piling up.
_LIVE: dict[str, Explorer] = {}


_STYLE = {"description_width": "120px"}
_WIDTH = "330px"


def _nice_step(span: float, parts: int) -> float:
    raw = span / parts if span > 0 else 0.01
    exp = 10.0 ** math.floor(math.log10(raw))
    for m in (5, 2, 1):
        if m * exp <= raw:
            return m * exp
    return exp  # pragma: no cover


def _slider(description: str, lo: float, hi: float, value: float, parts: int = 200):
    step = _nice_step(hi - lo, parts)
    decimals = max(0, -math.floor(math.log10(step)))
    return W.FloatSlider(
        value=float(np.clip(value, lo, hi)),
        min=lo,
        max=hi,
        step=step,
        description=description,
        continuous_update=False,
        readout_format=f".{decimals}f",
        style=_STYLE,
        layout=W.Layout(width=_WIDTH),
    )


class _Slot:
    """The controls of one movable real pole or complex pair."""

    def __init__(self, index: int, kind: str, controls: dict[str, W.FloatSlider]) -> None:
        self.index = index
        self.kind = kind
        self.controls = controls


class Explorer(DragPoles):
    """A live explorer: controls, the figure and messages, wired to :func:`compute_frame`.

    Build one with :func:`pa9_explorer`, :func:`case_study_explorer`,
    :func:`missile_explorer` or :func:`explorer`. Display it (last line of a
    cell): with a kernel, the controls act at once; in the static book the
    pre-computed frames of :func:`uio_teach.explorers.static.static_html`
    show instead.

    Parameters
    ----------
    scenario : Scenario
        What to explore.
    settings : Settings, optional
        The starting values of the controls (the scenario's defaults).
    dpi : float
        Resolution of the live figure.
    static : bool
        Include the static frames in the display (needed for the static
        book; ``False`` displays faster in a live notebook).
    drag : bool, optional
        Show the figure as an ipympl canvas on which the movable poles can be
        dragged on the pole map (besides the sliders). By default in a Jupyter
        kernel with ipympl installed; otherwise the figure is a picture and the
        sliders work alone.

    Attributes
    ----------
    scenario : Scenario
        The scenario.
    controls : dict
        The control widgets by name: ``"pole 1"`` ... (or, for a complex
        pair, ``"pole 2 real part"`` and ``"pole 2 frequency"``, in discrete
        time ``"pole 2 radius"`` and ``"pole 2 angle"``), ``"pattern"`` (how
        many complex pairs), ``"mode"`` and ``"decay"`` (LMI), ``"disturbance"``,
        ``"amplitude"``, ``"frequency"``, ``"period"``, ``"noise"``, ``"tau"``,
        ``"start"`` (where the observers start, ``uio_teach.explorers.STARTS``),
        and one slider per physical parameter of the plant
        (``Scenario.plant_controls``, named as they are, e.g. ``"gamma1"``):
        moving one remakes the plant, its existence check and the figure.
    figure : ExplorerFigure
        The figure, updated in place.
    frame : Frame
        The frame on display.
    image : ipywidgets.Image
        The rendered figure.
    message : ipywidgets.HTML
        The poles and the messages of the frame.
    widget : ipywidgets.VBox
        The whole explorer.

    Examples
    --------
    >>> from uio_teach.explorers import widgets
    >>> ex = widgets.case_study_explorer(static=False)
    >>> ex.controls["pole 1"].value = 1.05      # what a student's slider does
    >>> print(ex.frame.observer_message)   # doctest: +NORMALIZE_WHITESPACE
    this pole makes the PMO unstable: the error grows (pole 1.05 outside the unit circle;
    |e| from 3.74 to 33.4)
    >>> ex.set(mode="lmi", decay=0.4)
    >>> print(ex.frame.observer_message)   # doctest: +NORMALIZE_WHITESPACE
    no gain meets the bound radius 0.4: the fixed poles (invariant zeros, radius 0.5)
    cannot move; choose a bound beyond them
    """

    def __init__(
        self,
        scenario: Scenario,
        settings: Settings | None = None,
        *,
        dpi: float = 90,
        static: bool = True,
        drag: bool | None = None,
    ) -> None:
        old = _LIVE.pop(scenario.name, None)
        if old is not None:
            old.close()
        _LIVE[scenario.name] = self
        self.scenario = scenario
        self._base = scenario.defaults if settings is None else settings
        self._static = static
        self._static_html: str | None = None
        self._holding = 0
        self._reverting = False
        self._refused = ""
        self.controls: dict[str, W.Widget] = {}
        self._slots: list[_Slot] = []
        self.figure = ExplorerFigure(scenario, dpi=dpi)
        self.frame: Frame | None = None
        self.image = W.Image(format="png", layout=W.Layout(width="100%", max_width="900px"))
        self.message = W.HTML()
        # the picture in words, updated with it: its text alternative, read out on each change
        self.words = W.HTML(layout=W.Layout(max_width="900px"))
        self.canvas: Any = None
        self._dragging: tuple[int, str] | None = None
        if drag is None:
            drag = in_kernel() and drag_available() and scenario.movable > 0
        if scenario.plant_controls:
            drag = False  # a new plant is a new figure: shown as a picture
        if drag:
            self.canvas = self._make_canvas()
        fig = self.figure.fig
        self._connections = [
            fig.canvas.mpl_connect("button_press_event", self.on_press),
            fig.canvas.mpl_connect("motion_notify_event", self.on_motion),
            fig.canvas.mpl_connect("button_release_event", self.on_release),
        ]
        self._build_controls()
        self.update()

    # controls -----------------------------------------------------------------------------
    def _build_controls(self) -> None:
        sc, base = self.scenario, self._base
        c = self.controls
        observer = [W.HTML(f"<b>{html.escape(sc.observer_name)} poles</b>")]
        self._pole_box = W.VBox()
        k = sc.movable
        if k >= 2:
            pairs = sum(1 for p in base.poles if complex(p).imag)
            c["pattern"] = W.Dropdown(
                options=[(self._pattern_label(k, j), j) for j in range(k // 2 + 1)],
                value=min(pairs, k // 2),
                description="movable poles",
                style=_STYLE,
                layout=W.Layout(width=_WIDTH),
            )
            c["pattern"].observe(self._pattern_changed, names="value")
            observer.append(c["pattern"])
        self._make_slots(list(base.poles))
        observer.append(self._pole_box)
        fixed = sc.fixed_poles
        if sc.family == "ginverse":
            text = "set by the observer's structure (no gain to tune)"
        elif k == 0:
            text = "none can be moved"
        else:
            text = ""
        if fixed.size:
            zeros = format_poles(fixed, 3)
            text += ("; " if text else "") + f"fixed: {zeros} (invariant zeros)"
        self._fixed_text = W.HTML(f"<small>{html.escape(text)}</small>")
        observer.append(self._fixed_text)
        if sc.decay_limits is not None:
            c["mode"] = W.ToggleButtons(
                options=[("place poles", "poles"), ("LMI bound", "lmi")],
                value=base.mode,
                description="design",
                style={"description_width": "120px", "button_width": "95px"},
            )
            lo, hi = sc.decay_limits
            label = "radius bound" if sc.discrete else "decay rate"
            c["decay"] = _slider(label, lo, hi, base.decay, 70)
            observer[1:1] = [c["mode"]]
            observer.append(c["decay"])
        dist = [W.HTML("<b>Disturbance</b>")]
        c["disturbance"] = W.Dropdown(
            options=list(DISTURBANCES),
            value=base.disturbance if base.disturbance in DISTURBANCES else DISTURBANCES[0],
            description="type",
            style=_STYLE,
            layout=W.Layout(width=_WIDTH),
        )
        unit = "steps" if sc.discrete else "s"
        freq = "rad/step" if sc.discrete else "rad/s"
        c["amplitude"] = _slider("amplitude", *sc.amplitude_limits, base.amplitude, 100)
        c["frequency"] = _slider(f"frequency ({freq})", *sc.disturbance_frequency_limits,
                                 base.frequency)  # fmt: skip
        c["period"] = _slider(f"switching ({unit})", *sc.period_limits, base.period)
        dist += [c["disturbance"], c["amplitude"], c["frequency"], c["period"]]
        c["start"] = W.Dropdown(
            options=[(k, k) for k in STARTS],
            value=base.start if base.start in STARTS else "zero estimate",
            description="observer start",
            style=_STYLE,
            layout=W.Layout(width=_WIDTH),
        )
        observer.append(c["start"])
        meas = [W.HTML("<b>Measurement</b>")]
        c["noise"] = _slider("noise (std)", *sc.noise_limits, base.noise, 100)
        meas.append(c["noise"])
        if sc.tau_limits is not None:
            c["tau"] = _slider(f"filter τ ({unit})", *sc.tau_limits, base.tau, 100)
            meas += [c["tau"], W.HTML("<small>τ = 0: plain numerical derivative</small>")]
        for name, control in c.items():
            if name in ("pattern",) or name.startswith("pole "):
                continue
            control.observe(self._changed, names="value")
        groups = [observer, dist, meas]
        if sc.plant_controls:
            plant_box = [W.HTML("<b>Plant</b>")]
            for pc in sc.plant_controls:
                c[pc.name] = _slider(pc.label, *pc.limits, pc.value, 180)
                c[pc.name].tooltip = pc.doc
                c[pc.name].observe(self._plant_changed, names="value")
                plant_box.append(c[pc.name])
            groups.insert(0, plant_box)
        self._show_relevant()
        boxes = [W.VBox(b, layout=W.Layout(margin="0 16px 4px 0")) for b in groups]
        controls = W.HBox(boxes, layout=W.Layout(flex_flow="row wrap"))
        view = self.canvas if self.canvas is not None else self.image
        self.widget = W.VBox([controls, view, self.words, self.message])

    @staticmethod
    def _pattern_label(k: int, pairs: int) -> str:
        real = k - 2 * pairs
        parts = []
        if real:
            parts.append(f"{real} real")
        if pairs:
            parts.append(f"{pairs} complex pair" + ("s" if pairs > 1 else ""))
        return " + ".join(parts)

    def _make_slots(self, entries: list[complex]) -> None:
        """Controls for the movable poles: one slider per real pole, two per complex pair."""
        sc = self.scenario
        for slot in self._slots:
            for name, control in slot.controls.items():
                control.unobserve(self._changed, names="value")
                self.controls.pop(name, None)
        self._slots = []
        if sc.movable == 0:
            self._pole_box.children = ()
            return
        lo, hi = sc.pole_limits
        widgets = []
        for i, p in enumerate(entries, start=1):
            p = complex(p)
            if not p.imag:
                ctl = {f"pole {i}": _slider(f"pole {i}", lo, hi, p.real)}
                kind = "real"
            elif sc.discrete:
                radius, angle = abs(p), math.degrees(abs(cmath.phase(p)))
                ctl = {
                    f"pole {i} radius": _slider(f"pole {i} radius", 0.0, hi, radius),
                    f"pole {i} angle": _slider(f"pole {i} angle (°)", 0.0, 180.0, angle, 180),
                }
                kind = "pair"
            else:
                f_hi = sc.frequency_limits[1]
                ctl = {
                    f"pole {i} real part": _slider(f"pole {i} real part", lo, hi, p.real),
                    f"pole {i} frequency": _slider(f"pole {i} ± imag", 0.0, f_hi, abs(p.imag)),
                }
                kind = "pair"
            for name, control in ctl.items():
                control.observe(self._changed, names="value")
                self.controls[name] = control
                widgets.append(control)
            self._slots.append(_Slot(i, kind, ctl))
        self._pole_box.children = tuple(widgets)

    def _pattern_changed(self, change: dict) -> None:
        sc = self.scenario
        pairs = int(change["new"])
        current = [p for p in self._read_poles() if not complex(p).imag]
        defaults = [complex(p).real for p in sc.defaults.poles if not complex(p).imag]
        reals = (current + defaults + [sc.pole_limits[0] / 4] * sc.movable)[
            : sc.movable - 2 * pairs
        ]
        if sc.discrete:
            pair = cmath.rect(0.5, math.radians(45))
        else:
            sigma = min(defaults) if defaults else sc.pole_limits[0] / 4
            pair = complex(sigma, abs(sigma))
        with self.hold():
            self._make_slots([*reals, *([pair] * pairs)])

    def _show_relevant(self) -> None:
        c = self.controls
        kind = c["disturbance"].value
        sine = kind in ("sinusoid", "damped sinusoid")
        c["frequency"].layout.display = None if sine else "none"
        c["period"].layout.display = "none" if sine else None
        if "mode" in c:
            lmi = c["mode"].value == "lmi"
            self._pole_box.layout.display = "none" if lmi else None
            if "pattern" in c:
                c["pattern"].layout.display = "none" if lmi else None
            c["decay"].layout.display = None if lmi else "none"

    def _read_poles(self) -> tuple[complex, ...]:
        poles: list[complex] = []
        for slot in self._slots:
            values = [control.value for control in slot.controls.values()]
            if slot.kind == "real":
                poles.append(float(values[0]))
                continue
            if self.scenario.discrete:
                p = cmath.rect(values[0], math.radians(values[1]))
            else:
                p = complex(values[0], values[1])
            if abs(p.imag) <= tols.CONJUGATE_RTOL * max(1.0, abs(p)):
                poles += [float(p.real), float(p.real)]  # a double real pole
            else:
                poles.append(p)
        return tuple(poles)

    @property
    def settings(self) -> Settings:
        """The settings the controls show now."""
        c = self.controls
        changes: dict[str, Any] = {
            "poles": self._read_poles() if self.scenario.movable else self._base.poles,
            "disturbance": c["disturbance"].value,
            "amplitude": float(c["amplitude"].value),
            "frequency": float(c["frequency"].value),
            "period": float(c["period"].value),
            "noise": float(c["noise"].value),
            "start": c["start"].value,
        }
        if "mode" in c:
            changes["mode"] = c["mode"].value
            changes["decay"] = float(c["decay"].value)
        if "tau" in c:
            changes["tau"] = float(c["tau"].value)
        return self._base.replace(**changes)

    # updating -----------------------------------------------------------------------------
    @contextmanager
    def hold(self) -> Iterator[None]:
        """Change several controls, then update once.

        Examples
        --------
        >>> from uio_teach.explorers import widgets
        >>> ex = widgets.pa9_explorer(static=False)
        >>> with ex.hold():
        ...     ex.controls["amplitude"].value = 2.0
        ...     ex.controls["disturbance"].value = "random steps"
        >>> ex.frame.settings.amplitude, ex.frame.settings.disturbance
        (2.0, 'random steps')
        """
        self._holding += 1
        try:
            yield
        finally:
            self._holding -= 1
            if not self._holding:
                self.update()

    def set(self, **values: Any) -> None:
        """Set controls by name (as a student would), then update once.

        Parameters
        ----------
        **values
            New values by control name; a name with spaces is passed with
            ``**{"pole 1": -2.0}``.

        Raises
        ------
        KeyError
            No control of that name.

        Examples
        --------
        >>> from uio_teach.explorers import widgets
        >>> ex = widgets.missile_explorer(static=False)
        >>> ex.set(tau=0.0, noise=0.1)
        >>> ex.frame.messages[-1]
        'the numerical derivative amplifies the noise: try a filter time constant tau > 0'
        """
        with self.hold():
            if "pattern" in values:
                self.controls["pattern"].value = values.pop("pattern")
            for name, value in values.items():
                if name not in self.controls:
                    raise KeyError(f"no control {name!r}; the controls are {sorted(self.controls)}")
                self.controls[name].value = value

    def _changed(self, change: dict) -> None:
        if not self._holding:
            self.update()

    def _plant_changed(self, change: dict) -> None:
        """A physical parameter moved: remake the scenario (plant, existence) and show it in the
        same figure (a new one only if its panels or legends differ)."""
        old = self.scenario
        values = {pc.name: float(self.controls[pc.name].value) for pc in old.plant_controls}
        if self._reverting:
            return
        try:
            new = old.rebuild(**values)
        except ValueError as exc:  # a plant the model refuses (a level below empty, ...)
            self._refused = (
                f"{change['owner'].description} = {change['new']:g} is refused: {exc}; the "
                "plant is kept as it was"
            )
            self._reverting = True
            try:
                change["owner"].value = change["old"]
            finally:
                self._reverting = False
            if not self._holding:
                self.update()
            return
        self._refused = ""
        self.scenario = new
        _LIVE[new.name] = self
        if not self.figure.replace_scenario(new):  # other panels or legends: a new figure
            self.figure.fig.clear()
            self.figure = ExplorerFigure(new, dpi=self.figure.fig.dpi)
        fixed = new.fixed_poles
        text = f"fixed: {format_poles(fixed, 3)} (invariant zeros)" if fixed.size else ""
        self._fixed_text.value = f"<small>{html.escape(text)}</small>"
        if new.movable != old.movable:
            with self.hold():
                self._make_slots(list(new.defaults.poles))
        elif not self._holding:
            self.update()

    def update(self) -> None:
        """Recompute the frame for the controls' values and redraw the figure in place.

        Examples
        --------
        >>> from uio_teach.explorers import widgets
        >>> ex = widgets.pa9_explorer(static=False, drag=False)
        >>> ex.update()
        >>> bytes(ex.image.value[:4])
        b'\\x89PNG'
        """
        self._show_relevant()
        try:
            frame = compute_frame(self.scenario, self.settings)
            self.figure.update(frame)
            if self.canvas is not None:
                self.figure.draw()
                self.canvas.blit()  # sends the changed pixels to the page
            else:
                self.image.value = self.figure.to_png(colors=128, compress_level=1)
        except Exception as exc:  # pragma: no cover - compute_frame already turns errors into text
            self.message.value = (
                f'<span style="color:#c0392b">could not update the picture: '
                f"{html.escape(str(exc))}</span>"
            )
            return
        self.frame = frame
        refused = (
            f'<div style="color:#c0392b">{html.escape(self._refused)}</div>'
            if self._refused
            else ""
        )
        self.message.value = _message_html(frame) + refused
        # the live region says what the error did and how fast, once per change; the picture's
        # full description (its panels, the pole map) follows, not spoken at every change
        poles = format_poles(self.settings.poles, 3)
        said = frame_status(frame, "observer poles", poles)
        whole = frame_alt(frame, "observer poles", poles)
        self.words.value = (
            '<p role="status" aria-live="polite" aria-atomic="true" '
            f'style="font-size:0.85em;margin:0.2em 0">{html.escape(said)}</p>'
            f'<p style="font-size:0.85em;margin:0.2em 0">{html.escape(whole)}</p>'
        )

    def close(self) -> None:
        """Close the figure's canvas and the widgets (frees their memory at once).

        Examples
        --------
        >>> from uio_teach.explorers import widgets
        >>> ex = widgets.pa9_explorer(static=False, drag=False)
        >>> ex.close()
        """
        if _LIVE.get(self.scenario.name) is self:
            del _LIVE[self.scenario.name]
        for cid in self._connections:
            self.figure.fig.canvas.mpl_disconnect(cid)
        for slot in self._slots:
            for control in slot.controls.values():
                control.unobserve_all()
        for control in self.controls.values():
            control.unobserve_all()
        if self.canvas is not None:
            _close_tree(self.canvas)
        _close_tree(self.widget)
        for control in list(self.controls.values()):
            _close_tree(control)
        _close_tree(self.image)
        _close_tree(self.message)
        self.figure._background = None  # the largest buffer: free it even if self is kept

    # display ------------------------------------------------------------------------------
    def static_html(self) -> str:
        """The static frames of this explorer (computed once, on first use).

        Returns
        -------
        str

        Examples
        --------
        >>> from uio_teach.explorers import widgets
        >>> ex = widgets.case_study_explorer(static=False)
        >>> ex.static_html().count('data-k="')     # 9 pole positions, 2 disturbance types
        18
        """
        if self._static_html is None:
            self._static_html = static_html(self.scenario, self._base)
        return self._static_html

    def _repr_mimebundle_(self, **kwargs: Any) -> dict[str, Any]:
        data = dict(self.widget._repr_mimebundle_(**kwargs) or {})
        data["text/plain"] = (
            f"{self.scenario.title} explorer ({self.scenario.observer_name} and Luenberger "
            "observer): run in Jupyter with a Python kernel to use the controls"
        )
        if self._static:
            data["text/html"] = self.static_html()
        return data

    def __repr__(self) -> str:
        return f"<Explorer {self.scenario.title!r}: {self.scenario.observer_name}>"


def _close_tree(widget: Any) -> None:
    """Close a widget, its children, its layout and its style (they are widgets too)."""
    for child in getattr(widget, "children", ()) or ():
        _close_tree(child)
    for name in ("layout", "style"):
        sub = getattr(widget, name, None)
        if isinstance(sub, W.Widget):
            sub.close()
    widget.close()


def _message_html(frame: Frame) -> str:
    name = html.escape(frame.scenario.observer_name)
    lines = [frame.scenario.note] if frame.scenario.note else []
    lines += [frame.explanation] if frame.explanation else []
    if frame.poles.size:
        lines.append(f"{name} poles: {format_poles(frame.poles, 3)}")
    if frame.luenberger_poles.size:
        lines.append(f"Luenberger poles: {format_poles(frame.luenberger_poles, 3)}")
    text = "<br>".join(html.escape(line) for line in lines)
    notes = "".join(f"<li>{html.escape(m)}</li>" for m in frame.all_messages)
    if notes:
        text += f'<ul style="color:#c0392b;margin:0.2em 0">{notes}</ul>'
    return f'<div style="font-size:0.9em">{text}</div>'


def pa9_explorer(*, static: bool = True, drag: bool | None = None) -> Explorer:
    """Explore the PA9 decoupling UIO against a Luenberger observer.

    Three movable poles (real, or one complex pair and a real pole), the
    disturbance type, amplitude, frequency or switching period, and the
    measurement noise. See :mod:`uio_teach.worked.pa9`.

    Parameters
    ----------
    static : bool
        Include the static book's frames in the display.
    drag : bool, optional
        Drag the movable poles on the pole map (ipympl); by default when
        ipympl is installed.

    Returns
    -------
    Explorer

    Examples
    --------
    >>> from uio_teach.explorers import widgets
    >>> ex = widgets.pa9_explorer(static=False)
    >>> ex.set(pattern=1)                    # one real pole and one complex pair
    >>> sorted(n for n in ex.controls if n.startswith("pole"))
    ['pole 1', 'pole 2 frequency', 'pole 2 real part']
    """
    return worked_explorer("pa9", static=static, drag=drag)


def case_study_explorer(*, static: bool = True, drag: bool | None = None) -> Explorer:
    """Explore the discrete case study: one movable pole, or the LMI's radius bound.

    The two fixed poles at 0.5 are the invariant zeros; in ``"LMI bound"``
    mode the gain comes from the LMI, infeasible below radius 0.5. See
    :mod:`uio_teach.worked.case_study`.

    Parameters
    ----------
    static : bool
        Include the static book's frames in the display.
    drag : bool, optional
        Drag the movable poles on the pole map (ipympl); by default when
        ipympl is installed.

    Returns
    -------
    Explorer

    Examples
    --------
    >>> from uio_teach.explorers import widgets
    >>> ex = widgets.case_study_explorer(static=False)
    >>> ex.set(mode="lmi", decay=0.8)
    >>> bool(abs(ex.frame.poles).max() <= 0.8 + 1e-6)
    True
    """
    return worked_explorer("case_study", static=static, drag=drag)


def missile_explorer(
    *, observer_family: str = "pmo", static: bool = True, drag: bool | None = None
) -> Explorer:
    """Explore the missile autopilot: the observer, its residual and the reconstructed inputs.

    Two movable poles of the projection-operator observer (the other two
    are fixed at the invariant zeros), the unknown inputs (by default the
    paper's damped sinusoids), noise and the reconstruction filter's time
    constant. See :mod:`uio_teach.worked.missile`.

    Parameters
    ----------
    observer_family : {"pmo", "ginverse"}
        The projection-operator observer, or the g-inverse observer (whose
        poles are fixed: the main control is then the amplitude).
    static : bool
        Include the static book's frames in the display.
    drag : bool, optional
        Drag the movable poles on the pole map (ipympl); by default when
        ipympl is installed.

    Returns
    -------
    Explorer

    Raises
    ------
    ValueError
        An unknown observer family.

    Examples
    --------
    >>> from uio_teach.explorers import widgets
    >>> ex = widgets.missile_explorer(static=False)
    >>> ex.frame.input_estimate.estimates.shape
    (2, 1001)
    """
    if observer_family not in ("pmo", "ginverse"):
        raise InputError(f"observer_family must be 'pmo' or 'ginverse', got {observer_family!r}")
    scenario = scenario_of("missile")
    if observer_family == "ginverse":
        scenario = dataclasses.replace(
            scenario,
            family="ginverse",
            static_control="amplitude",
            static_values=(0.0, 5.0, 10.0, 20.0, 40.0),
            cache={},
        )
    return Explorer(scenario, static=static, drag=drag)


def tank_explorer(*, static: bool = True) -> Explorer:
    """Explore the quadruple tank: the UIO's two poles, and the valves ``gamma1``, ``gamma2``.

    Moving a valve remakes the plant; below ``gamma1 + gamma2 = 1`` an
    invariant zero is in the right half-plane and the explorer says that no
    UIO exists, and why. See :func:`uio_teach.explorers.scenarios.experiment_scenario`.

    Parameters
    ----------
    static : bool
        Include the static book's frames in the display.

    Returns
    -------
    Explorer

    Examples
    --------
    >>> from uio_teach.explorers import widgets
    >>> ex = widgets.tank_explorer(static=False)
    >>> ex.set(gamma1=0.43, gamma2=0.34)
    >>> ex.frame.observer_message.startswith("no UIO exists")
    True
    """
    return worked_explorer("quadruple_tank", static=static)


def worked_explorer(name: str, *, static: bool = True, drag: bool | None = None) -> Explorer:
    """The explorer of a worked example of :data:`uio_teach.worked.WORKED`, by name.

    Parameters
    ----------
    name : str
        ``"pa9"``, ``"case_study"``, ``"missile"``, ``"quadruple_tank"``, ...
    static : bool
        Include the static book's frames in the display.
    drag : bool, optional
        Drag the movable poles on the pole map (ipympl).

    Returns
    -------
    Explorer

    Raises
    ------
    uio_teach.worked.RegistryError
        An unknown worked example (the message lists the known ones).

    Examples
    --------
    >>> from uio_teach.explorers import widgets
    >>> widgets.worked_explorer("pa9", static=False).scenario.title
    'PA9'
    """
    return Explorer(scenario_of(name), static=static, drag=drag)


def explorer(
    plant: Plant,
    observer_family: str = "uio",
    *,
    poles: Any = None,
    timepts: Any = None,
    initial_state: Any = None,
    u: Any = None,
    reconstruct: bool = False,
    static: bool = True,
    drag: bool | None = None,
) -> Explorer:
    """Explore your own plant: an unknown input observer against a Luenberger observer.

    Default poles, time window and control ranges come from
    :func:`uio_teach.explorers.make_scenario`. If no unknown input observer
    exists for the plant, the explorer says why (and still shows the
    Luenberger observer).

    Parameters
    ----------
    plant : Plant
        The plant.
    observer_family : {"uio", "pmo", "ginverse"}
        The observer design.
    poles : array_like, optional
        The movable poles to start from (one entry per complex pair).
    timepts : array_like, optional
        The simulation grid.
    initial_state : array_like, optional
        The plant's initial state.
    u : callable, optional
        The known input.
    reconstruct : bool
        Also reconstruct the unknown input (``E`` of full column rank).
    static : bool
        Include the static book's frames in the display.
    drag : bool, optional
        Drag the movable poles on the pole map (ipympl); by default when
        ipympl is installed.

    Returns
    -------
    Explorer

    Raises
    ------
    ValueError
        ``plant`` is not a :class:`~uio_teach.Plant` or an unknown family.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.explorers import widgets
    >>> ex = widgets.explorer(ut.examples.missile_autopilot(), "ginverse", static=False)
    >>> [n for n in ex.controls if n.startswith("pole")]
    []
    >>> ex.frame.luenberger_poles.size
    4
    """
    scenario = make_scenario(
        plant,
        observer_family,
        poles=poles,
        timepts=timepts,
        initial_state=initial_state,
        u=u,
        reconstruct=reconstruct,
        name=(plant.name or "plant").replace(" ", "-"),
    )
    return Explorer(scenario, static=static, drag=drag)
