"""The course's drawing: standard figures and the panels, names and labels they are made of.

Drawing code only; the numbers come from :func:`uio_teach.simulate` and
:func:`uio_teach.reconstruct_input`.

* figures: :func:`plot_response` (states and estimates, error, residual) and
  :func:`plot_input_estimate`; each returns the ``matplotlib.figure.Figure`` and
  accepts an existing figure or axes;
* panels: :func:`plot_error`, :func:`plot_residual` and :func:`plot_channels` draw
  one line per channel into an axes; :func:`finish_panel` labels and grids it;
* the bank of UIOs: :func:`plot_bank_alarms` (each member's windowed residual over its
  threshold, one panel per run, one legend for all panels);
* checks: :func:`covered_curves` (the curves a legend covers, for tests of every figure);
* names: :func:`symbol` (``$e_{1}$``, ``$\\hat{x}_{2}$``), :func:`axis_label` (the error
  ``e = x - xhat``, the residual ``r = y - C xhat``, an input and its estimate) and
  :func:`time_label`; :func:`new_figure` makes a figure without pyplot.

Conventions that make the figures say only true things:

* units: PA9, the case study and the missile paper give no physical units, so the standard
  figures' state, input and disturbance axes say "(model units)" (a figure of a plant with
  units, such as the quadruple tank's pump panel, names them with :func:`with_unit`); the
  time axis says "time (s)" for continuous time and "step k" for a discrete-time plant
  counted in steps;
* colours and line styles: the course's cycle (:data:`COLORS`, the Okabe-Ito palette, safe for
  readers with any of the three dichromacies) and a line style per channel
  (:data:`LINESTYLES`), so that no two curves of a panel differ by hue alone; channel ``i``
  of the error is drawn in :func:`channel_style` ``(i)``; a residual channel that measures one
  state (a row of ``C`` with one nonzero entry, e.g. ``r2 = e3`` in PA9) takes that
  state's colour and style, the others those no state uses;
* words: every figure is described (:func:`uio_teach.figure_text.describe`) from the numbers
  it draws, what is plotted and what the reader should see;
* rounding: a panel whose curves are zero up to rounding (``1e-12`` next to signals of
  size 1) is not blown up to fill the axes: its range is at least a thousandth of the
  signals' size, so the curves lie on zero, and the panel says "zero to rounding".

The course figures (``uio-teach figures``), the explorers and the book use them,
so a symbol or a label is written in one place.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from . import tolerances as tols
from .errors import InputError
from .figure_text import describe, description

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .detection import Threshold
    from .isolation import UIOBank
    from .reconstruction import InputEstimate
    from .simulation import UIOResponse

__all__ = [
    "plot_response",
    "plot_input_estimate",
    "plot_bank_alarms",
    "plot_error",
    "plot_residual",
    "plot_channels",
    "line_look",
    "finish_panel",
    "new_figure",
    "symbol",
    "axis_label",
    "time_label",
    "with_unit",
    "residual_colors",
    "covered_curves",
    "legend_beside",
    "shade_band",
    "low_contrast_areas",
    "channel_style",
    "marker_style",
    "how_it_ends",
    "residual_channels",
    "describe",
    "description",
    "COLORS",
    "LINESTYLES",
    "UNIT",
]

COLORS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000")
"""The course's colour cycle, the Okabe-Ito palette (blue, vermillion, bluish green, reddish
purple, orange, sky blue, black) without its yellow, which is too light on white. The book's
``matplotlibrc`` sets the same cycle, with :data:`LINESTYLES`."""
LINESTYLES = ("-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)), (0, (8, 2)), (0, (1, 1)))
"""The line style of each colour of :data:`COLORS`, so that curves stay apart in grey print
and for a reader who sees two of the colours as one."""

UNIT = "model units"
"""The unit of states, inputs and disturbances in the standard figures (PA9, the case study and
the missile paper give no physical units)."""

FIGURE_WIDTH = 9.0
"""Width (inches) of a new figure; drawn at 100 dpi, the book shows it at 688 of its 911 px."""
FONT_SIZE = 11
"""Font size (points) of legends and notes, about 11.5 px at the book's column width (688 px)."""

_MIN_SPAN = 1e-3
"""The smallest half-range of a panel, relative to the size of the signals it derives from."""

_AXIS_LABELS = {
    "error": r"error $e = x - \hat{x}$",
    "residual": r"residual $r = y - C\hat{x}$",
}


def time_label(dt: float | bool | None) -> str:
    """The label of the time axis: ``"time (s)"``, or ``"step k"`` for a plant counted in steps.

    A discrete-time plant with ``dt=True`` or a sampling period of 1 (the
    case study's unit step) is counted in steps ``k``; one with another
    sampling period is plotted against time in seconds.

    Parameters
    ----------
    dt : None, True or float
        The plant's ``dt``.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.plotting import time_label
    >>> time_label(None), time_label(True), time_label(1.0), time_label(0.1)
    ('time (s)', 'step k', 'step k', 'time (s)')
    """
    if dt is True or (dt is not None and dt is not False and float(dt) == 1.0):
        return "step k"
    return "time (s)"


def with_unit(label: str, unit: str = UNIT) -> str:
    """A vertical-axis label with its unit: ``"$x_{1}$ (model units)"``.

    Parameters
    ----------
    label : str
        The label.
    unit : str, optional
        The unit (default ``UNIT``).

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.plotting import symbol, with_unit
    >>> with_unit(symbol("x", 0))
    '$x_{1}$ (model units)'
    """
    return f"{label} ({unit})"


def channel_style(i: int) -> dict[str, Any]:
    """The colour and line style of channel ``i`` (from 0): ``color`` and ``linestyle``.

    Parameters
    ----------
    i : int
        The channel; the cycle repeats after ``len(COLORS)`` channels.

    Returns
    -------
    dict
        Keyword arguments for ``Axes.plot``.

    Examples
    --------
    >>> from uio_teach.plotting import channel_style
    >>> channel_style(0), channel_style(1)["linestyle"]
    ({'color': '#0072B2', 'linestyle': '-'}, '--')
    """
    k = int(i) % len(COLORS)
    return {"color": COLORS[k], "linestyle": LINESTYLES[k]}


def residual_channels(C: np.ndarray) -> list[int]:
    """The style channel of each residual: that of the state its row of ``C`` measures.

    Row ``i`` of ``C`` with a single nonzero entry, in column ``j``, makes
    ``r_i`` a multiple of ``e_j`` (without noise), so it is drawn like ``e_j``
    (:func:`channel_style` ``(j)``); other rows get the channels after those of the states.

    Parameters
    ----------
    C : array_like
        The output matrix, ``p x n``.

    Returns
    -------
    list of int

    Examples
    --------
    >>> from uio_teach.plotting import residual_channels
    >>> residual_channels([[1, 0, 0], [0, 0, 1]])  # PA9: r1 = e1, r2 = e3
    [0, 2]
    >>> residual_channels([[0, 2, 1], [1, 0, 0]])  # the case study: r1 mixes e2 and e3
    [3, 0]
    """
    C = np.atleast_2d(np.asarray(C, dtype=float))
    channels, spare = [], C.shape[1]
    for row in C:
        nonzero = np.flatnonzero(row)
        if nonzero.size == 1:
            channels.append(int(nonzero[0]))
        else:
            channels.append(spare)
            spare += 1
    return channels


def residual_colors(C: np.ndarray) -> list[str]:
    """The colour of each residual channel: that of the state its row of ``C`` measures.

    Parameters
    ----------
    C : array_like
        The output matrix, ``p x n``.

    Returns
    -------
    list of str
        :func:`channel_style` colours of :func:`residual_channels`.

    Examples
    --------
    >>> from uio_teach.plotting import COLORS, residual_colors
    >>> residual_colors([[1, 0, 0], [0, 0, 1]]) == [COLORS[0], COLORS[2]]
    True
    """
    return [channel_style(j)["color"] for j in residual_channels(C)]


def zero_to_rounding(ax: Axes, values: np.ndarray, scale: float) -> bool:
    """Keep rounding noise on zero: a half-range of at least ``_MIN_SPAN * scale``.

    ``scale`` is the size of the signals ``values`` derive from (the states for
    an error, the outputs for a residual). Returns True, and writes "zero to
    rounding" in the panel, when every value is below ``ROUNDING_RTOL * scale``.
    """
    values = np.asarray(values, dtype=float)
    if not scale > 0 or values.size == 0 or not np.all(np.isfinite(values)):
        return False
    peak = float(np.max(np.abs(values)))
    half = _MIN_SPAN * scale
    if peak < half:
        low, high = ax.get_ylim()
        if high - low < 2 * half:
            ax.set_ylim(-half, half)
    if peak <= tols.ROUNDING_RTOL * scale:
        ax.text(
            0.02,
            0.9,
            f"zero to rounding (largest {peak:.0e})" if peak > 0 else "zero",
            transform=ax.transAxes,
            fontsize=FONT_SIZE,
            va="top",
        )
        return True
    return False


def symbol(letter: str, i: int, *, hat: bool = False) -> str:
    """The name of channel ``i`` (counted from 0) of a signal, as matplotlib mathtext.

    Parameters
    ----------
    letter : str
        The signal's letter: ``"x"``, ``"e"``, ``"r"``, ``"d"``, ``"v"``...
    i : int
        The channel, from 0; it is written from 1.
    hat : bool, optional
        The estimate's name, with a hat.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.plotting import symbol
    >>> print(symbol("e", 0), symbol("x", 1, hat=True), symbol("d", 11))
    $e_{1}$ $\\hat{x}_{2}$ $d_{12}$
    """
    name = f"\\hat{{{letter}}}" if hat else letter
    return f"${name}_{{{i + 1}}}$"


def axis_label(what: str, letter: str = "d") -> str:
    """The label of a panel's vertical axis: the error, the residual, or an input and its estimate.

    Parameters
    ----------
    what : {"error", "residual", "input"}
        The panel.
    letter : str, optional
        The input's letter (``"input"`` only).

    Returns
    -------
    str

    Raises
    ------
    ValueError
        An unknown panel.

    Examples
    --------
    >>> from uio_teach.plotting import axis_label
    >>> print(axis_label("error"), "|", axis_label("input", "v"))
    error $e = x - \\hat{x}$ | $v$ and $\\hat{v}$
    """
    if what == "input":
        return f"${letter}$ and $\\hat{{{letter}}}$"
    if what not in _AXIS_LABELS:
        raise InputError(f"what must be 'error', 'residual' or 'input', got {what!r}")
    return _AXIS_LABELS[what]


def new_figure(width: float = 8.0, height: float = 5.0) -> Figure:
    """A figure of the object API (no pyplot, no GUI), with constrained layout.

    Parameters
    ----------
    width, height : float, optional
        Size in inches.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from uio_teach.plotting import new_figure
    >>> new_figure(6, 4).get_size_inches().tolist()
    [6.0, 4.0]
    """
    from matplotlib.figure import Figure  # deferred on purpose: matplotlib only when drawing

    return Figure(figsize=(width, height), layout="constrained")


def finish_panel(ax: Axes, ylabel: str, legend: bool = True) -> None:
    """Label a panel's vertical axis, add a light grid and (optionally) the legend.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    ylabel : str
        The label of its vertical axis.
    legend : bool, optional
        Show the legend (beside the panel, :func:`legend_beside`).

    Examples
    --------
    >>> from uio_teach.plotting import finish_panel, new_figure
    >>> ax = new_figure().subplots()
    >>> _ = ax.plot([0, 1], [0, 1], label="$e_{1}$")
    >>> finish_panel(ax, "error")
    >>> ax.get_ylabel(), ax.get_legend() is not None
    ('error', True)
    """
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    if legend:
        legend_beside(ax)


BAND_EDGE = "#6E6E6E"
"""The hatching and edges of a shaded band (:func:`shade_band`), 5.1 to 1 on white, so that the
band stands out (WCAG 2.1, 1.4.11, asks 3:1 for the parts of a graphic one needs to read it)."""


def shade_band(ax: Axes, start: float, stop: float, label: str, **kwargs: Any) -> Any:
    """A vertical band from ``start`` to ``stop`` (a region of the x axis where something holds),
    seen by every reader: a pale fill under the curves, hatched and edged in a grey of 5.1:1 on
    white (a pale fill alone reads at 1.1:1).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    start, stop : float
        The band's ends on the x axis.
    label : str
        Its entry in the legend.
    **kwargs
        Passed on to ``ax.axvspan`` (over the band's own settings).

    Returns
    -------
    matplotlib.patches.Polygon or Rectangle
        The band.

    Examples
    --------
    >>> from uio_teach.plotting import low_contrast_areas, new_figure, shade_band
    >>> ax = new_figure().subplots()
    >>> band = shade_band(ax, 0.0, 0.5, "no UIO")
    >>> low_contrast_areas(ax.figure)
    []
    >>> _ = ax.axvspan(0.6, 0.8, color="#CC79A7", alpha=0.08, label="faint")
    >>> low_contrast_areas(ax.figure)
    [('faint', 1.08)]
    """
    settings = {
        "facecolor": "#F2F2F2",
        "edgecolor": BAND_EDGE,
        "hatch": "//",
        "linewidth": 1.0,
        "zorder": 0,
        "label": label,
    }
    return ax.axvspan(start, stop, **{**settings, **kwargs})


def _contrast(a: Any, b: Any) -> float:
    from matplotlib.colors import to_rgb  # deferred: matplotlib only when drawing

    def luminance(colour: Any) -> float:
        c = np.asarray(to_rgb(colour), dtype=float)
        c = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
        return float(0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2])

    hi, lo = sorted((luminance(a), luminance(b)), reverse=True)
    return (hi + 0.05) / (lo + 0.05)


def low_contrast_areas(fig: Figure, least: float = 3.0) -> list[tuple[str, float]]:
    """The labelled areas of a figure (bands, filled regions) that stand out from the panel's
    background by less than ``least`` (WCAG 2.1, 1.4.11: 3:1): by their fill (mixed with the
    background as drawn), or by a hatch or an edge in a colour of that contrast.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    least : float
        The contrast an area needs.

    Returns
    -------
    list of (str, float)
        Each area's label and the best contrast it has, rounded to two decimals.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from uio_teach.plotting import low_contrast_areas
    >>> fig, ax = plt.subplots()
    >>> _ = ax.axvspan(0, 1, color="#F5F5F5", label="faint band")
    >>> low_contrast_areas(fig)
    [('faint band', 1.09)]
    >>> plt.close(fig)
    """
    from matplotlib.colors import to_rgba  # deferred: matplotlib only when drawing

    found = []
    for ax in fig.axes:
        back = to_rgba(ax.get_facecolor())[:3]
        for patch in [*ax.patches, *ax.collections]:
            label = str(patch.get_label())
            if not label or label.startswith("_") or not hasattr(patch, "get_facecolor"):
                continue
            faces = np.atleast_2d(patch.get_facecolor())
            if not faces.size:
                continue
            r, g, b, a = faces[0]
            fill = tuple(a * np.array([r, g, b]) + (1 - a) * np.array(back))
            best = _contrast(fill, back)
            # an edge, or a hatch (drawn in the edge's colour), of a colour that stands out
            edges = np.atleast_2d(patch.get_edgecolor())
            widths = np.atleast_1d(patch.get_linewidth())
            hatched = bool(getattr(patch, "get_hatch", lambda: None)())
            if edges.size and edges[0][3] > 0.5 and (float(widths[0]) > 0 or hatched):
                best = max(best, _contrast(tuple(edges[0][:3]), back))
            if best < least:
                found.append((label, round(best, 2)))
    return found


def legend_beside(ax: Axes, **kwargs: Any) -> Any:
    """The panel's legend beside it, right of its upper corner: never over a curve.

    A constrained-layout figure (:func:`new_figure`) narrows the panels to make room.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    **kwargs
        Passed to ``ax.legend`` (handles, labels, ``ncol``, ...).

    Returns
    -------
    matplotlib.legend.Legend

    Examples
    --------
    >>> from uio_teach.plotting import covered_curves, legend_beside, new_figure
    >>> ax = new_figure().subplots()
    >>> _ = ax.plot([0, 1], [1, 1], label="flat at the top")
    >>> _ = legend_beside(ax)
    >>> covered_curves(ax.figure)
    []
    """
    options = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0}
    return ax.legend(**{**options, "fontsize": FONT_SIZE, **kwargs})


def plot_channels(
    ax: Axes,
    t: np.ndarray,
    values: np.ndarray,
    letter: str,
    *,
    discrete: bool = False,
    **kwargs: Any,
) -> None:
    """One line per row of ``values``, drawn in :func:`channel_style` and named :func:`symbol`.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    t : numpy.ndarray
        The time points.
    values : numpy.ndarray
        One row per channel.
    letter : str
        The signal's letter for the legend.
    discrete : bool, optional
        Draw steps (a discrete-time signal).
    **kwargs
        Further line properties; ``channels`` (a list of int, one per row) draws row ``i``
        in ``channel_style(channels[i])``, ``colors`` (a list, one per row) replaces the
        colours only.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.plotting import new_figure, plot_channels
    >>> ax = new_figure().subplots()
    >>> plot_channels(ax, np.arange(3.0), np.zeros((2, 3)), "r")
    >>> [line.get_label() for line in ax.lines]
    ['$r_{1}$', '$r_{2}$']
    """
    colors = kwargs.pop("colors", None)
    channels = kwargs.pop("channels", None)
    for i, row in enumerate(np.atleast_2d(values)):
        look = channel_style(channels[i] if channels is not None else i)
        if colors is not None:
            look["color"] = colors[i]
        _line(ax, t, row, discrete, label=symbol(letter, i), **{**look, **kwargs})


def plot_error(ax: Axes, response: UIOResponse, *, legend: bool = True) -> None:
    """The estimation error ``e = x - xhat`` of a simulation, one line per state, labelled.

    An error that is zero to rounding (relative to the states) is drawn on
    zero, and the panel says so.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    response : UIOResponse
        The result of :func:`uio_teach.simulate`.
    legend : bool, optional
        Show the legend.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.worked.pa9 import PA9
    >>> from uio_teach.plotting import new_figure, plot_error
    >>> resp = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles))
    >>> ax = new_figure().subplots()
    >>> plot_error(ax, resp)
    >>> print(ax.get_ylabel(), len(ax.lines))
    error $e = x - \\hat{x}$ 3
    """
    plot_channels(ax, response.time, response.error, "e", discrete=response.plant.is_discrete)
    finish_panel(ax, axis_label("error"), legend)
    zero_to_rounding(ax, response.error, _size(response.states))


def plot_residual(ax: Axes, response: UIOResponse, *, legend: bool = True) -> None:
    """The output residual ``r = y - C xhat`` of a simulation, one line per output, labelled.

    A channel that measures one state has that state's colour in
    :func:`plot_error` (``residual_colors``). A residual that is zero to
    rounding is drawn on zero, and the panel says so.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    response : UIOResponse
        The result of :func:`uio_teach.simulate`.
    legend : bool, optional
        Show the legend.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.worked.pa9 import PA9
    >>> from uio_teach.plotting import new_figure, plot_residual
    >>> resp = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles))
    >>> ax = new_figure().subplots()
    >>> plot_residual(ax, resp)
    >>> [line.get_label() for line in ax.lines]
    ['$r_{1}$', '$r_{2}$']
    """
    plot_channels(
        ax,
        response.time,
        response.residual,
        "r",
        discrete=response.plant.is_discrete,
        channels=residual_channels(response.plant.C),
    )
    finish_panel(ax, axis_label("residual"), legend)
    zero_to_rounding(ax, response.residual, _size(response.outputs))


def _size(values: np.ndarray) -> float:
    """The size of a signal: its largest finite magnitude (0 if none)."""
    values = np.asarray(values, dtype=float)
    finite = np.abs(values[np.isfinite(values)])
    return float(finite.max()) if finite.size else 0.0


def _figure_and_axes(
    fig: Figure | None,
    axes: Sequence[Axes] | None,
    names: list[str],
    layout: list[list[str]],
    height: float,
) -> tuple[Figure, list[Axes]]:
    """A figure and one axes per name: the given ``axes``, or new ones arranged as ``layout``."""
    if axes is not None:
        axes = list(np.ravel(np.asarray(axes, dtype=object)))
        if len(axes) != len(names):
            raise InputError(
                f"axes must hold {len(names)} axes ({', '.join(names)}), got {len(axes)}"
            )
        return axes[0].figure, axes
    if fig is None:
        import matplotlib.pyplot as plt  # deferred on purpose: pyplot only for a new figure

        fig = plt.figure(figsize=(FIGURE_WIDTH, height), layout="constrained")
    else:
        fig.clear()
    by_name = fig.subplot_mosaic(layout)
    return fig, [by_name[name] for name in names]


def _line(ax: Axes, t: np.ndarray, values: np.ndarray, discrete: bool, **kwargs: Any) -> None:
    if discrete:
        ax.step(t, values, where="post", **kwargs)
    else:
        ax.plot(t, values, **kwargs)


def _actual_and_estimate(
    ax: Axes,
    t: np.ndarray,
    actual: np.ndarray | None,
    estimate: np.ndarray,
    discrete: bool,
    letter: str,
    i: int,
) -> None:
    """One panel: a signal (solid, coloured) and its estimate (black, dashed), labelled."""
    name = symbol(letter, i)
    if actual is not None:
        _line(ax, t, actual, discrete, label=name, color=channel_style(i)["color"])
    hat = symbol(letter, i, hat=True)
    _line(ax, t, estimate, discrete, label=hat, color="k", linestyle="--", linewidth=1.0)
    finish_panel(ax, with_unit(name))


# --- the figures in words ----------------------------------------------------------------------

_SETTLED = 0.02
"""A signal has settled on zero once it stays below this fraction of its peak."""


def _plain(name: str) -> str:
    """A mathtext name in words for a text alternative: ``$\\hat{x}_{2}$`` -> ``x-hat 2``."""
    text = re.sub(r"\\hat\{(\w+)\}", r"\1-hat", name)
    text = re.sub(r"_\{(\w+)\}", r" \1", text)
    return text.replace("$", "").replace("\\", "").replace("{", "").replace("}", "")


def _when(t: float, dt: float | bool | None) -> str:
    return f"step {t:g}" if time_label(dt) == "step k" else f"t = {t:.3g} s"


def how_it_ends(
    t: Any, values: Any, scale: float | None = None, dt: float | bool | None = None
) -> str:
    """How signals end, in words: zero to rounding, settled on zero (and from when), or not.

    For the text alternative of a figure: what the reader should see of its curves.

    Parameters
    ----------
    t : array_like, shape (N,)
        The time points.
    values : array_like, shape (N,) or (k, N)
        The signals (an error, a residual, a gap between a signal and its estimate).
    scale : float, optional
        The size of the signals they derive from (the states for an error): below a
        billionth of it they are zero to rounding. By default their own peak.
    dt : None, True or float, optional
        The plant's ``dt``: ``"step k"`` or ``"t = ... s"`` in the words.

    Returns
    -------
    str
        A phrase to follow "the error", e.g. ``"decays to zero (below 2% of its peak from
        t = 2.87 s on)"``.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.plotting import how_it_ends
    >>> t = np.linspace(0, 10, 1001)
    >>> how_it_ends(t, np.exp(-t))
    'decays to zero (below 2% of its peak from t = 3.92 s on)'
    >>> how_it_ends(t, np.sin(t))
    'does not settle on zero: at the end it is still 54% of its peak'
    >>> how_it_ends(t, [np.exp(-t), 0.1 * np.exp(-t)])
    'decays to zero (every channel below 2% of the largest peak from t = 3.92 s on)'
    """
    t = np.asarray(t, dtype=float)
    values = np.atleast_2d(np.asarray(values, dtype=float))
    finite = np.where(np.isfinite(values), np.abs(values), np.inf)
    worst = finite.max(axis=0) if values.size else np.zeros(0)
    peak = float(worst[np.isfinite(worst)].max()) if np.isfinite(worst).any() else np.inf
    if not np.isfinite(peak):
        return "grows without bound (the simulation overflowed)"
    scale = peak if scale is None else scale
    if peak <= tols.ROUNDING_RTOL * max(scale, 1e-300):
        return "is zero to rounding throughout"
    above = np.flatnonzero(worst > _SETTLED * peak)
    last = int(above[-1]) if above.size else -1
    # one signal: "its peak"; several: all of them against the largest peak of any
    many = values.shape[0] > 1
    if last + 1 >= worst.size or worst.size - last < max(2, worst.size // 20):
        share = float(worst[-max(1, worst.size // 10) :].max()) / peak
        if many:
            return (
                "does not settle on zero: at the end its largest channel is still "
                f"{share:.0%} of the largest peak"
            )
        return f"does not settle on zero: at the end it is still {share:.0%} of its peak"
    when = _when(t[last + 1], dt)
    if many:
        return (
            f"decays to zero (every channel below {_SETTLED:.0%} of the largest peak from "
            f"{when} on)"
        )
    return f"decays to zero (below {_SETTLED:.0%} of its peak from {when} on)"


def marker_style(i: int, samples: int) -> dict[str, Any]:
    """Markers that tell channel ``i`` apart where colour and line style cannot.

    For a panel whose line style already means something else (solid: one run, dashed:
    another): channel ``i`` gets its own marker, about eight along the curve, offset from
    the other channels' so that they do not sit on each other.

    Parameters
    ----------
    i : int
        The channel, from 0.
    samples : int
        The number of points of the curve.

    Returns
    -------
    dict
        Keyword arguments for ``Axes.plot``: ``marker``, ``markevery``, ``markersize``.

    Examples
    --------
    >>> from uio_teach.plotting import marker_style
    >>> marker_style(1, 801)
    {'marker': 's', 'markevery': (12, 100), 'markersize': 5}
    """
    step = max(1, int(samples) // 8)
    offset = (int(i) * max(1, int(samples) // 64)) % step
    return {
        "marker": _MARKERS[int(i) % len(_MARKERS)],
        "markevery": (offset, step),
        "markersize": 5,
    }


_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def _describe_response(fig: Figure, response: UIOResponse, title: str) -> None:
    plant = response.plant
    t = np.asarray(response.time, dtype=float)
    n = plant.n
    states = ", ".join(f"x{i + 1}" for i in range(n))
    error = how_it_ends(t, response.error, _size(response.states), plant.dt)
    residual = how_it_ends(t, response.residual, _size(response.outputs), plant.dt)
    alt = (
        f"{title}: against time, each state ({states}) drawn solid with its estimate dashed "
        f"in black, then the estimation error e = x - x-hat and the output residual r = y - C "
        f"x-hat, one curve per channel. The error {error}; the residual {residual}."
    )
    ranges = ", ".join(
        f"x{i + 1} from {np.nanmin(response.states[i]):.3g} to {np.nanmax(response.states[i]):.3g}"
        for i in range(n)
    )
    details = [f"State panels, each with its estimate: {ranges} (model units)."]
    details.append(
        "Error panel: "
        + "; ".join(
            f"e{i + 1} ({_look(i)}) "
            + how_it_ends(t, response.error[i], _size(response.states), plant.dt)
            for i in range(n)
        )
        + "."
    )
    channels = residual_channels(plant.C)
    details.append(
        "Residual panel: "
        + "; ".join(
            f"r{i + 1} ({_look(j)}) "
            + how_it_ends(t, response.residual[i], _size(response.outputs), plant.dt)
            for i, j in enumerate(channels)
        )
        + "."
    )
    describe(fig, alt, " ".join(details))


_COLOUR_NAMES = ("blue", "vermillion", "bluish green", "reddish purple", "orange", "sky blue",
                 "black")  # fmt: skip
_STYLE_NAMES = ("solid", "dashed", "dash-dotted", "dotted", "dash-dot-dot", "long-dashed",
                "densely dotted")  # fmt: skip


_OTHER_COLOURS = {"#000000": "black", "#808080": "grey", "#999999": "grey"}
_DASHES = {"-": "solid", "--": "dashed", "-.": "dash-dotted", ":": "dotted", "None": "no line"}


def line_look(line: Any) -> str:
    """A drawn curve's colour, line style and marker in words, read from the curve itself.

    For the words of a figure: what a reader is told to look for is what was drawn, even
    when a chapter picks its colours by hand or a style sheet changes the cycle.

    Parameters
    ----------
    line : matplotlib.lines.Line2D
        The curve.

    Returns
    -------
    str
        E.g. ``"blue, solid"`` or ``"vermillion, dashed, squares"``; a colour outside the
        course's palette is named by its hex code.

    Examples
    --------
    >>> from uio_teach.plotting import line_look, new_figure
    >>> ax = new_figure().subplots()
    >>> line_look(ax.plot([0, 1], color="#D55E00", ls="--", marker="s")[0])
    'vermillion, dashed, squares'
    """
    from matplotlib.colors import to_hex  # deferred: matplotlib only when drawing

    colour = to_hex(line.get_color()).lower()
    names = {c.lower(): n for c, n in zip(COLORS, _COLOUR_NAMES, strict=True)}
    name = names.get(colour) or _OTHER_COLOURS.get(colour, colour)
    style = line.get_linestyle()
    words = [name, _DASHES.get(style, "patterned")]
    marker = line.get_marker()
    marks = {"o": "circles", "s": "squares", "^": "triangles", "D": "diamonds", "v": "triangles"}
    if marker not in (None, "None", "", " "):
        words.append(marks.get(marker, "markers"))
    return ", ".join(words)


def _look(i: int) -> str:
    """Channel ``i``'s colour and line style in words: ``"blue, solid"``."""
    k = int(i) % len(COLORS)
    return f"{_COLOUR_NAMES[k]}, {_STYLE_NAMES[k]}"


def _describe_input_estimate(fig: Figure, estimate: InputEstimate, title: str, letter: str) -> None:
    q = estimate.estimates.shape[0]
    t = np.asarray(estimate.time, dtype=float)
    dt = estimate.dt
    parts = []
    for i in range(q):
        name = f"{letter}{i + 1}"
        if estimate.actual is None:
            peak = _size(estimate.estimates[i])
            parts.append(f"the reconstruction of {name} reaches {peak:.3g} at most")
            continue
        gap = np.asarray(estimate.estimates[i], dtype=float) - estimate.actual[i]
        scale = _size(estimate.actual[i])
        parts.append(
            f"the gap between {name} and its reconstruction " + how_it_ends(t, gap, scale, dt)
        )
    inputs = ", ".join(f"{letter}{i + 1}" for i in range(q))
    said = "; ".join(parts)
    alt = (
        f"{title}: against time, each unknown input ({inputs}) drawn solid with its "
        f"reconstruction dashed in black. {said[:1].upper()}{said[1:]}."
    )
    describe(fig, alt, "")


def plot_response(
    response: UIOResponse,
    *,
    fig: Figure | None = None,
    axes: Sequence[Axes] | None = None,
    title: str | None = None,
) -> Figure:
    """The standard figure of a simulation: each state with its estimate, the error, the residual.

    Left column: one panel per state, ``x_i`` (solid) and ``xhat_i``
    (dashed). Right column: the estimation error ``e = x - xhat`` and the
    output residual ``r = y - C xhat``, all channels. Discrete responses are
    drawn as steps.

    Parameters
    ----------
    response : UIOResponse
        The result of :func:`uio_teach.simulate`.
    fig : matplotlib.figure.Figure, optional
        Figure to draw into (cleared first); a new one by default.
    axes : sequence of matplotlib.axes.Axes, optional
        ``n + 2`` axes to draw into instead: the ``n`` states, then the
        error, then the residual.
    title : str, optional
        Figure title; by default the observer family and the plant name.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach.plotting import plot_response
    >>> plant = ut.examples.pa9()
    >>> resp = ut.simulate(plant, ut.design_uio(plant, poles=[-1, -2, -3]),
    ...                    np.linspace(0, 5, 501), initial_state=[1, 0, 0])
    >>> fig = plot_response(resp)
    >>> len(fig.axes), sorted(ax.get_ylabel() for ax in fig.axes)[:2]
    (5, ['$x_{1}$ (model units)', '$x_{2}$ (model units)'])
    >>> sorted({ax.get_xlabel() for ax in fig.axes} - {''})
    ['time (s)']
    """
    plant = response.plant
    n = plant.n
    t = response.time
    discrete = plant.is_discrete
    # left: one panel per state; right: error (top half) and residual (bottom half)
    layout = [[f"x{i // 2}", "error" if i < n else "residual"] for i in range(2 * n)]
    names = [f"x{i}" for i in range(n)] + ["error", "residual"]
    fig, ax = _figure_and_axes(fig, axes, names, layout, max(4.0, 1.8 * n))
    state_axes, ax_err, ax_res = ax[:n], ax[n], ax[n + 1]
    xlabel = time_label(plant.dt)
    for i, a in enumerate(state_axes):
        _actual_and_estimate(a, t, response.states[i], response.estimates[i], discrete, "x", i)
    state_axes[-1].set_xlabel(xlabel)
    plot_error(ax_err, response)
    plot_residual(ax_res, response)
    for a in (ax_err, ax_res):
        a.set_xlabel(xlabel)
    if title is None:
        name = plant.name or "plant"
        title = f"{response.observer.family} on {name}"
    fig.suptitle(title)
    _describe_response(fig, response, _plain(title))
    return fig


def plot_input_estimate(
    estimate: InputEstimate,
    *,
    fig: Figure | None = None,
    axes: Sequence[Axes] | None = None,
    title: str | None = None,
    symbol: str = "d",
) -> Figure:
    """One panel per unknown input: the true ``d_i`` and its reconstruction.

    Parameters
    ----------
    estimate : InputEstimate
        The result of :func:`uio_teach.reconstruct_input`.
    fig : matplotlib.figure.Figure, optional
        Figure to draw into (cleared first); a new one by default.
    axes : sequence of matplotlib.axes.Axes, optional
        ``q`` axes to draw into instead.
    title : str, optional
        Figure title; by default the method (and ``tau``).
    symbol : str, optional
        Letter of the unknown input in the labels (``"v"`` for the missile
        paper's ``v1``, ``v2``).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach.plotting import plot_input_estimate
    >>> plant = ut.examples.pa9()
    >>> resp = ut.simulate(plant, ut.design_uio(plant, poles=[-1, -2, -3]),
    ...                    np.linspace(0, 5, 501), d=ut.signals.sinusoid())
    >>> fig = plot_input_estimate(ut.reconstruct_input(plant, resp))
    >>> fig.axes[0].get_ylabel()
    '$d_{1}$ (model units)'
    """
    q = estimate.estimates.shape[0]
    t = estimate.time
    discrete = estimate.dt is not None
    names = [f"{symbol}{i}" for i in range(q)]
    fig, ax = _figure_and_axes(fig, axes, names, [[name] for name in names], 1.2 + 2.2 * q)
    for i, a in enumerate(ax):
        actual = None if estimate.actual is None else estimate.actual[i]
        _actual_and_estimate(a, t, actual, estimate.estimates[i], discrete, symbol, i)
    ax[-1].set_xlabel(time_label(estimate.dt))
    if title is None:
        title = f"unknown input reconstruction ({estimate.method}"
        title += f", tau = {estimate.tau:g})" if estimate.tau is not None else ")"
    fig.suptitle(title)
    _describe_input_estimate(fig, estimate, _plain(title), symbol)
    return fig


# The bank's figure: the members' colours (black is the alarm level), the smallest font size.
_MEMBER_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")
BANK_FONT_SIZE = FONT_SIZE + 1
"""Font size (points) of every text of :func:`plot_bank_alarms`, about 9 px or more when the
figure is shown at the width of the book's column."""


def plot_bank_alarms(
    timepts: Any,
    runs: Any,
    banks: Sequence[UIOBank],
    thresholds: Sequence[Sequence[Threshold | None]],
    *,
    fault_time: float | None = None,
    columns: int = 2,
    fig: Figure | None = None,
) -> Figure:
    """Draw each bank member's evaluation function over its threshold, one panel per run.

    Every panel shows one run (a fault, or none) and all the members of all the banks:
    ``J / threshold`` on a logarithmic axis, so a curve above 1 (the black dashed line)
    is an alarm. The members keep one colour and marker in every panel; the members of the second
    bank are dashed. One legend, above the panels, names them all; the hatched grey band is the
    start before monitoring begins.

    Parameters
    ----------
    timepts : array_like, shape (N,)
        The time grid of the runs.
    runs : mapping of str to UIOResponse
        The runs to show, by name (e.g. ``"actuator 1"``, ``"no fault"``).
    banks : sequence of UIOBank
        The banks whose members are drawn.
    thresholds : sequence of sequences of Threshold or None
        One threshold per member, as :meth:`uio_teach.UIOBank.thresholds` returns them; a member
        without one (it does not exist) is not drawn.
    fault_time : float, optional
        When the faults start (a dotted vertical line).
    columns : int, optional
        Panels per row.
    fig : matplotlib.figure.Figure, optional
        Draw into this figure (it is cleared); by default a new pyplot figure, 9 inches
        wide, so that a notebook shows it.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach.plotting import plot_bank_alarms
    >>> plant = ut.Plant(ut.examples.pa9().A, np.eye(3), B=ut.examples.pa9().B,
    ...                  E=ut.examples.pa9().E)
    >>> bank = ut.design_uio_bank(plant, "sensor", poles=[-2, -3, -4])
    >>> t = np.linspace(0, 4, 401)
    >>> detector = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> healthy = [ut.simulate_fault(plant, detector, t, noise=0.01, seed=k)
    ...            for k in range(20)]
    >>> ths = bank.thresholds(healthy, false_alarm_rate=0.05, window=0.5)
    >>> fig = plot_bank_alarms(t, {"no fault": healthy[0]}, [bank], [ths])
    >>> len(fig.axes), len(fig.legends)
    (1, 1)
    """
    from .detection import residual_rms  # the evaluation function J of eq. (fd-rms)

    t = np.asarray(timepts, dtype=float)
    names = list(runs)
    if not names:
        raise InputError("runs is empty: give at least one run to draw")
    if len(banks) != len(thresholds):
        raise InputError(
            f"give one list of thresholds per bank: {len(banks)} banks, {len(thresholds)} lists"
        )
    columns = max(1, min(int(columns), len(names)))
    rows = -(-len(names) // columns)
    if fig is None:
        import matplotlib.pyplot as plt  # deferred: a pyplot figure shows in a notebook

        fig = plt.figure(figsize=(FIGURE_WIDTH, 1.0 + 2.4 * rows), layout="constrained")
    else:
        fig.clear()
    axes = np.atleast_1d(fig.subplots(rows, columns, sharex=True, sharey=True, squeeze=False))
    size = BANK_FONT_SIZE
    handles: dict[str, Any] = {}
    peaks: dict[str, dict[str, tuple[float, float | None]]] = {name: {} for name in names}
    for k, name in enumerate(names):
        ax = axes.flat[k]
        colour = 0
        for b, (bank, ths) in enumerate(zip(banks, thresholds, strict=True)):
            for member, residual, th in zip(
                bank.members, bank.residuals(runs[name]), ths, strict=True
            ):
                if residual is None or th is None:
                    colour += 1
                    continue
                J = residual_rms(t, residual, th.window)
                label = f"blind to {member.fault}"
                (line,) = ax.plot(
                    t,
                    J / th.value,
                    lw=1.4,
                    ls="-" if b == 0 else "--",
                    color=COLORS[colour % len(COLORS)],
                    marker=_MEMBER_MARKERS[colour % len(_MEMBER_MARKERS)],
                    markevery=(colour * max(1, t.size // 64), max(1, t.size // 8)),
                    markersize=5,
                    label=label,
                )
                ratio = (J / th.value)[t >= th.start]
                above = t[t >= th.start][ratio > 1.0]
                # the peak, and when the alarm ends (None: it lasts to the end of the run)
                ends = None if not above.size or above[-1] >= t[-1] else float(above[-1])
                peaks[name][label] = (float(np.nanmax(ratio)), ends)
                handles.setdefault(label, line)
                colour += 1
                start = th.start
        level = ax.axhline(1, color="k", lw=1, ls="--")
        if handles:
            shade_band(ax, t[0], start, "_not monitored")  # the words say so
        if fault_time is not None:
            ax.axvline(fault_time, color="0.4", ls=":", lw=1.2)
        ax.set_yscale("log")
        ax.set_title(name if name == "no fault" else f"fault: {name}", fontsize=size + 1)
        ax.grid(alpha=0.3, which="both")
        ax.tick_params(labelsize=size)
    for ax in axes.flat[len(names) :]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel("J / threshold", fontsize=size)
    for k in range(columns):
        column = [ax for ax in axes[:, k] if ax.get_visible()]
        column[-1].set_xlabel(time_label(None), fontsize=size)
        column[-1].xaxis.set_tick_params(labelbottom=True)
    labels = list(handles) + ["alarm level (J = threshold)"]
    lines = list(handles.values()) + [level]
    fig.legend(
        lines,
        labels,
        loc="outside upper center",
        ncols=3,
        fontsize=size,
        frameon=False,
    )
    _describe_bank(fig, peaks, fault_time, len(banks))
    return fig


def _describe_bank(
    fig: Figure,
    peaks: dict[str, dict[str, tuple[float, float | None]]],
    fault_time: float | None,
    banks: int = 1,
) -> None:
    """The bank's figure in words: which members raise an alarm in which run, and until when."""

    def members(names: list[str]) -> str:
        return (
            ("the member" if len(names) == 1 else "the members") + " blind to " + ", ".join(names)
        )

    runs = []
    isolates = True
    for name, found in peaks.items():
        loud = [m.removeprefix("blind to ") for m, (p, _) in found.items() if p > 1.0]
        quiet = [m.removeprefix("blind to ") for m, (p, _) in found.items() if p <= 1.0]
        brief = [
            f"{m.removeprefix('blind to ')} falls back below 1 at t = {end:.3g} s"
            for m, (p, end) in found.items()
            if p > 1.0 and end is not None
        ]
        what = "no fault" if name == "no fault" else f"fault: {name}"
        runs.append(
            f"Run {what}: "
            + (f"alarms from {members(loud)}" if loud else "no alarm")
            + (f" (the one blind to {'; the one blind to '.join(brief)})" if brief else "")
            + (f"; {members(quiet)} stay{'s' if len(quiet) == 1 else ''} below 1." if quiet and loud
               else ".")
        )  # fmt: skip
        isolates &= quiet == [name] if name != "no fault" else not loud
    start = f" The faults start at t = {fault_time:g} s (a dotted line)." if fault_time else ""
    summary = (
        " In every fault run all members raise an alarm except the one blind to that fault, "
        "which isolates it; with no fault none does."
        if isolates
        else " Which members raise an alarm in each run is described below."
    )
    alt = (
        "Alarms of the bank of UIOs, one panel per run: each member's evaluation function over "
        "its threshold (J / threshold, logarithmic axis) against time, "
        + ("the first bank's members solid, the others dashed, " if banks > 1 else "solid, ")
        + "each member in its own colour and marker; a curve above "
        "the dashed black line at 1 is an alarm; the hatched grey band at the start is not "
        "monitored." + start + summary
    )
    describe(fig, alt, " ".join(runs))


def covered_curves(fig: Figure) -> list[tuple[str, str]]:
    """The curves a legend covers: (legend's first label, curve's label) for each.

    Every visible legend of the figure (in an axes or on the figure) is measured on the drawn
    figure, in display coordinates; a curve is covered when one of its drawn points lies inside
    a legend's frame: its vertices and points along each segment a pixel apart (steps as
    drawn), within the part of the frame inside the curve's axes and its clip box.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (drawn first, on an Agg canvas if it has none that renders).

    Returns
    -------
    list of tuple of str
        Empty when no legend covers a curve.

    Examples
    --------
    >>> from uio_teach.plotting import covered_curves, new_figure
    >>> fig = new_figure()
    >>> ax = fig.subplots()
    >>> _ = ax.plot([0, 1], [0, 1], label="rising")
    >>> _ = ax.legend(loc="upper left")
    >>> covered_curves(fig)
    []
    >>> _ = ax.legend(loc="center")
    >>> covered_curves(fig)
    [('rising', 'rising')]
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # deferred: only this check draws
    from matplotlib.cbook import STEP_LOOKUP_MAP  # deferred: as above
    from matplotlib.transforms import Bbox  # deferred: as above

    if not hasattr(fig.canvas, "get_renderer"):  # a figure without pyplot: an Agg canvas
        FigureCanvasAgg(fig)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    legends = [lg for lg in [*legends, *fig.legends] if lg.get_visible()]
    found = []
    for legend in legends:
        box = legend.get_frame().get_window_extent(renderer)
        name = legend.get_texts()[0].get_text() if legend.get_texts() else ""
        for ax in fig.axes:
            if not ax.get_visible():
                continue
            for line in ax.get_lines():
                area = Bbox.intersection(box, ax.get_window_extent(renderer))
                clip = line.get_clip_box()
                if area is not None and clip is not None and line.get_clip_on():
                    area = Bbox.intersection(area, clip)
                if not line.get_visible() or area is None or area.width <= 0 or area.height <= 0:
                    continue
                x, y = (np.asarray(v, dtype=float).ravel() for v in line.get_data())
                if x.size == 0:
                    continue
                style = line.get_drawstyle()
                if style != "default" and style in STEP_LOOKUP_MAP:
                    x, y = STEP_LOOKUP_MAP[style](x, y)
                xy = line.get_transform().transform(np.column_stack([x, y]))
                ok = np.isfinite(xy).all(axis=1)
                points = [xy[ok]]
                both = ok[:-1] & ok[1:]
                a, b = xy[:-1][both], xy[1:][both]
                steps = np.clip(np.ceil(np.hypot(*(b - a).T)), 1, 2000).astype(int)
                for m in np.unique(steps):
                    s = np.linspace(0.0, 1.0, m + 1)[:, None, None]
                    sel = steps == m
                    points.append((a[sel] + s * (b[sel] - a[sel])).reshape(-1, 2))
                p = np.concatenate(points)
                across = (p[:, 0] > area.x0) & (p[:, 0] < area.x1)
                inside = across & (p[:, 1] > area.y0) & (p[:, 1] < area.y1)
                if inside.any():
                    found.append((name, line.get_label()))
    return found
