"""The labs of the course: which chapter, which parameters, which checks.

:data:`LABS` names each lab of the course by id, with its chapter in
``book/``, its parameter class and the check ids its check cells produce,
read from the worked examples that have a lab (their ``LabEntry`` in
:data:`uio_teach.worked.WORKED`); :func:`lab_of` finds the lab of a chapter.
:class:`LabError` and :class:`LabUsageError` are the errors of everything
that makes labs. This module imports only the registry, so the notebook
builder (:mod:`~uio_teach.instructor.lab_notebook`), the
variants (:mod:`~uio_teach.instructor.variants`) and the writer
(:mod:`~uio_teach.instructor.labs`) can all import it.

Examples
--------
>>> from uio_teach.instructor.lab_registry import LABS, lab_of
>>> "pa9" in LABS, lab_of("book/lab_pa9.md").id
(True, 'pa9')
"""

from __future__ import annotations

import importlib
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import UIOTeachError
from ..worked import RegistryView

__all__ = ["LABS", "Lab", "LabError", "LabUsageError", "lab_of", "missing_parts"]


class LabError(UIOTeachError, ValueError):
    """A lab chapter that cannot be converted (one-line message naming the file)."""


class LabUsageError(LabError):
    """A source that is not a lab chapter, or a folder that does not exist (a usage error)."""


@dataclass(frozen=True)
class Lab:
    """One lab of the course: its chapter, its parameter class and its checks.

    Attributes
    ----------
    id : str
        The worked example's name (``"pa9"``, ...).
    source : str
        The file name of its chapter in ``book/``.
    params : type
        Its parameter class (a :class:`uio_teach.lab_params.LabParams`).
    check_ids : tuple of str
        The ``check_id`` of every result its check cells produce, in order.

    Examples
    --------
    >>> from uio_teach.instructor.lab_registry import LABS
    >>> LABS["pa9"].check_ids
    ('pa9.design', 'pa9.simulation', 'pa9.plot', 'pa9.piecewise', 'pa9.piecewise_plot')
    """

    id: str
    source: str
    params: type
    check_ids: tuple[str, ...]


def _labs(worked: Mapping[str, Any]) -> dict[str, Lab]:
    """The labs of the worked examples that have one."""
    return {
        name: Lab(name, entry.lab.source, entry.lab.params, entry.lab.check_ids)
        for name, entry in worked.items()
        if entry.lab is not None
    }


LABS: Mapping[str, Lab] = RegistryView("LABS", _labs)
"""The labs of the course, by id (each a :class:`Lab`), from :data:`uio_teach.worked.WORKED`."""


def lab_of(source: str | os.PathLike[str]) -> Lab | None:
    """The registered lab whose chapter is ``source`` (by file name), or ``None``.

    Parameters
    ----------
    source : str or path-like

    Returns
    -------
    Lab or None

    Examples
    --------
    >>> from uio_teach.instructor.lab_registry import lab_of
    >>> lab_of("book/lab_missile.md").id
    'missile'
    """
    name = Path(source).name
    return next((lab for lab in LABS.values() if lab.source == name), None)


def missing_parts(lab: Lab, book_dir: str | os.PathLike[str]) -> list[str]:
    """What a lab still lacks of the files every lab needs, one sentence each (empty: nothing).

    A lab is its worked example's module (the :class:`~uio_teach.worked.LabEntry`)
    plus four files the module cannot hold (CONTRIBUTING.md, *A lab*): the
    chapter in ``book/``, its line in ``_toc.yml`` (beside the folder
    ``book/``), a check function in :mod:`uio_teach.checks` for every check
    id (exported by its ``__init__``), and in the chapter one cell tagged
    ``parameters`` and one ``{code-cell}`` tagged ``check`` per check id.

    Parameters
    ----------
    lab : Lab
        The lab (an entry of :data:`LABS`).
    book_dir : str or path-like
        The folder ``book/`` of the checkout.

    Returns
    -------
    list of str

    Examples
    --------
    >>> from uio_teach.instructor.lab_registry import LABS, missing_parts
    >>> print(missing_parts(LABS["pa9"], "/nowhere/book")[0])
    the chapter /nowhere/book/lab_pa9.md of the pa9 lab does not exist: write it ...
    """
    book = Path(book_dir)
    chapter = book / lab.source
    out = []
    if not chapter.is_file():
        out.append(
            f"the chapter {chapter} of the {lab.id} lab does not exist: write it "
            "(CONTRIBUTING.md, A lab)"
        )
    toc = book.parent / "_toc.yml"
    entry = f"{book.name}/{Path(lab.source).stem}"
    if toc.is_file() and not re.search(
        rf"^\s*-\s*file:\s*{re.escape(entry)}(\.md)?\s*$", toc.read_text("utf-8"), re.M
    ):
        out.append(f"_toc.yml does not list the {lab.id} lab's chapter: add `- file: {entry}`")
    checks = importlib.import_module("uio_teach.checks")
    for check_id in lab.check_ids:
        name = check_id.replace(".", "_")
        if not callable(getattr(checks, name, None)):
            out.append(
                f"uio_teach.checks has no function {name} for the check id {check_id!r}: write "
                "it with @never_raises in a module of uio_teach/checks/ and import it in "
                "uio_teach/checks/__init__.py"
            )
    if chapter.is_file():
        text = chapter.read_text("utf-8")
        cells = re.findall(r"^```\{code-cell\}[^\n]*\n((?:.*\n)*?)```", text, re.M)
        params = [c for c in cells if re.search(r"^:tags:.*\bparameters\b", c, re.M)]
        if len(params) != 1 or "PARAMS" not in params[0]:
            out.append(
                f"{chapter.name} needs exactly one code cell tagged `parameters` that defines "
                f"PARAMS (it has {len(params)})"
            )
        checks_cells = [c for c in cells if re.search(r"^:tags:.*\bcheck\b", c, re.M)]
        if len(checks_cells) != len(lab.check_ids):
            out.append(
                f"{chapter.name} has {len(checks_cells)} code cells tagged `check`, but its "
                f"LabEntry names {len(lab.check_ids)} check ids ({', '.join(lab.check_ids)}): "
                "one check cell per check id, in order"
            )
    return out
