"""The course's worked examples, one registry entry each: everything else derives from it.

A :class:`WorkedExample` names, for one worked example, its plant factory
(:mod:`uio_teach.examples`), its experiment (:mod:`uio_teach.experiments`), the
observer family its poles set, its figures, its explorer scenario and, when it
has one, its lab chapter. From these entries come

* the experiments by name (:data:`uio_teach.experiments.EXPERIMENTS`) and the
  plant of each lab (:func:`uio_teach.experiments.plant_from_params`);
* the tables of the term config (``uio_teach.instructor.config``): the
  experiment's declared fields, and the key that sets the observer's poles;
* the figures of ``uio-teach figures`` (``uio_teach.instructor.figures``), each
  drawn from the experiment with the config's values in place
  (:func:`run_from_config`);
* the explorer of each example (``WorkedExample.make_scenario``), whose sliders
  for physical parameters are the experiment's fields passed to the plant
  factory that declare a ``range``.

The entries live in the modules of this package, each holding a tuple
``EXAMPLES``; a new worked example is one new module here (see
:mod:`uio_teach.worked.quadruple_tank`), found when the registry is first read.

Examples
--------
>>> from uio_teach.worked import WORKED
>>> list(WORKED)
['pa9', 'case_study', 'missile', 'quadruple_tank']
>>> WORKED["quadruple_tank"].family, WORKED["pa9"].lab
('uio', 'lab_pa9.md')
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = ["WorkedExample", "FigureEntry", "WORKED", "resolve", "run_from_config"]

_GENERIC_SCENARIO = "uio_teach.explorers.scenarios:experiment_scenario"

FAMILIES = ("uio", "pmo")
"""The observer families whose poles a worked example's config key sets."""


def resolve(target: str) -> Any:
    """The object a ``"package.module:name"`` string names (imported on first use).

    Parameters
    ----------
    target : str

    Returns
    -------
    object

    Examples
    --------
    >>> from uio_teach.worked import resolve
    >>> resolve("uio_teach.examples:pa9")().name
    'PA9'
    """
    module, _, name = target.partition(":")
    obj: Any = importlib.import_module(module)
    for part in name.split("."):
        obj = getattr(obj, part)
    return obj


@dataclass(frozen=True)
class FigureEntry:
    """One output of ``uio-teach figures`` of a worked example.

    Attributes
    ----------
    name : str
        The file stem (and the name ``--only`` takes).
    description : str
        One line, shown by ``--list``.
    draw : str
        ``"module:function"`` of ``draw(runs) -> Figure`` (a table:
        ``draw(runs, folder) -> paths``), imported only when drawn, so that the
        registry does not load matplotlib.
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
    draw: str
    table: bool = False


@dataclass(frozen=True)
class WorkedExample:
    """A worked example of the course: the one declaration everything else reads.

    Attributes
    ----------
    name : str
        Its identifier: the table of the term config, the lab's id.
    title : str
        How the book names it.
    plant : str
        ``"module:function"`` of the plant factory; the experiment's fields
        listed in ``Experiment.plant_fields`` are passed to it as keywords.
    experiment : str
        ``"module:NAME"`` of the experiment (:mod:`uio_teach.experiments`).
    family : str
        The observer that the experiment's ``poles`` set: ``"uio"`` or
        ``"pmo"`` (``None`` poles of a PMO: the LMI gain).
    scenario : str or None
        ``"module:function"`` returning the explorer's scenario (``None``: made
        from the experiment and ``explorer`` by
        ``uio_teach.explorers.scenarios.experiment_scenario``).
    explorer : dict
        The explorer's options beyond the experiment's declarations (ranges of
        the poles, the channels of ``d``, ...; see ``experiment_scenario``).
    figures : tuple of FigureEntry
        Its outputs of ``uio-teach figures``, in order.
    lab : str or None
        The file name of its lab chapter in ``book/`` (``None``: no lab).
    order : int
        Its place among the worked examples (the book's order).

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
    plant: str
    experiment: str
    family: str
    scenario: str | None = None
    explorer: Mapping[str, Any] = field(default_factory=dict)
    figures: tuple[FigureEntry, ...] = ()
    lab: str | None = None
    order: int = 100

    def __post_init__(self) -> None:
        if self.family not in FAMILIES:
            raise ValueError(f"family must be one of {FAMILIES}, got {self.family!r}")

    def plant_factory(self) -> Callable[..., Any]:
        """The plant factory (imported on first use)."""
        return resolve(self.plant)

    def run(self) -> Any:
        """The experiment (imported on first use, looked up on every call)."""
        return resolve(self.experiment)

    def make_scenario(self, **plant_values: Any) -> Any:
        """The explorer's scenario; ``plant_values`` set physical parameters of the plant."""
        if self.scenario is None:
            return resolve(_GENERIC_SCENARIO)(self.name, **plant_values)
        return resolve(self.scenario)(**plant_values)

    def poles_key(self) -> str | None:
        """The config key that sets the observer's poles (``None``: not in the config)."""
        # deferred: the experiments read this registry (a cycle at import time)
        from ..experiments import experiment_params

        spec = dict(experiment_params(self.run())).get("poles")
        return None if spec is None else spec.config_key(self.name, "poles")


class _Registry(Mapping):
    """The worked examples by name, found in this package's modules on first use."""

    def __init__(self) -> None:
        self._entries: dict[str, WorkedExample] | None = None

    def _load(self) -> dict[str, WorkedExample]:
        if self._entries is None:
            found: list[WorkedExample] = []
            for info in pkgutil.iter_modules(__path__):
                module = importlib.import_module(f"{__name__}.{info.name}")
                found += list(getattr(module, "EXAMPLES", ()))
            found.sort(key=lambda e: (e.order, e.name))
            names = [e.name for e in found]
            twice = sorted({n for n in names if names.count(n) > 1})
            if twice:
                raise ValueError(f"worked examples declared twice: {', '.join(twice)}")
            self._entries = {e.name: e for e in found}
        return self._entries

    def __getitem__(self, name: str) -> WorkedExample:
        return self._load()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._load())

    def __len__(self) -> int:
        return len(self._load())

    def __repr__(self) -> str:
        return f"WORKED({', '.join(self)})"


WORKED: Mapping[str, WorkedExample] = _Registry()
"""The course's worked examples by name, in the book's order."""


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
