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
and SVG files are left out (:func:`save_figure`). Each picture has its words beside it: what
it shows, in a text file of the same name (``pa9_sine.txt``), and in the file's own metadata.

Examples
--------
>>> import tempfile
>>> from uio_teach.instructor import figures
>>> "pa9_sine" in figures.FIGURES
True
>>> with tempfile.TemporaryDirectory() as tmp:
...     results = figures.generate(tmp, ["pa9_sine"], fmt="svg", dpi=50)
...     [path.name for path in results[0].paths]
['pa9_sine.svg', 'pa9_sine.txt']
"""

from __future__ import annotations

import difflib
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import matplotlib.style

from ..errors import InputError
from ..folders import MANIFEST, OutputError, StagedFolder, prepare_output_dir, write_manifest
from ..worked import WORKED, RegistryView, run_from_config
from .config import (
    ConfigError,
    FigureConfig,
    check_dpi,
    default_config_toml,
    design_observer,
    load_config,
)
from .output import FORMATS, save_description, save_figure

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


class _Runs:
    """What a worked example's figures ask for: its run, its observer, shared results.

    Each run is a worked experiment with the configuration's values in place of
    its own (:func:`uio_teach.worked.run_from_config`: every declared field
    with a config key, none mapped here by hand); each worked example's module
    draws its figures from these (``draw(runs)``).
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

    def observer(self, name: str) -> Any:
        """The observer of the worked example ``name`` with the config's poles (and plant)."""
        key = WORKED[name].poles_key()
        if key is None:
            raise InputError(f"the worked example {name!r} has no poles in the term config")
        return design_observer(self.cfg, key)


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


def _figures(worked: Mapping[str, Any]) -> dict[str, FigureSpec]:
    """The figures of every worked example of the registry, in its order."""
    out = {}
    for entry in worked.values():
        for fig in entry.figures:
            out[fig.name] = FigureSpec(fig.name, fig.description, fig.draw, fig.table)
    return out


FIGURES: Mapping[str, FigureSpec] = RegistryView("FIGURES", _figures)
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
    uio_teach.folders.OutputError
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
        raise InputError(f"fmt must be one of {', '.join(FORMATS)}, got {fmt!r}")
    dpi = check_dpi(dpi)
    wanted = list(FIGURES) if names is None else list(dict.fromkeys(names))
    unknown = [n for n in wanted if n not in FIGURES]
    if unknown:
        raise InputError(unknown_figure_message(unknown[0]))
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
                        picture = save_figure(fig, folder / f"{name}.{fmt}", fmt, dpi)
                        words = save_description(fig, picture)  # its text alternative
                        made = (picture,) if words is None else (picture, words)
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
