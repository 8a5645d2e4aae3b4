"""Sphinx extension: the pages' HTML meets WCAG 2.1 AA where the writers fall short.

* The bibliography: docutils writes each entry of a citation list with the role
  ``doc-biblioentry``, deprecated in DPUB-ARIA 1.1 and not an item of the ``list`` that holds it
  (screen readers announce a list with no items); the entries are written as ``listitem``.

The rest lives in ``_static/`` (added to every page): ``a11y.js`` makes every frame that scrolls
sideways a named tab stop, ``a11y.css`` the link colour and the focus ring. The figures' text
alternatives come from the kernel (``uio_teach.figure_text``), the explorers' from
``uio_teach.explorers.static``.
"""

from __future__ import annotations

from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.writers.html5 import HTML5Translator


def visit_citation(self: HTML5Translator, node: nodes.citation) -> None:
    """A bibliography entry: an item of the citation list (role ``listitem``)."""
    if not isinstance(node.previous_sibling(), type(node)):
        self.body.append('<div role="list" class="citation-list">\n')
    self.body.append(self.starttag(node, "div", classes=[node.tagname], role="listitem"))


def setup(app: Sphinx) -> dict[str, Any]:
    HTML5Translator.visit_citation = visit_citation  # type: ignore[method-assign]
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
