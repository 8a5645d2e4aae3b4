"""Regenerate every figure of the course, deterministically, from a small TOML configuration.

This module is what ``python -m uio_teach figures`` runs (see :mod:`uio_teach.cli`).
Each figure has a name and a one-line description in :data:`FIGURES`; the
numbers come from the package (:func:`uio_teach.simulate`,
:func:`uio_teach.reconstruct_input`, :func:`uio_teach.catch_time`), the
drawing from matplotlib's object API (no pyplot, no GUI backend).

The parameters an instructor changes from one term to the next (disturbance
amplitude and frequency, switching times and levels, observer poles, noise
level, seed, matplotlib style) live in a TOML file read by :func:`load_config`;
:func:`default_config_toml` prints the defaults, with a comment per key.

The same configuration gives byte-identical files: the noise is seeded, and
the time stamps and software names that matplotlib would write into PNG, PDF
and SVG files are left out (:func:`save_figure`).

Examples
--------
>>> import tempfile
>>> from uio_teach import figures
>>> "pa9_sine" in figures.FIGURES
True
>>> with tempfile.TemporaryDirectory() as tmp:
...     results = figures.generate(tmp, ["pa9_sine"], fmt="svg", dpi=50)
...     [path.name for path in results[0].paths]
['pa9_sine.svg']
"""

from __future__ import annotations

import difflib
import math
import os
import tempfile
import time
import tomllib
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "FORMATS",
    "FIGURES",
    "FigureSpec",
    "FigureResult",
    "FigureConfig",
    "ConfigError",
    "OutputError",
    "load_config",
    "default_config_toml",
    "prepare_output_dir",
    "save_figure",
    "generate",
]

FORMATS = ("png", "pdf", "svg")
"""The image formats :func:`save_figure` writes."""

CATCH_TOL = 0.02
"""Relative tolerance of the Table II catch times (2 % of the signal's peak)."""

_SVG_HASHSALT = "uio-teach"


class ConfigError(ValueError):
    """A configuration file that cannot be used; the message is one line and names the key."""


class OutputError(OSError):
    """The output folder cannot be created or written to."""


# configuration ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Option:
    kind: str  # "int", "float", "floats", "poles", "str"
    default: Any
    help: str
    minimum: float | None = None  # inclusive lower bound (numbers)
    positive: bool = False  # strictly positive (numbers)
    length: int | None = None  # exact length (lists)
    optional: bool = False  # may be absent (default None)


_SCHEMA: dict[str, _Option] = {
    "seed": _Option(
        "int", 4, "seed of every random number: PA9's measurement noise, the case study's v"
    ),
    "style": _Option(
        "str",
        "default",
        "matplotlib style: a name of matplotlib.style.available or a .mplstyle file",
    ),
    "pa9.poles": _Option("poles", [-1.0, -2.0, -3.0], "UIO poles (also the Luenberger poles)"),
    "pa9.duration": _Option("float", 10.0, "simulated time in s", positive=True),
    "pa9.samples": _Option("int", 2001, "number of time points", minimum=2),
    "pa9.initial_state": _Option("floats", [1.0, -1.0, 0.5], "plant state x(0)", length=3),
    "pa9.noise": _Option(
        "float", 0.0, "standard deviation of the measurement noise (0: none)", minimum=0.0
    ),
    "pa9.sine.amplitude": _Option("float", 1.0, "d(t) = amplitude sin(frequency t)"),
    "pa9.sine.frequency": _Option("float", 2.0, "angular frequency in rad/s", positive=True),
    "pa9.piecewise.times": _Option(
        "floats", [0.0, 2.0, 5.0, 7.5], "switching times in s, increasing", minimum=0.0
    ),
    "pa9.piecewise.values": _Option(
        "floats", [1.0, -1.5, 2.0, 0.0], "the level held from each switching time"
    ),
    "case_study.poles": _Option(
        "poles",
        None,
        "the one movable pole, e.g. [0.2]; absent: the LMI gain of the case study",
        optional=True,
    ),
    "case_study.steps": _Option("int", 40, "number of steps k = 0 ... steps", minimum=2),
    "case_study.initial_state": _Option("floats", [1.0, -2.0, 3.0], "plant state x[0]", length=3),
    "case_study.u2.amplitude": _Option("float", 2.0, "u2[k] = amplitude sin(frequency k)"),
    "case_study.u2.frequency": _Option(
        "float", 0.6, "angular frequency in rad per step", positive=True
    ),
    "case_study.v.amplitude": _Option(
        "float", 1.0, "v: a random staircase, levels uniform in [-amplitude, amplitude]", minimum=0
    ),
    "case_study.v.hold": _Option("int", 5, "steps each level of v is held", minimum=1),
    "missile.pmo_poles": _Option(
        "poles", [-100.0, -120.0], "PMO poles (the paper's are not given; see chapter 5)"
    ),
    "missile.duration": _Option("float", 0.3, "simulated time in s", positive=True),
    "missile.samples": _Option("int", 6001, "number of time points", minimum=2),
}

_DISCRETE_POLES = {"case_study.poles"}
_SECTION_HELP = {
    "pa9": "Practical Assignment 9: the decoupling observer and its lab",
    "pa9.sine": "the sinusoidal disturbance",
    "pa9.piecewise": "the piecewise-constant disturbance (0 before the first switching time)",
    "case_study": "the discrete-time case study (projection-operator observer)",
    "case_study.u2": "the unknown state input",
    "case_study.v": "the measurement disturbance",
    "missile": "the missile autopilot of De, Banerjee and Das (2014)",
}


def _flatten(table: Mapping[str, Any], prefix: str = "") -> Iterable[tuple[str, Any]]:
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            if name in _SECTION_HELP:
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


def _bounds(key: str, opt: _Option, x: float) -> None:
    if opt.positive and x <= 0:
        raise ConfigError(f"{key}: must be > 0, got {x:g}")
    if opt.minimum is not None and x < opt.minimum:
        raise ConfigError(f"{key}: must be >= {opt.minimum:g}, got {x:g}")


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


def _fmt_pole(z: complex, digits: int = 6) -> str:
    re_, im = float(np.round(z.real, 12)), float(np.round(z.imag, 12))
    if im == 0:
        return f"{re_:.{digits}g}"
    return f"{re_:.{digits}g}{im:+.{digits}g}j"


def _check_value(key: str, opt: _Option, value: Any) -> Any:
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
    discrete = key in _DISCRETE_POLES
    for z in poles:
        if discrete and not abs(z) < 1:
            raise ConfigError(
                f"{key}: the pole {_fmt_pole(z)} is unstable: a discrete-time observer needs "
                "|pole| < 1"
            )
        if not discrete and not z.real < 0:
            raise ConfigError(
                f"{key}: the pole {_fmt_pole(z)} is unstable: a continuous-time observer needs "
                "a negative real part"
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

    Examples
    --------
    >>> from uio_teach.figures import FigureConfig
    >>> cfg = FigureConfig.from_dict({"pa9": {"sine": {"amplitude": 3}}})
    >>> cfg["pa9.sine.amplitude"], cfg["pa9.sine.frequency"]
    (3.0, 2.0)
    >>> [p.real for p in cfg["pa9.poles"]]
    [-1.0, -2.0, -3.0]
    """

    def __init__(self, values: Mapping[str, Any] | None = None, source: str = "defaults") -> None:
        merged = {}
        for key, opt in _SCHEMA.items():
            merged[key] = _check_value(key, opt, opt.default) if opt.default is not None else None
        merged.update(values or {})
        self._values = MappingProxyType(merged)
        self.source = source

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<dict>") -> FigureConfig:
        """Validate a nested dict (the parsed TOML) and fill in the defaults.

        Parameters
        ----------
        data : mapping
            Tables and keys as in the TOML file, e.g.
            ``{"pa9": {"poles": [-2, -3, -4]}}``.
        source : str
            Name of the origin, put in front of error messages.

        Returns
        -------
        FigureConfig

        Raises
        ------
        ConfigError
            An unknown key, a value of the wrong type, a bad length, an
            unstable pole, or poles an observer cannot have (wrong count,
            missing conjugate, ...). The message is one line.

        Examples
        --------
        >>> from uio_teach.figures import FigureConfig, ConfigError
        >>> try:
        ...     FigureConfig.from_dict({"pa9": {"poles": [1, -2, -3]}}, source="term.toml")
        ... except ConfigError as err:
        ...     print(str(err).split(": a ")[0])
        term.toml: pa9.poles: the pole 1 is unstable
        """
        try:
            values = {}
            for key, value in _flatten(data):
                if key in _SECTION_HELP:
                    raise ConfigError(f"{key}: expected a table [{key}], got {_describe(value)}")
                if key not in _SCHEMA:
                    raise ConfigError(_unknown_key(key, isinstance(value, dict)))
                values[key] = _check_value(key, _SCHEMA[key], value)
            cfg = cls(values, source)
            cfg._check_relations()
            cfg._check_designs()
        except ConfigError as err:
            raise ConfigError(f"{source}: {err}") from None
        return cfg

    def _check_relations(self) -> None:
        times, values = self["pa9.piecewise.times"], self["pa9.piecewise.values"]
        if len(times) != len(values):
            raise ConfigError(
                f"pa9.piecewise: times and values must have the same length, got {len(times)} "
                f"and {len(values)}"
            )
        if any(b <= a for a, b in zip(times, times[1:], strict=False)):
            raise ConfigError(f"pa9.piecewise.times: must be strictly increasing, got {times}")
        style = self["style"]
        import matplotlib.style

        if style not in matplotlib.style.available and style != "default":
            path = Path(style)
            if not (path.suffix == ".mplstyle" and path.is_file()):
                close = difflib.get_close_matches(style, matplotlib.style.available, 1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                raise ConfigError(
                    f"style: {style!r} is neither a matplotlib style nor a .mplstyle file{hint}"
                )

    def _check_designs(self) -> None:
        """Design every observer once, so that bad poles are reported before any work."""
        for key in ("pa9.poles", "case_study.poles", "missile.pmo_poles"):
            try:
                _design(self, key)
            except ConfigError as err:
                raise ConfigError(f"{key}: {err}") from None
            except ValueError as err:
                text = " ".join(str(err).split())
                text = text.removeprefix("poles: ")
                raise ConfigError(f"{key}: {text}") from None

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
            for k, o in _SCHEMA.items()
        }


def _unknown_key(key: str, table: bool = False) -> str:
    see = "`uio-teach figures --print-config` lists every key"
    if table:
        close = difflib.get_close_matches(key, list(_SECTION_HELP), 1, 0.5)
        hint = f" (did you mean [{close[0]}]?)" if close else ""
        return f"unknown table [{key}]{hint}; {see}"
    close = difflib.get_close_matches(key, list(_SCHEMA) + list(_SECTION_HELP), 1, 0.6)
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
        The file cannot be read, is not valid TOML, or has a bad value (the
        message is one line, starting with the file name).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.figures import load_config
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
    return FigureConfig.from_dict(data, source=name)


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
    >>> from uio_teach.figures import FigureConfig, default_config_toml
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
    for key, opt in _SCHEMA.items():
        table, _, name = key.rpartition(".")
        if table != section:
            section = table
            lines += ["", f"[{table}]  # {_SECTION_HELP[table]}"]
        if opt.default is None:
            lines.append(f"# {name} = [0.2]  # {opt.help}")
        else:
            lines.append(f"{name} = {_toml_value(opt.default)}  # {opt.help}")
    return "\n".join(lines) + "\n"


# the simulations --------------------------------------------------------------------------------


def _design(cfg: Mapping[str, Any], key: str):
    """The observer that ``key`` configures (validated poles in, observer out)."""
    import uio_teach as ut

    poles = cfg[key]
    if key == "pa9.poles":
        plant = ut.examples.pa9()
        _expect_count(key, poles, ut.check_existence(plant).movable)
        return ut.design_uio(plant, poles=list(poles))
    if key == "case_study.poles":
        plant = ut.examples.dt_case_study()
        if poles is None:
            return ut.design_pmo(plant, method="lmi")
        _expect_count(key, poles, ut.check_existence(plant).movable)
        return ut.design_pmo(plant, poles=list(poles))
    if key == "missile.pmo_poles":
        plant = ut.examples.missile_autopilot()
        _expect_count(key, poles, ut.check_existence(plant).movable)
        return ut.design_pmo(plant, poles=list(poles))
    raise KeyError(key)  # pragma: no cover


def _expect_count(key: str, poles: Sequence[complex], movable: int) -> None:
    if len(poles) != movable:
        raise ConfigError(
            f"expected {movable} pole{'s' if movable != 1 else ''} (the movable poles of this "
            f"observer), got {len(poles)}"
        )


class _Runs:
    """Every simulation the figures need, computed once and shared (lazily)."""

    def __init__(self, cfg: FigureConfig) -> None:
        self.cfg = cfg

    # PA9 --------------------------------------------------------------------------------------
    @cached_property
    def pa9(self) -> dict[str, Any]:
        import uio_teach as ut

        c = self.cfg
        plant = ut.examples.pa9()
        uio = _design(c, "pa9.poles")
        luen = ut.design_luenberger(plant, poles=list(c["pa9.poles"]))
        t = np.linspace(0.0, c["pa9.duration"], c["pa9.samples"])
        u = ut.signals.stack(ut.signals.step(1.0), ut.signals.sinusoid(0.5, 1.0))
        d_sine = ut.signals.sinusoid(c["pa9.sine.amplitude"], c["pa9.sine.frequency"])
        d_steps = ut.signals.piecewise_constant(c["pa9.piecewise.times"], c["pa9.piecewise.values"])
        noise = c["pa9.noise"] or None

        def run(obs, d):
            return ut.simulate(
                plant,
                obs,
                t,
                u=u,
                d=d,
                initial_state=c["pa9.initial_state"],
                noise=noise,
                seed=c["seed"],
            )

        return {
            "plant": plant,
            "uio": uio,
            "d_sine": d_sine,
            "d_steps": d_steps,
            "uio_sine": run(uio, d_sine),
            "uio_steps": run(uio, d_steps),
            "luen_sine": run(luen, d_sine),
            "luen_steps": run(luen, d_steps),
        }

    # case study -------------------------------------------------------------------------------
    @cached_property
    def case(self) -> dict[str, Any]:
        import uio_teach as ut

        c = self.cfg
        plant = ut.examples.dt_case_study()
        pmo = _design(c, "case_study.poles")
        steps = np.arange(c["case_study.steps"] + 1, dtype=float)
        rng = np.random.default_rng(c["seed"])
        hold = c["case_study.v.hold"]
        switch = np.arange(0, steps[-1] + 1, hold)
        amp = c["case_study.v.amplitude"]
        v = ut.signals.piecewise_constant(switch, rng.uniform(-amp, amp, switch.size))
        u2 = ut.signals.sinusoid(c["case_study.u2.amplitude"], c["case_study.u2.frequency"])
        x0 = c["case_study.initial_state"]
        return {
            "plant": plant,
            "pmo": pmo,
            "loud": ut.simulate(plant, pmo, steps, d=u2, v=v, initial_state=x0),
            "quiet": ut.simulate(plant, pmo, steps, initial_state=x0),
        }

    # missile ----------------------------------------------------------------------------------
    @cached_property
    def missile(self) -> dict[str, Any]:
        import uio_teach as ut

        c = self.cfg
        plant = ut.examples.missile_autopilot()
        t = np.linspace(0.0, c["missile.duration"], c["missile.samples"])
        x0 = ut.examples.MISSILE_PUBLISHED.x0
        v = ut.examples.missile_inputs()
        out: dict[str, Any] = {"plant": plant, "time": t}
        out["free"] = ut.simulate(plant, ut.design_ginverse(plant), t, initial_state=x0)
        pmo = _design(c, "missile.pmo_poles")
        # Both observers start from q(0) = -M y(0): the PMO knows nothing at t = 0
        # (xhat(0) = 0) and the g-inverse observer reads the measured states. Started at
        # q(0) = 0 instead, the PMO would give the g-inverse's estimates whatever its poles
        # (chapter 5 explains both starts and Table II).
        q0 = -pmo.M @ plant.C @ x0
        for name, obs in (("pmo", pmo), ("ginverse", ut.design_ginverse(plant))):
            resp = ut.simulate(plant, obs, t, d=v, initial_state=x0, observer_state=q0)
            est = ut.reconstruct_input(plant, resp)
            out[name] = {
                "observer": obs,
                "response": resp,
                "inputs": est,
                "catch_states": ut.catch_time(t, resp.states, resp.estimates, tol=CATCH_TOL),
                "catch_inputs": ut.catch_time(t, resp.inputs.d, est.estimates, tol=CATCH_TOL),
            }
        return out


# drawing ----------------------------------------------------------------------------------------


def _new_figure(width: float = 8.0, height: float = 5.0) -> Figure:
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


def _poles_text(obs) -> str:
    return ", ".join(_fmt_pole(complex(p), 4) for p in obs.poles())


def _finish(ax, ylabel: str, legend: bool = True) -> None:
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    if legend:
        ax.legend(loc="upper right", fontsize="small")


def _pa9_disturbance(runs: _Runs, which: str) -> Figure:
    r = runs.pa9
    resp, d = r[f"uio_{which}"], r[f"d_{which}"]
    fig = _new_figure(8.0, 6.5)
    ax_d, ax_e, ax_r = fig.subplots(3, 1, sharex=True)
    t = resp.time
    ax_d.plot(t, resp.inputs.d[0], color="k")
    formula = repr(d)
    ax_d.set_title(f"d(t) = {formula if len(formula) <= 80 else formula[:77] + '...'}")
    _finish(ax_d, "disturbance $d$", legend=False)
    for i in range(resp.error.shape[0]):
        ax_e.plot(t, resp.error[i], label=f"$e_{i + 1}$")
    _finish(ax_e, r"error $e = x - \hat{x}$")
    for i in range(resp.residual.shape[0]):
        ax_r.plot(t, resp.residual[i], label=f"$r_{i + 1}$")
    _finish(ax_r, r"residual $r = y - C\hat{x}$")
    ax_r.set_xlabel("time (s)")
    kind = "sinusoidal" if which == "sine" else "piecewise-constant"
    fig.suptitle(f"PA9: UIO with a {kind} disturbance (poles {_poles_text(r['uio'])})")
    return fig


def _pa9_sine(runs: _Runs) -> Figure:
    return _pa9_disturbance(runs, "sine")


def _pa9_piecewise(runs: _Runs) -> Figure:
    return _pa9_disturbance(runs, "steps")


def _pa9_states(runs: _Runs) -> Figure:
    r = runs.pa9
    return r["uio_sine"].plot(
        fig=_new_figure(9.0, 6.0), title=f"PA9: UIO, sinusoidal disturbance d(t) = {r['d_sine']!r}"
    )


def _pa9_luenberger(runs: _Runs) -> Figure:
    r = runs.pa9
    fig = _new_figure(9.0, 5.5)
    axes = fig.subplots(2, 2, sharex=True, sharey="row")
    pairs = [
        ("UIO", r["uio_sine"], r["uio_steps"]),
        ("Luenberger observer", r["luen_sine"], r["luen_steps"]),
    ]
    for col, (name, sine, steps) in enumerate(pairs):
        for row, (what, sym, label) in enumerate(
            [("error", "e", "error $e$"), ("residual", "r", "residual $r$")]
        ):
            ax = axes[row, col]
            values = getattr(sine, what)
            for i in range(values.shape[0]):
                ax.plot(sine.time, values[i], color=f"C{i}", label=f"${sym}_{i + 1}$")
                ax.plot(steps.time, getattr(steps, what)[i], color=f"C{i}", linestyle="--")
            _finish(ax, label)
        axes[0, col].set_title(name)
        axes[1, col].set_xlabel("time (s)")
    fig.suptitle(
        f"PA9, poles {_poles_text(r['uio'])}: solid sinusoidal d, dashed piecewise-constant d"
    )
    return fig


def _case_response(runs: _Runs) -> Figure:
    r = runs.case
    return r["loud"].plot(
        fig=_new_figure(9.0, 6.0),
        title=f"Case study: PMO (poles {_poles_text(r['pmo'])}), unknown input u2 and "
        "disturbance v active",
    )


def _case_error(runs: _Runs) -> Figure:
    r = runs.case
    loud, quiet = r["loud"], r["quiet"]
    k = loud.time
    fig = _new_figure(8.0, 4.5)
    ax = fig.subplots()
    norm = np.linalg.norm(loud.error, axis=0)
    ax.semilogy(k, norm, "o", label=r"$\|e[k]\|$ with $u_2$ and $v$")
    ax.semilogy(k, np.linalg.norm(quiet.error, axis=0), "k+", label=r"$\|e[k]\|$ without them")
    rho = float(np.max(np.abs(r["pmo"].poles())))
    if rho > 0:
        ax.semilogy(k, norm[0] * rho**k, "--", label=rf"$\|e[0]\|\,{rho:.3g}^k$")
    ax.set_xlabel("step k")
    _finish(ax, r"$\|e[k]\|_2$")
    ax.set_title("Case study: the estimation error ignores both unknown signals")
    return fig


def _missile_states(runs: _Runs, name: str, label: str, figs: str) -> Figure:
    m = runs.missile
    resp, free = m[name]["response"], m["free"]
    fig = _new_figure(9.0, 6.0)
    axes = fig.subplots(2, 2, sharex=True)
    t = resp.time
    for i, ax in enumerate(axes.flat):
        ax.plot(t, resp.states[i], color="tab:red", label=f"$x_{i + 1}$ with $v$")
        ax.plot(t, free.states[i], color="tab:green", label=f"$x_{i + 1}$ without $v$")
        ax.plot(t, resp.estimates[i], color="k", linestyle=":", lw=2, label=rf"$\hat{{x}}_{i + 1}$")
        _finish(ax, f"$x_{i + 1}$")
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    fig.suptitle(
        f"Missile autopilot, {label} (poles {_poles_text(m[name]['observer'])}); the paper's {figs}"
    )
    return fig


def _missile_pmo(runs: _Runs) -> Figure:
    return _missile_states(runs, "pmo", "PMO", "Fig. 4.1-4.4")


def _missile_ginverse(runs: _Runs) -> Figure:
    return _missile_states(runs, "ginverse", "g-inverse observer", "Fig. 4.7-4.10")


def _missile_error(runs: _Runs) -> Figure:
    m = runs.missile
    fig = _new_figure(9.0, 6.0)
    axes = fig.subplots(2, 2, sharex=True)
    for i, ax in enumerate(axes.flat):
        for name, label, style in (("pmo", "PMO", "-"), ("ginverse", "g-inverse", "--")):
            resp = m[name]["response"]
            ax.plot(resp.time, resp.error[i], linestyle=style, label=label)
        _finish(ax, rf"$e_{i + 1} = x_{i + 1} - \hat{{x}}_{i + 1}$")
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    fig.suptitle("Missile autopilot: estimation error of both observers")
    return fig


def _missile_inputs(runs: _Runs) -> Figure:
    m = runs.missile
    fig = _new_figure(9.0, 5.5)
    axes = fig.subplots(2, 1, sharex=True)
    t = m["time"]
    actual = m["pmo"]["response"].inputs.d
    for i, ax in enumerate(axes):
        ax.plot(t, actual[i], color="tab:red", lw=2.5, alpha=0.6, label=f"$v_{i + 1}$")
        for name, label, style in (("pmo", "PMO", "-"), ("ginverse", "g-inverse", ":")):
            est = m[name]["inputs"].estimates[i]
            ax.plot(
                t, est, color="k", linestyle=style, lw=1.2, label=rf"$\hat{{v}}_{i + 1}$ {label}"
            )
        _finish(ax, f"$v_{i + 1}$")
        lim = 1.3 * float(np.max(np.abs(actual[i])))
        ax.set_ylim(-lim, lim)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(
        r"Missile autopilot: unknown inputs and their reconstructions "
        r"$\hat{v} = E^+(\dot{\hat{x}} - A\hat{x})$ (Fig. 4.5-4.6, 4.11-4.12)"
    )
    return fig


def _table2_rows(runs: _Runs) -> list[tuple[str, float, float, float, float]]:
    import uio_teach as ut

    m = runs.missile
    pub = ut.examples.MISSILE_PUBLISHED
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


def _table2(runs: _Runs, out: Path) -> list[Path]:
    rows = _table2_rows(runs)
    csv_path, md_path = out / "missile_table2.csv", out / "missile_table2.md"
    header = "signal,pmo_computed_s,pmo_paper_s,ginverse_computed_s,ginverse_paper_s"
    csv = [header] + [f"{s},{a:.4f},{b:.2f},{c:.4f},{d:.2f}" for s, a, b, c, d in rows]
    m = runs.missile
    md = [
        "Table II: time (s) after which each estimate stays within "
        f"{CATCH_TOL:.0%} of the signal's peak",
        "",
        f"PMO poles {_poles_text(m['pmo']['observer'])}; g-inverse observer poles "
        f"{_poles_text(m['ginverse']['observer'])}; simulated over {m['time'][-1]:g} s "
        f"({m['time'].size} time points).",
        "",
        "| signal | PMO, computed | PMO, paper | g-inverse, computed | g-inverse, paper |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    md += [f"| {s} | {a:.3f} | {b:.2f} | {c:.3f} | {d:.2f} |" for s, a, b, c, d in rows]
    for path, lines in ((csv_path, csv), (md_path, md)):
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return [csv_path, md_path]


@dataclass(frozen=True)
class FigureSpec:
    """One output of ``uio-teach figures``: a figure, or a table (``.csv`` and ``.md``).

    Attributes
    ----------
    name : str
        File stem and the name ``--only`` takes.
    description : str
        One line, shown by ``--list``.
    draw : callable
        ``draw(runs) -> Figure`` for a figure, ``draw(runs, out) -> list of
        paths`` for a table.
    table : bool
        True for a table (written as CSV and Markdown, whatever ``--format``).

    Examples
    --------
    >>> from uio_teach.figures import FIGURES
    >>> FIGURES["missile_table2"].table
    True
    """

    name: str
    description: str
    draw: Callable[..., Any] = field(repr=False)
    table: bool = False


FIGURES: Mapping[str, FigureSpec] = MappingProxyType(
    {
        spec.name: spec
        for spec in [
            FigureSpec(
                "pa9_sine",
                "PA9 lab: sinusoidal disturbance d(t), error e and residual r of the UIO",
                _pa9_sine,
            ),
            FigureSpec(
                "pa9_piecewise",
                "PA9 lab: piecewise-constant disturbance d(t), error e and residual r of the UIO",
                _pa9_piecewise,
            ),
            FigureSpec(
                "pa9_states",
                "PA9: each state with its UIO estimate, error and residual (sinusoidal d)",
                _pa9_states,
            ),
            FigureSpec(
                "pa9_luenberger",
                "PA9: UIO vs Luenberger observer, same poles, errors and residuals for both d",
                _pa9_luenberger,
            ),
            FigureSpec(
                "case_response",
                "Case study: states, estimates, error and residual with u2 and v both active",
                _case_response,
            ),
            FigureSpec(
                "case_error",
                "Case study: error norm on a log scale, with and without the unknown signals",
                _case_error,
            ),
            FigureSpec(
                "missile_pmo",
                "Missile: x1..x4 with/without v and the PMO estimates (paper Fig. 4.1-4.4)",
                _missile_pmo,
            ),
            FigureSpec(
                "missile_ginverse",
                "Missile: x1..x4 with/without v and the g-inverse estimates (Fig. 4.7-4.10)",
                _missile_ginverse,
            ),
            FigureSpec(
                "missile_error",
                "Missile: estimation error of the PMO and the g-inverse observer, per state",
                _missile_error,
            ),
            FigureSpec(
                "missile_inputs",
                "Missile: v1, v2 and their reconstructions by both observers (Fig. 4.5-4.6, "
                "4.11-4.12)",
                _missile_inputs,
            ),
            FigureSpec(
                "missile_table2",
                "Missile: Table II, catch times (tol 2 %) next to the paper's, as .csv and .md",
                _table2,
                table=True,
            ),
        ]
    }
)
"""Every output of ``uio-teach figures``, by name, in the order they are made."""


# writing ----------------------------------------------------------------------------------------


def save_figure(fig: Figure, path: str | os.PathLike[str], fmt: str, dpi: int = 150) -> Path:
    """Save a figure so that the same figure always gives the same bytes.

    PNG files get no ``Software`` entry, PDF files no ``CreationDate``, SVG
    files no ``Date``, and SVG element ids come from a fixed salt instead of
    a random one.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or path-like
        The file to write.
    fmt : {"png", "pdf", "svg"}
        The format.
    dpi : int
        Resolution (raster images and raster parts of vector files).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from matplotlib.figure import Figure
    >>> from uio_teach.figures import save_figure
    >>> fig = Figure(figsize=(2, 2))
    >>> _ = fig.subplots().plot([0, 1], [1, 0])
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     a = save_figure(fig, pathlib.Path(tmp) / "a.svg", "svg").read_bytes()
    ...     b = save_figure(fig, pathlib.Path(tmp) / "b.svg", "svg").read_bytes()
    >>> a == b
    True
    """
    import matplotlib

    if fmt not in FORMATS:
        raise ValueError(f"fmt must be one of {', '.join(FORMATS)}, got {fmt!r}")
    metadata = {
        "png": {"Software": None},
        "pdf": {"CreationDate": None, "ModDate": None},
        "svg": {"Date": None},
    }[fmt]
    with matplotlib.rc_context({"svg.hashsalt": _SVG_HASHSALT}):
        fig.savefig(path, format=fmt, dpi=dpi, metadata=metadata)
    return Path(path)


def prepare_output_dir(out: str | os.PathLike[str]) -> Path:
    """Create the output folder if needed and make sure files can be written into it.

    Parameters
    ----------
    out : str or path-like
        The folder.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    OutputError
        The folder cannot be created, is a file, or is not writable; the
        message is one line.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.figures import prepare_output_dir, OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     prepare_output_dir(pathlib.Path(tmp) / "new" / "folder").is_dir()
    True
    >>> with tempfile.NamedTemporaryFile() as f:
    ...     try:
    ...         prepare_output_dir(pathlib.Path(f.name) / "sub")
    ...     except OutputError as err:
    ...         print("cannot create" in str(err))
    True
    """
    path = Path(out)
    if path.exists() and not path.is_dir():
        raise OutputError(f"the output folder {os.fspath(path)} is a file, not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        reason = err.strerror or str(err)
        raise OutputError(f"cannot create the output folder {os.fspath(path)}: {reason}") from None
    try:
        with tempfile.NamedTemporaryFile(dir=path, prefix=".uio-teach-write-test-"):
            pass
    except OSError as err:
        reason = err.strerror or str(err)
        raise OutputError(
            f"cannot write to the output folder {os.fspath(path)}: {reason}"
        ) from None
    return path


@dataclass(frozen=True)
class FigureResult:
    """What :func:`generate` did for one figure.

    Attributes
    ----------
    name : str
        The figure's name.
    paths : tuple of pathlib.Path
        The files written (empty on failure).
    seconds : float
        Wall-clock time spent on it (its share of shared simulations included).
    error : str or None
        A one-line description of the failure, or ``None``.

    Examples
    --------
    >>> from uio_teach.figures import FigureResult
    >>> FigureResult("pa9_sine", (), 0.1, "ValueError: bad").ok
    False
    """

    name: str
    paths: tuple[Path, ...]
    seconds: float
    error: str | None = None

    @property
    def ok(self) -> bool:
        """True if the figure was written."""
        return self.error is None


def generate(
    out: str | os.PathLike[str],
    names: Sequence[str] | None = None,
    *,
    fmt: str = "png",
    dpi: int = 150,
    config: FigureConfig | None = None,
    progress: Callable[[int, int, FigureResult], None] | None = None,
) -> list[FigureResult]:
    """Make the figures ``names`` (all by default) into the folder ``out``.

    A figure that fails is reported in its :class:`FigureResult` and the
    others are still made.

    Parameters
    ----------
    out : str or path-like
        Output folder (created if needed).
    names : sequence of str, optional
        Names from :data:`FIGURES`; all of them by default.
    fmt : {"png", "pdf", "svg"}
        Image format (tables are always ``.csv`` and ``.md``).
    dpi : int
        Resolution.
    config : FigureConfig, optional
        The parameters; the defaults when omitted.
    progress : callable, optional
        Called as ``progress(index, total, result)`` after each figure
        (``index`` counts from 1).

    Returns
    -------
    list of FigureResult
        One per requested name, in the order of :data:`FIGURES`.

    Raises
    ------
    ValueError
        An unknown name, format or a non-positive ``dpi``.
    OutputError
        ``out`` cannot be created or written to.

    Examples
    --------
    >>> import tempfile
    >>> from uio_teach import figures
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     res = figures.generate(tmp, ["case_error"], dpi=40)
    ...     res[0].ok, res[0].paths[0].name
    (True, 'case_error.png')
    """
    import matplotlib.style

    if fmt not in FORMATS:
        raise ValueError(f"fmt must be one of {', '.join(FORMATS)}, got {fmt!r}")
    if isinstance(dpi, bool) or not isinstance(dpi, int) or dpi <= 0:
        raise ValueError(f"dpi must be a positive integer, got {dpi!r}")
    wanted = list(FIGURES) if names is None else list(dict.fromkeys(names))
    unknown = [n for n in wanted if n not in FIGURES]
    if unknown:
        raise ValueError(unknown_figure_message(unknown[0]))
    wanted = [n for n in FIGURES if n in wanted]
    folder = prepare_output_dir(out)
    cfg = config if config is not None else FigureConfig()
    runs = _Runs(cfg)
    results: list[FigureResult] = []
    for index, name in enumerate(wanted, start=1):
        spec = FIGURES[name]
        start = time.perf_counter()
        try:
            with matplotlib.style.context(cfg["style"]):
                if spec.table:
                    paths = tuple(spec.draw(runs, folder))
                else:
                    fig = spec.draw(runs)
                    paths = (save_figure(fig, folder / f"{name}.{fmt}", fmt, dpi),)
            result = FigureResult(name, paths, time.perf_counter() - start)
        except Exception as exc:  # one figure failing must not stop the others
            message = " ".join(str(exc).split()) or "no message"
            result = FigureResult(
                name, (), time.perf_counter() - start, f"{type(exc).__name__}: {message}"
            )
        results.append(result)
        if progress is not None:
            progress(index, len(wanted), result)
    return results


def unknown_figure_message(name: str) -> str:
    """The one-line message for a figure name that does not exist.

    Parameters
    ----------
    name : str
        The name that was asked for.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.figures import unknown_figure_message
    >>> unknown_figure_message("pa9_sin").split(";")[0]
    "unknown figure 'pa9_sin' (did you mean 'pa9_sine'?)"
    """
    close = difflib.get_close_matches(name, list(FIGURES), 1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return f"unknown figure {name!r}{hint}; `uio-teach figures --list` names them all"
