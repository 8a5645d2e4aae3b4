"""Every chapter of the book runs from top to bottom.

Each MyST Markdown notebook in ``book/`` (a ``.md`` file whose front matter has a ``kernelspec``)
is read with myst-nb and executed with nbclient in ``book/``, as the book build does. One test per
chapter, named after the chapter file, so a failing cell points at its chapter.
"""

from __future__ import annotations

import re
from pathlib import Path

import nbclient
import pytest
import yaml
from myst_nb.core.read import read_myst_markdown_notebook
from nbclient.exceptions import CellExecutionError

BOOK = Path(__file__).resolve().parents[1] / "book"
CELL_TIMEOUT = 300  # seconds, as `execute.timeout` in _config.yml


def _front_matter(text: str) -> dict:
    if not text.startswith("---"):
        return {}
    end = text.find("\n---", 3)
    if end < 0:
        return {}
    data = yaml.safe_load(text[3:end])
    return data if isinstance(data, dict) else {}


def chapter_notebooks(book: Path = BOOK) -> list[Path]:
    """The ``.md`` files of ``book`` that are notebooks (they declare a kernelspec)."""
    return sorted(
        path
        for path in book.rglob("*.md")
        if ".ipynb_checkpoints" not in path.parts
        and "kernelspec" in _front_matter(path.read_text(encoding="utf-8"))
    )


CHAPTERS = chapter_notebooks()


def test_the_book_has_chapters() -> None:
    assert CHAPTERS, f"no MyST notebook (front matter with a kernelspec) found in {BOOK}"


@pytest.mark.book
@pytest.mark.parametrize(
    "chapter", CHAPTERS, ids=[str(path.relative_to(BOOK)) for path in CHAPTERS]
)
def test_chapter_runs(chapter: Path) -> None:
    notebook = read_myst_markdown_notebook(chapter.read_text(encoding="utf-8"), path=chapter)
    kernel = notebook.metadata.get("kernelspec", {}).get("name", "python3")
    client = nbclient.NotebookClient(
        notebook,
        timeout=CELL_TIMEOUT,
        kernel_name=kernel,
        resources={"metadata": {"path": str(chapter.parent)}},
    )
    try:
        client.execute()
    except CellExecutionError as error:
        pytest.fail(f"{chapter.relative_to(BOOK)}: a cell failed\n{error}", pytrace=False)


# --- the reader sees the computation, not the test ----------------------------------------------

MAX_VISIBLE_ASSERTS = 10
HIDDEN_TAGS = {"remove-cell", "remove-input", "hide-input", "hide-cell"}


def visible_assert_lines(chapter: Path) -> list[str]:
    """Lines with ``assert`` in the code cells of ``chapter`` that the rendered page shows."""
    notebook = read_myst_markdown_notebook(chapter.read_text(encoding="utf-8"), path=chapter)
    found = []
    for cell in notebook.cells:
        if cell.cell_type != "code" or HIDDEN_TAGS & set(cell.metadata.get("tags", [])):
            continue
        found += [line.strip() for line in cell.source.splitlines() if "assert" in line]
    return found


def test_few_visible_asserts() -> None:
    counts = {path.name: visible_assert_lines(path) for path in CHAPTERS}
    total = sum(len(lines) for lines in counts.values())
    detail = {name: len(lines) for name, lines in counts.items() if lines}
    assert total <= MAX_VISIBLE_ASSERTS, (
        f"{total} visible assert lines (at most {MAX_VISIBLE_ASSERTS}): {detail}; move checks"
        " that do not teach into a hidden cell (tags: [remove-cell]) or into the tests"
    )


def test_hidden_checks_still_run() -> None:
    """Hidden cells must be removed from the page, not from execution (no skip-execution)."""
    for chapter in CHAPTERS:
        notebook = read_myst_markdown_notebook(chapter.read_text(encoding="utf-8"), path=chapter)
        skipped = [
            cell.source.splitlines()[0]
            for cell in notebook.cells
            if cell.cell_type == "code"
            and "skip-execution" in cell.metadata.get("tags", [])
            and "assert" in cell.source
        ]
        assert not skipped, f"{chapter.name}: checks that never run: {skipped}"


# --- every chapter opens with its goals and closes with a summary and exercises -----------------


def course_chapters() -> list[Path]:
    """The chapters of the numbered part of ``_toc.yml``, labs excepted, in reading order."""
    toc = yaml.safe_load((BOOK.parent / "_toc.yml").read_text(encoding="utf-8"))
    part = next(p for p in toc["parts"] if p.get("numbered"))
    files = [BOOK.parent / f"{entry['file']}.md" for entry in part["chapters"]]
    return [path for path in files if not path.name.startswith("lab_")]


COURSE_CHAPTERS = course_chapters()


@pytest.mark.parametrize("chapter", COURSE_CHAPTERS, ids=[path.name for path in COURSE_CHAPTERS])
def test_chapter_structure(chapter: Path) -> None:
    text = chapter.read_text(encoding="utf-8")
    opening = text.find("```{admonition} In this chapter")
    assert opening >= 0, f"{chapter.name}: no 'In this chapter' box under the title"
    box = text[opening : text.find("```", opening + 3)]
    for phrase in ("You will be able to", "It assumes"):
        assert phrase in box, f"{chapter.name}: the opening box does not say {phrase!r}"
    summary, exercises = text.find("\n## Summary\n"), text.find("\n## Exercises\n")
    assert 0 < summary < exercises, f"{chapter.name}: no '## Summary' followed by '## Exercises'"
    assert "```{exercise}" in text[exercises:], f"{chapter.name}: no exercise"
    starts = re.findall(r"```\{solution-start\}[^\n]*\n(:class: [^\n]*)?", text[exercises:])
    assert starts, f"{chapter.name}: no solution"
    unfolded = [opts for opts in starts if "dropdown" not in opts]
    assert not unfolded, f"{chapter.name}: every solution must be folded (:class: dropdown)"


def test_no_hard_coded_chapter_or_equation_numbers() -> None:
    """Numbers follow the table of contents only through {numref}, {eq}, {ref} and {doc} roles."""
    pattern = re.compile(r"\b[Cc]hapters? \d|(?<![\w`])\(\d+\.\d+\)")
    found = []
    for page in sorted(BOOK.glob("*.md")):
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            if pattern.search(line):
                found.append(f"{page.name}:{number}: {line.strip()}")
    assert not found, "hard-coded chapter or equation numbers:\n" + "\n".join(found)


# --- each chapter as a notebook (the book's _ext/chapter_notebooks.py) --------------------------


def test_chapter_converts_to_a_notebook_without_outputs(tmp_path: Path) -> None:
    import importlib.util

    import nbformat

    spec = importlib.util.spec_from_file_location(
        "chapter_notebooks", BOOK.parent / "_ext" / "chapter_notebooks.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    chapter = BOOK / "case_study.md"
    target = tmp_path / "case_study.ipynb"
    module.write_notebook(chapter, target)
    notebook = nbformat.read(target, as_version=4)
    nbformat.validate(notebook)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    source = read_myst_markdown_notebook(chapter.read_text(encoding="utf-8"), path=chapter)
    assert len(code) == sum(cell.cell_type == "code" for cell in source.cells)
    assert all(not cell.outputs and cell.execution_count is None for cell in code)
    # the checks hidden in the book are kept, and still marked as such
    assert any("remove-cell" in cell.metadata.get("tags", []) for cell in code)
    assert notebook.metadata["kernelspec"]["name"] == "python3"
    assert "jupytext" not in notebook.metadata
