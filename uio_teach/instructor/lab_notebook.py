"""Build the notebooks of one lab chapter: a student version and a solution version.

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
(``--groups``). A source without a solution is not a lab
(:class:`~uio_teach.instructor.lab_registry.LabUsageError`). Writing the
notebooks of a term into a folder is :mod:`uio_teach.instructor.labs`.

Both have empty outputs and pass :func:`nbformat.validate`. The MyST syntax
that Jupyter does not render is rewritten as plain Markdown by
:mod:`uio_teach.instructor.myst`: exercises become quotes titled "Exercise
<number>" (numbered as in the book), ``{eq}`` references become "eq. (3.2)",
``{doc}`` and ``{ref}`` become "chapter 3", ``{cite:p}`` becomes (Author,
year), labelled display equations get a ``\\tag``.

Examples
--------
>>> import tempfile, pathlib
>>> from uio_teach.instructor import lab_notebook
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
...     student = lab_notebook.make_notebook(src, "student")
>>> print(student.cells[-2].source)
# TODO: Exercise 1 (ex-demo-1). Write your code here.
# The cells below use these names; replace None by your answer:
x = None
"""

from __future__ import annotations

import ast
import json
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from ..errors import InputError
from .book import HEADING, TARGET, BookIndex, fence_states
from .lab_registry import LabError, LabUsageError
from .myst import Converter, Directive, tokens

__all__ = [
    "VERSIONS",
    "LAB_PATTERN",
    "SOLUTION_TAG",
    "CHECK_TAG",
    "TODO_TAG",
    "INSTRUCTOR_TAG",
    "PARAMETERS_TAG",
    "find_labs",
    "make_notebook",
    "params_source",
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
    >>> from uio_teach.instructor.lab_notebook import params_source
    >>> print(params_source({"poles": [-1.0, -2.0]}))
    PARAMS = {
        "poles": [-1.0, -2.0]
    }
    """
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
        for line, verbatim in zip(lines, fence_states(lines), strict=True):
            stripped = line.strip()
            target = None if verbatim else TARGET.match(stripped)
            heading = None if verbatim else HEADING.match(line)
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
    >>> from uio_teach.folders import default_book_dir
    >>> from uio_teach.instructor.lab_notebook import find_labs, make_notebook
    >>> lab = find_labs(default_book_dir())[0]
    >>> student = make_notebook(lab, "student")
    >>> any("solution" in c.metadata.get("tags", []) for c in student.cells)
    False
    >>> any(c.source.startswith("# TODO") for c in student.cells)
    True
    """
    # deferred on purpose: jupytext and nbformat come with the optional ``instructor`` extra
    import jupytext
    import nbformat

    if version not in VERSIONS:
        raise InputError(f"version must be one of {VERSIONS}, got {version!r}")
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
    >>> from uio_teach.folders import default_book_dir
    >>> from uio_teach.instructor.lab_notebook import find_labs
    >>> [p.name for p in find_labs(default_book_dir())]
    ['lab_case_study.md', 'lab_missile.md', 'lab_pa9.md']
    """
    folder = Path(book_dir)
    if not folder.is_dir():
        what = "not a folder" if folder.exists() else "no such folder"
        raise LabUsageError(f"{os.fspath(folder)}: {what}")
    return sorted(p for p in folder.glob(LAB_PATTERN) if p.is_file())
