"""The grade side of the labs' checks: which answers each check needs, and the verdicts.

A lab's check cells (``book/lab_*.md``) call a check function of
:mod:`uio_teach.checks` on the group's answer variables, on ``PARAMS`` and on
the set-up cell's ``plant``. The grader makes the same calls, with the same
arguments, in its own process: for each lab, :data:`GRADED` lists its checks
in order (the check id, the answer variables it reads, and a function
``(answers, params, plant) -> CheckResult``), and
:func:`grade_answers` calls them with the answers taken out of the group's
kernel (see :mod:`uio_teach.checks.answers`) and the parameters **of the
answer key**, never those of the notebook. The plant is the group's plant,
from the key's parameters (:func:`lab_plant`).

An answer that is missing (the variable was never assigned, or the cell that
assigns it raised) gives a ✗ that names the variable, and, when a cell raised,
which cell and the exception, with a hint for the common cases.

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach.grading.lab_checks import Missing, grade_answers
>>> plant = ut.examples.pa9()
>>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
>>> answers = {"H": obs.H, "T": obs.T, "K1": obs.K1, "F": obs.F, "K2": obs.K2}
>>> params = {"poles": [-1, -2, -3]}
>>> first = grade_answers("pa9", answers, params)[0]
>>> first.check_id, first.passed
('pa9.design', True)
>>> answers["K1"] = Missing("K1", cell=4, ename="LinAlgError", evalue="Singular matrix")
>>> print(grade_answers("pa9", answers, params)[0].failures[0])  # doctest: +ELLIPSIS
K1 is missing: code cell 4 raised LinAlgError (Singular matrix). ...
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from .. import examples
from ..checks import (
    case_study_lmi,
    case_study_plot,
    case_study_pole,
    case_study_projection,
    case_study_residual,
    case_study_simulation,
    clear_collected,
    missile_catch_times,
    missile_ginverse,
    missile_noise,
    missile_plot,
    missile_pmo,
    missile_reconstruction,
    pa9_design,
    pa9_piecewise,
    pa9_piecewise_plot,
    pa9_plot,
    pa9_simulation,
)
from ..checks.common import CheckResult
from ..experiments import plant_from_params

__all__ = ["GradedCheck", "Missing", "GRADED", "lab_plant", "grade_answers", "missing_message"]


@dataclass(frozen=True)
class Missing:
    """An answer the grader could not take out of the kernel.

    Attributes
    ----------
    name : str
        The variable.
    cell : int or None
        The code cell (counted from 1, the student's cells only) that raised
        before the check, or None when nothing raised.
    ename : str
        The exception's class name ("" when nothing raised).
    evalue : str
        Its message, on one line.
    reason : str
        Why else it is missing (not carried out of the kernel, malformed).

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import Missing
    >>> Missing("H").cell is None
    True
    """

    name: str
    cell: int | None = None
    ename: str = ""
    evalue: str = ""
    reason: str = ""


@dataclass(frozen=True)
class GradedCheck:
    """One check of a lab, as the grader runs it.

    Attributes
    ----------
    check_id : str
        The gradebook column (``"pa9.design"``).
    title : str
        What is checked, for a ✗ made by the grader.
    names : tuple of str
        The answer variables it reads (those of the lab's check cell).
    run : callable
        ``run(answers, params, plant) -> CheckResult``.
    given : tuple of str
        The other names of the check cell, which the grader takes from the
        answer key, never from the notebook: the group's ``plant`` (from the
        key's parameters) and, in the missile lab, the paper's ``x0``.
    """

    check_id: str
    title: str
    names: tuple[str, ...]
    run: Callable[[Mapping[str, Any], Mapping[str, Any], Any], CheckResult]
    given: tuple[str, ...] = ("plant",)


def _pa9_run(a: Mapping[str, Any], p: Mapping[str, Any], plant: Any) -> dict[str, Any]:
    """What a PA9 run is checked against: the asked poles and x(0), the group's H, K1, plant."""
    return {
        "poles": p["poles"],
        "initial_state": p["initial_state"],
        "H": a["H"],
        "K1": a["K1"],
        "plant": plant,
    }


def _pa9() -> tuple[GradedCheck, ...]:
    return (
        GradedCheck(
            "pa9.design",
            "Requirement 1: the UIO design",
            ("H", "T", "K1", "F", "K2"),
            lambda a, p, plant: pa9_design(
                a["H"], a["T"], a["K1"], a["F"], a["K2"], plant=plant, poles=p["poles"]
            ),
        ),
        GradedCheck(
            "pa9.simulation",
            "Requirement 2: the simulation with a sinusoidal d",
            ("resp_sine", "H", "K1"),
            lambda a, p, plant: pa9_simulation(
                a["resp_sine"],
                amplitude=p["sine"]["amplitude"],
                frequency=p["sine"]["frequency"],
                **_pa9_run(a, p, plant),
            ),
        ),
        GradedCheck(
            "pa9.plot",
            "Requirement 3: the plot of e and r",
            ("fig", "resp_sine"),
            lambda a, p, plant: pa9_plot(a["fig"], response=a["resp_sine"], plant=plant),
        ),
        GradedCheck(
            "pa9.piecewise",
            "Requirement 4: the piecewise-constant d",
            ("resp_steps", "resp_sine", "H", "K1"),
            lambda a, p, plant: pa9_piecewise(
                a["resp_steps"],
                sinusoidal=a["resp_sine"],
                times=p["piecewise"]["times"],
                values=p["piecewise"]["values"],
                **_pa9_run(a, p, plant),
            ),
        ),
        GradedCheck(
            "pa9.piecewise_plot",
            "Requirement 4: the plot of the piecewise-constant run",
            ("fig_steps", "resp_steps"),
            lambda a, p, plant: pa9_piecewise_plot(
                a["fig_steps"], response=a["resp_steps"], plant=plant
            ),
        ),
    )


def _case_study() -> tuple[GradedCheck, ...]:
    return (
        GradedCheck(
            "case_study.projection",
            "The projection M",
            ("M",),
            lambda a, p, plant: case_study_projection(a["M"], plant=plant),
        ),
        GradedCheck(
            "case_study.lmi",
            "The gain L from the LMI",
            ("L", "P_lmi", "Y_lmi"),
            lambda a, p, plant: case_study_lmi(a["L"], a["P_lmi"], plant=plant, Y=a["Y_lmi"]),
        ),
        GradedCheck(
            "case_study.pole",
            "The movable pole",
            ("L_moved",),
            lambda a, p, plant: case_study_pole(a["L_moved"], p["pole"], plant=plant),
        ),
        GradedCheck(
            "case_study.simulation",
            "A run with both unknown signals",
            ("run", "pmo"),
            lambda a, p, plant: case_study_simulation(
                a["run"],
                u2=(p["u2"]["amplitude"], p["u2"]["frequency"]),
                v=(p["v"]["amplitude"], p["v"]["hold"], p["v"]["seed"]),
                initial_state=p["initial_state"],
                plant=plant,
                observer=a["pmo"],
            ),
        ),
        GradedCheck(
            "case_study.residual",
            "The residual and Dv",
            ("Dv", "Nr", "run"),
            lambda a, p, plant: case_study_residual(a["Dv"], a["Nr"], a["run"], plant=plant),
        ),
        GradedCheck(
            "case_study.plot",
            "The plot of the run",
            ("fig", "run"),
            lambda a, p, plant: case_study_plot(a["fig"], a["run"], plant=plant),
        ),
    )


def _missile_run(a: Mapping[str, Any], plant: Any) -> dict[str, Any]:
    """What a missile run is checked against: the group's plant and PMO, the paper's x0.

    The initial state is the paper's x0, as the lab's set-up cell takes it.
    """
    return {"plant": plant, "observer": a["pmo"], "initial_state": examples.MISSILE_PUBLISHED.x0}


_MISSILE_GIVEN = ("plant", "x0")


def _missile() -> tuple[GradedCheck, ...]:
    return (
        GradedCheck(
            "missile.pmo",
            "The PMO",
            ("M", "L", "F"),
            lambda a, p, plant: missile_pmo(
                a["M"], a["L"], a["F"], poles=p["pmo_poles"], plant=plant
            ),
        ),
        GradedCheck(
            "missile.ginverse",
            "The generalized-inverse observer",
            ("Cg", "Pc", "Kg"),
            lambda a, p, plant: missile_ginverse(a["Cg"], a["Pc"], a["Kg"], plant=plant),
        ),
        GradedCheck(
            "missile.reconstruction",
            "Reconstructing v1 and v2",
            ("vhat", "run_pmo", "pmo"),
            lambda a, p, plant: missile_reconstruction(
                a["vhat"],
                a["run_pmo"],
                poles=p["pmo_poles"],
                **_missile_run(a, plant),
            ),
            given=_MISSILE_GIVEN,
        ),
        GradedCheck(
            "missile.plot",
            "The plot of v1, v2 and their estimates",
            ("fig", "vhat"),
            lambda a, p, plant: missile_plot(a["fig"], a["vhat"], plant=plant),
        ),
        GradedCheck(
            "missile.catch_times",
            "The catch times",
            ("catch", "run_pmo0", "vhat0", "pmo"),
            lambda a, p, plant: missile_catch_times(
                a["catch"],
                a["run_pmo0"],
                a["vhat0"],
                tol=p["tol"],
                poles=p["pmo_poles"],
                **_missile_run(a, plant),
            ),
            given=_MISSILE_GIVEN,
        ),
        GradedCheck(
            "missile.noise",
            "What noise does to the reconstruction",
            ("rms_noisy", "run_noisy", "pmo"),
            lambda a, p, plant: missile_noise(
                a["rms_noisy"],
                a["run_noisy"],
                sigma=p["noise"]["sigma"],
                seed=p["noise"]["seed"],
                **_missile_run(a, plant),
            ),
            given=_MISSILE_GIVEN,
        ),
    )


GRADED: dict[str, tuple[GradedCheck, ...]] = {
    "pa9": _pa9(),
    "case_study": _case_study(),
    "missile": _missile(),
}
"""Lab id -> its checks, in the order of its check cells."""


def lab_plant(lab: str, params: Mapping[str, Any] | None) -> Any:
    """The plant of a group: the lab's plant (:data:`uio_teach.experiments.LAB_PLANTS`) with
    the matrices its parameters give, if any.

    Parameters
    ----------
    lab : str
        ``"pa9"``, ``"case_study"`` or ``"missile"``.
    params : mapping or None
        The group's parameters (from the answer key).

    Returns
    -------
    Plant

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import lab_plant
    >>> lab_plant("pa9", {"poles": [-1, -2, -3]}).n
    3
    """
    return plant_from_params(lab, params)


_HINTS = (
    (
        "LinAlgError",
        ("singular", "square"),
        "np.linalg.inv needs a square, invertible matrix; CE is not square here: a "
        "generalized inverse (np.linalg.pinv) is what the formula asks for",
    ),
    (
        "ValueError",
        ("matmul", "mismatch", "shapes", "broadcast"),
        "the shapes in a product do not fit: print the .shape of each factor and compare "
        "them with the sizes n, m, p, q of the plant",
    ),
    (
        "NameError",
        ("not defined",),
        "a name used in that cell was never assigned: run the cells above it, in order",
    ),
    (
        "TimeoutError",
        (),
        "the cell ran longer than the time limit of a cell: look for a loop that never ends",
    ),
    (
        "KeyError",
        (),
        "a key of PARAMS or of a dict is spelt differently: print the dict's keys",
    ),
)


def missing_message(missing: Missing) -> str:
    """The grader's ✗ for a missing answer: the variable, the cell that raised, a hint.

    Parameters
    ----------
    missing : Missing

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.grading.lab_checks import Missing, missing_message
    >>> print(missing_message(Missing("fig")))
    fig is missing: no cell assigned it before this check. Name your result fig.
    """
    name = missing.name
    if missing.reason:
        return f"{name} could not be graded: {missing.reason}."
    if missing.cell is None:
        return f"{name} is missing: no cell assigned it before this check. Name your result {name}."
    evalue = f" ({missing.evalue})" if missing.evalue else ""
    text = f"{name} is missing: code cell {missing.cell} raised {missing.ename or 'an error'}"
    text += f"{evalue}."
    low = missing.evalue.lower()
    for ename, words, hint in _HINTS:
        if missing.ename == ename and (not words or any(w in low for w in words)):
            return f"{text} Hint: {hint}."
    return f"{text} Fix that cell and run the notebook again from the top."


def grade_answers(
    lab: str,
    answers: Mapping[str, Any],
    params: Mapping[str, Any],
    *,
    plant: Any = None,
    per_check: Sequence[Mapping[str, Any]] | None = None,
) -> list[CheckResult]:
    """The verdict of every check of ``lab`` on the answers, with the key's parameters.

    Parameters
    ----------
    lab : str
        A lab of :data:`GRADED`.
    answers : mapping
        Variable name -> value (rebuilt objects) or :class:`Missing`.
    params : mapping
        The group's parameters, from the answer key (the lab's defaults when
        there is no key): never the notebook's ``PARAMS``.
    plant : Plant, optional
        The group's plant; :func:`lab_plant` by default.
    per_check : sequence of mapping, optional
        For each check, in order, the answers captured right after its check
        cell ran (later reassignments do not matter); ``answers`` fills what a
        capture lacks.

    Returns
    -------
    list of CheckResult
        One per check, in order, each with its ``check_id``.

    Raises
    ------
    KeyError
        ``lab`` is not a graded lab.
    """
    if plant is None:
        plant = lab_plant(lab, params)
    results = []
    for index, check in enumerate(GRADED[lab]):
        seen = dict(answers)
        if per_check is not None and index < len(per_check):
            seen.update(per_check[index])
        absent = [n for n in check.names if n not in seen or isinstance(seen[n], Missing)]
        if absent:
            result = CheckResult(check.title, check_id=check.check_id)
            for name in absent:
                why = seen.get(name)
                result.add(
                    False, missing_message(why if isinstance(why, Missing) else Missing(name))
                )
        else:
            try:
                result = check.run(seen, params, plant)
            except MemoryError:  # a limit of the checking process: the row says so
                raise
            except Exception as exc:  # never a traceback: the check could not be made
                result = CheckResult(
                    check.title,
                    [(False, f"the grader could not check your answers ({type(exc).__name__}).")],
                )
            result.check_id = check.check_id
        results.append(result)
    clear_collected()  # the check functions record their results; the grader keeps none
    return results
