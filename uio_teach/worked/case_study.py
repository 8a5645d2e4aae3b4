"""The discrete-time case study: its experiment, figures, explorer and lab, in one module.

*Case Study: projection operator unknown input observer for a discrete-time
system*: a projection-operator observer whose gain is certified by an LMI
watches the plant of :func:`uio_teach.examples.dt_case_study` while an unknown
state input ``d`` and a random staircase ``v`` on the outputs act. This module
is the whole worked example in the package: the run (:data:`CASE_STUDY`, its
fields the config table ``[case_study]`` and the lab's ``PARAMS``), the
figures of ``uio-teach figures``, the explorer's options, the lab's parameter
class (:class:`CaseStudyParams`) and the registry entry.

Examples
--------
>>> import uio_teach as ut
>>> from uio_teach.worked.case_study import CASE_STUDY
>>> pmo = ut.design_pmo(CASE_STUDY.plant(), method="lmi")
>>> CASE_STUDY.simulate(pmo).error.shape
(3, 41)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from .. import examples, signals
from .. import tolerances as tols
from .._display import format_poles
from ..errors import InputError
from ..existence import check_existence, decoupling
from ..experiments import (
    MAX_SEED,
    MAX_STEPS,
    MAX_VALUE,
    SEED_DOC,
    Experiment,
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
from ..observers import design_pmo
from . import ExplorerOptions, FigureEntry, LabEntry, WorkedExample

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["CaseStudyExperiment", "CASE_STUDY", "CASE_STUDY_LAB", "CaseStudyParams"]


@dataclass(frozen=True)
class CaseStudyExperiment(Experiment):
    """The discrete-time case study: PMO from the LMI, unknown input ``d``, random staircase ``v``.

    Attributes
    ----------
    d_amplitude : float
        Amplitude of the unknown state input ``d[k] = amplitude sin(frequency k)``.
    d_frequency : float
        Its angular frequency (rad per step).
    v_amplitude : float
        The measurement disturbance ``v`` holds levels drawn uniformly in
        ``[-v_amplitude, v_amplitude]``.
    v_hold : int
        Steps each level of ``v`` is held.

    Examples
    --------
    >>> from uio_teach.worked.case_study import CASE_STUDY
    >>> CASE_STUDY.timepts[-1], CASE_STUDY.poles, CASE_STUDY.d
    (np.float64(40.0), None, 2 sin(0.6 t))
    """

    lab: ClassVar[str] = "case_study"
    tables: ClassVar[Mapping[str, str]] = MappingProxyType(
        {
            "": "the discrete-time case study (projection-operator observer)",
            "d": "the unknown state input",
            "v": "the measurement disturbance",
        }
    )

    initial_state: np.ndarray = param(
        (1.0, -2.0, 3.0), "floats", "plant state x[0]", length=3, maximum=MAX_VALUE
    )
    poles: tuple[complex, ...] | None = param(
        None,
        "poles",
        "the one movable pole, e.g. [0.2]; absent: the LMI gain of the case study",
        discrete=True,
        optional=True,
        lab=False,
    )
    seed: int | None = param(
        4, "int", SEED_DOC, config="seed", key="v.seed", minimum=0, maximum=MAX_SEED
    )
    duration: float = param(
        None,
        "int",
        "number of steps k = 0 ... steps",
        key="steps",
        init=False,
        minimum=2,
        maximum=MAX_STEPS,
    )
    pole: float = param(
        0.3,
        "float",
        "where the lab's exercise moves the one movable pole (inside the unit circle)",
        config=False,
        minimum=-1.0,
        maximum=1.0,
    )
    d_amplitude: float = param(
        2.0,
        "float",
        "d[k] = amplitude sin(frequency k)",
        key="d.amplitude",
        maximum=MAX_VALUE,
        range=(0.0, 5.0),
        control="amplitude",
    )
    d_frequency: float = param(
        0.6,
        "float",
        "angular frequency, at most pi",
        unit="rad per step",
        key="d.frequency",
        positive=True,
        maximum=math.pi,
        range=(0.05, 3.0),
        control="frequency",
    )
    v_amplitude: float = param(
        1.0,
        "float",
        "v: a random staircase, levels uniform in [-amplitude, amplitude]",
        key="v.amplitude",
        minimum=0.0,
        maximum=MAX_VALUE,
    )
    v_hold: int = param(
        5, "int", "steps each level of v is held", key="v.hold", minimum=1, maximum=MAX_STEPS
    )

    def grid(self, samples: int | None = None, duration: float | None = None) -> np.ndarray:
        """The steps ``k = 0 ... duration`` (``samples``, if given, must be ``duration + 1``).

        Parameters
        ----------
        samples : int, optional
            Number of steps plus one.
        duration : int, optional
            The last step (default: ``duration``).

        Returns
        -------
        numpy.ndarray

        Examples
        --------
        >>> from uio_teach.worked.case_study import CASE_STUDY
        >>> CASE_STUDY.grid(duration=3).tolist()
        [0.0, 1.0, 2.0, 3.0]
        """
        if duration is None and samples is None:
            return self.timepts
        last = int(duration) if duration is not None else int(samples) - 1
        if samples is not None and int(samples) != last + 1:
            raise InputError(f"samples must be the steps plus one ({last + 1}), got {samples}")
        return np.arange(last + 1, dtype=float)

    @property
    def d(self) -> signals.Signal:
        """The unknown state input ``d[k] = d_amplitude sin(d_frequency k)``."""
        return signals.sinusoid(self.d_amplitude, self.d_frequency)

    @property
    def unknown_inputs(self) -> Mapping[str, Callable]:
        """``{"d": d}``."""
        return MappingProxyType({"d": self.d})

    def measurement_disturbance(
        self, seed: int | None = None, timepts: np.ndarray | None = None
    ) -> signals.Signal:
        """The random staircase ``v``: a new level every ``v_hold`` steps.

        Parameters
        ----------
        seed : int, optional
            Seed of ``numpy.random.default_rng`` (default: ``seed``).
        timepts : numpy.ndarray, optional
            The steps it must cover (default: ``timepts``).

        Returns
        -------
        Signal

        Examples
        --------
        >>> from uio_teach.worked.case_study import CASE_STUDY
        >>> v = CASE_STUDY.measurement_disturbance()
        >>> bool(v(0.0) == v(4.0) != v(5.0))
        True
        """
        t = self.timepts if timepts is None else np.asarray(timepts, dtype=float)
        rng = np.random.default_rng(self.seed if seed is None else seed)
        switch = np.arange(0, t[-1] + 1, self.v_hold)
        levels = rng.uniform(-self.v_amplitude, self.v_amplitude, switch.size)
        return signals.piecewise_constant(switch, levels)


CASE_STUDY = CaseStudyExperiment(name="case-study", timepts=np.arange(41.0))
"""The run of the case study.

Steps ``k = 0 ... 40``, ``x[0] = [1, -2, 3]``, the LMI gain, seed 4.
"""


# figures ---------------------------------------------------------------------------------------


def _runs(runs: Any) -> dict[str, Any]:
    """The runs of the case study's figures, computed once for both (``runs.shared``)."""

    def compute() -> dict[str, Any]:
        run = runs.run("case_study")
        pmo = runs.observer("case_study")
        return {
            "plant": run.plant(),
            "pmo": pmo,
            "loud": run.simulate(pmo),
            "quiet": run.simulate(pmo, d=None, v=None),
        }

    return runs.shared("case_study", compute)


def _case_response(runs: Any) -> Figure:
    # deferred: the registry is read without matplotlib, which the plotting module loads
    from ..plotting import new_figure

    r = _runs(runs)
    return r["loud"].plot(
        fig=new_figure(9.0, 6.0),
        title=f"Case study: PMO (poles {format_poles(r['pmo'].poles(), 4)}), unknown input d and "
        "disturbance v active",
    )


def _case_error(runs: Any) -> Figure:
    # deferred: the registry is read without matplotlib (see the first figure)
    from ..plotting import describe, finish_panel, how_it_ends, new_figure, time_label, with_unit

    r = _runs(runs)
    loud, quiet = r["loud"], r["quiet"]
    k = loud.time
    fig = new_figure(8.0, 4.5)
    ax = fig.subplots()
    norm = np.linalg.norm(loud.error, axis=0)
    ax.semilogy(k, norm, "o", label=r"$\|e[k]\|$ with $u_2$ and $v$")
    ax.semilogy(k, np.linalg.norm(quiet.error, axis=0), "k+", label=r"$\|e[k]\|$ without them")
    rho = float(np.max(np.abs(r["pmo"].poles())))
    if rho > 0:
        ax.semilogy(k, norm[0] * rho**k, "--", label=rf"$\|e[0]\|\,{rho:.3g}^k$")
    ax.set_xlabel(time_label(True))  # the case study counts steps k
    finish_panel(ax, with_unit(r"$\|e[k]\|_2$"))
    ax.set_title("Case study: the estimation error ignores both unknown signals")
    gap = float(np.max(np.abs(loud.error - quiet.error)))
    same = (
        "the same"
        if gap <= tols.ROUNDING_RTOL * max(float(norm.max()), 1.0)
        else f"within {gap:.2g}"
    )
    describe(
        fig,
        "The size of the case-study PMO's estimation error at each step k, on a logarithmic "
        "axis, with the unknown input d and the disturbance v (circles) and without them "
        f"(black crosses): {same}, so the error ignores both signals. The error "
        f"{how_it_ends(k, loud.error, float(np.max(np.abs(loud.states))), True)}"
        + (
            f"; both lie on the dashed line ||e[0]|| {rho:.3g}^k, the rate of the slowest pole."
            if rho > 0
            else "."
        ),
    )
    return fig


# the lab ---------------------------------------------------------------------------------------


CASE_STUDY_LAB = CASE_STUDY.with_values(
    initial_state=(2.0, 1.0, -1.0),
    pole=0.2,
    d_amplitude=1.5,
    d_frequency=0.8,
    seed=7,
    v_hold=4,
)
"""The lab's own numbers (the case study's plant and steps; another pole, start and signals).

The chapter prints the results of :data:`CASE_STUDY` (the pole moved to 0.3,
the run's error, ...); the lab asks for the same computations on these
numbers, so no page of the book gives its answers away."""


_POLES_KEY = "case_study.poles"
"""The config key of the observer's poles, which sets the lab's one ``pole``."""


@lab_params_of(CASE_STUDY_LAB)
class CaseStudyParams(LabParams):
    """The numbers of the case-study lab (the fields of :data:`CASE_STUDY`).

    Attributes
    ----------
    initial_state : tuple of float
        ``x[0]``.
    seed : int
        Seed of the levels of ``v``.
    duration : int
        The simulation runs over ``k = 0 ... duration`` (``PARAMS["steps"]``).
    style : str or tuple
        The matplotlib style of the plots.
    matrices : tuple
        The group's own plant matrices (``PARAMS["plant"]``; empty: the course's).
    pole : float
        Where exercise 3 moves the one movable pole (inside the unit circle).
    d_amplitude : float
        The amplitude of ``d[k] = amplitude sin(frequency k)``.
    d_frequency : float
        Its frequency, in rad per step.
    v_amplitude : float
        The staircase ``v`` holds levels uniform in ``[-amplitude, amplitude]``.
    v_hold : int
        Steps each level is held.

    Examples
    --------
    >>> from uio_teach.worked.case_study import CaseStudyParams
    >>> CaseStudyParams().to_params()["v"]
    {'seed': 7, 'amplitude': 1.0, 'hold': 4}
    """

    @classmethod
    def config_keys(cls) -> frozenset[str]:
        """As ``LabParams.config_keys``, and ``case_study.poles`` (it sets ``pole``)."""
        return super().config_keys() | {_POLES_KEY}

    @classmethod
    def from_config(cls, config: Mapping[str, Any] | None) -> CaseStudyParams:
        """As ``LabParams.from_config``; ``case_study.poles``, if given, sets ``pole``."""
        params = super().from_config(config)
        given = getattr(config, "given", None)
        key = _POLES_KEY
        unset = config is None or (given is not None and key not in given)
        poles = None if unset else config.get(key)
        if poles:
            return dataclasses.replace(params, pole=float(complex(poles[0]).real))
        return params

    @classmethod
    def vary(cls, rng: np.random.Generator, base: LabParams) -> dict[str, Any]:
        """What a group's variant draws: the plant's ``E``, ``D``; pole, ``d``, ``v``, ``x[0]``.

        ``A = 0.5 I`` stays (so the two fixed modes stay at 0.5, as the chapter
        tells), ``E`` is a column of small integers and ``D = [1, c]^T`` or
        ``[c, 1]^T`` (``c`` a multiple of 0.05): ``M``, ``A1``, the LMI's ``L``
        (``L D = 0``) and the moved pole's gain differ between groups;
        :meth:`problems` makes sure that ``M`` exists, the two fixed modes are
        stable and the LMI is feasible. The pole lies in [-0.6, 0.3], at least
        0.1 from the fixed modes and from the eigenvalues of ``A1`` (moving it
        takes a gain; a term's own pole must be 0.05 from them); the unknown
        inputs have amplitudes of at least 0.5; ``x[0]`` has integer entries
        and a nonzero initial error ``(I - MC) x[0]``; ``v`` has a seed of its
        own. Every other field keeps the term's value.
        """
        E = [[pick(rng, [1.0, 2.0])], *([pick(rng, [-1.0, 1.0, 2.0])] for _ in range(2))]
        c = pick(rng, [x for x in np.round(np.arange(-0.95, 0.96, 0.05), 2) if abs(x) > 0.01])
        D = [[1.0], [c]] if rng.integers(2) else [[c], [1.0]]
        matrices = {"E": E, "D": D}
        plant = plant_from_params("case_study", {"plant": matrices})
        M = decoupling(plant).M
        Pi = np.eye(plant.n) - M @ plant.C
        for _ in range(100):
            x0 = rng.choice([-3.0, -2.0, -1.0, 1.0, 2.0, 3.0], 3)
            if np.max(np.abs(Pi @ x0)) >= MIN_INITIAL_ERROR:
                break
        return {
            "initial_state": tuple(float(v) for v in x0),
            "seed": int(rng.integers(1, 1000)),
            "matrices": matrices,
            "pole": pick(rng, [-0.6, -0.4, -0.3, -0.2, 0.1, 0.2, 0.3]),
            "d_amplitude": pick(rng, [1.0, 1.5, 2.0, 2.5, 3.0]),
            "d_frequency": pick(rng, [0.3, 0.4, 0.5, 0.6, 0.7, 0.8]),
            "v_amplitude": pick(rng, [0.5, 1.0, 1.5]),
            "v_hold": int(rng.choice([3, 4, 5, 6])),
        }

    def distinct(self) -> dict[str, Any]:
        """The direction of ``D``: no ``M D = 0`` or ``L D = 0`` holds for two groups."""
        plant = self.plant()
        return {"D": direction_key(plant.D)}

    def fixed_modes(self) -> np.ndarray:
        """The two error modes no gain with ``L D = 0`` moves (the invariant zeros)."""
        return np.sort_complex(check_existence(self.plant()).fixed_modes)

    def problems(self) -> list[str]:
        """Why this variant would not be a fair exercise (empty: it is)."""
        out = []
        if not abs(self.pole) < 1:
            out.append("the movable pole must lie inside the unit circle")
        if abs(self.d_amplitude) < 0.1 or self.v_amplitude < 0.1:
            out.append("the unknown inputs must be visible")
        if self.duration < 20:
            out.append("the simulation is too short to see the error decay")
        if self.seed < 0 or self.v_hold < 1:
            out.append("the seed of v must be >= 0 and its hold at least one step")
        try:
            plant = self.plant()
        except ValueError as err:
            return [*out, f"the plant: {err}"]
        G = np.hstack([plant.C @ plant.E, plant.D])
        if np.linalg.matrix_rank(G) < G.shape[1] or np.linalg.cond(G) > 50:
            return [*out, "[C B2, D] must be well invertible, so that M exists"]
        report = check_existence(plant)
        fixed = report.fixed_modes
        if not report.ok or report.movable != 1 or fixed.size != 2:
            return [*out, "the observer must exist with one movable pole and two fixed modes"]
        if np.max(np.abs(fixed)) > 0.8:
            out.append("the fixed modes must be stable, and fast enough for the run")
        if np.min(np.abs(fixed - self.pole)) < 0.1:
            out.append("the movable pole must differ from the fixed modes")
        dec = decoupling(plant)
        e0 = (np.eye(plant.n) - dec.M @ plant.C) @ np.asarray(self.initial_state, float)
        if np.max(np.abs(e0)) < MIN_INITIAL_ERROR:
            out.append("x[0] must give a clearly nonzero initial error (I - MC) x[0]")
        if np.max(np.abs(decoupling(plant).M)) > 10:
            out.append("M has entries too large for a fair hand computation")
        natural = np.linalg.eigvals(decoupling(plant).A1)
        if np.min(np.abs(natural - self.pole)) < 0.05:
            # the mode is there already: L = 0 would "move" it, for every group alike
            out.append("the movable pole must be moved: away from the eigenvalues of A1")
        if not out:
            try:
                pmo = design_pmo(plant, method="lmi")
            except ValueError as err:
                return [f"the LMI has no solution: {err}"]
            if (
                np.max(np.abs(pmo.L @ plant.D)) > tols.CHECK_RTOL
                or np.max(np.abs(pmo.poles())) >= 1
            ):
                out.append("the LMI gain must satisfy L D = 0 and be stable")
        return out

    def answers(self) -> dict[str, Any]:
        """The answer key: ``M``, ``A1``, the gain ``L`` that moves the pole, the error poles."""
        plant = self.plant()
        dec = decoupling(plant)
        placed = design_pmo(plant, poles=[self.pole])
        return {
            "M": answer_value(dec.M),
            "A1": answer_value(dec.A1),
            "L_pole": answer_value(placed.L),
            "error_poles": answer_value(np.sort(placed.poles().real)),
            "fixed_modes": answer_value(np.sort_complex(check_existence(plant).fixed_modes)),
            "e0": answer_value(
                (np.eye(plant.n) - dec.M @ plant.C) @ np.asarray(self.initial_state)
            ),
        }


EXAMPLES = (
    WorkedExample(
        name="case_study",
        title="The discrete-time case study",
        plant=examples.dt_case_study,
        experiment=CASE_STUDY,
        family="pmo",
        order=20,
        # two fixed poles at 0.5 (the invariant zeros); v at half the amplitude and twice the
        # frequency of d; the LMI mode with a radius bound
        explorer=ExplorerOptions(
            title="Case study",
            poles=(0.0,),
            period=5.0,
            pole_limits=(-1.1, 1.1),
            frequency_limits=(0.0, 180.0),
            period_limits=(1.0, 20.0),
            noise_limits=(0.0, 0.5),
            decay=0.9,
            decay_limits=(0.3, 1.0),
            v_channels=((0.5, 2.0),),
            static_values=(-0.9, -0.5, 0.0, 0.3, 0.5, 0.7, 0.9, 0.97, 1.05),
        ),
        lab=LabEntry(
            "lab_case_study.md",
            CaseStudyParams,
            (
                "case_study.projection",
                "case_study.lmi",
                "case_study.pole",
                "case_study.simulation",
                "case_study.residual",
                "case_study.plot",
            ),
        ),
        figures=(
            FigureEntry(
                "case_response",
                "Case study: states, estimates, error and residual with d and v both active",
                _case_response,
            ),
            FigureEntry(
                "case_error",
                "Case study: error norm on a log scale, with and without the unknown signals",
                _case_error,
            ),
        ),
    ),
)
