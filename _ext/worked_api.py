"""The API page's section on the worked examples, written from the registry.

The directive ``worked-examples`` documents the module of every worked example of
:data:`uio_teach.worked.WORKED`, in the book's order: its docstring, then each name of its
``__all__`` (a class with its public members, a value without printing it). A new worked
example is one new module of :mod:`uio_teach.worked`; the API page lists it with no edit.
"""

from __future__ import annotations

import importlib
import inspect
from typing import Any

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective


def worked_modules() -> dict[str, str]:
    """The modules of the registry's worked examples and their titles, in the book's order."""
    from uio_teach.worked import WORKED

    modules: dict[str, str] = {}
    for entry in WORKED.values():
        modules.setdefault(entry.module, entry.title)
    return modules


def module_lines(name: str, title: str = "") -> list[str]:
    """The reStructuredText of one worked example's module (under a rubric: its title)."""
    module = importlib.import_module(name)
    lines = [f".. rubric:: {title}", ""] if title else []
    lines += [f".. automodule:: {name}", "   :no-members:", ""]
    for member in getattr(module, "__all__", ()):
        obj = getattr(module, member)
        if inspect.isclass(obj):
            lines += [f".. autoclass:: {name}.{member}", "   :members:", ""]
        elif inspect.isfunction(obj):
            lines += [f".. autofunction:: {name}.{member}", ""]
        else:
            lines += [f".. autodata:: {name}.{member}", "   :no-value:", ""]
    return lines


class WorkedExamples(SphinxDirective):
    """``worked-examples``: every worked example's module, from the registry."""

    has_content = False

    def run(self) -> list[nodes.Node]:
        lines: list[str] = []
        for name, title in worked_modules().items():
            lines += module_lines(name, title)
        container = nodes.container()
        self.state.nested_parse(StringList(lines, source="worked-examples"), 0, container)
        return container.children


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("worked-examples", WorkedExamples)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
