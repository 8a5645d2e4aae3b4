"""Grade submitted lab notebooks: run each on a copy, re-run its checks, write a gradebook CSV.

:func:`grade` takes the notebooks the groups handed in and, for each one:

1. reads it (the submission itself is never written to) and finds its lab and
   group: from the notebook's metadata ``{"uio_teach": {"lab": ..., "group":
   ...}}``, else from a file name such as ``pa9_g03.ipynb``;
2. makes a copy in a temporary folder with every stored output cleared (a
   stored ✓ counts for nothing), and, when an answer key is given, the cell
   tagged ``parameters`` replaced by ``PARAMS = <that group's parameters>``
   (added at the top if the group deleted it);
3. runs the copy in a fresh kernel, in a separate process, with a time limit
   per cell and for the whole notebook (the process is killed when it is
   over); a cell that raises or loops is recorded and the next cells still
   run;
4. reads the verdict of every cell tagged ``check`` (not those of the
   instructor notes, tagged ``instructor`` too): a small cell added after
   each one records (and prints) the results of
   :func:`uio_teach.checks.collected`, and a last added cell prints them all
   as JSON between two marker lines. Results made outside the check cells (an
   exercise that shows a failing check on purpose) do not count. A run killed
   at the time limit is graded on the check cells that ran.

The checks a lab must produce come from the lab registry
(``uio_teach.instructor.labs.LABS``, the ``check_ids`` of each lab) when it
exists; otherwise from what the check cells of all the submissions of that lab
produced, so a check cell one group deleted is still a ✗ ("not run") for it.

One row per submission goes to the CSV (file, lab, group, status, one column
per check id with ✓ or ✗, the number passed and out of how many), and one
feedback text per submission (every check message, every error) to a folder
beside it.

Grading runs the students' code with your permissions: run it in a container
or as a user that can read nothing else (see the instructors' page).

Examples
--------
>>> from uio_teach.instructor.grade import group_from_name
>>> group_from_name("submissions/pa9_g03.ipynb")
('pa9', 'g03')
"""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = [
    "GradeError",
    "Submission",
    "grade",
    "read_answer_key",
    "group_from_name",
    "write_gradebook",
    "BEGIN",
    "END",
]

BEGIN = "<<<uio-teach grade: results>>>"
"""The line before the JSON of the check results in the executed copy."""
CELL = "<<<uio-teach grade: check cell>>>"
"""The line before the JSON of one check cell's results (read when a run is cut short)."""
END = "<<<uio-teach grade: end>>>"
"""The line after it."""

PASS, FAIL = "✓", "✗"
_GROUP_NAME = re.compile(r"^(?P<lab>.+?)_(?P<group>g\d+)$")
_TAG = "uio-teach-grade"
_COMMAND = "uio-teach grade"


class GradeError(ValueError):
    """Grading cannot start (a missing answer key, an unreadable key); one line."""


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
        ``"ok"``, ``"error"`` (some cells raised), ``"timeout"`` (killed at the
        time limit) or ``"unreadable"`` (not a notebook).
    results : dict
        Check id -> the JSON of the check's result(s) (``to_dict``), in order.
    errors : list of str
        One line per cell that raised, and any note on the run.
    params : dict or None
        The parameters the copy ran with, when an answer key set them.
    expected : tuple of str
        The check ids this lab must produce.
    seconds : float
        Time spent running it.
    feedback_file : pathlib.Path or None
        The feedback text, once :func:`write_gradebook` wrote it (named after
        the submission; after its folder too when two submissions share a name).

    Examples
    --------
    >>> from uio_teach.instructor.grade import Submission
    >>> s = Submission("a.ipynb", "pa9", "g01", "ok",
    ...                results={"pa9.design": [{"passed": True}]},
    ...                expected=("pa9.design", "pa9.plot"))
    >>> s.verdicts(), s.total
    ({'pa9.design': True, 'pa9.plot': False}, 1)
    """

    file: str
    lab: str
    group: str
    status: str
    results: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)
    params: dict[str, Any] | None = None
    expected: tuple[str, ...] = ()
    seconds: float = 0.0
    feedback_file: Path | None = None

    def verdicts(self) -> dict[str, bool]:
        """Check id -> passed: ran at least once, and passed every time it ran."""
        ids = list(self.expected) + [i for i in self.results if i not in self.expected]
        return {
            i: bool(self.results.get(i)) and all(r.get("passed") for r in self.results[i])
            for i in ids
        }

    @property
    def total(self) -> int:
        """The number of checks passed."""
        return sum(self.verdicts().values())

    def feedback(self) -> str:
        """The feedback text for the group: every check's messages, then the errors."""
        lines = [
            f"Submission: {self.file}",
            f"Lab: {self.lab or 'unknown'}    Group: {self.group or 'unknown'}",
        ]
        if self.params is not None:
            lines.append(f"Parameters of this group: {json.dumps(self.params)}")
        verdicts = self.verdicts()
        lines += [f"Checks passed: {self.total} of {len(verdicts)}", ""]
        for check_id, ok in verdicts.items():
            runs = self.results.get(check_id, [])
            title = runs[0].get("title", "") if runs else ""
            lines.append(f"{PASS if ok else FAIL} {check_id}{': ' + title if title else ''}")
            if not runs:
                lines.append(
                    "    not run: the check cell is missing, or it raised before the check"
                )
            for run in runs:
                for item in run.get("items", []):
                    mark = {True: PASS, False: FAIL}.get(item.get("ok"), "•")
                    lines.append(f"    {mark} {item.get('message', '')}")
        if self.errors:
            lines += ["", "Problems while running the notebook:"]
            lines += [f"  - {e}" for e in self.errors]
        return "\n".join(lines) + "\n"


def group_from_name(path: str | os.PathLike[str]) -> tuple[str, str]:
    """The lab and group of a file named ``<lab>_<group>.ipynb`` (``("", "")`` otherwise).

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    (str, str)

    Examples
    --------
    >>> from uio_teach.instructor.grade import group_from_name
    >>> group_from_name("pa9_g12.ipynb"), group_from_name("lab_pa9.ipynb")
    (('pa9', 'g12'), ('', ''))
    """
    match = _GROUP_NAME.match(Path(path).stem)
    return (match["lab"], match["group"]) if match else ("", "")


def read_answer_key(path: str | os.PathLike[str]) -> dict[tuple[str, str], dict[str, Any]]:
    """The parameters of every (lab, group) in an answer key written by ``uio-teach labs``.

    Parameters
    ----------
    path : str or path-like
        The CSV, with at least the columns ``lab``, ``group`` and ``params``
        (the JSON of the group's ``PARAMS``).

    Returns
    -------
    dict
        ``(lab, group) -> params``.

    Raises
    ------
    GradeError
        The file is missing, lacks a column, or a ``params`` cell is not JSON.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.instructor.grade import read_answer_key
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     key = pathlib.Path(tmp) / "answer_key.csv"
    ...     _ = key.write_text('lab,group,params\\npa9,g01,"{""poles"": [-1, -2, -3]}"\\n')
    ...     read_answer_key(key)
    {('pa9', 'g01'): {'poles': [-1, -2, -3]}}
    """
    name = os.fspath(path)
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
    except FileNotFoundError:
        raise GradeError(f"{name}: no such file") from None
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise GradeError(f"{name}: cannot read it ({err})") from None
    key: dict[tuple[str, str], dict[str, Any]] = {}
    for number, row in enumerate(rows, start=2):
        missing = [c for c in ("lab", "group", "params") if c not in row or row[c] is None]
        if missing:
            raise GradeError(f"{name}: line {number}: no column {', '.join(missing)}")
        try:
            params = json.loads(row["params"])
        except ValueError:
            raise GradeError(f"{name}: line {number}: params is not JSON") from None
        key[(row["lab"], row["group"])] = params
    return key


def _registry() -> Mapping[str, Any]:
    """The lab registry, or an empty mapping when this version has none."""
    try:
        from . import labs
    except ImportError:  # pragma: no cover - jupytext missing
        return {}
    return getattr(labs, "LABS", None) or {}


def _record_field(record: Any, *names: str) -> Any:
    for name in names:
        if isinstance(record, Mapping) and name in record:
            return record[name]
        if hasattr(record, name):
            return getattr(record, name)
    return None


def _lab_of(nb: Any, path: Path, registry: Mapping[str, Any]) -> tuple[str, str]:
    meta = nb.get("metadata", {}).get("uio_teach", {}) if isinstance(nb, Mapping) else {}
    lab = str(meta.get("lab", "") or "") if isinstance(meta, Mapping) else ""
    group = str(meta.get("group", "") or "") if isinstance(meta, Mapping) else ""
    name_lab, name_group = group_from_name(path)
    lab, group = lab or name_lab, group or name_group
    if not lab:
        source = meta.get("source") if isinstance(meta, Mapping) else None
        stem = Path(str(source)).stem if source else path.stem
        for lab_id, record in registry.items():
            chapter = _record_field(record, "chapter", "source", "source_name")
            if chapter is not None and Path(str(chapter)).stem == stem:
                lab = lab_id
                break
        else:
            lab = stem.removeprefix("lab_")
    return lab, group


def _is_code(cell: Any) -> bool:
    return cell.get("cell_type") == "code"


def _tags(cell: Any) -> list[str]:
    return list(cell.get("metadata", {}).get("tags", []) or [])


def _prepare(nb: Any, params: dict[str, Any] | None) -> tuple[Any, int]:
    """The copy to run: outputs cleared, parameters set, recording cells added."""
    import nbformat

    setup = nbformat.v4.new_code_cell(
        "import json as _uio_json\n"
        "from uio_teach import checks as _uio_checks\n"
        "_uio_grade = []\n"
        "_uio_checks.clear_collected()"
    )
    cells = [setup]
    has_params = False
    checks = 0
    for cell in nb.cells:
        if _is_code(cell):
            cell.outputs = []
            cell.execution_count = None
        if _is_code(cell) and "parameters" in _tags(cell) and params is not None:
            cell.source = f"PARAMS = {json.dumps(params)}"
            has_params = True
        if _is_code(cell) and "check" in _tags(cell) and "instructor" not in _tags(cell):
            checks += 1
            cells.append(nbformat.v4.new_code_cell("_uio_checks.clear_collected()"))
            cells.append(cell)
            cells.append(
                nbformat.v4.new_code_cell(
                    f"_uio_entry = {{'cell': {checks}, 'results': "
                    "[r.to_dict() for r in _uio_checks.collected()]}\n"
                    "_uio_grade.append(_uio_entry)\n"
                    "_uio_checks.clear_collected()\n"
                    f"print({CELL!r})\nprint(_uio_json.dumps(_uio_entry))\nprint({END!r})"
                )
            )
        else:
            cells.append(cell)
    if params is not None and not has_params:
        cells.insert(1, nbformat.v4.new_code_cell(f"PARAMS = {json.dumps(params)}"))
    cells.append(
        nbformat.v4.new_code_cell(
            f"print({BEGIN!r})\nprint(_uio_json.dumps(_uio_grade))\nprint({END!r})"
        )
    )
    theirs = {id(cell) for cell in nb.cells}
    for cell in cells:
        if id(cell) not in theirs:
            cell.metadata["tags"] = [_TAG]
    nb.cells = cells
    return nb, checks


def _parse(
    executed: Any,
) -> tuple[list[dict[str, Any]] | None, list[dict[str, Any]], list[str]]:
    """The results of the last cell (None if it did not run), of each check cell, the errors."""
    errors: list[str] = []
    partial: list[dict[str, Any]] = []
    found = None
    user_cell = 0
    for cell in executed.cells:
        if not _is_code(cell):
            continue
        ours = _TAG in _tags(cell)
        if not ours:
            user_cell += 1
        for out in cell.get("outputs", []):
            if out.get("output_type") == "error":
                where = "a grading cell" if ours else f"code cell {user_cell}"
                evalue = " ".join(str(out.get("evalue", "")).split())
                if len(evalue) > 200:
                    evalue = evalue[:197] + "..."
                if out.get("ename") in ("KeyboardInterrupt", "TimeoutError"):
                    errors.append(
                        f"{where} was interrupted: it ran longer than the time limit of a cell"
                    )
                else:
                    errors.append(f"{where} raised {out.get('ename', 'an error')}: {evalue}")
            text = out.get("text", "") if out.get("output_type") == "stream" else ""
            for marker in (CELL, BEGIN):
                if ours and marker in text:
                    body = text.split(marker, 1)[1].split(END, 1)[0]
                    try:
                        data = json.loads(body)
                    except ValueError:
                        continue
                    if marker == BEGIN:
                        found = data
                    else:
                        partial.append(data)
    return found, partial, errors


def _run_copy(path: Path, cell_timeout: float, timeout: float) -> tuple[str, Any, str]:
    """Run the notebook at ``path`` in a separate process; (status, executed nb, note)."""
    import nbformat

    out_path = path.with_name("executed.ipynb")
    pid_path = path.with_name("kernel.pid")
    cmd = [
        sys.executable,
        "-m",
        "uio_teach.instructor.grade",
        "--run",
        os.fspath(path),
        os.fspath(out_path),
        str(cell_timeout),
        os.fspath(pid_path),
    ]
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONHASHSEED="0")
    proc = subprocess.Popen(
        cmd,
        cwd=path.parent,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    status, note = "ok", ""
    try:
        _, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        status, note = "timeout", f"stopped after {timeout:g} s, the time limit of a notebook"
        _kill(proc.pid)
        _, err = proc.communicate()
    finally:
        _kill_kernel(pid_path)
    if status == "ok" and proc.returncode != 0:
        lines = [line for line in (err or "").splitlines() if line.strip()]
        note = f"the notebook could not be run: {lines[-1] if lines else 'no message'}"
        status = "error"
    executed = None
    if out_path.is_file():
        try:
            executed = nbformat.read(out_path, as_version=4)
        except Exception:  # a half-written file after a kill
            executed = None
    return status, executed, note


def _kill(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def _kill_kernel(pid_path: Path) -> None:
    try:
        pid = int(pid_path.read_text())
    except (OSError, ValueError):
        return
    _kill(pid)  # the kernel leads its own session: this also ends what it started


def _grade_one(
    path: Path,
    key: Mapping[tuple[str, str], dict[str, Any]] | None,
    registry: Mapping[str, Any],
    cell_timeout: float,
    timeout: float,
) -> Submission:
    import nbformat

    start = time.perf_counter()
    try:
        nb = nbformat.reads(path.read_bytes().decode("utf-8"), as_version=4)
    except Exception as exc:
        reason = " ".join(str(exc).split())[:200] or type(exc).__name__
        lab, group = group_from_name(path)
        note = f"not a notebook: {reason}"
        return Submission(os.fspath(path), lab, group, "unreadable", errors=[note])
    lab, group = _lab_of(nb, path, registry)
    sub = Submission(os.fspath(path), lab, group, "ok")
    params = None
    if key is not None:
        params = key.get((lab, group))
        if params is None:
            sub.errors.append(
                f"no parameters for lab {lab!r}, group {group!r} in the answer key: graded with "
                "the notebook's own parameters cell"
            )
    sub.params = params
    record = registry.get(lab)
    expected = _record_field(record, "check_ids", "checks") if record is not None else None
    sub.expected = tuple(expected or ())
    copy, _ = _prepare(nb, params)
    with tempfile.TemporaryDirectory(prefix="uio-teach-grade-") as tmp:
        work = Path(tmp) / "submission.ipynb"
        nbformat.write(copy, work)
        status, executed, note = _run_copy(work, cell_timeout, timeout)
    sub.status = status
    if note:
        sub.errors.append(note)
    found, partial = None, []
    if executed is not None:
        found, partial, errors = _parse(executed)
        sub.errors += errors
        if errors and sub.status == "ok":
            sub.status = "error"
    if found is None:
        found = partial  # cut short: what the check cells that ran recorded
        if sub.status == "ok":
            sub.status = "error"
            sub.errors.append("the notebook did not run to its end")
    for entry in found or []:
        for result in entry.get("results", []):
            check_id = result.get("check_id") or result.get("title") or "unnamed check"
            sub.results.setdefault(check_id, []).append(result)
    sub.seconds = time.perf_counter() - start
    return sub


def _feedback_folder(out: str | os.PathLike[str]) -> Path:
    """The feedback folder that goes with the gradebook ``out``: ``<out stem>_feedback``.

    Parameters
    ----------
    out : str or path-like
        The gradebook CSV.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> from uio_teach.instructor.grade import _feedback_folder
    >>> _feedback_folder("marks/grades.csv").as_posix()
    'marks/grades_feedback'
    """
    out = Path(out)
    return out.with_name(f"{out.stem}_feedback")


def _check_gradebook_target(out: str | os.PathLike[str]) -> None:
    """Raise :class:`~uio_teach.instructor.output.OutputError` unless ``out`` may be (re)written.

    The gradebook must not be a folder, and its feedback folder must not exist,
    be empty, or be the feedback folder of an earlier run (it has the
    ``manifest.json`` that run wrote). A folder of that name holding anything
    else is never replaced.

    Parameters
    ----------
    out : str or path-like
        The gradebook CSV.

    Raises
    ------
    uio_teach.instructor.output.OutputError
        One line naming the file or folder and why.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.instructor.grade import _check_gradebook_target
    >>> from uio_teach.instructor.output import OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     mine = pathlib.Path(tmp) / "grades_feedback"
    ...     mine.mkdir()
    ...     _ = (mine / "notes.txt").write_text("mine")
    ...     try:
    ...         _check_gradebook_target(pathlib.Path(tmp) / "grades.csv")
    ...     except OutputError as err:
    ...         print("left alone" in str(err))
    True
    """
    from .output import MANIFEST, OutputError, check_output_folder, read_manifest

    out = Path(out)
    if out.is_dir():
        raise OutputError(f"the gradebook {os.fspath(out)} is a folder, not a file")
    folder = _feedback_folder(out)
    check_output_folder(folder)
    manifest = read_manifest(folder) if folder.is_dir() else None
    if manifest is not None and manifest.get("command") != _COMMAND:
        raise OutputError(
            f"the feedback folder {os.fspath(folder)} holds the output of "
            f"{manifest.get('command') or 'another command'} (its {MANIFEST}), not feedback "
            "of an earlier grading; it is left alone: choose another gradebook name"
        )


def write_gradebook(
    submissions: Sequence[Submission], out: str | os.PathLike[str]
) -> tuple[Path, Path]:
    """Write the gradebook CSV and one feedback text per submission (in ``<out stem>_feedback``).

    Columns: ``file``, ``lab``, ``group``, ``status``, one per check id (✓ or
    ✗; empty for a check of another lab), ``total`` (checks passed) and
    ``out_of``.

    The CSV and its feedback folder are replaced together: both are written
    beside their targets first, and only once everything is written are they
    moved in place, the folder whole, so no feedback text of an earlier run is
    left next to this run's gradebook. If writing fails, the previous CSV and
    folder stay exactly as they were. The folder holds a ``manifest.json``
    (the gradebook's name and SHA-256, every feedback file with its SHA-256);
    a folder of that name without one is not an earlier feedback folder, and
    it is left alone.

    Parameters
    ----------
    submissions : sequence of Submission
        The grades.
    out : str or path-like
        The CSV.

    Returns
    -------
    (pathlib.Path, pathlib.Path)
        The CSV and the feedback folder.

    Raises
    ------
    uio_teach.instructor.output.OutputError
        ``out`` is a folder, or its feedback folder exists and is not one of an
        earlier run; nothing is written.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.instructor.grade import Submission, write_gradebook
    >>> s = Submission("a.ipynb", "pa9", "g01", "ok", expected=("pa9.design",))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     csv_path, folder = write_gradebook([s], pathlib.Path(tmp) / "grades.csv")
    ...     print(csv_path.read_text(encoding="utf-8").splitlines()[1])
    ...     print(sorted(p.name for p in folder.iterdir()))
    a.ipynb,pa9,g01,ok,✗,0,1
    ['a.txt', 'manifest.json']
    """
    from .output import StagedFolder, sha256_file, write_manifest

    out = Path(out)
    folder = _feedback_folder(out)
    _check_gradebook_target(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    columns: list[str] = []
    for sub in submissions:
        columns += [c for c in sub.verdicts() if c not in columns]
    with StagedFolder(folder, "feedback") as stage:
        assert stage.path is not None
        names: list[str] = []
        for sub in submissions:
            path = Path(sub.file)
            candidates = [path.stem, f"{path.parent.name}_{path.stem}"]
            candidates += [f"{path.stem}-{n}" for n in range(2, len(submissions) + 2)]
            name = next(f"{c}.txt" for c in candidates if f"{c}.txt" not in names)
            names.append(name)
            (stage.path / name).write_text(sub.feedback(), encoding="utf-8")
        new_csv = stage.path.parent / f".{out.name}.new"
        try:
            with open(new_csv, "w", newline="", encoding="utf-8") as fh:
                writer = csv.writer(fh)
                writer.writerow(["file", "lab", "group", "status", *columns, "total", "out_of"])
                for sub in submissions:
                    verdicts = sub.verdicts()
                    marks = [
                        "" if c not in verdicts else (PASS if verdicts[c] else FAIL)
                        for c in columns
                    ]
                    writer.writerow(
                        [sub.file, sub.lab, sub.group, sub.status, *marks, sub.total, len(verdicts)]
                    )
            write_manifest(
                stage.path,
                command=_COMMAND,
                config={"gradebook": out.name, "gradebook_sha256": sha256_file(new_csv)},
                options={"submissions": [sub.file for sub in submissions]},
            )
            _swap_in(new_csv, out, stage)
        finally:
            new_csv.unlink(missing_ok=True)
    for sub, name in zip(submissions, names, strict=True):
        sub.feedback_file = folder / name
    return out, folder


def _swap_in(new_csv: Path, out: Path, stage: Any) -> None:
    """Move the new CSV to ``out`` and commit ``stage``; on failure, put the old CSV back."""
    backup = None
    if out.exists():
        backup = new_csv.with_name(f".{out.name}.old")
        backup.unlink(missing_ok=True)
        try:
            os.link(out, backup)
        except OSError:  # no hard links on this file system: a copy
            shutil.copy2(out, backup)
    try:
        os.replace(new_csv, out)
        try:
            stage.commit()
        except BaseException:
            if backup is not None:
                os.replace(backup, out)
                backup = None
            else:
                out.unlink(missing_ok=True)
            raise
    finally:
        if backup is not None:
            backup.unlink(missing_ok=True)


def grade(
    submissions: Sequence[str | os.PathLike[str]],
    out: str | os.PathLike[str],
    *,
    answer_key: str | os.PathLike[str] | None = None,
    timeout: float = 300.0,
    cell_timeout: float = 60.0,
    progress: Callable[[int, int, Submission], None] | None = None,
) -> list[Submission]:
    """Grade submitted notebooks; write the gradebook ``out`` (CSV) and the feedback texts.

    Parameters
    ----------
    submissions : sequence of path
        The notebooks handed in. They are only read.
    out : path
        The CSV to write; the feedback goes to ``<stem>_feedback/`` beside it. Both
        replace those of an earlier grading together (see :func:`write_gradebook`).
    answer_key : path, optional
        ``answer_key.csv`` of ``uio-teach labs --groups``: each notebook then
        runs with its group's parameters, whatever its parameters cell says.
    timeout : float
        Seconds a notebook may run in all; then its process and kernel are
        killed and it is graded as it stands ("timeout").
    cell_timeout : float
        Seconds a cell may run; then it is interrupted, recorded as an error,
        and the next cells run.
    progress : callable, optional
        ``progress(index, total, submission)`` after each notebook.

    Returns
    -------
    list of Submission

    Raises
    ------
    GradeError
        The answer key cannot be read, or a time limit is not positive.
    uio_teach.instructor.output.OutputError
        ``out`` is a folder, or its feedback folder exists and is not one of
        an earlier grading (checked before any notebook runs).

    Examples
    --------
    >>> from uio_teach.instructor.grade import grade, GradeError
    >>> try:
    ...     grade([], "grades.csv", timeout=0)
    ... except GradeError as err:
    ...     print(err)
    timeout: must be > 0 s, got 0
    """
    for name, value in (("timeout", timeout), ("cell_timeout", cell_timeout)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
            raise GradeError(f"{name}: must be > 0 s, got {value!r}")
    key = read_answer_key(answer_key) if answer_key is not None else None
    _check_gradebook_target(out)  # before the notebooks run, not after
    registry = _registry()
    graded: list[Submission] = []
    paths = [Path(p) for p in submissions]
    for index, path in enumerate(paths, start=1):
        sub = _grade_one(path, key, registry, min(cell_timeout, timeout), timeout)
        graded.append(sub)
        if progress is not None:
            progress(index, len(paths), sub)
    # without a registry, a lab's checks are those its submissions' check cells produced
    seen: dict[str, list[str]] = {}
    for sub in graded:
        ids = seen.setdefault(sub.lab, [])
        ids += [i for i in (*sub.expected, *sub.results) if i not in ids]
    for sub in graded:
        if not sub.expected:
            sub.expected = tuple(seen.get(sub.lab, ()))
    write_gradebook(graded, out)
    return graded


def _execute(src: str, dst: str, cell_timeout: float, pid_file: str) -> int:
    """Run a prepared copy in a fresh kernel (the child process of :func:`_run_copy`)."""
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(src, as_version=4)
    client = NotebookClient(
        nb,
        timeout=cell_timeout,
        kernel_name="python3",
        allow_errors=True,
        interrupt_on_timeout=True,
        error_on_timeout={
            "ename": "TimeoutError",
            "evalue": f"the cell ran longer than {cell_timeout:g} s and was interrupted",
            "traceback": [],
        },
        resources={"metadata": {"path": os.path.dirname(os.path.abspath(src))}},
    )

    def started(**_: Any) -> None:
        pid = getattr(getattr(client.km, "provisioner", None), "pid", None)
        if pid:
            Path(pid_file).write_text(str(pid))

    def save(**_: Any) -> None:  # so that a run killed at the time limit still tells something
        part = dst + ".part"
        nbformat.write(nb, part)
        os.replace(part, dst)

    client.on_notebook_start = started
    client.on_cell_executed = save
    try:
        client.execute()
    finally:
        save()
    return 0


if __name__ == "__main__":  # pragma: no cover - the child process of _run_copy
    if len(sys.argv) == 6 and sys.argv[1] == "--run":
        sys.exit(_execute(sys.argv[2], sys.argv[3], float(sys.argv[4]), sys.argv[5]))
    sys.exit("usage: python -m uio_teach.instructor.grade --run IN OUT CELL_TIMEOUT PID_FILE")
