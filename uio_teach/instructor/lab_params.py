"""The numbers of each lab, as a parameter class: defaults, the term config, one variant per group.

Every lab notebook has one code cell tagged ``parameters`` that defines
``PARAMS``, a JSON-compatible dict; the notebook's code reads its numbers from
it and passes them to the checks. One frozen dataclass per lab turns these
numbers into that dict (``to_params``) and back (``from_params``), reads them
from a term config (``from_config``), draws a variant for a lab group
(``draw``) and computes the answer key (``answers``).

The fields of each class are not written here: they are the fields of the
lab's experiment (:mod:`uio_teach.experiments`) declared with ``lab=True``,
with the experiment's values as defaults, their place in ``PARAMS`` and their
config key from the same declaration (``lab_params_of``). Only what is
particular to a lab is written here: how a group's variant is drawn, when a
variant is a fair exercise, and the answer key.

* :class:`PA9Params` -- the plant (``A``, ``E``), poles, initial state, the
  sinusoidal and the piecewise-constant disturbance of Practical Assignment 9;
* :class:`CaseStudyParams` -- the plant (``B2``, ``D``), the movable
  pole, the unknown input ``u2``, the staircase ``v`` and its seed, the
  initial state of the case study;
* :class:`MissileParams` -- the plant (``A``, ``B``, ``C``, ``E``), the PMO
  poles, the noise level and its seed of the missile lab (the paper's ``x0``
  and ``v`` stay).

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
import os
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any, ClassVar

import control as ct
import numpy as np

from ..examples import MISSILE_PUBLISHED
from ..existence import check_existence, decoupling
from ..experiments import (
    CASE_STUDY,
    MISSILE,
    PA9,
    Experiment,
    Param,
    experiment_params,
    plant_from_params,
    pole_text,
)
from ..observers import design_pmo
from ..plant import Plant
from ..reconstruction import catch_time, reconstruct_input

__all__ = [
    "PA9Params",
    "CaseStudyParams",
    "MissileParams",
    "LabParams",
    "lab_params_of",
    "pole_text",
    "params_dict",
    "MIN_INITIAL_ERROR",
]

MIN_INITIAL_ERROR = 0.25
"""The least largest entry of a group's initial estimation error e(0) (from z(0) = 0).

A drawn initial state whose error starts smaller (for PA9, an ``x(0)`` along
``E``, which ``T`` annuls) is drawn again: the exercises watch the error decay."""


def _pole(value: Any) -> complex | float:
    z = complex(value.replace(" ", "")) if isinstance(value, str) else complex(value)
    return z if z.imag else float(z.real)


def _floats(values: Any) -> tuple[float, ...]:
    return tuple(float(v) + 0.0 for v in np.asarray(values, dtype=float).ravel())


def _key(x: Any, digits: int = 10) -> Any:
    """Numbers of an answer key as JSON-compatible lists, rounded (no ``-0.0``)."""
    arr = np.asarray(x)
    if np.iscomplexobj(arr):
        if np.all(arr.imag == 0):
            arr = arr.real
        else:
            return [pole_text(complex(round(z.real, digits), round(z.imag, digits))) for z in arr]
    return (np.round(np.asarray(arr, float), digits) + 0.0).tolist()


def _style_rc(path: str) -> tuple[tuple[str, str], ...]:
    """The settings of a ``.mplstyle`` file as ``(key, value)`` strings (for a notebook)."""
    out = []
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        line = line.split("#", 1)[0].strip()
        if ":" in line:
            key, value = (part.strip() for part in line.split(":", 1))
            out.append((key, value.strip("'\"")))
    return tuple(out)


# one value: lab form (in the dataclass) <-> PARAMS (JSON) <-> term config ----------------------


def _lab_value(spec: Param, value: Any) -> Any:
    """A value of the experiment, the config or ``PARAMS`` as the parameter class keeps it."""
    if value is None:
        return None
    kind = spec.kind
    if kind == "int":
        return int(value)
    if kind == "float":
        return float(value) + 0.0
    if kind == "floats":
        return _floats(value)
    if kind == "poles":
        return tuple(_pole(p) for p in value)
    if kind == "matrices":
        items = value.items() if isinstance(value, Mapping) else value
        return tuple(
            sorted(
                (str(name), tuple(_floats(row) for row in np.atleast_2d(np.asarray(m, float))))
                for name, m in items
            )
        )
    if kind == "style":
        if isinstance(value, Mapping):
            return tuple(sorted((str(k), str(v)) for k, v in value.items()))
        if isinstance(value, (tuple, list)):
            return tuple((str(k), str(v)) for k, v in value)
        if os.path.isfile(str(value)):
            return _style_rc(str(value))
        return str(value)
    return value


def _json_value(spec: Param, value: Any) -> Any:
    """A value of the parameter class as ``PARAMS`` holds it (JSON)."""
    kind = spec.kind
    if value is None:
        return None
    if kind == "poles":
        return [pole_text(p) for p in value]
    if kind == "floats":
        return list(_floats(value))
    if kind == "matrices":
        return {name: [list(row) for row in rows] for name, rows in value}
    if kind == "style" and not isinstance(value, str):
        return dict(value)
    if kind == "int":
        return int(value)
    if kind == "float":
        return float(value) + 0.0
    return value


def _get(params: Mapping[str, Any], path: str) -> Any:
    node: Any = params
    for part in path.split("."):
        if not isinstance(node, Mapping) or part not in node:
            raise KeyError(path)
        node = node[part]
    return node


def _put(params: dict[str, Any], path: str, value: Any) -> None:
    *tables, last = path.split(".")
    node = params
    for part in tables:
        node = node.setdefault(part, {})
    node[last] = value


class LabParams:
    """What the three parameter classes share (see the module's docstring).

    The fields come from the lab's experiment (``lab_params_of``);
    ``to_params``, ``from_params``, ``from_config`` and :meth:`plant` read
    the declarations, so they need no change when a field is added.
    """

    lab: ClassVar[str] = ""
    experiment: ClassVar[Experiment]

    @classmethod
    def declared(cls) -> tuple[tuple[str, Param], ...]:
        """The fields of the lab (name and declaration), in the experiment's order."""
        return tuple((n, s) for n, s in experiment_params(cls.experiment) if s.lab)

    def to_params(self) -> dict[str, Any]:
        """``PARAMS`` of the notebook (a JSON-compatible dict)."""
        out: dict[str, Any] = {}
        defaults = type(self)()
        for name, spec in self.declared():
            value = getattr(self, name)
            if spec.omit_default and value == getattr(defaults, name):
                continue
            if value is None and spec.optional:
                continue
            _put(out, spec.key or name, _json_value(spec, value))
        return out

    @classmethod
    def from_params(cls, params: Mapping[str, Any]) -> LabParams:
        """The parameters of a ``PARAMS`` dict (the inverse of :meth:`to_params`)."""
        kwargs = {}
        for name, spec in cls.declared():
            try:
                value = _get(params, spec.key or name)
            except KeyError:
                if spec.omit_default or spec.optional:
                    continue
                raise
            kwargs[name] = _lab_value(spec, value)
        return cls(**kwargs)

    @classmethod
    def from_config(cls, config: Mapping[str, Any] | None) -> LabParams:
        """The parameters of a term config (:func:`uio_teach.instructor.config.load_config`).

        Every field with a config key takes the config's value (the defaults
        are the same experiments, so a config with no key gives the defaults).
        """
        if config is None:
            return cls()
        kwargs = {}
        for name, spec in cls.declared():
            key = spec.config_key(cls.lab, name)
            if key is not None and key in config and config[key] is not None:
                kwargs[name] = _lab_value(spec, config[key])
        return cls(**kwargs)

    def plant(self) -> Plant:
        """The plant of this variant (:func:`uio_teach.experiments.plant_from_params`)."""
        return plant_from_params(self.lab, self.to_params())

    def run(self) -> Experiment:
        """The lab's experiment with this variant's values (for simulations)."""
        values = {name: getattr(self, name) for name, _ in self.declared() if name != "duration"}
        values["matrices"] = dict(getattr(self, "matrices", ()) or ())
        return self.experiment.with_values(duration=getattr(self, "duration", None), **values)

    def distinct(self) -> dict[str, Any]:
        """What no two groups may share (hashable values by name); see :meth:`draw`."""
        return {}


def lab_params_of(experiment: Experiment, lab: str | None = None) -> Callable[[type], type]:
    """Make a class the parameter class of ``experiment``'s lab: its fields are the lab fields.

    Every field of the experiment declared with ``lab=True`` becomes a field
    of the (frozen) dataclass, with the experiment's value as default.

    Parameters
    ----------
    experiment : Experiment
        The lab's experiment (its values are the defaults).
    lab : str, optional
        The lab's id (default: ``experiment.lab``).

    Returns
    -------
    callable
        The class decorator.

    Examples
    --------
    >>> import dataclasses
    >>> from uio_teach.experiments import PA9, PA9Experiment, param
    >>> from uio_teach.instructor.lab_params import PA9Params, lab_params_of
    >>> @dataclasses.dataclass(frozen=True)
    ... class Louder(PA9Experiment):
    ...     loudness: float = param(3.0, "float", "how loud", key="sine.loudness")
    >>> @lab_params_of(Louder(name="pa9", timepts=PA9.timepts))
    ... class LouderParams(PA9Params):
    ...     pass
    >>> LouderParams().to_params()["sine"]
    {'amplitude': 1.0, 'frequency': 2.0, 'loudness': 3.0}
    """

    def decorate(cls: type) -> type:
        annotations = dict(cls.__dict__.get("__annotations__", {}))
        for name, spec in experiment_params(experiment):
            if not spec.lab:
                continue
            annotations[name] = "Any"
            setattr(cls, name, _lab_value(spec, getattr(experiment, name)))
        cls.__annotations__ = annotations
        cls.experiment = experiment
        cls.lab = lab or experiment.lab
        return dataclass(frozen=True)(cls)

    return decorate


def _choice(rng: np.random.Generator, values: Any) -> float:
    return float(rng.choice(np.asarray(values, dtype=float)))


def _direction(v: Any) -> tuple[float, ...]:
    """A vector's direction as a hashable key: unit length, first nonzero entry positive."""
    v = np.asarray(v, dtype=float).ravel()
    v = v / np.linalg.norm(v)
    first = v[np.flatnonzero(np.abs(v) > 1e-12)[0]]
    return tuple(np.round(v * np.sign(first), 9) + 0.0)


def _subspace(X: Any) -> tuple[float, ...]:
    """The column space of ``X`` as a hashable key (its orthogonal projector, rounded)."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    Q, _ = np.linalg.qr(X)
    return tuple(np.round(Q @ Q.T, 9).ravel() + 0.0)


# Practical Assignment 9 ----------------------------------------------------------------------


@lab_params_of(PA9)
class PA9Params(LabParams):
    """The numbers of the PA9 lab (the fields of :data:`uio_teach.experiments.PA9` for the lab).

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
    >>> from uio_teach.instructor.lab_params import PA9Params
    >>> PA9Params().to_params()["sine"]
    {'amplitude': 1.0, 'frequency': 2.0}
    """

    @classmethod
    def draw(cls, rng: np.random.Generator, base: PA9Params | None = None) -> PA9Params:
        """A variant for one group: the plant's ``A`` and ``E``, poles, ``x(0)``, disturbances.

        ``A`` keeps the assignment's structure (a second-order block and a
        first-order state, all stable: ``[[0, 1, 0], [-a0, -a1, 0], [0, 0, -a2]]``)
        and ``E`` a column of half-integers, so that ``H``, ``T``, ``K1``,
        ``F`` and ``K2`` differ between groups; :meth:`problems` makes sure
        that the UIO exists with all three poles movable. The poles are
        distinct, in [-6, -1] and at least 0.5 apart (the error decays to 1 %
        within the 10 s), the disturbances have amplitudes of at least 0.5 and
        the piecewise-constant one jumps three times, at least 1 s apart.
        """
        base = base or cls()
        a0, a1, a2 = (
            _choice(rng, [1.0, 2.0, 3.0, 4.0, 5.0]),
            _choice(rng, [2.0, 3.0, 4.0, 5.0]),
            _choice(rng, [1.0, 1.5, 2.0, 3.0]),
        )
        A = [[0.0, 1.0, 0.0], [-a0, -a1, 0.0], [0.0, 0.0, -a2]]
        E = [
            [_choice(rng, [0.5, 1.0, 1.5, 2.0, 2.5, 3.0])],
            [_choice(rng, [-1.0, -0.5, 0.0, 0.5, 1.0])],
            [_choice(rng, [-1.5, -1.0, -0.5, 0.5, 1.0, 1.5])],
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
        return cls(
            poles=poles,
            initial_state=x0,
            noise=base.noise,
            seed=base.seed,
            duration=base.duration,
            samples=base.samples,
            style=base.style,
            matrices=_lab_value(dict(experiment_params(PA9))["matrices"], {"A": A, "E": E}),
            sine_amplitude=_choice(rng, [0.5, 1.0, 1.5, 2.0]),
            sine_frequency=_choice(rng, [1.0, 1.5, 2.0, 2.5, 3.0]),
            switch_times=(0.0, *(float(x) for x in t)),
            switch_values=tuple(values),
        )

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
            "plant": (_direction(plant.E), tuple(plant.A.ravel())),
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


@lab_params_of(CASE_STUDY)
class CaseStudyParams(LabParams):
    """The numbers of the case-study lab (the fields of :data:`~uio_teach.experiments.CASE_STUDY`).

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
    u2_amplitude : float
        The amplitude of ``u2[k] = amplitude sin(frequency k)``.
    u2_frequency : float
        Its frequency, in rad per step.
    v_amplitude : float
        The staircase ``v`` holds levels uniform in ``[-amplitude, amplitude]``.
    v_hold : int
        Steps each level is held.

    Examples
    --------
    >>> from uio_teach.instructor.lab_params import CaseStudyParams
    >>> CaseStudyParams().to_params()["v"]
    {'seed': 4, 'amplitude': 1.0, 'hold': 5}
    """

    @classmethod
    def from_config(cls, config: Mapping[str, Any] | None) -> CaseStudyParams:
        """As ``LabParams.from_config``; ``case_study.poles``, if given, sets ``pole``."""
        params = super().from_config(config)
        poles = None if config is None else config.get("case_study.poles")
        if poles:
            return type(params)(**{**_fields(params), "pole": float(complex(poles[0]).real)})
        return params

    @classmethod
    def draw(cls, rng: np.random.Generator, base: CaseStudyParams | None = None) -> CaseStudyParams:
        """A variant for one group: the plant's ``B2`` and ``D``; pole, ``u2``, ``v``, ``x[0]``.

        ``A = 0.5 I`` stays (so the two fixed modes stay at 0.5, as the chapter
        tells), ``B2`` is a column of small integers and ``D = [1, d]^T`` or
        ``[d, 1]^T`` (``d`` a multiple of 0.05): ``M``, ``A1``, the LMI's ``L``
        (``L D = 0``) and the moved pole's gain differ between groups;
        :meth:`problems` makes sure that ``M`` exists, the two fixed modes are
        stable and the LMI is feasible. The pole lies in [-0.6, 0.3], at least
        0.1 from the fixed modes and from the eigenvalues of ``A1`` (moving it
        takes a gain; a term's own pole must be 0.05 from them); the unknown
        inputs have amplitudes of at least 0.5; ``x[0]`` has integer entries
        and a nonzero initial error ``(I - MC) x[0]``.
        """
        base = base or cls()
        B2 = [[_choice(rng, [1.0, 2.0])], *([_choice(rng, [-1.0, 1.0, 2.0])] for _ in range(2))]
        d = _choice(rng, [x for x in np.round(np.arange(-0.95, 0.96, 0.05), 2) if abs(x) > 0.01])
        D = [[1.0], [d]] if rng.integers(2) else [[d], [1.0]]
        matrices = {"E": B2, "D": D}
        plant = plant_from_params("case_study", {"plant": matrices})
        M = decoupling(plant).M
        Pi = np.eye(plant.n) - M @ plant.C
        for _ in range(100):
            x0 = rng.choice([-3.0, -2.0, -1.0, 1.0, 2.0, 3.0], 3)
            if np.max(np.abs(Pi @ x0)) >= MIN_INITIAL_ERROR:
                break
        return cls(
            initial_state=tuple(float(v) for v in x0),
            seed=int(rng.integers(1, 1000)),
            duration=base.duration,
            style=base.style,
            matrices=_lab_value(dict(experiment_params(CASE_STUDY))["matrices"], matrices),
            pole=_choice(rng, [-0.6, -0.4, -0.3, -0.2, 0.1, 0.2, 0.3]),
            u2_amplitude=_choice(rng, [1.0, 1.5, 2.0, 2.5, 3.0]),
            u2_frequency=_choice(rng, [0.3, 0.4, 0.5, 0.6, 0.7, 0.8]),
            v_amplitude=_choice(rng, [0.5, 1.0, 1.5]),
            v_hold=int(rng.choice([3, 4, 5, 6])),
        )

    def distinct(self) -> dict[str, Any]:
        """The direction of ``D``: no ``M D = 0`` or ``L D = 0`` holds for two groups."""
        plant = self.plant()
        return {"D": _direction(plant.D)}

    def fixed_modes(self) -> np.ndarray:
        """The two error modes no gain with ``L D = 0`` moves (the invariant zeros)."""
        return np.sort_complex(check_existence(self.plant()).fixed_modes)

    def problems(self) -> list[str]:
        """Why this variant would not be a fair exercise (empty: it is)."""
        out = []
        if not abs(self.pole) < 1:
            out.append("the movable pole must lie inside the unit circle")
        if abs(self.u2_amplitude) < 0.1 or self.v_amplitude < 0.1:
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
            if np.max(np.abs(pmo.L @ plant.D)) > 1e-6 or np.max(np.abs(pmo.poles())) >= 1:
                out.append("the LMI gain must satisfy L D = 0 and be stable")
        return out

    def answers(self) -> dict[str, Any]:
        """The answer key: ``M``, ``A1``, the gain ``L`` that moves the pole, the error poles."""
        plant = self.plant()
        dec = decoupling(plant)
        placed = design_pmo(plant, poles=[self.pole])
        return {
            "M": _key(dec.M),
            "A1": _key(dec.A1),
            "L_pole": _key(placed.L),
            "error_poles": _key(np.sort(placed.poles().real)),
            "fixed_modes": _key(np.sort_complex(check_existence(plant).fixed_modes)),
            "e0": _key((np.eye(plant.n) - dec.M @ plant.C) @ np.asarray(self.initial_state)),
        }


# The missile autopilot ---------------------------------------------------------------------------


@lab_params_of(MISSILE)
class MissileParams(LabParams):
    """The numbers of the missile lab (the fields of :data:`~uio_teach.experiments.MISSILE`).

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
    >>> from uio_teach.instructor.lab_params import MissileParams
    >>> MissileParams().to_params()["pmo_poles"]
    [-100.0, -120.0]
    """

    @classmethod
    def draw(cls, rng: np.random.Generator, base: MissileParams | None = None) -> MissileParams:
        """A variant for one group: the airframe, actuator and sensors; PMO poles; noise and seed.

        ``A`` keeps the paper's structure (``x2' = -a x1 - b x3``, a fin
        actuator of natural frequency ``wn`` and damping ``zeta``), ``B`` its
        gain, ``E`` small integers, and ``C`` measures ``x1 + c x3`` and
        ``x2 + c' x3`` (sensors that see a little of the fin deflection), so that ``M``,
        ``Cg``, ``Pc``, ``Kg`` and the predicted noise differ between groups.
        :meth:`problems` makes sure that ``CE`` is square and invertible, the
        two invariant zeros (the fixed modes) are stable and actuator-like, and
        the PMO catches ``v1``, ``v2`` within the window. The two PMO poles
        lie in [-170, -70], at least 20 apart.
        """
        base = base or cls()
        wn = _choice(rng, [150.0, 160.0, 170.0, 180.0, 190.0, 200.0])
        zeta = _choice(rng, [0.5, 0.6, 0.7])
        A = [
            [0.0, 0.0, 0.0, 0.0],
            [
                -_choice(rng, [70.0, 80.0, 86.0, 90.0, 100.0]),
                0.0,
                -_choice(rng, [8, 10, 12, 14]),
                0,
            ],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, -(wn**2), -round(2 * zeta * wn, 6)],
        ]
        B = [[0.0], [0.0], [0.0], [-round(1.4 * wn**2, 6)]]
        E = rng.choice([-1.0, 1.0, 2.0, 3.0, 4.0, 5.0], (4, 2)).tolist()
        C = [
            [1.0, 0.0, round(_choice(rng, np.arange(-6, 7)) * 0.05, 2), 0.0],
            [0.0, 1.0, round(_choice(rng, np.arange(-6, 7)) * 0.05, 2), 0.0],
        ]
        while True:
            a, b = sorted(rng.choice(np.arange(-170.0, -69.0, 5.0), 2, replace=False))
            if b - a >= 20:
                break
        matrices = {"A": A, "B": B, "C": C, "E": E}
        return cls(
            poles=(float(b), float(a)),
            duration=base.duration,
            samples=base.samples,
            style=base.style,
            matrices=_lab_value(dict(experiment_params(MISSILE))["matrices"], matrices),
            noise_sigma=_choice(rng, [0.005, 0.01, 0.02]),
            noise_seed=int(rng.integers(1, 1000)),
            tol=base.tol,
        )

    def distinct(self) -> dict[str, Any]:
        """PMO poles, ``C`` (``Cg``, ``Pc``) and the column space of ``E`` (``M``, ``Kg``)."""
        plant = self.plant()
        return {
            "poles": tuple(sorted(complex(p).real for p in self.poles)),
            "C": tuple(plant.C.ravel()),
            "E": _subspace(plant.E),
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
            "M": _key(M),
            "L": _key(pmo.L),
            "Cg": _key(Cg),
            "Pc": _key(Pc),
            "Kg": _key(Pc @ E @ CEg),
            "error_poles": _key(np.sort_complex(pmo.poles())),
            "fixed_modes": _key(np.sort_complex(check_existence(plant).fixed_modes)),
            "noise_rms_predicted": _key(self.noise_sigma / (math.sqrt(2) * h) * rho, 6),
        }


def _fields(params: Any) -> dict[str, Any]:
    return {f.name: getattr(params, f.name) for f in fields(params)}


def params_dict(params: LabParams) -> dict[str, Any]:
    """The dataclass fields of ``params`` (for messages and tests)."""
    return asdict(params)  # type: ignore[call-overload]
