"""The figures' configuration: a schema of the keys an instructor may change, read from TOML.

The parameters that change from one term to the next (disturbance amplitude and
frequency, switching times and levels, observer poles, noise level, seed,
matplotlib style) live in a TOML file read by :func:`load_config` into a
validated, read-only :class:`FigureConfig`; :func:`default_config_toml` prints
the defaults, with a comment per key. The defaults of the worked experiments
come from :mod:`uio_teach.experiments`.

Examples
--------
>>> from uio_teach.instructor.config import FigureConfig
>>> FigureConfig()["pa9.poles"]
((-1+0j), (-2+0j), (-3+0j))
"""

from __future__ import annotations

import difflib
import math
import os
import tomllib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from .._display import format_poles
from ..errors import InputError, UIOTeachError
from ..existence import check_existence
from ..experiments import (
    EXPERIMENTS,
    MAX_DURATION,
    MAX_SAMPLES,
    MAX_SEED,
    MAX_STEPS,
    MAX_VALUE,
    Experiment,
    Param,
    experiment_params,
    number_text,
    out_of_bounds,
    pole_text,
)
from ..observers import design_pmo, design_uio
from ..worked import WORKED, RegistryView, run_from_config

__all__ = [
    "ConfigError",
    "FigureConfig",
    "load_config",
    "default_config_toml",
    "check_dpi",
    "config_schema",
    "config_tables",
    "ConfigKey",
    "design_observer",
    "OBSERVER_KEYS",
    "DPI_RANGE",
    "MAX_DURATION",
    "MAX_SAMPLES",
    "MAX_SEED",
    "MAX_STEPS",
    "MAX_VALUE",
]


class ConfigError(UIOTeachError, ValueError):
    """A configuration that cannot be used: one line per problem, each naming its key.

    Parameters
    ----------
    *problems : str
        One message per problem (the first is the exception's message when
        there is only one).

    Attributes
    ----------
    problems : list of str
        Every problem found, one line each, in the order of the file.

    Examples
    --------
    >>> from uio_teach.instructor.config import ConfigError
    >>> err = ConfigError("seed: must be >= 0, got -1", "pa9.samples: must be <= 200000")
    >>> print(err)
    seed: must be >= 0, got -1
    pa9.samples: must be <= 200000
    >>> err.problems[1]
    'pa9.samples: must be <= 200000'
    """

    def __init__(self, *problems: str) -> None:
        self.problems = [" ".join(str(p).split()) for p in problems]
        super().__init__("\n".join(self.problems))


DPI_RANGE = (20, 1200)
"""The resolutions ``uio-teach figures --dpi`` accepts (both ends included)."""
MAX_POLE = 1e5
"""The largest magnitude of a continuous-time pole (faster ones need a finer grid than allowed)."""


@dataclass(frozen=True)
class ConfigKey:
    """One key of the term config, derived from the ``Param`` of an experiment's field.

    Attributes
    ----------
    key : str
        The dotted key (``"pa9.sine.amplitude"``).
    kind : str
        ``"int"``, ``"float"``, ``"floats"``, ``"poles"`` or ``"str"``.
    default : object
        The course's value, as TOML writes it (``None``: absent by default).
    help : str
        The comment of ``--print-config``.
    minimum, maximum, positive, length, optional, discrete
        The bounds of :class:`~uio_teach.experiments.Param`.

    Examples
    --------
    >>> from uio_teach.instructor.config import config_schema
    >>> key = config_schema()["pa9.duration"]
    >>> key.kind, key.positive
    ('float', True)
    """

    key: str
    kind: str
    default: Any
    help: str
    minimum: float | None = None
    maximum: float | None = None
    positive: bool = False
    length: int | None = None
    optional: bool = False
    discrete: bool = False


def _toml_default(spec: Param, value: Any) -> Any:
    if value is None:
        return None
    if spec.kind == "poles":
        return [pole_text(p) for p in value]
    if spec.kind == "floats":
        return [float(v) + 0.0 for v in np.asarray(value, dtype=float).ravel()]
    if spec.kind == "int":
        return int(value)
    if spec.kind == "float":
        return float(value) + 0.0
    return value


def config_schema(
    experiments: Mapping[str, Experiment] | None = None,
) -> dict[str, ConfigKey]:
    """Every key of the term config, derived from the declared fields of the experiments.

    A field whose :class:`~uio_teach.experiments.Param` has ``config`` set
    becomes a key: its type, bounds and help come from the declaration, its
    default is the experiment's value. A key shared by several experiments
    (``seed``, ``style``) is declared alike in each. Global keys come first,
    then each experiment's table, its own keys before its subtables.

    Parameters
    ----------
    experiments : mapping, optional
        Table name to experiment (default: :data:`uio_teach.experiments.EXPERIMENTS`).

    Returns
    -------
    dict
        Dotted key to :class:`ConfigKey`, in the order of ``--print-config``.

    Examples
    --------
    >>> from uio_teach.instructor.config import config_schema
    >>> schema = config_schema()
    >>> schema["pa9.sine.frequency"].help, schema["pa9.sine.frequency"].default
    ("angular frequency, below the time grid's Nyquist frequency [rad/s]", 2.0)
    >>> list(schema)[:2]
    ['seed', 'style']
    """
    experiments = EXPERIMENTS if experiments is None else experiments
    found: dict[str, ConfigKey] = {}
    for section, experiment in experiments.items():
        for name, spec in experiment_params(experiment):
            key = spec.config_key(section, name)
            if key is None:
                continue
            entry = ConfigKey(
                key=key,
                kind="str" if spec.kind == "style" else spec.kind,
                default=_toml_default(spec, getattr(experiment, name)),
                help=spec.help,
                minimum=spec.minimum,
                maximum=spec.maximum,
                positive=spec.positive,
                length=spec.length,
                optional=spec.optional,
                discrete=spec.discrete,
            )
            if key in found and found[key] != entry:
                raise InputError(
                    f"the config key {key!r} is declared twice, differently: "
                    f"{found[key]} and {entry}"
                )
            found[key] = entry
    tables = config_tables(experiments)

    def order(key: str) -> tuple[int, int, int]:
        table = key.rpartition(".")[0]
        if not table:
            return (0, 0, 0)
        names = list(tables)
        section = table.split(".")[0]
        return (1, names.index(section), 0 if table == section else names.index(table))

    keys = sorted(found, key=lambda k: order(k) + (list(found).index(k),))
    return {k: found[k] for k in keys}


def config_tables(experiments: Mapping[str, Experiment] | None = None) -> dict[str, str]:
    """The tables of the term config and their comments (from the experiments' ``tables``).

    Parameters
    ----------
    experiments : mapping, optional
        Table name to experiment (default: :data:`uio_teach.experiments.EXPERIMENTS`).

    Returns
    -------
    dict

    Examples
    --------
    >>> from uio_teach.instructor.config import config_tables
    >>> config_tables()["pa9.sine"]
    'the sinusoidal disturbance'
    """
    experiments = EXPERIMENTS if experiments is None else experiments
    out: dict[str, str] = {}
    for section, experiment in experiments.items():
        docs = dict(experiment.tables)
        out[section] = docs.get("", section)
        for name, spec in experiment_params(experiment):
            key = spec.config_key(section, name)
            table = key.rpartition(".")[0] if key else ""
            if table.startswith(section + "."):
                out.setdefault(table, docs.get(table[len(section) + 1 :], table))
    return out


def _flatten(table: Mapping[str, Any], prefix: str = "") -> Iterable[tuple[str, Any]]:
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            if name in config_tables():
                yield from _flatten(value, name + ".")
            else:
                yield name, value
        else:
            yield name, value


def _describe(value: Any) -> str:
    if isinstance(value, str):
        return f"the string {value!r}"
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    return f"{type(value).__name__} {value!r}"


def _number(key: str, value: Any, what: str = "a number") -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(f"{key}: expected {what}, got {_describe(value)}")
    if not math.isfinite(value):
        raise ConfigError(f"{key}: expected a finite number, got {value}")
    return float(value)


def _bounds(key: str, opt: ConfigKey, x: float) -> None:
    problem = out_of_bounds(opt, x)
    if problem is not None:
        raise ConfigError(f"{key}: {problem}")


def _pole(key: str, value: Any) -> complex:
    if isinstance(value, str):
        try:
            z = complex(value.replace(" ", "").replace("i", "j"))
        except ValueError:
            raise ConfigError(
                f"{key}: cannot read the pole {value!r}; write a number, or a string such as "
                "'-1+2j' for a complex pole"
            ) from None
        if not (math.isfinite(z.real) and math.isfinite(z.imag)):
            raise ConfigError(f"{key}: poles must be finite, got {value!r}")
        return z
    return complex(_number(key, value, "a number or a string such as '-1+2j'"))


def _check_value(key: str, opt: ConfigKey, value: Any) -> Any:
    if opt.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{key}: expected an integer, got {_describe(value)}")
        _bounds(key, opt, value)
        return int(value)
    if opt.kind == "float":
        x = _number(key, value)
        _bounds(key, opt, x)
        return x
    if opt.kind == "str":
        if not isinstance(value, str):
            raise ConfigError(f"{key}: expected a string, got {_describe(value)}")
        return value
    if not isinstance(value, list):
        raise ConfigError(f"{key}: expected a list, e.g. {opt.default!r}, got {_describe(value)}")
    if not value:
        raise ConfigError(f"{key}: the list is empty")
    if opt.kind == "floats":
        xs = [_number(f"{key}[{i}]", v) for i, v in enumerate(value)]
        for x in xs:
            _bounds(key, opt, x)
        if opt.length is not None and len(xs) != opt.length:
            raise ConfigError(f"{key}: expected {opt.length} numbers, got {len(xs)}")
        return tuple(xs)
    # poles
    poles = tuple(_pole(f"{key}[{i}]", v) for i, v in enumerate(value))
    discrete = opt.discrete
    for z in poles:
        if not discrete and abs(z) > MAX_POLE:
            raise ConfigError(
                f"{key}: the pole {format_poles([z], 6)} is faster than {MAX_POLE:g} rad/s, "
                "more than the time grid can follow"
            )
    for z in poles:
        if discrete and not abs(z) < 1:
            raise ConfigError(
                f"{key}: the pole {format_poles([z], 6)} is unstable: a discrete-time observer "
                "needs |pole| < 1"
            )
        if not discrete and not z.real < 0:
            raise ConfigError(
                f"{key}: the pole {format_poles([z], 6)} is unstable: a continuous-time "
                "observer needs a negative real part"
            )
    return poles


class FigureConfig(Mapping[str, Any]):
    """The validated parameters of the figures: a read-only mapping from dotted keys to values.

    Build it with :func:`load_config` (from a TOML file) or
    :meth:`from_dict` (from a nested dict, as TOML would give); keys that are
    not given keep their defaults. Numbers are floats, lists are tuples,
    poles are complex.

    Parameters
    ----------
    values : mapping, optional
        Dotted keys (``"pa9.sine.amplitude"``) to already validated values;
        the defaults fill the rest. Use :meth:`from_dict` for unvalidated data.
    source : str
        Where the values came from (used in error messages).

    Attributes
    ----------
    source : str
        Where the values came from.
    given : frozenset of str
        The keys the source set (the rest are defaults); a lab takes only
        these from the config, and its own numbers for the rest.

    Examples
    --------
    >>> from uio_teach.instructor.config import FigureConfig
    >>> cfg = FigureConfig.from_dict({"pa9": {"sine": {"amplitude": 3}}})
    >>> sorted(cfg.given)
    ['pa9.sine.amplitude']
    >>> cfg["pa9.sine.amplitude"], cfg["pa9.sine.frequency"]
    (3.0, 2.0)
    >>> [p.real for p in cfg["pa9.poles"]]
    [-1.0, -2.0, -3.0]
    """

    def __init__(self, values: Mapping[str, Any] | None = None, source: str = "defaults") -> None:
        merged = {}
        for key, opt in config_schema().items():
            merged[key] = _check_value(key, opt, opt.default) if opt.default is not None else None
        merged.update(values or {})
        self._values = MappingProxyType(merged)
        self.source = source
        self.given = frozenset(values or {})

    @classmethod
    def from_dict(
        cls,
        data: Mapping[str, Any],
        source: str = "<dict>",
        base: str | os.PathLike[str] | None = None,
    ) -> FigureConfig:
        """Validate a nested dict (the parsed TOML) and fill in the defaults.

        Every key and value is checked, and every problem is reported at
        once, one line each.

        Parameters
        ----------
        data : mapping
            Tables and keys as in the TOML file, e.g.
            ``{"pa9": {"poles": [-2, -3, -4]}}``.
        source : str
            Name of the origin, put in front of error messages.
        base : str or path-like, optional
            The folder that relative file names (``style = "x.mplstyle"``)
            are read from: the configuration file's folder. Default: the
            current folder.

        Returns
        -------
        FigureConfig

        Raises
        ------
        ConfigError
            An unknown key, a value of the wrong type or out of its range, a
            bad length, an unstable pole, or poles an observer
            cannot have (wrong count, missing conjugate, ...). One line per
            problem, all of them (``err.problems``).

        Examples
        --------
        >>> from uio_teach.instructor.config import FigureConfig, ConfigError
        >>> try:
        ...     FigureConfig.from_dict({"pa9": {"poles": [1, -2, -3]}}, source="term.toml")
        ... except ConfigError as err:
        ...     print(str(err).split(": a ")[0])
        term.toml: pa9.poles: the pole 1 is unstable
        """
        problems: list[str] = []
        values: dict[str, Any] = {}
        schema, tables = config_schema(), config_tables()
        for key, value in _flatten(data):
            try:
                if key in tables:
                    raise ConfigError(f"{key}: expected a table [{key}], got {_describe(value)}")
                if key not in schema:
                    raise ConfigError(_unknown_key(key, isinstance(value, dict)))
                values[key] = _check_value(key, schema[key], value)
            except ConfigError as err:
                problems += err.problems
        if "style" in values:
            values["style"] = _resolve_style(values["style"], base)
        bad = {p.split(":", 1)[0].split("[", 1)[0] for p in problems}
        cfg = cls({k: v for k, v in values.items() if k not in bad}, source)
        problems += cfg._check_relations(skip=bad)
        problems += cfg._check_designs(skip=bad)
        if problems:
            raise ConfigError(*(f"{source}: {p}" for p in problems))
        return cfg

    def _check_relations(self, skip: set[str] = frozenset()) -> list[str]:
        """Problems between keys (lengths, order, Nyquist, files); keys in ``skip`` are bad."""
        problems = []
        times, values = self["pa9.piecewise.times"], self["pa9.piecewise.values"]
        if not {"pa9.piecewise.times", "pa9.piecewise.values"} & skip:
            if len(times) != len(values):
                problems.append(
                    f"pa9.piecewise: times and values must have the same length, got "
                    f"{len(times)} and {len(values)}"
                )
        if "pa9.piecewise.times" not in skip:
            if any(b <= a for a, b in zip(times, times[1:], strict=False)):
                problems.append(f"pa9.piecewise.times: must be strictly increasing, got {times}")
            elif "pa9.duration" not in skip and times and times[-1] >= self["pa9.duration"]:
                problems.append(
                    f"pa9.piecewise.times: {number_text(times[-1])} s is not before the end of "
                    f"the run (pa9.duration = {number_text(self['pa9.duration'])} s)"
                )
        if not {"pa9.samples", "pa9.duration", "pa9.sine.frequency"} & skip:
            nyquist = math.pi * (self["pa9.samples"] - 1) / self["pa9.duration"]
            if self["pa9.sine.frequency"] >= nyquist / 4:
                problems.append(
                    f"pa9.sine.frequency: {self['pa9.sine.frequency']:g} rad/s is too fast for "
                    f"the time grid (pa9.samples over pa9.duration): keep it below "
                    f"{nyquist / 4:.4g} rad/s, a quarter of the grid's Nyquist frequency"
                )
        if not {"case_study.v.hold", "case_study.steps"} & skip:
            if self["case_study.v.hold"] > self["case_study.steps"]:
                problems.append(
                    f"case_study.v.hold: {self['case_study.v.hold']} steps is longer than the run "
                    f"(case_study.steps = {self['case_study.steps']})"
                )
        style = self["style"]
        # matplotlib is heavy and only needed here: imported when a config is checked
        import matplotlib.style

        if "style" not in skip and style not in matplotlib.style.available and style != "default":
            path = Path(style)
            if path.suffix == ".mplstyle" or os.sep in style or "/" in style:
                if not path.is_file():
                    problems.append(f"style: no such file {style}")
            else:
                close = difflib.get_close_matches(style, matplotlib.style.available, 1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                problems.append(
                    f"style: {style!r} is neither a matplotlib style nor a .mplstyle file{hint}"
                )
        return problems

    def _check_designs(self, skip: set[str] = frozenset()) -> list[str]:
        """Design every observer once, so that bad poles are reported before any work."""
        problems = []
        for key in OBSERVER_KEYS:
            if key in skip:
                continue
            try:
                design_observer(self, key)
            except ConfigError as err:
                problems += [f"{key}: {p}" for p in err.problems]
            except ValueError as err:
                text = " ".join(str(err).split())
                text = text.removeprefix("poles: ")
                problems.append(f"{key}: {text}")
        return problems

    def __getitem__(self, key: str) -> Any:
        return self._values[key]

    def __iter__(self):
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __repr__(self) -> str:
        changed = {k: v for k, v in self.items() if v != FigureConfig._defaults().get(k)}
        return f"FigureConfig(source={self.source!r}, changed={changed})"

    @staticmethod
    def _defaults() -> dict[str, Any]:
        return {
            k: (None if o.default is None else _check_value(k, o, o.default))
            for k, o in config_schema().items()
        }


def _resolve_style(style: str, base: str | os.PathLike[str] | None) -> str:
    """A style file named relative to the configuration file, as an absolute path."""
    if style.endswith(".mplstyle") or "/" in style or os.sep in style:
        path = Path(style).expanduser()
        if not path.is_absolute() and base is not None:
            path = Path(base) / path
        return os.fspath(path.resolve())
    return style


def check_dpi(dpi: object) -> int:
    """The resolution ``dpi`` as an int, if it is within :data:`DPI_RANGE`.

    Parameters
    ----------
    dpi : int
        Dots per inch.

    Returns
    -------
    int

    Raises
    ------
    ConfigError
        Not an integer, or outside :data:`DPI_RANGE`.

    Examples
    --------
    >>> from uio_teach.instructor.config import check_dpi, ConfigError
    >>> check_dpi(150)
    150
    >>> try:
    ...     check_dpi(100000)
    ... except ConfigError as err:
    ...     print(err)
    dpi: must be between 20 and 1200, got 100000
    """
    low, high = DPI_RANGE
    if isinstance(dpi, bool) or not isinstance(dpi, int):
        raise ConfigError(f"dpi: expected an integer between {low} and {high}, got {dpi!r}")
    if not low <= dpi <= high:
        raise ConfigError(f"dpi: must be between {low} and {high}, got {dpi}")
    return dpi


def _unknown_key(key: str, table: bool = False) -> str:
    see = "`uio-teach figures --print-config` lists every key"
    if table:
        close = difflib.get_close_matches(key, list(config_tables()), 1, 0.5)
        hint = f" (did you mean [{close[0]}]?)" if close else ""
        return f"unknown table [{key}]{hint}; {see}"
    close = difflib.get_close_matches(key, list(config_schema()) + list(config_tables()), 1, 0.6)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return f"unknown key {key!r}{hint}; {see}"


def load_config(path: str | os.PathLike[str] | None = None) -> FigureConfig:
    """Read and validate a TOML configuration file (``None``: the defaults).

    Parameters
    ----------
    path : str or path-like, optional
        The TOML file. Every key is optional; see :func:`default_config_toml`.

    Returns
    -------
    FigureConfig

    Raises
    ------
    ConfigError
        The file cannot be read, is not valid TOML, or has bad values (one
        line per problem, each starting with the file name). A style file is
        looked up relative to the configuration file's folder.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.instructor.config import load_config
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = pathlib.Path(tmp) / "term.toml"
    ...     _ = path.write_text("[pa9.sine]\\namplitude = 0.5\\n")
    ...     load_config(path)["pa9.sine.amplitude"]
    0.5
    """
    if path is None:
        return FigureConfig()
    name = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise ConfigError(f"{name}: no such file") from None
    except OSError as err:
        raise ConfigError(f"{name}: cannot read it ({err.strerror or err})") from None
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{name}: not valid TOML: {' '.join(str(err).split())}") from None
    return FigureConfig.from_dict(data, source=name, base=Path(path).resolve().parent)


def _toml_value(value: Any) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def default_config_toml() -> str:
    """The default configuration as a commented TOML file, a starting point for a new term.

    Returns
    -------
    str

    Examples
    --------
    >>> import tomllib
    >>> from uio_teach.instructor.config import FigureConfig, default_config_toml
    >>> text = default_config_toml()
    >>> print(text.splitlines()[0])
    # Configuration of `uio-teach figures`. Every key is optional: delete what you do not change.
    >>> FigureConfig.from_dict(tomllib.loads(text)) == FigureConfig()
    True
    """
    lines = [
        "# Configuration of `uio-teach figures`. Every key is optional: delete what you do not "
        "change.",
        '# Complex poles are strings, e.g. poles = ["-1+1j", "-1-1j", -2].',
        "",
    ]
    section = ""
    tables = config_tables()
    for key, opt in config_schema().items():
        table, _, name = key.rpartition(".")
        if table != section:
            section = table
            lines += ["", f"[{table}]  # {tables[table]}"]
        if opt.default is None:
            lines.append(f"# {name} = [0.2]  # {opt.help}")
        else:
            lines.append(f"{name} = {_toml_value(opt.default)}  # {opt.help}")
    return "\n".join(lines) + "\n"


def _observer_keys(worked: Mapping[str, Any]) -> dict[str, str]:
    """The config keys that set an observer's poles, and their worked example."""
    keys = {name: entry.poles_key() for name, entry in worked.items()}
    return {key: name for name, key in keys.items() if key is not None}


OBSERVER_KEYS: Mapping[str, str] = RegistryView("OBSERVER_KEYS", _observer_keys)
"""The keys that set an observer's poles, and the worked example each belongs to (the
``poles`` field of each experiment of :data:`uio_teach.worked.WORKED`)."""


def design_observer(cfg: Mapping[str, Any], key: str) -> Any:
    """The observer that a poles key of the config sets (validated poles in, observer out).

    The worked example's observer family (``WorkedExample.family``)
    is designed for the plant of its experiment with the config's values in place
    (:func:`uio_teach.worked.run_from_config`: a physical parameter such as a
    valve changes the plant); a PMO without poles takes the LMI's gain.

    Parameters
    ----------
    cfg : mapping
        A validated configuration (:class:`FigureConfig`).
    key : str
        One of :data:`OBSERVER_KEYS`: ``"pa9.poles"`` (the UIO),
        ``"case_study.poles"`` (the PMO; absent: the LMI gain),
        ``"missile.pmo_poles"`` (the PMO), ``"quadruple_tank.poles"`` (the UIO).

    Returns
    -------
    Observer

    Raises
    ------
    ConfigError
        Not as many poles as the observer has movable ones, or no such
        observer for the plant (say why, from the existence check).
    ValueError
        Poles the observer cannot have (from the design).

    Examples
    --------
    >>> from uio_teach.instructor.config import FigureConfig, design_observer
    >>> design_observer(FigureConfig(), "missile.pmo_poles").L.shape
    (4, 2)
    """
    if key not in OBSERVER_KEYS:
        raise KeyError(f"{key!r} sets no observer; expected one of {', '.join(OBSERVER_KEYS)}")
    name = OBSERVER_KEYS[key]
    family = WORKED[name].family
    poles = cfg[key]
    run = run_from_config(name, cfg)
    plant = run.plant()
    report = check_existence(plant)
    if not report.ok:
        why = "; ".join(f"{c.name}: {c.reason}" for c in report.failed)
        specs = dict(experiment_params(run))
        given = [
            f"{specs[f].config_key(name, f)} = {number_text(getattr(run, f))}"
            for f in run.plant_fields
            if f in specs and specs[f].config_key(name, f)
        ]
        plant_text = f"the plant with {', '.join(given)}" if given else "this plant"
        raise ConfigError(f"no {family.upper()} exists for {plant_text} ({why})")
    if family == "pmo" and poles is None:
        return design_pmo(plant, method="lmi")
    _expect_count(key, poles, report.movable)
    design = design_uio if family == "uio" else design_pmo
    return design(plant, poles=list(poles))


def _expect_count(key: str, poles: Sequence[complex], movable: int) -> None:
    if len(poles) != movable:
        raise ConfigError(
            f"expected {movable} pole{'s' if movable != 1 else ''} (the movable poles of this "
            f"observer), got {len(poles)}"
        )
