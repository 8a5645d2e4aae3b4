"""The course's worked experiments, each defined once: the runs behind the figures and explorers.

An experiment is what the book simulates for one plant of :mod:`uio_teach.examples`:
the time grid, the known input, the unknown inputs, the initial state, the
observer poles, where the observer starts and the measurement noise. The
figures of ``uio-teach figures``, the explorers and the lab checks read these
values from here, so changing one (say the PA9 initial state) changes every
figure, explorer and lab that uses it.

* :data:`PA9` -- Practical Assignment 9: the decoupling UIO with the poles
  ``-1, -2, -3``, a sinusoidal and a piecewise-constant disturbance;
* :data:`CASE_STUDY` -- the discrete-time case study: the projection-operator
  observer (gain from the LMI), the unknown state input ``u2`` and a random
  staircase ``v``;
* :data:`MISSILE` -- the missile autopilot of De, Banerjee and Das: the PMO with
  the poles ``-100, -120``, the paper's unknown inputs ``v1, v2`` and initial
  state, the observer started at ``q(0) = -M C x(0)`` (so ``xhat(0) = 0``).

Each is a frozen dataclass; :meth:`Experiment.simulate` runs an observer on it
with :func:`uio_teach.simulate`.

Examples
--------
>>> import uio_teach as ut
>>> from uio_teach.experiments import PA9
>>> PA9.initial_state.tolist(), PA9.poles
([1.0, -1.0, 0.5], (-1.0, -2.0, -3.0))
>>> observer = ut.design_uio(PA9.plant(), poles=PA9.poles)
>>> sine = PA9.simulate(observer, d=PA9.d_sine)
>>> steps = PA9.simulate(observer, d=PA9.d_piecewise)
>>> bool(abs(sine.error - steps.error).max() < 1e-8)   # the UIO ignores d
True
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from . import examples, signals
from ._validation import as_matrix
from .plant import Plant
from .simulation import UIOResponse, simulate

__all__ = [
    "Experiment",
    "PA9Experiment",
    "CaseStudyExperiment",
    "MissileExperiment",
    "PA9",
    "CASE_STUDY",
    "MISSILE",
    "LAB_PLANTS",
    "plant_from_params",
]


def _frozen(values: Any) -> np.ndarray:
    arr = np.array(values, dtype=float)
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True)
class Experiment:
    """A worked experiment: the plant and everything a simulation of it needs but the observer.

    Attributes
    ----------
    name : str
        A short identifier.
    timepts : numpy.ndarray
        The simulation grid (read-only; for a discrete plant, one point per step).
    initial_state : numpy.ndarray
        The plant's initial state ``x(0)`` (read-only).
    poles : tuple of complex, or None
        The observer poles of the experiment (``None``: the gain comes from the LMI).
    noise : float or None
        Standard deviation of the measurement noise on every output (``None``: none).
    seed : int or None
        Seed of the noise and of any random signal of the experiment.

    Examples
    --------
    >>> from uio_teach.experiments import MISSILE
    >>> MISSILE.name, MISSILE.duration, MISSILE.timepts.size
    ('missile', 0.5, 10001)
    """

    name: str
    timepts: np.ndarray = field(repr=False)
    initial_state: np.ndarray
    poles: tuple[complex, ...] | None
    noise: float | None = None
    seed: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "timepts", _frozen(self.timepts))
        object.__setattr__(self, "initial_state", _frozen(self.initial_state).ravel())
        if self.poles is not None:
            poles = tuple(complex(p) if complex(p).imag else complex(p).real for p in self.poles)
            object.__setattr__(self, "poles", poles)

    # the plant and the time grid ----------------------------------------------------------------
    def plant(self) -> Plant:
        """A new copy of the experiment's plant (from :mod:`uio_teach.examples`).

        Returns
        -------
        Plant

        Examples
        --------
        >>> from uio_teach.experiments import PA9
        >>> PA9.plant().name
        'PA9'
        """
        raise NotImplementedError  # pragma: no cover - every experiment names its plant

    @property
    def duration(self) -> float:
        """The last time point (seconds, or steps)."""
        return float(self.timepts[-1])

    def grid(self, samples: int | None = None, duration: float | None = None) -> np.ndarray:
        """The time grid, or one from the same start with another length or resolution.

        Parameters
        ----------
        samples : int, optional
            Number of time points (default: as ``timepts``).
        duration : float, optional
            The last time point (default: :attr:`duration`).

        Returns
        -------
        numpy.ndarray

        Examples
        --------
        >>> from uio_teach.experiments import PA9
        >>> PA9.grid(samples=5).tolist()
        [0.0, 2.5, 5.0, 7.5, 10.0]
        """
        if samples is None and duration is None:
            return self.timepts
        start = float(self.timepts[0])
        stop = self.duration if duration is None else float(duration)
        count = self.timepts.size if samples is None else int(samples)
        return np.linspace(start, stop, count)

    # the run ------------------------------------------------------------------------------------
    @property
    def inputs(self) -> Callable | None:
        """The known input ``u`` (a signal of :mod:`uio_teach.signals`), or ``None``."""
        return None

    @property
    def unknown_inputs(self) -> Mapping[str, Callable]:
        """The experiment's unknown inputs ``d``, by name (the first one is the default)."""
        return MappingProxyType({})

    def measurement_disturbance(self) -> Callable | None:
        """The measurement disturbance ``v``, or ``None`` (seeded with ``seed``).

        Returns
        -------
        callable or None

        Examples
        --------
        >>> from uio_teach.experiments import PA9
        >>> PA9.measurement_disturbance() is None
        True
        """
        return None

    def observer_state(self, observer: Any) -> np.ndarray | None:
        """Where the observer starts: ``None`` for ``q(0) = 0``.

        Parameters
        ----------
        observer : Observer
            The observer to start.

        Returns
        -------
        numpy.ndarray or None

        Examples
        --------
        >>> from uio_teach.experiments import PA9
        >>> PA9.observer_state(None) is None
        True
        """
        return None

    def simulate(self, observer: Any, **changes: Any) -> UIOResponse:
        """Run ``observer`` on the experiment with :func:`uio_teach.simulate`.

        The known input, the first unknown input, the measurement disturbance,
        the initial state, the observer start, the noise and the seed are the
        experiment's; ``changes`` overrides any keyword of
        :func:`uio_teach.simulate` (``d=``, ``timepts=``, ``noise=``, ...).

        Parameters
        ----------
        observer : Observer
            A designed observer for :meth:`plant`.
        **changes
            Keywords passed on to :func:`uio_teach.simulate` instead of the
            experiment's values.

        Returns
        -------
        UIOResponse

        Examples
        --------
        >>> import uio_teach as ut
        >>> from uio_teach.experiments import CASE_STUDY
        >>> pmo = ut.design_pmo(CASE_STUDY.plant(), method="lmi")
        >>> CASE_STUDY.simulate(pmo).error.shape
        (3, 41)
        """
        unknown = list(self.unknown_inputs.values())
        kwargs: dict[str, Any] = {
            "timepts": self.timepts,
            "u": self.inputs,
            "d": unknown[0] if unknown else None,
            "v": self.measurement_disturbance(),
            "initial_state": self.initial_state,
            "observer_state": (
                changes["observer_state"]
                if "observer_state" in changes
                else self.observer_state(observer)
            ),
            "noise": self.noise,
            "seed": self.seed,
        }
        kwargs.update(changes)
        timepts = kwargs.pop("timepts")
        return simulate(self.plant(), observer, timepts, **kwargs)


@dataclass(frozen=True)
class PA9Experiment(Experiment):
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
    >>> from uio_teach.experiments import PA9
    >>> PA9.d_sine, PA9.d_piecewise
    (1 sin(2 t), piecewise constant (1 from t=0, -1.5 from t=2, 2 from t=5, 0 from t=7.5))
    >>> PA9.inputs
    [1 step(t - 0); 0.5 sin(1 t)]
    """

    sine_amplitude: float = 1.0
    sine_frequency: float = 2.0
    switch_times: tuple[float, ...] = (0.0, 2.0, 5.0, 7.5)
    switch_values: tuple[float, ...] = (1.0, -1.5, 2.0, 0.0)

    def plant(self) -> Plant:
        """The PA9 plant, :func:`uio_teach.examples.pa9`.

        Returns
        -------
        Plant

        Examples
        --------
        >>> from uio_teach.experiments import PA9
        >>> PA9.plant().n
        3
        """
        return examples.pa9()

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


@dataclass(frozen=True)
class CaseStudyExperiment(Experiment):
    """The discrete-time case study: PMO from the LMI, unknown input ``u2``, random staircase ``v``.

    Attributes
    ----------
    u2_amplitude : float
        Amplitude of the unknown state input ``u2[k] = amplitude sin(frequency k)``.
    u2_frequency : float
        Its angular frequency (rad per step).
    v_amplitude : float
        The measurement disturbance ``v`` holds levels drawn uniformly in
        ``[-v_amplitude, v_amplitude]``.
    v_hold : int
        Steps each level of ``v`` is held.

    Examples
    --------
    >>> from uio_teach.experiments import CASE_STUDY
    >>> CASE_STUDY.timepts[-1], CASE_STUDY.poles, CASE_STUDY.u2
    (np.float64(40.0), None, 2 sin(0.6 t))
    """

    u2_amplitude: float = 2.0
    u2_frequency: float = 0.6
    v_amplitude: float = 1.0
    v_hold: int = 5

    def plant(self) -> Plant:
        """The case-study plant, :func:`uio_teach.examples.dt_case_study`.

        Returns
        -------
        Plant

        Examples
        --------
        >>> from uio_teach.experiments import CASE_STUDY
        >>> CASE_STUDY.plant().is_discrete
        True
        """
        return examples.dt_case_study()

    @property
    def u2(self) -> signals.Signal:
        """The unknown state input ``u2`` (the plant's ``d``)."""
        return signals.sinusoid(self.u2_amplitude, self.u2_frequency)

    @property
    def unknown_inputs(self) -> Mapping[str, Callable]:
        """``{"u2": u2}``."""
        return MappingProxyType({"u2": self.u2})

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
        >>> from uio_teach.experiments import CASE_STUDY
        >>> v = CASE_STUDY.measurement_disturbance()
        >>> bool(v(0.0) == v(4.0) != v(5.0))
        True
        """
        t = self.timepts if timepts is None else np.asarray(timepts, dtype=float)
        rng = np.random.default_rng(self.seed if seed is None else seed)
        switch = np.arange(0, t[-1] + 1, self.v_hold)
        levels = rng.uniform(-self.v_amplitude, self.v_amplitude, switch.size)
        return signals.piecewise_constant(switch, levels)


@dataclass(frozen=True)
class MissileExperiment(Experiment):
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
    >>> from uio_teach.experiments import MISSILE
    >>> MISSILE.poles, MISSILE.v
    ((-100.0, -120.0), [10 exp(-2 t) cos(10 t); 50 exp(-5 t) sin(100 t)])
    """

    v_parameters: tuple[tuple[float, float, float, str], ...] = examples.MISSILE_INPUTS

    def plant(self) -> Plant:
        """The missile plant, :func:`uio_teach.examples.missile_autopilot`.

        Returns
        -------
        Plant

        Examples
        --------
        >>> from uio_teach.experiments import MISSILE
        >>> MISSILE.plant().q
        2
        """
        return examples.missile_autopilot()

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
        >>> from uio_teach.experiments import MISSILE
        >>> plant = MISSILE.plant()
        >>> pmo = ut.design_pmo(plant, poles=MISSILE.poles)
        >>> q0 = MISSILE.observer_state(pmo)
        >>> bool(abs(q0 + pmo.M @ plant.C @ MISSILE.initial_state).max() == 0)
        True
        """
        C = self.plant().C
        return -observer.M @ C @ self.initial_state


PA9 = PA9Experiment(
    name="pa9",
    timepts=np.linspace(0.0, 10.0, 2001),
    initial_state=[1.0, -1.0, 0.5],
    poles=(-1.0, -2.0, -3.0),
)
"""The run of Practical Assignment 9.

10 s on 2001 points, ``x(0) = [1, -1, 0.5]``, poles -1, -2, -3.
"""

CASE_STUDY = CaseStudyExperiment(
    name="case-study",
    timepts=np.arange(41.0),
    initial_state=[1.0, -2.0, 3.0],
    poles=None,
    seed=4,
)
"""The run of the case study.

Steps ``k = 0 ... 40``, ``x[0] = [1, -2, 3]``, the LMI gain, seed 4.
"""

MISSILE = MissileExperiment(
    name="missile",
    timepts=np.linspace(0.0, 0.5, 10_001),
    initial_state=examples.MISSILE_PUBLISHED.x0,
    poles=(-100.0, -120.0),
)
"""The run of the missile autopilot.

0.5 s on 10001 points, the paper's ``x0``, PMO poles -100, -120.
"""


LAB_PLANTS: Mapping[str, Callable[[], Plant]] = MappingProxyType(
    {
        "pa9": examples.pa9,
        "case_study": examples.dt_case_study,
        "missile": examples.missile_autopilot,
    }
)
"""The course's plant of each lab (``"pa9"``, ``"case_study"``, ``"missile"``), as a factory."""

_PLANT_MATRICES = ("A", "B", "C", "D", "E")


def plant_from_params(lab: str, params: Mapping[str, Any] | None = None) -> Plant:
    """The plant of a lab: the course's, with the matrices of ``params["plant"]`` in their place.

    A lab notebook's ``PARAMS`` may carry a group's own plant as
    ``PARAMS["plant"] = {"A": [[...]], "E": [[...]], ...}`` (nested lists, as
    JSON keeps them); a matrix that is not given is the course's. Every given
    matrix must have the shape of the course's one (the lab's text and checks
    rely on the sizes n, m, q, p, n_v).

    Parameters
    ----------
    lab : {"pa9", "case_study", "missile"}
        The lab (see :data:`LAB_PLANTS`).
    params : mapping, optional
        The lab's ``PARAMS``; only its ``"plant"`` entry is read. ``None``, or
        no ``"plant"`` entry: the course's plant.

    Returns
    -------
    Plant
        A new plant, with the name, sampling period and sizes of the course's.

    Raises
    ------
    ValueError
        An unknown lab, a ``"plant"`` entry that is not a mapping of the
        names ``A, B, C, D, E``, or a matrix that is not a finite real matrix
        of the course's shape (the message names the matrix and the shape
        expected).

    Examples
    --------
    >>> from uio_teach.experiments import plant_from_params
    >>> plant_from_params("pa9") == plant_from_params("pa9", {"poles": [-1, -2, -3]})
    True
    >>> plant = plant_from_params("pa9", {"plant": {"E": [[1], [0], [2]]}})
    >>> plant.E.ravel().tolist(), plant.A[1].tolist()
    ([1.0, 0.0, 2.0], [-2.0, -3.0, 0.0])
    >>> plant_from_params("pa9", {"plant": {"E": [[1, 0]]}})
    Traceback (most recent call last):
    ...
    ValueError: PARAMS["plant"]["E"] of the pa9 lab has shape (1, 2), expected (3, 1) ...
    """
    if not isinstance(lab, str) or lab not in LAB_PLANTS:
        raise ValueError(f"unknown lab {lab!r}: expected one of {', '.join(LAB_PLANTS)}")
    course = LAB_PLANTS[lab]()
    if params is None:
        return course
    if not isinstance(params, Mapping):
        raise ValueError(f"params of the {lab} lab must be a mapping (PARAMS), got {params!r}")
    given = params.get("plant")
    if given is None:
        return course
    if not isinstance(given, Mapping):
        raise ValueError(
            f'PARAMS["plant"] of the {lab} lab must map matrix names ({", ".join(_PLANT_MATRICES)})'
            f" to nested lists, got {type(given).__name__}"
        )
    unknown = sorted(str(k) for k in given if k not in _PLANT_MATRICES)
    if unknown:
        raise ValueError(
            f'PARAMS["plant"] of the {lab} lab: unknown matrix {", ".join(map(repr, unknown))};'
            f" expected some of {', '.join(_PLANT_MATRICES)}"
        )
    matrices = {name: getattr(course, name) for name in _PLANT_MATRICES}
    for name, value in given.items():
        label = f'PARAMS["plant"]["{name}"]'
        expected = matrices[name].shape
        try:
            arr = as_matrix(label, value)
        except ValueError as err:
            raise ValueError(f"{err} (the {lab} lab)") from None
        if arr.shape != expected:
            raise ValueError(
                f"{label} of the {lab} lab has shape {arr.shape}, expected {expected}"
                f" (the shape of the course's {name})"
            )
        matrices[name] = arr
    return Plant(
        matrices["A"],
        matrices["C"],
        B=matrices["B"],
        E=matrices["E"],
        D=matrices["D"],
        dt=course.dt,
        name=course.name,
    )
