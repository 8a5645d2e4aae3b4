"""Two editions of the book from one source: the student edition (default) and the instructor's.

The lab chapters carry their solutions (``{solution-start}`` ... ``{solution-end}`` blocks of
sphinx-exercise, code cells tagged ``solution``) and notes for the tutors (a section headed
"Instructor notes", code cells tagged ``instructor``). Every chapter is executed whole in both
editions, solutions included, so the checks and the figures after an exercise still run; only
what is rendered differs:

* **student** (``make book``, the default): the solutions and the cells tagged ``solution`` or
  ``instructor`` are left out of the pages (and so out of the search index). On a lab page (one
  with cells tagged ``solution``) each solution gives way to the starting code of the student
  notebook (its ``# TODO`` cell), and every code cell after the first solution is shown unrun,
  with a note: its output (a check's verdicts, a figure) was computed from the model solution. A
  section of notes for the tutors is left out whole, its heading with it, on every page; a page
  that is one such section (the instructors' page, which the table of contents lists) becomes a
  stub with no notebook. The pages' MyST sources
  are not copied into the site, and a lab chapter's notebook link gives the student notebook
  (``# TODO`` cells, as ``uio-teach labs`` writes it). No student page names the other edition.
* **instructor** (``make book-instructor``, that is ``UIO_TEACH_EDITION=instructor`` in the
  environment of ``jupyter-book build``): everything, as written.
* **selfstudy** (``make book-selfstudy``): the student edition for those who learn alone. Each
  solution is still preceded by the starting code, and follows it folded, behind "Show a
  worked solution (after you tried)" (a ``<details>`` element: closed until the reader opens
  it); the tutors' notes are left out as in the student edition.

The edition is read from the environment variable :data:`EDITION_VAR` when the build starts and
is the Sphinx setting ``uio_teach_edition``; changing it rebuilds every page.
"""

from __future__ import annotations

import os
import re
from typing import Any

from docutils import nodes
from sphinx import addnodes
from sphinx.application import Sphinx
from sphinx.config import Config
from sphinx.transforms import SphinxTransform
from sphinx.util import logging
from sphinx_exercise.nodes import solution_node

from uio_teach.instructor.lab_notebook import make_notebook
from uio_teach.instructor.lab_registry import LabUsageError

EDITION_VAR = "UIO_TEACH_EDITION"
EDITIONS = ("student", "instructor", "selfstudy")
LIKE_STUDENT = ("student", "selfstudy")  # the editions that leave the tutors' notes out
FOLD_SUMMARY = "Show a worked solution (after you tried)"
FOLD_CLASS = "selfstudy-solution"
HIDDEN_TAGS = ("solution", "instructor")  # code cells with these tags are not in the student pages
STUB_NOTE = (
    "This page is for those who teach the course: how to prepare a term, regenerate the "
    "figures, hand out the lab notebooks and grade the notebooks handed in."
)
UNRUN_NOTE = (
    "Run this cell in your notebook once your own code above it is written: its output "
    "depends on your work, so it is not shown here."
)
UNRUN_CLASS = "student-unrun"
STARTER_NOTE = "Your code goes here; the lab notebook starts you with:"
STARTER_CLASS = "student-starter"
STUB_CLASS = "student-stub"  # the section of a page that is a stub in the student edition

logger = logging.getLogger(__name__)


def edition_of(config: Config) -> str:
    """The edition this build makes: ``"student"`` or ``"instructor"``."""
    return config.uio_teach_edition


def trailing_labels(section: nodes.section) -> list[nodes.target]:
    """The labels that close ``section`` (at the end of its last descendant), in page order:
    MyST puts there a ``(label)=`` written before the next heading."""
    found: list[nodes.target] = []
    node: nodes.Node = section
    while isinstance(node, nodes.section) and node.children:
        tail = list(node.children)
        k = len(tail)
        while k > 0 and _is_label(tail[k - 1]):
            k -= 1
        found = tail[k:] + found
        if k < len(tail):
            break
        node = tail[-1]
    return found


def leave_out_objects(env: Any, docname: str, anchors: set[str]) -> None:
    """Record ``anchors`` as objects this edition of page ``docname`` leaves out: references
    to them read as their names (the same as for a tutors' section left out)."""
    _dropped_objects(env).setdefault(docname, set()).update(anchors)


def labels_before(section: nodes.section) -> list[str]:
    """The names of the labels written right before ``section``'s heading: MyST leaves a
    ``(label)=`` line as a target in front of the section, or as the last child of the section
    before it (the label reaches the section's own ids only later, when references resolve)."""
    parent = section.parent
    if parent is None:
        return []
    names: list[str] = []
    k = parent.index(section) - 1
    while k >= 0 and _is_label(parent.children[k]):
        names += parent.children[k].get("names", []) + parent.children[k].get("ids", [])
        k -= 1
    before = parent.children[k] if k >= 0 else None
    if isinstance(before, nodes.section):
        for label in trailing_labels(before):
            names += label.get("names", []) + label.get("ids", [])
    return names


def is_instructor_section(section: nodes.section) -> bool:
    """A section of notes for the tutors: headed "Instructor notes" or labelled ``*-instructor``
    (the label written on the section or right before its heading)."""
    title = section.next_node(nodes.title)
    heading = title.astext().strip().lower() if title is not None else ""
    labels = " ".join(section.get("ids", []) + section.get("names", []) + labels_before(section))
    return heading.startswith("instructor") or "-instructor" in labels


def _is_code_cell(node: nodes.Node) -> bool:
    return isinstance(node, nodes.container) and "cell" in node.get("classes", [])


def _tags(node: nodes.Element) -> list[str]:
    return [c[4:] for c in node.get("classes", []) if c.startswith("tag_")]


_TODO = re.compile(r"^# TODO: Exercise [^(\n]*\(([^)\n]+)\)")


def starters(source: str) -> dict[str, str]:
    """The starting code of each exercise of a lab chapter, by exercise label.

    It is the ``# TODO`` cell that the student notebook (``uio-teach labs``) has in place of the
    solution; empty for a page that is not a lab chapter.
    """
    try:
        notebook = make_notebook(source, "student")
    except LabUsageError:
        return {}
    out = {}
    for cell in notebook.cells:
        m = _TODO.match(cell.source) if cell.cell_type == "code" else None
        if m:
            out[m.group(1)] = cell.source
    return out


def _outputs(cell: nodes.Element) -> list[nodes.Element]:
    return [
        child
        for child in cell.children
        if isinstance(child, nodes.container) and "cell_output" in child.get("classes", [])
    ]


class StudentEdition(SphinxTransform):
    """Leave the solutions and the tutors' notes out of the student edition's pages.

    It runs after sphinx-exercise has merged each ``solution-start`` ... ``solution-end`` block
    into one solution node (priority 10), and before the references are resolved.
    """

    default_priority = 15

    def _attached(self, node: nodes.Node) -> bool:
        """Still in the page (a removed node keeps its ``parent``, so each link is checked)."""
        while node.parent is not None:
            if not any(child is node for child in node.parent.children):
                return False
            node = node.parent
        return node is self.document

    def apply(self, **kwargs: Any) -> None:
        edition = edition_of(self.config)
        if edition not in LIKE_STUDENT:
            return
        fold = edition == "selfstudy"
        cells = [node for node in self.document.findall(_is_code_cell)]
        first = next((i for i, c in enumerate(cells) if "solution" in _tags(c)), None)
        code = starters(self.env.doc2path(self.env.docname)) if first is not None else {}
        for node in list(self.document.findall(solution_node)):
            start = code.get(node.get("target_label", ""))
            if start is None:
                if fold:
                    fold_away(node)
                else:
                    node.parent.remove(node)
                continue
            box = nodes.container(classes=[STARTER_CLASS])
            box += nodes.paragraph(STARTER_NOTE, STARTER_NOTE)
            box += nodes.literal_block(start, start, language="ipython3")
            if fold:
                node.parent.insert(node.parent.index(node), box)
                fold_away(node)
            else:
                node.replace_self(box)
        for node in cells:
            if self._attached(node) and any(tag in HIDDEN_TAGS for tag in _tags(node)):
                if fold and "solution" in _tags(node) and not _inside_fold(node):
                    fold_away(node)
                elif not _inside_fold(node):
                    node.parent.remove(node)
        if first is not None:  # a lab page: what follows the first solution ran on the solutions
            for cell in cells[first:]:
                outputs = _outputs(cell)
                if not outputs or not self._attached(cell) or _inside_fold(cell):
                    continue  # a folded solution keeps its outputs
                for output in outputs:
                    cell.remove(output)
                note = nodes.paragraph(UNRUN_NOTE, "", nodes.emphasis(UNRUN_NOTE, UNRUN_NOTE))
                note["classes"].append(UNRUN_CLASS)
                cell += note
        # which sections are the tutors' is decided before any is dropped: a label written
        # before a heading sits at the end of the section before, which may itself go
        tutors = [s for s in self.document.findall(nodes.section) if is_instructor_section(s)]
        for section in tutors:
            if not self._attached(section):
                continue
            if isinstance(section.parent, nodes.section):  # a section of a page: dropped whole
                self._drop(section)
                continue
            # the page itself (the instructors' page, in the table of contents): a stub; its
            # sections go with their labels (a reference to one reads as its title)
            # last first: a section's label may close the section before it, still in place
            for nested in reversed(list(section.findall(nodes.section))[1:]):
                if self._attached(nested):
                    self._drop(nested)
            title = section.next_node(nodes.title)
            for child in list(section.children):
                if child is not title:
                    section.remove(child)
            section["classes"].append(STUB_CLASS)
            section += nodes.paragraph(STUB_NOTE, STUB_NOTE)

    def _drop(self, section: nodes.section) -> None:
        """Remove a section whole, with the label targets in front of it and its names; the
        labels at its end, written before the next heading, stay for the section they name."""
        title = section.next_node(nodes.title)
        text = title.astext() if title is not None else ""
        parent = section.parent
        place = parent.index(section) + 1
        for trailing in trailing_labels(section):
            trailing.parent.remove(trailing)
            parent.insert(place, trailing)
        ids = set(section.get("ids", []))
        names = set(section.get("names", []))
        labels = []  # its labels: the internal targets right in front of it
        k = parent.index(section) - 1
        while k >= 0 and _is_label(parent.children[k]):
            labels.append((parent, parent.children[k]))
            k -= 1
        # a label written before a heading can also close the section before it (MyST)
        node = parent.children[k] if k >= 0 else None
        while isinstance(node, nodes.section) and node.children:
            last = node.children[-1]
            if _is_label(last):
                labels.append((node, last))
                node.remove(last)
                continue
            node = last
        for owner, target in labels:
            names |= set(target.get("names", []))
            ids |= set(target.get("ids", []))
            if target.parent is owner and any(c is target for c in owner.children):
                owner.remove(target)
        # the objects it documents (the API page's autodoc entries): links to them go too
        objects = _dropped_objects(self.env).setdefault(self.env.docname, set())
        for signature in section.findall(addnodes.desc_signature):
            objects.update(signature.get("ids", []))
        for target in section.findall(nodes.target):  # an automodule's "module-..." anchor
            objects.update(i for i in target.get("ids", []) if i.startswith("module-"))
        forget_objects(self.env, self.env.docname, objects)
        parent.remove(section)
        dropped = _dropped(self.env)
        for name in names:  # no label of the page leads there any more
            self.document.nameids.pop(name, None)
            self.document.nametypes.pop(name, None)
            dropped[name] = (self.env.docname, text)
        for i in ids:
            self.document.ids.pop(i, None)


def forget_objects(env: Any, docname: str, anchors: set[str]) -> int:
    """Take the Python objects and modules documented at ``anchors`` of page ``docname`` out of
    the domain's records: the module index, the general index's object entries and the
    inventory (``objects.inv``) then list none of them. Returns how many were taken out."""
    data = env.get_domain("py").data
    count = 0
    for table in ("objects", "modules"):
        records = data.get(table, {})
        for name in [n for n, e in records.items() if e[0] == docname and e[1] in anchors]:
            del records[name]
            count += 1
    return count


def fold_away(node: nodes.Element) -> None:
    """Put ``node`` behind a closed ``<details>`` whose summary is :data:`FOLD_SUMMARY`."""
    box = nodes.container(classes=[FOLD_CLASS])
    opening = f'<details class="{FOLD_CLASS}"><summary>{FOLD_SUMMARY}</summary>'
    box += nodes.raw("", opening, format="html")
    node.replace_self(box)
    box += node
    box += nodes.raw("", "</details>", format="html")


def _inside_fold(node: nodes.Node) -> bool:
    while node is not None:
        if isinstance(node, nodes.container) and FOLD_CLASS in node.get("classes", []):
            return True
        node = node.parent
    return False


def _is_label(node: nodes.Node) -> bool:
    """An internal target (a ``(label)=`` line), not a link to elsewhere."""
    return isinstance(node, nodes.target) and not node.get("refuri")


def _dropped(env: Any) -> dict[str, tuple[str, str]]:
    """The labels of the tutors' sections left out of the student pages: (page, title)."""
    if not hasattr(env, "uio_teach_dropped"):
        env.uio_teach_dropped = {}
    return env.uio_teach_dropped


def _dropped_objects(env: Any) -> dict[str, set[str]]:
    """The anchors of the objects documented in the tutors' sections left out, by page."""
    if not hasattr(env, "uio_teach_dropped_objects"):
        env.uio_teach_dropped_objects = {}
    return env.uio_teach_dropped_objects


def _purge(app: Sphinx, env: Any, docname: str) -> None:
    dropped = _dropped(env)
    for name in [n for n, (doc, _) in dropped.items() if doc == docname]:
        del dropped[name]
    _dropped_objects(env).pop(docname, None)


def _merge(app: Sphinx, env: Any, docnames: set[str], other: Any) -> None:
    _dropped(env).update({n: v for n, v in _dropped(other).items() if v[0] in docnames})
    objects = _dropped_objects(other)
    _dropped_objects(env).update({d: objects[d] for d in docnames if d in objects})


def unlink_dropped(doctree: nodes.Node, anchors: set[str]) -> int:
    """Turn every link to one of ``anchors`` (objects of a tutors' section left out) into its
    text: the student edition links no anchor it does not have. Returns how many."""
    count = 0
    for ref in list(doctree.findall(nodes.reference)):
        target = ref.get("refid") or ref.get("refuri", "").partition("#")[2]
        if target and target in anchors:
            ref.replace_self(nodes.inline("", "", *ref.children))
            count += 1
    return count


def _unlink(app: Sphinx, doctree: nodes.Node, docname: str) -> None:
    if edition_of(app.config) not in LIKE_STUDENT:
        return
    anchors = set().union(*_dropped_objects(app.env).values())
    if anchors:
        unlink_dropped(doctree, anchors)


def dropped_object(anchors: set[str], node: nodes.Element) -> bool:
    """Does the Python cross-reference ``node`` name an object (or a module) of the anchors of
    a tutors' section left out? Its target may be written relative to the current module."""
    target = node.get("reftarget", "")
    if node.get("reftype") == "mod":
        return f"module-{target}" in anchors
    module = node.get("py:module") or ""
    names = {target, f"{module}.{target}"}
    return any(
        n == a or n.startswith(f"{a}.") or a.endswith(f".{target}") for a in anchors for n in names
    )


def _dropped_reference(app: Sphinx, env: Any, node: nodes.Element, contnode: nodes.Node):
    """A reference to a tutors' section left out: its title as plain text, not a dead link;
    a reference to an object documented there: its name, unlinked."""
    if node.get("refdomain") == "py" and edition_of(app.config) in LIKE_STUDENT:
        anchors = set().union(*_dropped_objects(env).values())
        return contnode if anchors and dropped_object(anchors, node) else None
    if node.get("refdomain") != "std" or node.get("reftype") != "ref":
        return None
    found = _dropped(env).get(node.get("reftarget", ""))
    if found is None:
        return None
    text = contnode.astext() if node.get("refexplicit") else found[1]
    return nodes.inline(text, text)


def is_stub(doctree: nodes.Node | None) -> bool:
    """Is this page a stub of the student edition (no notebook, no download of its source)?"""
    if doctree is None:
        return False
    return any(STUB_CLASS in s.get("classes", []) for s in doctree.findall(nodes.section))


def _check_edition(app: Sphinx, config: Config) -> None:
    if config.uio_teach_edition not in EDITIONS:
        raise ValueError(
            f"{EDITION_VAR} must be one of {', '.join(EDITIONS)}, got {config.uio_teach_edition!r}"
        )
    if config.uio_teach_edition in LIKE_STUDENT:
        # the pages' sources hold the solutions: not copied into the site, no "show source" link
        config.html_copy_source = False
        config.html_show_sourcelink = False
    # pages can say what holds in one edition only: ```{only} student``` or ```{only} instructor```
    app.tags.add(config.uio_teach_edition)
    logger.info(f"[editions] building the {config.uio_teach_edition} edition of the book")


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_config_value(
        "uio_teach_edition", os.environ.get(EDITION_VAR, "student").strip().lower(), "env"
    )
    app.connect("config-inited", _check_edition)
    app.connect("env-purge-doc", _purge)
    app.connect("env-merge-info", _merge)
    app.connect("missing-reference", _dropped_reference)
    app.connect("doctree-resolved", _unlink)
    app.add_transform(StudentEdition)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
