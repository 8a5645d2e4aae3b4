"""The missile autopilot: its experiment, figures, explorer and lab, in one module.

A. De, A. Banerjee, G. Das, *Comparison of unknown input estimation using
projection operator and generalized matrix inverse* (2014): the
projection-operator observer (PMO) and the generalized-inverse observer
estimate the states of :func:`uio_teach.examples.missile_autopilot` and
reconstruct its unknown inputs ``v1, v2``. This module is the whole worked
example in the package: the run (:data:`MISSILE`, its fields the config
table ``[missile]`` and the lab's ``PARAMS``), the figures of ``uio-teach
figures`` (Table II among them), the explorer's options, the lab's parameter
class (:class:`MissileParams`) and the registry entry.

Examples
--------
>>> from uio_teach.worked.missile import MISSILE
>>> MISSILE.name, MISSILE.duration, MISSILE.timepts.size
('missile', 0.5, 10001)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from .. import examples, signals
from .._display import format_poles
from ..examples import MISSILE_PUBLISHED
from ..existence import check_existence
from ..experiments import (
    MAX_SEED,
    MAX_VALUE,
    ContinuousExperiment,
    param,
)
from ..lab_params import (
    MIN_INITIAL_ERROR,
    LabParams,
    answer_value,
    lab_params_of,
    pick,
    subspace_key,
)
from ..observers import design_ginverse, design_pmo
from ..reconstruction import catch_time, reconstruct_input
from . import ExplorerOptions, FigureEntry, LabEntry, WorkedExample

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["MissileExperiment", "MISSILE", "MISSILE_LAB", "MissileParams"]


@dataclass(frozen=True)
class MissileExperiment(ContinuousExperiment):
    """The missile autopilot: the paper's ``x0`` and ``v1, v2``, the PMO started at ``xhat(0) = 0``.

    The unknown inputs are the paper's damped sinusoids
    ``v_i(t) = amplitude exp(-rate t) cos/sin(frequency t)``, one tuple
    ``(amplitude, rate, frequency, "cos" or "sin")`` each in ``v_parameters``.

    Attributes
    ----------
    v_parameters : tuple of tuple
        ``v1`` and ``v2`` as ``(amplitude, rate, frequency, kind)``.

    Examples
    --------
    >>> from uio_teach.worked.missile import MISSILE
    >>> MISSILE.poles, MISSILE.v
    ((-100.0, -120.0), [10 exp(-2 t) cos(10 t); 50 exp(-5 t) sin(100 t)])
    """

    lab: ClassVar[str] = "missile"
    tables: ClassVar[Mapping[str, str]] = MappingProxyType(
        {
            "": "the missile autopilot of De, Banerjee and Das (2014)",
            "noise": "the measurement noise of the lab's last exercise",
        }
    )

    initial_state: np.ndarray = field(default=tuple(examples.MISSILE_PUBLISHED.x0))
    poles: tuple[complex, ...] | None = param(
        (-100.0, -120.0),
        "poles",
        "PMO poles (the paper's are not given; see the missile chapter)",
        key="pmo_poles",
    )
    v_parameters: tuple[tuple[float, float, float, str], ...] = examples.MISSILE_INPUTS
    noise_sigma: float = param(
        0.01,
        "float",
        "standard deviation of the measurement noise",
        key="noise.sigma",
        positive=True,
        maximum=MAX_VALUE,
    )
    noise_seed: int = param(
        7, "int", "seed of that noise", key="noise.seed", minimum=0, maximum=MAX_SEED
    )
    tol: float = param(
        0.02,
        "float",
        "the band of the catch times, relative to each signal's peak",
        config=False,
        positive=True,
        maximum=1.0,
    )

    @property
    def v(self) -> Callable:
        """The unknown inputs ``[v1; v2]`` as one vector signal."""
        return signals.stack(*(signals.damped_sinusoid(*p) for p in self.v_parameters))

    @property
    def unknown_inputs(self) -> Mapping[str, Callable]:
        """``{"v": v}``."""
        return MappingProxyType({"v": self.v})

    def observer_state(self, observer: Any) -> np.ndarray:
        """``q(0) = -M C x(0)``: the estimate ``xhat(0) = q(0) + M y(0)`` starts at zero.

        Parameters
        ----------
        observer : Observer
            An observer with a matrix ``M`` (a PMO).

        Returns
        -------
        numpy.ndarray

        Examples
        --------
        >>> import uio_teach as ut
        >>> from uio_teach.worked.missile import MISSILE
        >>> plant = MISSILE.plant()
        >>> pmo = ut.design_pmo(plant, poles=MISSILE.poles)
        >>> q0 = MISSILE.observer_state(pmo)
        >>> bool(abs(q0 + pmo.M @ plant.C @ MISSILE.initial_state).max() == 0)
        True
        """
        C = self.plant().C
        return -observer.M @ C @ self.initial_state


MISSILE = MissileExperiment(name="missile", timepts=np.linspace(0.0, 0.5, 10_001))
"""The run of the missile autopilot.

0.5 s on 10001 points, the paper's ``x0``, PMO poles -100, -120.
"""


# figures ---------------------------------------------------------------------------------------


def _runs(runs: Any) -> dict[str, Any]:
    """The runs of the missile's figures, computed once for all of them (``runs.shared``)."""

    def compute() -> dict[str, Any]:
        run = runs.run("missile")
        plant, t = run.plant(), run.timepts
        out: dict[str, Any] = {"plant": plant, "time": t, "tol": run.tol}
        ginverse = design_ginverse(plant)
        out["free"] = run.simulate(ginverse, d=None, observer_state=None)
        pmo = runs.observer("missile")
        # Both observers start from q(0) = -M y(0): the PMO knows nothing at t = 0
        # (xhat(0) = 0) and the g-inverse observer reads the measured states. Started at
        # q(0) = 0 instead, the PMO would give the g-inverse's estimates whatever its poles
        # (the missile chapter explains both starts and Table II).
        q0 = run.observer_state(pmo)
        for name, obs in (("pmo", pmo), ("ginverse", ginverse)):
            resp = run.simulate(obs, observer_state=q0)
            est = reconstruct_input(plant, resp)
            out[name] = {
                "observer": obs,
                "response": resp,
                "inputs": est,
                "catch_states": catch_time(t, resp.states, resp.estimates, tol=run.tol),
                "catch_inputs": catch_time(t, resp.inputs.d, est.estimates, tol=run.tol),
            }
        return out

    return runs.shared("missile", compute)


def _missile_states(runs: Any, name: str, label: str, figs: str) -> Figure:
    # deferred: the registry is read without matplotlib, which the plotting module loads
    from ..plotting import (
        COLORS,
        describe,
        finish_panel,
        how_it_ends,
        new_figure,
        symbol,
        time_label,
        with_unit,
    )

    m = _runs(runs)
    resp, free = m[name]["response"], m["free"]
    fig = new_figure(9.0, 6.0)
    axes = fig.subplots(2, 2, sharex=True)
    t = resp.time
    for i, ax in enumerate(axes.flat):
        ax.plot(t, resp.states[i], color=COLORS[1], label=f"{symbol('x', i)} with $v$")
        ax.plot(t, free.states[i], color=COLORS[0], ls="--", label=f"{symbol('x', i)} without $v$")
        hat = symbol("x", i, hat=True)
        ax.plot(t, resp.estimates[i], color="k", linestyle=":", lw=2, label=hat)
        finish_panel(ax, with_unit(symbol("x", i)))
    for ax in axes[1]:
        ax.set_xlabel(time_label(m["plant"].dt))
    title = (
        f"Missile autopilot, {label} (poles {format_poles(m[name]['observer'].poles(), 4)}); "
        f"the paper's {figs}"
    )
    fig.suptitle(title)
    size = float(np.max(np.abs(resp.states)))
    # how far v moves each state: the largest gap to the run without v, against its range
    gaps = np.max(np.abs(resp.states - free.states), axis=1)
    spans = np.ptp(np.concatenate([resp.states, free.states], axis=1), axis=1)
    share = gaps / np.where(spans > 0, spans, 1.0)
    describe(
        fig,
        f"{title}: one panel per state x1 to x4 against time, the state with the unknown "
        "inputs v (vermillion, solid), without them (blue, dashed) and the observer's estimate "
        "(black, dotted). The unknown inputs move each state away from the run without them, "
        f"by up to {share.min():.0%} (x{int(np.argmin(share)) + 1}) to {share.max():.0%} "
        f"(x{int(np.argmax(share)) + 1}) of the range its panel shows, "
        "and the estimate follows the state with v: the estimation error "
        f"{how_it_ends(t, resp.error, size, m['plant'].dt)}.",
        " ".join(
            f"x{i + 1}: with v it ends at {resp.states[i, -1]:.3g}, without v at "
            f"{free.states[i, -1]:.3g} (the largest gap {gaps[i]:.3g}); the error "
            f"{how_it_ends(t, resp.error[i], size)}."
            for i in range(resp.states.shape[0])
        ),
    )
    return fig


def _missile_pmo(runs: Any) -> Figure:
    return _missile_states(runs, "pmo", "PMO", "Fig. 4.1-4.4")


def _missile_ginverse(runs: Any) -> Figure:
    return _missile_states(runs, "ginverse", "g-inverse observer", "Fig. 4.7-4.10")


def _missile_error(runs: Any) -> Figure:
    # deferred: the registry is read without matplotlib (see the first figure)
    from ..plotting import (
        describe,
        finish_panel,
        how_it_ends,
        new_figure,
        time_label,
        with_unit,
        zero_to_rounding,
    )

    m = _runs(runs)
    fig = new_figure(9.0, 6.0)
    axes = fig.subplots(2, 2, sharex=True)
    for i, ax in enumerate(axes.flat):
        errors = []
        for name, label, style in (("pmo", "PMO", "-"), ("ginverse", "g-inverse", "--")):
            resp = m[name]["response"]
            ax.plot(resp.time, resp.error[i], linestyle=style, label=label)
            errors.append(resp.error[i])
        finish_panel(ax, with_unit(rf"$e_{i + 1} = x_{i + 1} - \hat{{x}}_{i + 1}$"))
        # a measured state is estimated exactly: its error is rounding noise, shown on zero
        scale = float(np.max(np.abs(m["pmo"]["response"].states[i])))
        zero_to_rounding(ax, np.array(errors), scale)
    for ax in axes[1]:
        ax.set_xlabel(time_label(m["plant"].dt))
    fig.suptitle("Missile autopilot: estimation error of both observers")
    pmo, gin = m["pmo"]["response"], m["ginverse"]["response"]
    size = float(np.max(np.abs(pmo.states)))
    dt = m["plant"].dt
    apart = np.max(np.abs(pmo.error - gin.error), axis=0)
    when = float(pmo.time[int(np.argmax(apart))])
    describe(
        fig,
        "Missile autopilot: the estimation error e1 to e4 of the PMO (solid) and of the "
        "g-inverse observer (dashed) against time, one panel per state. "
        + "; ".join(
            f"e{i + 1}: the PMO's {how_it_ends(pmo.time, pmo.error[i], size, dt)}, the "
            f"g-inverse observer's {how_it_ends(gin.time, gin.error[i], size, dt)}"
            for i in range(pmo.error.shape[0])
        )
        + f". The two observers' errors differ most, by {float(apart.max()):.2g}, at "
        f"t = {when:.2g} s; the PMO's errors reach {float(np.max(np.abs(pmo.error))):.2g}, "
        f"the g-inverse observer's {float(np.max(np.abs(gin.error))):.2g}.",
    )
    return fig


def _missile_inputs(runs: Any) -> Figure:
    # deferred: the registry is read without matplotlib (see the first figure)
    from ..plotting import (
        COLORS,
        describe,
        finish_panel,
        how_it_ends,
        new_figure,
        symbol,
        time_label,
        with_unit,
    )

    m = _runs(runs)
    fig = new_figure(9.0, 5.5)
    axes = fig.subplots(2, 1, sharex=True)
    t = m["time"]
    actual = m["pmo"]["response"].inputs.d
    for i, ax in enumerate(axes):
        ax.plot(t, actual[i], color=COLORS[1], lw=2.5, alpha=0.6, label=symbol("v", i))
        for name, label, style in (("pmo", "PMO", "-"), ("ginverse", "g-inverse", ":")):
            est = m[name]["inputs"].estimates[i]
            hat = symbol("v", i, hat=True)
            ax.plot(t, est, color="k", linestyle=style, lw=1.2, label=f"{hat} {label}")
        finish_panel(ax, with_unit(symbol("v", i)))
        lim = 1.3 * float(np.max(np.abs(actual[i])))
        ax.set_ylim(-lim, lim)
    axes[-1].set_xlabel(time_label(m["plant"].dt))
    fig.suptitle(
        r"Missile autopilot: unknown inputs and their reconstructions "
        r"$\hat{v} = E^+(\dot{\hat{x}} - A\hat{x})$ (Fig. 4.5-4.6, 4.11-4.12)"
    )
    said = []
    for i, ax in enumerate(axes):
        scale = float(np.max(np.abs(actual[i])))
        low, high = ax.get_ylim()
        for name, label in (("pmo", "the PMO's"), ("ginverse", "the g-inverse observer's")):
            est = m[name]["inputs"].estimates[i]
            gap = est - actual[i]
            off = (est < low) | (est > high)
            start = (
                f" (it starts off the axis, at {est[0]:.3g}, and re-enters it at "
                f"t = {t[int(np.argmax(~off))]:.2g} s)"
                if off[0]
                else ""
            )
            said.append(
                f"for v{i + 1} {label} gap {how_it_ends(t, gap, scale, m['plant'].dt)}{start}"
            )
    describe(
        fig,
        "Missile autopilot: the unknown inputs v1 and v2 (wide pale vermillion lines) and their "
        "reconstructions by the PMO (black, solid) and the g-inverse observer (black, dotted) "
        "against time, one panel per input, each axis 1.3 times the input's peak high. After a "
        "short start the reconstructions lie on the inputs: " + "; ".join(said) + ".",
    )
    return fig


def _table2_rows(runs: Any) -> list[tuple[str, float, float, float, float]]:
    m = _runs(runs)
    pub = MISSILE_PUBLISHED
    names = ["x1", "x2", "x3", "x4", "v1", "v2"]
    computed = {
        name: list(m[name]["catch_states"]) + list(m[name]["catch_inputs"])
        for name in ("pmo", "ginverse")
    }
    return [
        (
            s,
            float(computed["pmo"][i]),
            float(pub.catch_pmo[s]),
            float(computed["ginverse"][i]),
            float(pub.catch_ginverse[s]),
        )
        for i, s in enumerate(names)
    ]


def _table2(runs: Any, out: Path) -> list[Path]:
    rows = _table2_rows(runs)
    csv_path, md_path = out / "missile_table2.csv", out / "missile_table2.md"
    header = "signal,pmo_computed_s,pmo_paper_s,ginverse_computed_s,ginverse_paper_s"
    csv = [header] + [f"{s},{a:.4f},{b:.2f},{c:.4f},{d:.2f}" for s, a, b, c, d in rows]
    m = _runs(runs)
    md = [
        "Table II: time (s) after which each estimate stays within "
        f"{m['tol']:.0%} of the signal's peak",
        "",
        f"PMO poles {format_poles(m['pmo']['observer'].poles(), 4)}; g-inverse observer poles "
        f"{format_poles(m['ginverse']['observer'].poles(), 4)}; simulated over {m['time'][-1]:g} s "
        f"({m['time'].size} time points).",
        "",
        "| signal | PMO, computed | PMO, paper | g-inverse, computed | g-inverse, paper |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    md += [f"| {s} | {a:.3f} | {b:.2f} | {c:.3f} | {d:.2f} |" for s, a, b, c, d in rows]
    for path, lines in ((csv_path, csv), (md_path, md)):
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return [csv_path, md_path]


# the lab ---------------------------------------------------------------------------------------


MISSILE_LAB = MISSILE.with_values(poles=(-90.0, -140.0), noise_sigma=0.015, noise_seed=3)
"""The lab's own numbers (the paper's plant, ``x0`` and inputs; other PMO poles and noise).

The chapter prints the results of :data:`MISSILE` (the catch times with the
poles -100, -120, the noise RMS of seed 7, ...); the lab asks for the same
computations with these numbers, so no page of the book gives its answers away."""


@lab_params_of(MISSILE_LAB)
class MissileParams(LabParams):
    """The numbers of the missile lab (the fields of :data:`MISSILE`).

    Attributes
    ----------
    poles : tuple of float
        The two movable PMO poles (rad/s; ``PARAMS["pmo_poles"]``).
    duration : float
        Simulated time in s (Table II is read over this window).
    samples : int
        Number of time points.
    style : str or tuple
        The matplotlib style of the plots.
    matrices : tuple
        The group's own plant matrices (``PARAMS["plant"]``; empty: the paper's).
    noise_sigma : float
        Standard deviation of the measurement noise of the last exercise.
    noise_seed : int
        Seed of that noise.
    tol : float
        The band of the catch times, relative to each signal's peak.

    Examples
    --------
    >>> from uio_teach.worked.missile import MissileParams
    >>> MissileParams().to_params()["pmo_poles"]
    [-90.0, -140.0]
    """

    @classmethod
    def vary(cls, rng: np.random.Generator, base: LabParams) -> dict[str, Any]:
        """What a group's variant draws: the airframe, actuator and sensors; PMO poles; noise.

        ``A`` keeps the paper's structure (``x2' = -a x1 - b x3``, a fin
        actuator of natural frequency ``wn`` and damping ``zeta``), ``B`` its
        gain, ``E`` small integers, and ``C`` measures ``x1 + c x3`` and
        ``x2 + c' x3`` (sensors that see a little of the fin deflection), so that ``M``,
        ``Cg``, ``Pc``, ``Kg`` and the predicted noise differ between groups.
        :meth:`problems` makes sure that ``CE`` is square and invertible, the
        two invariant zeros (the fixed modes) are stable and actuator-like, and
        the PMO catches ``v1``, ``v2`` within the window. The two PMO poles
        lie in [-170, -70], at least 20 apart. Every other field (the time
        grid, the catch band, ...) keeps the term's value.
        """
        wn = pick(rng, [150.0, 160.0, 170.0, 180.0, 190.0, 200.0])
        zeta = pick(rng, [0.5, 0.6, 0.7])
        A = [
            [0.0, 0.0, 0.0, 0.0],
            [
                -pick(rng, [70.0, 80.0, 86.0, 90.0, 100.0]),
                0.0,
                -pick(rng, [8, 10, 12, 14]),
                0,
            ],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, -(wn**2), -round(2 * zeta * wn, 6)],
        ]
        B = [[0.0], [0.0], [0.0], [-round(1.4 * wn**2, 6)]]
        E = rng.choice([-1.0, 1.0, 2.0, 3.0, 4.0, 5.0], (4, 2)).tolist()
        C = [
            [1.0, 0.0, round(pick(rng, np.arange(-6, 7)) * 0.05, 2), 0.0],
            [0.0, 1.0, round(pick(rng, np.arange(-6, 7)) * 0.05, 2), 0.0],
        ]
        chapter = {float(p.real) for p in map(complex, MISSILE.poles)}
        while True:  # not the chapter's poles: its catch times would be a group's answers
            a, b = sorted(rng.choice(np.arange(-170.0, -69.0, 5.0), 2, replace=False))
            if b - a >= 20 and not {float(a), float(b)} & chapter:
                break
        matrices = {"A": A, "B": B, "C": C, "E": E}
        return {
            "poles": (float(b), float(a)),
            "matrices": matrices,
            "noise_sigma": pick(rng, [0.005, 0.01, 0.02]),
            "noise_seed": int(rng.integers(1, 1000)),
        }

    def distinct(self) -> dict[str, Any]:
        """PMO poles, ``C`` (``Cg``, ``Pc``) and the column space of ``E`` (``M``, ``Kg``)."""
        plant = self.plant()
        return {
            "poles": tuple(sorted(complex(p).real for p in self.poles)),
            "C": tuple(plant.C.ravel()),
            "E": subspace_key(plant.E),
        }

    def problems(self) -> list[str]:
        """Why this variant would not be a fair exercise (empty: it is)."""
        out = []
        poles = np.array([complex(p) for p in self.poles])
        if poles.size != 2 or len(set(poles.tolist())) != 2:
            out.append("the two PMO poles must be distinct")
        if np.any(poles.real >= -10):
            out.append("the PMO poles must be stable and fast enough for the 0.5 s window")
        if self.noise_sigma <= 0:
            out.append("the noise exercise needs a positive noise level")
        if self.noise_seed < 0:
            out.append("the seed of the noise must be >= 0")
        try:
            plant = self.plant()
        except ValueError as err:
            return [*out, f"the plant: {err}"]
        CE = plant.C @ plant.E
        if np.linalg.matrix_rank(CE) < 2 or np.linalg.cond(CE) > 100:
            return [*out, "CE must be square and well invertible"]
        report = check_existence(plant)
        zeros = report.invariant_zeros
        if not report.ok or report.movable != 2 or zeros.size != 2:
            return [*out, "the PMO must exist with two movable poles and two invariant zeros"]
        if np.max(zeros.real) > -30 or np.max(np.abs(zeros)) > 600:
            out.append("the invariant zeros must be stable and actuator-like (|z| <= 600 rad/s)")
        if np.max(np.abs(plant.E @ np.linalg.inv(CE))) > 50:
            out.append("M has entries too large for a fair comparison with the paper's")
        if not out:
            # both observers of the lab must be designable for this plant (a design whose
            # decoupling cannot be certified is refused, and the group could not go on)
            try:
                design_ginverse(plant)
                design_pmo(plant, poles=[complex(p) for p in self.poles])
            except (ValueError, ArithmeticError) as err:
                return [*out, f"both observers must be designable: {err}"]
        if not out:
            # the lab's runs start the PMO at z(0) = 0: e(0) = (I - MC) x0
            M = design_pmo(plant, poles=[complex(p) for p in self.poles], Mv=MISSILE_PUBLISHED.Mv).M
            e0 = (np.eye(plant.n) - M @ plant.C) @ np.asarray(MISSILE_PUBLISHED.x0, float)
            if np.max(np.abs(e0)) < MIN_INITIAL_ERROR:
                out.append("the paper's x0 must give a clearly nonzero initial error (I - MC) x0")
        if not out:
            # the catch-time story: from xhat(0) = 0 the PMO's v-hat catches v1, v2 early
            run = self.run()
            pmo = design_pmo(plant, poles=[complex(p) for p in self.poles])
            response = run.simulate(pmo)
            vhat = reconstruct_input(plant, response)
            catch = catch_time(run.timepts, response.inputs.d, vhat.estimates, tol=self.tol)
            if not np.all(np.isfinite(catch)) or np.max(catch) > self.duration / 2:
                out.append("the PMO must catch v1 and v2 within the first half of the window")
        return out

    def answers(self) -> dict[str, Any]:
        """The answer key: ``M``, ``L``, ``Cg``, ``Pc``, ``Kg`` and the predicted noise RMS."""
        plant = self.plant()
        C, E = plant.C, plant.E
        Mv = MISSILE_PUBLISHED.Mv
        CE = C @ E
        CEg = np.linalg.pinv(CE)
        M = E @ CEg + Mv @ (np.eye(plant.p) - CE @ CEg)
        pmo = design_pmo(plant, poles=[complex(p) for p in self.poles], Mv=Mv)
        Cg = np.linalg.pinv(C)
        Pc = np.eye(plant.n) - Cg @ C
        h = self.duration / (self.samples - 1)
        rho = np.linalg.norm(np.linalg.inv(CE), axis=1)
        return {
            "M": answer_value(M),
            "L": answer_value(pmo.L),
            "Cg": answer_value(Cg),
            "Pc": answer_value(Pc),
            "Kg": answer_value(Pc @ E @ CEg),
            "error_poles": answer_value(np.sort_complex(pmo.poles())),
            "fixed_modes": answer_value(np.sort_complex(check_existence(plant).fixed_modes)),
            "noise_rms_predicted": answer_value(self.noise_sigma / (math.sqrt(2) * h) * rho, 6),
        }


def _channels() -> tuple[tuple[Any, ...], ...]:
    """The paper's ``v1, v2`` as explorer channels: multiples of ``v1``'s amplitude, frequency."""
    amplitude, _, frequency, _ = MISSILE.v_parameters[0]
    return tuple(
        (a / amplitude, w / frequency, rate / w, kind) for a, rate, w, kind in MISSILE.v_parameters
    )


EXAMPLES = (
    WorkedExample(
        name="missile",
        title="The missile autopilot",
        plant=examples.missile_autopilot,
        experiment=MISSILE,
        family="pmo",
        order=30,
        # the paper's damped sinusoids, 0.5 s on 1001 samples; the inputs reconstructed with a
        # filter of 2 ms; the controls' amplitude and frequency are v1's
        explorer=ExplorerOptions(
            title="Missile autopilot",
            samples=1001,
            disturbance="damped sinusoid",
            amplitude=MISSILE.v_parameters[0][0],
            frequency=MISSILE.v_parameters[0][2],
            period=0.05,
            tau=0.002,
            pole_limits=(-400.0, 40.0),
            frequency_limits=(0.0, 300.0),
            amplitude_limits=(0.0, 50.0),
            disturbance_frequency_limits=(1.0, 200.0),
            period_limits=(0.01, 0.25),
            noise_limits=(0.0, 0.5),
            tau_limits=(0.0, 0.05),
            d_channels=_channels(),
            static_values=(-400.0, -200.0, -100.0, -50.0, -20.0, -5.0, 5.0, 20.0),
            input_symbol="v",
        ),
        lab=LabEntry(
            "lab_missile.md",
            MissileParams,
            (
                "missile.pmo",
                "missile.ginverse",
                "missile.reconstruction",
                "missile.plot",
                "missile.catch_times",
                "missile.noise",
            ),
        ),
        figures=(
            FigureEntry(
                "missile_pmo",
                "Missile: x1..x4 with/without v and the PMO estimates (paper Fig. 4.1-4.4)",
                _missile_pmo,
            ),
            FigureEntry(
                "missile_ginverse",
                "Missile: x1..x4 with/without v and the g-inverse estimates (Fig. 4.7-4.10)",
                _missile_ginverse,
            ),
            FigureEntry(
                "missile_error",
                "Missile: estimation error of the PMO and the g-inverse observer, per state",
                _missile_error,
            ),
            FigureEntry(
                "missile_inputs",
                "Missile: v1, v2 and their reconstructions by both observers (Fig. 4.5-4.6, "
                "4.11-4.12)",
                _missile_inputs,
            ),
            FigureEntry(
                "missile_table2",
                "Missile: Table II, catch times (tol 2 %) next to the paper's, as .csv and .md",
                _table2,
                table=True,
            ),
        ),
    ),
)
