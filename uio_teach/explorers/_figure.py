"""The explorer's figure: built once, then updated in place, redrawn by blitting.

:class:`ExplorerFigure` lays out the unknown input observer's and the
Luenberger observer's errors, residuals (and reconstructed inputs) beside a
pole map and the applied unknown signals; :meth:`ExplorerFigure.update` puts a
new :class:`~uio_teach.explorers.Frame` into the existing lines and
:meth:`ExplorerFigure.draw` repaints only what changed. How the fast redraw
works is private to this module.

Examples
--------
>>> from uio_teach.explorers import scenario_of, render
>>> fig = render(scenario_of("missile"))
>>> len(fig.axes) > 4
True
"""

from __future__ import annotations

import io
import itertools
import math
import textwrap
from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle
from matplotlib.text import Text
from matplotlib.ticker import LogLocator, MaxNLocator, NullFormatter
from matplotlib.transforms import Bbox, IdentityTransform, TransformedBbox
from PIL import Image

from .. import tolerances as tols
from ..plotting import COLORS, axis_label, channel_style, symbol, time_label
from .frames import Frame, compute_frame, finite_max
from .messages import ROUNDING
from .model import Scenario, Settings

__all__ = ["ExplorerFigure", "render"]

# Legends inside the panels are opaque and square: drawn over the curves, they hide exactly
# their box, which lets the fast redraw paint them back from the stored background.
_LEGEND = {
    "loc": "upper right",
    "fontsize": 7,
    "ncol": 2,
    "handlelength": 1.2,
    "framealpha": 1.0,
    "fancybox": False,
    "borderpad": 0.3,
    "labelspacing": 0.25,
    "handletextpad": 0.5,
    "columnspacing": 1.0,
    "borderaxespad": 0.3,
}

_FOOTER_PT = 7.5  # the footer's font size (points, before ``fontscale``)


def _nice_range(arrays: Sequence[np.ndarray | None]) -> tuple[float, float]:
    """Axis limits around the data, snapped outward to half-decades (stable under small changes)."""
    lo, hi = np.inf, -np.inf
    for a in arrays:
        if a is None or not np.size(a):
            continue
        a = np.asarray(a, dtype=float)
        a = a[np.isfinite(a)]
        if a.size:
            lo, hi = min(lo, float(a.min())), max(hi, float(a.max()))
    if not np.isfinite(lo) or hi - lo < tols.DISPLAY_ZERO_RTOL * max(1.0, abs(lo), abs(hi)):
        mid = 0.0 if not np.isfinite(lo) else lo
        lo, hi = mid - max(1.0, abs(mid)) * 0.5, mid + max(1.0, abs(mid)) * 0.5
        if not np.isfinite(lo):
            return -1.0, 1.0
    pad = 0.06 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    unit = 10.0 ** math.floor(math.log10(max(abs(lo), abs(hi)))) / 2
    return math.floor(lo / unit) * unit, math.ceil(hi / unit) * unit


def _log_range(
    arrays: Sequence[np.ndarray | None], current: tuple[float, float] | None, decades: int = 8
) -> tuple[float, float]:
    """Log-axis limits: the top snapped up to a decade, ``decades`` decades down; sticky."""
    top = 0.0
    for a in arrays:
        if a is None or not np.size(a):
            continue
        a = np.abs(np.asarray(a, dtype=float))
        a = a[np.isfinite(a)]
        if a.size:
            top = max(top, float(a.max()))
    if top <= 0:
        top = 1.0
    if current is not None and current[1] >= top and current[1] <= 1e3 * top:
        return current
    hi = 10.0 ** math.ceil(math.log10(top * 1.2))
    return hi * 10.0**-decades, hi


def _keep_range(
    current: tuple[float, float], wanted: tuple[float, float], fresh: bool
) -> tuple[float, float]:
    """Keep the current limits while the data fit and fill at least a third of them."""
    lo, hi = wanted
    if fresh:
        return wanted
    if lo < current[0] or hi > current[1]:
        # grow with room to spare (the span doubles), so that the next larger curves fit too:
        # a slider swept upward rescales a few times, not at every step
        a, b = min(lo, current[0]), max(hi, current[1])
        pad = 0.5 * (b - a)
        return _nice_range([np.array([a - pad * (lo < current[0]), b + pad * (hi > current[1])])])
    if (hi - lo) < (current[1] - current[0]) / 3:
        return wanted
    return current


def _inside(inner: Any, outer: Any, slack: float = 1.0) -> bool:
    return bool(
        inner.x0 >= outer.x0 - slack
        and inner.x1 <= outer.x1 + slack
        and inner.y0 >= outer.y0 - slack
        and inner.y1 <= outer.y1 + slack
    )


def _titles(ax: Any) -> list:
    """An axes' visible titles (they never change: a panel redraw paints them back)."""
    titles = (ax.title, ax._left_title, ax._right_title)
    return [t for t in titles if t.get_visible() and t.get_text()]


def _pixels(box: Any, H: int, pad: int = 0) -> tuple[int, int, int, int]:
    """A display box as an Agg region (origin top left), grown by ``pad`` pixels."""
    return (
        math.floor(box.x0) - pad,
        H - math.ceil(box.y1) - pad,
        math.ceil(box.x1) + pad,
        H - math.floor(box.y0) + pad,
    )


def _meets(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


class ExplorerFigure:
    """The explorer's figure: built once, then updated in place for each frame.

    Columns: the unknown input observer, the Luenberger observer (rows: the
    size of the error ``|e| = |x - xhat|`` on a log scale, with the rates of
    the slowest moved and fixed poles or the LMI's certified envelope; the
    residual ``r = y - C xhat`` and, when the scenario reconstructs it, the
    unknown input with its reconstruction, the true input in grey), and a side
    column with the pole map (``x`` observer poles, ``+`` Luenberger poles,
    ``o`` invariant zeros, which are the fixed poles; unit circle in discrete
    time) and the applied unknown signals. Each panel has its own vertical
    scale, so a good estimate is not flattened by a bad one. Messages are
    written under the panels, never over the curves; a legend sits in a band
    at the top of its panel that the curves do not enter.

    :meth:`update` only changes the data of existing lines and texts
    (``set_data``, ``set_text``) and rescales the axes; :meth:`draw` renders
    with Agg. The figure is a plain :class:`matplotlib.figure.Figure` (no
    pyplot), so it is never shown twice in a notebook.

    Parameters
    ----------
    scenario : Scenario
        What the figure shows.
    dpi : float
        Resolution.
    figsize : tuple of float, optional
        Size in inches; by default 9 inches wide (4.4 when ``narrow``) and as
        tall as the panels, the title and the footer's reserved lines need.
    sticky : bool
        Keep an axis range while the new data fit it and fill at least a
        third of it (fewer redraws, for live use); ``False`` gives every frame
        its own range (for pictures that must not depend on the previous one).
    fontscale : float
        Multiplies every font size (larger for pictures shown scaled down).
    narrow : bool
        The layout for a phone: the two observers side by side, one row per
        kind of curve, the pole map and the unknown signals in a last row.
    lmi : bool, optional
        Whether the certified LMI envelope can be drawn (and is listed in the
        legend); by default when the scenario has an LMI mode.
    footer_lines : int
        The lines kept free under the panels for the messages: the footer
        never overlaps the tick labels, and the figure's size does not depend
        on the messages. Longer messages end in an ellipsis (all of them are
        in the text beside the figure).

    Attributes
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    axes : dict
        The axes by name: ``"uio.error"``, ``"lb.error"``, ``"uio.residual"``,
        ``"lb.residual"`` (``"uio.input"``, ``"lb.input"``), ``"poles"``,
        ``"signals"``.
    lines : dict
        The lines of each curve by the name of the curve, one per channel.
    bands : dict
        By panel name, the fraction of the panel's height kept for its legend.

    Examples
    --------
    >>> from uio_teach.explorers import ExplorerFigure, compute_frame, scenario_of
    >>> s = scenario_of("pa9")
    >>> ef = ExplorerFigure(s)
    >>> ef.update(compute_frame(s))
    >>> line = ef.lines["uio.error"][0]
    >>> before = line.get_ydata().copy()
    >>> ef.update(compute_frame(s, s.defaults.replace(poles=(-4.0, -5.0, -6.0))))
    >>> line is ef.lines["uio.error"][0], bool((line.get_ydata() != before).any())
    (True, True)
    >>> ef.to_png()[:4]
    b'\\x89PNG'
    """

    def __init__(
        self,
        scenario: Scenario,
        *,
        dpi: float = 90,
        figsize: tuple[float, float] | None = None,
        sticky: bool = True,
        fontscale: float = 1.0,
        narrow: bool = False,
        lmi: bool | None = None,
        footer_lines: int = 3,
    ) -> None:
        self.scenario = scenario
        self.fontscale = k = float(fontscale)
        self.narrow = bool(narrow)
        self.lmi = scenario.decay_limits is not None if lmi is None else bool(lmi)
        self.footer_lines = int(footer_lines)
        # the legends: the smallest text (on a phone as large as the tick labels)
        self.legend_pt = 7.0 * k
        self.lines: dict[str, list] = {}
        self.notes: dict[str, Any] = {}  # texts drawn over the curves (none by default)
        self._layout(figsize, dpi)
        self._observer_panels()
        self._pole_map()
        self._signal_panel()
        for ax in self.axes.values():
            ax.tick_params(labelsize=7 * k)
        self.bands: dict[str, float] = {}
        self._reserve_bands()
        top = 1 - 4 / 72 / self.fig.get_figheight()
        self.title = self.fig.suptitle("", fontsize=10 * k, y=top, va="top")
        # the observers' messages go under the panels (the footer), in space kept for them
        self.footer = self.fig.text(
            0.01, 0.005, "", fontsize=_FOOTER_PT * k, ha="left", va="bottom", color="#9E3A00"
        )
        width_pt = self.fig.get_figwidth() * 72 * 0.97
        self._wrap = max(30, int(width_pt / (0.56 * _FOOTER_PT * k)))
        self._title_wrap = max(30, int(width_pt / (0.55 * 10 * k)))
        self.frame: Frame | None = None
        self.full_draws = 0
        self.partial_draws = 0
        self._background: Any = None
        self._keys: dict[str, tuple] = {}
        self._cells: dict | None = None
        self._fresh = True
        self.sticky = sticky
        self._legend_boxes: dict[str, tuple[int, int, int, int]] = {}
        self._title_boxes: dict[str, list[tuple[int, int, int, int]]] = {}

    @staticmethod
    def _shape(sc: Scenario) -> tuple:
        """What the figure's panels, lines, labels and legends are made from (not the data)."""
        plant = sc.plant
        return (
            plant.n, plant.p, plant.q, plant.nv, plant.dt, sc.discrete, sc.reconstruct,
            sc.input_symbol, sc.observer_name, sc.movable > 0, bool(sc.fixed_poles.size),
            bool(sc.invariant_zeros.size),
        )  # fmt: skip

    def replace_scenario(self, scenario: Scenario) -> bool:
        """Show another plant of the same shape in this figure (a physical parameter moved).

        The panels, lines, labels and legends are kept; the invariant zeros are moved on the
        pole map and every axis range is chosen afresh at the next :meth:`update`, and the
        next :meth:`draw` redraws the pole map. A scenario with other panels, channels or
        legend entries (another number of states, or zeros where there were none) cannot be
        shown this way.

        Parameters
        ----------
        scenario : Scenario
            The new scenario.

        Returns
        -------
        bool
            Whether the figure now shows ``scenario``; ``False`` leaves it unchanged (build a
            new figure instead).

        Examples
        --------
        >>> from uio_teach.explorers import ExplorerFigure, compute_frame, scenario_of
        >>> s = scenario_of("quadruple_tank")
        >>> ef = ExplorerFigure(s)
        >>> ef.update(compute_frame(s))
        >>> ef.draw()
        >>> s2 = s.rebuild(gamma1=0.8)
        >>> ef.replace_scenario(s2), ef.scenario is s2
        (True, True)
        >>> ef.update(compute_frame(s2))
        >>> ef.draw()
        >>> ef.full_draws
        1
        """
        if self._shape(scenario) != self._shape(self.scenario):
            return False
        self.scenario = scenario
        zeros = scenario.invariant_zeros
        self._zeros.set_data(zeros.real, zeros.imag)
        self._fresh = True  # every range from the new plant's signals
        self._keys.pop("poles", None)  # the zeros are drawn with the pole map's background
        return True

    def smallest_text_pt(self) -> float:
        """The size of the smallest text drawn in the figure, in points.

        Returns
        -------
        float

        Examples
        --------
        >>> from uio_teach.explorers import ExplorerFigure, scenario_of
        >>> ExplorerFigure(scenario_of("pa9")).smallest_text_pt()
        7.0
        """
        texts = [t for t in self.fig.findobj(Text) if t.get_visible() and t.get_text().strip()]
        return float(min(t.get_fontsize() for t in texts))

    @property
    def rows(self) -> list[str]:
        """The kinds of curve, one row of panels each (error, residual, and input)."""
        return ["error", "residual"] + (["input"] if self.scenario.reconstruct else [])

    def _layout(self, figsize: tuple[float, float] | None, dpi: float) -> None:
        """Step 1: the figure and its grid of panels, with room kept for the footer's lines."""
        k = self.fontscale
        rows = self.rows
        # under the bottom panels: tick labels, the axis label, then the footer's lines
        axis_in = (15 * k * 1.3 + 8) / 72
        footer_in = self.footer_lines * _FOOTER_PT * k * 1.22 / 72 + 0.07
        # above the panels: the title (its top 4 pt under the edge), then the pole map's legend
        # (two rows) or, on a phone, the panel titles; bands apart, so each redraws alone
        top_in = (4 + 10 * k * 1.35 + 4 + self.legend_pt * 3.4 + 6) / 72
        if self.narrow:
            top_in = (4 + 10 * k * 1.35 + 4 + 9 * k * 1.4 + 6) / 72
        if self.narrow:
            # a spacer row keeps room for the time axis above the pole map and its legend; the
            # observers' rows share their time axis and sit close together
            gap = (2 * 8 * k * 1.3 + self.legend_pt * 1.6 + 12) / 72
            mosaic = [[f"uio.{r}", f"lb.{r}"] for r in rows] + [[".", "."], ["poles", "signals"]]
            heights = [1.45] * len(rows) + [gap] + [1.45]
            panel_in = sum(heights) + 0.14 * 1.45 * (len(mosaic) - 1)
            width = 4.4 if figsize is None else figsize[0]
            ratios = {"width_ratios": [1.0, 1.0], "height_ratios": heights}
        else:
            side = ["poles"] * (len(rows) - 1) + ["signals"]
            mosaic = [[f"uio.{r}", f"lb.{r}", s] for r, s in zip(rows, side, strict=True)]
            panel_in = 4.4 if self.scenario.reconstruct else 3.0
            width = 9.0 if figsize is None else figsize[0]
            ratios = {"width_ratios": [1.0, 1.0, 0.85]}
        height = top_in + panel_in + axis_in + footer_in if figsize is None else figsize[1]
        fig = Figure(figsize=(width, height), dpi=dpi)
        FigureCanvasAgg(fig)
        self.axes = fig.subplot_mosaic(
            mosaic,
            gridspec_kw={
                **ratios,
                "left": (0.62 if self.narrow else 0.68) * k / width,
                "right": 1 - 0.3 / width,
                "top": 1 - top_in / height,
                "bottom": (axis_in + footer_in) / height,
                "wspace": 0.42 if not self.narrow else 0.45,
                "hspace": 0.5 if not self.narrow else 0.14,
            },
        )
        self.fig = fig

    def _observer_panels(self) -> None:
        """Step 2: the two observers' columns: |e| (log), the residual, the input."""
        sc, axes, k = self.scenario, self.axes, self.fontscale
        plant, rows = sc.plant, self.rows
        style = {"drawstyle": "steps-post"} if sc.discrete else {}
        sym = sc.input_symbol
        counts = {"error": plant.n, "residual": plant.p, "input": plant.q}
        labels = {
            "error": lambda i: symbol("e", i),
            "residual": lambda i: symbol("r", i),
            "input": lambda i: symbol(sym, i, hat=True),
        }
        for who in ("uio", "lb"):
            for r in rows:
                ax = axes[f"{who}.{r}"]
                if r == "input":
                    self.lines[f"{who}.actual"] = [
                        ax.plot(
                            [], [], color="0.25", lw=2.4, alpha=0.45,
                            label="true" if i == 0 else "_true", **style,
                        )[0]
                        for i in range(plant.q)
                    ]  # fmt: skip
                self.lines[f"{who}.{r}"] = [
                    ax.plot([], [], **channel_style(i), lw=1.1, label=labels[r](i), **style)[0]
                    for i in range(counts[r])
                ]
                ax.grid(True, alpha=0.3)
                if r == "error":
                    ax.set_yscale("log")
                    ax.yaxis.set_major_locator(LogLocator(base=100.0, numticks=6))
                    ax.yaxis.set_minor_locator(LogLocator(base=10.0, numticks=12))
                    ax.yaxis.set_minor_formatter(NullFormatter())
                else:
                    ax.yaxis.set_major_locator(MaxNLocator(4 if self.narrow else 5))
                    ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
                if r != rows[-1]:
                    ax.tick_params(labelbottom=False)
                if r == "error" and who == "uio":
                    self._guide_lines(ax)
                if who == "uio" or self.narrow:
                    text = axis_label(r, sym) if r != "error" else "|error| (log)"
                    ax.set_ylabel(text if who == "uio" else "", fontsize=8 * k)
                if counts[r] and (who == "uio" or r in ("input", "error")):
                    # the log error axis reaches a decade above the clipping bound, so its
                    # top band is free of curves: a wide, flat legend sits there, naming each
                    # error channel e_1, e_2, ... (in both observers' panels) and the guides
                    if r == "error":
                        shown = [g for g in self.lines["guides"] if g.get_label()[0] != "_"]
                        handles = [*self.lines[f"{who}.error"], *(shown if who == "uio" else [])]
                        if self.narrow:
                            # a phone's panel has no room above the curves for every channel:
                            # the guides alone, as the channels are named in the words
                            handles = shown if who == "uio" else []
                        if handles:
                            ax.legend(
                                handles=handles,
                                **{
                                    **_LEGEND,
                                    "fontsize": self.legend_pt,
                                    "ncol": 1 if self.narrow else 2,
                                },
                            )
                    else:
                        ax.legend(**{**_LEGEND, "fontsize": self.legend_pt})
            axes[f"{who}.{rows[-1]}"].set_xlabel(self._xlabel(), fontsize=8 * k)
        short = self.narrow
        axes["uio.error"].set_title(
            sc.observer_name if short else f"{sc.observer_name} (decouples {sym})",
            fontsize=9 * k,
            fontweight="bold",
        )
        axes["lb.error"].set_title(
            "Luenberger" if short else f"Luenberger observer (ignores {sym})",
            fontsize=9 * k,
            fontweight="bold",
        )

    def _guide_lines(self, ax: Any) -> None:
        """The guides over |e|; the legend lists only those this figure can draw."""
        sc = self.scenario
        moved = sc.movable > 0
        self.lines["guides"] = [
            ax.plot([], [], color=c, lw=1.3, ls=ls, label=lab if shown else f"_{lab}")[0]
            for c, ls, lab, shown in (
                ("k", "-.", "certified", self.lmi),
                (COLORS[3], (0, (6, 2)), "slowest moved", moved),
                (COLORS[2], (0, (1, 2)), "slowest fixed", bool(sc.fixed_poles.size)),
            )
        ]

    def _xlabel(self) -> str:
        plant = self.scenario.plant
        unit_step = plant.dt is True or (self.scenario.discrete and float(plant.dt) == 1.0)
        return "step k" if unit_step else time_label(plant.dt)

    def _pole_map(self) -> None:
        """Step 3: the pole map: x observer poles, + Luenberger poles, o invariant zeros."""
        sc, k = self.scenario, self.fontscale
        pz = self.axes["poles"]
        pz.set_xlabel("real part", fontsize=8 * k)
        pz.set_ylabel("imaginary part", fontsize=8 * k)
        pz.grid(True, alpha=0.3)
        if sc.discrete:
            theta = np.linspace(0, 2 * np.pi, 181)
            pz.plot(np.cos(theta), np.sin(theta), color="0.5", lw=0.8)
            pz.set_aspect("equal", adjustable="box")  # the unit circle drawn round
        else:
            pz.axvline(0.0, color="0.5", lw=0.8)
        pz.axhline(0.0, color="0.8", lw=0.6)
        zeros = sc.invariant_zeros
        (self._zeros,) = pz.plot(
            zeros.real, zeros.imag, "o", ms=9, mfc="none", mec=COLORS[2], mew=1.5,
            label="fixed" if zeros.size else "_fixed",
        )  # fmt: skip
        self.lines["poles"] = pz.plot(
            [], [], "x", ms=8, mew=1.8, color=COLORS[3], label=sc.observer_name
        )
        self.lines["luenberger poles"] = pz.plot(
            [], [], "+", ms=9, mew=1.2, color=COLORS[0], label="Luenberger"
        )
        pz.legend(
            loc="lower center",
            bbox_to_anchor=(0.5, 1.0),
            ncol=3 if self.narrow else 2,
            fontsize=self.legend_pt,
            frameon=False,
            handlelength=1.0,
            columnspacing=0.8,
            borderaxespad=0.2,
        )

    def _signal_panel(self) -> None:
        """Step 4: the applied unknown signals (d solid, v dashed)."""
        sc, k = self.scenario, self.fontscale
        plant = sc.plant
        style = {"drawstyle": "steps-post"} if sc.discrete else {}
        sig = self.axes["signals"]
        sig.set_ylabel("unknown inputs", fontsize=8 * k)
        if self.narrow:  # beside the pole map: the label on the free right edge, not over the map
            sig.yaxis.set_label_position("right")
        self.lines["d"] = [
            sig.plot([], [], **channel_style(i), lw=1.0, label=symbol(sc.input_symbol, i), **style)[
                0
            ]
            for i in range(plant.q)
        ]
        self.lines["v"] = [
            sig.plot([], [], **channel_style(i + plant.q), lw=1.0, label=symbol("v", i), **style)[0]
            for i in range(plant.nv)
        ]
        if plant.q + plant.nv:
            sig.legend(**{**_LEGEND, "fontsize": self.legend_pt})
        sig.set_xlabel(self._xlabel(), fontsize=8 * k)
        sig.grid(True, alpha=0.3)
        sig.yaxis.set_major_locator(MaxNLocator(4 if self.narrow else 5))
        sig.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))

    def _reserve_bands(self) -> None:
        """Step 5: a band at the top of each panel with a legend, kept free of curves.

        A legend is laid out in as few rows as the panel's width allows; the band is its
        height (and a little room) as a fraction of the panel's. The panel's curves are
        clipped under the band and its vertical range puts the data under it, so that no
        curve runs under a legend (the legends stay in place: a redraw paints them back).
        """
        renderer = self.fig.canvas.get_renderer()
        pad = 2.0 * self.fig.dpi / 72  # 2 pt between the legend and the curves
        for name, ax in self.axes.items():
            legend = ax.get_legend()
            if legend is None or name == "poles":  # the pole map's legend is above it
                continue
            handles, labels = legend.legend_handles, [t.get_text() for t in legend.get_texts()]
            box = ax.get_window_extent(renderer)
            for ncol in range(len(handles), 0, -1):
                legend = ax.legend(
                    handles=[h for h in self._legend_sources(ax, labels)],
                    labels=labels,
                    **{**_LEGEND, "fontsize": self.legend_pt, "ncol": ncol},
                )
                width = legend.get_window_extent(renderer).width
                if width <= box.width - 2 * pad:
                    break
            frame = legend.get_window_extent(renderer)
            band = min(0.6, (box.y1 - frame.y0 + pad) / box.height)
            self.bands[name] = band
            clip = TransformedBbox(Bbox([[0.0, 0.0], [1.0, 1.0 - band]]), ax.transAxes)
            for line in ax.get_lines():
                line.set_clip_box(clip)

    def _legend_sources(self, ax: Any, labels: list[str]) -> list:
        """The lines of a panel named in its legend, in the legend's order."""
        by_label = {line.get_label(): line for line in ax.get_lines()}
        return [by_label[label] for label in labels]

    def _under_band(
        self, name: str, current: tuple[float, float], log: bool = False
    ) -> tuple[float, float]:
        """The part of a panel's range under its legend's band (all of it without one)."""
        band = self.bands.get(name, 0.0)
        lo, hi = (math.log10(v) for v in current) if log else current
        hi = lo + (hi - lo) * (1.0 - band)
        return (10.0**lo, 10.0**hi) if log else (lo, hi)

    def _over_band(
        self, name: str, wanted: tuple[float, float], log: bool = False
    ) -> tuple[float, float]:
        """A panel's range that puts ``wanted`` under its legend's band."""
        band = self.bands.get(name, 0.0)
        lo, hi = (math.log10(v) for v in wanted) if log else wanted
        hi = lo + (hi - lo) / (1.0 - band)
        return (10.0**lo, 10.0**hi) if log else (lo, hi)

    def update(self, frame: Frame) -> None:
        """Show a frame: new data in the existing lines and texts, axes rescaled.

        Parameters
        ----------
        frame : Frame
            The result of :func:`compute_frame` for this figure's scenario.

        Examples
        --------
        >>> from uio_teach.explorers import ExplorerFigure, scenario_of, compute_frame
        >>> s = scenario_of("case_study")
        >>> ef = ExplorerFigure(s)
        >>> ef.update(compute_frame(s, s.defaults.replace(poles=(1.05,))))
        >>> "the error grows" in ef.footer.get_text()
        True
        """
        self.frame = frame
        t = frame.time
        empty = np.zeros(0)
        for name, lines in self.lines.items():
            if name in ("poles", "luenberger poles", "d", "v", "guides") or name.endswith(
                ".actual"
            ):
                continue
            arr = frame.curves.get(name)
            if arr is not None and name.endswith(".error"):
                arr = np.abs(arr)
            for i, line in enumerate(lines):
                if arr is None:
                    line.set_data(empty, empty)
                else:
                    line.set_data(t, arr[i])
        guides = {"certified": None, "moved": None, "fixed": None}
        for label, values in frame.guides.items():
            for key in guides:
                if key in label:
                    guides[key] = values
        for line, values in zip(self.lines["guides"], guides.values(), strict=True):
            line.set_data((t, values) if values is not None else (empty, empty))
        for who in ("uio", "lb"):
            if f"{who}.actual" in self.lines:
                show = frame.curves.get(f"{who}.input") is not None
                for i, line in enumerate(self.lines[f"{who}.actual"]):
                    line.set_data((t, frame.d[i]) if show else (empty, empty))
        for i, line in enumerate(self.lines["d"]):
            line.set_data(t, frame.d[i])
        for i, line in enumerate(self.lines["v"]):
            line.set_data(t, frame.v[i])
        self.lines["poles"][0].set_data(frame.poles.real, frame.poles.imag)
        lp = frame.luenberger_poles
        self.lines["luenberger poles"][0].set_data(lp.real, lp.imag)
        title = f"{self.scenario.title}: {frame.disturbance}" + (
            f", noise {frame.settings.noise:.3g}" if frame.settings.noise else ""
        )
        self.title.set_text(textwrap.shorten(title, self._title_wrap, placeholder=" …"))
        self.footer.set_text(self._footer_text(frame.all_messages))
        rows = {name.split(".")[1] for name in self.axes if name.startswith("uio.")}
        fresh = self._fresh or not self.sticky
        for row in rows:
            for who in ("uio", "lb"):
                ax = self.axes[f"{who}.{row}"]
                data = [frame.curves.get(f"{who}.{row}")]
                if row == "error":
                    # the curves are clipped at limits["error"], which the plant's own signals
                    # set, not the poles: a range from it stays put while the poles move
                    top = frame.limits.get("error")
                    ranged = [np.array([top])] if top else data
                    name = f"{who}.{row}"
                    current = None if fresh else self._under_band(name, ax.get_ylim(), log=True)
                    ax.set_ylim(*self._over_band(name, _log_range(ranged, current), log=True))
                    continue
                if row == "input":  # zoomed on the true input: a wild estimate runs off the panel
                    size = finite_max(frame.d) or 1.0
                    data = [np.array([-1.6 * size, 1.6 * size])]
                elif finite_max(*data) <= ROUNDING * frame.limits.get(row, 10.0) / 10:
                    # zero to rounding: a flat line on the scale of the plant's own signals,
                    # never rounding noise magnified into a trend
                    size = frame.limits.get(row, 10.0) / 10
                    data = [np.array([-size, size])]
                name = f"{who}.{row}"
                kept = _keep_range(self._under_band(name, ax.get_ylim()), _nice_range(data), fresh)
                ax.set_ylim(*self._over_band(name, kept))
        sig = self.axes["signals"]
        wanted = _nice_range([frame.d, frame.v])
        kept = _keep_range(self._under_band("signals", sig.get_ylim()), wanted, fresh)
        sig.set_ylim(*self._over_band("signals", kept))
        self._fresh = False
        if len(t) > 1:
            for name, ax in self.axes.items():
                if name != "poles":
                    ax.set_xlim(t[0], t[-1])
        self._scale_pole_map(frame)

    def _footer_text(self, messages: Sequence[str]) -> str:
        """The messages wrapped into the footer's reserved lines; an ellipsis if they overflow."""
        lines: list[str] = []
        for m in messages:
            lines += textwrap.wrap(m, self._wrap) or [""]
        if len(lines) > self.footer_lines:
            keep = lines[: self.footer_lines]
            keep[-1] = textwrap.shorten(keep[-1], self._wrap - 18, placeholder=" …")
            keep[-1] += " (all in the text)"
            lines = keep
        return "\n".join(lines)

    def _scale_pole_map(self, frame: Frame) -> None:
        """Limits covering the controls' range (a pole moves on a still map), wider if needed."""
        ax = self.axes["poles"]
        sc = self.scenario
        pts = np.concatenate([frame.poles, frame.luenberger_poles, sc.invariant_zeros])
        pts = pts[np.isfinite(pts)]
        if sc.discrete:
            r = max(1.25, sc.pole_limits[1] * 1.1, *(1.1 * np.abs(pts)).tolist())
            lim = _nice_range([np.array([-r, r])])
            ax.set_xlim(*lim)
            ax.set_ylim(*lim)
            return
        base_re = np.array([*sc.pole_limits, 0.0])
        zeros_im = float(np.abs(sc.invariant_zeros.imag).max()) if sc.invariant_zeros.size else 0
        base_im = max(
            0.5 * sc.frequency_limits[1],
            1.2 * zeros_im,
            0.3 * (sc.pole_limits[1] - sc.pole_limits[0]),
        )
        x0, x1 = _nice_range([base_re, pts.real])
        y = _nice_range([np.array([-base_im, base_im]), pts.imag, -pts.imag])[1]
        ax.set_xlim(x0, x1)
        ax.set_ylim(-y, y)

    def draw(self) -> None:
        """Render the figure with Agg, redrawing only what changed.

        A copy of the figure without its curves, markers and messages (axes,
        ticks, legends, titles) is kept. Each call paints the copy back,
        draws the curves, markers and messages on it, and paints the legends
        back over the curves (blitting). When an axis range changes, only that
        panel is redrawn into the copy (each panel owns a fixed cell of the
        figure), and a changed title or footer only its band. The first call,
        or a panel or text that would not fit its place, renders everything
        (``fig.canvas.draw()``). The figure stays an ordinary figure:
        ``fig.savefig`` draws everything.

        Examples
        --------
        >>> from uio_teach.explorers import ExplorerFigure, compute_frame, scenario_of
        >>> s = scenario_of("pa9")
        >>> ef = ExplorerFigure(s)
        >>> ef.update(compute_frame(s))
        >>> ef.draw()
        >>> ef.update(compute_frame(s, s.defaults.replace(poles=(-1.5, -2.0, -3.0))))
        >>> ef.draw()      # same axis ranges: only the changing artists are redrawn
        >>> ef.full_draws
        1
        """
        canvas = self.fig.canvas
        size = (canvas, self.fig.dpi, *self.fig.get_size_inches())
        if size != getattr(self, "_size", None):  # a new canvas, or resized (HiDPI screen)
            self._size = size
            self._background = None
            self._cells = None
        keys = {name: (*ax.get_xlim(), *ax.get_ylim()) for name, ax in self.axes.items()}
        keys["title"] = (self.title.get_text(),)
        keys["footer"] = (self.footer.get_text(),)
        changed = [name for name, key in keys.items() if self._keys.get(name) != key]
        if self._background is None or changed:
            dynamic = self._dynamic_artists()
            for artist in dynamic:
                artist.set_animated(True)
            try:
                if self._background is None or not self._cells or not self._redraw(changed):
                    canvas.draw()
                    self.full_draws += 1
                    if self._cells is None:
                        self._cells = self._find_cells()
                self._background = canvas.copy_from_bbox(self.fig.bbox)
                self._keys = keys
                self._legend_boxes = self._legend_regions()
            finally:
                for artist in dynamic:
                    artist.set_animated(False)
        else:
            canvas.restore_region(self._background)
        renderer = canvas.get_renderer()
        notes = list(self.notes.values())
        for artist in self._dynamic_artists():
            if artist.get_visible() and artist not in notes:
                artist.draw(renderer)
        for box in self._legend_boxes.values():  # the legends cover the curves, as in a full draw
            # xy: where the stored region's corner goes (the whole figure: no shift)
            canvas.restore_region(self._background, bbox=box, xy=(0, 0))
        for note in notes:
            if note.get_visible():
                note.draw(renderer)

    def _legend_regions(self) -> dict[str, tuple[int, int, int, int]]:
        """The boxes of the legends inside panels by panel, in Agg pixels (origin top left)."""
        renderer = self.fig.canvas.get_renderer()
        H = int(round(self.fig.bbox.height))
        out = {}
        for name, ax in self.axes.items():
            legend = ax.get_legend()
            if legend is None or not legend.get_visible():
                continue
            box = legend.get_frame().get_window_extent(renderer)
            if not ax.bbox.contains(box.x0 + 1, box.y0 + 1):
                continue  # outside the panel: no curve crosses it
            x0, x1 = math.floor(box.x0), math.ceil(box.x1)
            y0, y1 = H - math.ceil(box.y1), H - math.floor(box.y0)
            out[name] = (x0, y0, x1, y1)
        return out

    def _redraw(self, names: list[str]) -> bool:
        """Redraw some panels or texts into the stored background; False if one leaves its place.

        A panel's legend and titles do not change with its range and keep their place: they
        are painted back from the stored background instead of being laid out and drawn again
        (the legend is the slowest part of a panel; a title may reach over the next column),
        and the check that the panel keeps to its cell looks at the axes, ticks and labels
        only (nothing else in a panel moves with its range). A painted-back title that would
        cover a redrawn panel's new ticks means a full render instead.
        """
        canvas = self.fig.canvas
        renderer = canvas.get_renderer()
        canvas.restore_region(self._background)
        color = self.fig.get_facecolor()
        H = int(round(self.fig.bbox.height))
        drawn: dict[str, tuple[int, int, int, int]] = {}
        if any(name not in self._cells for name in names):
            return False  # a panel without a cell of its own
        for name in names:
            box = self._cells[name]
            blank = Rectangle(
                (box.x0, box.y0),
                box.width,
                box.height,
                transform=IdentityTransform(),
                facecolor=color,
                edgecolor="none",
                antialiased=False,
            )
            blank.draw(renderer)
            if name in self.axes:
                ax = self.axes[name]
                legend = self._legend_boxes.get(name)
                hidden = _titles(ax) + ([ax.get_legend()] if legend is not None else [])
                for a in hidden:
                    a.set_visible(False)
                try:
                    ax.draw(renderer)
                    tight = ax.get_tightbbox(renderer, bbox_extra_artists=[])
                finally:
                    for a in hidden:
                        a.set_visible(True)
                if legend is not None:
                    canvas.restore_region(self._background, bbox=legend, xy=(0, 0))
                if not ax.get_visible():
                    continue
                drawn[name] = _pixels(tight, H)
            else:
                tight = None
                text = {"title": self.title, "footer": self.footer}[name]
                text.draw(renderer)
                if not text.get_visible() or not text.get_text():
                    continue
                tight = text.get_window_extent(renderer)
                drawn[name] = _pixels(tight, H)
            if tight is None or not _inside(tight, box):
                return False  # a wider tick label or a longer text: render everything
        # the panels' titles, painted back wherever a blanked cell reached them
        cells = [_pixels(self._cells[name], H) for name in names]
        for owner, boxes in self._title_boxes.items():
            for tb in boxes:
                if not any(_meets(tb, c) for c in cells):
                    continue
                if any(_meets(tb, d) for other, d in drawn.items() if other != owner):
                    return False
                canvas.restore_region(self._background, bbox=tb, xy=(0, 0))
        self.partial_draws += 1
        return True

    def _find_cells(self) -> dict:
        """Each panel's cell and the title and footer bands (pixels), or {} if the title
        band overlaps the panels; a panel that does not keep to a cell of its own has none."""
        renderer = self.fig.canvas.get_renderer()
        W, H = self.fig.bbox.width, self.fig.bbox.height
        # the panels' titles are painted back after a redraw (see _redraw), not redrawn: a
        # title reaching over the next column does not make the cells overlap
        tight = {}
        self._title_boxes = {}
        for name, ax in self.axes.items():
            titles = _titles(ax)
            self._title_boxes[name] = [
                _pixels(t.get_window_extent(renderer), round(H), pad=1) for t in titles
            ]
            for t in titles:
                t.set_visible(False)
            try:
                tight[name] = ax.get_tightbbox(renderer)
            finally:
                for t in titles:
                    t.set_visible(True)
        top = max(t.y1 for t in tight.values())
        bottom = min(t.y0 for t in tight.values())
        title = self.title.get_window_extent(renderer)
        if title.y0 <= top + 2:
            return {}
        title_cut = (top + title.y0) / 2
        footer_cut = bottom - 1
        # the columns of the grid (a pole map drawn round is narrower than its grid cell, so
        # its left edge does not tell its column)
        grid_column = {name: ax.get_subplotspec().colspan.start for name, ax in self.axes.items()}
        columns = [
            [n for n, c in grid_column.items() if c == column]
            for column in sorted(set(grid_column.values()))
        ]
        cuts = [0.0]
        for left, right in itertools.pairwise(columns):
            a = max(tight[n].x1 for n in left)
            b = min(tight[n].x0 for n in right)
            cuts.append((a + b) / 2)
        cuts.append(W)
        cells = {
            "title": Bbox.from_extents(0, title_cut, W, H),
            "footer": Bbox.from_extents(0, 0, W, footer_cut),
        }
        for c, names in enumerate(columns):
            for name in names:
                p = tight[name]
                above = [tight[n].y0 for n in names if tight[n].y0 >= p.y1 - 1e-6 and n != name]
                below = [tight[n].y1 for n in names if tight[n].y1 <= p.y0 + 1e-6 and n != name]
                y1 = (p.y1 + min(above)) / 2 if above else title_cut
                y0 = (p.y0 + max(below)) / 2 if below else footer_cut
                cells[name] = Bbox.from_extents(cuts[c], y0, cuts[c + 1], y1)
        # a panel reaching over a neighbouring column (two panels of a phone's last row) has
        # no cell of its own: a change of its range renders everything
        for name in [n for n in self.axes if not _inside(tight[n], cells[n])]:
            del cells[name]
        return cells

    def _dynamic_artists(self) -> list:
        """What changes between frames and is drawn on the stored background: curves,
        markers and messages (legends, titles and the footer belong to the background)."""
        out: list = []
        for lines in self.lines.values():
            out += lines
        return [*out, *self.notes.values()]

    def to_png(
        self, *, colors: int | None = None, draw: bool = True, compress_level: int | None = None
    ) -> bytes:
        """The figure as PNG bytes, optionally with a reduced palette (much smaller files).

        Parameters
        ----------
        colors : int, optional
            Quantize to this many colours (e.g. 64) and optimize the PNG: for
            the static book's frames. ``None`` keeps full colour and encodes
            fast (for the live widget).
        draw : bool
            Render first; ``False`` reuses the last :meth:`draw`.
        compress_level : int, optional
            zlib level of the PNG (default 6 with ``colors``, 1 without).

        Returns
        -------
        bytes

        Examples
        --------
        >>> from uio_teach.explorers import ExplorerFigure, compute_frame, scenario_of
        >>> s = scenario_of("pa9")
        >>> ef = ExplorerFigure(s, dpi=60)
        >>> ef.update(compute_frame(s))
        >>> len(ef.to_png(colors=32)) < len(ef.to_png())
        True
        """
        if draw:
            self.draw()
        rgba = np.asarray(self.fig.canvas.buffer_rgba())
        img = Image.fromarray(rgba[..., :3])
        buf = io.BytesIO()
        if colors:
            img = img.quantize(colors=colors, method=Image.Quantize.FASTOCTREE, dither=0)
            img.save(buf, format="png", compress_level=compress_level or 6)
        else:
            img.save(buf, format="png", compress_level=compress_level or 1)
        return buf.getvalue()


def render(scenario: Scenario, settings: Settings | None = None, *, dpi: float = 90) -> Figure:
    """One explorer picture as a new figure, built from scratch (no widget needed).

    Parameters
    ----------
    scenario : Scenario
        What to explore.
    settings : Settings, optional
        The control values; the scenario's defaults by default.
    dpi : float
        Resolution.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from uio_teach.explorers import scenario_of, render
    >>> fig = render(scenario_of("missile"))
    >>> len(fig.axes)
    8
    """
    ef = ExplorerFigure(scenario, dpi=dpi)
    ef.update(compute_frame(scenario, settings))
    return ef.fig
