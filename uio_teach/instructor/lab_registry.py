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

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import UIOTeachError
from ..worked import RegistryView

__all__ = ["LABS", "Lab", "LabError", "LabUsageError", "lab_of"]


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
