"""The labs of the course: which chapter, which parameters, which checks.

:data:`LABS` names each lab of the course by id, with its chapter in
``book/``, its parameter class (:mod:`uio_teach.instructor.lab_params`) and
the check ids its check cells produce; :func:`lab_of` finds the lab of a
chapter. :class:`LabError` and :class:`LabUsageError` are the errors of
everything that makes labs. This module imports only the parameter classes,
so the notebook builder (:mod:`~uio_teach.instructor.lab_notebook`), the
variants (:mod:`~uio_teach.instructor.variants`) and the writer
(:mod:`~uio_teach.instructor.labs`) can all import it.

Examples
--------
>>> from uio_teach.instructor.lab_registry import LABS, lab_of
>>> list(LABS), lab_of("book/lab_pa9.md").id
(['pa9', 'case_study', 'missile'], 'pa9')
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import UIOTeachError
from .lab_params import CaseStudyParams, MissileParams, PA9Params

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
        ``"pa9"``, ``"case_study"`` or ``"missile"``.
    source : str
        The file name of its chapter in ``book/``.
    params : type
        Its parameter class (:mod:`uio_teach.instructor.lab_params`).
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


def _registry() -> dict[str, Lab]:
    return {
        "pa9": Lab(
            "pa9",
            "lab_pa9.md",
            PA9Params,
            ("pa9.design", "pa9.simulation", "pa9.plot", "pa9.piecewise", "pa9.piecewise_plot"),
        ),
        "case_study": Lab(
            "case_study",
            "lab_case_study.md",
            CaseStudyParams,
            (
                "case_study.projection",
                "case_study.lmi",
                "case_study.pole",
                "case_study.simulation",
                "case_study.residual",
                "case_study.plot",
            ),
        ),
        "missile": Lab(
            "missile",
            "lab_missile.md",
            MissileParams,
            (
                "missile.pmo",
                "missile.ginverse",
                "missile.reconstruction",
                "missile.plot",
                "missile.catch_times",
                "missile.noise",
            ),
        ),
    }


LABS: dict[str, Lab] = _registry()
"""The labs of the course, by id (each a :class:`Lab`)."""


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
