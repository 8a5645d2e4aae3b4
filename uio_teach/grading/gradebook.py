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
>>> from uio_teach.grading.gradebook import Submission
>>> s = Submission("a.ipynb", "pa9", "g01", "ok",
...                results={"pa9.design": {"passed": True, "items": []}},
...                expected=("pa9.design", "pa9.plot"))
>>> s.verdicts(), s.total
({'pa9.design': True, 'pa9.plot': False}, 1)
"""

from __future__ import annotations

import csv
import hashlib
import html
import io
import json
import os
import re
import unicodedata
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..folders import (
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
    "export_path",
    "safe_cell",
    "file_cell",
    "shown",
    "name_shown",
    "exports",
    "read_gradebook",
    "header_of",
    "write_table",
    "write_exports",
    "needs_a_look",
    "MAX_NAME_BYTES",
    "PASS",
    "FAIL",
    "COMMAND",
    "EXPORTS",
]

PASS, FAIL = "✓", "✗"
EXPORTS = ("canvas", "groups", "moodle")
"""The exports written beside a gradebook (:func:`export_path` of each)."""
COMMAND = "uio-teach grade"
"""The command recorded in the feedback folder's manifest."""
_FIRST = ["file", "lab", "group", "status", "reason"]
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029]+")
_ONE_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029]")
_NUMBER = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")
_GOOD = ("ok", "error", "timeout")  # rows whose marks stand as they are
_LAST = ["total", "out_of", "late"]


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
        end), ``"timeout"`` (stopped at the time limit), and the rows that need
        a look: ``"check by hand"`` (its identity disagrees or is missing),
        ``"over limits"``, ``"refused"`` (not a regular file of the hand-in
        folder), ``"unreadable"`` (not a notebook), ``"unknown lab"`` and
        ``"grader error"``.
    reason : str
        Why the row has that status, on one line ("" for ``ok``).
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
    late : bool
        The LMS marked it late (its own column, ``late``, in the gradebook).

    Examples
    --------
    >>> from uio_teach.grading.gradebook import Submission
    >>> s = Submission("pa9_g01.ipynb", "pa9", "g01", "unreadable",
    ...                errors=["not a notebook"], expected=("pa9.design",))
    >>> s.row(["pa9.design"])
    ['pa9_g01.ipynb', 'pa9', 'g01', 'unreadable', '', '✗', 0, 1, '']
    """

    file: str
    lab: str
    group: str
    status: str
    reason: str = ""
    results: dict[str, dict[str, Any]] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)
    params: dict[str, Any] | None = None
    expected: tuple[str, ...] = ()
    seconds: float = 0.0
    feedback_file: Path | None = None
    late: bool = False

    def verdicts(self) -> dict[str, bool]:
        """Check id -> passed (a check with no result failed)."""
        ids = list(self.expected) + [i for i in self.results if i not in self.expected]
        return {i: bool(self.results.get(i, {}).get("passed")) for i in ids}

    @property
    def total(self) -> int:
        """The number of checks passed."""
        return sum(self.verdicts().values())

    @property
    def needs_a_look(self) -> bool:
        """Whether an instructor should look at this row before its marks count."""
        return needs_a_look(self.status)

    def feedback(self) -> str:
        """The feedback text for the group: every check's messages, then the grader's notes."""
        lines = [
            f"Submission: {name_shown(self.file)}",
            f"Lab: {self.lab or 'unknown'}    Group: {self.group or 'unknown'}",
            f"Status: {self.status}" + (f" ({self.reason})" if self.reason else ""),
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
        return shown("\n".join(lines) + "\n")

    def feedback_html(self) -> str:
        """The feedback as a small HTML page (every text escaped)."""
        e = html.escape
        verdicts = self.verdicts()
        parts = [
            "<!DOCTYPE html>",
            '<html lang="en"><head><meta charset="utf-8">',
            f"<title>Feedback: {e(name_shown(Path(self.file).name))}</title>",
            "<style>body{font-family:sans-serif;max-width:50em;margin:2em auto}"
            ".ok{color:#06602a}.no{color:#a3001b}li{margin:.2em 0}</style></head><body>",
            f"<h1>Lab {e(self.lab or 'unknown')}, group {e(self.group or 'unknown')}</h1>",
            f"<p>Hand-in: <code>{e(name_shown(self.file))}</code><br>Status: "
            f"<strong>{e(self.status)}"
            f"</strong>{e(' (' + self.reason + ')') if self.reason else ''}<br>"
            f"Checks passed: {self.total} of {len(verdicts)}</p>",
        ]
        if self.params is not None:
            parts.append(
                f"<p>Parameters of this group: <code>{e(json.dumps(self.params))}</code></p>"
            )
        for check_id, ok in verdicts.items():
            result = self.results.get(check_id) or {}
            mark = f'<span class="{"ok" if ok else "no"}">{PASS if ok else FAIL}</span>'
            title = result.get("title", "")
            parts.append(f"<h2>{mark} {e(check_id)}{e(': ' + title) if title else ''}</h2><ul>")
            if not result:
                parts.append("<li>not graded: the notebook could not be run</li>")
            for item in result.get("items", []):
                sign = {True: PASS, False: FAIL}.get(item.get("ok"), "•")
                parts.append(f"<li>{e(sign)} {e(str(item.get('message', '')))}</li>")
            parts.append("</ul>")
        if self.errors:
            parts.append("<h2>Problems while running the notebook</h2><ul>")
            parts += [f"<li>{e(str(x))}</li>" for x in self.errors]
            parts.append("</ul>")
        parts.append("</body></html>")
        return shown("\n".join(parts) + "\n")

    def row(self, columns: Sequence[str]) -> list[Any]:
        """The CSV row under the check columns ``columns`` (empty for a check of another lab)."""
        verdicts = self.verdicts()
        marks = ["" if c not in verdicts else (PASS if verdicts[c] else FAIL) for c in columns]
        first = [file_cell(self.file), self.lab, self.group, self.status, self.reason]
        return [*first, *marks, self.total, len(verdicts), "late" if self.late else ""]


def shown(text: Any) -> str:
    """A name as text that any file can hold: bytes that are not UTF-8 as ``\\xe9``.

    A Linux file name is bytes, in any encoding; Python keeps those that are
    not UTF-8 as lone surrogates, which no UTF-8 file can hold. They are
    shown as backslash escapes, so the name stays readable and distinct.

    Parameters
    ----------
    text : object

    Returns
    -------
    str

    Examples
    --------
    >>> import os
    >>> from uio_teach.grading.gradebook import shown
    >>> print(shown(os.fsdecode(b"Jos\\xe9_pa9_g01.ipynb")))
    Jos\\xe9_pa9_g01.ipynb
    """
    text = str(text)
    try:
        raw = text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:
        raw = text.encode("utf-8", "surrogatepass")
    return raw.decode("utf-8", "backslashreplace")


def name_shown(file: Any) -> str:
    """A file name as :func:`shown` writes it, and a name not in Unicode's NFC form told apart.

    Two names that differ only in their normal form (``é`` as one character,
    or as ``e`` and a combining accent, as a macOS zip writes it) look alike;
    the combining marks of a name that is not NFC are shown as ``\\u0301``,
    so two such names never print alike.

    Parameters
    ----------
    file : object

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.grading.gradebook import name_shown
    >>> print(name_shown("Jos\u00e9.ipynb"), name_shown("Jose\u0301.ipynb"))
    José.ipynb Jose\u0301.ipynb
    """
    text = shown(file)
    if unicodedata.normalize("NFC", text) == text:
        return text
    return "".join(f"\\u{ord(c):04x}" if unicodedata.combining(c) else c for c in text)


def safe_cell(value: Any) -> str:
    """A CSV cell a spreadsheet shows as text: one line, never a formula.

    Control characters and line breaks become spaces; a cell that starts with
    ``=``, ``+``, ``-`` or ``@`` and is not a number gets a leading ``'``.

    Parameters
    ----------
    value : object

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.grading.gradebook import safe_cell
    >>> print(safe_cell('=HYPERLINK("http://x")'), safe_cell("-3"), safe_cell("a\\nb"))
    '=HYPERLINK("http://x") -3 a b
    """
    text = _CONTROL.sub(" ", shown(value)).strip()
    if text[:1] in ("=", "+", "-", "@") and not _NUMBER.match(text):
        text = "'" + text
    return text


def file_cell(file: str) -> str:
    """A hand-in's name as its gradebook cell: :func:`safe_cell` of :func:`shown`, and every
    control character (a line break is legal in a file name) as ``\\x0a``, so that two names
    never share a cell.

    Parameters
    ----------
    file : str

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.grading.gradebook import file_cell
    >>> print(file_cell("a\\nb.ipynb"), file_cell("a b.ipynb"))
    a\\x0ab.ipynb a b.ipynb
    """
    return safe_cell(_ONE_CONTROL.sub(lambda m: f"\\x{ord(m[0]):02x}", name_shown(file)))


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
    >>> from uio_teach.grading.gradebook import feedback_folder
    >>> feedback_folder("marks/grades.csv").as_posix()
    'marks/grades_feedback'
    """
    out = Path(out)
    return out.with_name(f"{out.stem}_feedback")


def check_gradebook_target(out: str | os.PathLike[str]) -> None:
    """Raise :class:`~uio_teach.folders.OutputError` unless ``out`` may be written.

    The gradebook must not be a folder; its feedback folder must be absent,
    empty, or the feedback folder of an earlier grading (its manifest says so).

    Parameters
    ----------
    out : str or path-like

    Raises
    ------
    uio_teach.folders.OutputError

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.grading.gradebook import check_gradebook_target
    >>> from uio_teach.folders import OutputError
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


MAX_NAME_BYTES = 200
"""The longest stem of a feedback file, in bytes. With its suffix and the temporary name it is
written under (``.<name>.html.part``), it stays within the 255 bytes a file name may have."""


def _short(stem: str, whole: str) -> str:
    """``stem`` cut to :data:`MAX_NAME_BYTES` bytes (whole characters), then a hash of ``whole``."""
    raw = stem.encode("utf-8", "surrogateescape")
    if len(raw) <= MAX_NAME_BYTES:
        return stem
    digest = hashlib.sha256(whole.encode("utf-8", "surrogateescape")).hexdigest()[:10]
    cut = raw[: MAX_NAME_BYTES - 11]
    while cut and (cut[-1] & 0xC0) == 0x80:  # never half a UTF-8 character
        cut = cut[:-1]
    if cut and cut[-1] >= 0xC0:
        cut = cut[:-1]
    return f"{cut.decode('utf-8', 'surrogateescape')}-{digest}"


def feedback_names(files: Sequence[str]) -> dict[str, str]:
    """Submission -> the name of its feedback text (its stem; its folder too on a clash).

    A stem longer than :data:`MAX_NAME_BYTES` bytes is cut and ends in a hash
    of the whole name, so every name of any legal length has its own text.

    Parameters
    ----------
    files : sequence of str

    Returns
    -------
    dict

    Examples
    --------
    >>> from uio_teach.grading.gradebook import feedback_names
    >>> feedback_names(["a/x.ipynb", "b/x.ipynb"])
    {'a/x.ipynb': 'x.txt', 'b/x.ipynb': 'b_x.txt'}
    >>> len(feedback_names(["é" * 120 + ".ipynb"])["é" * 120 + ".ipynb"].encode())
    203
    """
    names: dict[str, str] = {}
    for file in files:
        path = Path(file)
        candidates = [path.stem, f"{path.parent.name}_{path.stem}"]
        candidates += [f"{path.stem}-{n}" for n in range(2, len(files) + 2)]
        taken = set(names.values())
        names[file] = next(
            f"{_short(c, file)}.txt" for c in candidates if f"{_short(c, file)}.txt" not in taken
        )
    return names


def _feedback_names(files: Sequence[str]) -> dict[str, str]:
    """:func:`feedback_names` of the names as shown (a name that is not UTF-8 escaped)."""
    by_shown = feedback_names(list(dict.fromkeys(shown(f) for f in files)))
    return {f: by_shown[shown(f)] for f in files}


def export_path(out: str | os.PathLike[str], kind: str) -> Path:
    """The export ``kind`` (``"canvas"`` or ``"groups"``) beside the gradebook ``out``.

    Parameters
    ----------
    out : str or path-like
    kind : str

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> from uio_teach.grading.gradebook import export_path
    >>> export_path("marks/grades.csv", "canvas").as_posix()
    'marks/grades_canvas.csv'
    """
    out = Path(out)
    return out.with_name(f"{out.stem}_{kind}.csv")


def header_of(columns: Sequence[str]) -> list[str]:
    """The header of a gradebook with these check columns.

    Examples
    --------
    >>> from uio_teach.grading.gradebook import header_of
    >>> header_of(["pa9.design"])
    ['file', 'lab', 'group', 'status', 'reason', 'pa9.design', 'total', 'out_of', 'late']
    """
    return [*_FIRST, *columns, *_LAST]


def write_table(path: str | os.PathLike[str], rows: Iterable[Sequence[Any]]) -> None:
    """Write rows as a CSV, atomically (a reader never sees half of it)."""
    _write_atomic(Path(path), _csv_text(rows))


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


def exports(
    header: Sequence[str],
    rows: Sequence[Sequence[str]],
    students: Mapping[str, Sequence[tuple[str, str]]],
) -> tuple[list[list[str]], list[list[str]] | None, list[list[str]] | None]:
    """The export keyed by group, Canvas's and Moodle's (None without students: they could
    match none).

    Moodle's grade import (*Grades*, *Import*, *CSV file*) maps each row to a user by the
    column ``ID number`` (the roster's student id: choose "ID number", or the user field the
    roster's ids are, as the mapping) and takes one column per lab, named as the grade item;
    it has no "Points Possible" line (the maximum is the grade item's).

    Parameters
    ----------
    header : sequence of str
        The gradebook's header.
    rows : sequence of sequence of str
        Its rows, in order.
    students : mapping
        Group -> list of (student id, name), from the roster.

    Returns
    -------
    (list, list or None, list or None)
    """
    at = {name: i for i, name in enumerate(header)}
    labs: dict[str, str] = {}
    groups: dict[tuple[str, str], list[Sequence[str]]] = {}
    for row in rows:
        lab, group = row[at["lab"]], row[at["group"]]
        if lab:
            labs.setdefault(lab, row[at["out_of"]])
        if lab and group:
            groups.setdefault((lab, group), []).append(row)
    plain: list[list[Any]] = [["group", "lab", "total", "out_of", "status", "reason", "file"]]
    scores: dict[tuple[str, str], str] = {}
    for (lab, group), same in sorted(groups.items(), key=lambda kv: (kv[0][1], kv[0][0])):
        row = same[0]
        status, reason = row[at["status"]], row[at["reason"]]
        if len(same) > 1:
            status, reason = "check by hand", "more than one hand-in"
        score = row[at["total"]] if status in _GOOD else ""
        scores[(lab, group)] = score
        files = "; ".join(r[at["file"]] for r in same)
        plain.append([group, lab, score, row[at["out_of"]], status, reason, files])
    plain = [[safe_cell(c) for c in r] for r in plain]
    if not students:
        return plain, None, None
    names = [f"{lab} (uio-teach)" for lab in labs]
    canvas: list[list[Any]] = [["Student", "ID", "SIS User ID", "SIS Login ID", "Section", *names]]
    canvas.append(["Points Possible", "", "", "", "", *labs.values()])
    moodle: list[list[Any]] = [["ID number", "Full name", "Group", *names]]
    for group in sorted({g for _, g in groups}):
        marks = [scores.get((lab, group), "") for lab in labs]
        for student, name in students.get(group, []):
            canvas.append([name or student, "", student, "", group, *marks])
            moodle.append([student, name, group, *marks])
    return (
        plain,
        [[safe_cell(c) for c in r] for r in canvas],
        [[safe_cell(c) for c in r] for r in moodle],
    )


def write_exports(
    out: str | os.PathLike[str],
    header: Sequence[str],
    rows: Sequence[Sequence[str]],
    students: Mapping[str, Sequence[tuple[str, str]]],
) -> None:
    """Write the exports of :func:`exports` beside the gradebook ``out``.

    Without students, no Canvas import is written (one of an earlier grading
    into the same gradebook is removed: it would no longer be this one's).

    Parameters
    ----------
    out : str or path-like
    header, rows, students
        As :func:`exports` takes them.
    """
    plain, canvas, moodle = exports(header, rows, students)
    _write_atomic(export_path(out, "groups"), _csv_text(plain))
    for kind, table in (("canvas", canvas), ("moodle", moodle)):
        target = export_path(out, kind)
        if table is not None:
            _write_atomic(target, _csv_text(table))
        else:
            target.unlink(missing_ok=True)


def read_gradebook(out: str | os.PathLike[str]) -> tuple[list[str], list[list[str]]]:
    """The header and the whole rows of a gradebook CSV (a row cut short by a kill left out).

    Parameters
    ----------
    out : str or path-like

    Returns
    -------
    (list of str, list of list of str)

    Raises
    ------
    uio_teach.folders.OutputError
        It cannot be read, or it is not a gradebook of uio-teach.
    """
    try:
        with open(out, newline="", encoding="utf-8") as fh:
            table = list(csv.reader(fh))
    except FileNotFoundError:
        raise OutputError(f"{os.fspath(out)}: no such gradebook") from None
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise OutputError(f"cannot read the gradebook {os.fspath(out)}: {err}") from None
    if not table:
        return [], []
    header, body = table[0], table[1:]
    if header[: len(_FIRST)] != _FIRST or header[-len(_LAST) :] != _LAST:
        raise OutputError(
            f"{os.fspath(out)} is not a gradebook of uio-teach (its header is not "
            f"{','.join(_FIRST)},...,{','.join(_LAST)}); it is left alone"
        )
    return header, [row for row in body if len(row) == len(header)]


def needs_a_look(status: str) -> bool:
    """Whether a row of this status needs an instructor's look before its marks count.

    Examples
    --------
    >>> from uio_teach.grading.gradebook import needs_a_look
    >>> needs_a_look("ok"), needs_a_look("check by hand")
    (False, True)
    """
    return status not in _GOOD


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
        Keep the rows already there; :meth:`has` says which hand-ins have one.
    students : dict, optional
        Group -> list of (student id, name), for the Canvas export (none: no
        Canvas export, which could match no student).
    shard : (int, int), optional
        ``(K, N)``: this gradebook holds the rows of shard K of N of the
        class ``files`` (see :mod:`uio_teach.grading.merge`).
    sources : dict, optional
        What the grading read besides the hand-ins (the SHA-256 of the answer
        key and of the roster), kept in the manifest so that shards of
        different gradings are never merged.

    Raises
    ------
    uio_teach.folders.OutputError
        The CSV is a folder, or its feedback folder is not ours.
    GradebookBusy
        Another run holds the lock.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.grading.gradebook import Gradebook, Submission
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     out = pathlib.Path(tmp) / "grades.csv"
    ...     with Gradebook(out, ["a.ipynb"], ["pa9.design"]) as book:
    ...         book.add(Submission("a.ipynb", "pa9", "g01", "ok", expected=("pa9.design",)))
    ...     print(out.read_text(encoding="utf-8").splitlines()[1])
    a.ipynb,pa9,g01,ok,,✗,0,1,
    """

    def __init__(
        self,
        out: str | os.PathLike[str],
        files: Sequence[str],
        columns: Sequence[str],
        *,
        resume: bool = False,
        students: dict[str, list[tuple[str, str]]] | None = None,
        shard: tuple[int, int] | None = None,
        sources: dict[str, Any] | None = None,
    ) -> None:
        self.out = Path(out)
        self.students = dict(students or {})
        self.shard = shard
        self.sources = dict(sources or {})
        self.subs: dict[str, Submission] = {}
        self.folder = feedback_folder(self.out)
        self.files = list(files)
        self.columns = list(columns)
        self.resume = resume
        self.names = _feedback_names(self.files)
        self.done: dict[str, list[str]] = {}
        self._lock = FolderLock(self.out)  # the file .<name>.lock beside the CSV
        self._csv: Any = None

    # opening ------------------------------------------------------------------------------
    def __enter__(self) -> Gradebook:
        self.lock()
        try:
            self.open()
        except BaseException:
            self._unlock()
            raise
        return self

    def lock(self) -> None:
        """Take the gradebook's lock (first of all: before any notebook runs).

        Raises
        ------
        uio_teach.folders.OutputError
            The CSV is a folder, or its feedback folder is not ours.
        GradebookBusy
            Another run holds the lock.
        """
        check_gradebook_target(self.out)
        self.out.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._lock.acquire()
        except FolderBusy:
            raise GradebookBusy(
                f"another grading run is writing {os.fspath(self.out)} (it holds "
                f"{self._lock.path.name}); wait for it to end, or choose another gradebook"
            ) from None

    def _read_rows(self) -> tuple[list[str], list[list[str]]]:
        if not self.out.exists():
            return [], []
        return read_gradebook(self.out)  # a row cut short by a kill is graded again

    def _kept(self) -> tuple[list[str], list[list[str]]]:
        """The header and the rows a resumed run keeps (none for a new grading)."""
        if not self.resume:
            return [], []
        header, kept = self._read_rows()
        manifest = read_manifest(self.folder) if self.folder.is_dir() else None
        options = (manifest or {}).get("options") or {}
        if kept and options:
            earlier = options.get("shard")
            if (tuple(earlier) if earlier else None) != self.shard:

                def name(shard: Any) -> str:
                    return f"shard {shard[0]}/{shard[1]}" if shard else "the whole class"

                raise OutputError(
                    f"{os.fspath(self.out)} holds the rows of {name(earlier)}, not of "
                    f"{name(self.shard)}: resume it with the same --shard"
                )
            for what, digest in self.sources.items():
                if options.get(what, digest) != digest:
                    raise OutputError(
                        f"{os.fspath(self.out)} was graded with another "
                        f"{what.removesuffix('_sha256').replace('_', ' ')} (its {MANIFEST}): "
                        "resume it with the same one, or grade afresh without --resume"
                    )
        wanted = {file_cell(f) for f in self.files}
        names = {file_cell(f): n for f, n in self.names.items()}
        # a row whose feedback text is lost is graded again
        kept = [row for row in kept if row[0] in wanted and (self.folder / names[row[0]]).is_file()]
        return header, kept

    def prior(self) -> set[str]:
        """The hand-ins whose rows a resumed run keeps (none for a new grading).

        Returns
        -------
        set of str
            Their files, as given.
        """
        cells = {row[0] for row in self._kept()[1]}
        return {f for f in self.files if file_cell(f) in cells}

    def open(self) -> None:
        """Start writing: a new gradebook, or the resumed one with the rows it keeps."""
        self.folder.mkdir(parents=True, exist_ok=True)
        header, kept = self._kept()
        if not self.resume:  # a new grading: the texts of the earlier one go
            for old in self.folder.iterdir():
                if old.is_file() and (old.suffix in (".txt", ".html") or old.name == MANIFEST):
                    old.unlink()
        old_columns = header[len(_FIRST) : -len(_LAST)] if header else []
        self.columns = old_columns + [c for c in self.columns if c not in old_columns]
        if header and old_columns != self.columns:  # new check columns: widen the old rows
            width = len(self.columns) - len(old_columns)
            kept = [row[: -len(_LAST)] + [""] * width + row[-len(_LAST) :] for row in kept]
        self.done = {row[0]: row for row in kept}
        _write_atomic(self.out, _csv_text([self._header(), *kept]))
        write_manifest(self.folder, command=COMMAND, config=self._config(), options=self._options())
        self._csv = open(self.out, "a", encoding="utf-8", newline="")

    def _header(self) -> list[str]:
        return [*_FIRST, *self.columns, *_LAST]

    def _config(self) -> dict[str, Any]:
        return {"gradebook": self.out.name}

    def _options(self) -> dict[str, Any]:
        options: dict[str, Any] = {
            "submissions": [shown(f) for f in self.files],
            "columns": list(self.columns),
            "students": {g: [list(s) for s in v] for g, v in sorted(self.students.items())},
            **self.sources,
        }
        if self.shard is not None:
            options["shard"] = list(self.shard)
        return options

    def has(self, file: str) -> bool:
        """Whether the hand-in ``file`` has its row already (kept by ``resume``, or added)."""
        return file_cell(file) in self.done

    # writing ------------------------------------------------------------------------------
    def add(self, sub: Submission) -> None:
        """Write ``sub``'s feedback text and append its row (flushed and synced).

        Parameters
        ----------
        sub : Submission
        """
        name = self.names.get(sub.file) or _feedback_names([sub.file])[sub.file]
        path = self.folder / name
        _write_atomic(path, sub.feedback())
        _write_atomic(path.with_suffix(".html"), sub.feedback_html())
        sub.feedback_file = path
        row = [safe_cell(v) for v in sub.row(self.columns)]
        self._csv.write(_csv_text([row]))
        self._csv.flush()
        os.fsync(self._csv.fileno())
        self.done[row[0]] = row
        self.subs[row[0]] = sub

    def finish(self) -> None:
        """Rewrite the CSV in the submissions' order and write the feedback manifest."""
        rows = [
            self.done[c] for c in dict.fromkeys(file_cell(f) for f in self.files) if c in self.done
        ]
        self._csv.close()
        _write_atomic(self.out, _csv_text([self._header(), *rows]))
        write_exports(self.out, self._header(), rows, self.students)
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
