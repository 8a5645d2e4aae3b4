"""The numbers of a lab, as a parameter class: defaults, the term config, one variant per group.

Every lab notebook has one code cell tagged ``parameters`` that defines
``PARAMS``, a JSON-compatible dict; the notebook's code reads its numbers from
it and passes them to the checks. One frozen dataclass per lab turns these
numbers into that dict (``to_params``) and back (``from_params``), reads them
from a term config (``from_config``), draws a variant for a lab group
(``draw``) and computes the answer key (``answers``).

This module holds what every lab shares (:class:`LabParams`,
:func:`lab_params_of`); each lab's class lives in its worked example's module
(``uio_teach.worked.pa9.PA9Params``, ...). The fields of a class are not
written there: they are the fields of the lab's experiment declared with
``lab=True``, with the experiment's values as defaults, their place in
``PARAMS`` and their config key from the same declaration. Only what is
particular to a lab is written with it: what a group's variant changes
(``vary``: :meth:`LabParams.draw` keeps every other field as configured), when
a variant is a fair exercise, and the answer key.

Examples
--------
>>> from uio_teach.worked.pa9 import PA9Params
>>> PA9Params().to_params()["poles"]
[-1.5, -2.5, -4.0]
>>> PA9Params.from_params(PA9Params().to_params()) == PA9Params()
True
"""

from __future__ import annotations

import dataclasses
import os
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from .errors import UIOTeachError
from .experiments import Experiment, Param, experiment_params, plant_from_params, pole_text
from .plant import Plant

__all__ = [
    "LabParams",
    "LabParamsError",
    "lab_params_of",
    "lab_value",
    "answer_value",
    "pick",
    "direction_key",
    "subspace_key",
    "pole_text",
    "params_dict",
    "MIN_INITIAL_ERROR",
]


class LabParamsError(UIOTeachError, ValueError):
    """Lab parameters that cannot be used: an unknown or missing entry (named in the message)."""


MIN_INITIAL_ERROR = 0.25
"""The least largest entry of a group's initial estimation error e(0) (from z(0) = 0).

A drawn initial state whose error starts smaller (for PA9, an ``x(0)`` along
``E``, which ``T`` annuls) is drawn again: the exercises watch the error decay."""


def _pole(value: Any) -> complex | float:
    z = complex(value.replace(" ", "")) if isinstance(value, str) else complex(value)
    return z if z.imag else float(z.real)


def _floats(values: Any) -> tuple[float, ...]:
    return tuple(float(v) + 0.0 for v in np.asarray(values, dtype=float).ravel())


def answer_value(x: Any, digits: int = 10) -> Any:
    """Numbers of an answer key as JSON-compatible lists, rounded (no ``-0.0``).

    Parameters
    ----------
    x : array_like
        Real or complex numbers (complex ones become strings such as ``"-1+2j"``).
    digits : int
        Decimal places kept.

    Returns
    -------
    list

    Examples
    --------
    >>> from uio_teach.lab_params import answer_value
    >>> answer_value([[-0.0, 1 / 3]], digits=3), answer_value([-1 + 2j])
    ([[0.0, 0.333]], ['-1+2j'])
    """
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


def lab_value(spec: Param, value: Any) -> Any:
    """A value of the experiment, the config or ``PARAMS`` as the parameter class keeps it.

    Parameters
    ----------
    spec : Param
        The field's declaration (its ``kind`` decides the form).
    value : object
        The value, as the experiment, the config or JSON holds it.

    Returns
    -------
    object
        Hashable: tuples for lists, ``(name, rows)`` pairs for matrices.

    Examples
    --------
    >>> from uio_teach.experiments import Param
    >>> from uio_teach.lab_params import lab_value
    >>> lab_value(Param("poles", "poles"), [-1, "-2+1j"])
    (-1.0, (-2+1j))
    """
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


def _paths(params: Mapping[str, Any], prefix: str = "") -> list[str]:
    """Every leaf of a nested ``PARAMS`` dict as a dotted path (``"sine.amplitude"``)."""
    out = []
    for key, value in params.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping) and value and path != "plant":
            out += _paths(value, f"{path}.")
        else:
            out.append(path)
    return out


class LabParams(ABC):
    """What every lab's parameter class shares (see the module's docstring).

    The fields come from the lab's experiment (:func:`lab_params_of`);
    ``to_params``, ``from_params``, ``from_config``, :meth:`draw` and
    :meth:`plant` read the declarations, so they need no change when a field
    is added. Four methods only the lab can write are abstract, so a lab's
    class that forgets one cannot be made at all (Python names the missing
    ones) rather than deal groups the same numbers or an empty key:
    :meth:`vary` (what a group's variant changes), :meth:`distinct` (what
    no two groups may share), :meth:`problems` (when a variant is a fair
    exercise) and :meth:`answers` (the answer key).

    Examples
    --------
    >>> from uio_teach.worked.pa9 import PA9Params
    >>> [name for name, _ in PA9Params.declared()][:3]
    ['initial_state', 'poles', 'noise']
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
        """The parameters of a ``PARAMS`` dict (the inverse of :meth:`to_params`).

        An entry that no field declares, or a declared one that is missing
        (and has no default to fall back on), is a :class:`LabParamsError`
        naming it: a value is never dropped or replaced by a default unseen.
        """
        if not isinstance(params, Mapping):
            raise LabParamsError(f"PARAMS of the {cls.lab} lab must be a mapping, got {params!r}")
        known = {spec.key or name for name, spec in cls.declared()}
        unknown = [
            path
            for path in _paths(params)
            if path not in known and not any(path.startswith(f"{k}.") for k in known)
        ]
        if unknown:
            raise LabParamsError(
                f"PARAMS of the {cls.lab} lab: unknown entr{'y' if len(unknown) == 1 else 'ies'} "
                f"{', '.join(map(repr, unknown))}; expected some of {', '.join(sorted(known))}"
            )
        kwargs = {}
        for name, spec in cls.declared():
            try:
                value = _get(params, spec.key or name)
            except KeyError:
                if spec.omit_default or spec.optional:
                    continue
                raise LabParamsError(
                    f"PARAMS of the {cls.lab} lab: {spec.key or name!r} is missing ({spec.help})"
                ) from None
            kwargs[name] = lab_value(spec, value)
        return cls(**kwargs)

    @classmethod
    def config_keys(cls) -> frozenset[str]:
        """The keys of the term config this lab reads (its fields' config keys).

        ``uio-teach labs`` names every key a config sets that no lab reads
        (``uio_teach.instructor.labs.unused_config_keys``); a lab whose
        :meth:`from_config` reads another key says so here.
        """
        keys = (spec.config_key(cls.lab, name) for name, spec in cls.declared())
        return frozenset(k for k in keys if k is not None)

    @classmethod
    def from_config(cls, config: Mapping[str, Any] | None) -> LabParams:
        """The parameters of a term config (:func:`uio_teach.instructor.config.load_config`).

        Every field whose config key the config sets takes the config's value;
        the others keep the lab's own defaults, which are not the chapters'
        runs (the figures' defaults), so that no chapter prints a lab's answer.
        A config that says which keys it was given (``given``, as
        ``FigureConfig`` does) sets those; a plain mapping sets every key it has.
        """
        if config is None:
            return cls()
        given = getattr(config, "given", None)
        kwargs = {}
        for name, spec in cls.declared():
            key = spec.config_key(cls.lab, name)
            if key is None or key not in config or config[key] is None:
                continue
            if given is not None and key not in given:
                continue
            kwargs[name] = lab_value(spec, config[key])
        return cls(**kwargs)

    @classmethod
    @abstractmethod
    def vary(cls, rng: np.random.Generator, base: LabParams) -> dict[str, Any]:
        """What one group's variant changes: field names and their drawn values.

        Each lab's class says what it draws (the plant, poles, signals, ...);
        every field it does not name keeps the value of ``base``. Abstract:
        only the lab knows which numbers make another exercise with other
        answers; a lab that varies nothing would give every group the
        same answers, so it says so by returning ``{}`` on purpose.
        """

    @classmethod
    def draw(cls, rng: np.random.Generator, base: LabParams | None = None) -> LabParams:
        """A variant for one group: ``base`` with the fields of :meth:`vary` drawn anew.

        Every field that :meth:`vary` does not draw keeps the value of
        ``base`` (the term's configured values), whatever fields the lab
        has, so a configured value reaches every group unless the lab
        varies it on purpose.

        Parameters
        ----------
        rng : numpy.random.Generator
            The source of the draw.
        base : LabParams, optional
            The term's parameters (default: the course's).

        Returns
        -------
        LabParams
        """
        base = base if base is not None else cls()
        drawn = cls.vary(rng, base)
        names = {f.name for f in fields(base)}  # type: ignore[arg-type]
        unknown = sorted(set(drawn) - names)
        if unknown:
            raise LabParamsError(f"{cls.__name__}.vary draws fields it does not have: {unknown}")
        values = {}
        for name, spec in cls.declared():
            if name in drawn:
                values[name] = lab_value(spec, drawn[name])
        return dataclasses.replace(base, **values)  # type: ignore[type-var]

    def plant(self) -> Plant:
        """The plant of this variant (:func:`uio_teach.experiments.plant_from_params`)."""
        return plant_from_params(self.lab, self.to_params())

    def run(self) -> Experiment:
        """The lab's experiment with this variant's values (for simulations)."""
        values = {name: getattr(self, name) for name, _ in self.declared() if name != "duration"}
        values["matrices"] = dict(getattr(self, "matrices", ()) or ())
        return self.experiment.with_values(duration=getattr(self, "duration", None), **values)

    @abstractmethod
    def distinct(self) -> dict[str, Any]:
        """What no two groups may share (hashable values by name), e.g. ``{"poles": ...}``.

        Abstract: two variants that differ only in numbers that do not
        decide the answers (a seed, a time grid) would share an answer key;
        the lab names what decides them. The names appear in the message of
        :func:`uio_teach.instructor.variants.draw_variants` when too many
        draws collide.
        """

    @abstractmethod
    def problems(self) -> list[str]:
        """Why this variant would not be a fair exercise, one sentence each (empty: it is).

        Abstract: only the lab knows what its exercises need (a UIO that
        exists, poles fast enough for the simulated time, a disturbance large
        enough to see); a drawn variant with a problem is drawn again.
        """

    @abstractmethod
    def answers(self) -> dict[str, Any]:
        """The answer key of this variant: JSON-compatible numbers by name.

        Abstract: the key is what the lab asks for, computed from the
        variant's own plant and numbers (:func:`answer_value`);
        ``uio-teach labs --groups`` writes it to ``answer_key.csv``.
        """


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
    >>> from uio_teach.experiments import param
    >>> from uio_teach.lab_params import lab_params_of
    >>> from uio_teach.worked.pa9 import PA9, PA9Experiment, PA9Params
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
            setattr(cls, name, lab_value(spec, getattr(experiment, name)))
        cls.__annotations__ = annotations
        cls.experiment = experiment
        cls.lab = lab or experiment.lab
        return dataclass(frozen=True)(cls)

    return decorate


def pick(rng: np.random.Generator, values: Any) -> float:
    """One of ``values``, drawn by ``rng``, as a float.

    Parameters
    ----------
    rng : numpy.random.Generator
    values : array_like
        The choices.

    Returns
    -------
    float

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.lab_params import pick
    >>> pick(np.random.default_rng(0), [1, 2, 3]) in (1.0, 2.0, 3.0)
    True
    """
    return float(rng.choice(np.asarray(values, dtype=float)))


def direction_key(v: Any) -> tuple[float, ...]:
    """A vector's direction as a hashable key: unit length, first nonzero entry positive.

    Parameters
    ----------
    v : array_like
        A nonzero vector.

    Returns
    -------
    tuple of float

    Examples
    --------
    >>> from uio_teach.lab_params import direction_key
    >>> direction_key([0, -2]) == direction_key([0, 5])
    True
    """
    v = np.asarray(v, dtype=float).ravel()
    v = v / np.linalg.norm(v)
    first = v[np.flatnonzero(np.abs(v) > 1e-12)[0]]
    return tuple(np.round(v * np.sign(first), 9) + 0.0)


def subspace_key(X: Any) -> tuple[float, ...]:
    """The column space of ``X`` as a hashable key (its orthogonal projector, rounded).

    Parameters
    ----------
    X : array_like
        A matrix of full column rank.

    Returns
    -------
    tuple of float

    Examples
    --------
    >>> from uio_teach.lab_params import subspace_key
    >>> subspace_key([[1], [1]]) == subspace_key([[-3], [-3]])
    True
    """
    X = np.atleast_2d(np.asarray(X, dtype=float))
    Q, _ = np.linalg.qr(X)
    return tuple(np.round(Q @ Q.T, 9).ravel() + 0.0)


def params_dict(params: LabParams) -> dict[str, Any]:
    """The dataclass fields of ``params`` (for messages and tests).

    Parameters
    ----------
    params : LabParams

    Returns
    -------
    dict

    Examples
    --------
    >>> from uio_teach.lab_params import params_dict
    >>> from uio_teach.worked.missile import MissileParams
    >>> params_dict(MissileParams())["tol"]
    0.02
    """
    return asdict(params)  # type: ignore[call-overload]
