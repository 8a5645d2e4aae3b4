"""The course's worked examples, one module each: everything else derives from their entries.

Each worked example is one module of this package (:mod:`~uio_teach.worked.pa9`,
:mod:`~uio_teach.worked.case_study`, :mod:`~uio_teach.worked.missile`,
:mod:`~uio_teach.worked.quadruple_tank`) that holds all of it: its experiment
(the fields an instructor may change, each declared once with
:func:`uio_teach.experiments.param`), the drawing code of its figures, its
explorer's options and, when it has a lab, the lab's parameter class. A
:class:`WorkedExample` in the module's ``EXAMPLES`` names these, with the
plant factory (:mod:`uio_teach.examples`) and the observer family its poles
set. From these entries come

* the experiments by name (:data:`uio_teach.experiments.EXPERIMENTS`) and the
  plant of each lab (:func:`uio_teach.experiments.plant_from_params`);
* the tables of the term config (``uio_teach.instructor.config``): the
  experiment's declared fields, and the key that sets the observer's poles;
* the figures of ``uio-teach figures`` (``uio_teach.instructor.figures``), each
  drawn from the experiment with the config's values in place
  (:func:`run_from_config`);
* the explorer of each example (``uio_teach.explorers.scenario_of``, from its
  :class:`ExplorerOptions`), with a slider for every declared field that has a
  ``range``;
* the labs of ``uio-teach labs`` (``uio_teach.instructor.labs.LABS``): the
  chapter, the parameter class and the check ids of each :class:`LabEntry`.

A new worked example is one new module here, with a tuple ``EXAMPLES``: it is
found when the registry is first read (:func:`discover` also reads the modules
of another package), and the tests, the API page, the figure list, the term
config and the command line take it from there.

Examples
--------
>>> from uio_teach.worked import WORKED
>>> WORKED["quadruple_tank"].family, WORKED["pa9"].lab.source
('uio', 'lab_pa9.md')
>>> all(name in WORKED for name in ("pa9", "case_study", "missile", "quadruple_tank"))
True
"""

from __future__ import annotations

import dataclasses
import difflib
import importlib
import pkgutil
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import UIOTeachError

__all__ = [
    "WorkedExample",
    "FigureEntry",
    "LabEntry",
    "ExplorerOptions",
    "RegistryError",
    "RegistryView",
    "WORKED",
    "discover",
    "run_from_config",
]

FAMILIES = ("uio", "pmo")
"""The observer families whose poles a worked example's config key sets."""


class RegistryError(UIOTeachError, ValueError):
    """A worked example's declaration that cannot be used (the message names what and why)."""


def _callable(owner: str, what: str, value: Any, optional: bool = False) -> None:
    """Refuse a declaration that is not the object itself (a string naming it, say)."""
    if optional and value is None:
        return
    if isinstance(value, str):
        raise RegistryError(
            f"{owner}: {what} must be the object itself (import it), not the string {value!r}: "
            "an import is a reference every tool follows and every rename updates"
        )
    if not callable(value):
        raise RegistryError(f"{owner}: {what} must be callable, got {type(value).__name__}")


@dataclass(frozen=True)
class FigureEntry:
    """One output of ``uio-teach figures`` of a worked example.

    Attributes
    ----------
    name : str
        The file stem (and the name ``--only`` takes).
    description : str
        One line, shown by ``--list``.
    draw : callable
        ``draw(runs) -> Figure`` (a table: ``draw(runs, folder) -> paths``),
        the function itself; it imports matplotlib only when it draws, so the
        registry does not load it.
    table : bool
        A table (``.csv`` and ``.md``) rather than a picture.

    Examples
    --------
    >>> from uio_teach.worked import WORKED
    >>> [f.name for f in WORKED["quadruple_tank"].figures]
    ['tank_error', 'tank_zeros']
    """

    name: str
    description: str
    draw: Callable[..., Any]
    table: bool = False

    def __post_init__(self) -> None:
        _callable(f"figure {self.name!r}", "draw", self.draw)


_REQUIRED: Any = object()  # marks an explorer option without a default


def _pair(name: str, value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise RegistryError(
            f"explorer option {name!r} must be a pair (low, high), got {value!r}"
        ) from None
    if not lo < hi:
        raise RegistryError(f"explorer option {name!r} must have low < high, got {value!r}")
    return (lo, hi)


@dataclass(frozen=True, init=False)
class ExplorerOptions:
    """A worked example's explorer: what its experiment's declarations do not say.

    The plant, the time grid, the known input, the initial state, the starting
    poles and the disturbance's amplitude, frequency and noise (with their
    ranges, from the fields declared with ``control="amplitude"``,
    ``"frequency"`` or ``"noise"``) come from the experiment, and every other
    declared field with a ``range`` gets a slider of its own; these options
    say the rest. Built from keywords only: a missing required option or an
    unknown one is a :class:`RegistryError` naming it.

    Attributes
    ----------
    period : float
        The starting switching period of the piecewise-constant and
        random-step disturbances (required).
    pole_limits : (float, float)
        The range of a real pole (required).
    frequency_limits : (float, float)
        The range of a complex pair's imaginary part (required).
    period_limits : (float, float)
        The range of the switching period (required).
    static_values : tuple of float
        The values of the static book's main control (required).
    title : str or None
        The figure title (``None``: the entry's title).
    samples : int or None
        Time points of the explorer's grid (``None``: the experiment's).
    poles : tuple of complex or None
        The starting poles, when the experiment has none (an LMI gain).
    disturbance : str
        The starting disturbance type.
    amplitude : float or None
        The starting amplitude, for an experiment that declares no field for
        it (then ``amplitude_limits`` is required too).
    frequency : float or None
        The starting frequency, likewise (with ``disturbance_frequency_limits``).
    amplitude_limits : (float, float) or None
        The amplitude's range, when no declared field sets it (given while a
        field declares one: an error, the value would be set twice).
    disturbance_frequency_limits : (float, float) or None
        The frequency's range, likewise.
    noise_limits : (float, float) or None
        The noise's range, likewise (default: 0 to 0.5).
    decay : float
        The starting LMI bound.
    decay_limits : (float, float) or None
        The LMI bound's range (``None``: no LMI mode).
    tau : float
        The starting time constant of the input reconstruction's filter.
    tau_limits : (float, float) or None
        Its range (``None``: the inputs are not reconstructed).
    d_channels : tuple of tuple
        How each channel of ``d`` follows the disturbance controls:
        ``(gain, speed)`` or ``(gain, speed, decay, kind)`` per channel
        (empty: ``(1, 1)`` for each unknown input).
    v_channels : tuple of tuple
        The same for the measurement disturbance ``v`` (empty: none).
    static_control : str
        The static book's main control: ``"pole"``, ``"amplitude"`` or
        ``"plant:<field>"`` (a field's own slider).
    note : callable or None
        Called with the plant's physical parameters (the experiment's
        ``plant_fields``): a sentence on this plant (``None``: none).
    input_symbol : str
        The unknown input's symbol in the figure.

    Examples
    --------
    >>> from uio_teach.worked import ExplorerOptions
    >>> opts = ExplorerOptions(period=2.5, pole_limits=(-10, 1), frequency_limits=(0, 10),
    ...                        period_limits=(0.25, 5), static_values=(-1.0, -2.0))
    >>> opts.pole_limits, opts.disturbance
    ((-10.0, 1.0), 'sinusoid')
    >>> ExplorerOptions(period=2.5, pole_limits=(-10, 1), frequency_limits=(0, 10),
    ...                 period_limits=(0.25, 5), static_values=(-1.0,), perod=3)
    Traceback (most recent call last):
    ...
    uio_teach.worked.RegistryError: unknown explorer option 'perod' (did you mean 'period'?)...; ...
    >>> ExplorerOptions(pole_limits=(-10, 1), frequency_limits=(0, 10),
    ...                 period_limits=(0.25, 5), static_values=(-1.0,))
    Traceback (most recent call last):
    ...
    uio_teach.worked.RegistryError: explorer option 'period' is missing ...
    """

    period: float = _REQUIRED
    pole_limits: tuple[float, float] = _REQUIRED
    frequency_limits: tuple[float, float] = _REQUIRED
    period_limits: tuple[float, float] = _REQUIRED
    static_values: tuple[float, ...] = _REQUIRED
    title: str | None = None
    samples: int | None = None
    poles: tuple[complex, ...] | None = None
    disturbance: str = "sinusoid"
    amplitude: float | None = None
    frequency: float | None = None
    amplitude_limits: tuple[float, float] | None = None
    disturbance_frequency_limits: tuple[float, float] | None = None
    noise_limits: tuple[float, float] | None = None
    decay: float = 0.9
    decay_limits: tuple[float, float] | None = None
    tau: float = 0.0
    tau_limits: tuple[float, float] | None = None
    d_channels: tuple[tuple[Any, ...], ...] = ()
    v_channels: tuple[tuple[Any, ...], ...] = ()
    static_control: str = "pole"
    note: Callable[..., str] | None = None
    input_symbol: str = "d"

    def __init__(self, **options: Any) -> None:
        names = [f.name for f in dataclasses.fields(self)]
        for key in options:
            if key not in names:
                close = difflib.get_close_matches(key, names, 1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                raise RegistryError(
                    f"unknown explorer option {key!r}{hint}; expected some of {', '.join(names)}"
                )
        for f in dataclasses.fields(self):
            value = options.get(f.name, f.default)
            if value is _REQUIRED:
                raise RegistryError(
                    f"explorer option {f.name!r} is missing (what it is: see ExplorerOptions)"
                )
            object.__setattr__(self, f.name, value)
        self._check()

    def _check(self) -> None:
        set_ = object.__setattr__
        for name in (
            "pole_limits",
            "frequency_limits",
            "period_limits",
            "amplitude_limits",
            "disturbance_frequency_limits",
            "noise_limits",
            "decay_limits",
            "tau_limits",
        ):
            set_(self, name, _pair(name, getattr(self, name)))
        for name in ("period", "decay", "tau", "amplitude", "frequency"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, (int, float)):
                raise RegistryError(f"explorer option {name!r} must be a number, got {value!r}")
        if self.samples is not None and (not isinstance(self.samples, int) or self.samples < 2):
            raise RegistryError(
                f"explorer option 'samples' must be an int >= 2, got {self.samples!r}"
            )
        try:
            set_(self, "static_values", tuple(float(v) for v in self.static_values))
        except (TypeError, ValueError):
            raise RegistryError(
                f"explorer option 'static_values' must be numbers, got {self.static_values!r}"
            ) from None
        for name in ("d_channels", "v_channels"):
            channels = tuple(tuple(c) for c in getattr(self, name))
            for c in channels:
                if len(c) not in (2, 4):
                    raise RegistryError(
                        f"explorer option {name!r}: each channel is (gain, speed) or "
                        f"(gain, speed, decay, kind), got {c!r}"
                    )
            set_(self, name, channels)
        if self.poles is not None:
            set_(self, "poles", tuple(self.poles))
        _callable("explorer option 'note'", "it", self.note, optional=True)
        if not (
            self.static_control in ("pole", "amplitude") or self.static_control.startswith("plant:")
        ):
            raise RegistryError(
                "explorer option 'static_control' must be 'pole', 'amplitude' or "
                f"'plant:<field>', got {self.static_control!r}"
            )


@dataclass(frozen=True)
class LabEntry:
    """The lab of a worked example: its chapter, its parameter class and its checks.

    Attributes
    ----------
    source : str
        The file name of the lab chapter in ``book/``.
    params : type
        The lab's parameter class (a ``uio_teach.lab_params.LabParams``).
    check_ids : tuple of str
        The ``check_id`` of every result its check cells produce, in order.

    Examples
    --------
    >>> from uio_teach.worked import WORKED
    >>> lab = WORKED["pa9"].lab
    >>> lab.source, lab.params.__name__, lab.check_ids[0]
    ('lab_pa9.md', 'PA9Params', 'pa9.design')
    """

    source: str
    params: type
    check_ids: tuple[str, ...]


@dataclass(frozen=True)
class WorkedExample:
    """A worked example of the course: the one declaration everything else reads.

    Attributes
    ----------
    name : str
        Its identifier: the table of the term config, the lab's id.
    title : str
        How the book names it.
    plant : callable
        The plant factory (a function of :mod:`uio_teach.examples`, imported);
        the experiment's fields listed in ``Experiment.plant_fields`` are
        passed to it as keywords.
    experiment : Experiment
        The experiment (an ``uio_teach.experiments.Experiment``).
    family : str
        The observer that the experiment's ``poles`` set: ``"uio"`` or
        ``"pmo"`` (``None`` poles of a PMO: the LMI gain).
    explorer : ExplorerOptions
        Its explorer's options beyond the experiment's declarations.
    figures : tuple of FigureEntry
        Its outputs of ``uio-teach figures``, in order.
    lab : LabEntry or None
        Its lab (``None``: no lab).
    order : int
        Its place among the worked examples (the book's order).
    module : str
        The module that declares it (set by the registry; the API page
        documents it).

    Examples
    --------
    >>> from uio_teach.worked import WORKED
    >>> tank = WORKED["quadruple_tank"]
    >>> tank.plant_factory()(gamma1=0.43, gamma2=0.34).name
    'quadruple tank (P- pumps, gamma 0.43, 0.34)'
    >>> tank.poles_key(), tank.lab is None
    ('quadruple_tank.poles', True)
    """

    name: str
    title: str
    plant: Callable[..., Any]
    experiment: Any
    family: str
    explorer: ExplorerOptions
    figures: tuple[FigureEntry, ...] = ()
    lab: LabEntry | None = None
    order: int = 100
    module: str = dataclasses.field(default="", compare=False)

    def __post_init__(self) -> None:
        _callable(f"worked example {self.name!r}", "plant", self.plant)
        if isinstance(self.experiment, str):
            raise RegistryError(
                f"worked example {self.name!r}: experiment must be the Experiment itself, "
                f"not the string {self.experiment!r}"
            )
        if self.family not in FAMILIES:
            raise RegistryError(
                f"worked example {self.name!r}: family must be one of {FAMILIES}, "
                f"got {self.family!r}"
            )
        if not isinstance(self.explorer, ExplorerOptions):
            raise RegistryError(
                f"worked example {self.name!r}: explorer must be ExplorerOptions, "
                f"got {type(self.explorer).__name__}"
            )
        if self.lab is not None and not isinstance(self.lab, LabEntry):
            raise RegistryError(
                f"worked example {self.name!r}: lab must be a LabEntry or None, "
                f"got {type(self.lab).__name__}"
            )

    def plant_factory(self) -> Callable[..., Any]:
        """The plant factory."""
        return self.plant

    def run(self) -> Any:
        """The experiment."""
        return self.experiment

    def poles_key(self) -> str | None:
        """The config key that sets the observer's poles (``None``: not in the config)."""
        # deferred: the experiments read this registry (a cycle at import time)
        from ..experiments import experiment_params

        spec = dict(experiment_params(self.run())).get("poles")
        return None if spec is None else spec.config_key(self.name, "poles")


class RegistryView(Mapping):
    """A read-only mapping made from the registry each time it is read.

    What the package derives from the worked examples (the experiments by
    name, the figures, the labs, the poles keys of the term config) is a view:
    it follows the registry, a worked example found later included
    (:func:`discover`), and nothing keeps a copy that could go stale.

    Parameters
    ----------
    name : str
        How it prints (``"FIGURES"``, ...).
    items : callable
        ``items(WORKED) -> dict``: the mapping, made from the registry.

    Examples
    --------
    >>> from uio_teach.worked import RegistryView
    >>> titles = RegistryView("TITLES", lambda worked: {n: e.title for n, e in worked.items()})
    >>> titles["missile"], len(titles) >= 4
    ('The missile autopilot', True)
    """

    def __init__(self, name: str, items: Callable[[Mapping[str, WorkedExample]], dict]) -> None:
        self._name = name
        self._make = items

    def _items(self) -> dict:
        return self._make(WORKED)

    def __getitem__(self, key: Any) -> Any:
        return self._items()[key]

    def __iter__(self) -> Iterator[Any]:
        return iter(self._items())

    def __len__(self) -> int:
        return len(self._items())

    def __repr__(self) -> str:
        return f"{self._name}({', '.join(map(str, self))})"


class _Registry(RegistryView):
    """The worked examples by name, found in the modules of the packages read on first use."""

    def __init__(self) -> None:
        super().__init__("WORKED", lambda _worked: self._load())
        self._entries: dict[str, WorkedExample] | None = None
        self._packages: list[tuple[list[str], str]] = [(list(__path__), __name__)]

    def add_package(self, path: list[str], prefix: str) -> None:
        if (path, prefix) not in self._packages:
            self._packages.append((path, prefix))
        self._entries = None

    def remove_package(self, prefix: str) -> None:
        self._packages = [p for p in self._packages if p[1] != prefix or p[1] == __name__]
        self._entries = None

    def _load(self) -> dict[str, WorkedExample]:
        if self._entries is None:
            found: list[WorkedExample] = []
            for path, prefix in self._packages:
                for info in pkgutil.iter_modules(path):
                    module = importlib.import_module(f"{prefix}.{info.name}")
                    for entry in getattr(module, "EXAMPLES", ()):
                        if not isinstance(entry, WorkedExample):
                            raise RegistryError(
                                f"{module.__name__}.EXAMPLES holds {entry!r}, not a WorkedExample"
                            )
                        if not entry.module:
                            entry = dataclasses.replace(entry, module=module.__name__)
                        found.append(entry)
            found.sort(key=lambda e: (e.order, e.name))
            names = [e.name for e in found]
            figures = [f.name for e in found for f in e.figures]
            for what, seen in (("worked examples", names), ("figures", figures)):
                twice = sorted({n for n in seen if seen.count(n) > 1})
                if twice:
                    raise RegistryError(f"{what} declared twice: {', '.join(twice)}")
            self._entries = {e.name: e for e in found}
        return self._entries


WORKED: Mapping[str, WorkedExample] = _Registry()
"""The course's worked examples by name, in the book's order."""


def __getattr__(name: str) -> Any:
    """A worked example's module, imported on first use (``ut.worked.pa9``)."""
    if any(info.name == name for info in pkgutil.iter_modules(__path__)):
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def discover(package: str | None = None, *, remove: bool = False) -> list[str]:
    """Read the worked examples of another package too (or no more, with ``remove``).

    The registry reads the modules of :mod:`uio_teach.worked`; a course that
    keeps its own examples elsewhere (or a test) adds its package here, and
    every module of it with ``EXAMPLES`` joins the registry: the term config,
    the figures, the labs and the explorers then know them.

    Parameters
    ----------
    package : str, optional
        An importable package (``None``: just read the registry again).
    remove : bool
        Forget ``package`` instead.

    Returns
    -------
    list of str
        The names of the worked examples now registered.

    Examples
    --------
    >>> from uio_teach.worked import discover
    >>> discover()[:2]
    ['pa9', 'case_study']
    """
    registry = WORKED
    assert isinstance(registry, _Registry)
    if package is not None:
        if remove:
            registry.remove_package(package)
        else:
            module = importlib.import_module(package)
            registry.add_package(list(module.__path__), package)
    else:
        registry._entries = None
    return list(registry)


def run_from_config(name: str, config: Mapping[str, Any]) -> Any:
    """A worked example's experiment with the term config's values in place of its own.

    Every declared field of the experiment with a config key takes the
    config's value (``duration`` and ``samples`` remake the time grid); the
    key that the config leaves at its default gives the experiment's value.

    Parameters
    ----------
    name : str
        The worked example (a key of :data:`WORKED`).
    config : mapping
        Dotted config keys to validated values
        (``uio_teach.instructor.config.FigureConfig``).

    Returns
    -------
    Experiment

    Examples
    --------
    >>> from uio_teach.worked import run_from_config
    >>> run = run_from_config("pa9", {"pa9.sine.amplitude": 3.0, "pa9.duration": 5.0})
    >>> run.sine_amplitude, run.duration, run.samples
    (3.0, 5.0, 2001)
    """
    # deferred: the experiments read this registry (a cycle at import time)
    from ..experiments import experiment_params

    experiment = WORKED[name].run()
    values: dict[str, Any] = {}
    for field_name, spec in experiment_params(experiment):
        key = spec.config_key(name, field_name)
        if key is not None and key in config:
            value = config[key]
            if value is None and not spec.optional:
                continue
            values[field_name] = value
    return experiment.with_values(**values)
