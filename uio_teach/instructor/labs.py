"""Turn the book's lab chapters into Jupyter notebooks: a student version and a solution version.

A lab chapter is a MyST Markdown notebook in ``book/`` whose file name contains
``lab`` (``lab_pa9.md``). Its solutions live inside sphinx-exercise blocks,
``{solution-start} <label>`` ... ``{solution-end}``, and/or in code cells
tagged ``solution``. From the one source, :func:`make_notebook` builds:

* the **student** version: every solution is replaced by one code cell
  starting with ``# TODO: Exercise <number> (<label>)``. When later cells use
  names that the solution defined (``checks.pa9_design(H, T, K1)``), the TODO
  cell sets them to ``None``, so the notebook runs from top to bottom and each
  check cell says, in plain words, what is still missing. Check cells are kept
  (tagged ``check``); a section headed "Instructor notes" is left out. A
  solution that explains in words (a model answer) gets a markdown "Your
  answer" cell instead; nothing of the solution is left in the notebook.
* the **solution** version: complete, solution cells tagged ``solution``,
  the check cells that students run tagged ``check``, the instructor notes
  kept (tagged ``instructor``, never ``check``).

The one code cell tagged ``parameters`` defines ``PARAMS``, the numbers of the
exercise; with ``params=`` it is rewritten for a term (``--config``) or a group
(``--groups``). :data:`LABS` names the course's labs, their parameter classes
(:mod:`uio_teach.instructor.lab_params`) and the check ids of their check
cells. A source without a solution is not a lab (:class:`LabUsageError`).

Both have empty outputs and pass :func:`nbformat.validate`. The MyST syntax
that Jupyter does not render is rewritten as plain Markdown by
:mod:`uio_teach.instructor.myst`: exercises become quotes titled "Exercise
<number>" (numbered as in the book), ``{eq}`` references become "eq. (3.2)",
``{doc}`` and ``{ref}`` become "chapter 3", ``{cite:p}`` becomes (Author,
year), labelled display equations get a ``\\tag``.

Examples
--------
>>> import tempfile, pathlib
>>> from uio_teach.instructor import labs
>>> text = '''# Lab
... ```{exercise}
... :label: ex-demo-1
... Compute `x`.
... ```
... ```{solution-start} ex-demo-1
... ```
... ```{code-cell} ipython3
... x = 6 * 7
... ```
... ```{solution-end}
... ```
... ```{code-cell} ipython3
... print(x)
... ```
... '''
>>> with tempfile.TemporaryDirectory() as tmp:
...     src = pathlib.Path(tmp) / "lab_demo.md"
...     _ = src.write_text(text)
...     student = labs.make_notebook(src, "student")
>>> print(student.cells[-2].source)
# TODO: Exercise 1 (ex-demo-1). Write your code here.
# The cells below use these names; replace None by your answer:
x = None
"""

from __future__ import annotations

import ast
import os
import re
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from .book import (
    _HEADING,
    _TARGET,
    BookIndex,
    _fence_states,
    default_book_dir,
)
from .myst import Converter, Directive, tokens
from .variants import ANSWER_KEY, draw_variants, write_answer_key

__all__ = [
    "VERSIONS",
    "LABS",
    "Lab",
    "LabError",
    "LabUsageError",
    "BookIndex",
    "LabResult",
    "draw_variants",
    "lab_of",
    "params_source",
    "write_answer_key",
    "default_book_dir",
    "find_labs",
    "make_notebook",
    "write_labs",
]

VERSIONS = ("student", "solution")
"""The two versions of every lab notebook (also the names of the output sub-folders)."""

LAB_PATTERN = "*lab*.md"
SOLUTION_TAG = "solution"
CHECK_TAG = "check"
TODO_TAG = "todo"
INSTRUCTOR_TAG = "instructor"
PARAMETERS_TAG = "parameters"

Version = Literal["student", "solution"]

_CHECK_CALL = re.compile(r"\bchecks\.\w+\s*\(")


class LabError(ValueError):
    """A lab chapter that cannot be converted (one-line message naming the file)."""


class LabUsageError(LabError):
    """A source that is not a lab chapter, or a folder that does not exist (a usage error)."""


def _params_literal(source: str) -> Any:
    """The value of ``PARAMS = <literal>`` in a cell, or ``None`` if the cell is not that."""
    tree = _python(source)
    if tree is None or len(tree.body) != 1 or not isinstance(tree.body[0], ast.Assign):
        return None
    node = tree.body[0]
    if [getattr(t, "id", None) for t in node.targets] != ["PARAMS"]:
        return None
    try:
        return ast.literal_eval(node.value)
    except (ValueError, SyntaxError):
        return None


def params_source(params: dict[str, Any]) -> str:
    """The source of the ``parameters`` cell: ``PARAMS = {...}`` as a JSON-compatible literal.

    Parameters
    ----------
    params : dict
        JSON-compatible values (numbers, strings, lists, dicts).

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.instructor.labs import params_source
    >>> print(params_source({"poles": [-1.0, -2.0]}))
    PARAMS = {
        "poles": [-1.0, -2.0]
    }
    """
    import json

    text = json.dumps(params, indent=4, ensure_ascii=False, allow_nan=False)
    # short lists of numbers on one line
    text = re.sub(
        r"\[\s*([^\[\]{}]*?)\s*\]",
        lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]",
        text,
    )
    return f"PARAMS = {text}"


# Python names a solution defines and later cells use ---------------------------------------------


def _python(source: str) -> ast.Module | None:
    lines = [ln for ln in source.split("\n") if not ln.lstrip().startswith(("%", "!"))]
    try:
        return ast.parse("\n".join(lines))
    except SyntaxError:
        return None


def _stored(source: str) -> list[str]:
    """Names bound at the top level of a cell, in order of first binding."""
    tree = _python(source)
    names: list[str] = []

    def add(name: str) -> None:
        if name not in names:
            names.append(name)

    def targets(node: ast.AST) -> None:
        for sub in ast.walk(node):
            if isinstance(sub, ast.Name):
                add(sub.id)

    def visit(stmts: Iterable[ast.stmt]) -> None:
        for st in stmts:
            if isinstance(st, ast.Assign):
                for t in st.targets:
                    targets(t)
            elif isinstance(st, (ast.AnnAssign, ast.AugAssign)):
                targets(st.target)
            elif isinstance(st, (ast.For, ast.AsyncFor)):
                targets(st.target)
                visit(st.body)
                visit(st.orelse)
            elif isinstance(st, (ast.With, ast.AsyncWith)):
                for item in st.items:
                    if item.optional_vars is not None:
                        targets(item.optional_vars)
                visit(st.body)
            elif isinstance(st, (ast.If, ast.While)):
                visit(st.body)
                visit(st.orelse)
            elif isinstance(st, ast.Try):
                visit(st.body)
                for h in st.handlers:
                    visit(h.body)
                visit(st.orelse)
                visit(st.finalbody)
            elif isinstance(st, (ast.Import, ast.ImportFrom)):
                for alias in st.names:
                    add((alias.asname or alias.name).split(".")[0])
            elif isinstance(st, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                add(st.name)

    if tree is not None:
        visit(tree.body)
    return names


def _loaded(source: str) -> set[str]:
    tree = _python(source)
    if tree is None:
        return set()
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}


# the notebook ----------------------------------------------------------------------------------


@dataclass
class _Cell:
    kind: str  # "markdown" or "code"
    source: str
    tags: list[str] = field(default_factory=list)
    metadata: dict[str, Any] = field(default_factory=dict)
    solution_code: list[str] | None = None  # a TODO cell: the code it replaces
    todo_header: str = ""


class _Builder:
    def __init__(
        self,
        version: Version,
        converter: Converter,
        index: BookIndex,
        params: dict[str, Any] | None = None,
    ) -> None:
        self.version = version
        self.params = params
        self.parameters_seen = False
        self.solution_prose = False
        self.solutions = 0
        self.student = version == "student"
        self.conv = converter
        self.index = index
        self.cells: list[_Cell] = []
        self.md: list[str] = []
        self.md_tags: tuple[str, ...] = ()
        self.solution: str | None = None  # label of the open solution block
        self.solution_code: list[str] = []
        self.exercise: tuple[str, str] = ("", "")  # (label, number)
        self.exercise_count = 0
        self.instructor_level: int | None = None
        self.pending_labels: list[str] = []

    # context ------------------------------------------------------------------------------------
    def _context_tags(self) -> tuple[str, ...]:
        tags = []
        if self.solution is not None:
            tags.append(SOLUTION_TAG)
        if self.instructor_level is not None:
            tags.append(INSTRUCTOR_TAG)
        return tuple(tags)

    def _dropped(self) -> bool:
        return self.student and (self.solution is not None or self.instructor_level is not None)

    def _emit_md(self, text: str) -> None:
        if self.solution is not None and text.strip() and not text.startswith("**Solution of"):
            self.solution_prose = True
        if self._dropped() or not text.strip():
            return
        tags = self._context_tags()
        if tags != self.md_tags:
            self.flush()
            self.md_tags = tags
        self.md.append(text)

    def flush(self) -> None:
        text = "\n\n".join(t.strip("\n") for t in self.md if t.strip())
        if text.strip():
            self.cells.append(_Cell("markdown", text, list(self.md_tags)))
        self.md = []

    def _exercise_label(self, label: str | None) -> tuple[str, str]:
        label = label or self.exercise[0]
        if label in self.index.exercises:
            stem, k = self.index.exercises[label]
            return label, self.index.number(stem, k)
        return label, self.exercise[1] if label == self.exercise[0] else "?"

    # markdown -----------------------------------------------------------------------------------
    def markdown(self, text: str) -> None:
        for token in tokens(text):
            if isinstance(token, str):
                self._text(token)
            else:
                self._directive(token)

    def _text(self, text: str) -> None:
        chunk: list[str] = []
        lines = text.split("\n")
        for line, verbatim in zip(lines, _fence_states(lines), strict=True):
            stripped = line.strip()
            target = None if verbatim else _TARGET.match(stripped)
            heading = None if verbatim else _HEADING.match(line)
            if heading:
                level = len(heading.group("hashes"))
                if self.instructor_level is not None and level <= self.instructor_level:
                    self._emit_md(self.conv.inline("\n".join(chunk)))
                    chunk = []
                    self.instructor_level = None
                title = heading.group("text").lower()
                labels = " ".join(self.pending_labels).lower()
                if title.startswith("instructor") or "instructor" in labels:
                    self._emit_md(self.conv.inline("\n".join(chunk)))
                    chunk = []
                    self.instructor_level = level
            if target:
                self.pending_labels.append(target.group("label"))
            elif stripped:
                self.pending_labels = []
            chunk.append(line)
        self._emit_md(self.conv.inline("\n".join(chunk)))

    def _directive(self, d: Directive) -> None:
        if d.name == "solution-start":
            self.flush()
            self.solution = d.arg.strip() or self.exercise[0]
            self.solution_code = []
            self.solution_prose = False
            self.solutions += 1
            label, number = self._exercise_label(self.solution)
            self._emit_md(f"**Solution of Exercise {number}**")
            return
        if d.name == "solution-end":
            self.flush()
            if self.student and self.solution is not None:
                self._todo(self.solution, self.solution_code, prose=self.solution_prose)
            self.solution = None
            return
        if d.name == "exercise":
            self.exercise_count += 1
            label = d.options.get("label", "")
            number = (
                self._exercise_label(label)[1]
                if label in self.index.exercises
                else str(self.exercise_count)
            )
            self.exercise = (label, number)
            self._emit_md(self.conv.directive(d, number))
            return
        self._emit_md(self.conv.directive(d))

    # code ---------------------------------------------------------------------------------------
    def code(self, source: str, metadata: dict[str, Any]) -> None:
        tags = list(metadata.get("tags", []))
        meta = {k: v for k, v in metadata.items() if k != "tags"}
        is_solution = self.solution is not None or SOLUTION_TAG in tags
        if self.student and self.instructor_level is not None:
            return
        self.flush()
        if PARAMETERS_TAG in tags:
            if self.parameters_seen:
                raise LabError("more than one cell is tagged 'parameters'")
            self.parameters_seen = True
            if self.params is not None and _params_literal(source) != self.params:
                source = params_source(self.params)
            self.cells.append(_Cell("code", source, [PARAMETERS_TAG], meta))
            return
        if is_solution:
            if self.student:
                if self.solution is not None:
                    self.solution_code.append(source)
                else:
                    self.solutions += 1
                    self._todo(self.exercise[0], [source])
                return
            if SOLUTION_TAG not in tags:
                tags.append(SOLUTION_TAG)
        elif _CHECK_CALL.search(source) and CHECK_TAG not in tags and self.instructor_level is None:
            tags.append(CHECK_TAG)
        if self.instructor_level is not None:
            tags = [t for t in tags if t != CHECK_TAG]
            if INSTRUCTOR_TAG not in tags:
                tags.append(INSTRUCTOR_TAG)
        self.cells.append(_Cell("code", source, tags, meta))

    def _todo(self, label: str | None, code: list[str], prose: bool = False) -> None:
        label, number = self._exercise_label(label)
        name = (f"Exercise {number}" if number else "") + (f" ({label})" if label else "")
        name = name.strip() or "your code"
        if code:
            self.cells.append(
                _Cell("code", "", [TODO_TAG], solution_code=code, todo_header=f"# TODO: {name}.")
            )
        if prose or not code:
            self.cells.append(
                _Cell(
                    "markdown",
                    f"**Your answer to {name}** (in words; double-click to edit):\n\n*...*",
                    [TODO_TAG],
                )
            )

    # finishing ----------------------------------------------------------------------------------
    def finish(self) -> list[_Cell]:
        self.flush()
        if self.solution is not None:
            raise LabError(f"solution block {self.solution!r} is never closed (no solution-end)")
        for i, cell in enumerate(self.cells):
            if cell.solution_code is None:
                continue
            defined = []
            for src in cell.solution_code:
                defined += [n for n in _stored(src) if n not in defined]
            earlier: set[str] = set()
            for c in self.cells[:i]:
                if c.kind == "code" and c.solution_code is None:
                    earlier.update(_stored(c.source))
            later: set[str] = set()
            for c in self.cells[i + 1 :]:
                if c.kind == "code" and c.solution_code is None:
                    later.update(_loaded(c.source))
            names = [n for n in defined if n in later and n not in earlier]
            lines = [f"{cell.todo_header} Write your code here."]
            if names:
                lines.append("# The cells below use these names; replace None by your answer:")
                lines += [f"{n} = None" for n in names]
            cell.source = "\n".join(lines)
        return self.cells


_BANNER = {
    "student": (
        "> **Student version.** Write your code in the cells that start with `# TODO`, then run "
        "the check cell that follows: it says what is right (✓) and what is not yet (✗)."
    ),
    "solution": (
        "> **Solution version, for instructors.** Complete: the solutions are in the cells "
        "tagged `solution`, the checks in the cells tagged `check`."
    ),
}


def make_notebook(
    source: str | os.PathLike[str],
    version: Version,
    *,
    index: BookIndex | None = None,
    params: dict[str, Any] | None = None,
    metadata: dict[str, Any] | None = None,
) -> Any:
    """Build the student or solution notebook of one lab chapter (outputs empty).

    Parameters
    ----------
    source : str or path-like
        The MyST Markdown notebook (read with ``jupytext.read``).
    version : {"student", "solution"}
        Which notebook to build.
    index : BookIndex, optional
        Titles and numbers for the cross-references; by default read from the
        folder of ``source``.
    params : dict, optional
        The lab's numbers: the cell tagged ``parameters`` becomes
        ``PARAMS = <params>`` (default: the chapter's own cell).
    metadata : dict, optional
        Added to the notebook's ``uio_teach`` metadata (e.g. ``{"lab": "pa9",
        "group": "g01"}``).

    Returns
    -------
    nbformat.NotebookNode
        A valid nbformat 4 notebook.

    Raises
    ------
    LabError
        The source cannot be read, or a solution block is not closed; a
        ``LabUsageError`` (a subclass) when the source is not a lab chapter (it
        has no solution to hide) or does not exist.

    Examples
    --------
    >>> from uio_teach.instructor.labs import default_book_dir, find_labs, make_notebook
    >>> lab = find_labs(default_book_dir())[0]
    >>> student = make_notebook(lab, "student")
    >>> any("solution" in c.metadata.get("tags", []) for c in student.cells)
    False
    >>> any(c.source.startswith("# TODO") for c in student.cells)
    True
    """
    import jupytext
    import nbformat

    if version not in VERSIONS:
        raise ValueError(f"version must be one of {VERSIONS}, got {version!r}")
    path = Path(source)
    if not path.is_file():
        raise LabUsageError(f"{os.fspath(path)}: no such file")
    try:
        nb = jupytext.read(path)
    except Exception as exc:
        raise LabUsageError(
            f"{os.fspath(path)}: not a lab chapter (cannot read it as a MyST notebook: "
            f"{' '.join(str(exc).split())})"
        ) from None
    index = index if index is not None else BookIndex.from_book(path.parent)
    builder = _Builder(version, Converter(index, path.stem), index, params)
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            builder.markdown(cell.source)
        elif cell.cell_type == "code":
            builder.code(cell.source, dict(cell.metadata))
    try:
        cells = builder.finish()
    except LabError as err:
        raise LabError(f"{os.fspath(path)}: {err}") from None
    if builder.solutions == 0:
        raise LabUsageError(
            f"{os.fspath(path)}: not a lab chapter: it has no solution to hide (no "
            "solution-start/solution-end block and no code cell tagged 'solution')"
        )
    if params is not None and not builder.parameters_seen:
        raise LabError(f"{os.fspath(path)}: no code cell tagged 'parameters' to hold PARAMS")

    out = [nbformat.v4.new_markdown_cell(_BANNER[version])]
    for cell in cells:
        meta = dict(cell.metadata)
        if cell.tags:
            meta["tags"] = list(cell.tags)
        if cell.kind == "code":
            out.append(nbformat.v4.new_code_cell(cell.source, metadata=meta))
        else:
            out.append(nbformat.v4.new_markdown_cell(cell.source, metadata=meta))
    for i, cell in enumerate(out):
        cell["id"] = f"{version}-{i:03d}"
    kernelspec = dict(
        nb.metadata.get("kernelspec")
        or {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}
    )
    notebook = nbformat.v4.new_notebook(
        cells=out,
        metadata={
            "kernelspec": kernelspec,
            "language_info": {"name": "python"},
            "uio_teach": {"source": path.name, "version": version, **(metadata or {})},
        },
    )
    nbformat.validate(notebook)
    return notebook


def find_labs(book_dir: str | os.PathLike[str]) -> list[Path]:
    """The lab chapters of a book folder: ``*lab*.md``, sorted.

    Parameters
    ----------
    book_dir : str or path-like
        The folder of the chapters.

    Returns
    -------
    list of pathlib.Path

    Raises
    ------
    LabUsageError
        ``book_dir`` is not a folder.

    Examples
    --------
    >>> from uio_teach.instructor.labs import default_book_dir, find_labs
    >>> [p.name for p in find_labs(default_book_dir())]
    ['lab_case_study.md', 'lab_missile.md', 'lab_pa9.md']
    """
    folder = Path(book_dir)
    if not folder.is_dir():
        what = "not a folder" if folder.exists() else "no such folder"
        raise LabUsageError(f"{os.fspath(folder)}: {what}")
    return sorted(p for p in folder.glob(LAB_PATTERN) if p.is_file())


@dataclass(frozen=True)
class Lab:
    """One lab of the course: its chapter, its parameter class and its checks.

    Attributes
    ----------
    id : str
        ``"pa9"``, ``"case_study"`` or ``"missile"``.
    source : str
        The file name of its chapter in ``book/``.
    params : type
        Its parameter class (:mod:`uio_teach.instructor.lab_params`).
    check_ids : tuple of str
        The ``check_id`` of every result its check cells produce, in order.

    Examples
    --------
    >>> from uio_teach.instructor.labs import LABS
    >>> LABS["pa9"].check_ids
    ('pa9.design', 'pa9.simulation', 'pa9.plot', 'pa9.piecewise', 'pa9.piecewise_plot')
    """

    id: str
    source: str
    params: type
    check_ids: tuple[str, ...]


def _registry() -> dict[str, Lab]:
    from .lab_params import CaseStudyParams, MissileParams, PA9Params

    return {
        "pa9": Lab(
            "pa9",
            "lab_pa9.md",
            PA9Params,
            ("pa9.design", "pa9.simulation", "pa9.plot", "pa9.piecewise", "pa9.piecewise_plot"),
        ),
        "case_study": Lab(
            "case_study",
            "lab_case_study.md",
            CaseStudyParams,
            (
                "case_study.projection",
                "case_study.lmi",
                "case_study.pole",
                "case_study.simulation",
                "case_study.residual",
                "case_study.plot",
            ),
        ),
        "missile": Lab(
            "missile",
            "lab_missile.md",
            MissileParams,
            (
                "missile.pmo",
                "missile.ginverse",
                "missile.reconstruction",
                "missile.plot",
                "missile.catch_times",
                "missile.noise",
            ),
        ),
    }


LABS: dict[str, Lab] = _registry()
"""The labs of the course, by id (each a :class:`Lab`)."""


def lab_of(source: str | os.PathLike[str]) -> Lab | None:
    """The registered lab whose chapter is ``source`` (by file name), or ``None``.

    Parameters
    ----------
    source : str or path-like

    Returns
    -------
    Lab or None

    Examples
    --------
    >>> from uio_teach.instructor.labs import lab_of
    >>> lab_of("book/lab_missile.md").id
    'missile'
    """
    name = Path(source).name
    return next((lab for lab in LABS.values() if lab.source == name), None)


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
        Time spent.
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
    config: Any = None,
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
    JSON). The same arguments give byte-identical files.

    Parameters
    ----------
    out : str or path-like
        Output folder (created if needed).
    sources : sequence of path-like, optional
        The lab chapters; by default every ``*lab*.md`` of ``book_dir``.
    book_dir : str or path-like, optional
        The book's chapters (for the cross-references and the default
        sources); :func:`~uio_teach.instructor.book.default_book_dir` by default.
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

    Raises
    ------
    LabError
        A lab cannot be converted; a ``LabUsageError`` (a subclass) for a
        missing folder or file, a source that is not a lab, a bad ``groups``
        or numbers that make no fair exercise.
    OSError
        The output folder cannot be written (see
        :func:`uio_teach.instructor.output.prepare_output_dir`).

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
    import nbformat

    from .output import prepare_output_dir

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

    # every job before anything is written: (path, lab, group, params)
    jobs: list[tuple[Path, Lab | None, str, Any]] = []
    for path in paths:
        lab = lab_of(path)
        base = lab.params.from_config(config) if lab is not None else None
        if base is not None and base.problems():
            raise LabUsageError(
                f"the {lab.id} lab cannot be made with these numbers: "  # type: ignore[union-attr]
                + "; ".join(base.problems())
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

    results = []
    folders: dict[Any, Path] = {}
    for i, (path, lab, group, _params, nbs, seconds) in enumerate(built, start=1):
        start = time.perf_counter()
        written = {}
        for version, nb in nbs.items():
            if group:
                where = (lab.id, version)  # type: ignore[union-attr]
                if where not in folders:
                    folders[where] = prepare_output_dir(Path(out) / lab.id / version)  # type: ignore[union-attr]
                target = folders[where] / f"{lab.id}_{group}.ipynb"  # type: ignore[union-attr]
            else:
                if version not in folders:
                    folders[version] = prepare_output_dir(Path(out) / version)
                target = folders[version] / f"{path.stem}.ipynb"
            nbformat.write(nb, target)
            written[version] = target
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
        write_answer_key(Path(out) / ANSWER_KEY, [(lab, g, p) for _, lab, g, p, _, _ in built])
    return results
