"""Every chapter of the book runs from top to bottom.

Each MyST Markdown notebook in ``book/`` (a ``.md`` file whose front matter has a ``kernelspec``)
is read with myst-nb and executed with nbclient in ``book/``, as the book build does. One test per
chapter, named after the chapter file, so a failing cell points at its chapter.
"""

from __future__ import annotations

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
