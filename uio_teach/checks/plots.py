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

__all__ = ["pa9_plot"]


_ERROR = re.compile(r"error|\be(_\{?\w+\}?)?\b|x\s*-\s*\\?hat|x\s*-\s*x", re.IGNORECASE)
_RESIDUAL = re.compile(r"residual|\br(_\{?\w+\}?)?\b|y\s*-\s*c", re.IGNORECASE)
_TIME = re.compile(r"time|\bt\b|\(s\)|\[s\]|\bs\b|step|\bk\b|sec", re.IGNORECASE)


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
    result.add(
        False,
        f"fig must be a matplotlib figure (fig, ax = plt.subplots(...); or fig = resp.plot()), "
        f"got {type(fig).__name__}.",
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


def _match_rows(y: np.ndarray, M: np.ndarray, tol: float) -> list[int]:
    return [i for i in range(M.shape[0]) if np.allclose(y, M[i], rtol=0, atol=tol)]


@_never_raises("Practical Assignment 9: the plot of the error and the residual")
def pa9_plot(fig: Any, response: Any = None) -> CheckResult:
    """Check a figure of the error ``e`` and the residual ``r``: labelled axes, right curves.

    The checks: the figure has axes with data; every axes has a y-label and an
    x-label (a shared x-axis labelled once counts) that names time; some
    title, label or legend entry names the error and the residual. With
    ``response`` also: the curves are the rows of ``response.error`` and
    ``response.residual`` (not the states ``x`` or the outputs ``y``).

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
    ['axes 1, axes 2 have no x-label: label the time axis, e.g. ax.set_xlabel("time (s)").']
    >>> _ = ax_r.set_xlabel("time (s)")
    >>> checks.pa9_plot(fig).passed
    True
    """
    result = CheckResult("Practical Assignment 9: the plot of the error and the residual")
    fig = _figure(result, fig)
    if fig is None:
        return result
    axes = [ax for ax in fig.axes if ax.has_data()]
    if not axes:
        result.add(
            False,
            "the figure has no curves: did you plot into another figure? Plot with the axes "
            "of this figure, e.g. ax.plot(resp.time, resp.error.T).",
        )
        return result
    result.add(True, f"the figure has {_plural(len(axes), 'axes')} with curves.")

    # labels -----------------------------------------------------------------------------------
    no_y = [_axes_name(i, ax) for i, ax in enumerate(axes) if not ax.get_ylabel()]
    if no_y:
        result.add(
            False,
            f"{', '.join(no_y)} {'has' if len(no_y) == 1 else 'have'} no y-label: say what is "
            'plotted, e.g. ax.set_ylabel("error e").',
        )
    else:
        result.add(True, "every axes has a y-label.")
    no_x = [_axes_name(i, ax) for i, ax in enumerate(axes) if not _has_xlabel(ax, axes)]
    if no_x:
        result.add(
            False,
            f"{', '.join(no_x)} {'has' if len(no_x) == 1 else 'have'} no x-label: label the "
            'time axis, e.g. ax.set_xlabel("time (s)").',
        )
    else:
        not_time = sorted(
            {
                ax.get_xlabel()
                for ax in axes
                if ax.get_xlabel() and not _TIME.search(ax.get_xlabel())
            }
        )
        if not_time:
            result.add(
                False,
                f'the x-label {not_time[0]!r} does not say it is time: write e.g. "time (s)".',
            )
        else:
            result.add(True, "the x-axes are labelled with time.")

    texts = _texts(fig)
    has_e = any(_ERROR.search(t) for t in texts)
    has_r = any(_RESIDUAL.search(t) for t in texts)
    result.add(
        has_e,
        "the error is named in a label, title or legend."
        if has_e
        else 'no label, title or legend names the error: e.g. ax.set_ylabel("error e = x - x̂").',
    )
    result.add(
        has_r,
        "the residual is named in a label, title or legend."
        if has_r
        else 'no label, title or legend names the residual: e.g. ax.set_ylabel("residual r").',
    )

    # the curves themselves ----------------------------------------------------------------------
    if response is not None:
        resp = _read_response(result, response)
        if resp is not None:
            _check_curves(result, axes, resp)
    return result


def _check_curves(result: CheckResult, axes: Sequence, resp) -> None:
    N = resp.time.size
    err = np.asarray(resp.error, float)
    res = np.asarray(resp.residual, float)
    tol = 1e-9 * max(1.0, float(np.max(np.abs(resp.states))))
    found = {"e": set(), "r": set(), "x": set(), "y": set(), "enorm": False}
    for ax in axes:
        for line in ax.get_lines():
            y = np.asarray(line.get_ydata(), float)
            if y.shape != (N,):
                continue
            found["e"].update(_match_rows(y, err, tol))
            found["r"].update(_match_rows(y, res, tol))
            found["x"].update(_match_rows(y, np.asarray(resp.states, float), tol))
            found["y"].update(_match_rows(y, np.asarray(resp.outputs, float), tol))
            if np.allclose(y, np.linalg.norm(err, axis=0), rtol=0, atol=tol):
                found["enorm"] = True
    n, p = err.shape[0], res.shape[0]
    if found["enorm"] or len(found["e"]) == n:
        result.add(True, "the error curves are the error e = x - x̂ of the response.")
    elif found["e"]:
        missing = ", ".join(f"e{i + 1}" for i in range(n) if i not in found["e"])
        result.add(False, f"some error components are missing from the figure: {missing}.")
    elif found["x"]:
        result.add(
            False,
            "no curve is the error e = x - x̂, but some are the states x: plot resp.error, "
            "not resp.states.",
        )
    else:
        result.add(False, "no curve of the figure is the error of the response (resp.error).")
    if len(found["r"]) == p:
        result.add(True, "the residual curves are the residual r = y - C x̂ of the response.")
    elif found["r"]:
        missing = ", ".join(f"r{i + 1}" for i in range(p) if i not in found["r"])
        result.add(False, f"some residual components are missing from the figure: {missing}.")
    elif found["y"]:
        result.add(
            False,
            "no curve is the residual r = y - C x̂, but some are the outputs y: plot "
            "resp.residual, not resp.outputs.",
        )
    else:
        result.add(False, "no curve of the figure is the residual of the response (resp.residual).")
