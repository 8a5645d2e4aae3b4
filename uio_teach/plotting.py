"""The standard figures of the course: a simulation and an input reconstruction.

Drawing code only; the numbers come from :func:`uio_teach.simulate` and
:func:`uio_teach.reconstruct_input`. Every function returns the
``matplotlib.figure.Figure`` and accepts an existing figure or axes.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .reconstruction import InputEstimate
    from .simulation import UIOResponse

__all__ = ["plot_response", "plot_input_estimate", "time_label"]


def time_label(dt: float | bool | None) -> str:
    """The label of the time axis: ``"time (s)"``, or ``"step k"`` when ``dt=True``.

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
    >>> time_label(None), time_label(True), time_label(0.1)
    ('time (s)', 'step k', 'time (s)')
    """
    return "step k" if dt is True else "time (s)"


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
            raise ValueError(
                f"axes must hold {len(names)} axes ({', '.join(names)}), got {len(axes)}"
            )
        return axes[0].figure, axes
    if fig is None:
        import matplotlib.pyplot as plt

        fig = plt.figure(figsize=(10, height), layout="constrained")
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
    symbol: str,
    i: int,
) -> None:
    """One panel: a signal (coloured) and its estimate (black, dashed), labelled."""
    name = f"{symbol}_{{{i + 1}}}"
    if actual is not None:
        _line(ax, t, actual, discrete, label=f"${name}$", color=f"C{i}")
    hat = f"$\\hat{{{symbol}}}_{{{i + 1}}}$"
    _line(ax, t, estimate, discrete, label=hat, color="k", linestyle="--", linewidth=1.0)
    ax.set_ylabel(f"${name}$")
    ax.legend(loc="upper right", fontsize="small")
    ax.grid(True, alpha=0.3)


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
    >>> len(fig.axes), sorted(ax.get_ylabel() for ax in fig.axes)[:3]
    (5, ['$x_{1}$', '$x_{2}$', '$x_{3}$'])
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
    for i in range(n):
        _line(ax_err, t, response.error[i], discrete, label=f"$e_{{{i + 1}}}$", color=f"C{i}")
    ax_err.set_ylabel(r"error $e = x - \hat{x}$")
    for i in range(plant.p):
        _line(ax_res, t, response.residual[i], discrete, label=f"$r_{{{i + 1}}}$", color=f"C{i}")
    ax_res.set_ylabel(r"residual $r = y - C\hat{x}$")
    for a in (ax_err, ax_res):
        a.legend(loc="upper right", fontsize="small")
        a.grid(True, alpha=0.3)
        a.set_xlabel(xlabel)
    if title is None:
        name = plant.name or "plant"
        title = f"{response.observer.family} on {name}"
    fig.suptitle(title)
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
    '$d_{1}$'
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
    return fig
