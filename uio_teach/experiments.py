"""What every worked experiment shares: the base class, the field declarations, the lab plants.

An experiment is what the book simulates for one plant of :mod:`uio_teach.examples`:
the time grid, the known input, the unknown inputs, the initial state, the
observer poles, where the observer starts and the measurement noise. Each
worked example defines its own in its module of :mod:`uio_teach.worked`
(``uio_teach.worked.pa9.PA9``, ``uio_teach.worked.case_study.CASE_STUDY``,
``uio_teach.worked.missile.MISSILE``,
``uio_teach.worked.quadruple_tank.QUADRUPLE_TANK``); :data:`EXPERIMENTS` holds
them all, read from :data:`uio_teach.worked.WORKED`. The figures of
``uio-teach figures``, the explorers and the lab checks read their values from
there, so changing one (say the PA9 initial state) changes every figure,
explorer and lab that uses it.

Each is a frozen dataclass derived from :class:`Experiment`;
:meth:`Experiment.simulate` runs an observer on it with
:func:`uio_teach.simulate`. The numbers an instructor may change are fields
declared once with :func:`param` (type, unit, help, bounds, range): the term
config (``uio_teach.instructor.config``), the lab parameters
(:mod:`uio_teach.lab_params`) and the explorers' controls are derived from
these declarations (:func:`experiment_params`), so a new field is one line.
:func:`plant_from_params` gives a lab's plant, the course's or a group's own.

Examples
--------
>>> from uio_teach.experiments import EXPERIMENTS
>>> EXPERIMENTS["pa9"].initial_state.tolist(), EXPERIMENTS["pa9"].poles
([1.0, -1.0, 0.5], (-1.0, -2.0, -3.0))
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from ._validation import as_matrix
from .errors import InputError
from .plant import Plant
from .simulation import UIOResponse, simulate
from .worked import WORKED, RegistryView

__all__ = [
    "Experiment",
    "ContinuousExperiment",
    "EXPERIMENTS",
    "Param",
    "param",
    "experiment_params",
    "LAB_PLANTS",
    "plant_from_params",
    "pole_text",
]

PARAM_KINDS = ("int", "float", "floats", "poles", "str", "style", "matrices")
"""The kinds of value a :class:`Param` declares."""
CONTROLS = ("amplitude", "frequency", "noise")
"""The explorer's own controls that a declared field can set (:attr:`Param.control`); a
field with a ``range`` and none of these gets a slider of its own."""


@dataclass(frozen=True)
class Param:
    """What the course knows about one field of an experiment: the one declaration of it.

    The term config (``uio_teach.instructor.config``), the lab parameters
    (:mod:`uio_teach.lab_params`) and the explorers
    (``uio_teach.explorers.scenarios``) read their keys, types, bounds,
    help texts and ranges from these declarations, attached to the fields of
    the experiment dataclasses with :func:`param`; adding a field to an
    experiment adds it to all three.

    Parameters
    ----------
    kind : {"int", "float", "floats", "poles", "str", "style", "matrices"}
        The value's type: an integer, a number, a list of numbers, observer
        poles (complex ones as strings such as ``"-1+2j"``), a string, a
        matplotlib style, or plant matrices (``{"A": [[...]], ...}``).
    doc : str
        One line on what the value is (the config's comment).
    unit : str
        Its unit (``"s"``, ``"rad/s"``, ...; empty: none).
    key : str, optional
        Its dotted name inside the experiment's table of the term config and
        in the lab's ``PARAMS`` (``"sine.amplitude"``); default: the field's name.
    config : bool or str
        ``True``: a key ``<section>.<key>`` of the term config; a string: that
        key instead (``"seed"``, shared by the experiments); ``False``: not in
        the config.
    lab : bool
        An entry of the lab's ``PARAMS``.
    minimum, maximum : float, optional
        Inclusive bounds (for ``"floats"`` without ``minimum`` and for a
        ``"float"`` without ``minimum`` or ``positive``, ``maximum`` bounds the
        magnitude).
    positive : bool
        Strictly positive.
    length : int, optional
        The exact length of a list.
    discrete : bool
        Poles of a discrete-time observer (inside the unit circle).
    optional : bool
        May be absent (the value ``None``).
    omit_default : bool
        Left out of ``PARAMS`` while it has its default value.
    range : (float, float), optional
        The range a student explores: the field gets a slider in the
        explorer (of its own, or the control that ``control`` names). Only
        for ``"int"`` and ``"float"`` fields.
    control : str
        The explorer's own control that the field sets, with ``range``:
        ``"amplitude"``, ``"frequency"`` or ``"noise"`` (the disturbance and
        measurement controls); empty: a slider of its own, which remakes the
        explorer's run with the field's new value (a physical parameter of
        the plant, a time, ...).

    Examples
    --------
    >>> from uio_teach.experiments import experiment_params
    >>> from uio_teach.worked.pa9 import PA9
    >>> spec = dict(experiment_params(PA9))["sine_frequency"]
    >>> spec.key, spec.unit, spec.config_key("pa9")
    ('sine.frequency', 'rad/s', 'pa9.sine.frequency')
    """

    kind: str
    doc: str
    unit: str = ""
    key: str | None = None
    config: bool | str = True
    lab: bool = True
    minimum: float | None = None
    maximum: float | None = None
    positive: bool = False
    length: int | None = None
    discrete: bool = False
    optional: bool = False
    omit_default: bool = False
    range: tuple[float, float] | None = None
    control: str = ""

    def __post_init__(self) -> None:
        if self.kind not in PARAM_KINDS:
            raise InputError(f"Param kind must be one of {PARAM_KINDS}, got {self.kind!r}")
        if self.control and (self.control not in CONTROLS or self.range is None):
            raise InputError(
                f"a Param's control must be one of {CONTROLS} and comes with a range; got "
                f"range={self.range!r}, control={self.control!r}"
            )
        if self.range is not None:
            lo, hi = self.range
            if self.kind not in ("int", "float") or not lo < hi:
                raise InputError(
                    "a Param's range (a slider) needs an int or float field and low < high; "
                    f"got kind={self.kind!r}, range={self.range!r}"
                )

    def config_key(self, section: str, name: str = "") -> str | None:
        """The key of the term config (``None``: not in the config).

        Parameters
        ----------
        section : str
            The experiment's table (``"pa9"``, ``"case_study"``, ``"missile"``).
        name : str
            The field's name (used when :attr:`key` is not given).

        Returns
        -------
        str or None
        """
        if self.config is False:
            return None
        if isinstance(self.config, str):
            return self.config
        return f"{section}.{self.key or name}"

    @property
    def help(self) -> str:
        """The one-line help, :attr:`doc` and the unit in brackets."""
        return f"{self.doc} [{self.unit}]" if self.unit else self.doc


def number_text(x: float) -> str:
    """A bound or value as a person reads it: a whole number in full, others as Python prints them.

    Parameters
    ----------
    x : float

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.experiments import number_text
    >>> number_text(2**32), number_text(0.99), number_text(4294967295.0), number_text(1e-9)
    ('4294967296', '0.99', '4294967295', '1e-09')
    """
    x = float(x)
    if x.is_integer() and abs(x) < 1e15:
        return str(int(x))
    return repr(x)


def out_of_bounds(spec: Any, x: float) -> str | None:
    """What a number breaks of a field's declared bounds, or ``None`` when it keeps them.

    Parameters
    ----------
    spec : Param or ConfigKey
        The field's declaration (its ``kind``, ``minimum``, ``maximum`` and
        ``positive``, as :class:`Param` has them).
    x : float
        The value.

    Returns
    -------
    str or None
        ``"must be <= 0.99, got 0.995"`` and the like.

    Examples
    --------
    >>> from uio_teach.experiments import experiment_params, out_of_bounds
    >>> from uio_teach.worked.quadruple_tank import QUADRUPLE_TANK
    >>> spec = dict(experiment_params(QUADRUPLE_TANK))["gamma1"]
    >>> out_of_bounds(spec, 0.995), out_of_bounds(spec, 0.5)
    ('must be <= 0.99, got 0.995', None)
    """
    if spec.positive and x <= 0:
        return f"must be > 0, got {number_text(x)}"
    if spec.minimum is not None and x < spec.minimum:
        return f"must be >= {number_text(spec.minimum)}, got {number_text(x)}"
    if spec.maximum is not None:
        if spec.kind == "int" or spec.minimum is not None or spec.positive:
            if x > spec.maximum:
                return f"must be <= {number_text(spec.maximum)}, got {number_text(x)}"
        elif abs(x) > spec.maximum:
            return (
                f"must be between -{number_text(spec.maximum)} and "
                f"{number_text(spec.maximum)}, got {number_text(x)}"
            )
    return None


def param(default: Any, kind: str, doc: str, **options: Any) -> Any:
    """An experiment field declared with its :class:`Param` (a ``dataclasses.field``).

    Parameters
    ----------
    default : object
        The course's value (immutable: a tuple for a list).
    kind, doc : str
        See :class:`Param`.
    **options
        The other arguments of :class:`Param`, and ``init``/``repr`` of
        ``dataclasses.field``.

    Returns
    -------
    dataclasses.Field

    Examples
    --------
    >>> import dataclasses
    >>> from uio_teach.experiments import param
    >>> from uio_teach.worked.pa9 import PA9Experiment
    >>> @dataclasses.dataclass(frozen=True)
    ... class Heavier(PA9Experiment):
    ...     gain: float = param(2.0, "float", "a gain of the known input", positive=True)
    >>> Heavier(name="pa9", timepts=[0.0, 1.0]).gain
    2.0
    """
    init = options.pop("init", True)
    shown = options.pop("repr", True)
    kwargs: dict[str, Any] = {
        "init": init,
        "repr": shown,
        "metadata": {PARAM: Param(kind, doc, **options)},
    }
    if init:
        kwargs["default"] = default
    return field(**kwargs)


PARAM = "uio_teach.param"
"""The key of a field's :class:`Param` in its ``metadata``."""


def experiment_params(experiment: Any) -> tuple[tuple[str, Param], ...]:
    """The declared fields of an experiment (or experiment class), in order, with their Param.

    Parameters
    ----------
    experiment : Experiment or type
        An experiment, or its class.

    Returns
    -------
    tuple of (str, Param)

    Examples
    --------
    >>> from uio_teach.experiments import experiment_params
    >>> from uio_teach.worked.missile import MISSILE
    >>> [name for name, spec in experiment_params(MISSILE) if spec.lab]
    ['poles', 'duration', 'samples', 'style', 'matrices', 'noise_sigma', 'noise_seed', 'tol']
    """
    return tuple((f.name, f.metadata[PARAM]) for f in fields(experiment) if PARAM in f.metadata)


MAX_SEED = 2**32 - 1
"""The largest seed (numpy's legacy seeds and most tools take 32 bits)."""
MAX_SAMPLES = 200_000
"""The most time points of a continuous-time run (3 states, a few MB per signal)."""
MAX_STEPS = 100_000
"""The most steps of the discrete-time case study."""
MAX_DURATION = 10_000.0
"""The longest simulated time, in s."""
MAX_VALUE = 1e6
"""The largest magnitude of an amplitude, a level, a noise level or an initial state entry."""

SEED_DOC = "seed of every random number: PA9's measurement noise, the case study's v"
STYLE_DOC = "matplotlib style: a name of matplotlib.style.available or a .mplstyle file"


def pole_text(p: complex) -> float | str:
    """A pole as JSON and TOML keep it: a float if real, else a string such as ``"-1+2j"``.

    Parameters
    ----------
    p : complex

    Returns
    -------
    float or str

    Examples
    --------
    >>> from uio_teach.experiments import pole_text
    >>> pole_text(-2), pole_text(complex(-1, 2))
    (-2.0, '-1+2j')
    """
    z = complex(p)
    if z.imag == 0:
        return float(z.real) + 0.0
    return f"{z.real:g}{z.imag:+g}j"


def _frozen(values: Any) -> np.ndarray:
    arr = np.array(values, dtype=float)
    arr.setflags(write=False)
    return arr


def _matrices(value: Any) -> tuple[tuple[str, tuple[tuple[float, ...], ...]], ...]:
    """Plant matrices as a hashable, sorted tuple of ``(name, rows)`` (from a mapping or pairs)."""
    items = value.items() if isinstance(value, Mapping) else (value or ())
    out = []
    for name, matrix in items:
        rows = np.atleast_2d(np.asarray(matrix, dtype=float))
        out.append((str(name), tuple(tuple(float(x) + 0.0 for x in row) for row in rows)))
    return tuple(sorted(out))


@dataclass(frozen=True)
class Experiment:
    """A worked experiment: the plant and everything a simulation of it needs but the observer.

    The fields declared with :func:`param` are the experiment's numbers that
    an instructor may change: each carries its :class:`Param` (type, unit,
    help, bounds), from which the term config, the lab parameters and the
    explorers are derived (:func:`experiment_params`).

    Each experiment class also says ``lab``, the worked example's name in
    :data:`uio_teach.worked.WORKED` (its config table, and its lab's id when it
    has one), ``tables``, the comments of its config tables, and
    ``plant_fields``, the fields passed to the worked example's plant factory
    as keywords (physical parameters, such as the valves of the quadruple tank).

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
        Standard deviation of the measurement noise on every output (``None`` or 0: none).
    seed : int or None
        Seed of the noise and of any random signal of the experiment.
    duration : float
        The last time point (seconds, or steps), from ``timepts``.
    samples : int
        The number of time points, from ``timepts``.
    style : str
        The matplotlib style of its plots.
    matrices : tuple
        The plant's own matrices as ``(name, rows)`` pairs (empty: the course's
        plant); :meth:`plant` puts them in place.

    Examples
    --------
    >>> from uio_teach.worked.missile import MISSILE
    >>> MISSILE.name, MISSILE.duration, MISSILE.timepts.size
    ('missile', 0.5, 10001)
    """

    lab: ClassVar[str] = ""
    tables: ClassVar[Mapping[str, str]] = MappingProxyType({})
    plant_fields: ClassVar[tuple[str, ...]] = ()

    name: str
    timepts: np.ndarray = field(repr=False)
    initial_state: np.ndarray
    poles: tuple[complex, ...] | None
    noise: float | None = None
    seed: int | None = None
    duration: float = param(
        None, "float", "simulated time", unit="s", init=False, config=False, lab=False
    )
    samples: int = param(
        None, "int", "number of time points", init=False, config=False, lab=False, repr=False
    )
    style: str = param("default", "style", STYLE_DOC, config="style", omit_default=True, repr=False)
    matrices: tuple = param(
        (),
        "matrices",
        "the plant's own matrices, e.g. {'E': [[1], [0], [2]]} (none: the course's)",
        key="plant",
        config=False,
        omit_default=True,
        repr=False,
    )

    def __post_init__(self) -> None:
        object.__setattr__(self, "timepts", _frozen(self.timepts))
        object.__setattr__(self, "initial_state", _frozen(self.initial_state).ravel())
        if self.poles is not None:
            poles = tuple(complex(p) if complex(p).imag else complex(p).real for p in self.poles)
            object.__setattr__(self, "poles", poles)
        object.__setattr__(self, "duration", float(self.timepts[-1]))
        object.__setattr__(self, "samples", int(self.timepts.size))
        object.__setattr__(self, "matrices", _matrices(self.matrices))
        # a value beyond its declared bounds is refused however the experiment is made (the
        # config checks the same bounds, naming its key)
        for name, spec in experiment_params(self):
            value = getattr(self, name)
            if spec.kind in ("int", "float") and value is not None:
                problem = out_of_bounds(spec, float(value))
                if problem is not None:
                    raise InputError(f"{type(self).__name__}: {name} ({spec.doc}) {problem}")

    # the plant and the time grid ----------------------------------------------------------------
    def plant(self) -> Plant:
        """A new copy of the experiment's plant: the course's, with ``matrices`` in place.

        Returns
        -------
        Plant

        Examples
        --------
        >>> from uio_teach.worked.pa9 import PA9
        >>> PA9.plant().name
        'PA9'
        >>> PA9.with_values(matrices={"E": [[1], [0], [0]]}).plant().E.ravel().tolist()
        [1.0, 0.0, 0.0]
        """
        factory = WORKED[self.lab].plant_factory()
        course = factory(**{name: getattr(self, name) for name in self.plant_fields})
        return _with_matrices(self.lab, course, dict(self.matrices))

    def grid(self, samples: int | None = None, duration: float | None = None) -> np.ndarray:
        """The time grid, or one from the same start with another length or resolution.

        Parameters
        ----------
        samples : int, optional
            Number of time points (default: as ``timepts``).
        duration : float, optional
            The last time point (default: ``duration``).

        Returns
        -------
        numpy.ndarray

        Examples
        --------
        >>> from uio_teach.worked.pa9 import PA9
        >>> PA9.grid(samples=5).tolist()
        [0.0, 2.5, 5.0, 7.5, 10.0]
        """
        if samples is None and duration is None:
            return self.timepts
        start = float(self.timepts[0])
        stop = self.duration if duration is None else float(duration)
        count = self.timepts.size if samples is None else int(samples)
        return np.linspace(start, stop, count)

    def with_values(self, **values: Any) -> Experiment:
        """A copy with other values of its fields; ``duration`` and ``samples`` remake the grid.

        Parameters
        ----------
        **values
            Field names and their new values.

        Returns
        -------
        Experiment

        Examples
        --------
        >>> from uio_teach.worked.pa9 import PA9
        >>> run = PA9.with_values(duration=5.0, samples=11, sine_amplitude=2.0)
        >>> run.timepts[-1], run.timepts.size, run.sine_amplitude, PA9.duration
        (np.float64(5.0), 11, 2.0, 10.0)
        """
        samples, duration = values.pop("samples", None), values.pop("duration", None)
        if samples is not None or duration is not None:
            if "timepts" in values:
                raise InputError(
                    "give the time grid either as timepts or as samples/duration, not both "
                    "(one of them would be dropped)"
                )
            values["timepts"] = self.grid(samples=samples, duration=duration)
        names = {f.name for f in fields(self) if f.init}
        unknown = sorted(set(values) - names)
        if unknown:
            raise InputError(
                f"the experiment {self.name!r} has no field {', '.join(map(repr, unknown))}"
            )
        return replace(self, **values)

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
        >>> from uio_teach.worked.pa9 import PA9
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
        >>> from uio_teach.worked.pa9 import PA9
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
        >>> from uio_teach.worked.case_study import CASE_STUDY
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
class ContinuousExperiment(Experiment):
    """A continuous-time experiment: its length (s) and number of time points are config keys.

    Examples
    --------
    >>> from uio_teach.experiments import ContinuousExperiment, experiment_params
    >>> spec = dict(experiment_params(ContinuousExperiment))["duration"]
    >>> spec.unit, spec.config_key("pa9", "duration")
    ('s', 'pa9.duration')
    """

    duration: float = param(
        None, "float", "simulated time", unit="s", init=False, positive=True, maximum=MAX_DURATION
    )
    samples: int = param(
        None, "int", "number of time points", init=False, minimum=2, maximum=MAX_SAMPLES
    )


EXPERIMENTS: Mapping[str, Experiment] = RegistryView(
    "EXPERIMENTS", lambda worked: {name: entry.run() for name, entry in worked.items()}
)
"""The experiment of every worked example, by name.

The names are the tables of the term config; the values the experiments of the worked
examples' modules (a view of :data:`uio_teach.worked.WORKED`)."""


LAB_PLANTS: Mapping[str, Callable[[], Plant]] = RegistryView(
    "LAB_PLANTS",
    lambda worked: {name: entry.plant_factory() for name, entry in worked.items() if entry.lab},
)
"""The course's plant of each lab, as a factory (the worked examples of
:data:`uio_teach.worked.WORKED` that have a lab)."""

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
        The lab (see ``LAB_PLANTS``).
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
    uio_teach.errors.InputError: PARAMS["plant"]["E"] of the pa9 lab has shape (1, 2), ...
    """
    if not isinstance(lab, str) or lab not in LAB_PLANTS:
        raise InputError(f"unknown lab {lab!r}: expected one of {', '.join(LAB_PLANTS)}")
    course = LAB_PLANTS[lab]()
    if params is None:
        return course
    if not isinstance(params, Mapping):
        raise InputError(f"params of the {lab} lab must be a mapping (PARAMS), got {params!r}")
    return _with_matrices(lab, course, params.get("plant"))


def _with_matrices(lab: str, course: Plant, given: Any) -> Plant:
    """``course`` with the matrices of ``given`` (a lab's ``PARAMS["plant"]``) in their place."""
    if not given:
        return course
    if not isinstance(given, Mapping):
        raise InputError(
            f'PARAMS["plant"] of the {lab} lab must map matrix names ({", ".join(_PLANT_MATRICES)})'
            f" to nested lists, got {type(given).__name__}"
        )
    unknown = sorted(str(k) for k in given if k not in _PLANT_MATRICES)
    if unknown:
        raise InputError(
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
            raise InputError(f"{err} (the {lab} lab)") from None
        if arr.shape != expected:
            raise InputError(
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
