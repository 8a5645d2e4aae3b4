"""Write the lab notebooks of a term into one folder, all or nothing.

:func:`write_labs` builds, for every lab chapter of the book (and every group
with ``groups``), the student and the solution notebook
(:func:`~uio_teach.instructor.lab_notebook.make_notebook`) with the term's
numbers or the group's variant (:mod:`~uio_teach.instructor.variants`), and
writes them with the answer key through one
:class:`~uio_teach.folders.StagedFolder`: a run that fails or is
killed leaves the folder as it was, a finished run replaces it whole (no
notebook of an earlier run is left) and adds ``manifest.json``.

The builder, the registry of the labs and this writer are three modules:
:mod:`~uio_teach.instructor.lab_notebook`, :mod:`~uio_teach.instructor.lab_registry`
and this one; the names most used are also importable from here.

Examples
--------
>>> import tempfile, pathlib
>>> from uio_teach.instructor.labs import write_labs
>>> with tempfile.TemporaryDirectory() as tmp:
...     results = write_labs(pathlib.Path(tmp) / "labs")
...     sorted(p.name for p in (pathlib.Path(tmp) / "labs").iterdir())
['manifest.json', 'solution', 'student']
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UIOTeachWarning
from ..folders import MANIFEST, StagedFolder, default_book_dir, write_manifest
from . import lab_registry
from .book import BookIndex
from .config import config_schema
from .lab_notebook import (
    LAB_PATTERN,
    TODO_TAG,
    VERSIONS,
    find_labs,
    make_notebook,
    params_source,
)
from .lab_registry import Lab, LabError, LabUsageError, lab_of
from .variants import ANSWER_KEY, draw_variants, write_answer_key

__all__ = [
    "UNREAD_CONFIG_KEYS",
    "UnreadKeys",
    "ANSWER_KEY",
    "MANIFEST",
    "VERSIONS",
    "LABS",
    "Lab",
    "LabError",
    "LabUsageError",
    "BookIndex",
    "LabResult",
    "ConfigNotKeptWarning",
    "config_notes",
    "unused_config_keys",
    "draw_variants",
    "lab_of",
    "params_source",
    "write_answer_key",
    "default_book_dir",
    "find_labs",
    "make_notebook",
    "write_labs",
]


@dataclass(frozen=True)
class UnreadKeys:
    """Keys of the term config that a lab's notebooks are given (in PARAMS) but do not read.

    Attributes
    ----------
    keys : tuple of str
        The config keys.
    labs : tuple of str
        The labs (ids of :data:`LABS`) whose notebooks do not read them.
    why : str
        The reason, for the help and the instructors' page.

    Examples
    --------
    >>> from uio_teach.instructor.labs import UNREAD_CONFIG_KEYS
    >>> UNREAD_CONFIG_KEYS[0].text().split(":")[0]
    'pa9.noise and seed (pa9)'
    """

    keys: tuple[str, ...]
    labs: tuple[str, ...]
    why: str

    def text(self) -> str:
        """One sentence: the keys, the labs, why."""
        labs = "every lab" if set(self.labs) == set(LABS) else " and ".join(self.labs)
        return f"{' and '.join(self.keys)} ({labs}): {self.why}"


COMMAND = "uio-teach labs"
"""The command recorded in the manifest of a labs folder."""


class ConfigNotKeptWarning(UIOTeachWarning):
    """A value of the term config that the labs do not keep: drawn per group, or never read."""


def config_notes(lab: Lab, config: Mapping[str, Any], groups: bool) -> list[str]:
    """What the labs do with the values of ``config`` that differ from the course's, when not kept.

    A value is kept when it reaches every notebook of the lab as configured. It
    is not kept when the lab's notebooks do not read it (``UNREAD_CONFIG_KEYS``)
    or, with ``groups``, when each group's variant draws the field anew (the
    fields of ``lab.params.vary``): then it is said, one line per key, never
    dropped unseen.

    Parameters
    ----------
    lab : Lab
        The lab.
    config : mapping
        The term config.
    groups : bool
        Whether the labs are drawn per group.

    Returns
    -------
    list of str

    Examples
    --------
    >>> from uio_teach.instructor.config import FigureConfig
    >>> from uio_teach.instructor.labs import LABS, config_notes
    >>> cfg = FigureConfig.from_dict({"pa9": {"poles": [-2, -3, -4]}})
    >>> print(config_notes(LABS["pa9"], cfg, groups=True)[0])
    pa9.poles = [-2, -3, -4] is not kept: each group's variant of the pa9 lab draws its own
    """
    schema = config_schema()
    course = lab.params()
    base = lab.params.from_config(config)
    set_keys = {}
    for name, spec in lab.params.declared():
        key = spec.config_key(lab.id, name)
        if key is not None and key in config and getattr(base, name) != getattr(course, name):
            set_keys[key] = name
    for key in ("seed", "style"):  # shared keys that a lab may not declare
        if key in config and key in schema and config[key] != schema[key].default:
            set_keys.setdefault(key, key)
    notes = []
    if groups:
        drawn = set(lab.params.vary(np.random.default_rng(0), base))
        for key, name in set_keys.items():
            if name in drawn:
                notes.append(
                    f"{key} = {_shown(config[key])} is not kept: each group's variant of the "
                    f"{lab.id} lab draws its own"
                )
    for entry in UNREAD_CONFIG_KEYS:
        if lab.id in entry.labs:
            given = [k for k in entry.keys if k in set_keys]
            if given:
                verb, them = ("reach", "them") if len(given) > 1 else ("reaches", "it")
                notes.append(
                    f"{' and '.join(given)} of the term config {verb} the {lab.id} lab's "
                    f"PARAMS, but its notebooks do not read {them}: {entry.why}"
                )
    return notes


def unused_config_keys(config: Mapping[str, Any]) -> list[str]:
    """The keys ``config`` sets that no lab uses, one sentence each, by name.

    A key set in the term config reaches the labs' ``PARAMS`` when a lab's
    parameter class reads it (``config_keys()``: its experiment's fields with
    ``lab=True``, and what its ``from_config`` reads besides);
    the others set only the figures and the explorers (a worked example
    without a lab, or a field its lab does not ask about). ``uio-teach labs``
    prints these sentences, so that no configured value is dropped unseen.

    Parameters
    ----------
    config : mapping
        The term config (a ``FigureConfig`` says which keys it was given;
        a plain mapping sets every key it has).

    Returns
    -------
    list of str

    Examples
    --------
    >>> from uio_teach.instructor.config import FigureConfig
    >>> from uio_teach.instructor.labs import unused_config_keys
    >>> cfg = FigureConfig.from_dict({"quadruple_tank": {"gamma1": 0.8}, "pa9": {"noise": 0.1}})
    >>> print(unused_config_keys(cfg)[0])  # doctest: +ELLIPSIS
    quadruple_tank.gamma1 of the term config is used by no lab (quadruple_tank has none): it ...
    """
    used = {key for lab in LABS.values() for key in lab.params.config_keys()}
    given = getattr(config, "given", None)
    keys = sorted(given) if given is not None else sorted(config)
    notes = []
    for key in keys:
        if key in used:
            continue
        table = key.split(".", 1)[0]
        whose = (
            f"the {table} lab does not ask for it"
            if table in LABS
            else f"{table} has none"
            if "." in key
            else "no lab declares it"
        )
        notes.append(
            f"{key} of the term config is used by no lab ({whose}): it sets the figures and "
            "explorers only"
        )
    return notes


def _shown(value: Any) -> str:
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    if isinstance(value, complex):
        return f"{value.real:g}" if value.imag == 0 else f"{value:g}"
    if isinstance(value, float):
        return f"{value:g}"
    return repr(value) if isinstance(value, str) else str(value)


LABS: Mapping[str, Lab] = lab_registry.LABS
"""The labs of the course, by id (``uio_teach.instructor.lab_registry.LABS``, also here)."""

UNREAD_CONFIG_KEYS: tuple[UnreadKeys, ...] = (
    UnreadKeys(
        ("pa9.noise", "seed"),
        ("pa9",),
        "the noise exercise states its noise level and seed in its text (noise=0.01, seed=1), "
        "and its question and model answer are written for them",
    ),
    UnreadKeys(
        ("style",),
        tuple(LABS),
        "the notebooks draw with the matplotlib settings of the Jupyter they run in, the "
        "student's own",
    ),
)
"""What ``labs --config`` puts into PARAMS but the notebooks do not read, and why.

``uio-teach labs --help`` and the instructors' page say so; a test checks, key by key, that
the notebooks read every other key of the term config that changes their PARAMS.
"""


@dataclass(frozen=True)
class LabResult:
    """The two notebooks written for one lab chapter (and one group).

    Attributes
    ----------
    source : pathlib.Path
        The MyST chapter.
    student : pathlib.Path
        The student notebook.
    solution : pathlib.Path
        The solution notebook.
    todo_cells : int
        How many solutions the student version leaves to do.
    seconds : float
        Time spent (for the progress lines).
    group : str
        The group id (``"g01"``), or ``""`` without groups.

    Examples
    --------
    >>> from pathlib import Path
    >>> from uio_teach.instructor.labs import LabResult
    >>> LabResult(Path("l.md"), Path("s/l.ipynb"), Path("t/l.ipynb"), 4, 0.1).todo_cells
    4
    """

    source: Path
    student: Path
    solution: Path
    todo_cells: int
    seconds: float
    group: str = ""


def write_labs(
    out: str | os.PathLike[str],
    sources: Sequence[str | os.PathLike[str]] | None = None,
    *,
    book_dir: str | os.PathLike[str] | None = None,
    progress: Callable[[int, int, LabResult], None] | None = None,
    config: Mapping[str, Any] | None = None,
    groups: int | None = None,
    seed: int = 0,
) -> list[LabResult]:
    """Write the student and the solution notebook of every lab (per group with ``groups``).

    Without ``groups``: ``out/student/<lab>.ipynb`` and
    ``out/solution/<lab>.ipynb``, with the numbers of ``config`` (the term
    config) or of the chapter. With ``groups``: for every lab with a
    parameter class, ``out/<lab>/student/<lab>_g01.ipynb`` and
    ``out/<lab>/solution/<lab>_g01.ipynb`` for each group, each with its own
    numbers, and ``out/answer_key.csv`` (one row per lab and group: ``lab``,
    ``group``, ``params`` as JSON, then the expected matrices and numbers as
    JSON). Always ``out/manifest.json``: the command, the configuration and
    its hash, the options, the versions and every file with its SHA-256.

    All or nothing (``uio_teach.folders.StagedFolder``): the
    notebooks are written into a staging folder beside ``out`` that replaces
    ``out`` whole when every file is written, so a rerun (``groups=3``, then
    ``groups=2``) leaves no notebook of the earlier run, and a failed or
    killed run leaves ``out`` as it was. ``out`` must be new, empty or an
    earlier output (its manifest); a second run into the same folder at the
    same time is refused. The same arguments give byte-identical files.

    Parameters
    ----------
    out : str or path-like
        Output folder (created or replaced).
    sources : sequence of path-like, optional
        The lab chapters; by default every ``*lab*.md`` of ``book_dir``.
    book_dir : str or path-like, optional
        The book's chapters (for the cross-references and the default
        sources); :func:`~uio_teach.folders.default_book_dir` by default.
    progress : callable, optional
        Called as ``progress(index, total, result)`` after each notebook pair.
    config : mapping, optional
        A term config (:func:`uio_teach.instructor.config.load_config`): the
        labs' numbers follow it.
    groups : int, optional
        Number of lab groups: one variant per group.
    seed : int, optional
        Seed of the variants.

    Returns
    -------
    list of LabResult
        The paths are those in ``out``.

    Raises
    ------
    LabError
        A lab cannot be converted; a ``LabUsageError`` (a subclass) for a
        missing folder or file, a source that is not a lab, a bad ``groups``
        or numbers that make no fair exercise.
    uio_teach.folders.OutputError
        ``out`` cannot be written, is not ours (not empty, no manifest), or
        another run is writing it.

    Examples
    --------
    >>> import tempfile, nbformat
    >>> from uio_teach.instructor.labs import write_labs
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     result = write_labs(tmp)[0]
    ...     nb = nbformat.read(result.student, as_version=4)
    ...     result.student.parent.name, result.solution.parent.name
    ('student', 'solution')
    """
    # deferred on purpose: nbformat comes with the optional ``instructor`` extra
    import nbformat

    book = Path(book_dir) if book_dir is not None else default_book_dir()
    paths = [Path(s) for s in sources] if sources else find_labs(book)
    if sources is None or not sources:
        if not paths:
            raise LabUsageError(f"no lab chapter ({LAB_PATTERN}) in {os.fspath(book)}")
    elif not book.is_dir():
        raise LabUsageError(f"{os.fspath(book)}: no such folder")
    for path in paths:
        if not path.is_file():
            what = "a folder, not a lab chapter" if path.is_dir() else "no such file"
            raise LabUsageError(f"{os.fspath(path)}: {what}")
    if groups is not None and not 1 <= int(groups) <= 999:
        raise LabUsageError(f"groups must be between 1 and 999, got {groups}")
    if seed is None or int(seed) < 0:
        raise LabUsageError(f"seed must be a non-negative integer, got {seed}")
    index = BookIndex.from_book(book)

    if config is not None:
        for note in unused_config_keys(config):
            warnings.warn(ConfigNotKeptWarning(note), stacklevel=2)
    # every job before anything is written: (path, lab, group, params)
    jobs: list[tuple[Path, Lab | None, str, Any]] = []
    for path in paths:
        lab = lab_of(path)
        base = lab.params.from_config(config) if lab is not None else None
        if lab is not None and config is not None:
            for note in config_notes(lab, config, groups is not None):
                warnings.warn(ConfigNotKeptWarning(note), stacklevel=2)
        if lab is not None and base.problems():
            raise LabUsageError(
                f"the {lab.id} lab cannot be made with these numbers: " + "; ".join(base.problems())
            )
        if groups is None:
            jobs.append((path, lab, "", base))
        elif lab is not None:
            variants = draw_variants(lab, int(groups), int(seed), base)
            jobs += [(path, lab, f"g{g:02d}", v) for g, v in enumerate(variants, start=1)]
        else:
            raise LabUsageError(
                f"{os.fspath(path)}: --groups needs a lab of the course "
                f"({', '.join(lab.source for lab in LABS.values())})"
            )
    # convert first (a bad source fails before any file is written)
    built = []
    for path, lab, group, params in jobs:
        start = time.perf_counter()
        meta = {"lab": lab.id, "group": group} if lab is not None and group else {}
        if lab is not None and not group:
            meta = {"lab": lab.id}
        nbs = {
            v: make_notebook(
                path,
                v,
                index=index,
                params=params.to_params() if params is not None else None,
                metadata=meta,
            )
            for v in VERSIONS
        }
        built.append((path, lab, group, params, nbs, time.perf_counter() - start))

    target = Path(out)
    results = []
    with StagedFolder(target, "labs", command=COMMAND) as stage:
        for i, (path, lab, group, _params, nbs, seconds) in enumerate(built, start=1):
            start = time.perf_counter()
            written = {}
            for version, nb in nbs.items():
                if group:
                    where = Path(lab.id, version)  # type: ignore[union-attr]
                    name = f"{lab.id}_{group}.ipynb"  # type: ignore[union-attr]
                else:
                    where, name = Path(version), f"{path.stem}.ipynb"
                (stage.path / where).mkdir(parents=True, exist_ok=True)
                nbformat.write(nb, stage.path / where / name)
                stage.written()
                written[version] = target / where / name
            todo = sum(TODO_TAG in c.metadata.get("tags", []) for c in nbs["student"].cells)
            result = LabResult(
                path,
                written["student"],
                written["solution"],
                todo,
                seconds + time.perf_counter() - start,
                group,
            )
            results.append(result)
            if progress is not None:
                progress(i, len(built), result)
        if groups is not None:
            write_answer_key(stage.path / ANSWER_KEY, [(lab, g, p) for _, lab, g, p, _, _ in built])
            stage.written()
        options = {
            "sources": [p.name for p in paths],
            "groups": groups,
            "seed": int(seed) if groups is not None else None,
            "config_file": getattr(config, "source", None),
        }
        write_manifest(
            stage.path,
            command=COMMAND,
            config=dict(config) if config is not None else {},
            options=options,
        )
        stage.written()
        stage.commit()
    return results
