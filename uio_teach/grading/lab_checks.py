"""The lab chapters' own check cells, as the grader runs them on a group's answers.

A lab chapter (``book/lab_*.md``) marks each check cell a group runs with the
tag ``check``: one call of a check function of :mod:`uio_teach.checks` on the
group's answer variables, on ``PARAMS`` and on what the chapter's set-up cells
define (the group's ``plant``, the missile's ``x0``). The grader runs **those
cells**, read from the chapter (:func:`read_lab_checks`), never a copy of their
calls: in its checking process it runs the chapter's set-up cells with the
answer key's parameters, then each check cell with the group's answers taken
out of its kernel (:mod:`uio_teach.checks.answers`) in place of the names the
set-up does not define (:func:`grade_answers`). What the notebook's own
``PARAMS``, ``plant`` or checks say counts for nothing.

An answer that is missing (the variable was never assigned, or the cell that
assigns it raised) gives a ✗ that names the variable, and, when a cell raised,
which cell and the exception, with a hint for the common cases.

Examples
--------
>>> import uio_teach as ut
>>> from uio_teach.grading.lab_checks import Missing, grade_answers, lab_checks
>>> pa9 = lab_checks("pa9")
>>> pa9.checks[0].check_id, pa9.checks[0].names
('pa9.design', ('H', 'T', 'K1', 'F', 'K2'))
>>> params = pa9.default_params()
>>> obs = ut.design_uio(ut.examples.pa9(), poles=params["poles"])
>>> answers = {"H": obs.H, "T": obs.T, "K1": obs.K1, "F": obs.F, "K2": obs.K2}
>>> grade_answers(pa9, answers, params)[0].passed
True
>>> answers["K1"] = Missing("K1", cell=4, ename="LinAlgError", evalue="Singular matrix")
>>> print(grade_answers(pa9, answers, params)[0].failures[0])  # doctest: +ELLIPSIS
K1 is missing: code cell 4 raised LinAlgError (Singular matrix). ...
"""

from __future__ import annotations

import ast
import builtins
import contextlib
import copy
import functools
import io
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..checks.common import CheckResult
from ..errors import UIOTeachError
from ..folders import default_book_dir

__all__ = [
    "CHECK_TAG",
    "GradedCheck",
    "LabChecks",
    "LabChecksError",
    "Missing",
    "read_lab_checks",
    "lab_checks",
    "course_checks",
    "course_labs",
    "check_function",
    "lab_plant",
    "setup_namespace",
    "grade_answers",
    "missing_message",
]

CHECK_TAG = "check"
"""The tag of a chapter's check cells (the cells a group runs, and the grader runs again)."""
_CALL = re.compile(r"\bchecks\.(\w+)\s*\(")
_HEADING = re.compile(r"^#{1,6}\s+(.*\S)\s*$", re.M)
_ROLE = re.compile(r"\{\w+(?::\w+)?\}`([^`]*)`")


class LabChecksError(UIOTeachError, ValueError):
    """A lab chapter whose check cells cannot be graded (one line naming the chapter)."""


def check_function(source: str) -> str | None:
    """The check function a check cell calls (``checks.<name>(...)``), or None.

    Parameters
    ----------
    source : str

    Returns
    -------
    str or None

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import check_function
    >>> check_function("checks.pa9_design(H, T, K1, F, K2, poles=PARAMS['poles'])")
    'pa9_design'
    """
    match = _CALL.search(source)
    return match[1] if match else None


@dataclass(frozen=True)
class Missing:
    """An answer the grader could not take out of the kernel.

    Attributes
    ----------
    name : str
        The variable.
    cell : int or None
        The code cell (counted from 1, the student's cells only) that raised
        before the check, or None when nothing raised.
    ename : str
        The exception's class name ("" when nothing raised).
    evalue : str
        Its message, on one line.
    reason : str
        Why else it is missing (not carried out of the kernel, malformed).

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import Missing
    >>> Missing("H").cell is None
    True
    """

    name: str
    cell: int | None = None
    ename: str = ""
    evalue: str = ""
    reason: str = ""


@dataclass(frozen=True)
class GradedCheck:
    """One check cell of a lab chapter, as the grader runs it.

    Attributes
    ----------
    check_id : str
        The gradebook column: the lab and the function, ``"pa9.design"`` for
        ``checks.pa9_design``.
    function : str
        The check function the cell calls (``"pa9_design"``).
    title : str
        The heading of the chapter's section that holds the cell (for a ✗ the
        grader writes when an answer is missing).
    names : tuple of str
        The answer variables it reads: the names of the cell that the
        chapter's set-up cells do not define (nor ``PARAMS``, nor a builtin).
    source : str
        The cell's code, as in the chapter.
    """

    check_id: str
    function: str
    title: str
    names: tuple[str, ...]
    source: str


@dataclass(frozen=True)
class LabChecks:
    """The check cells of one lab chapter, with what they need to run.

    Attributes
    ----------
    lab : str
        The lab id (``"pa9"``).
    chapter : str
        The chapter's file name.
    setup : tuple of str
        The chapter's set-up cells: its code cells before the first exercise,
        the ``parameters`` cell left out (``PARAMS`` comes from the key).
    params : str
        The chapter's ``parameters`` cell (the course's own numbers).
    checks : tuple of GradedCheck
        Its check cells, in order.
    given : tuple of str
        The code the course itself holds: every code cell of the chapter, its
        solutions included. Copy detection sets it aside
        (:mod:`uio_teach.grading.copies`): an untouched template, or a line
        as the course's own solution writes it, is no sign of a copy.
    """

    lab: str
    chapter: str
    setup: tuple[str, ...]
    params: str
    checks: tuple[GradedCheck, ...]
    given: tuple[str, ...] = ()

    @property
    def check_ids(self) -> tuple[str, ...]:
        """The gradebook columns of the lab, in order."""
        return tuple(c.check_id for c in self.checks)

    @property
    def names(self) -> tuple[str, ...]:
        """Every answer variable of the lab, sorted."""
        return tuple(sorted({n for c in self.checks for n in c.names}))

    def default_params(self) -> dict[str, Any]:
        """``PARAMS`` of the chapter's parameters cell (the course's own numbers)."""
        ns: dict[str, Any] = {}
        _run_cells([self.params], ns, f"<{self.chapter}: parameters>")
        params = ns.get("PARAMS")
        if not isinstance(params, dict):
            raise LabChecksError(f"{self.chapter}: its parameters cell defines no dict PARAMS")
        return params

    def to_dict(self) -> dict[str, Any]:
        """Plain data (for the checking process)."""
        return {
            "lab": self.lab,
            "chapter": self.chapter,
            "setup": list(self.setup),
            "params": self.params,
            "checks": [
                {
                    "check_id": c.check_id,
                    "function": c.function,
                    "title": c.title,
                    "names": list(c.names),
                    "source": c.source,
                }
                for c in self.checks
            ],
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> LabChecks:
        """The inverse of :meth:`to_dict`."""
        return cls(
            str(data["lab"]),
            str(data["chapter"]),
            tuple(str(s) for s in data["setup"]),
            str(data["params"]),
            tuple(
                GradedCheck(
                    str(c["check_id"]),
                    str(c["function"]),
                    str(c["title"]),
                    tuple(str(n) for n in c["names"]),
                    str(c["source"]),
                )
                for c in data["checks"]
            ),
        )


def _title(markdown: str) -> str:
    text = _ROLE.sub(r"\1", markdown).replace("$", "").replace("`", "")
    return " ".join(text.split())


def _defined(source: str) -> set[str]:
    """The names a cell binds at its top level (assignments, imports, functions, loops)."""
    tree = ast.parse(source)
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
    return names


def _read(source: str) -> list[str]:
    """The names a cell reads, in the order they appear."""
    found = [
        n
        for n in ast.walk(ast.parse(source))
        if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)
    ]
    found.sort(key=lambda n: (n.lineno, n.col_offset))
    return list(dict.fromkeys(n.id for n in found))


def read_lab_checks(path: str | os.PathLike[str], lab: str) -> LabChecks:
    """The check cells of the lab chapter ``path`` (MyST Markdown), with its set-up cells.

    Parameters
    ----------
    path : str or path-like
        The chapter.
    lab : str
        Its lab id: each check function is ``<lab>_<what>`` (checked).

    Returns
    -------
    LabChecks

    Raises
    ------
    LabChecksError
        The chapter cannot be read, has no parameters cell or no check cell, a
        check cell calls no check function, calls one of another lab or one
        twice, or is not Python.

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import read_lab_checks
    >>> from uio_teach.folders import default_book_dir
    >>> checks = read_lab_checks(default_book_dir() / "lab_missile.md", "missile")
    >>> checks.check_ids[:2], checks.checks[2].names
    (('missile.pmo', 'missile.ginverse'), ('vhat', 'run_pmo', 'pmo'))
    """
    import jupytext  # deferred on purpose: the optional ``instructor`` extra

    name = Path(path).name
    try:
        nb = jupytext.read(path, fmt="md:myst")
    except FileNotFoundError:
        raise LabChecksError(f"{name}: no such lab chapter ({os.fspath(path)})") from None
    except Exception as err:  # jupytext raises many kinds on a broken file
        raise LabChecksError(f"{name}: cannot read it ({type(err).__name__}: {err})") from None
    setup: list[str] = []
    params = ""
    found: list[tuple[str, str]] = []
    alike: list[str] = []
    title = ""
    started = False
    for cell in nb.cells:
        source = cell.source
        if cell.cell_type == "markdown":
            headings = _HEADING.findall(source)
            if headings:
                title = _title(headings[-1])
            started = started or "{exercise}" in source or "{solution-start}" in source
            continue
        if cell.cell_type != "code":
            continue
        tags = cell.metadata.get("tags", [])
        alike.append(source)
        if "parameters" in tags:
            params = source
        elif CHECK_TAG in tags:
            found.append((source, title))
        elif not started:
            setup.append(source)
    if not params:
        raise LabChecksError(f"{name}: no code cell tagged parameters (PARAMS)")
    if not found:
        raise LabChecksError(f"{name}: no code cell tagged {CHECK_TAG}")
    given = {"PARAMS", *dir(builtins)}
    for source in setup:
        try:
            given |= _defined(source)
        except SyntaxError as err:
            raise LabChecksError(f"{name}: a set-up cell is not Python ({err.msg})") from None
    checks = []
    for source, heading in found:
        function = check_function(source)
        where = f"{name}: the check cell under {heading!r}"
        if function is None:
            raise LabChecksError(f"{where} calls no check function (checks.<lab>_...)")
        if not function.startswith(f"{lab}_"):
            raise LabChecksError(f"{where} calls checks.{function}, not a check of lab {lab}")
        try:
            read = _read(source)
        except SyntaxError as err:
            raise LabChecksError(f"{where} is not Python ({err.msg})") from None
        names = tuple(n for n in read if n not in given)
        check_id = f"{lab}.{function[len(lab) + 1 :]}"
        if any(c.check_id == check_id for c in checks):
            raise LabChecksError(f"{where} calls checks.{function} a second time")
        checks.append(GradedCheck(check_id, function, heading, names, source))
    return LabChecks(lab, name, tuple(setup), params, tuple(checks), tuple(alike))


@functools.lru_cache(maxsize=16)
def _cached(path: str, mtime: float, lab: str) -> LabChecks:
    return read_lab_checks(path, lab)


def course_labs(book: str | os.PathLike[str] | None = None) -> dict[str, Path]:
    """The labs of the course: lab id -> its chapter, ``book/lab_<id>.md``.

    The chapters are the registry the grader reads (the term's tooling keeps
    its own, ``uio_teach.instructor.lab_registry.LABS``, which a test holds
    equal to this): grading needs neither the labs' parameter classes nor the
    algorithms they load.

    Parameters
    ----------
    book : path, optional
        The book's folder (:func:`~uio_teach.folders.default_book_dir` by default).

    Returns
    -------
    dict

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import course_labs
    >>> sorted(course_labs())
    ['case_study', 'missile', 'pa9']
    """
    folder = Path(book) if book is not None else default_book_dir()
    return {path.stem[4:]: path for path in sorted(folder.glob("lab_*.md"))}


def lab_checks(lab: str, book: str | os.PathLike[str] | None = None) -> LabChecks:
    """The check cells of the course's lab ``lab``, read from its chapter.

    Parameters
    ----------
    lab : str
        A lab of the course (:func:`course_labs`).
    book : path, optional
        The book's folder (:func:`~uio_teach.folders.default_book_dir` by default).

    Returns
    -------
    LabChecks

    Raises
    ------
    LabChecksError
        Not a lab of the course, or its chapter cannot be graded.
    """
    labs = course_labs(book)
    if lab not in labs:
        raise LabChecksError(f"{lab!r} is not a lab of the course ({', '.join(labs)})")
    path = labs[lab]
    try:
        mtime = path.stat().st_mtime
    except OSError:
        mtime = -1.0
    return _cached(os.fspath(path), mtime, lab)


def course_checks(book: str | os.PathLike[str] | None = None) -> dict[str, LabChecks]:
    """The check cells of every lab of the course, by lab id.

    Parameters
    ----------
    book : path, optional
        The book's folder.

    Returns
    -------
    dict

    Raises
    ------
    LabChecksError
        The book holds no lab chapter, or one cannot be graded.

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import course_checks
    >>> {lab: len(c.checks) for lab, c in course_checks().items()}
    {'case_study': 6, 'missile': 6, 'pa9': 5}
    """
    labs = course_labs(book)
    if not labs:
        raise LabChecksError("no lab chapter (book/lab_*.md) found: is the book installed?")
    return {lab: lab_checks(lab, book) for lab in labs}


def lab_plant(lab: str, params: Mapping[str, Any] | None) -> Any:
    """The plant of a group: the lab's plant with the matrices its parameters give, if any.

    Parameters
    ----------
    lab : str
        ``"pa9"``, ``"case_study"`` or ``"missile"``.
    params : mapping or None
        The group's parameters (from the answer key).

    Returns
    -------
    Plant

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import lab_plant
    >>> lab_plant("pa9", {"poles": [-1, -2, -3]}).n
    3
    """
    from ..experiments import plant_from_params  # deferred: the algorithms load on use

    return plant_from_params(lab, params)


def _run_cells(sources: Sequence[str], ns: dict[str, Any], where: str) -> Any:
    """Run cells in ``ns`` as a kernel would; the value of the last one's last expression."""
    value = None
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        for source in sources:
            tree = ast.parse(source, where)
            last = tree.body.pop() if tree.body and isinstance(tree.body[-1], ast.Expr) else None
            exec(compile(tree, where, "exec"), ns)  # noqa: S102 - the chapter's own code
            value = None
            if last is not None:
                value = eval(compile(ast.Expression(last.value), where, "eval"), ns)  # noqa: S307
    return value


def setup_namespace(checks: LabChecks, params: Mapping[str, Any]) -> dict[str, Any]:
    """What the chapter's set-up cells define with ``PARAMS = params`` (a fresh namespace).

    Parameters
    ----------
    checks : LabChecks
    params : mapping
        The group's parameters (from the answer key).

    Returns
    -------
    dict
    """
    ns: dict[str, Any] = {"__name__": "__uio_teach_checks__", "PARAMS": copy.deepcopy(params)}
    _run_cells(checks.setup, ns, f"<{checks.chapter}: set-up>")
    return ns


_HINTS = (
    (
        "LinAlgError",
        ("square",),
        "np.linalg.inv takes only a square matrix, and this one is not square: where a formula "
        "inverts a matrix that is not square (CE in Practical Assignment 9), it means a "
        "generalized inverse (np.linalg.pinv)",
    ),
    (
        "LinAlgError",
        ("singular",),
        "np.linalg.inv was given a singular matrix, which has no inverse: check how that "
        "matrix was built, and whether the formula asks for a generalized inverse "
        "(np.linalg.pinv) instead",
    ),
    (
        "ValueError",
        ("matmul", "mismatch", "shapes", "broadcast"),
        "the shapes in a product do not fit: print the .shape of each factor and compare "
        "them with the sizes n, m, p, q of the plant",
    ),
    (
        "NameError",
        ("not defined",),
        "a name used in that cell is not assigned by any cell above it (the grader runs the "
        "notebook from the top, in order): check its spelling, or move the cell that assigns "
        "it above",
    ),
    (
        "TimeoutError",
        (),
        "the cell ran longer than the time limit of a cell: look for a loop that never ends",
    ),
    (
        "KeyError",
        (),
        "a key of PARAMS or of a dict is spelt differently: print the dict's keys",
    ),
)


def missing_message(missing: Missing) -> str:
    """The grader's ✗ for a missing answer: the variable, the cell that raised, a hint.

    Parameters
    ----------
    missing : Missing

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import Missing, missing_message
    >>> print(missing_message(Missing("fig")))
    fig is missing: no cell assigned it before this check. Name your result fig.
    """
    name = missing.name
    if missing.reason:
        return f"{name} could not be graded: {missing.reason}."
    if missing.cell is None:
        return f"{name} is missing: no cell assigned it before this check. Name your result {name}."
    evalue = f" ({missing.evalue})" if missing.evalue else ""
    text = f"{name} is missing: code cell {missing.cell} raised {missing.ename or 'an error'}"
    text += f"{evalue}."
    low = missing.evalue.lower()
    for ename, words, hint in _HINTS:
        if missing.ename == ename and (not words or any(w in low for w in words)):
            return f"{text} Hint: {hint}."
    return f"{text} Fix that cell and run the notebook again from the top."


def grade_answers(
    checks: LabChecks,
    answers: Mapping[str, Any],
    params: Mapping[str, Any],
    *,
    per_check: Sequence[Mapping[str, Any]] | None = None,
    namespace: Mapping[str, Any] | None = None,
) -> list[CheckResult]:
    """The verdict of every check cell of a lab on the answers, with the key's parameters.

    The chapter's set-up cells run with ``PARAMS = params``; then each check
    cell runs on a copy of what they defined, the answers in place of the
    names it reads, and gives its result.

    Parameters
    ----------
    checks : LabChecks
        The lab's check cells (:func:`lab_checks`).
    answers : mapping
        Variable name -> value (rebuilt objects) or :class:`Missing`.
    params : mapping
        The group's parameters, from the answer key (the chapter's own when
        there is no key): never the notebook's ``PARAMS``.
    per_check : sequence of mapping, optional
        For each check, in order, the answers captured right after its check
        cell ran (later reassignments do not matter); ``answers`` fills what a
        capture lacks.
    namespace : mapping, optional
        What :func:`setup_namespace` gave for these parameters (made here by default).

    Returns
    -------
    list of CheckResult
        One per check, in order, each with its ``check_id``.
    """
    from ..checks import clear_collected  # deferred: the checks load their plotting on use

    ns = dict(namespace) if namespace is not None else setup_namespace(checks, params)
    results = []
    for index, check in enumerate(checks.checks):
        seen = dict(answers)
        if per_check is not None and index < len(per_check):
            seen.update(per_check[index])
        absent = [n for n in check.names if n not in seen or isinstance(seen[n], Missing)]
        if absent:
            result = CheckResult(check.title, check_id=check.check_id)
            for name in absent:
                why = seen.get(name)
                result.add(
                    False, missing_message(why if isinstance(why, Missing) else Missing(name))
                )
        else:
            local = dict(ns)
            local["PARAMS"] = copy.deepcopy(dict(params))
            local.update({n: seen[n] for n in check.names})
            try:
                result = _run_cells([check.source], local, f"<{checks.chapter}: {check.check_id}>")
            except MemoryError:  # a limit of the checking process: the row says so
                raise
            except Exception as exc:  # never a traceback: the check could not be made
                result = CheckResult(
                    check.title,
                    [(False, f"the grader could not check your answers ({type(exc).__name__}).")],
                )
            if not isinstance(result, CheckResult):
                result = CheckResult(
                    check.title,
                    [(False, "the grader could not check your answers (no result).")],
                )
            result.check_id = check.check_id
        results.append(result)
    clear_collected()  # the check functions record their results; the grader keeps none
    return results
