"""Checks of the case-study lab: the projection-operator observer of a discrete-time plant.

* :func:`case_study_projection` -- ``M``: ``(I - MC)E = 0`` and ``MD = 0``;
* :func:`case_study_lmi` -- the gain ``L`` of the LMI: ``LD = 0``, a stable
  ``F = A1 - LC`` (and, with ``P``, the LMI itself);
* :func:`case_study_pole` -- a gain that moves the one movable pole to the
  asked place, with ``LD = 0`` (the two poles at 0.5 stay);
* :func:`case_study_simulation` -- a run with ``d`` and ``v`` as asked: the
  error ignores both and decays;
* :func:`case_study_residual` -- ``D v`` and the combination ``N r`` that
  ``v`` does not reach.

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach import checks
>>> plant = ut.examples.dt_case_study()
>>> C, E, D = plant.C, plant.E, plant.D
>>> M = np.hstack([E, np.zeros((3, 1))]) @ np.linalg.pinv(np.hstack([C @ E, D]))
>>> checks.case_study_projection(M).passed
True
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from .. import examples
from .. import tolerances as tols
from .._display import format_matrix_line, format_poles
from ..existence import check_existence, decoupling
from ..linalg import left_null
from ..worked.case_study import CASE_STUDY
from .common import (
    CheckResult,
    check_plant_of,
    close,
    get_plant,
    never_raises,
    numbers,
    read_matrix,
    read_response,
    rerun_without_unknown_inputs,
    same_poles,
    up_to,
)
from .plots import panel_texts, plotted_axes, read_figure

__all__ = [
    "case_study_projection",
    "case_study_lmi",
    "case_study_pole",
    "case_study_simulation",
    "case_study_residual",
    "case_study_plot",
]


def _M_ref(plant) -> np.ndarray:
    """The projection matrix ``M = [E 0][C E D]^+`` of the package's design."""
    return decoupling(plant).M


def _small(X: np.ndarray, scale: float, tol: float) -> tuple[bool, float]:
    big = float(np.max(np.abs(X))) if X.size else 0.0
    return big <= tol * max(1.0, scale), big


@never_raises("Case study: the projection matrix M", "case_study.projection")
def case_study_projection(M: Any, plant: Any = None, *, tol: float | None = None) -> CheckResult:
    """Check ``M``: it removes ``d``, ``(I - MC)E = 0``, and the disturbance, ``MD = 0``.

    Parameters
    ----------
    M : array_like, shape (n, p)
        Your ``M``.
    plant : Plant, optional
        The plant; :func:`uio_teach.examples.dt_case_study` by default.
    tol : float, optional
        Tolerance of the two identities (relative to the largest entry of ``M``); default
        ``tolerances.CHECK_EXACT_RTOL``.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> plant = ut.examples.dt_case_study()
    >>> M = plant.E @ np.linalg.pinv(plant.C @ plant.E)   # forgets D
    >>> "Your M is E (CE)^+, which ignores D" in checks.case_study_projection(M).failures[0]
    True
    """
    tol = tols.CHECK_EXACT_RTOL if tol is None else tol
    result = CheckResult("Case study: the projection matrix M")
    plant = get_plant(result, plant, "dt_case_study")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    M = read_matrix(result, "M", M, n, p, f"n x p = {n} x {p}")
    if M is None:
        return result
    C, E, D = plant.C, plant.E, plant.D
    scale = float(np.max(np.abs(M)))
    ok, big = _small((np.eye(n) - M @ C) @ E, scale, tol)
    ref = _M_ref(plant)
    if ok:
        result.add(True, f"(I - MC)E = 0{up_to(big, 'largest entry')}: d is projected out.")
    else:
        rounded = next(
            (k for k in (4, 2) if close(M, np.round(ref, k), tols.CHECK_EXACT_RTOL)), None
        )
        if rounded is not None:
            hint = (
                f" Your M is the right M rounded to {rounded} decimals: compute it at full "
                "precision instead of typing printed digits."
            )
        elif close(M, -ref, tols.CHECK_EXACT_RTOL):
            hint = " Your M is -[E 0][CE D]^+: check the sign."
        else:
            hint = (
                " M must satisfy M [CE D] = [E 0]; [CE D] is square here: which inverse solves it?"
            )
        result.add(
            False,
            f"(I - MC)E is not 0: it is {format_matrix_line((np.eye(n) - M @ C) @ E)} "
            f"(largest entry {big:.3g}), so d still drives the error.{hint}",
        )
    ok, big = _small(M @ D, scale, tol)
    if ok:
        result.add(True, f"MD = 0{up_to(big, 'largest entry')}: v does not enter x̂ through My.")
    else:
        only_e = E @ np.linalg.pinv(C @ E)
        hint = (
            " Your M is E (CE)^+, which ignores D: M must remove d and v together."
            if close(M, only_e, tols.CHECK_EXACT_RTOL)
            else " M must also satisfy MD = 0, together with MCE = E."
        )
        result.add(
            False,
            f"MD is not 0: MD = {format_matrix_line(M @ D)} (largest entry {big:.3g}), so the "
            f"disturbance v enters the estimate directly.{hint}",
        )
    return result


def _error_matrix(plant, L: np.ndarray) -> np.ndarray:
    """``F = (I - M C) A - L C`` with the package's ``M``."""
    return decoupling(plant).A1 - L @ plant.C


def _LD(result: CheckResult, L: np.ndarray, plant, tol: float, *, lmi: bool) -> bool:
    """✓/✗ ``LD = 0``, the hint naming the cause in the exercise's own terms: the LMI's linear
    constraint where ``L`` comes from an LMI (``lmi``), the form ``L = l N`` where it is placed
    by hand."""
    LD = L @ plant.D
    ok, big = _small(LD, float(np.max(np.abs(L))), tol)
    if ok:
        result.add(True, f"LD = 0{up_to(big, 'largest entry')}: v does not enter through y - Cx̂.")
        return True
    pub = examples.DT_CASE_STUDY_PUBLISHED.L
    hint = (
        " Your L is the printed one, rounded to 4 decimals; rounding moves it off LD = 0. Use "
        "the gain of your solver."
        if close(L, pub, tols.CHECK_EXACT_RTOL)
        else (
            " With Y = PL, LD = 0 is the linear constraint YD = 0: is it in your LMI?"
            if lmi
            else " A gain with LD = 0 has the form L = l N, with N D = 0 (N the combination of "
            "outputs that v does not reach): build your L from N."
        )
    )
    result.add(
        False,
        f"LD is not 0: LD = {format_matrix_line(LD)} (largest entry {big:.3g}), so the "
        f"disturbance v drives the error.{hint}",
    )
    return False


@never_raises("Case study: the gain L from the LMI", "case_study.lmi")
def case_study_lmi(
    L: Any,
    P: Any = None,
    plant: Any = None,
    *,
    tol: float | None = None,
    Y: Any = None,
    margin: float = 0.0,
) -> CheckResult:
    """Check the LMI gain ``L``: the solved ``P``, ``Y`` certify it and give it, ``LD = 0``.

    The checks: ``P`` (the solver's value) is symmetric positive definite;
    ``L = P^{-1} Y`` with the solver's ``Y`` (so ``L = Y`` or ``L = PY`` fail,
    even where ``P`` is close to the identity); ``LD = 0``; ``F = A1 - LC``
    stable; ``P`` certifies the LMI ``[[-P, F^T P], [P F, -P]] <= -margin I``.
    Any solver's ``P`` and ``Y`` pass: the gain is not unique.

    Parameters
    ----------
    L : array_like, shape (n, p)
        Your gain (``L = P^{-1} Y`` from the solver).
    P : array_like, shape (n, n)
        The solver's ``P``. Without it (``None``, the LMI skipped) the check fails.
    plant : Plant, optional
        The plant; :func:`uio_teach.examples.dt_case_study` by default.
    tol : float, optional
        Tolerance of ``LD = 0``, of ``L = P^{-1} Y`` (relative) and of the LMI
        (a solver meets them to about 1e-8); default ``tolerances.CHECK_RTOL``.
    Y : array_like, shape (n, p), optional
        The solver's ``Y``: the gain must be ``P^{-1} Y``. Without it, ``L``
        cannot be traced to the solve, and the check says so (a ✗).
    margin : float, optional
        The margin the exercise puts on the LMI block (``0.01``); the block's
        largest eigenvalue must be at most ``-margin`` (to ``tol``).

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> pmo = ut.design_pmo(ut.examples.dt_case_study(), method="lmi")
    >>> P = pmo.lmi_certificate
    >>> checks.case_study_lmi(pmo.L, P, Y=P @ pmo.L).passed
    True
    >>> checks.case_study_lmi(pmo.L, None).failures[0][:40]
    'P is missing: the gain must come from th'
    """
    tol = tols.CHECK_RTOL if tol is None else tol
    result = CheckResult("Case study: the gain L from the LMI")
    plant = get_plant(result, plant, "dt_case_study")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    L = read_matrix(result, "L", L, n, p, f"n x p = {n} x {p}")
    if P is None:
        result.add(
            False,
            "P is missing: the gain must come from the solved LMI, and P (the solver's value) "
            "is what certifies it. Solve the LMI and pass P's value.",
        )
        Pm = None
    else:
        Pm = read_matrix(result, "P", P, n, n, f"n x n = {n} x {n}")
    Ym = read_matrix(result, "Y", Y, n, p, f"n x p = {n} x {p}") if Y is not None else None
    if L is None:
        return result
    certified = Pm is not None and (Y is None or Ym is not None) and _P_definite(result, Pm, tol)
    from_solve = _L_from_solve(result, L, Pm, Ym, tol) if certified else False
    _LD(result, L, plant, tol, lmi=True)
    F = _error_matrix(plant, L)
    eig = np.linalg.eigvals(F)
    worst = float(np.max(np.abs(eig)))
    if worst < 1 - tols.STABILITY_MARGIN:
        result.add(
            True,
            f"F = A1 - LC is stable: its eigenvalues {format_poles(eig)} lie inside the unit "
            "circle.",
        )
    else:
        result.add(
            False,
            f"F = A1 - LC is not stable: its eigenvalues {format_poles(eig)} include "
            f"{worst:.4g} in magnitude, on or outside the unit circle. The LMI as printed is "
            "non-strict and accepts such a gain: the exercise's margin excludes it.",
        )
    if certified and from_solve is not False:
        block = np.block([[-Pm, F.T @ Pm], [Pm @ F, -Pm]])
        top = float(np.max(np.linalg.eigvalsh((block + block.T) / 2)))
        if top <= -float(margin) + tol * max(1.0, float(np.max(np.abs(Pm)))):
            result.add(True, "P certifies the LMI: [[-P, F'P], [PF, -P]] <= 0 for your L.")
        elif from_solve:  # L = P^-1 Y holds: one solve, of an LMI without the exercise's margin
            result.add(
                False,
                f"P does not certify this L with the exercise's margin: the LMI block has the "
                f"eigenvalue {top:.3g}, above {-float(margin):g}. L and P are from one solve, "
                f"so the LMI you solved lacks the margin: ask for the block <= -{float(margin):g} "
                "I, not <= 0.",
            )
        else:
            result.add(
                False,
                f"P does not certify this L: the LMI block has the eigenvalue {top:.3g}, above "
                f"{-float(margin):g}. Without Y, L cannot be traced to the solve: are L and P "
                "from the same solve?",
            )
    return result


def _P_definite(result: CheckResult, Pm: np.ndarray, tol: float) -> bool:
    sym = float(np.max(np.abs(Pm - Pm.T)))
    low = float(np.min(np.linalg.eigvalsh((Pm + Pm.T) / 2)))
    if sym > tol * max(1.0, float(np.max(np.abs(Pm)))) or low <= 0:
        result.add(
            False,
            f"P is not symmetric positive definite (smallest eigenvalue {low:.3g}, "
            f"asymmetry {sym:.2g}): declare it symmetric and ask for P >> 0.01 I in the LMI.",
        )
        return False
    return True


def _L_from_solve(
    result: CheckResult, L: np.ndarray, Pm: np.ndarray, Ym: np.ndarray | None, tol: float
) -> bool | None:
    """✓/✗: ``L = P^{-1} Y`` with the solver's values; None when ``Y`` was not given."""
    if Ym is None:
        result.add(
            False,
            "Y is not given, so L cannot be traced to the solve: pass the solver's value of Y "
            "too (the gain is L = P^-1 Y).",
        )
        return None
    ref = np.linalg.solve(Pm, Ym)
    if close(L, ref, tol):
        result.add(True, "L = P^-1 Y with the solver's P and Y.")
        return True
    if close(L, Ym, tol):
        hint = " Your L is Y itself: Y = PL, so P must be divided out."
    elif close(L, Pm @ Ym, tol):
        hint = " Your L is P Y: Y = PL, so L is P^-1 Y, not P Y."
    else:
        hint = " Are L, P and Y from the same solve?"
    result.add(False, f"L is not P^-1 Y with the solver's P and Y.{hint}")
    return False


@never_raises("Case study: moving the movable pole", "case_study.pole")
def case_study_pole(
    L: Any, pole: float, plant: Any = None, *, tol: float | None = None
) -> CheckResult:
    """Check a gain that moves the one movable pole to ``pole`` with ``LD = 0``.

    Parameters
    ----------
    L : array_like, shape (n, p)
        Your gain.
    pole : float
        Where the exercise asks to move the movable pole.
    plant : Plant, optional
        The plant; :func:`uio_teach.examples.dt_case_study` by default.
    tol : float, optional
        Tolerance of ``LD = 0`` and of the poles; default ``tolerances.CHECK_RTOL``.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> placed = ut.design_pmo(ut.examples.dt_case_study(), poles=[0.3])
    >>> checks.case_study_pole(placed.L, 0.3).passed
    True
    """
    tol = tols.CHECK_RTOL if tol is None else tol
    result = CheckResult("Case study: moving the movable pole")
    plant = get_plant(result, plant, "dt_case_study")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    L = read_matrix(result, "L", L, n, p, f"n x p = {n} x {p}")
    if L is None:
        return result
    pole = float(pole)
    decoupled = _LD(result, L, plant, tol, lmi=False)
    eig = np.sort_complex(np.linalg.eigvals(_error_matrix(plant, L)))
    fixed = np.asarray(check_existence(plant).fixed_modes, complex)
    if same_poles(eig, np.concatenate([[pole], fixed]), tol):
        result.add(
            True,
            f"F = A1 - LC has the poles {format_poles(eig)}: the movable pole is at "
            f"{pole:g}, the fixed ones {format_poles(fixed)} stay.",
        )
    elif np.any(np.abs(eig - pole) <= tol * max(1.0, abs(pole))) and not decoupled:
        result.add(
            False,
            f"F has the poles {format_poles(eig)}: {pole:g} is there, but the fixed poles moved "
            "too, which only a gain with LD != 0 can do (see above).",
        )
    else:
        result.add(
            False,
            f"F = A1 - LC has the poles {format_poles(eig)}, but the exercise asks to move the "
            f"movable pole to {pole:g} (the fixed ones {format_poles(fixed)} stay): with "
            "L = l N, which l puts the one observable mode of (A1, NC) there?",
        )
    return result


def _staircase(timepts: np.ndarray, amplitude: float, hold: int, seed: int) -> np.ndarray:
    """The experiment's staircase ``v`` with the asked amplitude, hold and seed, on ``timepts``."""
    run = CASE_STUDY.with_values(v_amplitude=amplitude, v_hold=hold)
    v = run.measurement_disturbance(seed=seed, timepts=timepts)
    return np.asarray(v(timepts), float).ravel()


@never_raises("Case study: the simulation with d and v", "case_study.simulation")
def case_study_simulation(
    response: Any,
    *,
    d: tuple[float, float] | None = None,
    v: tuple[float, int, int] | None = None,
    initial_state: Any = None,
    decay: float = 0.01,
    plant: Any = None,
    observer: Any = None,
) -> CheckResult:
    """Check a run with both unknown signals: the error ignores ``d`` and ``v`` and decays.

    Parameters
    ----------
    response : UIOResponse
        The result of :func:`uio_teach.simulate` on the case-study plant.
    d : (amplitude, frequency), optional
        The asked ``d[k] = amplitude sin(frequency k)``.
    v : (amplitude, hold, seed), optional
        The asked staircase ``v`` (levels uniform in ``[-amplitude, amplitude]``,
        drawn by ``numpy.random.default_rng(seed)``, a new one every ``hold`` steps).
    initial_state : array_like, optional
        The asked ``x[0]``.
    decay : float, optional
        The largest final error relative to the initial one.
    plant : Plant, optional
        The plant of the lab's set-up cell: the run must be of it.
    observer : PMO, optional
        Your observer (built from your LMI gain): the run must simulate it,
        started from ``z[0] = 0``.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.worked.case_study import CASE_STUDY as CS
    >>> pmo = ut.design_pmo(CS.plant(), method="lmi")
    >>> checks.case_study_simulation(CS.simulate(pmo)).passed
    True
    """
    result = CheckResult("Case study: the simulation with d and v")
    resp = read_response(result, response)
    if resp is None or not check_plant_of(result, resp, plant):
        return result
    _observer_as_asked(result, resp, observer)
    _signals_as_asked(result, resp, d, v, initial_state)
    _ignores_and_decays(result, resp, decay)
    return result


def _signals_as_asked(result: CheckResult, resp: Any, d: Any, v: Any, initial_state: Any) -> None:
    """✓/✗ on d (the unknown input), the staircase v and x[0], as the exercise asks."""
    t = np.asarray(resp.time, float)
    d_run = np.asarray(resp.inputs.d, float)
    vv = np.asarray(resp.inputs.v, float)
    if not np.any(d_run):
        result.add(False, "d is zero during the whole run: the unknown input acts on the state.")
    elif d is not None:
        want = float(d[0]) * np.sin(float(d[1]) * t)
        if np.allclose(
            d_run[0], want, rtol=0, atol=tols.CHECK_EXACT_RTOL * max(1.0, abs(float(d[0])))
        ):
            result.add(True, f"d is the asked {float(d[0]):g} sin({float(d[1]):g} k).")
        else:
            result.add(
                False,
                f"d is not the asked {float(d[0]):g} sin({float(d[1]):g} k): take its numbers "
                'from PARAMS["d"].',
            )
    else:
        result.add(True, "d acts during the run.")
    if vv.size == 0 or not np.any(vv):
        result.add(False, "v is zero during the whole run: the staircase v acts on y.")
    elif v is not None:
        want = _staircase(t, float(v[0]), int(v[1]), int(v[2]))
        if np.allclose(vv[0], want, rtol=0, atol=tols.CHECK_ZERO_ATOL):
            result.add(True, "v is the asked staircase.")
        else:
            result.add(
                False,
                'v is not the asked staircase (amplitude, hold and seed of PARAMS["v"]): use '
                "the v made in the cell at the top.",
            )
    else:
        result.add(True, "v acts during the run.")
    if initial_state is not None:
        want_x0 = np.asarray(initial_state, float).ravel()
        if want_x0.shape == resp.states[:, 0].shape and np.allclose(resp.states[:, 0], want_x0):
            result.add(True, f"x[0] = {numbers(want_x0)}, as asked.")
        else:
            result.add(
                False,
                f"the plant starts from x[0] = {numbers(resp.states[:, 0])}, but the exercise "
                f"asks for {numbers(want_x0)}"
                + (" (initial_state left out?)." if not np.any(resp.states[:, 0]) else "."),
            )


def _ignores_and_decays(result: CheckResult, resp: Any, decay: float) -> None:
    """✓/✗: the error is the same without d and v, and decays."""
    t = np.asarray(resp.time, float)
    diff, decoupled = rerun_without_unknown_inputs(resp)
    if decoupled:
        result.add(
            True,
            f"the error ignores d and v: run again without them, it is the same"
            f"{up_to(diff, 'largest difference')}.",
        )
    else:
        result.add(
            False,
            f"the error depends on the unknown signals: run again without d and v, it changes "
            f"by up to {diff:.3g}. Is the observer designed for this plant, with LD = 0?",
        )
    e0 = float(np.max(np.abs(resp.error[:, 0])))
    e1 = float(np.max(np.abs(resp.error[:, -1])))
    if e0 <= tols.CHECK_ZERO_ATOL:
        result.add(False, "the error is zero from the start: start the plant from x[0] != 0.")
    elif e1 <= decay * e0:
        result.add(True, f"the error decays: {e0:.3g} at k = 0, {e1:.2g} at k = {t[-1]:g}.")
    elif not decoupled:
        result.add(
            False,
            f"the error does not decay: {e1:.3g} at the end against {e0:.3g} at k = 0, because "
            "the unknown signals keep driving it (see above).",
        )
    else:
        result.add(
            False,
            f"the error has not decayed: {e1:.3g} at the end against {e0:.3g} at k = 0; run more "
            "steps.",
        )


def _observer_as_asked(result: CheckResult, resp: Any, observer: Any) -> None:
    """✓/✗: the run simulates the student's PMO, started from z[0] = 0."""
    family = str(getattr(resp.observer, "family", ""))
    if family != "PMO":
        result.add(
            False,
            f"the run simulates a {family or type(resp.observer).__name__}, but the exercise "
            "asks for the PMO built from your LMI gain.",
        )
    elif observer is not None:
        theirs = getattr(observer, "L", None)
        if theirs is None or not close(
            np.asarray(resp.observer.L), np.asarray(theirs), tols.CHECK_EXACT_RTOL
        ):
            result.add(
                False,
                "the run simulates another PMO than the one built from your LMI gain L.",
            )
        else:
            result.add(True, "the run simulates your PMO.")
    z0 = np.asarray(resp.observer_states[:, 0], float)
    if float(np.max(np.abs(z0))) > tols.CHECK_EXACT_RTOL * max(
        1.0, float(np.max(np.abs(resp.states)))
    ):
        result.add(
            False,
            f"the observer starts from z[0] = {numbers(z0)}, but the exercise asks for "
            "z[0] = 0 (ut.simulate's default).",
        )


@never_raises("Case study: the residual and D v", "case_study.residual")
def case_study_residual(Dv: Any, Nr: Any, response: Any, *, plant: Any = None) -> CheckResult:
    """Check ``D v`` (what the residual settles on) and ``N r`` (the part ``v`` cannot reach).

    Parameters
    ----------
    Dv : array_like, shape (p, N)
        ``D`` times the run's ``v``, one column per step.
    Nr : array_like, shape (1, N)
        The residual seen through a row ``N`` with ``N D = 0``.
    response : UIOResponse
        The run.
    plant : Plant, optional
        The plant of the lab's set-up cell.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.worked.case_study import CASE_STUDY as CS
    >>> plant = CS.plant()
    >>> run = CS.simulate(ut.design_pmo(plant, method="lmi"))
    >>> N = ut.linalg.left_null(plant.D)
    >>> checks.case_study_residual(plant.D @ run.inputs.v, N @ run.residual, run).passed
    True
    """
    result = CheckResult("Case study: the residual and D v")
    missing = [name for name, value in (("Dv", Dv), ("Nr", Nr)) if value is None]
    for name in missing:
        result.add(False, f"{name} is missing: compute it from the run (see the exercise).")
    resp = read_response(result, response)
    if resp is None or missing or not check_plant_of(result, resp, plant):
        return result
    plant = resp.plant
    N = resp.time.size
    p = plant.p
    Dv_m = read_matrix(result, "Dv", Dv, p, N, f"p x N = {p} x {N}: one column per step")
    Nr_m = read_matrix(result, "Nr", Nr, 1, N, f"1 x N = 1 x {N}")
    if Dv_m is None or Nr_m is None:
        return result
    v = np.asarray(resp.inputs.v, float)
    ref = plant.D @ v
    if close(Dv_m, ref, tols.CHECK_EXACT_RTOL):
        result.add(True, "Dv is D times the run's v.")
    else:
        result.add(
            False, "Dv is not D times the v of this run (its inputs.v, one column per step)."
        )
    r = np.asarray(resp.residual, float)
    late = resp.time >= resp.time[0] + 0.5 * (resp.time[-1] - resp.time[0])
    gap = float(np.max(np.abs(r - ref)[:, late]))
    result.add(
        None,
        f"over the second half of the run, max |r - Dv| = {gap:.2g}: r = Ce + Dv settles on Dv.",
    )
    Nd = left_null(plant.D)
    want = Nd @ r
    r_scale = max(1.0, float(np.max(np.abs(r))))
    got_big = float(np.max(np.abs(Nr_m)))
    want_big = float(np.max(np.abs(want)))
    if want_big <= tols.CHECK_EXACT_RTOL * r_scale:
        match = got_big <= tols.CHECK_RUN_RTOL * r_scale
    else:
        k = float(np.vdot(want, Nr_m) / np.vdot(want, want))
        match = abs(k) > tols.CHECK_EXACT_RTOL and np.allclose(
            Nr_m, k * want, rtol=0, atol=tols.CHECK_RUN_RTOL * abs(k) * r_scale
        )
    if match:
        tail = float(np.max(np.abs(Nr_m[:, late])))
        result.add(
            True,
            f"Nr is the residual seen through a row N with N D = 0: v does not reach it "
            f"(max |N r| over the second half: {tail:.2g}).",
        )
    else:
        result.add(
            False,
            f"Nr is not the residual seen through a row N with N D = 0 (its entries reach "
            f"{got_big:.3g}): N is a row with N D = 0, applied to the run's residual.",
        )
    return result


@never_raises("Case study: the plot of the residual and D v", "case_study.plot")
def case_study_plot(fig: Any, response: Any, *, plant: Any = None) -> CheckResult:
    """Check the figure of the residual ``r`` with ``D v``, and of ``N r``, against the step ``k``.

    The checks: every residual component ``r_i`` and every ``(Dv)_i`` of the run
    is drawn in one panel; ``N r`` (for the row ``N`` with ``N D = 0``, any
    scale) in another; the curves against the run's steps, with an x-label that
    says steps; the panels labelled (``r``, ``Dv``, ``N r``).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    response : UIOResponse
        The run that was plotted.
    plant : Plant, optional
        The plant of the lab's set-up cell.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from matplotlib.figure import Figure
    >>> from uio_teach import checks
    >>> from uio_teach.worked.case_study import CASE_STUDY as CS
    >>> plant = CS.plant()
    >>> run = CS.simulate(ut.design_pmo(plant, method="lmi"))
    >>> fig = Figure()
    >>> ax_r, ax_n = fig.subplots(2, 1, sharex=True)
    >>> _ = ax_r.plot(run.time, run.residual.T, label=["r1", "r2"])
    >>> _ = ax_r.plot(run.time, (plant.D @ run.inputs.v).T, label=["(Dv)1", "(Dv)2"])
    >>> _ = ax_r.set_ylabel("residual r and Dv")
    >>> N = ut.linalg.left_null(plant.D)
    >>> _ = ax_n.plot(run.time, (N @ run.residual).T); _ = ax_n.set_ylabel("N r")
    >>> _ = ax_n.set_xlabel("step k")
    >>> checks.case_study_plot(fig, run).passed
    True
    """
    result = CheckResult("Case study: the plot of the residual and D v")
    resp = read_response(result, response)
    fig = read_figure(result, fig)
    if resp is None or fig is None or not check_plant_of(result, resp, plant):
        return result
    t = np.asarray(resp.time, float)
    plotted = plotted_axes(result, fig, t)
    if plotted is None:
        return result
    axes = plotted[0]
    N = t.size
    r = np.asarray(resp.residual, float)
    Dv = resp.plant.D @ np.asarray(resp.inputs.v, float)
    Nr = (left_null(resp.plant.D) @ r).ravel()
    scale = max(1.0, float(np.max(np.abs(r))))

    def rows_in(ax: Any, M: np.ndarray) -> set[int]:
        ys = [np.asarray(ln.get_ydata(), float) for ln in ax.get_lines()]
        ys = [y for y in ys if y.shape == (N,)]
        return {
            i
            for i in range(M.shape[0])
            for y in ys
            if np.allclose(y, M[i], rtol=0, atol=tols.CHECK_EXACT_RTOL * scale)
        }

    def shows_Nr(ax: Any) -> bool:
        tiny = float(np.max(np.abs(Nr))) <= tols.CHECK_EXACT_RTOL * scale
        for ln in ax.get_lines():
            y = np.asarray(ln.get_ydata(), float)
            if y.shape != (N,):
                continue
            if tiny:
                if float(np.max(np.abs(y))) <= tols.CHECK_RUN_RTOL * scale:
                    return True
                continue
            k = float(np.dot(Nr, y) / np.dot(Nr, Nr))
            if abs(k) > tols.CHECK_EXACT_RTOL and np.linalg.norm(
                y - k * Nr
            ) <= tols.CHECK_RTOL * np.linalg.norm(y):
                return True
        return False

    p = r.shape[0]
    both = [ax for ax in axes if len(rows_in(ax, r)) == p and len(rows_in(ax, Dv)) == p]
    if both:
        result.add(True, "one panel shows every component of the residual r with D v.")
    elif any(len(rows_in(ax, r)) == p for ax in axes):
        result.add(
            False,
            "the residual is drawn, but not next to D v (every component) in the same panel: "
            "the exercise compares the two.",
        )
    elif any(rows_in(ax, resp.outputs) for ax in axes):
        result.add(False, "a panel shows the outputs y, not the residual r = y - C x̂.")
    else:
        result.add(False, "no panel shows the residual r of the run (every component).")
    n_axes = [ax for ax in axes if shows_Nr(ax)]
    if n_axes:
        result.add(True, "another panel shows N r, the residual seen through N with N D = 0.")
    else:
        result.add(
            False,
            "no panel shows N r, the residual seen through the row N with N D = 0 (the "
            "combination v does not reach).",
        )
    for ax in both[:1]:
        text = " ".join(panel_texts(ax))
        if not (re.search(r"\bresidual|\br\b|\br_?\d", text) and re.search(r"D\s*v", text)):
            result.add(
                False,
                "the panel of r and D v does not say which curve is which: label it (y-label "
                "or legend naming r and Dv).",
            )
    for ax in n_axes[:1]:
        if not re.search(r"N\s*r|N\s*\\?cdot\s*r", " ".join(panel_texts(ax))):
            result.add(False, "the panel of N r is not labelled as N r.")
    return result
