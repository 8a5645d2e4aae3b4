"""Grade submitted lab notebooks: each run sandboxed, its answers checked in the grader's process.

:func:`grade` takes the notebooks the groups handed in and, for each one:

1. reads it (the submission itself is never written to) and finds its lab and
   group: from the notebook's metadata ``{"uio_teach": {"lab": ..., "group":
   ...}}``, else from a file name such as ``pa9_g03.ipynb``;
2. makes a copy with every stored output cleared (a stored ✓ counts for
   nothing), the ``parameters`` cell set to the group's parameters from the
   answer key, and small cells added that write the answer variables out as
   data (:mod:`uio_teach.instructor.runner`);
3. runs the copy in a fresh kernel inside a sandbox
   (:mod:`uio_teach.instructor.sandbox`: only its own copy visible, no
   network, no other process, limits on memory, processes and time); a cell
   that raises or loops is recorded and the next cells still run;
4. rebuilds the answers as genuine objects in the grader's own process
   (:mod:`uio_teach.checks.answers`) and runs the lab's checks on them with
   **the answer key's parameters** (:mod:`uio_teach.checks.grading`). The
   verdicts the check cells printed inside the notebook count for nothing, and
   nothing the notebook defines (``PARAMS``, a patched class, a patched
   module) reaches the checks: only right values pass;
5. appends its row to the gradebook and writes its feedback text at once
   (:mod:`uio_teach.instructor.gradebook`), so a killed run keeps every
   finished row and ``resume=True`` grades only what is missing.

``jobs`` submissions run at a time. The temporary folders of a run are
removed when it ends; those of runs that were killed are removed by the next.

Examples
--------
>>> from uio_teach.instructor.grade import group_from_name
>>> group_from_name("submissions/pa9_g03.ipynb")
('pa9', 'g03')
"""

from __future__ import annotations

import ast
import csv
import json
import os
import re
import shutil
import stat
import tempfile
import threading
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from pathlib import Path
from typing import Any

import nbformat

from ..checks.answers import AnswerError, from_data
from ..checks.grading import GRADED, Missing, grade_answers, lab_plant
from ..errors import UIOTeachError, UIOTeachWarning
from .gradebook import (
    FAIL,
    PASS,
    Gradebook,
    GradebookBusy,
    Submission,
    check_gradebook_target,
    feedback_folder,
)
from .labs import LABS
from .runner import RunOutcome, prepare, run_notebook
from .sandbox import Limits, sandbox_problem

__all__ = [
    "GradeError",
    "SandboxRefused",
    "UnsandboxedWarning",
    "Submission",
    "Gradebook",
    "GradebookBusy",
    "Limits",
    "grade",
    "read_answer_key",
    "write_gradebook",
    "group_from_name",
    "clean_leftovers",
    "feedback_folder",
    "PASS",
    "FAIL",
    "TEMP_PREFIX",
]

TEMP_PREFIX = "uio-teach-grade-"
"""The name of every temporary folder of a grading run starts so."""
_OWNER = "owner.json"
_GROUP_NAME = re.compile(r"^(?P<lab>.+?)_(?P<group>g\d+)$")
_CHECKING = threading.Lock()  # the checks run one at a time in the grader's process


class GradeError(UIOTeachError, ValueError):
    """Grading cannot start (a missing answer key, an unreadable key, a bad option); one line."""


class SandboxRefused(GradeError):
    """Submissions cannot be isolated here, and running them unisolated was not asked for."""


class UnsandboxedWarning(UIOTeachWarning):
    """The submissions run with the grader's permissions (``sandbox=False``)."""


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
        if not isinstance(params, dict):
            raise GradeError(f"{name}: line {number}: params is not a JSON object")
        key[(row["lab"], row["group"])] = params
    return key


# temporary folders --------------------------------------------------------------------------


def _start_time(pid: int) -> str | None:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19]
    except (OSError, IndexError):
        return None


def _remove(folder: Path) -> None:
    def unlock(func: Callable[..., Any], path: str, _: Any) -> None:
        try:  # a submission may leave a folder without write permission
            os.chmod(os.path.dirname(path), stat.S_IRWXU)
            os.chmod(path, stat.S_IRWXU)
            func(path)
        except OSError:
            pass

    shutil.rmtree(folder, onerror=unlock)


def clean_leftovers(root: str | os.PathLike[str] | None = None) -> list[Path]:
    """Remove the temporary folders of grading runs that were killed (ours only).

    A run's folder holds ``owner.json`` (the grading process and its start
    time); it is removed when that process no longer runs. Folders of other
    users, or without that file, are left alone.

    Parameters
    ----------
    root : path, optional
        Where the runs' folders are (the system's temporary folder by default).

    Returns
    -------
    list of pathlib.Path
        The folders removed.

    Examples
    --------
    >>> import tempfile
    >>> from uio_teach.instructor.grade import clean_leftovers
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     clean_leftovers(tmp)
    []
    """
    root = Path(root or tempfile.gettempdir())
    removed = []
    for folder in sorted(root.glob(f"{TEMP_PREFIX}*")):
        try:
            info = folder.lstat()
            if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
                continue
            owner = json.loads((folder / _OWNER).read_text(encoding="utf-8"))
            pid, started = int(owner["pid"]), str(owner["start"])
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if _start_time(pid) != started:
            _remove(folder)
            removed.append(folder)
    return removed


# one submission ----------------------------------------------------------------------------


def _lab_of(nb: Any, path: Path) -> tuple[str, str]:
    meta = nb.get("metadata", {}).get("uio_teach", {}) if isinstance(nb, Mapping) else {}
    meta = meta if isinstance(meta, Mapping) else {}
    lab = str(meta.get("lab", "") or "")
    group = str(meta.get("group", "") or "")
    name_lab, name_group = group_from_name(path)
    lab, group = lab or name_lab, group or name_group
    if not lab:
        source = meta.get("source")
        stem = Path(str(source)).stem if source else path.stem
        lab = next((k for k, v in LABS.items() if Path(v.source).stem == stem), "")
        lab = lab or stem.removeprefix("lab_")
    return lab, group


def _read(path: Path) -> tuple[Any, str, str, str]:
    """The notebook (or None), its lab, its group, and why it is unreadable."""
    try:
        nb = nbformat.reads(path.read_bytes().decode("utf-8"), as_version=4)
        if not isinstance(nb.get("cells"), list):
            raise ValueError("no cells")
    except Exception as exc:
        reason = " ".join(str(exc).split())[:200] or type(exc).__name__
        return None, *group_from_name(path), f"not a notebook: {reason}"
    return nb, *_lab_of(nb, path), ""


def _defaults(lab: str) -> dict[str, Any]:
    return LABS[lab].params().to_params()


def _assigns(source: str, name: str) -> bool:
    """Whether the code ``source`` assigns ``name`` (at any depth; ``=``, ``for``, ``with``...)."""
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return re.search(rf"^\s*{re.escape(name)}\s*=(?!=)", source, re.M) is not None
    return any(
        isinstance(node, ast.Name) and node.id == name and isinstance(node.ctx, ast.Store)
        for node in ast.walk(tree)
    )


def _missing(name: str, position: int | None, outcome: RunOutcome) -> Missing:
    """Why ``name`` is absent at ``position``: the cell that raised before it, if any."""
    before = [e for e in outcome.errors if position is None or e.position < position]
    if not before:
        return Missing(name)
    culprit = next((e for e in reversed(before) if _assigns(e.source, name)), None)
    if culprit is None:  # a check cell's error follows from an earlier one
        culprit = ([e for e in before if not e.is_check] or before)[-1]
    return Missing(name, culprit.cell, culprit.ename, culprit.evalue)


def _answers(
    lab: str, outcome: RunOutcome, plant: Any
) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """The answers at the end, and those captured after each check cell, rebuilt."""
    cache: dict[tuple[str, str], Any] = {}

    def rebuild(tag: str, name: str) -> Any:
        if (tag, name) not in cache:
            raw = outcome.captures[tag]
            if name not in raw:
                cache[(tag, name)] = _missing(name, outcome.positions.get(tag), outcome)
            else:
                try:
                    cache[(tag, name)] = from_data(raw[name], plant=plant)
                except (AnswerError, ValueError, TypeError) as err:
                    why = err if isinstance(err, AnswerError) else type(err).__name__
                    cache[(tag, name)] = Missing(
                        name, reason=f"its value could not be read ({why})"
                    )
        return cache[(tag, name)]

    every = sorted({n for check in GRADED[lab] for n in check.names})
    if "final" in outcome.captures:
        final = {n: rebuild("final", n) for n in every}
    else:
        final = {n: _missing(n, None, outcome) for n in every}
    per_check = []
    for index, check in enumerate(GRADED[lab]):
        tag = str(index)
        if tag in outcome.captures:
            per_check.append({n: rebuild(tag, n) for n in check.names})
        else:  # its check cell was deleted or never reached: what the notebook ended with
            per_check.append({n: final[n] for n in check.names})
    return final, per_check


def _error_notes(outcome: RunOutcome) -> list[str]:
    notes = []
    for e in outcome.errors:
        if e.ename in ("KeyboardInterrupt", "TimeoutError"):
            notes.append(
                f"code cell {e.cell} was interrupted: it ran longer than the time limit of a cell"
            )
        else:
            notes.append(f"code cell {e.cell} raised {e.ename or 'an error'}: {e.evalue}")
    return notes + list(outcome.notes)


def _grade_one(
    path: Path,
    key: Mapping[tuple[str, str], dict[str, Any]] | None,
    *,
    root: Path,
    index: int,
    sandbox: bool,
    timeout: float,
    cell_timeout: float,
    limits: Limits,
    stop: threading.Event,
) -> Submission:
    start = time.perf_counter()
    nb, lab, group, unreadable = _read(path)
    sub = Submission(os.fspath(path), lab, group, "ok")
    if lab in GRADED:
        sub.expected = tuple(c.check_id for c in GRADED[lab])
    if nb is None:
        sub.status, sub.errors = "unreadable", [unreadable]
        return sub
    if lab not in GRADED:
        sub.status = "unknown lab"
        sub.errors.append(
            f"lab {lab!r} is not one of the course's labs ({', '.join(GRADED)}): not run"
        )
        return sub
    params = None if key is None else key.get((lab, group))
    if params is None:
        params = _defaults(lab)
        if key is not None:
            sub.errors.append(
                f"no parameters for lab {lab!r}, group {group!r} in the answer key: graded "
                "with the course's own numbers"
            )
    sub.params = params
    copy, positions = prepare(nb, lab, params if key is not None else None)
    folder = root / f"{index:04d}"
    try:
        outcome = run_notebook(
            copy,
            folder,
            positions=positions,
            sandbox=sandbox,
            timeout=timeout,
            cell_timeout=cell_timeout,
            limits=limits,
            stop=stop,
        )
    finally:
        _remove(folder)
    sub.status = outcome.status
    sub.errors += _error_notes(outcome)
    with _CHECKING:
        try:
            plant = lab_plant(lab, params)
            final, per_check = _answers(lab, outcome, plant)
            results = grade_answers(lab, final, params, plant=plant, per_check=per_check)
        except Exception as exc:  # the key itself is wrong: no verdict, one line
            sub.errors.append(f"the grader could not check this lab ({type(exc).__name__})")
            results = []
    sub.results = {r.check_id: r.to_dict() for r in results if r.check_id}
    sub.seconds = time.perf_counter() - start
    return sub


# the run ----------------------------------------------------------------------------------


def write_gradebook(
    submissions: Sequence[Submission], out: str | os.PathLike[str]
) -> tuple[Path, Path]:
    """Write a whole gradebook at once: the CSV and one feedback text per submission.

    :func:`grade` writes its rows one by one as it goes; this writes graded
    submissions in one call (a fresh gradebook, as a run without ``resume``).

    Parameters
    ----------
    submissions : sequence of Submission
        The grades, in the order of the rows.
    out : str or path-like
        The CSV; the feedback goes to ``<stem>_feedback/`` beside it.

    Returns
    -------
    (pathlib.Path, pathlib.Path)
        The CSV and the feedback folder.

    Raises
    ------
    uio_teach.instructor.output.OutputError
        ``out`` is a folder, or its feedback folder is not one of an earlier grading.

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
    columns: list[str] = []
    for sub in submissions:
        columns += [c for c in sub.verdicts() if c not in columns]
    with Gradebook(out, [s.file for s in submissions], columns) as book:
        for sub in submissions:
            book.add(sub)
    return book.out, book.folder


def _positive(name: str, value: Any) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise GradeError(f"{name}: must be > 0 s, got {value!r}")


def grade(
    submissions: Sequence[str | os.PathLike[str]],
    out: str | os.PathLike[str],
    *,
    answer_key: str | os.PathLike[str] | None = None,
    timeout: float = 300.0,
    cell_timeout: float = 60.0,
    progress: Callable[[int, int, Submission], None] | None = None,
    resume: bool = False,
    jobs: int = 1,
    sandbox: bool = True,
    limits: Limits | None = None,
) -> list[Submission]:
    """Grade submitted notebooks; write the gradebook ``out`` (CSV) and the feedback texts.

    Parameters
    ----------
    submissions : sequence of path
        The notebooks handed in. They are only read.
    out : path
        The CSV to write; the feedback goes to ``<stem>_feedback/`` beside it.
        Each row is written as soon as its submission is graded.
    answer_key : path, optional
        ``answer_key.csv`` of ``uio-teach labs --groups``: each submission is
        graded with its group's parameters (and runs with them). Without it,
        with the course's own numbers.
    timeout : float
        Seconds a notebook may run in all; then every process of its run is
        killed and it is graded on what it computed ("timeout").
    cell_timeout : float
        Seconds a cell may run; then it is interrupted, and the next cells run.
    progress : callable, optional
        ``progress(index, total, submission)`` after each notebook.
    resume : bool
        Keep the rows of ``out`` and grade only the submissions that have none.
    jobs : int
        How many submissions run at a time.
    sandbox : bool
        Run each submission in the sandbox (refused where it is unavailable).
        ``False`` runs the students' code with your permissions, with a
        :class:`UnsandboxedWarning`.
    limits : Limits, optional
        Memory, processes, file size and CPU time of a run.

    Returns
    -------
    list of Submission
        The submissions graded by this call (with ``resume``, not those kept).

    Raises
    ------
    GradeError
        The answer key cannot be read, an option is out of range.
    SandboxRefused
        The sandbox is unavailable and ``sandbox`` is True.
    uio_teach.instructor.output.OutputError
        ``out`` is a folder, its feedback folder is not ours, or another run
        is writing it (checked before any notebook runs).

    Examples
    --------
    >>> from uio_teach.instructor.grade import grade, GradeError
    >>> try:
    ...     grade([], "grades.csv", timeout=0)
    ... except GradeError as err:
    ...     print(err)
    timeout: must be > 0 s, got 0
    """
    _positive("timeout", timeout)
    _positive("cell_timeout", cell_timeout)
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise GradeError(f"jobs: must be a whole number >= 1, got {jobs!r}")
    key = read_answer_key(answer_key) if answer_key is not None else None
    check_gradebook_target(out)  # before the notebooks run, not after
    if sandbox:
        problem = sandbox_problem()
        if problem is not None:
            raise SandboxRefused(
                f"cannot isolate the submissions: {problem}. Grading runs the students' code; "
                "--no-sandbox runs it with your permissions (only for notebooks you trust)"
            )
    else:
        warnings.warn(
            "the submissions run WITHOUT a sandbox, with your permissions: a notebook can read "
            "the answer key and your files, change the gradebook, and end your processes",
            UnsandboxedWarning,
            stacklevel=2,
        )
    limits = limits or Limits(cpu_seconds=int(timeout) + 60)
    clean_leftovers()
    files = [os.fspath(p) for p in submissions]
    labs = [_read(Path(f))[1] for f in files]
    columns: list[str] = []
    for lab in labs:
        columns += [c.check_id for c in GRADED.get(lab, ()) if c.check_id not in columns]
    graded: list[Submission] = []
    with Gradebook(out, files, columns, resume=resume) as book:
        todo = [(i, f) for i, f in enumerate(files) if f not in book.done]
        todo = [(i, f) for n, (i, f) in enumerate(todo) if f not in {g for _, g in todo[:n]}]
        root = Path(tempfile.mkdtemp(prefix=TEMP_PREFIX))
        try:
            (root / _OWNER).write_text(
                json.dumps({"pid": os.getpid(), "start": _start_time(os.getpid())}),
                encoding="utf-8",
            )
            stop = threading.Event()
            with ThreadPoolExecutor(max_workers=jobs) as pool:
                running: dict[Future[Submission], str] = {}
                queue = list(todo)
                try:
                    while queue or running:
                        while queue and len(running) < jobs:
                            index, file = queue.pop(0)
                            future = pool.submit(
                                _grade_one,
                                Path(file),
                                key,
                                root=root,
                                index=index,
                                sandbox=sandbox,
                                timeout=timeout,
                                cell_timeout=min(cell_timeout, timeout),
                                limits=limits,
                                stop=stop,
                            )
                            running[future] = file
                        finished, _ = wait(running, return_when=FIRST_COMPLETED)
                        for future in finished:
                            running.pop(future)
                            sub = future.result()
                            book.add(sub)
                            graded.append(sub)
                            if progress is not None:
                                progress(len(graded), len(todo), sub)
                finally:  # interrupted: stop every run still going, keep the finished rows
                    stop.set()
                    for future in running:
                        future.cancel()
        finally:
            _remove(root)
    order = {f: i for i, f in enumerate(files)}
    graded.sort(key=lambda s: order[s.file])
    return graded
