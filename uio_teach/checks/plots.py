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

from ._common import (
    CheckResult,
    _never_raises,
    _plural,
)
from .responses import _read_response

__all__ = ["pa9_plot", "error_residual_plot"]


_ERROR = re.compile(r"error|\be(_\{?\w+\}?|\d)?\b|x\s*-\s*\\?hat|x\s*-\s*x", re.IGNORECASE)
_RESIDUAL = re.compile(r"residual|\br(_\{?\w+\}?|\d)?\b|y\s*-\s*c", re.IGNORECASE)
_TIME = re.compile(r"time|\bt\b|step|\bk\b|sample", re.IGNORECASE)
_UNIT = re.compile(
    r"\((m?s|sec|seconds?|steps?)\)|\[(m?s|sec|seconds?|steps?)\]|\bin (m?s|seconds?|steps)\b"
    r"|\bseconds?\b|\bsteps?\b|\bstep k\b|\bs\)$",
    re.IGNORECASE,
)


def _figure(result: CheckResult, fig: Any):
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
            "fig is missing (None): make the figure, e.g. "
            "fig, (ax_e, ax_r) = plt.subplots(2, 1, sharex=True).",
        )
        return None
    result.add(
        False,
        "fig must be a matplotlib figure, e.g. from "
        f"fig, (ax_e, ax_r) = plt.subplots(2, 1, sharex=True); got {type(fig).__name__}.",
    )
    return None


def _axes_name(i: int, ax) -> str:
    title = ax.get_title()
    return f"axes {i + 1}" + (f" ('{title}')" if title else "")


def _texts(fig, ax=None) -> list[str]:
    """Titles, axis labels, legend entries and line labels of one axes (or of the figure)."""
    axes = [ax] if ax is not None else list(fig.axes)
    out: list[str] = []
    if ax is None and getattr(fig, "_suptitle", None) is not None:
        out.append(fig._suptitle.get_text())
    for a in axes:
        out += [a.get_title(), a.get_ylabel(), a.get_title("left"), a.get_title("right")]
        legend = a.get_legend()
        if legend is not None:
            out += [t.get_text() for t in legend.get_texts()]
        out += [ln.get_label() for ln in a.get_lines() if not ln.get_label().startswith("_")]
    if ax is None:
        for legend in getattr(fig, "legends", []):
            out += [t.get_text() for t in legend.get_texts()]
    return [t for t in out if t]


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


@_never_raises("Practical Assignment 9: the plot of the error and the residual", "pa9.plot")
def pa9_plot(fig: Any, response: Any = None) -> CheckResult:
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
    ['axes 1 (error), axes 2 (residual) have no x-label: label the time axis with its unit, e.g. ax.set_xlabel("time (s)").']
    >>> _ = ax_r.set_xlabel("time (s)")
    >>> checks.pa9_plot(fig).passed
    True
    """  # noqa: E501
    result = CheckResult("Practical Assignment 9: the plot of the error and the residual")
    error_residual_plot(result, fig, response)
    return result


def _panel_texts(ax) -> list[str]:
    out = [ax.get_ylabel(), ax.get_title(), ax.get_title("left"), ax.get_title("right")]
    legend = ax.get_legend()
    if legend is not None:
        out += [t.get_text() for t in legend.get_texts()]
    out += [ln.get_label() for ln in ax.get_lines() if not ln.get_label().startswith("_")]
    return [t for t in out if t]


def _kind(ax) -> str:
    texts = _panel_texts(ax)
    e = any(_ERROR.search(t) for t in texts)
    r = any(_RESIDUAL.search(t) for t in texts)
    return "both" if e and r else "e" if e else "r" if r else ""


def error_residual_plot(result: CheckResult, fig: Any, response: Any = None) -> None:
    """Add the ✓/✗ of a two-panel figure of ``e`` and ``r`` to ``result`` (see :func:`pa9_plot`)."""
    fig = _figure(result, fig)
    if fig is None:
        return
    axes = [ax for ax in fig.axes if ax.has_data()]
    if not axes:
        result.add(
            False,
            "the figure has no curves: did you plot into another figure? Plot with the axes "
            "of this figure, e.g. ax_e.plot(resp.time, resp.error.T).",
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
            "the figure has one axes with curves; e and r belong in two panels: "
            "fig, (ax_e, ax_r) = plt.subplots(2, 1, sharex=True), the error in ax_e, the "
            "residual in ax_r.",
        )
    else:
        result.add(True, f"the figure has {_plural(len(axes), 'axes')} with curves.")
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

    # x-labels: time, with a unit -----------------------------------------------------------------
    no_x = [name for name, ax in zip(names, axes, strict=True) if not _has_xlabel(ax, axes)]
    if no_x:
        result.add(
            False,
            f"{', '.join(no_x)} {'has' if len(no_x) == 1 else 'have'} no x-label: label the "
            'time axis with its unit, e.g. ax.set_xlabel("time (s)").',
        )
    else:
        labels = sorted({ax.get_xlabel() for ax in axes if ax.get_xlabel()})
        not_time = [x for x in labels if not _TIME.search(x)]
        no_unit = [x for x in labels if _TIME.search(x) and not _UNIT.search(x)]
        if not_time:
            result.add(
                False,
                f'the x-label {not_time[0]!r} does not say it is time: write e.g. "time (s)".',
            )
        elif no_unit:
            result.add(
                False,
                f'the x-label {no_unit[0]!r} has no unit: write e.g. "time (s)" (or "step k" '
                "for a discrete-time plant).",
            )
        else:
            result.add(True, "the x-axes are labelled with time and its unit.")

    if response is None:
        return
    resp = _read_response(result, response)
    if resp is None:
        return
    _check_curves(result, axes, kinds, resp)


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


def _check_curves(result: CheckResult, axes: Sequence, kinds: Sequence[str], resp) -> None:
    N = resp.time.size
    err = np.asarray(resp.error, float)
    res = np.asarray(resp.residual, float)
    x = np.asarray(resp.states, float)
    xhat = np.asarray(resp.estimates, float)
    yy = np.asarray(resp.outputs, float)
    tol = 1e-9 * max(1.0, float(np.max(np.abs(x))))
    n, p = err.shape[0], res.shape[0]
    t = np.asarray(resp.time, float)

    # against what? ------------------------------------------------------------------------------
    index = np.arange(N, dtype=float)
    xs = [cx for ax in axes for cx, _ in _curves(ax, N)]
    if xs and not np.allclose(index, t):
        if any(np.allclose(cx, index) for cx in xs):
            result.add(
                False,
                f"some curves are plotted against the sample index 0 ... {N - 1}, not against "
                "time: ax.plot(resp.time, ...).",
            )
            return
        if not all(np.allclose(cx, t, rtol=0, atol=1e-9 * max(1.0, abs(t[-1]))) for cx in xs):
            result.add(
                False, "some curves are not plotted against resp.time: ax.plot(resp.time, ...)."
            )
            return

    def content(ax) -> dict:
        found = {"e": set(), "-e": set(), "r": set(), "y": set(), "x": set(), "xhat": set()}
        found["norm"] = False
        found["other"] = 0
        for _, cy in _curves(ax, N):
            hit = False
            for key, M in (
                ("e", err),
                ("-e", -err),
                ("r", res),
                ("y", yy),
                ("x", x),
                ("xhat", xhat),
            ):
                rows = _match_rows(cy, M, tol)
                found[key].update(rows)
                hit = hit or bool(rows)
            if np.allclose(cy, np.linalg.norm(err, axis=0), rtol=0, atol=tol):
                found["norm"] = hit = True
            found["other"] += not hit
        return found

    e_axes = [ax for ax, k in zip(axes, kinds, strict=True) if k == "e"]
    r_axes = [ax for ax, k in zip(axes, kinds, strict=True) if k == "r"]
    if not e_axes or not r_axes:
        return  # already a ✗ for the labels; the curves cannot be told apart
    fe = content(e_axes[0])
    fr = content(r_axes[0])
    all_e = fe["norm"] or len(fe["e"]) == n
    all_r = len(fr["r"]) == p
    if not all_e and len(fr["e"]) == n and len(fe["r"]) == p and n != p:
        result.add(
            False,
            "the panels are swapped: the panel labelled as the error shows r, the one labelled "
            "as the residual shows e. Exchange the labels (or the curves).",
        )
        return
    zero_e = {i for i in range(n) if np.allclose(err[i], 0, rtol=0, atol=tol)}
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
    if all_r:
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
