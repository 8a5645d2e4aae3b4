"""Two editions of the book from one source: the student edition (default) and the instructor's.

The lab chapters carry their solutions (``{solution-start}`` ... ``{solution-end}`` blocks of
sphinx-exercise, code cells tagged ``solution``) and notes for the tutors (a section headed
"Instructor notes", code cells tagged ``instructor``). Every chapter is executed whole in both
editions, solutions included, so the checks and the figures after an exercise still run; only
what is rendered differs:

* **student** (``make book``, the default): the solutions and the cells tagged ``solution`` or
  ``instructor`` are left out of the pages (and so out of the search index), an "Instructor
  notes" section keeps its title and says where its notes are, the pages' MyST sources are not
  copied into the site, and a lab chapter's notebook link gives the student notebook
  (``# TODO`` cells, as ``uio-teach labs`` writes it).
* **instructor** (``make book-instructor``, that is ``UIO_TEACH_EDITION=instructor`` in the
  environment of ``jupyter-book build``): everything, as written.

The edition is read from the environment variable :data:`EDITION_VAR` when the build starts and
is the Sphinx setting ``uio_teach_edition``; changing it rebuilds every page.
"""

from __future__ import annotations

import os
from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.config import Config
from sphinx.transforms import SphinxTransform
from sphinx.util import logging
from sphinx_exercise.nodes import solution_node

EDITION_VAR = "UIO_TEACH_EDITION"
EDITIONS = ("student", "instructor")
HIDDEN_TAGS = ("solution", "instructor")  # code cells with these tags are not in the student pages
NOTE = (
    "The notes for the tutors of this lab (what the groups should find, how to run the lab, "
    "the common mistakes) are in the instructor edition of the book: "
)
COMMAND = "make book-instructor"

logger = logging.getLogger(__name__)


def edition_of(config: Config) -> str:
    """The edition this build makes: ``"student"`` or ``"instructor"``."""
    return config.uio_teach_edition


def is_instructor_section(section: nodes.section) -> bool:
    """A section of notes for the tutors: headed "Instructor notes" or labelled ``*-instructor``."""
    title = section.next_node(nodes.title)
    heading = title.astext().strip().lower() if title is not None else ""
    labels = " ".join(section.get("ids", []) + section.get("names", []))
    return heading.startswith("instructor") or "-instructor" in labels


class StudentEdition(SphinxTransform):
    """Leave the solutions and the tutors' notes out of the student edition's pages.

    It runs after sphinx-exercise has merged each ``solution-start`` ... ``solution-end`` block
    into one solution node (priority 10), and before the references are resolved.
    """

    default_priority = 15

    def apply(self, **kwargs: Any) -> None:
        if edition_of(self.config) != "student":
            return
        for node in list(self.document.findall(solution_node)):
            node.parent.remove(node)
        for node in list(self.document.findall(nodes.container)):
            classes = node.get("classes", [])
            if node.parent is not None and any(f"tag_{tag}" in classes for tag in HIDDEN_TAGS):
                node.parent.remove(node)
        for section in list(self.document.findall(nodes.section)):
            if not is_instructor_section(section):
                continue
            title = section.next_node(nodes.title)
            for child in list(section.children):
                if child is not title:
                    section.remove(child)
            note = nodes.paragraph(NOTE, NOTE)
            note += nodes.literal(COMMAND, COMMAND)
            note += nodes.Text(".")
            section += note


def _check_edition(app: Sphinx, config: Config) -> None:
    if config.uio_teach_edition not in EDITIONS:
        raise ValueError(
            f"{EDITION_VAR} must be one of {', '.join(EDITIONS)}, got {config.uio_teach_edition!r}"
        )
    if config.uio_teach_edition == "student":
        # the pages' sources hold the solutions: not copied into the site, no "show source" link
        config.html_copy_source = False
        config.html_show_sourcelink = False
    logger.info(f"[editions] building the {config.uio_teach_edition} edition of the book")


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_config_value(
        "uio_teach_edition", os.environ.get(EDITION_VAR, "student").strip().lower(), "env"
    )
    app.connect("config-inited", _check_edition)
    app.add_transform(StudentEdition)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
