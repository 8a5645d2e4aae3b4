"""The numbers of each lab, as a parameter class: defaults, the term config, one variant per group.

Every lab notebook has one code cell tagged ``parameters`` that defines
``PARAMS``, a JSON-compatible dict; the notebook's code reads its numbers from
it and passes them to the checks. One frozen dataclass per lab turns these
numbers into that dict (``to_params``) and back (``from_params``),
reads them from a term config (``from_config``), draws a variant for a
lab group (``draw``) and computes the answer key (``answers``).

* :class:`PA9Params` -- poles, initial state, the sinusoidal and the
  piecewise-constant disturbance of Practical Assignment 9;
* :class:`CaseStudyParams` -- the movable pole, the unknown input ``u2``,
  the staircase ``v`` and its seed, the initial state of the case study;
* :class:`MissileParams` -- the PMO poles, the noise level and its seed of
  the missile lab (the paper's matrices, ``x0`` and ``v`` stay).

The defaults are the worked experiments of :mod:`uio_teach.experiments`.

Examples
--------
>>> from uio_teach.instructor.lab_params import PA9Params
>>> PA9Params().to_params()["poles"]
[-1.0, -2.0, -3.0]
>>> PA9Params.from_params(PA9Params().to_params()) == PA9Params()
True
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any, ClassVar

import numpy as np

from ..experiments import CASE_STUDY, MISSILE, PA9

__all__ = ["PA9Params", "CaseStudyParams", "MissileParams", "LabParams", "pole_text"]


def pole_text(p: complex) -> float | str:
    """A pole for ``PARAMS``: a float if real, else a string such as ``"-1+2j"``.

    Parameters
    ----------
    p : complex

    Returns
    -------
    float or str

    Examples
    --------
    >>> from uio_teach.instructor.lab_params import pole_text
    >>> pole_text(-2), pole_text(complex(-1, 2))
    (-2.0, '-1+2j')
    """
    z = complex(p)
    if z.imag == 0:
        return float(z.real) + 0.0
    return f"{z.real:g}{z.imag:+g}j"


def _pole(value: Any) -> complex | float:
    z = complex(value.replace(" ", "")) if isinstance(value, str) else complex(value)
    return z if z.imag else float(z.real)


def _floats(values: Any) -> tuple[float, ...]:
    return tuple(float(v) + 0.0 for v in values)


def _key(x: Any, digits: int = 10) -> Any:
    """Numbers of an answer key as JSON-compatible lists, rounded (no ``-0.0``)."""
    arr = np.asarray(x)
    if np.iscomplexobj(arr):
        if np.all(arr.imag == 0):
            arr = arr.real
        else:
            return [pole_text(complex(round(z.real, digits), round(z.imag, digits))) for z in arr]
    return (np.round(np.asarray(arr, float), digits) + 0.0).tolist()


class LabParams:
    """What the three parameter classes share (see the module's docstring)."""

    lab: ClassVar[str] = ""

    def to_params(self) -> dict[str, Any]:  # pragma: no cover - every lab defines it
        raise NotImplementedError

    @classmethod
    def from_params(cls, params: Mapping[str, Any]) -> LabParams:  # pragma: no cover
        raise NotImplementedError


# Practical Assignment 9 ----------------------------------------------------------------------


@dataclass(frozen=True)
class PA9Params(LabParams):
    """The numbers of the PA9 lab.

    Attributes
    ----------
    poles : tuple
        The observer poles (three; complex ones in conjugate pairs).
    initial_state : tuple of float
        ``x(0)``.
    sine_amplitude : float
        The amplitude of ``d(t) = amplitude sin(frequency t)``.
    sine_frequency : float
        Its frequency, in rad/s.
    switch_times : tuple of float
        The times at which the piecewise-constant ``d`` switches.
    switch_values : tuple of float
        The values it takes.
    duration : float
        Simulated time in s.
    samples : int
        Number of time points.

    Examples
    --------
    >>> from uio_teach.instructor.lab_params import PA9Params
    >>> PA9Params().to_params()["sine"]
    {'amplitude': 1.0, 'frequency': 2.0}
    """

    lab: ClassVar[str] = "pa9"

    poles: tuple = tuple(PA9.poles)
    initial_state: tuple[float, ...] = _floats(PA9.initial_state)
    sine_amplitude: float = PA9.sine_amplitude
    sine_frequency: float = PA9.sine_frequency
    switch_times: tuple[float, ...] = _floats(PA9.switch_times)
    switch_values: tuple[float, ...] = _floats(PA9.switch_values)
    duration: float = PA9.duration
    samples: int = int(PA9.timepts.size)

    def to_params(self) -> dict[str, Any]:
        """``PARAMS`` of the notebook (a JSON-compatible dict)."""
        return {
            "poles": [pole_text(p) for p in self.poles],
            "initial_state": list(_floats(self.initial_state)),
            "sine": {
                "amplitude": float(self.sine_amplitude),
                "frequency": float(self.sine_frequency),
            },
            "piecewise": {
                "times": list(_floats(self.switch_times)),
                "values": list(_floats(self.switch_values)),
            },
            "duration": float(self.duration),
            "samples": int(self.samples),
        }

    @classmethod
    def from_params(cls, params: Mapping[str, Any]) -> PA9Params:
        """The parameters of a ``PARAMS`` dict (the inverse of :meth:`to_params`)."""
        return cls(
            poles=tuple(_pole(p) for p in params["poles"]),
            initial_state=_floats(params["initial_state"]),
            sine_amplitude=float(params["sine"]["amplitude"]),
            sine_frequency=float(params["sine"]["frequency"]),
            switch_times=_floats(params["piecewise"]["times"]),
            switch_values=_floats(params["piecewise"]["values"]),
            duration=float(params["duration"]),
            samples=int(params["samples"]),
        )

    @classmethod
    def from_config(cls, config: Mapping[str, Any] | None) -> PA9Params:
        """The parameters of a term config (:func:`uio_teach.instructor.config.load_config`)."""
        if config is None:
            return cls()
        return cls(
            poles=tuple(_pole(p) for p in config["pa9.poles"]),
            initial_state=_floats(config["pa9.initial_state"]),
            sine_amplitude=float(config["pa9.sine.amplitude"]),
            sine_frequency=float(config["pa9.sine.frequency"]),
            switch_times=_floats(config["pa9.piecewise.times"]),
            switch_values=_floats(config["pa9.piecewise.values"]),
            duration=float(config["pa9.duration"]),
            samples=int(config["pa9.samples"]),
        )

    @classmethod
    def draw(cls, rng: np.random.Generator, base: PA9Params | None = None) -> PA9Params:
        """A variant for one group: three distinct real poles in [-5, -1], new disturbances.

        Every variant is solvable in the same way: the plant (and so the UIO) is
        the assignment's, the poles are distinct, stable and at least 0.5 apart
        (the error decays to 1 % within the 10 s), the disturbances have
        amplitudes of at least 0.5 and the piecewise-constant one jumps three
        times, at least 1 s apart.
        """
        base = base or cls()
        grid = np.arange(-5.0, -0.99, 0.5)
        poles = tuple(sorted((float(p) for p in rng.choice(grid, 3, replace=False)), reverse=True))
        levels = [-2.0, -1.5, -1.0, -0.5, 0.5, 1.0, 1.5, 2.0]
        x0 = tuple(float(v) for v in rng.choice([-1.5, -1.0, -0.5, 0.5, 1.0, 1.5], 3))
        while True:
            t = np.sort(rng.choice(np.arange(1.0, 9.0, 0.5), 3, replace=False))
            if np.all(np.diff(t) >= 1.0):
                break
        values = [float(rng.choice(levels))]
        while len(values) < 4:
            v = float(rng.choice(levels))
            if abs(v - values[-1]) >= 0.5:
                values.append(v)
        return cls(
            poles=poles,
            initial_state=x0,
            sine_amplitude=float(rng.choice([0.5, 1.0, 1.5, 2.0])),
            sine_frequency=float(rng.choice([1.0, 1.5, 2.0, 2.5, 3.0])),
            switch_times=(0.0, *(float(x) for x in t)),
            switch_values=tuple(values),
            duration=base.duration,
            samples=base.samples,
        )

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
        return out

    def answers(self) -> dict[str, Any]:
        """The answer key: ``H``, ``T``, ``K1`` (python-control's placement), ``F``, ``K2``."""
        import control as ct

        from .. import examples

        plant = examples.pa9()
        A, C, E = plant.A, plant.C, plant.E
        H = E @ np.linalg.pinv(C @ E)
        T = np.eye(plant.n) - H @ C
        K1 = ct.place((T @ A).T, C.T, [complex(p) for p in self.poles]).T
        F = T @ A - K1 @ C
        return {
            "H": _key(H),
            "T": _key(T),
            "K1": _key(K1),
            "F": _key(F),
            "K2": _key(F @ H),
            "error_poles": _key(np.sort_complex(np.linalg.eigvals(F))),
        }


# The discrete-time case study ------------------------------------------------------------------


@dataclass(frozen=True)
class CaseStudyParams(LabParams):
    """The numbers of the case-study lab.

    Attributes
    ----------
    pole : float
        Where exercise 3 moves the one movable pole (inside the unit circle).
    initial_state : tuple of float
        ``x[0]``.
    u2_amplitude : float
        The amplitude of ``u2[k] = amplitude sin(frequency k)``.
    u2_frequency : float
        Its frequency, in rad per step.
    v_amplitude : float
        The staircase ``v`` holds levels uniform in ``[-amplitude, amplitude]``.
    v_hold : int
        Steps each level is held.
    seed : int
        Seed of the levels of ``v``.
    steps : int
        The simulation runs over ``k = 0 ... steps``.

    Examples
    --------
    >>> from uio_teach.instructor.lab_params import CaseStudyParams
    >>> CaseStudyParams().to_params()["v"]
    {'amplitude': 1.0, 'hold': 5, 'seed': 4}
    """

    lab: ClassVar[str] = "case_study"

    pole: float = 0.3
    initial_state: tuple[float, ...] = _floats(CASE_STUDY.initial_state)
    u2_amplitude: float = CASE_STUDY.u2_amplitude
    u2_frequency: float = CASE_STUDY.u2_frequency
    v_amplitude: float = CASE_STUDY.v_amplitude
    v_hold: int = CASE_STUDY.v_hold
    seed: int = int(CASE_STUDY.seed or 0)
    steps: int = int(CASE_STUDY.duration)

    def to_params(self) -> dict[str, Any]:
        """``PARAMS`` of the notebook (a JSON-compatible dict)."""
        return {
            "pole": float(self.pole) + 0.0,
            "initial_state": list(_floats(self.initial_state)),
            "u2": {"amplitude": float(self.u2_amplitude), "frequency": float(self.u2_frequency)},
            "v": {
                "amplitude": float(self.v_amplitude),
                "hold": int(self.v_hold),
                "seed": int(self.seed),
            },
            "steps": int(self.steps),
        }

    @classmethod
    def from_params(cls, params: Mapping[str, Any]) -> CaseStudyParams:
        """The parameters of a ``PARAMS`` dict (the inverse of :meth:`to_params`)."""
        return cls(
            pole=float(params["pole"]),
            initial_state=_floats(params["initial_state"]),
            u2_amplitude=float(params["u2"]["amplitude"]),
            u2_frequency=float(params["u2"]["frequency"]),
            v_amplitude=float(params["v"]["amplitude"]),
            v_hold=int(params["v"]["hold"]),
            seed=int(params["v"]["seed"]),
            steps=int(params["steps"]),
        )

    @classmethod
    def from_config(cls, config: Mapping[str, Any] | None) -> CaseStudyParams:
        """The parameters of a term config (``case_study.*`` and ``seed``)."""
        if config is None:
            return cls()
        poles = config["case_study.poles"]
        return cls(
            pole=float(complex(poles[0]).real) if poles else cls.pole,
            initial_state=_floats(config["case_study.initial_state"]),
            u2_amplitude=float(config["case_study.u2.amplitude"]),
            u2_frequency=float(config["case_study.u2.frequency"]),
            v_amplitude=float(config["case_study.v.amplitude"]),
            v_hold=int(config["case_study.v.hold"]),
            seed=int(config["seed"]),
            steps=int(config["case_study.steps"]),
        )

    @classmethod
    def draw(cls, rng: np.random.Generator, base: CaseStudyParams | None = None) -> CaseStudyParams:
        """A variant for one group: the movable pole, ``u2``, ``v`` and ``x[0]`` redrawn.

        The pole lies in [-0.6, 0.3], at least 0.2 from the fixed poles 0.5; the
        unknown inputs have amplitudes of at least 0.5; ``x[0]`` has integer
        entries and a nonzero initial error ``(I - MC) x[0]``.
        """
        base = base or cls()
        from .. import examples

        plant = examples.dt_case_study()
        C, B2, D = plant.C, plant.E, plant.D
        M = np.hstack([B2, np.zeros((plant.n, D.shape[1]))]) @ np.linalg.pinv(
            np.hstack([C @ B2, D])
        )
        Pi = np.eye(plant.n) - M @ C
        while True:
            x0 = rng.choice([-3.0, -2.0, -1.0, 1.0, 2.0, 3.0], 3)
            if np.linalg.norm(Pi @ x0) > 0.5:
                break
        return cls(
            pole=float(rng.choice([-0.6, -0.4, -0.2, 0.0, 0.2, 0.3])),
            initial_state=tuple(float(v) for v in x0),
            u2_amplitude=float(rng.choice([1.0, 1.5, 2.0, 2.5, 3.0])),
            u2_frequency=float(rng.choice([0.3, 0.4, 0.5, 0.6, 0.7, 0.8])),
            v_amplitude=float(rng.choice([0.5, 1.0, 1.5])),
            v_hold=int(rng.choice([3, 4, 5, 6])),
            seed=int(rng.integers(1, 1000)),
            steps=base.steps,
        )

    def problems(self) -> list[str]:
        """Why this variant would not be a fair exercise (empty: it is)."""
        out = []
        if not abs(self.pole) < 1:
            out.append("the movable pole must lie inside the unit circle")
        if abs(self.pole - 0.5) < 0.1:
            out.append("the movable pole must differ from the fixed poles 0.5")
        if abs(self.u2_amplitude) < 0.1 or self.v_amplitude < 0.1:
            out.append("the unknown inputs must be visible")
        if self.steps < 20:
            out.append("the simulation is too short to see the error decay")
        if self.seed < 0 or self.v_hold < 1:
            out.append("the seed of v must be >= 0 and its hold at least one step")
        return out

    def answers(self) -> dict[str, Any]:
        """The answer key: ``M``, ``A1``, the gain ``L`` that moves the pole, the error poles."""
        from .. import examples
        from ..observers import design_pmo

        plant = examples.dt_case_study()
        C, B2, D, A = plant.C, plant.E, plant.D, plant.A
        M = np.hstack([B2, np.zeros((plant.n, D.shape[1]))]) @ np.linalg.pinv(
            np.hstack([C @ B2, D])
        )
        A1 = (np.eye(plant.n) - M @ C) @ A
        placed = design_pmo(plant, poles=[self.pole])
        return {
            "M": _key(M),
            "A1": _key(A1),
            "L_pole": _key(placed.L),
            "error_poles": _key(np.sort(placed.poles().real)),
            "e0": _key((np.eye(plant.n) - M @ C) @ np.asarray(self.initial_state)),
        }


# The missile autopilot ---------------------------------------------------------------------------


@dataclass(frozen=True)
class MissileParams(LabParams):
    """The numbers of the missile lab (the paper's matrices, ``x0`` and ``v`` are fixed).

    Attributes
    ----------
    pmo_poles : tuple of float
        The two movable PMO poles (rad/s).
    noise : float
        Standard deviation of the measurement noise of the last exercise.
    seed : int
        Seed of that noise.
    duration : float
        Simulated time in s (Table II is read over this window).
    samples : int
        Number of time points.
    tol : float
        The band of the catch times, relative to each signal's peak.

    Examples
    --------
    >>> from uio_teach.instructor.lab_params import MissileParams
    >>> MissileParams().to_params()["pmo_poles"]
    [-100.0, -120.0]
    """

    lab: ClassVar[str] = "missile"

    pmo_poles: tuple[float, ...] = _floats(np.real(MISSILE.poles))
    noise: float = 0.01
    seed: int = 7
    duration: float = MISSILE.duration
    samples: int = int(MISSILE.timepts.size)
    tol: float = 0.02

    def to_params(self) -> dict[str, Any]:
        """``PARAMS`` of the notebook (a JSON-compatible dict)."""
        return {
            "pmo_poles": [pole_text(p) for p in self.pmo_poles],
            "noise": {"sigma": float(self.noise), "seed": int(self.seed)},
            "duration": float(self.duration),
            "samples": int(self.samples),
            "tol": float(self.tol),
        }

    @classmethod
    def from_params(cls, params: Mapping[str, Any]) -> MissileParams:
        """The parameters of a ``PARAMS`` dict (the inverse of :meth:`to_params`)."""
        return cls(
            pmo_poles=tuple(_pole(p) for p in params["pmo_poles"]),
            noise=float(params["noise"]["sigma"]),
            seed=int(params["noise"]["seed"]),
            duration=float(params["duration"]),
            samples=int(params["samples"]),
            tol=float(params["tol"]),
        )

    @classmethod
    def from_config(cls, config: Mapping[str, Any] | None) -> MissileParams:
        """The parameters of a term config (``missile.pmo_poles``; the rest as the chapter)."""
        if config is None:
            return cls()
        return cls(pmo_poles=tuple(_pole(p) for p in config["missile.pmo_poles"]))

    @classmethod
    def draw(cls, rng: np.random.Generator, base: MissileParams | None = None) -> MissileParams:
        """A variant for one group: two PMO poles in [-160, -80], 20 apart; noise and seed.

        The poles stay in the range of the fixed pair (about 177 rad/s in
        magnitude), so every variant converges within the 0.5 s window.
        """
        base = base or cls()
        while True:
            a, b = sorted(rng.choice(np.arange(-160.0, -79.0, 10.0), 2, replace=False))
            if b - a >= 20:
                break
        return cls(
            pmo_poles=(float(b), float(a)),
            noise=float(rng.choice([0.005, 0.01, 0.02])),
            seed=int(rng.integers(1, 1000)),
            duration=base.duration,
            samples=base.samples,
            tol=base.tol,
        )

    def problems(self) -> list[str]:
        """Why this variant would not be a fair exercise (empty: it is)."""
        out = []
        poles = np.array([complex(p) for p in self.pmo_poles])
        if poles.size != 2 or len(set(poles.tolist())) != 2:
            out.append("the two PMO poles must be distinct")
        if np.any(poles.real >= -10):
            out.append("the PMO poles must be stable and fast enough for the 0.5 s window")
        if self.noise <= 0:
            out.append("the noise exercise needs a positive noise level")
        if self.seed < 0:
            out.append("the seed of the noise must be >= 0")
        return out

    def answers(self) -> dict[str, Any]:
        """The answer key: ``M``, ``L``, ``Cg``, ``Pc``, ``K`` and the predicted noise RMS."""
        from .. import examples
        from ..observers import design_pmo

        plant = examples.missile_autopilot()
        A, C, E = plant.A, plant.C, plant.E
        Mv = examples.MISSILE_PUBLISHED.Mv
        CE = C @ E
        CEg = np.linalg.pinv(CE)
        M = E @ CEg + Mv @ (np.eye(plant.p) - CE @ CEg)
        pmo = design_pmo(plant, poles=[complex(p) for p in self.pmo_poles], Mv=Mv)
        Cg = np.linalg.pinv(C)
        Pc = np.eye(plant.n) - Cg @ C
        h = self.duration / (self.samples - 1)
        rho = np.linalg.norm(np.linalg.inv(CE), axis=1)
        del A
        return {
            "M": _key(M),
            "L": _key(pmo.L),
            "Cg": _key(Cg),
            "Pc": _key(Pc),
            "K": _key(Pc @ E @ CEg),
            "error_poles": _key(np.sort_complex(pmo.poles())),
            "noise_rms_predicted": _key(self.noise / (math.sqrt(2) * h) * rho, 6),
        }


def params_dict(params: LabParams) -> dict[str, Any]:
    """The dataclass fields of ``params`` (for messages and tests)."""
    return asdict(params)  # type: ignore[call-overload]
