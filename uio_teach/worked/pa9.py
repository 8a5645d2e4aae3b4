"""Practical Assignment 9: its experiment, figures, explorer and lab, in one module.

The decoupling UIO ``z' = F z + T B u + K y``, ``xhat = z + H y`` of
*Estimation for control -- Practical Assignment 9* watches the plant of
:func:`uio_teach.examples.pa9` under a sinusoidal and a piecewise-constant
disturbance. This module is the whole worked example in the package: the run
(:data:`PA9`, its fields the config table ``[pa9]`` and the lab's ``PARAMS``),
the figures of ``uio-teach figures``, the explorer's options, the lab's
parameter class (:class:`PA9Params`) and the registry entry.

Examples
--------
>>> import uio_teach as ut
>>> from uio_teach.worked.pa9 import PA9
>>> PA9.initial_state.tolist(), PA9.poles
([1.0, -1.0, 0.5], (-1.0, -2.0, -3.0))
>>> observer = ut.design_uio(PA9.plant(), poles=PA9.poles)
>>> sine = PA9.simulate(observer, d=PA9.d_sine)
>>> steps = PA9.simulate(observer, d=PA9.d_piecewise)
>>> bool(abs(sine.error - steps.error).max() < 1e-8)   # the UIO ignores d
True
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from .. import examples, signals
from .._display import format_poles
from ..existence import check_existence
from ..experiments import (
    MAX_SEED,
    MAX_VALUE,
    SEED_DOC,
    ContinuousExperiment,
    param,
    plant_from_params,
)
from ..lab_params import (
    MIN_INITIAL_ERROR,
    LabParams,
    answer_value,
    direction_key,
    lab_params_of,
    pick,
)
from ..observers import design_luenberger
from . import ExplorerOptions, FigureEntry, LabEntry, WorkedExample

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["PA9Experiment", "PA9", "PA9_LAB", "PA9Params"]


@dataclass(frozen=True)
class PA9Experiment(ContinuousExperiment):
    """Practical Assignment 9: the decoupling UIO, a sinusoidal and a piecewise-constant ``d``.

    Attributes
    ----------
    sine_amplitude : float
        Amplitude of the sinusoidal disturbance ``d(t) = amplitude sin(frequency t)``.
    sine_frequency : float
        Its angular frequency (rad/s).
    switch_times : tuple of float
        The piecewise-constant disturbance: the times it switches (0 before the first).
    switch_values : tuple of float
        The level held from each switching time.

    Examples
    --------
    >>> from uio_teach.worked.pa9 import PA9
    >>> PA9.d_sine, PA9.d_piecewise
    (1 sin(2 t), piecewise constant (1 from t=0, -1.5 from t=2, 2 from t=5, 0 from t=7.5))
    >>> PA9.inputs
    [1 step(t - 0); 0.5 sin(1 t)]
    """

    lab: ClassVar[str] = "pa9"
    tables: ClassVar[Mapping[str, str]] = MappingProxyType(
        {
            "": "Practical Assignment 9: the decoupling observer and its lab",
            "sine": "the sinusoidal disturbance",
            "piecewise": "the piecewise-constant disturbance (0 before the first switching time)",
        }
    )

    initial_state: np.ndarray = param(
        (1.0, -1.0, 0.5), "floats", "plant state x(0)", length=3, maximum=MAX_VALUE
    )
    poles: tuple[complex, ...] | None = param(
        (-1.0, -2.0, -3.0), "poles", "UIO poles (also the Luenberger poles)"
    )
    noise: float | None = param(
        0.0,
        "float",
        "standard deviation of the measurement noise (0: none)",
        minimum=0.0,
        maximum=MAX_VALUE,
        omit_default=True,
        range=(0.0, 0.2),
        control="noise",
    )
    seed: int | None = param(
        4, "int", SEED_DOC, config="seed", minimum=0, maximum=MAX_SEED, omit_default=True
    )
    sine_amplitude: float = param(
        1.0,
        "float",
        "d(t) = amplitude sin(frequency t)",
        key="sine.amplitude",
        maximum=MAX_VALUE,
        range=(0.0, 5.0),
        control="amplitude",
    )
    sine_frequency: float = param(
        2.0,
        "float",
        "angular frequency, below the time grid's Nyquist frequency",
        unit="rad/s",
        key="sine.frequency",
        positive=True,
        range=(0.1, 10.0),
        control="frequency",
    )
    switch_times: tuple[float, ...] = param(
        (0.0, 2.0, 5.0, 7.5),
        "floats",
        "switching times, increasing, within the duration",
        unit="s",
        key="piecewise.times",
        minimum=0.0,
    )
    switch_values: tuple[float, ...] = param(
        (1.0, -1.5, 2.0, 0.0),
        "floats",
        "the level held from each switching time",
        key="piecewise.values",
        maximum=MAX_VALUE,
    )

    @property
    def inputs(self) -> Callable:
        """The known input ``u = [1, 0.5 sin t]``."""
        return signals.stack(signals.step(1.0), signals.sinusoid(0.5, 1.0))

    @property
    def d_sine(self) -> signals.Signal:
        """The sinusoidal disturbance."""
        return signals.sinusoid(self.sine_amplitude, self.sine_frequency)

    @property
    def d_piecewise(self) -> signals.Signal:
        """The piecewise-constant disturbance."""
        return signals.piecewise_constant(self.switch_times, self.switch_values)

    @property
    def unknown_inputs(self) -> Mapping[str, Callable]:
        """``{"sine": d_sine, "piecewise": d_piecewise}``."""
        return MappingProxyType({"sine": self.d_sine, "piecewise": self.d_piecewise})


PA9 = PA9Experiment(name="pa9", timepts=np.linspace(0.0, 10.0, 2001))
"""The run of Practical Assignment 9.

10 s on 2001 points, ``x(0) = [1, -1, 0.5]``, poles -1, -2, -3.
"""


# figures ---------------------------------------------------------------------------------------


def _runs(runs: Any) -> dict[str, Any]:
    """The runs of PA9's figures, computed once for all of them (``runs.shared``)."""

    def compute() -> dict[str, Any]:
        run = runs.run("pa9")
        plant = run.plant()
        uio = runs.observer("pa9")
        luen = design_luenberger(plant, poles=list(run.poles))
        d_sine, d_steps = run.d_sine, run.d_piecewise
        return {
            "plant": plant,
            "uio": uio,
            "d_sine": d_sine,
            "d_steps": d_steps,
            "uio_sine": run.simulate(uio, d=d_sine),
            "uio_steps": run.simulate(uio, d=d_steps),
            "luen_sine": run.simulate(luen, d=d_sine),
            "luen_steps": run.simulate(luen, d=d_steps),
        }

    return runs.shared("pa9", compute)


def _pa9_disturbance(runs: Any, which: str) -> Figure:
    # deferred: the registry is read without matplotlib, which the plotting module loads
    from ..plotting import (
        describe,
        finish_panel,
        how_it_ends,
        new_figure,
        plot_error,
        plot_residual,
        time_label,
        with_unit,
    )

    r = _runs(runs)
    resp, d = r[f"uio_{which}"], r[f"d_{which}"]
    fig = new_figure(8.0, 6.5)
    ax_d, ax_e, ax_r = fig.subplots(3, 1, sharex=True)
    t = resp.time
    ax_d.plot(t, resp.inputs.d[0], color="k")
    formula = repr(d)
    ax_d.set_title(f"d(t) = {formula if len(formula) <= 80 else formula[:77] + '...'}")
    finish_panel(ax_d, with_unit("disturbance $d$"), legend=False)
    plot_error(ax_e, resp)
    plot_residual(ax_r, resp)
    ax_r.set_xlabel(time_label(resp.plant.dt))
    kind = "sinusoidal" if which == "sine" else "piecewise-constant"
    title = f"PA9: UIO with a {kind} disturbance (poles {format_poles(r['uio'].poles(), 4)})"
    fig.suptitle(title)
    size = float(np.max(np.abs(resp.states)))
    describe(
        fig,
        f"{title}: against time, the disturbance d (black), the UIO's estimation error e1, "
        "e2, e3 and its residual r1, r2, each channel in its own colour and line style. The "
        f"error {how_it_ends(t, resp.error, size, resp.plant.dt)}, whatever d does; the "
        f"residual {how_it_ends(t, resp.residual, float(np.max(np.abs(resp.outputs))))}.",
        f"The disturbance d(t) = {formula}.",
    )
    return fig


def _pa9_sine(runs: Any) -> Figure:
    return _pa9_disturbance(runs, "sine")


def _pa9_piecewise(runs: Any) -> Figure:
    return _pa9_disturbance(runs, "steps")


def _pa9_states(runs: Any) -> Figure:
    # deferred: the registry is read without matplotlib (see the first figure)
    from ..plotting import new_figure

    r = _runs(runs)
    return r["uio_sine"].plot(
        fig=new_figure(9.0, 6.0), title=f"PA9: UIO, sinusoidal disturbance d(t) = {r['d_sine']!r}"
    )


def _pa9_luenberger(runs: Any) -> Figure:
    # deferred: the registry is read without matplotlib (see the first figure)
    from ..plotting import channel_style as look
    from ..plotting import (
        describe,
        finish_panel,
        how_it_ends,
        marker_style,
        new_figure,
        residual_channels,
        symbol,
        time_label,
    )

    r = _runs(runs)
    fig = new_figure(9.0, 5.5)
    axes = fig.subplots(2, 2, sharex=True, sharey="row")
    pairs = [
        ("UIO", r["uio_sine"], r["uio_steps"]),
        ("Luenberger observer", r["luen_sine"], r["luen_steps"]),
    ]
    for col, (name, sine, steps) in enumerate(pairs):
        for row, (what, sym, label) in enumerate(
            [("error", "e", "error $e$"), ("residual", "r", "residual $r$")]
        ):
            ax = axes[row, col]
            values = getattr(sine, what)
            channels = (
                residual_channels(sine.plant.C)
                if what == "residual"
                else list(range(values.shape[0]))
            )
            for i, j in enumerate(channels):
                # the line style says which disturbance: a colour and a marker per channel
                style = {"color": look(j)["color"], **marker_style(j, sine.time.size)}
                ax.plot(sine.time, values[i], **style, label=symbol(sym, i))
                ax.plot(steps.time, getattr(steps, what)[i], **style, linestyle="--")
            finish_panel(ax, label)
        axes[0, col].set_title(name)
        axes[1, col].set_xlabel(time_label(r["plant"].dt))
    fig.suptitle(
        f"PA9, poles {format_poles(r['uio'].poles(), 4)}: solid sinusoidal d, "
        "dashed piecewise-constant d"
    )
    words = []
    for name, sine, steps in pairs:
        gap = float(np.max(np.abs(sine.error - steps.error)))
        size = float(np.max(np.abs(sine.states)))
        same = "lie on top of each other" if gap <= 1e-6 * size else f"differ by up to {gap:.2g}"
        words.append(
            f"{name}: the errors for the two disturbances {same}; with the sinusoid the "
            f"error {how_it_ends(sine.time, sine.error, size, sine.plant.dt)}"
        )
    describe(
        fig,
        "The estimation error and the residual of the UIO and of a Luenberger observer with "
        "the same poles on PA9, each for a sinusoidal (solid) and a piecewise-constant "
        "(dashed) disturbance; each channel has its own colour and marker. "
        + ". ".join(words)
        + ".",
    )
    return fig


# the lab ---------------------------------------------------------------------------------------


PA9_LAB = PA9.with_values(
    poles=(-1.5, -2.5, -4.0),
    initial_state=(0.5, 1.0, -1.0),
    sine_amplitude=1.5,
    sine_frequency=1.5,
    switch_times=(0.0, 1.5, 4.0, 8.0),
    switch_values=(-1.0, 2.0, 0.5, -1.5),
)
"""The lab's own numbers (the chapter's plant and grid; other poles, start and disturbances).

The chapters print the results of :data:`PA9` (``K1``, the errors, ...); the
lab asks for the same computations on these numbers, so no page of the book
gives its answers away."""


@lab_params_of(PA9_LAB)
class PA9Params(LabParams):
    """The numbers of the PA9 lab (the fields of :data:`PA9_LAB`: not the chapter's run).

    Attributes
    ----------
    poles : tuple
        The observer poles (three; complex ones in conjugate pairs).
    initial_state : tuple of float
        ``x(0)``.
    noise : float
        Standard deviation of the measurement noise (0: none).
    seed : int
        Seed of that noise.
    duration : float
        Simulated time in s.
    samples : int
        Number of time points.
    style : str or tuple
        The matplotlib style of the plots (a name, or a style file's settings).
    matrices : tuple
        The group's own plant matrices (``PARAMS["plant"]``; empty: the course's).
    sine_amplitude : float
        The amplitude of ``d(t) = amplitude sin(frequency t)``.
    sine_frequency : float
        Its frequency, in rad/s.
    switch_times : tuple of float
        The times at which the piecewise-constant ``d`` switches.
    switch_values : tuple of float
        The values it takes.

    Examples
    --------
    >>> from uio_teach.worked.pa9 import PA9Params
    >>> PA9Params().to_params()["sine"]
    {'amplitude': 1.5, 'frequency': 1.5}
    """

    @classmethod
    def vary(cls, rng: np.random.Generator, base: LabParams) -> dict[str, Any]:
        """What a group's variant draws: the plant's ``A`` and ``E``, poles, ``x(0)``, disturbances.

        ``A`` keeps the assignment's structure (a second-order block and a
        first-order state, all stable: ``[[0, 1, 0], [-a0, -a1, 0], [0, 0, -a2]]``)
        and ``E`` a column of half-integers, so that ``H``, ``T``, ``K1``,
        ``F`` and ``K2`` differ between groups; :meth:`problems` makes sure
        that the UIO exists with all three poles movable. The poles are
        distinct, in [-6, -1] and at least 0.5 apart (the error decays to 1 %
        within the 10 s), the disturbances have amplitudes of at least 0.5 and
        the piecewise-constant one jumps three times, at least 1 s apart.
        Every other field (noise, seed, time grid, style, ...) keeps the
        term's value (:meth:`~uio_teach.lab_params.LabParams.draw`).
        """
        a0, a1, a2 = (
            pick(rng, [1.0, 2.0, 3.0, 4.0, 5.0]),
            pick(rng, [2.0, 3.0, 4.0, 5.0]),
            pick(rng, [1.0, 1.5, 2.0, 3.0]),
        )
        A = [[0.0, 1.0, 0.0], [-a0, -a1, 0.0], [0.0, 0.0, -a2]]
        E = [
            [pick(rng, [0.5, 1.0, 1.5, 2.0, 2.5, 3.0])],
            [pick(rng, [-1.0, -0.5, 0.0, 0.5, 1.0])],
            [pick(rng, [-1.5, -1.0, -0.5, 0.5, 1.0, 1.5])],
        ]
        grid = np.arange(-6.0, -0.99, 0.5)
        poles = tuple(sorted((float(p) for p in rng.choice(grid, 3, replace=False)), reverse=True))
        levels = [-2.0, -1.5, -1.0, -0.5, 0.5, 1.0, 1.5, 2.0]
        # x(0) along E would start the error e(0) = T x(0) at zero: nothing to see decay
        T = PA9Params.error_start_map(A, E)
        for _ in range(100):
            x0 = tuple(float(v) for v in rng.choice([-1.5, -1.0, -0.5, 0.5, 1.0, 1.5], 3))
            if np.max(np.abs(T @ np.asarray(x0))) >= MIN_INITIAL_ERROR:
                break
        while True:
            t = np.sort(rng.choice(np.arange(1.0, 9.0, 0.5), 3, replace=False))
            if np.all(np.diff(t) >= 1.0):
                break
        values = [float(rng.choice(levels))]
        while len(values) < 4:
            v = float(rng.choice(levels))
            if abs(v - values[-1]) >= 0.5:
                values.append(v)
        return {
            "poles": poles,
            "initial_state": x0,
            "matrices": {"A": A, "E": E},
            "sine_amplitude": pick(rng, [0.5, 1.0, 1.5, 2.0]),
            "sine_frequency": pick(rng, [1.0, 1.5, 2.0, 2.5, 3.0]),
            "switch_times": (0.0, *(float(x) for x in t)),
            "switch_values": tuple(values),
        }

    @staticmethod
    def error_start_map(A: Any, E: Any) -> np.ndarray:
        """``T = I - H C`` of the PA9 plant with this ``A`` and ``E``: e(0) = T x(0)."""
        plant = plant_from_params("pa9", {"plant": {"A": A, "E": E}})
        C, E = plant.C, plant.E
        return np.eye(plant.n) - E @ np.linalg.pinv(C @ E) @ C

    def distinct(self) -> dict[str, Any]:
        """Poles, and the direction of ``E`` with ``A`` (``H`` and ``T`` depend on it)."""
        plant = self.plant()
        return {
            "poles": tuple(sorted(complex(p).real for p in self.poles)),
            "plant": (direction_key(plant.E), tuple(plant.A.ravel())),
        }

    def problems(self) -> list[str]:
        """Why this variant would not be a fair exercise (empty: it is)."""
        out = []
        poles = np.array([complex(p) for p in self.poles])
        if poles.size != 3 or len({complex(p) for p in poles}) != 3:
            out.append("the three poles must be distinct")
        if np.any(poles.real >= 0):
            out.append("every pole must be stable")
        elif math.exp(float(np.max(poles.real)) * self.duration) > 1e-3:
            out.append("the slowest pole is too slow for the simulated time")
        if abs(self.sine_amplitude) < 0.1:
            out.append("the sinusoid is too small to be seen")
        if len(self.switch_times) < 2 or np.max(np.abs(self.switch_values)) < 0.1:
            out.append("the piecewise-constant disturbance must jump and be visible")
        if not np.any(np.asarray(self.initial_state)):
            out.append("x(0) must be nonzero")
        try:
            plant = self.plant()
        except ValueError as err:
            return [*out, f"the plant: {err}"]
        e0 = self.error_start_map(plant.A, plant.E) @ np.asarray(self.initial_state, float)
        if np.max(np.abs(e0)) < MIN_INITIAL_ERROR:
            out.append("x(0) must give a clearly nonzero initial error e(0) = T x(0)")
        report = check_existence(plant)
        if not report.ok or report.movable != plant.n:
            out.append("the UIO must exist with every pole movable ((C, TA) observable)")
        elif not np.all(np.linalg.eigvals(plant.A).real < 0):
            out.append("the plant must be stable (the simulation runs without control)")
        return out

    def answers(self) -> dict[str, Any]:
        """The answer key: ``H``, ``T``, ``K1`` (python-control's placement), ``F``, ``K2``."""
        plant = self.plant()
        A, C, E = plant.A, plant.C, plant.E
        H = E @ np.linalg.pinv(C @ E)
        T = np.eye(plant.n) - H @ C
        import control as ct  # deferred: python-control loads slowly, and only the key needs it

        K1 = ct.place((T @ A).T, C.T, [complex(p) for p in self.poles]).T
        F = T @ A - K1 @ C
        return {
            "H": answer_value(H),
            "T": answer_value(T),
            "K1": answer_value(K1),
            "F": answer_value(F),
            "K2": answer_value(F @ H),
            "error_poles": answer_value(np.sort_complex(np.linalg.eigvals(F))),
        }


EXAMPLES = (
    WorkedExample(
        name="pa9",
        title="Practical Assignment 9",
        plant=examples.pa9,
        experiment=PA9,
        family="uio",
        order=10,
        # the 10 s window on 1001 samples (half the run's resolution, for a quick redraw)
        explorer=ExplorerOptions(
            title="PA9",
            samples=1001,
            period=2.5,
            pole_limits=(-10.0, 1.0),
            frequency_limits=(0.0, 10.0),
            period_limits=(0.25, 5.0),
            static_values=(-8.0, -4.0, -2.0, -1.0, -0.5, -0.2, 0.2, 0.5),
        ),
        lab=LabEntry(
            "lab_pa9.md",
            PA9Params,
            ("pa9.design", "pa9.simulation", "pa9.plot", "pa9.piecewise", "pa9.piecewise_plot"),
        ),
        figures=(
            FigureEntry(
                "pa9_sine",
                "PA9 lab: sinusoidal disturbance d(t), error e and residual r of the UIO",
                _pa9_sine,
            ),
            FigureEntry(
                "pa9_piecewise",
                "PA9 lab: piecewise-constant disturbance d(t), error e and residual r of the UIO",
                _pa9_piecewise,
            ),
            FigureEntry(
                "pa9_states",
                "PA9: each state with its UIO estimate, error and residual (sinusoidal d)",
                _pa9_states,
            ),
            FigureEntry(
                "pa9_luenberger",
                "PA9: UIO vs Luenberger observer, same poles, errors and residuals for both d",
                _pa9_luenberger,
            ),
        ),
    ),
)
