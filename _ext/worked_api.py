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


def tutors_only(obj: object) -> bool:
    """A lab's parameter class (variants, the answer key): instructor tooling."""
    from uio_teach.lab_params import LabParams

    return inspect.isclass(obj) and issubclass(obj, LabParams)


def module_lines(name: str, title: str = "", *, student: bool = False) -> list[str]:
    """The reStructuredText of one worked example's module (under a rubric: its title); for
    a student edition without the lab's parameter class."""
    module = importlib.import_module(name)
    lines = [f".. rubric:: {title}", ""] if title else []
    lines += [f".. automodule:: {name}", "   :no-members:", ""]
    for member in getattr(module, "__all__", ()):
        obj = getattr(module, member)
        if student and tutors_only(obj):
            continue
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
        from editions import LIKE_STUDENT, edition_of, leave_out_objects

        student = edition_of(self.config) in LIKE_STUDENT
        lines: list[str] = []
        for name, title in worked_modules().items():
            lines += module_lines(name, title, student=student)
            if student:  # references to the classes left out read as their names
                module = importlib.import_module(name)
                left = [
                    m for m in getattr(module, "__all__", ()) if tutors_only(getattr(module, m))
                ]
                leave_out_objects(self.env, self.env.docname, {f"{name}.{m}" for m in left})
        container = nodes.container()
        self.state.nested_parse(StringList(lines, source="worked-examples"), 0, container)
        return container.children


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("worked-examples", WorkedExamples)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
