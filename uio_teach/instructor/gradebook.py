"""The gradebook: one CSV row and one feedback text per submission, written as each is graded.

:class:`Gradebook` keeps a grading run's results safe:

* each row is appended to the CSV, flushed and synced as soon as its
  submission is graded, and its feedback text written (atomically) beside it,
  so a run that is killed or interrupted keeps every finished row;
* ``resume=True`` reads the rows already there, and the run grades only the
  submissions that have none;
* a fresh run (no ``resume``) starts a new gradebook: the CSV is emptied and
  the feedback texts of the earlier grading are removed;
* a lock file next to the CSV refuses a second run into the same gradebook;
* once every submission is graded, the CSV is rewritten (atomically) in the
  order the submissions were given, and the feedback folder gets its
  ``manifest.json``.

The feedback folder (``<stem>_feedback`` beside the CSV) must be absent,
empty, or the feedback folder of an earlier grading; anything else is left
alone and the run refused before any notebook runs.

Examples
--------
>>> from uio_teach.instructor.gradebook import Submission
>>> s = Submission("a.ipynb", "pa9", "g01", "ok",
...                results={"pa9.design": {"passed": True, "items": []}},
...                expected=("pa9.design", "pa9.plot"))
>>> s.verdicts(), s.total
({'pa9.design': True, 'pa9.plot': False}, 1)
"""

from __future__ import annotations

import csv
import io
import json
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .output import (
    MANIFEST,
    FolderBusy,
    FolderLock,
    OutputError,
    check_output_folder,
    read_manifest,
    sha256_file,
    write_manifest,
)

__all__ = [
    "Submission",
    "Gradebook",
    "GradebookBusy",
    "feedback_folder",
    "check_gradebook_target",
    "feedback_names",
    "PASS",
    "FAIL",
    "COMMAND",
]

PASS, FAIL = "✓", "✗"
COMMAND = "uio-teach grade"
"""The command recorded in the feedback folder's manifest."""
_FIRST = ["file", "lab", "group", "status"]
_LAST = ["total", "out_of"]


class GradebookBusy(FolderBusy):
    """Another grading run is writing this gradebook."""


@dataclass
class Submission:
    """The grade of one submitted notebook.

    Attributes
    ----------
    file : str
        The submission, as given.
    lab : str
        The lab id ("" when unknown).
    group : str
        The group id ("" when unknown).
    status : str
        ``"ok"``, ``"error"`` (some cells raised, or the run did not reach its
        end), ``"timeout"`` (stopped at the time limit), ``"unreadable"`` (not
        a notebook) or ``"unknown lab"``.
    results : dict
        Check id -> the check's result as a dict (``CheckResult.to_dict()``).
    errors : list of str
        The grader's notes: cells that raised, a run cut short.
    params : dict or None
        The parameters it was graded with (from the answer key).
    expected : tuple of str
        The check ids of its lab.
    seconds : float
        Time spent grading it.
    feedback_file : pathlib.Path or None
        Its feedback text, once written.

    Examples
    --------
    >>> from uio_teach.instructor.gradebook import Submission
    >>> s = Submission("pa9_g01.ipynb", "pa9", "g01", "unreadable",
    ...                errors=["not a notebook"], expected=("pa9.design",))
    >>> s.row(["pa9.design"])
    ['pa9_g01.ipynb', 'pa9', 'g01', 'unreadable', '✗', 0, 1]
    """

    file: str
    lab: str
    group: str
    status: str
    results: dict[str, dict[str, Any]] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)
    params: dict[str, Any] | None = None
    expected: tuple[str, ...] = ()
    seconds: float = 0.0
    feedback_file: Path | None = None

    def verdicts(self) -> dict[str, bool]:
        """Check id -> passed (a check with no result failed)."""
        ids = list(self.expected) + [i for i in self.results if i not in self.expected]
        return {i: bool(self.results.get(i, {}).get("passed")) for i in ids}

    @property
    def total(self) -> int:
        """The number of checks passed."""
        return sum(self.verdicts().values())

    def feedback(self) -> str:
        """The feedback text for the group: every check's messages, then the grader's notes."""
        lines = [
            f"Submission: {self.file}",
            f"Lab: {self.lab or 'unknown'}    Group: {self.group or 'unknown'}",
        ]
        if self.params is not None:
            lines.append(f"Parameters of this group: {json.dumps(self.params)}")
        verdicts = self.verdicts()
        lines += [f"Checks passed: {self.total} of {len(verdicts)}", ""]
        for check_id, ok in verdicts.items():
            result = self.results.get(check_id)
            title = (result or {}).get("title", "")
            lines.append(f"{PASS if ok else FAIL} {check_id}{': ' + title if title else ''}")
            if result is None:
                lines.append("    not graded: the notebook could not be run")
                continue
            for item in result.get("items", []):
                mark = {True: PASS, False: FAIL}.get(item.get("ok"), "•")
                lines.append(f"    {mark} {item.get('message', '')}")
        if self.errors:
            lines += ["", "Problems while running the notebook:"]
            lines += [f"  - {e}" for e in self.errors]
        return "\n".join(lines) + "\n"

    def row(self, columns: Sequence[str]) -> list[Any]:
        """The CSV row under the check columns ``columns`` (empty for a check of another lab)."""
        verdicts = self.verdicts()
        marks = ["" if c not in verdicts else (PASS if verdicts[c] else FAIL) for c in columns]
        return [self.file, self.lab, self.group, self.status, *marks, self.total, len(verdicts)]


def feedback_folder(out: str | os.PathLike[str]) -> Path:
    """The feedback folder that goes with the gradebook ``out``: ``<out stem>_feedback``.

    Parameters
    ----------
    out : str or path-like

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> from uio_teach.instructor.gradebook import feedback_folder
    >>> feedback_folder("marks/grades.csv").as_posix()
    'marks/grades_feedback'
    """
    out = Path(out)
    return out.with_name(f"{out.stem}_feedback")


def check_gradebook_target(out: str | os.PathLike[str]) -> None:
    """Raise :class:`~uio_teach.instructor.output.OutputError` unless ``out`` may be written.

    The gradebook must not be a folder; its feedback folder must be absent,
    empty, or the feedback folder of an earlier grading (its manifest says so).

    Parameters
    ----------
    out : str or path-like

    Raises
    ------
    uio_teach.instructor.output.OutputError

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.instructor.gradebook import check_gradebook_target
    >>> from uio_teach.instructor.output import OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     mine = pathlib.Path(tmp) / "grades_feedback"
    ...     mine.mkdir()
    ...     _ = (mine / "notes.txt").write_text("mine")
    ...     try:
    ...         check_gradebook_target(pathlib.Path(tmp) / "grades.csv")
    ...     except OutputError as err:
    ...         print("left alone" in str(err))
    True
    """
    out = Path(out)
    if out.is_dir():
        raise OutputError(f"the gradebook {os.fspath(out)} is a folder, not a file")
    folder = feedback_folder(out)
    check_output_folder(folder)
    manifest = read_manifest(folder) if folder.is_dir() else None
    if manifest is not None and manifest.get("command") != COMMAND:
        raise OutputError(
            f"the feedback folder {os.fspath(folder)} holds the output of "
            f"{manifest.get('command') or 'another command'} (its {MANIFEST}), not feedback "
            "of an earlier grading; it is left alone: choose another gradebook name"
        )


def feedback_names(files: Sequence[str]) -> dict[str, str]:
    """Submission -> the name of its feedback text (its stem; its folder too on a clash).

    Parameters
    ----------
    files : sequence of str

    Returns
    -------
    dict

    Examples
    --------
    >>> from uio_teach.instructor.gradebook import feedback_names
    >>> feedback_names(["a/x.ipynb", "b/x.ipynb"])
    {'a/x.ipynb': 'x.txt', 'b/x.ipynb': 'b_x.txt'}
    """
    names: dict[str, str] = {}
    for file in files:
        path = Path(file)
        candidates = [path.stem, f"{path.parent.name}_{path.stem}"]
        candidates += [f"{path.stem}-{n}" for n in range(2, len(files) + 2)]
        taken = set(names.values())
        names[file] = next(f"{c}.txt" for c in candidates if f"{c}.txt" not in taken)
    return names


def _write_atomic(path: Path, text: str) -> None:
    part = path.with_name(f".{path.name}.part")
    with open(part, "w", encoding="utf-8", newline="") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(part, path)


def _csv_text(rows: Iterable[Sequence[Any]]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf)
    for row in rows:
        writer.writerow(row)
    return buf.getvalue()


class Gradebook:
    """A gradebook CSV and its feedback folder, written row by row.

    Parameters
    ----------
    out : path
        The CSV.
    files : sequence of str
        Every submission of the run, in order (the final order of the rows).
    columns : sequence of str
        The check ids (one column each).
    resume : bool
        Keep the rows already there; :attr:`done` lists their files.

    Raises
    ------
    uio_teach.instructor.output.OutputError
        The CSV is a folder, or its feedback folder is not ours.
    GradebookBusy
        Another run holds the lock.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.instructor.gradebook import Gradebook, Submission
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     out = pathlib.Path(tmp) / "grades.csv"
    ...     with Gradebook(out, ["a.ipynb"], ["pa9.design"]) as book:
    ...         book.add(Submission("a.ipynb", "pa9", "g01", "ok", expected=("pa9.design",)))
    ...     print(out.read_text(encoding="utf-8").splitlines()[1])
    a.ipynb,pa9,g01,ok,✗,0,1
    """

    def __init__(
        self,
        out: str | os.PathLike[str],
        files: Sequence[str],
        columns: Sequence[str],
        *,
        resume: bool = False,
    ) -> None:
        self.out = Path(out)
        self.folder = feedback_folder(self.out)
        self.files = list(files)
        self.columns = list(columns)
        self.resume = resume
        self.names = feedback_names(self.files)
        self.done: dict[str, list[str]] = {}
        self._lock = FolderLock(self.out)  # the file .<name>.lock beside the CSV
        self._csv: Any = None

    # opening ------------------------------------------------------------------------------
    def __enter__(self) -> Gradebook:
        check_gradebook_target(self.out)
        self.out.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._lock.acquire()
        except FolderBusy:
            raise GradebookBusy(
                f"another grading run is writing {os.fspath(self.out)} (it holds "
                f"{self._lock.path.name}); wait for it to end, or choose another gradebook"
            ) from None
        try:
            self._open()
        except BaseException:
            self._unlock()
            raise
        return self

    def _read_rows(self) -> tuple[list[str], list[list[str]]]:
        try:
            with open(self.out, newline="", encoding="utf-8") as fh:
                table = list(csv.reader(fh))
        except FileNotFoundError:
            return [], []
        except (OSError, UnicodeDecodeError, csv.Error) as err:
            raise OutputError(f"cannot read the gradebook {os.fspath(self.out)}: {err}") from None
        if not table:
            return [], []
        header, body = table[0], table[1:]
        if header[: len(_FIRST)] != _FIRST or header[-len(_LAST) :] != _LAST:
            raise OutputError(
                f"{os.fspath(self.out)} is not a gradebook of uio-teach (its header is not "
                f"{','.join(_FIRST)},...,{','.join(_LAST)}); it is left alone"
            )
        # a row cut short by a kill has fewer fields: it is graded again
        return header, [row for row in body if len(row) == len(header)]

    def _open(self) -> None:
        self.folder.mkdir(parents=True, exist_ok=True)
        header: list[str] = []
        kept: list[list[str]] = []
        if self.resume:
            header, kept = self._read_rows()
            wanted = set(self.files)
            kept = [row for row in kept if row[0] in wanted]
        else:  # a new grading: the texts of the earlier one go
            for old in self.folder.iterdir():
                if old.is_file() and (old.suffix == ".txt" or old.name == MANIFEST):
                    old.unlink()
        old_columns = header[len(_FIRST) : -len(_LAST)] if header else []
        self.columns = old_columns + [c for c in self.columns if c not in old_columns]
        if header and old_columns != self.columns:  # new check columns: widen the old rows
            width = len(self.columns) - len(old_columns)
            kept = [row[: -len(_LAST)] + [""] * width + row[-len(_LAST) :] for row in kept]
        self.done = {row[0]: row for row in kept}
        for file in list(self.done):  # a row whose feedback text is lost is graded again
            if not (self.folder / self.names[file]).is_file():
                del self.done[file]
        kept = [row for row in kept if row[0] in self.done]
        _write_atomic(self.out, _csv_text([self._header(), *kept]))
        write_manifest(self.folder, command=COMMAND, config=self._config(), options=self._options())
        self._csv = open(self.out, "a", encoding="utf-8", newline="")

    def _header(self) -> list[str]:
        return [*_FIRST, *self.columns, *_LAST]

    def _config(self) -> dict[str, Any]:
        return {"gradebook": self.out.name}

    def _options(self) -> dict[str, Any]:
        return {"submissions": self.files}

    # writing ------------------------------------------------------------------------------
    def add(self, sub: Submission) -> None:
        """Write ``sub``'s feedback text and append its row (flushed and synced).

        Parameters
        ----------
        sub : Submission
        """
        name = self.names.get(sub.file) or feedback_names([sub.file])[sub.file]
        path = self.folder / name
        _write_atomic(path, sub.feedback())
        sub.feedback_file = path
        row = [str(v) for v in sub.row(self.columns)]
        self._csv.write(_csv_text([row]))
        self._csv.flush()
        os.fsync(self._csv.fileno())
        self.done[sub.file] = row

    def finish(self) -> None:
        """Rewrite the CSV in the submissions' order and write the feedback manifest."""
        rows = [self.done[f] for f in self.files if f in self.done]
        self._csv.close()
        _write_atomic(self.out, _csv_text([self._header(), *rows]))
        self._csv = open(self.out, "a", encoding="utf-8", newline="")
        config = {**self._config(), "gradebook_sha256": sha256_file(self.out)}
        write_manifest(self.folder, command=COMMAND, config=config, options=self._options())

    def _unlock(self) -> None:
        self._lock.release()

    def __exit__(self, exc_type: Any, *exc: object) -> None:
        try:
            if self._csv is not None:
                if exc_type is None:
                    self.finish()
                self._csv.close()
                self._csv = None
        finally:
            self._unlock()
