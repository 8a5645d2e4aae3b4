"""Check of the PA9 lab's figure: labelled axes showing the error ``e`` and the residual ``r``.

Examples
--------
>>> from matplotlib.figure import Figure
>>> from uio_teach.checks import pa9_plot
>>> pa9_plot(Figure()).passed
False
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from .. import tolerances as tols
from .common import CheckResult, check_plant_of, never_raises, plural, read_response

__all__ = [
    "pa9_plot",
    "pa9_piecewise_plot",
    "error_residual_plot",
    "read_figure",
    "time_unit",
    "time_factor",
    "xlabels",
    "curves_against_time",
    "plotted_axes",
    "panel_texts",
    "figure_titles",
]


_ERROR = re.compile(r"error|\be(_\{?\w+\}?|\d)?\b|x\s*-\s*\\?hat|x\s*-\s*x", re.IGNORECASE)
_RESIDUAL = re.compile(r"residual|\br(_\{?\w+\}?|\d)?\b|y\s*-\s*c", re.IGNORECASE)
_TIME = re.compile(r"time|\bt\b|step|\bk\b|sample", re.IGNORECASE)


def read_figure(result: CheckResult, fig: Any) -> Any:
    """The matplotlib figure behind ``fig`` (a figure, an axes or an array of axes), or a ✗.

    Examples
    --------
    >>> from uio_teach.checks.common import CheckResult
    >>> from uio_teach.checks.plots import read_figure
    >>> result = CheckResult("demo")
    >>> read_figure(result, None) is None, result.failures[0][:22]
    (True, 'fig is missing (None):')
    """
    # matplotlib is imported here on purpose: `import uio_teach` must not load it
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

    if isinstance(fig, (Figure, SubFigure)):
        return fig
    if isinstance(fig, Axes):
        return fig.figure
    if isinstance(fig, (np.ndarray, list, tuple)):
        flat = [a for a in np.ravel(np.asarray(fig, dtype=object)) if isinstance(a, Axes)]
        if flat:
            return flat[0].figure
    if fig is None:
        result.add(
            False,
            "fig is missing (None): make the figure the exercise asks for and name it as the "
            "check cell does.",
        )
        return None
    result.add(
        False,
        f"fig must be a matplotlib figure (from plt.subplots), got {type(fig).__name__}.",
    )
    return None


_MS = re.compile(r"\b(ms|msec|milliseconds?)\b", re.IGNORECASE)
_US = re.compile(r"(µs|μs|\bus\b|microseconds?)", re.IGNORECASE)
_S = re.compile(r"(\(s\)|\[s\]|\bin s\b|\bs\)|\bsec\b|\bseconds?\b)", re.IGNORECASE)
_STEPS = re.compile(r"\b(steps?|samples?|k)\b", re.IGNORECASE)
_SCALE = {"s": 1.0, "ms": 1e3, "us": 1e6, "steps": 1.0}
_UNIT_NAME = {"s": "s", "ms": "ms", "us": "µs", "steps": "steps"}


def time_unit(label: str) -> str | None:
    """The time unit an x-label names: ``"s"``, ``"ms"``, ``"us"``, ``"steps"``, or None.

    Examples
    --------
    >>> from uio_teach.checks.plots import time_unit
    >>> time_unit("time (ms)"), time_unit("time [s]"), time_unit("step k"), time_unit("time")
    ('ms', 's', 'steps', None)
    """
    if _MS.search(label):
        return "ms"
    if _US.search(label):
        return "us"
    if _S.search(label):
        return "s"
    if _STEPS.search(label):
        return "steps"
    return None


def time_factor(x: np.ndarray, t: np.ndarray) -> float | None:
    """The factor ``k`` with ``x = k t`` (1, 1e3 or 1e6: time in s, ms or µs), or None.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.checks.plots import time_factor
    >>> t = np.linspace(0, 1, 5)
    >>> time_factor(1000 * t, t), time_factor(t + 1, t)
    (1000.0, None)
    """
    x = np.asarray(x, float)
    t = np.asarray(t, float)
    if x.shape != t.shape:
        return None
    for k in (1.0, 1e3, 1e6):
        if np.allclose(
            x,
            k * t,
            rtol=tols.CHECK_EXACT_RTOL,
            atol=tols.CHECK_EXACT_RTOL * k * max(1.0, float(np.max(np.abs(t)))),
        ):
            return k
    return None


def _axes_name(i: int, ax) -> str:
    title = ax.get_title()
    return f"axes {i + 1}" + (f" ('{title}')" if title else "")


def _has_xlabel(ax, axes: Sequence) -> bool:
    """An x-label of its own, or one below it in the same column over the same time range."""
    if ax.get_xlabel():
        return True
    shared = ax.get_shared_x_axes()
    box = ax.get_position()
    for other in axes:
        if other is ax or not other.get_xlabel():
            continue
        if shared.joined(ax, other):
            return True
        obox = other.get_position()
        same_column = abs(obox.x0 - box.x0) < 0.02 and abs(obox.x1 - box.x1) < 0.02
        if same_column and obox.y0 < box.y0 and np.allclose(other.get_xlim(), ax.get_xlim()):
            return True
    return False


def xlabels(result: CheckResult, axes: Sequence, names: Sequence[str]) -> set[str]:
    """✓/✗ on the x-labels: every panel has one (or shares one) that names time and its unit.

    Returns the units the labels name (``{"s"}``, ``{"ms"}``, ``{"steps"}``...).

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from uio_teach.checks.common import CheckResult
    >>> from uio_teach.checks.plots import xlabels
    >>> ax = Figure().subplots()
    >>> _ = ax.plot([0, 1], [1, 0]); _ = ax.set_xlabel("time (ms)")
    >>> xlabels(CheckResult("demo"), [ax], ["axes 1"])
    {'ms'}
    """
    no_x = [name for name, ax in zip(names, axes, strict=True) if not _has_xlabel(ax, axes)]
    if no_x:
        result.add(
            False,
            f"{', '.join(no_x)} {'has' if len(no_x) == 1 else 'have'} no x-label: label the "
            "time axis with its unit.",
        )
        return set()
    labels = sorted({ax.get_xlabel() for ax in axes if ax.get_xlabel()})
    not_time = [x for x in labels if not _TIME.search(x) and time_unit(x) is None]
    no_unit = [x for x in labels if time_unit(x) is None]
    if not_time:
        result.add(False, f"the x-label {not_time[0]!r} does not say it is time.")
        return set()
    if no_unit:
        result.add(
            False,
            f"the x-label {no_unit[0]!r} has no unit: time in seconds (or steps k for a "
            "discrete-time plant) needs its unit in the label.",
        )
        return set()
    units = {time_unit(x) for x in labels}
    result.add(True, "the x-axes are labelled with time and its unit.")
    return units  # type: ignore[return-value]


def curves_against_time(
    result: CheckResult, axes: Sequence, t: np.ndarray, units: set[str]
) -> bool:
    """✓/✗: every curve of ``t.size`` points is drawn against ``t`` in the unit its label names.

    Time in ms labelled "time (ms)" is right; time in s labelled "time (ms)", or the sample
    index labelled as time, is not.

    Examples
    --------
    >>> import numpy as np
    >>> from matplotlib.figure import Figure
    >>> from uio_teach.checks.common import CheckResult
    >>> from uio_teach.checks.plots import curves_against_time
    >>> t = np.linspace(0, 0.5, 11)
    >>> ax = Figure().subplots()
    >>> _ = ax.plot(1000 * t, np.sin(t))
    >>> curves_against_time(CheckResult("demo"), [ax], t, {"ms"})
    True
    >>> r = CheckResult("demo"); curves_against_time(r, [ax], t, {"s"})
    False
    """
    N = t.size
    xs = [cx for ax in axes for cx, _ in _curves(ax, N)]
    if not xs:
        return True
    index = np.arange(N, dtype=float)
    discrete_index = np.allclose(index, t)
    factors = {time_factor(cx, t) for cx in xs}
    if None in factors:
        if not discrete_index and any(np.allclose(cx, index) for cx in xs):
            result.add(
                False,
                f"some curves are plotted against the sample index 0 ... {N - 1}, not against "
                "the time of the run.",
            )
        else:
            result.add(False, "some curves are not plotted against the time points of the run.")
        return False
    if len(factors) > 1:
        result.add(False, "the panels draw time in different units: use one unit throughout.")
        return False
    (k,) = factors
    if units and discrete_index:
        wrong = sorted(u for u in units if u not in ("steps", "s"))
        if wrong:
            result.add(
                False,
                f"the x-label says time in {_UNIT_NAME[wrong[0]]}, but the curves are drawn "
                "against the steps k of the run: the label's unit must be the unit of the data.",
            )
            return False
    elif units:
        wrong = sorted(u for u in units if _SCALE[u] != k or u == "steps")
        drawn = {1.0: "s", 1e3: "ms", 1e6: "µs"}[k]
        if wrong:
            result.add(
                False,
                f"the x-label says time in {_UNIT_NAME[wrong[0]]}, but the curves are drawn "
                f"against time in {drawn}: the label's unit must be the unit of the data.",
            )
            return False
        result.add(True, f"the curves are drawn against the run's time, in {drawn} as labelled.")
    return True


def plotted_axes(result: CheckResult, fig: Any, t: np.ndarray) -> tuple[list, list[str]] | None:
    """The panels of ``fig`` that hold curves, and their names, once their time axes are right.

    A ✗, and None, when no panel holds a curve, or when the curves are not drawn
    against ``t`` in the unit the x-labels name (:func:`xlabels`,
    :func:`curves_against_time`).

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from uio_teach.checks.common import CheckResult
    >>> from uio_teach.checks.plots import plotted_axes
    >>> result = CheckResult("demo")
    >>> plotted_axes(result, Figure(), [0.0, 0.1]) is None, result.failures[0][:25]
    (True, 'the figure has no curves:')
    """
    axes = [ax for ax in fig.axes if ax.has_data()]
    if not axes:
        result.add(False, "the figure has no curves: did you draw into another figure?")
        return None
    names = [f"axes {i + 1}" for i in range(len(axes))]
    units = xlabels(result, axes, names)
    if not curves_against_time(result, axes, np.asarray(t, float), units):
        return None
    return axes, names


def panel_texts(ax: Any, title_locs: Sequence[str] = ("center",)) -> list[str]:
    """The texts that say what a panel shows: y-label, titles, legend entries, line labels.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    title_locs : sequence of str, optional
        Which of its titles count (``"center"``, ``"left"``, ``"right"``).

    Returns
    -------
    list of str
        The non-empty texts; labels matplotlib makes up (``"_child0"``) are left out.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from uio_teach.checks.plots import panel_texts
    >>> ax = Figure().subplots()
    >>> _ = ax.plot([0, 1], [1, 0], label="r1"); _ = ax.set_ylabel("residual")
    >>> panel_texts(ax)
    ['residual', 'r1']
    """
    out = [ax.get_ylabel()] + [ax.get_title(loc) for loc in title_locs]
    legend = ax.get_legend()
    if legend is not None:
        out += [t.get_text() for t in legend.get_texts()]
    out += [ln.get_label() for ln in ax.get_lines() if not ln.get_label().startswith("_")]
    return [t for t in out if t]


def figure_titles(fig: Any, axes: Sequence) -> list[str]:
    """The figure's title (``""`` when it has none), then the title of each of ``axes``.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from uio_teach.checks.plots import figure_titles
    >>> fig = Figure()
    >>> ax = fig.subplots()
    >>> _ = fig.suptitle("v and v̂"); _ = ax.set_title("v1")
    >>> figure_titles(fig, fig.axes)
    ['v and v̂', 'v1']
    """
    sup = getattr(fig, "_suptitle", None)
    return [sup.get_text() if sup is not None else ""] + [ax.get_title() for ax in axes]


_QUANTITIES = {
    "e": re.compile(r"\berror|\be\b", re.IGNORECASE),
    "r": re.compile(r"\bresidual|\br\b", re.IGNORECASE),
    "x": re.compile(r"\bstates?\b|\bestimates?\b|\boutputs?\b|\binputs?\b", re.IGNORECASE),
}


def titles(result: CheckResult, fig: Any, axes: Sequence, kinds: Sequence[str]) -> None:
    """✗ for a panel title that names another quantity than the panel shows (e.g. "states")."""
    for i, (ax, kind) in enumerate(zip(axes, kinds, strict=True)):
        title = " ".join(t for t in (ax.get_title(), ax.get_title("left")) if t)
        if not title or kind not in ("e", "r"):
            continue
        other = "r" if kind == "e" else "e"
        says_other = bool(_QUANTITIES[other].search(title)) and not _QUANTITIES[kind].search(title)
        says_x = bool(_QUANTITIES["x"].search(title)) and not _QUANTITIES[kind].search(title)
        if says_other or says_x:
            what = "error e" if kind == "e" else "residual r"
            result.add(
                False,
                f"the title {title!r} of axes {i + 1} does not fit the panel, which shows the "
                f"{what}: a title says what is drawn.",
            )


def experiment_title(result: CheckResult, fig: Any, resp: Any) -> None:
    """✗ for a figure or panel title that names another experiment than the plotted run."""
    text = " ".join(t for t in figure_titles(fig, fig.axes) if t).lower()
    if not text:
        return
    d = np.asarray(resp.inputs.d, float)
    jumps = (
        np.abs(np.diff(d, axis=1)) > tols.CHECK_EXACT_RTOL * max(1.0, float(np.max(np.abs(d))))
        if d.size
        else d
    )
    changing = float(np.mean(np.any(jumps, axis=0))) if d.size > d.shape[0] else 0.0
    kind = "" if not np.any(d) else "piecewise" if changing < 0.5 else "sinus"
    family = str(getattr(resp.observer, "family", "")).lower()
    wrong = None
    if kind == "sinus" and ("piecewise" in text or "step" in text.split()):
        wrong = "a piecewise-constant disturbance, but the run's d is a sinusoid"
    elif kind == "piecewise" and ("sinus" in text or "sine" in text.split()):
        wrong = "a sinusoidal disturbance, but the run's d is piecewise constant"
    elif "luenberger" in text and "luenberger" not in family:
        wrong = f"a Luenberger observer, but the run's observer is a {resp.observer.family}"
    if wrong is not None:
        result.add(False, f"the title names {wrong}: a title must say what is drawn.")


@never_raises("Practical Assignment 9: the plot of the error and the residual", "pa9.plot")
def pa9_plot(fig: Any, response: Any = None, *, plant: Any = None) -> CheckResult:
    """Check a figure of the error ``e`` and the residual ``r``: one panel each, labelled, right curves.

    The checks: the figure has (at least) two axes with curves; one panel is
    labelled as the error and another as the residual (by its y-label, title
    or legend); every panel has an x-label (a shared x-axis labelled once
    counts) that names time with a unit ("time (s)", or "step k" for a
    discrete plant). With ``response`` also, panel by panel: the error panel
    shows the rows of ``response.error`` (or their norm), the residual panel
    the rows of ``response.residual``, both against ``response.time``. A
    wrong curve is named: the states ``x``, the estimates ``x̂``, ``-e``, the
    outputs ``y``, swapped panels, the sample index instead of time.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (an ``Axes`` or an array of axes is accepted too).
    response : UIOResponse, optional
        The simulation that was plotted, to check the curves themselves.
    plant : Plant, optional
        The plant of the lab's set-up cell: the plotted run must be of this plant.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import numpy as np
    >>> from matplotlib.figure import Figure
    >>> from uio_teach import checks
    >>> fig = Figure()
    >>> ax_e, ax_r = fig.subplots(2, 1, sharex=True)
    >>> t = np.linspace(0, 5, 51)
    >>> _ = ax_e.plot(t, np.exp(-t)); _ = ax_e.set_ylabel("error e")
    >>> _ = ax_r.plot(t, np.exp(-2 * t)); _ = ax_r.set_ylabel("residual r")
    >>> checks.pa9_plot(fig).failures
    ['axes 1 (error), axes 2 (residual) have no x-label: label the time axis with its unit.']
    >>> _ = ax_r.set_xlabel("time (s)")
    >>> checks.pa9_plot(fig).passed
    True
    """  # noqa: E501
    result = CheckResult("Practical Assignment 9: the plot of the error and the residual")
    error_residual_plot(result, fig, response, plant)
    return result


@never_raises(
    "Practical Assignment 9: the plot of the piecewise-constant test", "pa9.piecewise_plot"
)
def pa9_piecewise_plot(fig: Any, response: Any = None, *, plant: Any = None) -> CheckResult:
    """Check the figure of the piecewise-constant test: panels of ``e`` and ``r`` (and ``d``).

    The same checks as :func:`pa9_plot`, on the run with the piecewise-constant
    disturbance; a panel of ``d`` may be added.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    response : UIOResponse, optional
        The run with the piecewise-constant disturbance.
    plant : Plant, optional
        The plant of the lab's set-up cell.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.worked.pa9 import PA9
    >>> run = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles), d=PA9.d_piecewise)
    >>> checks.pa9_piecewise_plot(None, run).passed
    False
    """
    result = CheckResult("Practical Assignment 9: the plot of the piecewise-constant test")
    error_residual_plot(result, fig, response, plant)
    return result


def _kind(ax) -> str:
    texts = panel_texts(ax, ("center", "left", "right"))
    e = any(_ERROR.search(t) for t in texts)
    r = any(_RESIDUAL.search(t) for t in texts)
    return "both" if e and r else "e" if e else "r" if r else ""


def error_residual_plot(
    result: CheckResult, fig: Any, response: Any = None, plant: Any = None
) -> None:
    """Add the ✓/✗ of a two-panel figure of ``e`` and ``r`` to ``result`` (see :func:`pa9_plot`)."""
    fig = read_figure(result, fig)
    if fig is None:
        return
    axes = [ax for ax in fig.axes if ax.has_data()]
    if not axes:
        result.add(
            False,
            "the figure has no curves: did you plot into another figure? Draw with the axes "
            "of this figure.",
        )
        return
    kinds = [_kind(ax) for ax in axes]
    names = [
        f"axes {i + 1}" + (" (error)" if k == "e" else " (residual)" if k == "r" else "")
        for i, k in enumerate(kinds)
    ]
    if len(axes) < 2:
        result.add(
            False,
            "the figure has one axes with curves; e and r belong in two panels (two axes, one "
            "above the other, sharing the time axis).",
        )
    else:
        result.add(True, f"the figure has {plural(len(axes), 'axes')} with curves.")
    e_axes = [ax for ax, k in zip(axes, kinds, strict=True) if k == "e"]
    r_axes = [ax for ax, k in zip(axes, kinds, strict=True) if k == "r"]
    if len(axes) >= 2:
        if e_axes:
            result.add(True, "one panel is labelled as the error e.")
        else:
            result.add(
                False,
                "no panel is labelled as the error alone: give the error panel a y-label such "
                'as "error e = x - x̂".',
            )
        if r_axes:
            result.add(True, "one panel is labelled as the residual r.")
        else:
            result.add(
                False,
                "no panel is labelled as the residual alone: give the residual panel a y-label "
                'such as "residual r = y - C x̂".',
            )

    units = xlabels(result, axes, names)
    titles(result, fig, axes, kinds)
    if response is None:
        return
    resp = read_response(result, response)
    if resp is None or not check_plant_of(result, resp, plant):
        return
    _check_curves(result, axes, kinds, resp, units)
    experiment_title(result, fig, resp)


def _match_rows(y: np.ndarray, M: np.ndarray, tol: float) -> list[int]:
    return [i for i in range(M.shape[0]) if np.allclose(y, M[i], rtol=0, atol=tol)]


def _curves(ax, N: int) -> list[tuple[np.ndarray, np.ndarray]]:
    out = []
    for line in ax.get_lines():
        y = np.asarray(line.get_ydata(), float)
        x = np.asarray(line.get_xdata(), float)
        if y.shape == (N,) and x.shape == (N,):
            out.append((x, y))
    return out


def _panel_content(ax: Any, resp: Any, tol: float) -> dict:
    """Which rows of e, -e, r, y, x, x̂ (and the norm of e) the curves of one panel are."""
    N = resp.time.size
    err = np.asarray(resp.error, float)
    found: dict = {"e": set(), "-e": set(), "r": set(), "y": set(), "x": set(), "xhat": set()}
    found["norm"] = False
    found["other"] = 0
    for _, cy in _curves(ax, N):
        hit = False
        for key, M in (
            ("e", err),
            ("-e", -err),
            ("r", resp.residual),
            ("y", resp.outputs),
            ("x", resp.states),
            ("xhat", resp.estimates),
        ):
            rows = _match_rows(cy, np.asarray(M, float), tol)
            found[key].update(rows)
            hit = hit or bool(rows)
        if np.allclose(cy, np.linalg.norm(err, axis=0), rtol=0, atol=tol):
            found["norm"] = hit = True
        found["other"] += not hit
    return found


def _check_curves(
    result: CheckResult, axes: Sequence, kinds: Sequence[str], resp: Any, units: set
) -> None:
    err = np.asarray(resp.error, float)
    tol = tols.CHECK_EXACT_RTOL * max(1.0, float(np.max(np.abs(resp.states))))
    n, p = err.shape[0], np.shape(resp.residual)[0]
    if not curves_against_time(result, axes, np.asarray(resp.time, float), units):
        return
    e_axes = [ax for ax, k in zip(axes, kinds, strict=True) if k == "e"]
    r_axes = [ax for ax, k in zip(axes, kinds, strict=True) if k == "r"]
    if not e_axes or not r_axes:
        return  # already a ✗ for the labels; the curves cannot be told apart
    fe = _panel_content(e_axes[0], resp, tol)
    fr = _panel_content(r_axes[0], resp, tol)
    all_e = fe["norm"] or len(fe["e"]) == n
    if not all_e and len(fr["e"]) == n and len(fe["r"]) == p and n != p:
        result.add(
            False,
            "the panels are swapped: the panel labelled as the error shows r, the one labelled "
            "as the residual shows e. Exchange the labels (or the curves).",
        )
        return
    zero_e = {i for i in range(n) if np.allclose(err[i], 0, rtol=0, atol=tol)}
    _error_panel(result, fe, all_e, zero_e, n)
    _residual_panel(result, fr, n, p)


def _error_panel(result: CheckResult, fe: dict, all_e: bool, zero_e: set, n: int) -> None:
    if all_e:
        result.add(True, "the error panel shows the error e = x - x̂ of the response.")
    elif len(fe["-e"] - zero_e) and not (fe["-e"] - zero_e) <= fe["e"]:
        result.add(
            False,
            "the error panel shows -e = x̂ - x: the error is e = x - x̂ (resp.error).",
        )
    elif fe["x"] - fe["e"]:
        result.add(
            False,
            "the error panel shows the states x (resp.states), not the error e = x - x̂: plot "
            "resp.error.",
        )
    elif fe["xhat"] - fe["e"]:
        result.add(
            False,
            "the error panel shows the estimates x̂ (resp.estimates), not the error "
            "e = x - x̂: plot resp.error.",
        )
    elif fe["e"]:
        missing = ", ".join(f"e{i + 1}" for i in range(n) if i not in fe["e"])
        result.add(False, f"the error panel lacks some error components: {missing}.")
    else:
        result.add(
            False, "no curve of the error panel is the error e of the response (resp.error)."
        )


def _residual_panel(result: CheckResult, fr: dict, n: int, p: int) -> None:
    if len(fr["r"]) == p:
        result.add(True, "the residual panel shows the residual r = y - C x̂ of the response.")
    elif fr["y"] - fr["r"]:
        result.add(
            False,
            "the residual panel shows the outputs y (resp.outputs), not the residual "
            "r = y - C x̂: plot resp.residual.",
        )
    elif fr["r"]:
        missing = ", ".join(f"r{i + 1}" for i in range(p) if i not in fr["r"])
        result.add(False, f"the residual panel lacks some residual components: {missing}.")
    elif len(fr["e"]) == n:
        result.add(
            False,
            "the residual panel shows the error e, not the residual r = y - C x̂ (one curve per "
            "output): plot resp.residual.",
        )
    else:
        result.add(
            False,
            "no curve of the residual panel is the residual r of the response (resp.residual).",
        )
