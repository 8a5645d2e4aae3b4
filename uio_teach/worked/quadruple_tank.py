"""The quadruple-tank process (Johansson, 2000): its experiment, figures, explorer and entry.

Four tanks, two pumps, the two lower levels measured; both pump flows are the
unknown inputs (``E = B``, :func:`uio_teach.examples.quadruple_tank`), the
model linearized at the steady state of the valves and pump voltages. The
valves ``gamma1, gamma2`` decide whether a UIO exists: at 0 the rank
condition fails; above 0 the invariant zeros solve
``(1 + s T3)(1 + s T4) = (1 - gamma1)(1 - gamma2) / (gamma1 gamma2)``, and one
of them is at the origin when ``gamma1 + gamma2 = 1`` and in the right
half-plane below. With the plant in :mod:`uio_teach.examples`, this
module is the whole of the worked example in the package: the experiment
(:data:`QUADRUPLE_TANK`, its fields the config table ``[quadruple_tank]``),
its figures, its explorer's options (a slider per valve) and its registry entry.

Examples
--------
>>> import uio_teach as ut
>>> from uio_teach.worked.quadruple_tank import QUADRUPLE_TANK, valve_verdict
>>> QUADRUPLE_TANK.gamma1, QUADRUPLE_TANK.gamma2, QUADRUPLE_TANK.poles
(0.7, 0.6, (-0.1, -0.2))
>>> print(valve_verdict(0.43, 0.34))   # doctest: +NORMALIZE_WHITESPACE
gamma1 + gamma2 = 0.77 < 1: the valves send on average less than half of the pumps' flow to
the lower tanks, an invariant zero lies in the right half-plane at 0.0129, and no UIO with a
stable error exists
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from .. import signals
from .. import tolerances as tols
from .._display import format_poles
from ..errors import InputError
from ..examples import TankOperatingPoint, quadruple_tank, tank_operating_point
from ..existence import check_existence
from ..experiments import MAX_DURATION, MAX_SAMPLES, MAX_VALUE, Experiment, param
from ..luenberger import luenberger_poles
from ..observers import design_luenberger, design_uio
from ..simulation import UIOResponse
from . import ExplorerOptions, FigureEntry, WorkedExample

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["QuadrupleTankExperiment", "QUADRUPLE_TANK", "valve_verdict"]

VALVE_DOC = "the share of pump {i}'s flow sent to lower tank {i} (the rest to upper tank {j})"


@dataclass(frozen=True)
class QuadrupleTankExperiment(Experiment):
    """The quadruple tank with the pumps of P-, linearized at the steady state of its valves.

    The UIO (two movable poles; the two invariant zeros are its fixed poles)
    watches the levels while pump 1 steps and pump 2 oscillates, unknown to it.
    Both observers start from the estimate ``xhat(0) = 0``
    (:meth:`observer_state`). Initial levels or pump voltages that would be
    negative are refused, and so is a run whose linear model empties a tank.

    Attributes
    ----------
    gamma1 : float
        Valve 1's split (from 0 up to 0.99); passed to the plant.
    gamma2 : float
        Valve 2's split.
    step_size : float
        Pump 1's unknown deviation: a step of this many volts ...
    step_time : float
        ... at this time (s).
    sine_amplitude : float
        Pump 2's unknown deviation ``amplitude sin(frequency t)`` (V) ...
    sine_frequency : float
        ... of this angular frequency (rad/s).

    Examples
    --------
    >>> from uio_teach.worked.quadruple_tank import QUADRUPLE_TANK
    >>> QUADRUPLE_TANK.d
    [0.5 step(t - 100); 0.3 sin(0.05 t)]
    """

    lab: ClassVar[str] = "quadruple_tank"
    plant_fields: ClassVar[tuple[str, ...]] = ("gamma1", "gamma2")
    tables: ClassVar[Mapping[str, str]] = MappingProxyType(
        {
            "": "the quadruple-tank process of Johansson (2000), pumps of setting P-",
            "pump1": "pump 1's unknown deviation, a step",
            "pump2": "pump 2's unknown deviation, a sinusoid",
        }
    )

    initial_state: np.ndarray = param(
        (2.0, -1.0, 1.0, 1.5),
        "floats",
        "level deviations h(0) - h0 of tanks 1-4",
        unit="cm",
        length=4,
        maximum=MAX_VALUE,
    )
    poles: tuple[complex, ...] | None = param(
        (-0.1, -0.2), "poles", "UIO poles (two; the other two are the invariant zeros)"
    )
    duration: float = param(
        None, "float", "simulated time", unit="s", init=False, positive=True, maximum=MAX_DURATION
    )
    samples: int = param(
        None, "int", "number of time points", init=False, minimum=2, maximum=MAX_SAMPLES
    )
    gamma1: float = param(
        0.70,
        "float",
        VALVE_DOC.format(i=1, j=4),
        minimum=0.0,
        maximum=0.99,
        range=(0.0, 0.95),
    )
    gamma2: float = param(
        0.60,
        "float",
        VALVE_DOC.format(i=2, j=3),
        minimum=0.0,
        maximum=0.99,
        range=(0.0, 0.95),
    )
    step_size: float = param(
        0.5, "float", "size of the step", unit="V", key="pump1.step", maximum=MAX_VALUE
    )
    step_time: float = param(
        100.0, "float", "time of the step", unit="s", key="pump1.time", minimum=0.0
    )
    sine_amplitude: float = param(
        0.3,
        "float",
        "amplitude of the sinusoid",
        unit="V",
        key="pump2.amplitude",
        maximum=MAX_VALUE,
        range=(0.0, 1.0),
        control="amplitude",
    )
    sine_frequency: float = param(
        0.05,
        "float",
        "its angular frequency",
        unit="rad/s",
        key="pump2.frequency",
        positive=True,
        range=(0.005, 0.5),
        control="frequency",
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.matrices:  # the plant's own matrices: its states need not be levels
            return
        h0 = self.operating_point().h0
        low = h0 + self.initial_state
        if low.size == h0.size and np.any(low < 0):
            i = int(np.argmin(low))
            raise InputError(
                f"initial_state: the deviation {self.initial_state[i]:g} cm would leave tank "
                f"{i + 1} at {low[i]:.3g} cm, below empty (its level at this operating point is "
                f"{h0[i]:.3g} cm); keep every h(0) - h0 above -h0"
            )
        for key, what, lowest in (
            ("pump1.step", f"a step of {self.step_size:g} V", self.v0[0] + min(self.step_size, 0)),
            (
                "pump2.amplitude",
                f"an amplitude of {self.sine_amplitude:g} V",
                self.v0[1] - abs(self.sine_amplitude),
            ),
        ):
            if lowest < 0:
                pump = key[4]
                raise InputError(
                    f"{key}: {what} takes pump {pump} to {lowest:.3g} V, below 0 (it runs at "
                    f"{self.v0[int(pump) - 1]:g} V at the operating point)"
                )

    def operating_point(self) -> TankOperatingPoint:
        """The steady state of the run's valves and pump voltages (levels, time constants).

        Returns
        -------
        uio_teach.examples.TankOperatingPoint

        Examples
        --------
        >>> from uio_teach.worked.quadruple_tank import QUADRUPLE_TANK
        >>> QUADRUPLE_TANK.operating_point().h0.round(2).tolist()
        [12.26, 12.69, 1.63, 1.4]
        """
        return tank_operating_point(gamma1=self.gamma1, gamma2=self.gamma2)

    def observer_state(self, observer: Any) -> np.ndarray:
        """The observer state whose estimate ``xhat(0)`` is zero, as for any observer.

        The UIO's estimate is ``z + H y``: it starts at ``z(0) = -H y(0)``. With
        ``z(0) = 0`` instead its error would start in the upper tanks alone,
        where its gain never acts.

        Parameters
        ----------
        observer : Observer

        Returns
        -------
        numpy.ndarray

        Examples
        --------
        >>> import numpy as np, uio_teach as ut
        >>> from uio_teach.worked.quadruple_tank import QUADRUPLE_TANK as run
        >>> uio = ut.design_uio(run.plant(), poles=run.poles)
        >>> real = uio.realization()
        >>> y0 = run.plant().C @ run.initial_state
        >>> bool(np.allclose(real.C @ run.observer_state(uio) + real.D_y @ y0, 0))
        True
        """
        real = observer.realization()
        y0 = self.plant().C @ self.initial_state
        return np.linalg.lstsq(real.C, -real.D_y @ y0, rcond=None)[0]

    def simulate(self, observer: Any, **changes: Any) -> UIOResponse:
        """As :meth:`uio_teach.experiments.Experiment.simulate`; a level below empty is refused.

        Parameters
        ----------
        observer : Observer
        **changes
            Keywords of :func:`uio_teach.simulate`.

        Returns
        -------
        UIOResponse

        Raises
        ------
        ValueError
            The linear model takes a level below 0 (the deviations are too large for it).
        """
        res = super().simulate(observer, **changes)
        if self.matrices:
            return res
        h0 = self.operating_point().h0
        levels = h0[:, None] + res.states
        if np.any(levels < 0):
            i, k = np.unravel_index(int(np.argmin(levels)), levels.shape)
            raise InputError(
                f"the run takes tank {i + 1} to {levels[i, k]:.3g} cm at t = {res.time[k]:g} s, "
                f"below empty (its level at the operating point is {h0[i]:.3g} cm): the pump "
                "deviations are too large for the linear model"
            )
        return res

    @property
    def v0(self) -> tuple[float, float]:
        """Setting P-'s pump voltages at the operating point, in V."""
        return tank_operating_point().v0

    @property
    def d(self) -> signals.Signal:
        """The pumps' unknown deviations ``[d1; d2]``."""
        return signals.stack(
            signals.step(self.step_size, self.step_time),
            signals.sinusoid(self.sine_amplitude, self.sine_frequency),
        )

    @property
    def unknown_inputs(self) -> Mapping[str, Callable]:
        """``{"pumps": d}``."""
        return MappingProxyType({"pumps": self.d})


QUADRUPLE_TANK = QuadrupleTankExperiment(
    name="quadruple-tank", timepts=np.linspace(0.0, 600.0, 1201)
)
"""The run of the quadruple tank.

600 s on 1201 points, the valves and pumps of P-, UIO poles -0.1, -0.2, both observers
started from the estimate 0."""


def valve_verdict(gamma1: float, gamma2: float, v0: Any = None) -> str:
    """One sentence: does a UIO exist for these valves, and why (from the existence check).

    Parameters
    ----------
    gamma1, gamma2 : float
        The valve splits.
    v0 : pair of float, optional
        The pump voltages (default: setting P-'s).

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.worked.quadruple_tank import valve_verdict
    >>> print(valve_verdict(0.7, 0.3))   # doctest: +NORMALIZE_WHITESPACE
    gamma1 + gamma2 = 1: the valves send on average half of the pumps' flow to the lower
    tanks, an invariant zero sits at the origin (to round-off), and no UIO with a stable error
    exists
    >>> valve_verdict(0.5, 0.5 + 1e-6)[:43]
    'gamma1 + gamma2 = 1.000001 > 1: the valves '
    >>> print(valve_verdict(0.0, 0.6))   # doctest: +NORMALIZE_WHITESPACE
    gamma1 = 0: pump 1 feeds upper tank 4 only and reaches the measured levels only through it,
    so CE is singular, the rank condition fails and no UIO exists
    """
    report = check_existence(quadruple_tank(gamma1=gamma1, gamma2=gamma2, v0=v0))
    closed = [i for i, g in ((1, gamma1), (2, gamma2)) if g == 0]
    if closed:
        upper = {1: 4, 2: 3}
        if len(closed) == 1:
            (i,) = closed
            what = f"gamma{i} = 0: pump {i} feeds upper tank {upper[i]} only and reaches"
            tail = "through it, so CE is singular"
        else:
            what = (
                "gamma1 = 0 and gamma2 = 0: pumps 1 and 2 feed upper tanks 4 and 3 only and reach"
            )
            tail = "through them, so CE = 0"
        return f"{what} the measured levels only {tail}, the rank condition fails and no UIO exists"
    if report["rank condition"].holds is not True:  # a valve so nearly closed that CE is singular
        i, g = min(((1, gamma1), (2, gamma2)), key=lambda pair: pair[1])
        return (
            f"gamma{i} = {g:.3g}: pump {i} sends almost nothing to lower tank {i}, so CE is "
            "singular to round-off, the rank condition fails and no UIO exists"
        )
    zeros = np.sort(report.invariant_zeros.real)
    total = gamma1 + gamma2
    if abs(total - 1) <= 4 * np.finfo(float).eps:  # 0.7 + 0.3 is 1 to round-off
        head = (
            "gamma1 + gamma2 = 1: the valves send on average half of the pumps' flow to the "
            "lower tanks"
        )
    else:
        # close to 1: enough digits to tell the side
        digits = max(3, 2 + math.ceil(-math.log10(abs(total - 1))))
        share = "more" if total > 1 else "less"
        sign = ">" if total > 1 else "<"
        head = (
            f"gamma1 + gamma2 = {total:.{digits}g} {sign} 1: the valves send on average {share} "
            "than half of the pumps' flow to the lower tanks"
        )
    if report.ok:
        slow = zeros[-1]
        return (
            f"{head}, both invariant zeros are stable ({', '.join(f'{z:.3g}' for z in zeros)}) "
            f"and a UIO exists; its slowest fixed pole {slow:.3g} ({-1 / slow:.3g} s per e-fold) "
            "is a mode of the error that no gain moves"
        )
    if not zeros.size:  # pragma: no cover - the rank condition holds: the plant has its zeros
        return f"{head}, and no UIO with a stable error exists"
    worst = float(zeros[-1])
    if abs(worst) <= tols.STABILITY_MARGIN * max(1.0, float(np.max(np.abs(zeros)))):
        place = "an invariant zero sits at the origin (to round-off)"
    else:
        place = f"an invariant zero lies in the right half-plane at {worst:.3g}"
    return f"{head}, {place}, and no UIO with a stable error exists"


# figures ---------------------------------------------------------------------------------------


def _run(runs: Any) -> dict[str, Any]:
    """The tank's runs of the figures, computed once for both (``runs.shared``)."""

    def compute() -> dict[str, Any]:
        run = runs.run("quadruple_tank")
        plant = run.plant()
        uio = design_uio(plant, poles=list(run.poles))  # the config checked that it exists
        luen = design_luenberger(plant, poles=luenberger_poles(plant, uio.poles()))
        return {
            "run": run,
            "plant": plant,
            "uio": uio,
            "uio_run": run.simulate(uio),
            "luen_run": run.simulate(luen),
        }

    return runs.shared("quadruple_tank", compute)


def _figure_error(runs: Any) -> Figure:
    # deferred: the registry is read without matplotlib, which the plotting module loads
    from ..plotting import (
        channel_style,
        describe,
        finish_panel,
        how_it_ends,
        new_figure,
        plot_error,
        symbol,
        time_label,
        with_unit,
    )

    r = _run(runs)
    resp, luen = r["uio_run"], r["luen_run"]
    fig = new_figure(8.0, 7.0)
    ax_d, ax_e, ax_l = fig.subplots(3, 1, sharex=True)
    for i in range(resp.inputs.d.shape[0]):
        ax_d.plot(resp.time, resp.inputs.d[i], **channel_style(i), label=symbol("d", i))
    finish_panel(ax_d, with_unit("pump deviations $d$", "V"))
    plot_error(ax_e, resp)
    ax_e.set_title(
        f"UIO, poles {format_poles(r['uio'].poles(), 3)}, from the estimate 0", fontsize=9
    )
    plot_error(ax_l, luen)
    ax_l.set_title("Luenberger observer with the same poles, from the same start", fontsize=9)
    ax_l.set_xlabel(time_label(r["plant"].dt))
    run = r["run"]
    title = f"Quadruple tank, gamma = {run.gamma1:g}, {run.gamma2:g}: the UIO ignores the pumps"
    fig.suptitle(title)
    size = float(np.max(np.abs(resp.states)))
    t = resp.time
    describe(
        fig,
        f"{title}. Three panels against time: the pumps' unknown deviations d1, d2; the UIO's "
        f"estimation error, which {how_it_ends(t, resp.error, size, resp.plant.dt)}; the "
        "Luenberger observer's error with the same poles, which "
        f"{how_it_ends(t, luen.error, size, luen.plant.dt)}.",
    )
    return fig


def _figure_zeros(runs: Any) -> Figure:
    # deferred: the registry is read without matplotlib, which the plotting module loads
    from ..plotting import COLORS, describe, finish_panel, new_figure, shade_band

    run = _run(runs)["run"]
    ratio = run.gamma2 / run.gamma1
    top = min(0.99, 0.99 / ratio)
    g1 = np.linspace(0.05, top, 241)
    zeros = np.array(
        [
            np.sort(
                check_existence(quadruple_tank(gamma1=g, gamma2=g * ratio)).invariant_zeros.real
            )
            for g in g1
        ]
    )
    total = g1 * (1 + ratio)
    fig = new_figure(8.0, 4.5)
    ax = fig.subplots()
    ax.plot(total, zeros[:, 0], color=COLORS[0], label="faster zero")
    ax.plot(total, zeros[:, 1], color=COLORS[1], ls="--", label="slower zero")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.axvline(1.0, color="0.5", lw=0.8, ls=":")
    mine = np.sort(check_existence(run.plant()).invariant_zeros.real)
    here = run.gamma1 + run.gamma2
    ax.plot([here, here], mine, "ko", mfc="none", label="this run's valves")
    shade_band(ax, total[0], 1.0, "_no UIO")  # named by the text in it
    ax.text(0.98, 0.05, "no UIO", transform=ax.get_xaxis_transform(), ha="right", color="0.15")
    lim = 2.5 * max(float(np.max(np.abs(mine))), 0.02)
    ax.set_ylim(-lim, 0.6 * lim)
    ax.set_xlabel(
        r"$\gamma_1 + \gamma_2$"
        + f" (along $\\gamma_2 = {ratio:.3g}\\,\\gamma_1$, each at its own steady state)"
    )
    finish_panel(ax, "invariant zero (1/s)")
    ax.set_title("Quadruple tank: the zeros move with the valves and cross 0 at 1")
    fast, slow = zeros[:, 0], zeros[:, 1]
    cross = total[int(np.argmax(slow <= 0))]  # the first total where the slower zero is not > 0
    describe(
        fig,
        f"The two invariant zeros (1/s) of the quadruple tank against gamma1 + gamma2 from "
        f"{total[0]:.2g} to {total[-1]:.2g} (valves moved together, gamma2 = {ratio:.3g} "
        "gamma1; a dotted vertical line at 1): the faster zero (blue, solid) stays negative, "
        f"{_on_axis(total, fast, ax.get_ylim())}; the slower one (vermillion, dashed) falls "
        f"from {slow[0]:.2g} to {slow[-1]:.2g}, through zero at gamma1 + gamma2 = "
        f"{cross:.2g}, and is positive below it, where no UIO exists (the shaded band), "
        f"{_on_axis(total, slow, ax.get_ylim())}. This run's "
        f"valves, gamma1 + gamma2 = {here:.3g}, give the zeros {mine[0]:.3g} and "
        f"{mine[1]:.3g} (open circles).",
    )
    return fig


def _on_axis(x: np.ndarray, y: np.ndarray, ylim: tuple[float, float]) -> str:
    """Where a curve is inside the axis' vertical limits, in words (it may leave the picture)."""
    inside = (y >= ylim[0]) & (y <= ylim[1])
    if inside.all():
        return f"from {y[0]:.2g} to {y[-1]:.2g}"
    if not inside.any():
        return f"outside the axis ({ylim[0]:.2g} to {ylim[1]:.2g}) throughout"
    shown = x[inside]
    return (
        f"inside the axis ({ylim[0]:.2g} to {ylim[1]:.2g}) only from gamma1 + gamma2 = "
        f"{shown[0]:.2g} to {shown[-1]:.2g}, beyond the axis elsewhere (from {y.min():.2g} "
        f"to {y.max():.2g})"
    )


EXAMPLES = (
    WorkedExample(
        name="quadruple_tank",
        title="The quadruple-tank process",
        plant=quadruple_tank,
        experiment=QUADRUPLE_TANK,
        family="uio",
        order=40,
        explorer=ExplorerOptions(
            title="Quadruple tank",
            samples=601,
            period=100.0,
            pole_limits=(-0.5, 0.01),
            frequency_limits=(0.0, 0.5),
            period_limits=(10.0, 300.0),
            noise_limits=(0.0, 0.2),
            d_channels=((1.0, 1.0), (0.5, 1.5)),
            # the static book's slider: valve 2, valve 1 at 0.7 (the line is at 0.3; at 0 the
            # rank condition fails)
            static_control="plant:gamma2",
            static_values=(0.0, 0.1, 0.2, 0.29, 0.31, 0.4, 0.6, 0.8),
            note=valve_verdict,
        ),
        figures=(
            FigureEntry(
                "tank_error",
                "Quadruple tank: pump deviations, error of the UIO and of a Luenberger observer",
                _figure_error,
            ),
            FigureEntry(
                "tank_zeros",
                "Quadruple tank: the invariant zeros against gamma1 + gamma2, the run's valves",
                _figure_zeros,
            ),
        ),
    ),
)
