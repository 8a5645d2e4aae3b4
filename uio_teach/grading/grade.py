"""Grade a class's hand-ins: each run sandboxed, its answers checked in a limited process.

:func:`grade` takes the hand-in folder (or the files) and, for each hand-in:

1. reads it without following links (:func:`read_handin`): only a regular
   file of the folder is read, never written; its group comes from the file
   name (``pa9_g03.ipynb``) or the roster
   (:func:`~uio_teach.grading.rosters.read_roster`), and what the
   notebook's metadata says is only compared with it; a clean copy of its
   cells is made (``uio_teach.grading.runner.clean_notebook``);
2. compares the class (``_identity_notes``): a notebook that disagrees
   with its name, a group handing in twice, the same code from two groups
   (once comments, layout and the names of its own variables are set aside:
   ``uio_teach.grading.copies``) or no group at all is "check by hand",
   never ``ok``;
3. makes a copy with every stored output cleared (a stored ✓ counts for
   nothing), the ``parameters`` cell set to the group's parameters from the
   answer key, and small cells added that write the answer variables out as
   data (``uio_teach.grading.runner``);
4. runs the copy in a fresh kernel inside a sandbox
   (``uio_teach.grading.sandbox``: only its own copy visible, no
   network, no other process, an unprivileged user when the grader is root,
   limits on memory, processes, writes and time); a cell that raises or
   loops is recorded and the next cells still run;
5. checks the answers in a child process with limits of time and memory
   (``uio_teach.grading.checking``): answers over the size caps are not
   rebuilt, the rest are rebuilt as genuine objects and checked by the lab
   chapter's own check cells with **the answer key's parameters**
   (``uio_teach.grading.lab_checks``). The verdicts
   the check cells printed count for nothing, and nothing the notebook
   defines (``PARAMS``, a patched class, a patched module) reaches the
   checks: only right values pass;
6. appends its row to the gradebook and writes its feedback at once
   (``uio_teach.grading.gradebook``), so a killed or interrupted run
   keeps every finished row and ``resume=True`` grades only what is missing.

Whatever fails on one hand-in (reading, preparing, running, reading back,
checking, or the grader itself) becomes that row's status with a one-line
reason; the run goes on. ``jobs`` hand-ins run at a time, from the start:
the sandbox is tested with the real interpreter and a one-cell notebook
beside the first ones, and no row is written before that test has passed.
With ``shard=(K, N)`` only shard K of N is graded (every hand-in still read:
copies are caught across shards), for ``uio_teach.grading.merge``. The
temporary folders of a run are removed when it ends; those of runs that were
killed are removed by the next.

Examples
--------
>>> from uio_teach.grading.grade import group_from_name
>>> group_from_name("submissions/pa9_g03.ipynb")
('pa9', 'g03')
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import shutil
import stat
import sys
import tempfile
import threading
import time
import warnings
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import nbformat

from ..errors import UIOTeachWarning
from ..folders import sha256_file
from .checking import check_in_child
from .copies import MIN_STATEMENTS, SIMILAR, fingerprint, similarity, statements
from .gradebook import (
    EXPORTS,
    FAIL,
    PASS,
    Gradebook,
    GradebookBusy,
    Submission,
    check_gradebook_target,
    export_path,
    feedback_folder,
)
from .lab_checks import CHECK_TAG, LabChecks, LabChecksError, course_checks, course_labs
from .merge import check_shard, shard_of
from .rosters import (
    GradeError,
    group_from_name,
    group_id,
    is_late,
    read_answer_key,
    read_roster,
    same_form,
)
from .runner import RunOutcome, clean_notebook, prepare, run_notebook
from .sandbox import (
    OWNER,
    TEMP_PREFIX,
    Limits,
    SandboxUser,
    own_folder,
    sandbox_problem,
    start_time,
)
from .survey import Survey, added_since, survey

__all__ = [
    "GradeError",
    "SandboxRefused",
    "UnsandboxedWarning",
    "Submission",
    "Gradebook",
    "GradebookBusy",
    "Limits",
    "grade",
    "Handin",
    "read_handin",
    "handin_files",
    "read_roster",
    "NEEDS_A_LOOK",
    "read_answer_key",
    "write_gradebook",
    "group_from_name",
    "clean_leftovers",
    "feedback_folder",
    "PASS",
    "FAIL",
    "TEMP_PREFIX",
    "Graded",
    "SELF_TEST_FOLDER",
    "self_test_key",
]


class Graded(list):
    """The submissions a run graded (a list), and what else its hand-in folder held.

    Attributes
    ----------
    survey : Survey or None
        The hand-in folder as the run found it (None when files were given):
        the hand-ins, and every other entry with why it is not graded.
    added : list of (str, str)
        What appeared in the folder during the run, not graded.

    Examples
    --------
    >>> from uio_teach.grading.grade import Graded
    >>> result = Graded([])
    >>> len(result), result.survey, result.added
    (0, None, [])
    """

    survey: Survey | None = None
    added: list[tuple[str, str]] = []


class SandboxRefused(GradeError):
    """Submissions cannot be isolated here, and running them unisolated was not asked for."""


class UnsandboxedWarning(UIOTeachWarning):
    """The submissions run with the grader's permissions (``sandbox=False``)."""


# temporary folders --------------------------------------------------------------------------


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
    >>> from uio_teach.grading.grade import clean_leftovers
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
            owner = json.loads((folder / OWNER).read_text(encoding="utf-8"))
            pid, started = int(owner["pid"]), str(owner["start"])
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if start_time(pid) != started:
            _remove(folder)
            removed.append(folder)
    return removed


# one hand-in ------------------------------------------------------------------------------

MAX_HANDIN_BYTES = 32 * 1024 * 1024
"""The largest hand-in read (a larger file is a refused row)."""
NEEDS_A_LOOK = (
    "grader error",
    "refused",
    "unreadable",
    "unknown lab",
    "check by hand",
    "over limits",
)
"""The statuses of rows an instructor should look at (the others are marks as they stand)."""


@dataclass
class Handin:
    """One hand-in as the grader found it, before it runs (see :func:`read_handin`).

    Examples
    --------
    >>> from uio_teach.grading.grade import Handin
    >>> Handin("pa9_g01.ipynb", "pa9", "g01").status
    ''

    Attributes
    ----------
    file : str
        The path as given.
    lab, group : str
        From the roster, else from the file name (never from the notebook).
    notebook : NotebookNode or None
        The grader's clean copy (``uio_teach.grading.runner.clean_notebook``).
    status, reason : str
        ``"refused"`` or ``"unreadable"`` and why (empty when it can run).
    notes : list of str
        What the grader noticed (a dropped cell, what the notebook says of itself).
    meta_lab, meta_group : str
        The lab and group the notebook's metadata claims.
    code : str
        A fingerprint of its code (for hand-ins copied between groups).
    units : collections.Counter
        Its code as normalised statements (for near-copies,
        :func:`uio_teach.grading.copies.statements`).
    """

    file: str
    lab: str = ""
    group: str = ""
    notebook: Any = None
    status: str = ""
    reason: str = ""
    notes: list[str] = field(default_factory=list)
    meta_lab: str = ""
    meta_group: str = ""
    code: str = ""
    units: Counter[str] = field(default_factory=Counter)


def _kind(mode: int) -> str:
    if stat.S_ISLNK(mode):
        return "a link, not a file: hand-ins must be regular files in the hand-in folder"
    if stat.S_ISDIR(mode):
        return "a folder, not a notebook file"
    return "not a regular file (a device, a pipe or a socket)"


def _read_bytes(path: Path) -> tuple[bytes | None, str]:
    """The bytes of a hand-in, or why it is refused; links are never followed."""
    try:
        info = os.lstat(path)
    except OSError as err:
        return None, f"cannot be read ({err.strerror or type(err).__name__})"
    if not stat.S_ISREG(info.st_mode):
        return None, _kind(info.st_mode)
    if info.st_nlink > 1:
        return None, "a second name (a hard link) of another file: hand in a copy"
    if info.st_size > MAX_HANDIN_BYTES:
        return None, f"larger than {MAX_HANDIN_BYTES >> 20} MB"
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path, flags | getattr(os, "O_NOCTTY", 0))
    except OSError as err:
        return None, f"cannot be read ({err.strerror or type(err).__name__})"
    with os.fdopen(fd, "rb") as fh:
        now = os.fstat(fh.fileno())
        if not stat.S_ISREG(now.st_mode) or (now.st_ino, now.st_dev) != (
            info.st_ino,
            info.st_dev,
        ):
            return None, "changed while it was read (it is no longer the same regular file)"
        data = fh.read(MAX_HANDIN_BYTES + 1)
    if len(data) > MAX_HANDIN_BYTES:
        return None, f"larger than {MAX_HANDIN_BYTES >> 20} MB"
    return data, ""


def _parse(data: bytes) -> tuple[Any, str]:
    """The JSON of a hand-in, or why it is not a notebook (never quoting its content)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return None, "not a notebook: not UTF-8 text"
    try:
        return json.loads(text), ""
    except json.JSONDecodeError as err:
        return None, f"not a notebook: not JSON (line {err.lineno}, column {err.colno})"
    except (ValueError, RecursionError):
        return None, "not a notebook: not JSON"


def _meta(raw: Any) -> tuple[str, str, str]:
    meta = raw.get("metadata") if isinstance(raw, dict) else None
    meta = meta.get("uio_teach") if isinstance(meta, dict) else None
    meta = meta if isinstance(meta, dict) else {}

    def text(key: str) -> str:
        value = meta.get(key)
        return _one_line(value, 40) if isinstance(value, str) else ""

    return text("lab"), group_id(text("group")), text("source")


def _one_line(text: Any, limit: int = 200) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _own_code(nb: Any) -> list[str]:
    """The code cells of a notebook but those every group has alike: ``parameters``, ``check``."""
    sources = []
    for cell in nb.cells:
        tags = cell.get("metadata", {}).get("tags", [])
        if cell.get("cell_type") != "code" or {"parameters", CHECK_TAG} & set(tags):
            continue
        sources.append(cell.source)
    return sources


def read_handin(
    path: str | os.PathLike[str],
    roster: Mapping[str, tuple[str, str]] | None = None,
    *,
    keep: Iterable[str] = (),
) -> Handin:
    """Read one hand-in: refuse what is not a regular file, parse it, find its lab and group.

    The file is opened without following links; a link, a folder, a device,
    a second name of another file or a file over ``MAX_HANDIN_BYTES`` is
    refused, and nothing of it is read. The group and lab come from the
    roster (by file name), else from a name like ``pa9_g03.ipynb``; what the
    notebook's metadata says is kept only to compare.

    Parameters
    ----------
    path : str or path-like
    roster : mapping, optional
        File name -> (lab, group), from :func:`~uio_teach.grading.rosters.read_roster`.
    keep : iterable of str
        The answer variables of the labs: names a copy cannot change
        (see ``uio_teach.grading.copies``).

    Returns
    -------
    Handin

    Examples
    --------
    >>> import tempfile, pathlib, os
    >>> from uio_teach.grading.grade import read_handin
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     link = pathlib.Path(tmp) / "pa9_g01.ipynb"
    ...     os.symlink("/etc/passwd", link)
    ...     h = read_handin(link)
    >>> h.status, h.group, h.reason.split(":")[0]
    ('refused', 'g01', 'a link, not a file')
    """
    file = os.fspath(path)
    name_lab, name_group = group_from_name(file)
    lab, group = (roster or {}).get(same_form(Path(file).name), (name_lab, name_group))
    lab = lab or name_lab
    handin = Handin(file, lab, group)
    if is_late(file):
        handin.notes.append("the LMS marked this hand-in late (_LATE_ in its name)")
    data, why = _read_bytes(Path(file))
    if data is None:
        handin.status, handin.reason = "refused", why
        return handin
    raw, why = _parse(data)
    if raw is not None:
        try:
            handin.notebook, notes = clean_notebook(raw)
            handin.notes += notes
        except ValueError as err:
            why = (
                str(err)
                if str(err).startswith(("not a notebook", "a notebook"))
                else (f"not a notebook: {err}")
            )
    if handin.notebook is None:
        handin.status, handin.reason = "unreadable", why
        return handin
    handin.meta_lab, handin.meta_group, source = _meta(raw)
    if not handin.lab:
        stem = Path(source).stem if source else Path(file).stem
        handin.lab = handin.meta_lab or next((k for k in course_labs() if f"lab_{k}" == stem), "")
    sources = _own_code(handin.notebook)
    handin.code = fingerprint(sources, keep=keep)
    handin.units = statements(sources, keep=keep)
    return handin


def _identity_notes(
    handins: Sequence[Handin], given: Mapping[str, Counter[str]] | None = None
) -> dict[str, list[str]]:
    """File -> why its identity needs a look: the notebook disagrees, a group twice, a copy.

    ``given`` (lab -> the statements of the course's own code of that lab) is set aside before
    code is compared: a hand-in with nothing of its own (an untouched template) is no copy.
    """
    given = given or {}
    notes: dict[str, list[str]] = {h.file: [] for h in handins}
    for h in handins:
        if h.status:
            continue
        if not h.group:
            said = f" (the notebook says {h.meta_group})" if h.meta_group else ""
            notes[h.file].append(
                f"no group: the file name is not <lab>_<group>.ipynb and no roster names it{said}"
            )
        elif h.meta_group and h.meta_group != h.group:
            notes[h.file].append(
                f"the notebook says group {h.meta_group}, its file name or the roster {h.group}"
            )
        if h.meta_lab and h.lab and h.meta_lab != h.lab:
            notes[h.file].append(f"the notebook says lab {h.meta_lab}, its file name {h.lab}")
    by_group: dict[tuple[str, str], list[Handin]] = {}
    by_code: dict[str, list[Handin]] = {}
    for h in handins:
        if h.status:
            continue
        if h.group:
            by_group.setdefault((h.lab, h.group), []).append(h)
        if h.code and h.units - given.get(h.lab, Counter()):  # something of its own
            by_code.setdefault(h.code, []).append(h)
    for (_, group), same in by_group.items():
        for h in same if len(same) > 1 else ():
            others = ", ".join(o.file for o in same if o is not h)
            notes[h.file].append(f"group {group} handed in more than once (also {others})")
    for same in by_code.values():
        if len({h.group for h in same}) < 2:
            continue
        for h in same:
            others = ", ".join(
                f"group {o.group or '(none)'} ({o.file})" for o in same if o.group != h.group
            )
            notes[h.file].append(
                f"the same code as {others}, once comments, blank lines, formatting and the "
                "names of variables are set aside"
            )
    exact = {h.file for same in by_code.values() if len({h.group for h in same}) > 1 for h in same}
    _near_copies(handins, given, notes, exact)
    return notes


def _near_copies(
    handins: Sequence[Handin],
    given: Mapping[str, Counter[str]],
    notes: dict[str, list[str]],
    exact: set[str],
) -> None:
    """Note every pair of groups of one lab whose own statements are mostly alike.

    Set aside first: the course's own code of the lab and, in a class of four hand-ins or
    more, what at least half of them hold (what everyone writes is no sign of a copy).
    """
    labs: dict[str, list[Handin]] = {}
    for h in handins:
        if not h.status and h.units:
            labs.setdefault(h.lab, []).append(h)
    for lab, same in labs.items():
        common = Counter(given.get(lab, Counter()))
        if len(same) >= 4:
            seen = Counter(s for h in same for s in set(h.units))
            common |= Counter({s: 1 << 30 for s, n in seen.items() if 2 * n >= len(same)})
        for i, a in enumerate(same):
            for b in same[i + 1 :]:
                if a.group == b.group or (a.file in exact and b.file in exact):
                    continue
                share, smaller = similarity(a.units, b.units, common)
                if share < SIMILAR or smaller < MIN_STATEMENTS:
                    continue
                for h, o in ((a, b), (b, a)):
                    notes[h.file].append(
                        f"code much like group {o.group or '(none)'}'s ({o.file}): {share:.0%} "
                        "of their own statements alike, once names, numbers as written, "
                        "statement order, cells, dead code, prints and equivalent calls are "
                        "set aside"
                    )


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


@dataclass(frozen=True)
class _Run:
    """The settings every hand-in of one grading run shares."""

    key: Mapping[tuple[str, str], dict[str, Any]] | None
    checks: Mapping[str, LabChecks]
    root: Path
    sandbox: bool
    timeout: float
    cell_timeout: float
    check_timeout: float
    limits: Limits
    stop: threading.Event


def _grade_one(handin: Handin, identity: list[str], index: int, run: _Run) -> Submission:
    start = time.perf_counter()
    sub = Submission(handin.file, handin.lab, handin.group, "ok", late=is_late(handin.file))
    if handin.lab in run.checks:
        sub.expected = run.checks[handin.lab].check_ids
    try:
        _run_one(sub, handin, identity, index, run)
    except InterruptedError:
        raise
    except Exception as exc:  # any failure of the grader on this hand-in is this row's, only
        sub.status = "grader error"
        sub.reason = (
            f"the grader failed on this hand-in ({type(exc).__name__}: {_one_line(exc, 120)})"
        )
        sub.errors.append(sub.reason)
    sub.seconds = time.perf_counter() - start
    return sub


def _run_one(sub: Submission, handin: Handin, identity: list[str], index: int, run: _Run) -> None:
    key, sandbox, limits, stop = run.key, run.sandbox, run.limits, run.stop
    lab, group = handin.lab, handin.group
    if handin.status:
        sub.status, sub.reason = handin.status, handin.reason
        sub.errors.append(handin.reason)
        return
    sub.errors += handin.notes
    sub.errors += identity
    if lab not in run.checks:
        sub.status = "unknown lab"
        labs = ", ".join(run.checks)
        sub.reason = f"lab {lab!r} is not one of the course's labs ({labs}): not run"
        sub.errors.append(sub.reason)
        return
    params = None if key is None else key.get((lab, group))
    if key is not None and params is None:
        sub.status = "check by hand"
        if group:
            sub.reason = (
                f"group {group!r} of lab {lab!r} is not in the answer key; not run: check the "
                "group its file name or the roster gives against the key's groups"
            )
        else:
            why = identity[0] if identity else "no group"
            sub.reason = f"{why}; not run: name the file <lab>_<group>.ipynb or list it in --roster"
        sub.errors.append(sub.reason)
        return
    checks = run.checks[lab]
    if params is None:
        params = checks.default_params()
    sub.params = params
    copy, positions = prepare(
        handin.notebook, checks, params if key is not None else None, output_mb=limits.output_mb
    )
    folder = run.root / f"{index:04d}"
    # a user id of its own on the whole machine, held until every process of the run has ended
    with SandboxUser() if sandbox else contextlib.nullcontext() as user:
        try:
            outcome = run_notebook(
                copy,
                folder,
                positions=positions,
                sandbox=sandbox,
                timeout=run.timeout,
                cell_timeout=run.cell_timeout,
                limits=limits,
                stop=stop,
                user=user,
            )
        finally:
            _remove(folder)
    if outcome.status == "interrupted":
        raise InterruptedError("the grading run was interrupted")
    sub.status = outcome.status
    sub.errors += _error_notes(outcome)
    request = {
        "checks": checks.to_dict(),
        "params": params,
        "positions": outcome.positions,
        "errors": [
            {
                "cell": e.cell,
                "position": e.position,
                "ename": e.ename,
                "evalue": e.evalue,
                "source": e.source,
                "is_check": e.is_check,
            }
            for e in outcome.errors
        ],
        "captures": outcome.captures,
    }
    checked = check_in_child(
        request, timeout=run.check_timeout, memory_mb=limits.memory_mb, stop=stop
    )
    sub.results = {
        str(r.get("check_id")): r
        for r in checked.results
        if isinstance(r, dict) and r.get("check_id")
    }
    sub.errors += checked.notes
    over = [n for n in outcome.notes if "more than" in n or "larger than" in n]
    if checked.over or sub.status == "over limits":
        sub.status = "over limits"
        sub.reason = (checked.notes or over or ["a limit was reached"])[0]
    if identity:
        sub.status, sub.reason = "check by hand", identity[0]
    elif not group:
        sub.status, sub.reason = "check by hand", "no group: graded with the course's own numbers"
    if sub.status == "grader error" and not identity:
        sub.reason = next((n for n in outcome.notes if "runner failed" in n), "the grader failed")
    if sub.status in ("error", "timeout") and not sub.reason:
        sub.reason = (sub.errors or [sub.status])[0]


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
    uio_teach.folders.OutputError
        ``out`` is a folder, or its feedback folder is not one of an earlier grading.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.grading.grade import Submission, write_gradebook
    >>> s = Submission("a.ipynb", "pa9", "g01", "ok", expected=("pa9.design",))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     csv_path, folder = write_gradebook([s], pathlib.Path(tmp) / "grades.csv")
    ...     print(csv_path.read_text(encoding="utf-8").splitlines()[1])
    ...     print(sorted(p.name for p in folder.iterdir()))
    a.ipynb,pa9,g01,ok,,✗,0,1,
    ['a.html', 'a.txt', 'manifest.json']
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


_SELF_TEST: dict[tuple[Any, ...], str | None] = {}
SELF_TEST_FOLDER = "/var/tmp/uio-teach-sandbox-test-{uid}"
"""Where a passed test of the sandbox is remembered, for every run of the machine by the same
user (a folder of that user's alone; ``{uid}`` is the user's id)."""


def self_test_key(limits: Limits) -> str:
    """What a passed test of the sandbox holds for: the interpreter, the package's code (its
    version and every module's size and time), bubblewrap and the limits (CPU time aside).

    Parameters
    ----------
    limits : Limits

    Returns
    -------
    str
        A SHA-256, as 64 hexadecimal digits.

    Examples
    --------
    >>> from uio_teach.grading.grade import Limits, self_test_key
    >>> self_test_key(Limits()) == self_test_key(Limits(cpu_seconds=5))
    True
    >>> self_test_key(Limits()) == self_test_key(Limits(memory_mb=1024))
    False
    """
    import uio_teach  # deferred on purpose: only to find the package's own files

    package = Path(uio_teach.__file__).resolve().parent
    files = []
    for path in sorted(package.rglob("*.py")):
        if "_course" in path.relative_to(package).parts:
            continue
        info = path.stat()
        files.append([path.relative_to(package).as_posix(), info.st_size, info.st_mtime_ns])
    bwrap = shutil.which("bwrap") or "/usr/bin/bwrap"
    try:
        bwrap_time = os.stat(bwrap).st_mtime_ns
    except OSError:
        bwrap_time = 0
    what = {
        "python": [sys.executable, sys.version],
        "uio_teach": [uio_teach.__version__, os.fspath(package), files],
        "bwrap": [bwrap, bwrap_time],
        "limits": dataclasses.asdict(dataclasses.replace(limits, cpu_seconds=0)),
        "uid": os.geteuid() if hasattr(os, "geteuid") else None,
        "kernel": os.uname().release if hasattr(os, "uname") else "",
    }
    return hashlib.sha256(json.dumps(what, sort_keys=True).encode()).hexdigest()


def _self_test_folder() -> Path | None:
    """The machine's folder of passed sandbox tests of this user, or None (then none is kept)."""
    if not hasattr(os, "geteuid"):  # pragma: no cover - the sandbox is Linux only
        return None
    folder = Path(SELF_TEST_FOLDER.format(uid=os.geteuid()))
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        info = os.lstat(folder)
    except OSError:
        return None
    if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.geteuid() or info.st_mode & 0o077:
        return None  # not a folder of this user's alone: nothing read from it, nothing kept
    return folder


def _self_test(limits: Limits, stop: threading.Event | None = None) -> str | None:
    """Run one tiny notebook through the sandbox as a hand-in runs; why it failed, or None.

    A test that passed is remembered on the machine (:data:`SELF_TEST_FOLDER`, by
    :func:`self_test_key`): every later run and shard with the same interpreter, package, bubblewrap
    and limits starts without it, and runs that start together wait for the one test (a lock).
    A failure is not remembered. ``stop`` (the run was interrupted) ends it at once; that
    answer is not kept.
    """
    key = (sys.executable, dataclasses.replace(limits, cpu_seconds=0))  # CPU time aside
    if key in _SELF_TEST:
        return _SELF_TEST[key]
    folder = _self_test_folder()
    if folder is None:
        return _self_test_now(key, limits, stop)
    import fcntl  # deferred on purpose: POSIX only, so the package imports everywhere

    name = self_test_key(limits)
    passed = folder / f"{name}.passed"
    fd = os.open(folder / f"{name}.lock", os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)  # another run testing the same: wait for its answer
        if passed.is_file() and not passed.is_symlink():
            _SELF_TEST[key] = None
            return None
        problem = _self_test_now(key, limits, stop)
        if problem is None:
            passed.write_text(json.dumps({"python": sys.executable}) + "\n", encoding="utf-8")
        return problem
    finally:
        os.close(fd)


def _self_test_now(
    key: tuple[Any, ...], limits: Limits, stop: threading.Event | None
) -> str | None:
    problem = sandbox_problem()
    if problem is None:
        nb = nbformat.v4.new_notebook()
        nb.metadata["kernelspec"] = {
            "name": "python3",
            "display_name": "Python 3",
            "language": "python",
        }
        nb.cells.append(nbformat.v4.new_code_cell("import uio_teach\nx = 1 + 1"))
        copy, positions = prepare(nb, None, None)
        root = Path(tempfile.mkdtemp(prefix=TEMP_PREFIX))
        try:
            with SandboxUser() as user:
                outcome = run_notebook(
                    copy,
                    root / "self-test",
                    positions=positions,
                    sandbox=True,
                    timeout=180,
                    cell_timeout=120,
                    limits=limits,
                    user=user,
                    stop=stop,
                )
        finally:
            _remove(root)
        if outcome.status == "interrupted":
            return "the run was interrupted"
        if outcome.status != "ok" or "final" not in outcome.captures:
            why = "; ".join(_error_notes(outcome)) or outcome.status
            problem = f"a one-cell notebook does not run in the sandbox ({_one_line(why, 300)})"
    _SELF_TEST[key] = problem
    return problem


def grade(
    submissions: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
    out: str | os.PathLike[str],
    *,
    answer_key: str | os.PathLike[str] | None = None,
    roster: str | os.PathLike[str] | None = None,
    timeout: float = 300.0,
    cell_timeout: float = 60.0,
    check_timeout: float = 120.0,
    progress: Callable[[int, int, Submission], None] | None = None,
    resume: bool = False,
    jobs: int = 1,
    sandbox: bool = True,
    limits: Limits | None = None,
    shard: tuple[int, int] | None = None,
) -> list[Submission]:
    """Grade hand-ins; write the gradebook ``out`` (CSV), its exports and the feedback.

    Every hand-in gets its row, whatever happens to it: a file that is not a
    regular file of the hand-in folder is refused, a file that is not a
    notebook is unreadable, a notebook whose identity disagrees (its metadata
    against its file name or the roster, a group handing in twice, the same
    code from two groups, no group) is "check by hand", answers over the
    caps or checks over their limits are "over limits", and any failure of
    the grader itself on one hand-in is that row's "grader error". The run
    goes on; see ``NEEDS_A_LOOK``.

    Parameters
    ----------
    submissions : path or sequence of path
        The hand-in folder, or the hand-ins. They are only read. Every entry
        of a folder named ``*.ipynb`` (any case), at any depth (an LMS's
        download in folders), is a hand-in with its row; every other entry is
        listed in the result's ``survey`` with why it is not graded, and what
        appears during the run in its ``added`` (see ``uio_teach.grading.survey``).
    out : path
        The CSV to write; the feedback goes to ``<stem>_feedback/`` beside it,
        the LMS exports to ``<stem>_groups.csv``, ``<stem>_canvas.csv`` and
        ``<stem>_moodle.csv``.
        Each row is written as soon as its hand-in is graded.
    answer_key : path, optional
        ``answer_key.csv`` of ``uio-teach labs --groups``: each hand-in is
        graded with its group's parameters (and runs with them). Without it,
        with the course's own numbers.
    roster : path, optional
        A CSV naming each hand-in's group (see :func:`~uio_teach.grading.rosters.read_roster`).
    timeout : float
        Seconds a notebook may run in all; then every process of its run is
        killed and it is graded on what it computed ("timeout").
    cell_timeout : float
        Seconds a cell may run; then it is interrupted, and the next cells run.
    check_timeout : float
        Seconds the checks of one hand-in may take (in their own process).
    progress : callable, optional
        ``progress(index, total, submission)`` after each notebook.
    resume : bool
        Keep the rows of ``out`` and grade only the hand-ins that have none.
    jobs : int
        How many hand-ins run at a time.
    sandbox : bool
        Run each hand-in in the sandbox (refused where it is unavailable).
        ``False`` runs the students' code with your permissions, with a
        ``UnsandboxedWarning``.
    limits : Limits, optional
        Memory, processes, file size, CPU time and writes of a run.
    shard : (int, int), optional
        ``(K, N)``: grade only shard K of N of the hand-ins (each hand-in is in
        exactly one shard, by its file name, whatever order they are listed
        in; see :func:`~uio_teach.grading.merge.shard_of`). Every hand-in is
        still read, so copies and groups handing in twice are caught across
        shards; ``uio-teach merge`` puts the shards' gradebooks together.

    Returns
    -------
    Graded
        The hand-ins graded by this call (with ``resume``, not those kept), a
        list of Submission; with what else the folder held.

    Raises
    ------
    GradeError
        The answer key or the roster cannot be read, an option is out of range.
    SandboxRefused
        The sandbox is unavailable (or cannot run a one-cell notebook) and
        ``sandbox`` is True.
    uio_teach.folders.OutputError
        ``out`` is a folder, its feedback folder is not ours, or another run
        is writing it (checked before any notebook runs).
    KeyboardInterrupt
        The run was interrupted: every run is stopped at once, the finished rows are kept.

    Examples
    --------
    >>> from uio_teach.grading.grade import grade, GradeError
    >>> try:
    ...     grade([], "grades.csv", timeout=0)
    ... except GradeError as err:
    ...     print(err)
    timeout: must be > 0 s, got 0
    """
    _positive("timeout", timeout)
    _positive("cell_timeout", cell_timeout)
    _positive("check_timeout", check_timeout)
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise GradeError(f"jobs: must be a whole number >= 1, got {jobs!r}")
    key = read_answer_key(answer_key) if answer_key is not None else None
    try:
        checks = course_checks()
    except LabChecksError as err:
        raise GradeError(f"cannot read the labs' check cells: {err}") from None
    files_roster, students = read_roster(roster) if roster is not None else ({}, {})
    sources = {
        "answer_key_sha256": sha256_file(answer_key) if answer_key is not None else None,
        "roster_sha256": sha256_file(roster) if roster is not None else None,
    }
    if shard is not None:
        shard = check_shard(shard)
    check_gradebook_target(out)  # before the notebooks run, not after
    limits = limits or Limits(cpu_seconds=int(timeout) + 60)
    if not sandbox:
        warnings.warn(
            "the submissions run WITHOUT a sandbox, with your permissions: a notebook can read "
            "the answer key and your files, change the gradebook, and end your processes",
            UnsandboxedWarning,
            stacklevel=2,
        )
    clean_leftovers()
    folder = _folder_of(submissions)
    own = [out, feedback_folder(out), *(export_path(out, k) for k in EXPORTS)]
    found = survey(folder, own=own) if folder is not None else None
    files = found.handins if found is not None else handin_files(submissions)
    keep = {n for c in checks.values() for n in c.names}
    handins = []
    for file in files:  # every hand-in of the class, also in a shard: copies across shards
        try:
            handins.append(read_handin(file, files_roster, keep=keep))
        except Exception as exc:  # never stops the run: the row says so
            handins.append(
                Handin(file, status="grader error", reason=f"cannot be read ({type(exc).__name__})")
            )
    given = {lab: statements(c.given, keep=c.names) for lab, c in checks.items()}
    identity = _identity_notes(handins, given)
    columns: list[str] = []
    for h in handins:
        ids = checks[h.lab].check_ids if h.lab in checks else ()
        columns += [c for c in ids if c not in columns]
    graded: list[Submission] = []
    book = Gradebook(
        out, files, columns, resume=resume, students=students, shard=shard, sources=sources
    )
    book.lock()  # another run into this gradebook is refused before any notebook runs
    try:
        kept = book.prior()
        todo = [
            (i, h)
            for i, h in enumerate(handins)
            if h.file not in kept and (shard is None or shard_of(h.file, shard[1]) == shard[0])
        ]
        seen: set[str] = set()
        todo = [(i, h) for i, h in todo if not (h.file in seen or seen.add(h.file))]
        _grade_all(
            book,
            todo,
            identity,
            graded,
            progress,
            jobs,
            sandbox,
            limits,
            _Run(
                key,
                checks,
                Path(),
                sandbox,
                timeout,
                min(cell_timeout, timeout),
                check_timeout,
                limits,
                threading.Event(),
            ),
        )
    except BaseException:
        book.__exit__(*sys.exc_info())
        raise
    book.__exit__(None, None, None)
    order = {f: i for i, f in enumerate(files)}
    graded.sort(key=lambda s: order[s.file])
    result = Graded(graded)
    if found is not None and folder is not None:
        result.survey = found
        result.added = added_since(found, survey(folder, own=own))
    return result


def _folder_of(
    submissions: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
) -> Path | None:
    """The hand-in folder, when a folder (not a link to one) was given."""
    if isinstance(submissions, (str, os.PathLike)):
        folder = Path(submissions)
        if folder.is_dir() and not folder.is_symlink():
            return folder
    return None


def _grade_all(
    book: Gradebook,
    todo: Sequence[tuple[int, Handin]],
    identity: Mapping[str, list[str]],
    graded: list[Submission],
    progress: Callable[[int, int, Submission], None] | None,
    jobs: int,
    sandbox: bool,
    limits: Limits,
    settings: _Run,
) -> None:
    """Grade ``todo``, ``jobs`` at a time, while the sandbox is tested beside them.

    The first hand-ins start at once; the one-cell test of the sandbox runs
    beside them, and no row is written before it has passed (the gradebook is
    opened only then: a sandbox that fails leaves an earlier gradebook as it
    was, and every run is stopped).
    """
    root = Path(tempfile.mkdtemp(prefix=TEMP_PREFIX))
    stop = settings.stop
    run = dataclasses.replace(settings, root=root)
    pool = ThreadPoolExecutor(max_workers=jobs)
    tester = ThreadPoolExecutor(max_workers=1)
    # nothing of a student's runs when nothing is to be graded: no test to wait for
    test = tester.submit(_self_test, limits, stop) if sandbox and todo else None
    opened = False
    held: list[Submission] = []
    try:
        own_folder(root)
        running: dict[Future[Submission], Handin] = {}
        queue = list(todo)
        while queue or running or not opened:
            while queue and len(running) < jobs:
                index, handin = queue.pop(0)
                future = pool.submit(_grade_one, handin, identity.get(handin.file, []), index, run)
                running[future] = handin
            waiting: list[Future[Any]] = [*running] + ([test] if test and not opened else [])
            finished, _ = wait(waiting, timeout=0.5, return_when=FIRST_COMPLETED)
            for future in finished:
                if future in running:
                    running.pop(future)
                    held.append(future.result())
            if not opened and (test is None or test.done()):
                problem = test.result() if test is not None else None
                if problem is not None:
                    raise SandboxRefused(
                        f"cannot isolate the hand-ins: {problem}. Grading runs the students' "
                        "code; --no-sandbox runs it with your permissions (only for notebooks "
                        "you trust)"
                    )
                book.open()
                opened = True
            if opened:
                for sub in held:
                    book.add(sub)
                    graded.append(sub)
                    if progress is not None:
                        progress(len(graded), len(todo), sub)
                held.clear()
    finally:  # interrupted: stop every run still going at once, keep the finished rows
        stop.set()
        pool.shutdown(wait=True, cancel_futures=True)
        tester.shutdown(wait=False, cancel_futures=True)
        _remove(root)


def handin_files(
    submissions: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
) -> list[str]:
    """The hand-ins: each ``*.ipynb`` entry of a folder at any depth (links too), or the paths.

    A folder is surveyed (``uio_teach.grading.survey.survey``): an
    entry named ``*.ipynb`` in any case, at any depth, is a hand-in, links
    and folders of that name too (refused when read).

    Parameters
    ----------
    submissions : path or sequence of path

    Returns
    -------
    list of str

    Examples
    --------
    >>> from uio_teach.grading.grade import handin_files
    >>> handin_files(["b.ipynb", "a.ipynb"])
    ['b.ipynb', 'a.ipynb']
    """
    if isinstance(submissions, (str, os.PathLike)):
        folder = _folder_of(submissions)
        return survey(folder).handins if folder is not None else [os.fspath(submissions)]
    return [os.fspath(p) for p in submissions]
