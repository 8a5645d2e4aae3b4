"""Grading a class in shards, on several machines, and merging the shards' gradebooks.

``uio-teach grade ... --shard K/N`` grades the hand-ins of shard K of N
(:func:`shard_of`: by a hash of the file's name, so every hand-in is in
exactly one shard whatever order the files are listed in, and a class splits
the same way on every machine). Each shard still reads the whole class, so a
copy or a group handing in twice is caught across shards, and its gradebook's
manifest records the class (the hand-ins, the check columns, the roster's
students, the SHA-256 of the answer key and of the roster) and its shard.

:func:`merge` puts the shards' gradebooks together into exactly what one
whole run writes: the CSV with every row in the class's order, the feedback
texts and pages, the per-group and Canvas exports and the manifest. It
refuses, naming the gradebooks, shards of different classes or gradings,
a shard given twice or missing, a hand-in with a row in two gradebooks, and a
shard whose run has not finished (resume it first).

Examples
--------
>>> from uio_teach.grading.merge import shard_of
>>> names = [f"pa9_g{i:02d}.ipynb" for i in range(1, 31)]
>>> sorted({shard_of(n, 3) for n in names})
[1, 2, 3]
>>> [shard_of(n, 3) for n in names] == [shard_of(n, 3) for n in reversed(names)][::-1]
True
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..folders import MANIFEST, read_manifest, sha256_file, write_manifest
from .gradebook import (
    COMMAND,
    EXPORTS,
    check_gradebook_target,
    export_path,
    feedback_folder,
    feedback_names,
    file_cell,
    header_of,
    read_gradebook,
    write_exports,
    write_table,
)
from .rosters import GradeError

__all__ = ["shard_of", "check_shard", "parse_shard", "merge", "MergeError"]

_SHARD = re.compile(r"^\s*(\d+)\s*/\s*(\d+)\s*$")


class MergeError(GradeError):
    """Gradebooks that cannot be merged (one line naming them and why)."""


def shard_of(file: str | os.PathLike[str], shards: int) -> int:
    """The shard (1 to ``shards``) of a hand-in: a hash of its file name, not of its place.

    Parameters
    ----------
    file : str or path-like
        The hand-in (only its name counts, not its folder).
    shards : int
        How many shards.

    Returns
    -------
    int

    Examples
    --------
    >>> from uio_teach.grading.merge import shard_of
    >>> shard_of("handed_in/pa9_g01.ipynb", 4) == shard_of("/elsewhere/pa9_g01.ipynb", 4)
    True
    """
    name = os.fsencode(Path(file).name)
    return int.from_bytes(hashlib.sha256(name).digest()[:8], "big") % shards + 1


def check_shard(shard: Sequence[int]) -> tuple[int, int]:
    """``(K, N)`` as given, checked: whole numbers with 1 <= K <= N.

    Parameters
    ----------
    shard : sequence of int
        ``(K, N)``.

    Returns
    -------
    (int, int)

    Raises
    ------
    GradeError
        Not two whole numbers, or K outside 1..N.

    Examples
    --------
    >>> from uio_teach.grading.merge import check_shard
    >>> check_shard((2, 4))
    (2, 4)
    """
    try:
        k, n = shard
    except (TypeError, ValueError):
        raise GradeError(f"shard: expected K/N, got {shard!r}") from None
    if any(isinstance(v, bool) or not isinstance(v, int) for v in (k, n)) or not 1 <= k <= n:
        raise GradeError(f"shard: expected K/N with 1 <= K <= N, got {k}/{n}")
    return k, n


def parse_shard(text: str) -> tuple[int, int]:
    """``"K/N"`` as ``(K, N)`` (see :func:`check_shard`).

    Parameters
    ----------
    text : str

    Returns
    -------
    (int, int)

    Examples
    --------
    >>> from uio_teach.grading.merge import parse_shard
    >>> parse_shard("3/8")
    (3, 8)
    """
    match = _SHARD.match(text)
    if not match:
        raise GradeError(f"shard: expected K/N (e.g. 2/4), got {text!r}")
    return check_shard((int(match[1]), int(match[2])))


def _shard_name(shard: Any) -> str:
    return f"shard {shard[0]}/{shard[1]}" if shard else "the whole class"


class _Part:
    """One gradebook to merge: its rows, its manifest's record of the class, its shard."""

    def __init__(self, out: Path) -> None:
        self.out = out
        self.folder = feedback_folder(out)
        self.header, self.rows = read_gradebook(out)
        manifest = read_manifest(self.folder) if self.folder.is_dir() else None
        if manifest is None or manifest.get("command") != COMMAND:
            raise MergeError(
                f"{os.fspath(out)}: no feedback folder of uio-teach grade beside it "
                f"({self.folder.name}/{MANIFEST}): not a gradebook to merge"
            )
        options = dict(manifest.get("options") or {})
        if "columns" not in options or "students" not in options:
            raise MergeError(
                f"{os.fspath(out)}: written by an older grader that does not record its class: "
                "grade it again"
            )
        shard = options.pop("shard", None)
        self.shard = tuple(shard) if shard else None
        self.options = options
        self.config = dict(manifest.get("config") or {})
        if self.config.get("gradebook_sha256") != sha256_file(out):
            raise MergeError(
                f"{os.fspath(out)}: its run did not finish ({_shard_name(self.shard)}: the CSV "
                "is not the one its manifest records); resume it with --resume, then merge"
            )


def shard_gradebooks(gradebooks: Sequence[str | os.PathLike[str]]) -> list[Path]:
    """The gradebooks among the files given, without the exports written beside them.

    Parameters
    ----------
    gradebooks : sequence of path
        Files as a pattern such as ``marks/grades_*.csv`` lists them.

    Returns
    -------
    list of pathlib.Path
        The given files in their order, less every ``<gradebook>_groups.csv`` and
        ``<gradebook>_canvas.csv`` of a gradebook among them.

    Examples
    --------
    >>> from uio_teach.grading.merge import shard_gradebooks
    >>> files = ["grades_1.csv", "grades_1_canvas.csv", "grades_1_groups.csv", "grades_2.csv"]
    >>> [p.name for p in shard_gradebooks(files)]
    ['grades_1.csv', 'grades_2.csv']
    """
    paths = [Path(g) for g in gradebooks]
    exports = {export_path(p, kind).resolve() for p in paths for kind in EXPORTS}
    return [p for p in paths if p.resolve() not in exports]


def merge(gradebooks: Sequence[str | os.PathLike[str]], out: str | os.PathLike[str]) -> Path:
    """Merge shard gradebooks into the gradebook ``out`` one whole run would have written.

    Parameters
    ----------
    gradebooks : sequence of path
        The gradebook CSV of every shard (``--shard 1/N`` ... ``N/N``), in any order.
        The exports written beside a gradebook given here (``grades_1_groups.csv``,
        ``grades_1_canvas.csv``, which a pattern such as ``marks/grades_*.csv`` also
        matches) are left out.
    out : path
        The merged gradebook; its feedback folder and exports go beside it.

    Returns
    -------
    pathlib.Path
        ``out``.

    Raises
    ------
    MergeError
        No gradebook, gradebooks of different classes or gradings, a shard
        twice or missing, a row in two gradebooks, a shard not finished, or
        ``out`` is one of the gradebooks.
    uio_teach.folders.OutputError
        A gradebook cannot be read, or ``out``'s feedback folder is not ours.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.grading.gradebook import Gradebook, Submission
    >>> from uio_teach.grading.merge import merge, shard_of
    >>> files = [f"pa9_g{i:02d}.ipynb" for i in range(1, 7)]
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     parts = []
    ...     for k in (1, 2):
    ...         part = pathlib.Path(tmp) / f"grades_{k}.csv"
    ...         with Gradebook(part, files, ["pa9.design"], shard=(k, 2)) as book:
    ...             for f in files:
    ...                 if shard_of(f, 2) == k:
    ...                     book.add(Submission(f, "pa9", f[4:7], "ok"))
    ...         parts.append(part)
    ...     out = merge(parts, pathlib.Path(tmp) / "grades.csv")
    ...     len(out.read_text(encoding="utf-8").splitlines())
    7
    """
    if not gradebooks:
        raise MergeError("no gradebook to merge")
    out = Path(out)
    paths = shard_gradebooks(gradebooks)
    for path in paths:
        if path.resolve() == out.resolve():
            raise MergeError(f"--out {os.fspath(out)} is one of the gradebooks to merge")
    parts = [_Part(p) for p in paths]
    first = parts[0]
    for part in parts[1:]:
        for what in ("submissions", "columns", "students", "answer_key_sha256", "roster_sha256"):
            mine, theirs = first.options.get(what), part.options.get(what)
            if what == "submissions":
                mine, theirs = sorted(mine or []), sorted(theirs or [])
            if mine != theirs:
                raise MergeError(
                    f"{os.fspath(part.out)} and {os.fspath(first.out)} are not shards of one "
                    f"grading: their {what.replace('_sha256', '').replace('_', ' ')} differ"
                )
    totals = {p.shard[1] if p.shard else 1 for p in parts}
    if len(totals) > 1:
        raise MergeError(
            "the gradebooks are shards of different splits ("
            + ", ".join(f"{os.fspath(p.out)}: {_shard_name(p.shard)}" for p in parts)
            + ")"
        )
    (n,) = totals
    by_shard: dict[int, _Part] = {}
    for part in parts:
        k = part.shard[0] if part.shard else 1
        if k in by_shard:
            raise MergeError(
                f"{os.fspath(part.out)} and {os.fspath(by_shard[k].out)} are both "
                f"{_shard_name(part.shard or (1, 1))}: give each shard once"
            )
        by_shard[k] = part
    missing = [k for k in range(1, n + 1) if k not in by_shard]
    if missing:
        raise MergeError(
            f"shard {', '.join(f'{k}/{n}' for k in missing)} missing: give the gradebook of "
            f"every shard 1/{n} to {n}/{n}"
        )
    files = list(first.options["submissions"])
    columns = list(first.options["columns"])
    header = header_of(columns)
    rows: dict[str, list[str]] = {}
    owner: dict[str, _Part] = {}
    for part in parts:
        at = {name: i for i, name in enumerate(part.header)}
        for row in part.rows:
            cell = row[0]
            if cell in rows:
                raise MergeError(
                    f"{cell} has a row in both {os.fspath(owner[cell].out)} and "
                    f"{os.fspath(part.out)}: overlapping shards"
                )
            rows[cell] = [row[at[c]] if c in at else "" for c in header]
            owner[cell] = part
    cells = [file_cell(f) for f in files]
    absent = [c for c in cells if c not in rows]
    if absent:
        raise MergeError(
            f"{len(absent)} hand-in(s) have no row in any gradebook (first: {absent[0]}): "
            "resume the shard that holds them with --resume, then merge"
        )
    for cell in rows:
        if cell not in cells:
            raise MergeError(
                f"{cell} in {os.fspath(owner[cell].out)} is not a hand-in of the class"
            )
    check_gradebook_target(out)
    folder = feedback_folder(out)
    names = feedback_names(list(dict.fromkeys(files)))
    students = {g: [tuple(s) for s in v] for g, v in first.options["students"].items()}
    out.parent.mkdir(parents=True, exist_ok=True)
    if folder.is_dir():  # an earlier merge or grading into this gradebook: its texts go
        for old in folder.iterdir():
            if old.is_file() and (old.suffix in (".txt", ".html") or old.name == MANIFEST):
                old.unlink()
    folder.mkdir(exist_ok=True)
    for file, cell in zip(files, cells, strict=True):
        source = owner[cell].folder / names[file]
        for path in (source, source.with_suffix(".html")):
            if path.is_file():
                shutil.copyfile(path, folder / path.name)
    ordered = [rows[c] for c in dict.fromkeys(cells)]
    write_table(out, [header, *ordered])
    write_exports(out, header, ordered, students)
    config = {"gradebook": out.name, "gradebook_sha256": sha256_file(out)}
    write_manifest(folder, command=COMMAND, config=config, options=first.options)
    return out
