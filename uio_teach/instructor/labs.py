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
  solution made of prose only becomes a markdown "Your answer" cell.
* the **solution** version: complete, solution cells tagged ``solution``,
  check cells ``check``, the instructor notes kept (tagged ``instructor``).

Both have empty outputs and pass :func:`nbformat.validate`. The MyST syntax
that Jupyter does not render is rewritten as plain Markdown: exercises become
quotes titled "Exercise <number>" (numbered as in the book), ``{eq}`` references
become equation numbers, ``{ref}`` and ``{doc}`` become titles, ``{cite:p}``
becomes (Author, year), labelled display equations get a ``\\tag``.

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
    _LABELLED_MATH,
    _TARGET,
    BookIndex,
    _fence_states,
    default_book_dir,
)

__all__ = [
    "VERSIONS",
    "BookIndex",
    "LabResult",
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

Version = Literal["student", "solution"]

_ROLE = re.compile(r"\{(?P<name>[\w:.-]+)\}`(?P<content>[^`]+)`")
_CHECK_CALL = re.compile(r"\bchecks\.\w+\s*\(")
_ADMONITIONS = {
    "note",
    "tip",
    "hint",
    "important",
    "warning",
    "caution",
    "attention",
    "danger",
    "error",
    "seealso",
}


class LabError(ValueError):
    """A lab chapter that cannot be converted (one-line message naming the file)."""


# MyST Markdown -> Jupyter Markdown ---------------------------------------------------------------


@dataclass
class _Directive:
    name: str
    arg: str
    options: dict[str, str]
    body: str


def _tokens(text: str) -> list[str | _Directive]:
    """Split Markdown into plain text and top-level directives, as jupytext's MyST parser does.

    The block parser of :mod:`jupytext.myst` (markdown-it-py with the MyST plugins, and the
    colon fence of mdit-py-plugins) finds the directives; jupytext reads their options.
    """
    from jupytext.myst import get_parser, parse_directive_options
    from mdit_py_plugins.colon_fence import colon_fence_plugin

    lines = text.split("\n")
    out: list[str | _Directive] = []
    done = 0
    for token in get_parser().use(colon_fence_plugin).parse(text):
        info = token.info.strip()
        if token.level or token.type not in ("fence", "colon_fence") or not info.startswith("{"):
            continue
        head = re.match(r"^\{(?P<name>[\w:.-]+)\}[ \t]*(?P<arg>.*)$", info)
        if head is None:
            continue
        start, end = token.map
        if start > done:
            out.append("\n".join(lines[done:start]))
        body, options = parse_directive_options(token.content, f"line {start + 1}: ")
        options = {str(k): "" if v is None else str(v) for k, v in options.items()}
        out.append(_Directive(head["name"], head["arg"], options, "\n".join(body).strip("\n")))
        done = end
    if done < len(lines):
        out.append("\n".join(lines[done:]))
    return [t for t in out if not isinstance(t, str) or t.strip("\n")] or [text]


def _quote(text: str) -> str:
    return "\n".join(f"> {line}" if line.strip() else ">" for line in text.split("\n"))


class _Converter:
    """MyST roles, labels and labelled equations of one page, written as plain Markdown."""

    def __init__(self, index: BookIndex, stem: str) -> None:
        self.index = index
        self.stem = stem

    def role(self, m: re.Match[str]) -> str:
        name, content = m.group("name"), m.group("content")
        explicit = re.match(r"^(?P<text>.+?)\s*<(?P<target>[^>]+)>$", content, re.DOTALL)
        target = explicit.group("target") if explicit else content
        if name.startswith("cite"):
            return self.index.cite("t" if name.endswith(":t") else "p", content)
        if name == "math":
            return f"${content}$"
        if name in ("sub", "sup"):
            return f"<{name}>{content}</{name}>"
        if explicit:
            return explicit.group("text")
        if name == "doc":
            return self.index.page(Path(target).stem, self.stem)
        if name == "eq":
            if target in self.index.equations:
                stem, k = self.index.equations[target]
                where = "" if stem == self.stem else f" of {self.index.page(stem, self.stem)}"
                return f"({self.index.number(stem, k)}){where}"
            return f"({target})"
        if name in ("ref", "numref"):
            if target in self.index.exercises:
                stem, k = self.index.exercises[target]
                return f"Exercise {self.index.number(stem, k)}"
            if target in self.index.sections:
                stem, title = self.index.sections[target]
                where = "" if stem == self.stem else f" in {self.index.page(stem, self.stem)}"
                return f"*{title}*{where}"
            return target
        return content

    def inline(self, text: str) -> str:
        def tag(m: re.Match[str]) -> str:
            label = m.group("label")
            if label in self.index.equations:
                stem, k = self.index.equations[label]
                number = self.index.number(stem, k)
            else:
                number = label
            return f"$${m.group('body').rstrip()} \\tag{{{number}}}$$"

        text = _LABELLED_MATH.sub(tag, text)
        lines = [ln for ln in text.split("\n") if not _TARGET.match(ln.strip())]
        lines = [ln for ln in lines if not re.match(r"^%( |$)", ln)]  # MyST comments
        text = _ROLE.sub(self.role, "\n".join(lines))
        return re.sub(r"\n{3,}", "\n\n", text).strip("\n")

    def directive(self, d: _Directive, exercise_number: str | None = None) -> str:
        body = self.markdown(d.body)
        if d.name == "exercise":
            title = f"**Exercise {exercise_number}**" + (f" ({d.arg})" if d.arg else "")
            return _quote(f"{title}\n\n{body}")
        if d.name in _ADMONITIONS or d.name == "admonition":
            title = d.arg if d.name == "admonition" and d.arg else d.name.capitalize()
            return _quote(f"**{title}.** {body}")
        if d.name == "math":
            return f"$$\n{d.body}\n$$"
        if d.name in ("code", "code-block", "sourcecode"):
            return f"```{d.arg}\n{d.body}\n```"
        if d.name in ("figure", "image"):
            return f"*Figure: {body or d.arg}*"
        return body

    def markdown(self, text: str) -> str:
        parts = []
        for token in _tokens(text):
            parts.append(self.inline(token) if isinstance(token, str) else self.directive(token))
        return "\n\n".join(p for p in parts if p.strip())


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
    def __init__(self, version: Version, converter: _Converter, index: BookIndex) -> None:
        self.version = version
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
        for token in _tokens(text):
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

    def _directive(self, d: _Directive) -> None:
        if d.name == "solution-start":
            self.flush()
            self.solution = d.arg.strip() or self.exercise[0]
            self.solution_code = []
            label, number = self._exercise_label(self.solution)
            self._emit_md(f"**Solution of Exercise {number}**")
            return
        if d.name == "solution-end":
            self.flush()
            if self.student and self.solution is not None:
                self._todo(self.solution, self.solution_code)
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
        if is_solution:
            if self.student:
                if self.solution is not None:
                    self.solution_code.append(source)
                else:
                    self._todo(self.exercise[0], [source])
                return
            if SOLUTION_TAG not in tags:
                tags.append(SOLUTION_TAG)
        elif _CHECK_CALL.search(source) and CHECK_TAG not in tags:
            tags.append(CHECK_TAG)
        if self.instructor_level is not None and INSTRUCTOR_TAG not in tags:
            tags.append(INSTRUCTOR_TAG)
        self.cells.append(_Cell("code", source, tags, meta))

    def _todo(self, label: str | None, code: list[str]) -> None:
        label, number = self._exercise_label(label)
        name = (f"Exercise {number}" if number else "") + (f" ({label})" if label else "")
        name = name.strip() or "your code"
        if code:
            self.cells.append(
                _Cell("code", "", [TODO_TAG], solution_code=code, todo_header=f"# TODO: {name}.")
            )
        else:
            self.cells.append(_Cell("markdown", f"**Your answer to {name}:**\n\n*...*", [TODO_TAG]))

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
    source: str | os.PathLike[str], version: Version, *, index: BookIndex | None = None
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

    Returns
    -------
    nbformat.NotebookNode
        A valid nbformat 4 notebook.

    Raises
    ------
    LabError
        The source cannot be read, or a solution block is not closed.

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
    try:
        nb = jupytext.read(path)
    except Exception as exc:
        raise LabError(f"{os.fspath(path)}: cannot read it as a notebook: {exc}") from None
    index = index if index is not None else BookIndex.from_book(path.parent)
    builder = _Builder(version, _Converter(index, path.stem), index)
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            builder.markdown(cell.source)
        elif cell.cell_type == "code":
            builder.code(cell.source, dict(cell.metadata))
    try:
        cells = builder.finish()
    except LabError as err:
        raise LabError(f"{os.fspath(path)}: {err}") from None

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
            "uio_teach": {"source": path.name, "version": version},
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

    Examples
    --------
    >>> from uio_teach.instructor.labs import default_book_dir, find_labs
    >>> [p.name for p in find_labs(default_book_dir())][:1]
    ['lab_pa9.md']
    """
    return sorted(p for p in Path(book_dir).glob(LAB_PATTERN) if p.is_file())


@dataclass(frozen=True)
class LabResult:
    """The two notebooks written for one lab chapter.

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


def write_labs(
    out: str | os.PathLike[str],
    sources: Sequence[str | os.PathLike[str]] | None = None,
    *,
    book_dir: str | os.PathLike[str] | None = None,
    progress: Callable[[int, int, LabResult], None] | None = None,
) -> list[LabResult]:
    """Write ``out/student/<lab>.ipynb`` and ``out/solution/<lab>.ipynb`` for every lab.

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
        Called as ``progress(index, total, result)`` after each lab.

    Returns
    -------
    list of LabResult

    Raises
    ------
    LabError
        No lab chapter found, or one cannot be converted.
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
    if not paths:
        raise LabError(f"no lab chapter ({LAB_PATTERN}) in {os.fspath(book)}")
    for path in paths:
        if not path.is_file():
            raise LabError(f"{os.fspath(path)}: no such file")
    folders = {v: prepare_output_dir(Path(out) / v) for v in VERSIONS}
    index = BookIndex.from_book(book)
    results = []
    for i, path in enumerate(paths, start=1):
        start = time.perf_counter()
        written = {}
        todo = 0
        for version in VERSIONS:
            nb = make_notebook(path, version, index=index)
            if version == "student":
                todo = sum(TODO_TAG in c.metadata.get("tags", []) for c in nb.cells)
            target = folders[version] / f"{path.stem}.ipynb"
            nbformat.write(nb, target)
            written[version] = target
        result = LabResult(
            path, written["student"], written["solution"], todo, time.perf_counter() - start
        )
        results.append(result)
        if progress is not None:
            progress(i, len(paths), result)
    return results
