"""Every chapter of the book as a Jupyter notebook (.ipynb), for machines without jupytext.

When a page written from a MyST Markdown notebook (a ``.md`` source whose front matter declares a
``kernelspec``) is rendered to HTML, its source is converted with jupytext into
``_notebooks/<name>.ipynb`` in the output folder, with no outputs, and a link to that file is put
under the page title. The root page (the landing page) is not a chapter and gets no link.

In the student edition of the book (``_ext/editions.py``) a lab chapter's notebook is its student
version, as ``uio-teach labs`` writes it (``# TODO`` cells in place of the solutions, no notes for
the tutors); the instructor edition links the whole chapter. A page that the student edition
reduces to a stub (the instructors' page) gets no notebook there.

The theme's download menu (top right of each page) offers the same notebook as ``.ipynb``; its
``.md`` entry links the page's source, which only the instructor edition copies into the site
(``_sources/``), so the student edition's menu has no ``.md`` entry.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import jupytext
import nbformat
from editions import is_stub
from sphinx.application import Sphinx

from uio_teach.instructor.book import split_front_matter
from uio_teach.instructor.lab_notebook import make_notebook
from uio_teach.instructor.lab_registry import LabUsageError

NOTEBOOK_DIR = "_notebooks"
LINK_TEXT = "Download this chapter as a notebook (.ipynb)"


def chapter_source(app: Sphinx, pagename: str) -> Path | None:
    """The MyST notebook behind ``pagename``, or None when the page is not a chapter."""
    if pagename == app.config.root_doc or pagename not in app.env.found_docs:
        return None
    source = Path(app.env.doc2path(pagename))
    if source.suffix != ".md" or not source.is_file():
        return None
    if "kernelspec" not in split_front_matter(source.read_text(encoding="utf-8"))[0]:
        return None
    return source


def write_notebook(source: Path, target: Path, edition: str = "instructor") -> None:
    """Convert a MyST notebook to .ipynb with every output and execution count cleared.

    In the ``"student"`` edition a lab chapter becomes its student notebook.
    """
    if edition in ("student", "selfstudy"):
        try:
            notebook = make_notebook(source, "student")
        except LabUsageError:  # not a lab: no solution to leave out
            pass
        else:
            target.parent.mkdir(parents=True, exist_ok=True)
            nbformat.write(notebook, target)
            return
    notebook = jupytext.read(source)
    notebook.metadata.pop("jupytext", None)
    for cell in notebook.cells:
        if cell.cell_type == "code":
            cell.outputs = []
            cell.execution_count = None
    nbformat.validate(notebook)
    target.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(notebook, target)


def add_notebook(
    app: Sphinx, pagename: str, templatename: str, context: dict[str, Any], doctree: Any
) -> None:
    source = chapter_source(app, pagename)
    if source is None or app.builder.format != "html" or "body" not in context:
        return
    edition = getattr(app.config, "uio_teach_edition", "instructor")
    if edition in ("student", "selfstudy") and is_stub(doctree):
        return
    relative = f"{NOTEBOOK_DIR}/{Path(pagename).name}.ipynb"
    write_notebook(source, Path(app.outdir) / relative, edition)
    href = context["pathto"](relative, 1)
    context["uio_teach_notebook"] = href
    link = (
        '<p class="chapter-notebook"><a class="reference download" '
        f'href="{href}" download>{LINK_TEXT}</a></p>'
    )
    body = context["body"]
    end_of_title = body.find("</h1>")
    if end_of_title < 0:
        context["body"] = link + body
    else:
        cut = end_of_title + len("</h1>")
        context["body"] = body[:cut] + link + body[cut:]


def fix_download_menu(
    app: Sphinx, pagename: str, templatename: str, context: dict[str, Any], doctree: Any
) -> None:
    """The theme's download menu: the chapter's notebook, and the ``.md`` source only if copied.

    Runs after the theme has made the menu (its handler has priority 501).
    """
    student = getattr(app.config, "uio_teach_edition", "instructor") in ("student", "selfstudy")
    notebook = context.get("uio_teach_notebook")
    for group in context.get("header_buttons", []):
        if group.get("label") != "download-buttons":
            continue
        kept = []
        for button in group.get("buttons", []):
            label = button.get("label")
            if label == "download-notebook-button":
                continue  # replaced by the chapter's own notebook below
            if label == "download-source-button" and (student or not app.config.html_copy_source):
                continue
            kept.append(button)
        if notebook:
            kept.insert(
                0,
                {
                    "type": "link",
                    "url": notebook,
                    "text": ".ipynb",
                    "icon": "fas fa-code",
                    "tooltip": "Download this chapter as a notebook",
                    "label": "download-notebook-button",
                },
            )
        group["buttons"] = kept


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("html-page-context", add_notebook)
    app.connect("html-page-context", fix_download_menu, priority=600)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
