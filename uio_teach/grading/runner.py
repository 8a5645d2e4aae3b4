"""Run one submitted notebook in a sandbox and take its answers out, as data.

:func:`prepare` makes the copy that runs: every stored output cleared, the
``parameters`` cell set to the group's parameters from the answer key (so the
in-notebook checks give the group feedback on its own numbers), and small
cells added: one at the top that defines the exporter, one right after each
check cell that writes the answer variables that check needs to
``answers/<check>.json`` (so a later reassignment does not matter), and one at
the end that writes every answer variable of the lab to ``answers/final.json``
(used for a check whose cell the group deleted).

:func:`run_notebook` runs that copy in a fresh kernel, in a separate process,
inside the :class:`~uio_teach.grading.sandbox.Sandbox` (unless told not to),
with a time limit per cell (the cell is interrupted, the next ones run) and
for the whole notebook (then every process of the run is killed), and a cap
on all it writes into its folder (the run is stopped beyond). It reads back
only data: the answer files (regular files, no links, bounded size, kept as
text for the checking process) and the runner's records. The notebook is
never saved while it runs, so a run costs in proportion to its cells; what it
prints or displays beyond ``Limits.output_mb`` is cut, and the row says so.

The runner's records (the cells that raised, an output that was cut, a
failure of the runner itself, the end of the run) never pass through a place
the notebook can write: the runner writes them into a pipe that only it holds
inside the sandbox (:data:`RECORDS`; the pipe is not passed on to the kernel,
and the runner makes itself undumpable, so a kernel of the same user cannot
reach it through ``/proc``). A notebook that writes files named like the
grader's records changes nothing, and the records' cells are matched against
the grader's own copy. Nothing the notebook prints decides anything, and the
runner's own output is kept to its last lines; a failure of the runner itself
is the grader's ("grader error"), never the notebook's.

:func:`clean_notebook` turns the JSON of a hand-in into a fresh notebook of the
grader's own: code, markdown and raw cells with their source and their string
tags, nothing else; whatever odd value the hand-in carries (tags that are a
number, a source that is a dict) is dropped there, with a note, before
anything else reads it.

Examples
--------
>>> from uio_teach.grading.runner import clean_notebook
>>> nb, notes = clean_notebook({"nbformat": 4, "cells": [{"cell_type": "code", "source": "x"}]})
>>> nb.cells[0].source, notes
('x', [])
"""

from __future__ import annotations

import collections
import json
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import nbformat

from ..errors import InputError
from .lab_checks import LabChecks, check_function
from .sandbox import HOME, Limits, Sandbox, drop_privileges

__all__ = [
    "RunOutcome",
    "CellError",
    "clean_notebook",
    "prepare",
    "run_notebook",
    "read_limited",
    "kept_output",
    "GRADING_TAG",
    "RECORDS",
    "MAX_RECORD_BYTES",
    "MAX_FILE_BYTES",
    "MAX_ANSWER_BYTES",
]

GRADING_TAG = "uio-teach-grade"
"""The tag of the cells the grader adds."""
MAX_FILE_BYTES = 256 * 1024 * 1024
"""The largest file of the run read back."""
RECORDS = "records"
"""The runner's records go into a pipe the grader reads, one JSON object a line, never into a
file of the run's folder.

``{"error": {...}}`` for a cell that raised, as it ends;
``{"cut": true}`` when the output passed its cap; ``{"failed": "..."}`` for the runner's own
failure; ``{"done": true}`` at the end of a run."""
MAX_RECORD_BYTES = 16 * 1024 * 1024
"""The most of the runner's records read (a run whose cells raise more is over it)."""
MAX_ANSWER_BYTES = 64 * 1024 * 1024
"""The largest answer file read back (a larger one is a row "over limits")."""
_TAIL_BYTES = 64 * 1024
_SETUP = """\
def _uio_export(_uio_tag, _uio_names):
    from uio_teach.checks import answers as _uio_answers
    _uio_ns = globals()
    _uio_values = {_n: _uio_ns[_n] for _n in _uio_names if _n in _uio_ns}
    with open(f"answers/{_uio_tag}.json", "w", encoding="utf-8") as _uio_fh:
        _uio_fh.write(_uio_answers.dumps(_uio_values))
import os as _uio_os, sys as _uio_sys
def _uio_cap(_uio_stream, _uio_left=[%d]):
    _uio_write = _uio_stream.write
    def write(text):
        if _uio_left[0] <= 0:
            return len(text)
        _uio_left[0] -= len(text)
        if _uio_left[0] < 0:
            return _uio_write(text[: len(text) + _uio_left[0]]) or len(text)
        return _uio_write(text)
    _uio_stream.write = write
_uio_cap(_uio_sys.stdout)
_uio_cap(_uio_sys.stderr)
del _uio_cap
"""


@dataclass(frozen=True)
class CellError:
    """A cell of the student's that raised.

    Attributes
    ----------
    cell : int
        Its number among the student's code cells (from 1).
    position : int
        Its index in the prepared notebook.
    ename, evalue : str
        The exception's class and message (one line).
    source : str
        The cell's code.
    is_check : bool
        Whether it is a check cell (its error then follows from an earlier one).
    """

    cell: int
    position: int
    ename: str
    evalue: str
    source: str
    is_check: bool = False


@dataclass
class RunOutcome:
    """What one run gave.

    Attributes
    ----------
    status : str
        ``"ok"``, ``"error"``, ``"timeout"``, ``"over limits"`` or ``"interrupted"``.
    captures : dict
        Capture tag (``"0"``, ``"1"``, ... per check, ``"final"``) -> the text of
        its answer file, unparsed (the checking process parses it, under limits).
    positions : dict
        Capture tag -> index of its cell in the prepared notebook.
    errors : list of CellError
    notes : list of str
        The grader's notes on the run (a killed run, a dead kernel, a limit).
    """

    status: str
    captures: dict[str, str] = field(default_factory=dict)
    positions: dict[str, int] = field(default_factory=dict)
    errors: list[CellError] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def _tags(cell: Any) -> list[str]:
    tags = cell.get("metadata", {}).get("tags", []) if isinstance(cell, Mapping) else []
    return [t for t in tags if isinstance(t, str)] if isinstance(tags, list) else []


def _ours(source: str) -> Any:
    cell = nbformat.v4.new_code_cell(source)
    cell.metadata["tags"] = [GRADING_TAG]
    return cell


def _source(value: Any) -> str | None:
    if isinstance(value, str):
        return value
    if isinstance(value, list) and all(isinstance(line, str) for line in value):
        return "".join(value)
    return None


def clean_notebook(raw: Any) -> tuple[Any, list[str]]:
    """A fresh notebook of the grader's own from the JSON of a hand-in, and what was dropped.

    Only the cells are kept: each code, markdown or raw cell with its source
    (a string or a list of strings) and its string tags. A cell of another
    kind, a source of another type, or tags that are not a list of strings
    are dropped, and each such drop is noted once; outputs, attachments and
    all other metadata are left behind.

    Parameters
    ----------
    raw : object
        The hand-in's JSON, as :func:`json.loads` gave it.

    Returns
    -------
    (NotebookNode, list of str)

    Raises
    ------
    ValueError
        ``raw`` is not a notebook of format 4 or 3 (one line naming its format).

    Examples
    --------
    >>> from uio_teach.grading.runner import clean_notebook
    >>> raw = {"nbformat": 4, "cells": [
    ...     {"cell_type": "code", "source": "x = 1", "metadata": {"tags": 5}}]}
    >>> nb, notes = clean_notebook(raw)
    >>> nb.cells[0].source, nb.cells[0].metadata.get("tags"), notes
    ('x = 1', None, ['a cell whose tags are not a list of names: its tags were ignored'])
    """
    if not isinstance(raw, dict):
        raise InputError("not a notebook (not a JSON object)")
    version = raw.get("nbformat")
    converted = []
    if "nbformat" not in raw:
        raise InputError("not a notebook (no nbformat field)")
    if version == 3:
        raw = _upgrade(raw)
        converted.append("a notebook of format 3 (nbformat 3), converted to format 4 to run")
    elif isinstance(version, int) and not isinstance(version, bool) and version < 3:
        raise InputError(
            f"a notebook of format {version} (nbformat {version}), too old to convert: open it "
            "in Jupyter and save it again (format 4)"
        )
    elif version != 4:
        raise InputError(
            f"a notebook of format {_one_line(repr(version), 40)} (nbformat): the grader reads "
            "formats 4 and 3"
        )
    if not isinstance(raw.get("cells"), list):
        raise InputError("not a notebook of format 4 (no list of cells)")
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    notes: list[str] = converted

    def note(text: str) -> None:
        if text not in notes:
            notes.append(text)

    for cell in raw["cells"]:
        kind = cell.get("cell_type") if isinstance(cell, dict) else None
        source = _source(cell.get("source", "")) if isinstance(cell, dict) else None
        if kind not in ("code", "markdown", "raw") or source is None:
            note("a cell that is not a code, markdown or raw cell with text: it was left out")
            continue
        metadata = cell.get("metadata", {})
        tags = metadata.get("tags", []) if isinstance(metadata, dict) else []
        if not (isinstance(tags, list) and all(isinstance(t, str) for t in tags)):
            note("a cell whose tags are not a list of names: its tags were ignored")
            tags = []
        made = {
            "code": nbformat.v4.new_code_cell,
            "markdown": nbformat.v4.new_markdown_cell,
            "raw": nbformat.v4.new_raw_cell,
        }[kind](source)
        if tags:
            made.metadata["tags"] = list(tags)
        nb.cells.append(made)
    return nb, notes


def _upgrade(raw: dict[str, Any]) -> Any:
    """A notebook of format 3 as format 4 (nbformat's converter), or a one-line ValueError."""
    try:
        node = nbformat.from_dict(raw)
        node.setdefault("nbformat_minor", 0)
        new = nbformat.converter.convert(node, 4)
        return json.loads(json.dumps(new))
    except Exception as err:  # the converter raises many kinds on a malformed notebook
        raise InputError(
            f"a notebook of format 3 (nbformat 3) that could not be converted to format 4 "
            f"({type(err).__name__}): open it in Jupyter and save it again"
        ) from None


def prepare(
    nb: Any,
    checks: LabChecks | None,
    params: Mapping[str, Any] | None,
    *,
    output_mb: int = Limits.output_mb,
) -> tuple[Any, dict[str, int]]:
    """The copy to run: outputs cleared, the key's parameters set, the export cells added.

    Parameters
    ----------
    nb : nbformat.NotebookNode
        The hand-in, as :func:`clean_notebook` made it (modified in place and returned).
    checks : LabChecks or None
        The check cells of its lab (:func:`uio_teach.grading.lab_checks.lab_checks`);
        None (no lab of the course) adds no export cells.
    params : mapping or None
        The group's parameters from the answer key.
    output_mb : int
        The output a run keeps (``Limits.output_mb``): the notebook's streams
        are cut in the kernel one character past it (:func:`kept_output`), so
        the runner, which keeps that much and records the cut, never receives
        much more than it keeps.

    Returns
    -------
    (NotebookNode, dict)
        The copy, and capture tag -> index of its cell.
    """
    graded = checks.checks if checks is not None else ()
    by_function = {c.function: i for i, c in enumerate(graded)}
    every = sorted({n for c in graded for n in c.names})
    cells = [_ours(_SETUP % (kept_output(output_mb) + 1))]
    has_params = False
    placed: set[int] = set()
    for cell in nb.cells:
        if cell.get("cell_type") == "code":
            cell.outputs = []
            cell.execution_count = None
            tags = _tags(cell)
            if GRADING_TAG in tags:  # a cell pretending to be ours is the student's
                cell.metadata["tags"] = [t for t in tags if t != GRADING_TAG]
            if "parameters" in tags and params is not None:
                cell.source = f"PARAMS = {json.dumps(params)}"
                has_params = True
        cells.append(cell)
        if cell.get("cell_type") != "code":
            continue
        tags = _tags(cell)
        index = by_function.get(check_function(cell.source) or "")
        if "check" in tags and "instructor" not in tags and index is not None:
            if index not in placed:
                placed.add(index)
                names = list(graded[index].names)
                cells.append(_ours(f"_uio_export({str(index)!r}, {names!r})"))
    if params is not None and not has_params:
        cells.insert(1, _ours(f"PARAMS = {json.dumps(params)}"))
    cells.append(_ours(f"_uio_export('final', {every!r})"))
    nb.cells = cells
    positions = {}
    for position, cell in enumerate(cells):
        if GRADING_TAG in _tags(cell) and "_uio_export(" in cell.source:
            tag = re.search(r"_uio_export\('(\w+)'", cell.source)
            if tag:
                positions[tag[1]] = position
    return nb, positions


def kept_output(output_mb: int) -> int:
    """How many characters of output a run keeps (``output_mb`` MiB); one more is cut.

    Parameters
    ----------
    output_mb : int

    Returns
    -------
    int

    Examples
    --------
    >>> from uio_teach.grading.runner import kept_output
    >>> kept_output(2)
    2097152
    """
    return output_mb * 1024 * 1024


def read_limited(path: Path, limit: int = MAX_FILE_BYTES) -> bytes | None:
    """The bytes of a regular file written by the sandbox; None if absent, a link or too large.

    Parameters
    ----------
    path : pathlib.Path
    limit : int

    Returns
    -------
    bytes or None
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    with os.fdopen(fd, "rb") as fh:
        info = os.fstat(fh.fileno())
        if not stat.S_ISREG(info.st_mode) or info.st_size > limit:
            return None
        return fh.read(limit + 1)[:limit]


def _one_line(text: Any, limit: int = 200) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _errors(entries: Sequence[Any], prepared: Any) -> list[CellError] | None:
    """The student's cells that raised, from the runner's records (None if they are not its).

    The cells' code and tags come from ``prepared`` (the grader's own copy);
    only the position, the exception's class and its message are read from
    the records, and only as strings; a position that is not a cell of the
    student's is not the runner's.
    """
    numbers = {}
    number = 0
    for position, mine in enumerate(prepared.cells):
        if mine.get("cell_type") == "code" and GRADING_TAG not in _tags(mine):
            number += 1
            numbers[position] = number
    out: dict[int, CellError] = {}
    for entry in entries:
        try:
            position = entry["position"]
        except (KeyError, TypeError):
            return None
        if not isinstance(position, int) or position not in numbers:
            return None
        mine = prepared.cells[position]
        out.setdefault(
            position,
            CellError(
                numbers[position],
                position,
                _one_line(entry.get("ename", ""), 60),
                _one_line(entry.get("evalue", "")),
                str(mine.get("source", "")),
                "check" in _tags(mine),
            ),
        )
    return [out[p] for p in sorted(out)]


def _kill_group(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def _kill_child_kernel(pid_file: Path, parent: int) -> None:
    """Kill the kernel named in ``pid_file`` only if it is a child of ``parent`` (no sandbox)."""
    raw = read_limited(pid_file, 64)
    try:
        pid = int(raw or b"")
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, ValueError, IndexError):
        return
    ppid, pgid = int(fields[1]), int(fields[2])
    if ppid == parent and pgid == pid:  # our runner's kernel, leading its own group
        _kill_group(pgid)


def _matplotlib_cache(work: Path) -> None:
    """Copy the font list of matplotlib into the work folder (or the kernel rebuilds it)."""
    try:
        import matplotlib  # deferred on purpose: only to find its cache folder

        cache = Path(matplotlib.get_cachedir())
    except Exception:  # pragma: no cover - no usable matplotlib cache
        return
    target = work / ".config" / "matplotlib"
    target.mkdir(parents=True, exist_ok=True)
    for font_list in cache.glob("fontlist-*.json"):
        shutil.copy2(font_list, target / font_list.name)


def disk_usage(folder: Path, *, most: int = 100_000) -> int:
    """Bytes used under ``folder`` (links not followed); past ``most`` entries, a huge number.

    Parameters
    ----------
    folder : pathlib.Path
    most : int
        How many entries to look at: a folder with more counts as over any cap.

    Returns
    -------
    int
    """
    total, seen, stack = 0, 0, [os.fspath(folder)]
    while stack:
        try:
            entries = os.scandir(stack.pop())
        except OSError:
            continue
        with entries:
            for entry in entries:
                seen += 1
                if seen > most:
                    return 1 << 62
                try:
                    info = entry.stat(follow_symlinks=False)
                except OSError:
                    continue
                total += getattr(info, "st_blocks", 0) * 512 or info.st_size
                if stat.S_ISDIR(info.st_mode):
                    stack.append(entry.path)
    return total


class _Tail(threading.Thread):
    """Read a pipe to its end, keeping only its last bytes (a chatty run fills no disk)."""

    def __init__(self, stream: Any) -> None:
        super().__init__(daemon=True)
        self.stream = stream
        self.chunks: collections.deque[bytes] = collections.deque()
        self.size = 0

    def run(self) -> None:
        try:
            while chunk := self.stream.read1(65536) if hasattr(self.stream, "read1") else b"":
                self.chunks.append(chunk)
                self.size += len(chunk)
                while self.size - len(self.chunks[0]) > _TAIL_BYTES:
                    self.size -= len(self.chunks.popleft())
        except (OSError, ValueError):
            pass

    def text(self) -> str:
        return b"".join(self.chunks)[-_TAIL_BYTES:].decode("utf-8", "replace")


class _Records(threading.Thread):
    """Read the runner's records from the grader's end of their pipe (at most
    :data:`MAX_RECORD_BYTES`; the rest is drained and counted as too much)."""

    def __init__(self, fd: int) -> None:
        super().__init__(daemon=True)
        self.fd = fd
        self.data = bytearray()
        self.too_much = False

    def run(self) -> None:
        try:
            while chunk := os.read(self.fd, 65536):
                if len(self.data) + len(chunk) > MAX_RECORD_BYTES:
                    self.too_much = True
                    continue
                self.data += chunk
        except OSError:
            pass
        finally:
            os.close(self.fd)

    def entries(self) -> list[Any]:
        """Each record that parses as a JSON object (a line cut by a killed run does not)."""
        out = []
        for line in bytes(self.data).decode("utf-8", "replace").splitlines():
            try:
                entry = json.loads(line)
            except (ValueError, RecursionError):
                continue
            if isinstance(entry, dict):
                out.append(entry)
        return out


def run_notebook(
    nb: Any,
    folder: Path,
    *,
    positions: Mapping[str, int],
    sandbox: bool,
    timeout: float,
    cell_timeout: float,
    limits: Limits,
    stop: threading.Event | None = None,
    user: int | None = None,
) -> RunOutcome:
    """Run a prepared copy in ``folder`` (ours, emptied by the caller); read back its data.

    Parameters
    ----------
    nb : NotebookNode
        The prepared copy (:func:`prepare`).
    folder : pathlib.Path
        A fresh folder of the grader's; the sandbox sees only its ``work``.
    positions : mapping
        Capture tag -> cell index, from :func:`prepare`.
    sandbox : bool
        Run under bubblewrap (False: directly, with a loud warning by the caller).
    timeout, cell_timeout : float
        Seconds for the whole notebook and for one cell.
    limits : Limits
        Resource limits applied by the runner before the kernel starts; its
        ``disk_mb`` caps all the run writes into its folder.
    stop : threading.Event, optional
        When set (the grader was interrupted), the run is killed at once.
    user : int, optional
        The user id the sandbox runs as (:func:`~uio_teach.grading.sandbox.sandbox_user`).

    Returns
    -------
    RunOutcome
    """
    work = folder / "work"
    (work / "answers").mkdir(parents=True)
    _matplotlib_cache(work)
    nbformat.write(nb, work / "submission.ipynb")
    if sandbox and user is not None:  # the sandbox's own user writes its folder, nothing else
        for path in [work, *work.rglob("*")]:
            os.chown(path, user, user, follow_symlinks=False)
    inside = Path(HOME) if sandbox else work
    pid_file = folder / "kernel.pid"
    limit_arg = f"{limits.memory_mb},{limits.processes},{limits.file_mb},{limits.cpu_seconds}"
    limit_arg += f",{limits.output_mb}"
    limit_arg += f",{user if sandbox and user is not None else ''}"
    read_end, write_end = os.pipe()  # the runner's records: never a file the notebook can write
    command = [
        sys.executable,
        "-m",
        "uio_teach.grading.runner",
        "--run",
        os.fspath(inside / "submission.ipynb"),
        str(write_end),
        repr(float(cell_timeout)),
        limit_arg,
        "" if sandbox else os.fspath(pid_file),
    ]
    status = "ok"
    notes: list[str] = []
    pipes = {"stdin": subprocess.DEVNULL, "stdout": subprocess.PIPE, "stderr": subprocess.STDOUT}
    try:
        if sandbox:
            sandboxed = Sandbox(work, limits=limits, user=user)
            proc = sandboxed.popen(command, pass_fds=(write_end,), **pipes)
        else:
            env = dict(os.environ, MPLBACKEND="Agg", PYTHONHASHSEED="0")
            env["MPLCONFIGDIR"] = os.fspath(work / ".config" / "matplotlib")
            proc = subprocess.Popen(
                command,
                cwd=work,
                env=env,
                start_new_session=True,
                pass_fds=(write_end,),
                **pipes,
            )
    except BaseException:
        os.close(read_end)
        raise
    finally:
        os.close(write_end)
    records = _Records(read_end)
    records.start()
    tail = _Tail(proc.stdout)
    tail.start()
    deadline = time.monotonic() + timeout
    next_measure = 0.0
    cap = limits.disk_mb * 1024 * 1024
    try:
        while proc.poll() is None:
            if stop is not None and stop.is_set():
                status = "interrupted"
                break
            now = time.monotonic()
            if now >= next_measure:
                next_measure = now + 0.5
                if disk_usage(work) > cap:
                    status = "over limits"
                    notes.append(
                        f"the notebook wrote more than {limits.disk_mb} MB into its folder and "
                        "was stopped; it is graded on what it computed until then"
                    )
                    break
            left = deadline - now
            if left <= 0:
                status = "timeout"
                notes.append(
                    f"the notebook ran longer than the time limit of {timeout:g} s and was "
                    "stopped; it is graded on what it computed until then"
                )
                break
            try:
                proc.wait(timeout=min(left, 0.25))
            except subprocess.TimeoutExpired:
                pass
    finally:
        if not sandbox:
            _kill_child_kernel(pid_file, proc.pid)
        _kill_group(proc.pid)  # the sandbox's own session: everything it started
        proc.wait()
        tail.join(timeout=5)
        records.join(timeout=5)
    outcome = RunOutcome(status, positions=dict(positions), notes=notes)
    entries = records.entries()
    errors = _errors([e["error"] for e in entries if "error" in e], nb)
    if errors is None:  # only the runner writes there: a mismatch is the grader's own fault
        status = "grader error"
        notes.insert(0, "the grader's notebook runner recorded a cell that is not the notebook's")
    outcome.errors = errors or []
    failed = next((e["failed"] for e in entries if "failed" in e), None)
    if failed is not None:  # the runner's own failure: never the notebook's
        status = "grader error"
        why = _one_line(failed, 160) or "unknown"
        notes.insert(0, f"the grader's notebook runner failed ({why}), not the notebook")
    if records.too_much and status in ("ok", "error"):
        status = "over limits"
        notes.append(
            f"the notebook's cells raised errors of more than {MAX_RECORD_BYTES >> 20} MB in "
            "all: the rest were not read"
        )
    cut = any(e.get("cut") is True for e in entries)
    if cut and status in ("ok", "error", "timeout"):
        if not any(n.startswith("the notebook's output") for n in notes):
            notes.insert(
                0,
                f"the notebook's output (what it printed or displayed) came to more than "
                f"{limits.output_mb} MB and was cut there; its answers are graded as usual",
            )
        status = "over limits"
    elif status == "ok" and proc.returncode != 0:
        text = tail.text()
        noise = ("[IPKernelApp]", "WARNING", "[W ", "[I ", "To connect another client")
        lines = [x for x in text.splitlines() if x.strip() and not x.lstrip().startswith(noise)]
        last = (
            _one_line(lines[-1])
            if lines
            else f"its processes ended early (exit status {proc.returncode})"
        )
        if "DeadKernelError" in text or "Kernel died" in text:
            last = "the kernel died (the notebook ended its own process, or ran out of memory)"
        notes.append(f"the notebook could not be run to its end: {last}")
        status = "error"
    for tag in positions:
        path = work / "answers" / f"{tag}.json"
        data = read_limited(path, MAX_ANSWER_BYTES)
        if data is None:
            try:
                too_large = path.lstat().st_size > MAX_ANSWER_BYTES
            except OSError:
                too_large = False
            if too_large:
                status = "over limits"
                notes.append(
                    f"the answers after one check are larger than {MAX_ANSWER_BYTES >> 20} MB: "
                    "not graded"
                )
            continue
        outcome.captures[tag] = data.decode("utf-8", "replace")
    if status == "ok" and "final" not in outcome.captures:
        status = "error"
        notes.append("the notebook did not run to its end")
    if status == "ok" and outcome.errors:
        status = "error"
    outcome.status = status
    outcome.notes = notes
    return outcome


def _size(msg: Mapping[str, Any]) -> int:
    """About how many bytes an output message carries (its text and its data)."""
    content = msg.get("content") or {}
    size = len(content.get("text") or "")
    for value in (content.get("data") or {}).values():
        size += len(value) if isinstance(value, str) else len(json.dumps(value))
    return size


def _execute(src: str, record_fd: int, cell_timeout: float, limits: str, pid_file: str) -> int:
    """Run a prepared copy in a fresh kernel (the process :func:`run_notebook` starts).

    Nothing is saved per cell: each cell that raised is appended to ``log``
    (one JSON line) as it ends, and its outputs are dropped (the grader reads
    answers from their files, never outputs), so the cost of a run grows with
    its cells and its memory does not. Output beyond the limit's ``output_mb``
    is cut. Each cell that raised, a cut, a failure of the runner itself
    and the end of the run are written as records (:data:`RECORDS`) into the
    pipe ``record_fd``, which the runner holds alone: it is closed for the
    kernel, and the runner is made undumpable so a kernel of the same user
    cannot open it through ``/proc``.
    """
    from nbclient import NotebookClient  # deferred on purpose: only the runner needs it
    from nbclient.exceptions import DeadKernelError

    *numbers, user = limits.split(",")
    drop_privileges(int(user) if user else None)  # before anything else: no root, no capability
    _private()  # a kernel of the same user cannot reach into this process through /proc
    os.set_inheritable(record_fd, False)  # the kernel does not get the records' pipe
    records = os.fdopen(record_fd, "w", encoding="utf-8", buffering=1)

    def record(entry: Mapping[str, Any]) -> None:
        try:
            records.write(json.dumps(entry) + "\n")
        except (OSError, ValueError):  # the grader stopped reading: the run is being ended
            pass

    memory, processes, file_mb, cpu, output_mb = (int(v) for v in numbers)
    Limits(memory, processes, file_mb, cpu).apply()
    folder = Path(src).parent
    nb = nbformat.read(src, as_version=4)
    keep = kept_output(output_mb)

    class Client(NotebookClient):  # type: ignore[misc]
        kept = 0
        cut = False

        def output(self, outs: Any, msg: Any, display_id: Any, cell_index: int) -> Any:
            if msg.get("msg_type") != "error":
                self.kept += _size(msg)
                if self.kept > keep:
                    if not self.cut:
                        self.cut = True
                        record({"cut": True})
                    return None
            return super().output(outs, msg, display_id, cell_index)

    client = Client(
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
        resources={"metadata": {"path": os.fspath(folder)}},
    )

    def started(**_: Any) -> None:
        pid = getattr(getattr(client.km, "provisioner", None), "pid", None)
        if pid and pid_file:
            Path(pid_file).write_text(str(pid))

    def executed(cell: Any, cell_index: int, **_: Any) -> None:
        for out in cell.get("outputs", []):
            if out.get("output_type") == "error":
                entry = {
                    "position": cell_index,
                    "ename": str(out.get("ename", ""))[:200],
                    "evalue": str(out.get("evalue", ""))[:2000],
                }
                record({"error": entry})
                break
        cell.outputs = []  # read; kept no longer

    client.on_notebook_start = started
    client.on_cell_executed = executed
    with records:
        try:
            client.execute()
        except DeadKernelError:
            raise  # the notebook ended its kernel: the notebook's doing
        except (Exception, MemoryError) as exc:  # the runner's own failure, never the notebook's
            record({"failed": f"{type(exc).__name__}: {_one_line(exc, 120)}".rstrip(": ")})
            return 3
        record({"done": True})
    return 0


def _private() -> None:
    """Make this process undumpable (Linux ``PR_SET_DUMPABLE`` 0): a process of the same user
    can then neither trace it nor open its files through ``/proc/<pid>/fd``."""
    if not sys.platform.startswith("linux"):  # pragma: no cover - the sandbox is Linux only
        return
    import ctypes  # deferred on purpose: only the runner inside the sandbox needs it

    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(4, 0, 0, 0, 0) != 0:  # PR_SET_DUMPABLE = 4
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_DUMPABLE, 0) failed")


def main(argv: Sequence[str]) -> int:
    """The runner's command line: ``--run SRC RECORD_FD CELL_TIMEOUT LIMITS PID_FILE``.

    Parameters
    ----------
    argv : sequence of str

    Returns
    -------
    int
    """
    if len(argv) == 6 and argv[0] == "--run":
        return _execute(argv[1], int(argv[2]), float(argv[3]), argv[4], argv[5])
    print("usage: python -m uio_teach.grading.runner --run SRC RECORD_FD CELL_TIMEOUT LIMITS PID")
    return 2


if __name__ == "__main__":  # pragma: no cover - the process run_notebook starts
    sys.exit(main(sys.argv[1:]))
