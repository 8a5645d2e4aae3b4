"""Regenerate every figure of the course, deterministically, from a small TOML configuration.

This module draws what ``uio-teach figures`` runs (see
:mod:`uio_teach.instructor.cli`).
Each figure has a name and a one-line description in :data:`FIGURES`, read
from the registry of worked examples (``uio_teach.worked.WORKED``): a worked
example lists its figures in its entry, and each is drawn from its experiment
with the config's values in place (``uio_teach.worked.run_from_config``); the
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
>>> from uio_teach.instructor import figures
>>> "pa9_sine" in figures.FIGURES
True
>>> with tempfile.TemporaryDirectory() as tmp:
...     results = figures.generate(tmp, ["pa9_sine"], fmt="svg", dpi=50)
...     [path.name for path in results[0].paths]
['pa9_sine.svg']
"""

from __future__ import annotations

import difflib
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib.style
import numpy as np

import uio_teach as ut

from .._display import format_poles
from ..plotting import (
    finish_panel,
    new_figure,
    plot_error,
    plot_residual,
    residual_colors,
    symbol,
    time_label,
    with_unit,
    zero_to_rounding,
)
from ..worked import WORKED, resolve, run_from_config
from .config import (
    ConfigError,
    FigureConfig,
    check_dpi,
    default_config_toml,
    design_observer,
    load_config,
)
from .output import (
    FORMATS,
    MANIFEST,
    OutputError,
    StagedFolder,
    prepare_output_dir,
    save_figure,
    write_manifest,
)

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "FORMATS",
    "MANIFEST",
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
    "check_dpi",
    "generate",
]

CATCH_TOL = 0.02
"""Relative tolerance of the Table II catch times (2 % of the signal's peak)."""


class _Runs:
    """Every simulation the figures need, computed once and shared (lazily).

    Each run is a worked experiment with the configuration's values in place of
    its own (:func:`uio_teach.worked.run_from_config`: every declared field
    with a config key, none mapped here by hand).
    """

    def __init__(self, cfg: FigureConfig) -> None:
        self.cfg = cfg

    def run(self, name: str) -> Any:
        """The experiment of the worked example ``name`` with the config's values."""
        return run_from_config(name, self.cfg)

    def shared(self, key: str, compute: Callable[[], Any]) -> Any:
        """``compute()`` once for all the figures that ask for ``key`` (a worked example's runs)."""
        cache = self.__dict__.setdefault("_shared", {})
        if key not in cache:
            cache[key] = compute()
        return cache[key]

    # PA9 --------------------------------------------------------------------------------------
    @cached_property
    def pa9(self) -> dict[str, Any]:
        c = self.cfg
        run = self.run("pa9")
        plant = run.plant()
        uio = design_observer(c, "pa9.poles")
        luen = ut.design_luenberger(plant, poles=list(run.poles))
        d_sine, d_steps = run.d_sine, run.d_piecewise
        return {
            "plant": plant,
            "uio": uio,
            "d_sine": d_sine,
            "d_steps": d_steps,
            "uio_sine": run.simulate(uio, d=d_sine),
            "uio_steps": run.simulate(uio, d=d_steps),
            "luen_sine": run.simulate(luen, d=d_sine),
            "luen_steps": run.simulate(luen, d=d_steps),
        }

    # case study -------------------------------------------------------------------------------
    @cached_property
    def case(self) -> dict[str, Any]:
        run = self.run("case_study")
        pmo = design_observer(self.cfg, "case_study.poles")
        return {
            "plant": run.plant(),
            "pmo": pmo,
            "loud": run.simulate(pmo),
            "quiet": run.simulate(pmo, d=None, v=None),
        }

    # missile ----------------------------------------------------------------------------------
    @cached_property
    def missile(self) -> dict[str, Any]:
        run = self.run("missile")
        plant, t = run.plant(), run.timepts
        out: dict[str, Any] = {"plant": plant, "time": t}
        ginverse = ut.design_ginverse(plant)
        out["free"] = run.simulate(ginverse, d=None, observer_state=None)
        pmo = design_observer(self.cfg, "missile.pmo_poles")
        # Both observers start from q(0) = -M y(0): the PMO knows nothing at t = 0
        # (xhat(0) = 0) and the g-inverse observer reads the measured states. Started at
        # q(0) = 0 instead, the PMO would give the g-inverse's estimates whatever its poles
        # (chapter 5 explains both starts and Table II).
        q0 = run.observer_state(pmo)
        for name, obs in (("pmo", pmo), ("ginverse", ginverse)):
            resp = run.simulate(obs, observer_state=q0)
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


def _poles_text(obs) -> str:
    return format_poles(obs.poles(), 4)


def _pa9_disturbance(runs: _Runs, which: str) -> Figure:
    r = runs.pa9
    resp, d = r[f"uio_{which}"], r[f"d_{which}"]
    fig = new_figure(8.0, 6.5)
    ax_d, ax_e, ax_r = fig.subplots(3, 1, sharex=True)
    t = resp.time
    ax_d.plot(t, resp.inputs.d[0], color="k")
    formula = repr(d)
    ax_d.set_title(f"d(t) = {formula if len(formula) <= 80 else formula[:77] + '...'}")
    finish_panel(ax_d, with_unit("disturbance $d$"), legend=False)
    plot_error(ax_e, resp)
    plot_residual(ax_r, resp)
    ax_r.set_xlabel(time_label(resp.plant.dt))
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
        fig=new_figure(9.0, 6.0), title=f"PA9: UIO, sinusoidal disturbance d(t) = {r['d_sine']!r}"
    )


def _pa9_luenberger(runs: _Runs) -> Figure:
    r = runs.pa9
    fig = new_figure(9.0, 5.5)
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
            colors = (
                residual_colors(sine.plant.C)
                if what == "residual"
                else [f"C{i}" for i in range(values.shape[0])]
            )
            for i in range(values.shape[0]):
                ax.plot(sine.time, values[i], color=colors[i], label=symbol(sym, i))
                ax.plot(steps.time, getattr(steps, what)[i], color=colors[i], linestyle="--")
            finish_panel(ax, label)
        axes[0, col].set_title(name)
        axes[1, col].set_xlabel(time_label(r["plant"].dt))
    fig.suptitle(
        f"PA9, poles {_poles_text(r['uio'])}: solid sinusoidal d, dashed piecewise-constant d"
    )
    return fig


def _case_response(runs: _Runs) -> Figure:
    r = runs.case
    return r["loud"].plot(
        fig=new_figure(9.0, 6.0),
        title=f"Case study: PMO (poles {_poles_text(r['pmo'])}), unknown input u2 and "
        "disturbance v active",
    )


def _case_error(runs: _Runs) -> Figure:
    r = runs.case
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
    return fig


def _missile_states(runs: _Runs, name: str, label: str, figs: str) -> Figure:
    m = runs.missile
    resp, free = m[name]["response"], m["free"]
    fig = new_figure(9.0, 6.0)
    axes = fig.subplots(2, 2, sharex=True)
    t = resp.time
    for i, ax in enumerate(axes.flat):
        ax.plot(t, resp.states[i], color="tab:red", label=f"{symbol('x', i)} with $v$")
        ax.plot(t, free.states[i], color="tab:green", label=f"{symbol('x', i)} without $v$")
        hat = symbol("x", i, hat=True)
        ax.plot(t, resp.estimates[i], color="k", linestyle=":", lw=2, label=hat)
        finish_panel(ax, with_unit(symbol("x", i)))
    for ax in axes[1]:
        ax.set_xlabel(time_label(m["plant"].dt))
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
    fig = new_figure(9.0, 6.0)
    axes = fig.subplots(2, 2, sharex=True)
    for i, ax in enumerate(axes.flat):
        errors = []
        for name, label, style in (("pmo", "PMO", "-"), ("ginverse", "g-inverse", "--")):
            resp = m[name]["response"]
            ax.plot(resp.time, resp.error[i], linestyle=style, label=label)
            errors.append(resp.error[i])
        finish_panel(ax, with_unit(rf"$e_{i + 1} = x_{i + 1} - \hat{{x}}_{i + 1}$"))
        # a measured state is estimated exactly: its error is rounding noise, shown on zero
        scale = float(np.max(np.abs(m["pmo"]["response"].states[i])))
        zero_to_rounding(ax, np.array(errors), scale)
    for ax in axes[1]:
        ax.set_xlabel(time_label(m["plant"].dt))
    fig.suptitle("Missile autopilot: estimation error of both observers")
    return fig


def _missile_inputs(runs: _Runs) -> Figure:
    m = runs.missile
    fig = new_figure(9.0, 5.5)
    axes = fig.subplots(2, 1, sharex=True)
    t = m["time"]
    actual = m["pmo"]["response"].inputs.d
    for i, ax in enumerate(axes):
        ax.plot(t, actual[i], color="tab:red", lw=2.5, alpha=0.6, label=symbol("v", i))
        for name, label, style in (("pmo", "PMO", "-"), ("ginverse", "g-inverse", ":")):
            est = m[name]["inputs"].estimates[i]
            hat = symbol("v", i, hat=True)
            ax.plot(t, est, color="k", linestyle=style, lw=1.2, label=f"{hat} {label}")
        finish_panel(ax, with_unit(symbol("v", i)))
        lim = 1.3 * float(np.max(np.abs(actual[i])))
        ax.set_ylim(-lim, lim)
    axes[-1].set_xlabel(time_label(m["plant"].dt))
    fig.suptitle(
        r"Missile autopilot: unknown inputs and their reconstructions "
        r"$\hat{v} = E^+(\dot{\hat{x}} - A\hat{x})$ (Fig. 4.5-4.6, 4.11-4.12)"
    )
    return fig


def _table2_rows(runs: _Runs) -> list[tuple[str, float, float, float, float]]:
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
    >>> from uio_teach.instructor.figures import FIGURES
    >>> FIGURES["missile_table2"].table
    True
    """

    name: str
    description: str
    draw: Callable[..., Any] = field(repr=False)
    table: bool = False


class _Figures(Mapping):
    """The figures of every worked example of the registry, in its order (read on use)."""

    def _items(self) -> dict[str, FigureSpec]:
        out = {}
        for entry in WORKED.values():
            for fig in entry.figures:
                out[fig.name] = FigureSpec(fig.name, fig.description, resolve(fig.draw), fig.table)
        return out

    def __getitem__(self, name: str) -> FigureSpec:
        return self._items()[name]

    def __iter__(self):
        return iter(self._items())

    def __len__(self) -> int:
        return len(self._items())

    def __repr__(self) -> str:
        return f"FIGURES({', '.join(self)})"


FIGURES: Mapping[str, FigureSpec] = _Figures()
"""Every output of ``uio-teach figures``, by name, in the order they are made."""


@dataclass(frozen=True)
class FigureResult:
    """What :func:`generate` did for one figure.

    Attributes
    ----------
    name : str
        The figure's name.
    paths : tuple
        The files written, as ``pathlib.Path`` (empty on failure).
    seconds : float
        Wall-clock time spent on it (its share of shared simulations included).
    error : str or None
        A one-line description of the failure, or ``None``.

    Examples
    --------
    >>> from uio_teach.instructor.figures import FigureResult
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

    All or nothing: the files are written into a temporary folder beside
    ``out`` and swapped in only when every figure was made, together with a
    manifest, ``manifest.json`` (the configuration as used
    and its hash, the versions, each file's SHA-256). The new folder replaces
    the old one whole, so no file of an earlier run is left. A figure that
    fails is reported in its :class:`FigureResult` and the others are still
    tried, but then nothing is written and an existing ``out`` is left exactly
    as it was (as after an exception or Ctrl-C).

    Parameters
    ----------
    out : str or path-like
        Output folder: created, or replaced if it holds an earlier output
        (a manifest of uio-teach) or nothing.
    names : sequence of str, optional
        Names from :data:`FIGURES`; all of them by default.
    fmt : {"png", "pdf", "svg"}
        Image format (tables are always ``.csv`` and ``.md``).
    dpi : int
        Resolution, within ``DPI_RANGE`` (20 to 1200).
    config : FigureConfig, optional
        The parameters; the defaults when omitted.
    progress : callable, optional
        Called as ``progress(index, total, result)`` after each figure
        (``index`` counts from 1).

    Returns
    -------
    list of FigureResult
        One per requested name, in the order of :data:`FIGURES`; the paths
        are those in ``out``.

    Raises
    ------
    ValueError
        An unknown name or format, or a ``dpi`` out of range.
    uio_teach.instructor.output.OutputError
        ``out`` cannot be created or written to, or is a folder that does not
        look like an earlier output (not empty, no manifest).

    Examples
    --------
    >>> import tempfile
    >>> from uio_teach.instructor import figures
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     res = figures.generate(tmp, ["case_error"], dpi=40)
    ...     res[0].ok, res[0].paths[0].name
    (True, 'case_error.png')
    """
    if fmt not in FORMATS:
        raise ValueError(f"fmt must be one of {', '.join(FORMATS)}, got {fmt!r}")
    dpi = check_dpi(dpi)
    wanted = list(FIGURES) if names is None else list(dict.fromkeys(names))
    unknown = [n for n in wanted if n not in FIGURES]
    if unknown:
        raise ValueError(unknown_figure_message(unknown[0]))
    wanted = [n for n in FIGURES if n in wanted]
    target = Path(out)
    cfg = config if config is not None else FigureConfig()
    runs = _Runs(cfg)
    results: list[FigureResult] = []
    with StagedFolder(target, "figures", command="uio-teach figures") as stage:
        folder = stage.path
        for index, name in enumerate(wanted, start=1):
            spec = FIGURES[name]
            start = time.perf_counter()
            try:
                with matplotlib.style.context(cfg["style"]):
                    if spec.table:
                        made = tuple(spec.draw(runs, folder))
                    else:
                        fig = spec.draw(runs)
                        made = (save_figure(fig, folder / f"{name}.{fmt}", fmt, dpi),)
                for _ in made:
                    stage.written()
                paths = tuple(target / path.name for path in made)
                result = FigureResult(name, paths, time.perf_counter() - start)
            except Exception as exc:  # one figure failing must not stop the others
                message = " ".join(str(exc).split()) or "no message"
                result = FigureResult(
                    name, (), time.perf_counter() - start, f"{type(exc).__name__}: {message}"
                )
            results.append(result)
            if progress is not None:
                progress(index, len(wanted), result)
        if all(r.ok for r in results):
            options = {"figures": wanted, "format": fmt, "dpi": dpi, "config_file": cfg.source}
            write_manifest(folder, command="uio-teach figures", config=cfg, options=options)
            stage.written()
            stage.commit()
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
    >>> from uio_teach.instructor.figures import unknown_figure_message
    >>> unknown_figure_message("pa9_sin").split(";")[0]
    "unknown figure 'pa9_sin' (did you mean 'pa9_sine'?)"
    """
    close = difflib.get_close_matches(name, list(FIGURES), 1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return f"unknown figure {name!r}{hint}; `uio-teach figures --list` names them all"
