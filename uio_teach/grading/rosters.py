"""Who handed in what: groups from file names, rosters and answer keys, as spreadsheets write them.

* :func:`group_from_name` reads the lab and group from a hand-in's file name,
  also as an LMS bulk download writes it (Canvas prefixes the student's name
  and ids, ``ann_48213_9920131_pa9_g02.ipynb``, and marks late ones
  ``_LATE_``; a re-submission ends in ``-1``);
* :func:`read_table` reads a CSV as any spreadsheet saves it: comma,
  semicolon, tab or bar between the fields, UTF-8 (with or without its
  mark), UTF-16 or Windows-1252;
* :func:`read_roster` and :func:`read_answer_key` read the two tables the
  grader is given, refusing a row that repeats another, by name.

Group names ``g<number>`` are written with at least two digits everywhere
(:func:`group_id`: ``g3``, ``g03``, ``G3``, ``Group-3``, ``group_3`` and
``Group 3`` are one group). Every name (a file's, a student's, a group's) is
compared in one Unicode normal form, NFC (``same_form``): a macOS zip
writes ``é`` as ``e`` and a combining accent (NFD), a roster saved on Windows
writes it as one character, and both name the same hand-in.

Examples
--------
>>> from uio_teach.grading.rosters import group_from_name
>>> group_from_name("ann_LATE_48213_9920131_pa9_g2.ipynb")
('pa9', 'g02')
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
import unicodedata
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from ..errors import UIOTeachError

__all__ = [
    "GradeError",
    "group_id",
    "same_form",
    "group_from_name",
    "is_late",
    "read_table",
    "read_roster",
    "read_answer_key",
    "DELIMITERS",
    "MAX_TABLE_BYTES",
]

DELIMITERS = (",", ";", "\t", "|")
"""The field separators a spreadsheet writes, tried in this order on a tie."""
MAX_TABLE_BYTES = 16 * 1024 * 1024
"""The largest roster or answer key read."""
_GROUP = re.compile(r"^g(?:roup)?[ _-]?0*(\d+)$", re.I)
_COPY = re.compile(r"(?:\s*\(\d+\)|-\d+)$")  # "name (3)", Canvas's "name-1"
_GROUP_PART = r"(?P<group>g(?:roup)?[ _-]?\d+)"
_GENERIC = re.compile(rf"^(?P<lab>[A-Za-z][\w-]*?)_{_GROUP_PART}$", re.I)
_LATE = re.compile(r"(?:^|_)LATE_")
# each column's names, the better first: a table with two of them takes the better one
# (Canvas's gradebook export has "Student", the display name, and "SIS User ID", the id)
_COLUMNS = {
    "group": ("group", "group name", "groups", "gruppe", "groupe", "section"),
    "file": ("file", "file name", "filename", "hand-in", "handin"),
    "student": (
        "sis user id",
        "student id",
        "id number",
        "username",
        "email address",
        "email",
        "student",
    ),
    "name": ("name", "student name", "full name", "student"),
    "first": ("first name",),
    "last": ("last name", "surname"),
    "lab": ("lab",),
    "params": ("params",),
}
_NOT_STUDENTS = ("points possible", "test student", "student, test")


class GradeError(UIOTeachError, ValueError):
    """Grading cannot start (a missing answer key, an unreadable key or roster, a bad option);
    one line naming the file or the option."""


def same_form(text: str) -> str:
    """A name in the one Unicode normal form the grader compares names in (NFC).

    Parameters
    ----------
    text : str

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.grading.rosters import same_form
    >>> same_form("Jose\u0301") == same_form("Jos\u00e9")
    True
    """
    return unicodedata.normalize("NFC", text)


def group_id(group: str) -> str:
    """The group's name as the course writes it: ``g`` and at least two digits.

    Parameters
    ----------
    group : str

    Returns
    -------
    str
        ``group`` itself when it is not ``g<number>``.

    Examples
    --------
    >>> from uio_teach.grading.rosters import group_id
    >>> group_id("g3"), group_id("G03"), group_id("group_12"), group_id("red")
    ('g03', 'g03', 'g12', 'red')
    >>> group_id("Group-30"), group_id("group_30"), group_id("G30"), group_id("Group 30")
    ('g30', 'g30', 'g30', 'g30')
    """
    text = same_form(group).strip()
    match = _GROUP.match(text)
    return f"g{int(match[1]):02d}" if match else text


def is_late(path: str | os.PathLike[str]) -> bool:
    """Whether an LMS download marks the hand-in late (Canvas: ``_LATE_`` in its name).

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    bool

    Examples
    --------
    >>> from uio_teach.grading.rosters import is_late
    >>> is_late("ann_LATE_1_2_pa9_g01.ipynb"), is_late("pa9_g01.ipynb")
    (True, False)
    """
    return bool(_LATE.search(Path(path).stem))


def group_from_name(
    path: str | os.PathLike[str], labs: Iterable[str] | None = None
) -> tuple[str, str]:
    """The lab and group a hand-in's file name gives (``("", "")`` when it gives none).

    The name ends in ``<lab>_<group>`` (``pa9_g03.ipynb``), after whatever an
    LMS put in front (Canvas: ``ann_48213_9920131_pa9_g03.ipynb``, late ones
    ``ann_LATE_48213_...``) and before a copy's number (``pa9_g03-1.ipynb``,
    ``pa9_g03 (2).ipynb``). The group is written as :func:`group_id` reads it
    (``pa9_Group-30``: group 30, not group "Group" handed in again). A lab of
    the course is found anywhere before the group; another lab only as the
    whole of the name before it (graded as an unknown lab). The name is read
    in NFC (``same_form``).

    Parameters
    ----------
    path : str or path-like
        The file.
    labs : iterable of str, optional
        The course's labs (its lab chapters, ``book/lab_<id>.md``, by default).

    Returns
    -------
    (str, str)
        The lab and the group (see :func:`group_id`).

    Examples
    --------
    >>> from uio_teach.grading.rosters import group_from_name
    >>> group_from_name("pa9_g12.ipynb"), group_from_name("lab_pa9.ipynb")
    (('pa9', 'g12'), ('', ''))
    >>> group_from_name("smith_john_48213_9920131_case_study_g02-1.ipynb")
    ('case_study', 'g02')
    >>> group_from_name("pa9_Group-30.ipynb"), group_from_name("pa9_G30 (2).ipynb")
    (('pa9', 'g30'), ('pa9', 'g30'))
    """
    if labs is None:
        from .lab_checks import course_labs  # deferred: only to find the book

        labs = course_labs()
    whole = same_form(Path(os.fspath(path)).stem)
    known = "|".join(re.escape(lab) for lab in sorted(labs, key=len, reverse=True))
    # the whole name first ("pa9_Group-30"), then without a copy's number ("pa9_g30-1")
    for stem in dict.fromkeys([whole, _COPY.sub("", whole)]):
        if known:
            match = re.search(rf"(?:^|_)(?P<lab>{known})_{_GROUP_PART}$", stem, re.I)
            if match:
                return match["lab"].lower(), group_id(match["group"])
        match = _GENERIC.match(stem)
        if match:
            return match["lab"], group_id(match["group"])
    return "", ""


def _decode(data: bytes, name: str) -> str:
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        return data.decode("utf-16")
    if data.startswith(b"\xef\xbb\xbf"):
        return data[3:].decode("utf-8")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        pass
    try:
        return data.decode("cp1252")
    except UnicodeDecodeError:
        raise GradeError(
            f"{name}: not text in UTF-8, UTF-16 or Windows-1252: save it as CSV UTF-8"
        ) from None


def _delimiter(header: str) -> str:
    """The separator of a header line: the candidate found most often outside quotes."""
    bare = re.sub(r'"[^"]*"', "", header)
    counts = [(bare.count(d), -i, d) for i, d in enumerate(DELIMITERS)]
    best = max(counts)
    return best[2] if best[0] else ","


def read_table(
    path: str | os.PathLike[str], columns: Sequence[str], *, what: str = "table"
) -> tuple[list[tuple[int, dict[str, str]]], str]:
    """The rows of a CSV as a spreadsheet saves it, by column name.

    Column names are read whatever their case and spacing (``Group``,
    ``SIS User ID``), with a few usual other names for each; a blank line
    is skipped.

    Parameters
    ----------
    path : str or path-like
    columns : sequence of str
        The columns it must have (of ``group``, ``file``, ``student``,
        ``name``, ``lab``, ``params``).
    what : str
        What the file is, for the messages.

    Returns
    -------
    (list of (int, dict), str)
        Each row's line number and its fields (every known column, "" when
        absent), and the separator found.

    Raises
    ------
    GradeError
        Missing, unreadable, too large, or without a column it must have
        (the message lists the columns it has and the separator read).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.grading.rosters import read_table
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = pathlib.Path(tmp) / "groups.csv"
    ...     _ = path.write_text("Group;Student;Name\\ng01;s1;Ann\\n")
    ...     rows, sep = read_table(path, ["group"])
    >>> rows[0][1]["student"], sep
    ('s1', ';')
    """
    name = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_TABLE_BYTES + 1)
    except FileNotFoundError:
        raise GradeError(f"{name}: no such file") from None
    except OSError as err:
        raise GradeError(f"{name}: cannot read it ({err.strerror or err})") from None
    if len(data) > MAX_TABLE_BYTES:
        raise GradeError(f"{name}: larger than {MAX_TABLE_BYTES >> 20} MB: not a {what}")
    text = _decode(data, name)
    lines = text.splitlines()
    header_line = next((line for line in lines if line.strip()), "")
    delimiter = _delimiter(header_line)
    try:
        table = list(csv.reader(io.StringIO(text, newline=""), delimiter=delimiter))
    except csv.Error as err:
        raise GradeError(f"{name}: cannot read it as CSV ({err})") from None
    numbered = [(n, row) for n, row in enumerate(table, start=1) if any(c.strip() for c in row)]
    if not numbered:
        raise GradeError(f"{name}: empty: a {what} needs a header line ({', '.join(columns)})")
    (_, header), body = numbered[0], numbered[1:]
    index: dict[str, int] = {}
    rank: dict[str, int] = {}
    keys = [" ".join(same_form(cell).strip().lower().replace("_", " ").split()) for cell in header]
    for column, aliases in _COLUMNS.items():  # each column: the best of its names found
        for i, key in enumerate(keys):
            if key in aliases and aliases.index(key) < rank.get(column, len(aliases)):
                index[column], rank[column] = i, aliases.index(key)
    if "group" in index and keys[index["group"]] == "section" and "group" in keys:
        index["group"] = keys.index("group")
    if index.get("student") == index.get("name") and "name" in index:
        # one column can only be one of them: an id column that is only "Student" is the id
        if keys[index["name"]] == "student":
            del index["name"]
    missing = [c for c in columns if c not in index]
    if missing:
        shown = {",": "comma", ";": "semicolon", "\t": "tab", "|": "bar"}[delimiter]
        has = ", ".join(repr(c.strip()) for c in header) or "none"
        raise GradeError(
            f"{name}: no column {' or '.join(repr(m) for m in missing)} in its header line "
            f"(read with a {shown} between fields: {has}); a {what} needs "
            f"{', '.join(repr(c) for c in columns)}"
        )
    rows = []
    for number, row in body:
        fields = {c: (same_form(row[i]).strip() if i < len(row) else "") for c, i in index.items()}
        for column in _COLUMNS:
            fields.setdefault(column, "")
        rows.append((number, fields))
    return rows, delimiter


def read_roster(
    path: str | os.PathLike[str],
) -> tuple[dict[str, tuple[str, str]], dict[str, list[tuple[str, str]]]]:
    """The groups of a roster: which hand-in is whose, and who is in each group.

    The table (any separator a spreadsheet writes, see :func:`read_table`) has
    a column ``group`` and at least one of ``file`` (the name of a hand-in,
    e.g. ``notebook (3).ipynb``) and ``student`` (a student's id in the LMS,
    e.g. its SIS user id); ``lab`` and ``name`` are optional. Canvas's own
    gradebook export is a roster as it is saved (its ``SIS User ID`` is the
    student, its ``Student`` the name, its ``Section`` the group unless a
    ``Group`` column is added; its "Points Possible" line and the test student
    are skipped); Moodle's participants export names the student by ``ID
    number`` (else ``Username`` or ``Email address``), the name by ``First
    name`` and ``Last name``, and the group by ``Groups``. Names are read in
    NFC (``same_form``). A row with a file says that file is the group's
    hand-in; a row with a student puts the student in the group (for the
    Canvas and Moodle exports). A student or a file listed
    twice is refused, naming it and both lines: one of the two rows is wrong,
    and a student listed twice would get two marks in Canvas.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    (dict, dict)
        File name -> (lab, group), and group -> list of (student, name).

    Raises
    ------
    GradeError
        The file is missing or unreadable, lacks the columns, a row lacks a
        group or both a file and a student, or names a file or a student twice.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.grading.rosters import read_roster
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     roster = pathlib.Path(tmp) / "groups.csv"
    ...     _ = roster.write_text("file,lab,group,student,name\\nx.ipynb,pa9,g1,s1,Ann\\n")
    ...     read_roster(roster)
    ({'x.ipynb': ('pa9', 'g01')}, {'g01': [('s1', 'Ann')]})
    """
    name = os.fspath(path)
    rows, _ = read_table(path, ["group"], what="roster")
    if rows and not any(r["file"] or r["student"] for _, r in rows):
        raise GradeError(f"{name}: a roster needs a column 'file' or 'student' besides 'group'")
    files: dict[str, tuple[str, str]] = {}
    file_lines: dict[str, int] = {}
    students: dict[str, list[tuple[str, str]]] = {}
    student_lines: dict[str, int] = {}
    for number, row in rows:
        group, file, student = group_id(row["group"]), row["file"], row["student"]
        if (row["name"] or student).strip().lower().startswith(_NOT_STUDENTS):
            continue  # Canvas's "Points Possible" line and its test student
        if not group or not (file or student):
            raise GradeError(f"{name}: line {number}: needs a group and a file or a student")
        if file:
            entry = (row["lab"], group)
            if file in files:
                earlier = file_lines[file]
                if files[file] != entry:
                    raise GradeError(
                        f"{name}: line {number}: {file} is listed for two groups "
                        f"({files[file][1]} on line {earlier}, {group} here)"
                    )
                raise GradeError(
                    f"{name}: line {number}: {file} is listed twice (also line {earlier})"
                )
            files[file], file_lines[file] = entry, number
        if student:
            full = row["name"] or " ".join(p for p in (row["first"], row["last"]) if p)
            who = f"{student} ({full})" if full else student
            if student in student_lines:
                raise GradeError(
                    f"{name}: line {number}: student {who} is listed twice (also line "
                    f"{student_lines[student]}): each student in one group, once"
                )
            student_lines[student] = number
            students.setdefault(group, []).append((student, full))
    return files, students


def read_answer_key(path: str | os.PathLike[str]) -> dict[tuple[str, str], dict[str, Any]]:
    """The parameters of every (lab, group) in an answer key written by ``uio-teach labs``.

    Read as a spreadsheet may have saved it again (:func:`read_table`).

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
        The file is missing, lacks a column, a ``params`` cell is not a JSON
        object, or a lab and group is listed twice.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.grading.rosters import read_answer_key
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     key = pathlib.Path(tmp) / "answer_key.csv"
    ...     _ = key.write_text('lab,group,params\\npa9,g01,"{""poles"": [-1, -2, -3]}"\\n')
    ...     read_answer_key(key)
    {('pa9', 'g01'): {'poles': [-1, -2, -3]}}
    """
    name = os.fspath(path)
    rows, _ = read_table(path, ["lab", "group", "params"], what="answer key")
    key: dict[tuple[str, str], dict[str, Any]] = {}
    lines: dict[tuple[str, str], int] = {}
    for number, row in rows:
        try:
            params = json.loads(row["params"])
        except ValueError:
            raise GradeError(f"{name}: line {number}: params is not JSON") from None
        if not isinstance(params, dict):
            raise GradeError(f"{name}: line {number}: params is not a JSON object")
        entry = (row["lab"], group_id(row["group"]))
        if entry in key:
            raise GradeError(
                f"{name}: line {number}: lab {entry[0]}, group {entry[1]} is listed twice "
                f"(also line {lines[entry]})"
            )
        key[entry], lines[entry] = params, number
    return key
