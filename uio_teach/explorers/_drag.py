"""Dragging the movable poles on the explorer's pole map (ipympl), besides the sliders.

:class:`DragPoles` gives :class:`~uio_teach.explorers.widgets.Explorer` its
matplotlib event handlers: a press near a movable pole grabs it, a motion moves
it (its sliders follow, so everything else stays as with the sliders), a
release lets go. The handlers take any object with the attributes of a
matplotlib mouse event, so they are tested without a browser. The canvas is
ipympl's widget; without ipympl the explorer shows a picture and the sliders
work alone.

Examples
--------
>>> from uio_teach.explorers._drag import drag_available
>>> isinstance(drag_available(), bool)
True
"""

from __future__ import annotations

import cmath
import math
import sys
from typing import Any

__all__ = ["DragPoles", "drag_available"]

_GRAB_PIXELS = 14  # a press this close to a movable pole on the pole map grabs it


def drag_available() -> bool:
    """True when poles can be dragged on the pole map: ipympl (the widget backend) is installed.

    Returns
    -------
    bool

    Examples
    --------
    >>> from uio_teach.explorers.widgets import drag_available
    >>> isinstance(drag_available(), bool)
    True
    """
    try:  # deferred on purpose: ipympl is optional, and probing it loads a widget backend
        import ipympl.backend_nbagg  # noqa: F401
    except Exception:  # not installed, or an incompatible version: sliders only
        return False
    return True


def in_kernel() -> bool:
    """True inside a Jupyter kernel (where a canvas widget can be shown).

    Returns
    -------
    bool

    Examples
    --------
    >>> from uio_teach.explorers._drag import in_kernel
    >>> in_kernel()
    False
    """
    ipython = sys.modules.get("IPython")  # loaded in every Jupyter kernel
    shell = ipython.get_ipython() if ipython is not None else None
    return shell is not None and hasattr(shell, "kernel")


def _clamp(control: Any, value: float) -> float:
    """A value inside the slider's range, on its step."""
    step = control.step or 0
    value = min(max(float(value), control.min), control.max)
    if step:
        value = control.min + round((value - control.min) / step) * step
        value = round(value, max(0, 1 - math.floor(math.log10(step))) + 6)
    return float(min(max(value, control.min), control.max))


class DragPoles:
    """The pole-dragging part of an explorer.

    It needs the explorer's ``figure``, ``controls``, ``scenario``,
    ``_slots`` and ``hold``.
    """

    figure: Any
    controls: dict
    scenario: Any
    _slots: list
    _dragging: tuple[int, str] | None = None

    # dragging poles on the pole map -------------------------------------------------------
    def _make_canvas(self) -> Any:
        """An ipympl canvas for the figure, or None when the widget backend does not load."""
        try:  # deferred on purpose: ipympl is optional (drag_available said it loads)
            from ipympl.backend_nbagg import Canvas, FigureManager  # optional

            canvas = Canvas(self.figure.fig)
            FigureManager(canvas, 0)
            canvas.header_visible = False
            canvas.footer_visible = False
            canvas.toolbar_visible = False
            canvas.resizable = False
            canvas.capture_scroll = False
            canvas.layout.width = "100%"
            canvas.layout.max_width = "900px"
        except Exception:  # a frontend without ipympl: sliders only
            return None
        self.figure._background = None  # the canvas is new: the next draw is a full one
        return canvas

    def _slot_points(self) -> list[tuple[int, complex]]:
        """The movable poles on the map (upper member of a pair), by slot."""
        out = []
        for index, slot in enumerate(self._slots):
            values = [control.value for control in slot.controls.values()]
            if slot.kind == "real":
                out.append((index, complex(values[0], 0.0)))
            elif self.scenario.discrete:
                out.append((index, cmath.rect(values[0], math.radians(values[1]))))
            else:
                out.append((index, complex(values[0], values[1])))
        return out

    def on_press(self, event: Any) -> None:
        """Grab the movable pole nearest to a press on the pole map (within a few pixels).

        Parameters
        ----------
        event : matplotlib.backend_bases.MouseEvent
            The press (``inaxes``, ``x``, ``y`` in pixels, ``button``).

        Examples
        --------
        >>> from types import SimpleNamespace
        >>> from uio_teach.explorers import widgets
        >>> ex = widgets.case_study_explorer(static=False, drag=False)
        >>> ax = ex.figure.axes["poles"]
        >>> x, y = ax.transData.transform((0.0, 0.0))        # where pole 1 is drawn
        >>> ex.on_press(SimpleNamespace(inaxes=ax, x=x, y=y, button=1, xdata=0.0, ydata=0.0))
        >>> ex.on_motion(SimpleNamespace(inaxes=ax, x=x, y=y, button=1, xdata=0.3, ydata=0.1))
        >>> ex.on_release(SimpleNamespace(inaxes=ax, button=1))
        >>> ex.settings.poles
        (0.3,)
        """
        ax = self.figure.axes["poles"]
        if getattr(event, "inaxes", None) is not ax or getattr(event, "button", 1) not in (1, None):
            return
        if "mode" in self.controls and self.controls["mode"].value == "lmi":
            return
        best, where = None, float(_GRAB_PIXELS)
        for index, p in self._slot_points():
            for q in (p, p.conjugate()):
                px, py = ax.transData.transform((q.real, q.imag))
                gap = math.hypot(px - event.x, py - event.y)
                if gap <= where:
                    best, where = index, gap
        self._dragging = None if best is None else (best, "grab")

    def on_motion(self, event: Any) -> None:
        """Move the grabbed pole to the pointer: its sliders follow, the figure updates.

        Parameters
        ----------
        event : matplotlib.backend_bases.MouseEvent
            The motion (``inaxes``, ``xdata``, ``ydata``).
        """
        if self._dragging is None:
            return
        ax = self.figure.axes["poles"]
        if getattr(event, "inaxes", None) is not ax or event.xdata is None:
            return
        slot = self._slots[self._dragging[0]]
        controls = list(slot.controls.values())
        z = complex(float(event.xdata), float(event.ydata))
        with self.hold():
            if slot.kind == "real":
                controls[0].value = _clamp(controls[0], z.real)
            elif self.scenario.discrete:
                controls[0].value = _clamp(controls[0], abs(z))
                controls[1].value = _clamp(controls[1], math.degrees(abs(cmath.phase(z))))
            else:
                controls[0].value = _clamp(controls[0], z.real)
                controls[1].value = _clamp(controls[1], abs(z.imag))

    def on_release(self, event: Any) -> None:
        """Let go of the grabbed pole.

        Parameters
        ----------
        event : matplotlib.backend_bases.MouseEvent
            The release.
        """
        self._dragging = None
