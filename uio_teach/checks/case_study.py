"""Checks of the case-study lab: the projection-operator observer of a discrete-time plant.

* :func:`case_study_projection` -- ``M``: ``(I - MC)B2 = 0`` and ``MD = 0``;
* :func:`case_study_lmi` -- the gain ``L`` of the LMI: ``LD = 0``, a stable
  ``F = A1 - LC`` (and, with ``P``, the LMI itself);
* :func:`case_study_pole` -- a gain that moves the one movable pole to the
  asked place, with ``LD = 0`` (the two poles at 0.5 stay);
* :func:`case_study_simulation` -- a run with ``u2`` and ``v`` as asked: the
  error ignores both and decays;
* :func:`case_study_residual` -- ``D v`` and the combination ``N r`` that
  ``v`` does not reach.

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach import checks
>>> plant = ut.examples.dt_case_study()
>>> C, B2, D = plant.C, plant.E, plant.D
>>> M = np.hstack([B2, np.zeros((3, 1))]) @ np.linalg.pinv(np.hstack([C @ B2, D]))
>>> checks.case_study_projection(M).passed
True
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._display import format_matrix_line, format_poles
from ._common import (
    CheckResult,
    _close,
    _get_plant,
    _never_raises,
    _numbers,
    _read_matrix,
    _up_to,
)

__all__ = [
    "case_study_projection",
    "case_study_lmi",
    "case_study_pole",
    "case_study_simulation",
    "case_study_residual",
]


def _M_ref(plant) -> np.ndarray:
    """The projection matrix ``M = [B2 0][C B2 D]^+`` of the package's design."""
    from ..existence import decoupling

    return decoupling(plant).M


def _small(X: np.ndarray, scale: float, tol: float) -> tuple[bool, float]:
    big = float(np.max(np.abs(X))) if X.size else 0.0
    return big <= tol * max(1.0, scale), big


@_never_raises("Case study: the projection matrix M", "case_study.projection")
def case_study_projection(M: Any, plant: Any = None, *, tol: float = 1e-9) -> CheckResult:
    """Check ``M``: it removes ``u2``, ``(I - MC)B2 = 0``, and the disturbance, ``MD = 0``.

    Parameters
    ----------
    M : array_like, shape (n, p)
        Your ``M``.
    plant : Plant, optional
        The plant; :func:`uio_teach.examples.dt_case_study` by default.
    tol : float, optional
        Tolerance of the two identities (relative to the largest entry of ``M``).

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
    >>> "Your M is B2 (CB2)^+, which ignores D" in checks.case_study_projection(M).failures[0]
    True
    """
    result = CheckResult("Case study: the projection matrix M")
    plant = _get_plant(result, plant, "dt_case_study")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    M = _read_matrix(result, "M", M, n, p, f"n x p = {n} x {p}")
    if M is None:
        return result
    C, B2, D = plant.C, plant.E, plant.D
    scale = float(np.max(np.abs(M)))
    ok, big = _small((np.eye(n) - M @ C) @ B2, scale, tol)
    ref = _M_ref(plant)
    if ok:
        result.add(True, f"(I - MC)B2 = 0{_up_to(big, 'largest entry')}: u2 is projected out.")
    else:
        if _close(M, np.round(ref, 4), 1e-9) or _close(M, np.round(ref, 2), 1e-9):
            hint = " Your M is the printed one, rounded: compute it at full precision."
        elif _close(M, -ref, 1e-9):
            hint = " Your M is -[B2 0][CB2 D]^+: drop the minus sign."
        else:
            hint = " M must satisfy M [CB2 D] = [B2 0]: M = [B2 0] [CB2 D]^+ (np.linalg.pinv)."
        result.add(
            False,
            f"(I - MC)B2 is not 0: it is {format_matrix_line((np.eye(n) - M @ C) @ B2)} "
            f"(largest entry {big:.3g}), so u2 still drives the error.{hint}",
        )
    ok, big = _small(M @ D, scale, tol)
    if ok:
        result.add(True, f"MD = 0{_up_to(big, 'largest entry')}: v does not enter x̂ through My.")
    else:
        only_b2 = B2 @ np.linalg.pinv(C @ B2)
        hint = (
            " Your M is B2 (CB2)^+, which ignores D: stack [CB2 D] and [B2 0] instead."
            if _close(M, only_b2, 1e-9)
            else " M must also satisfy MD = 0: M = [B2 0] [CB2 D]^+."
        )
        result.add(
            False,
            f"MD is not 0: MD = {format_matrix_line(M @ D)} (largest entry {big:.3g}), so the "
            f"disturbance v enters the estimate directly.{hint}",
        )
    return result


def _error_matrix(plant, L: np.ndarray) -> np.ndarray:
    """``F = (I - M C) A - L C`` with the package's ``M``."""
    from ..existence import decoupling

    return decoupling(plant).A1 - L @ plant.C


def _LD(result: CheckResult, L: np.ndarray, plant, tol: float) -> bool:
    LD = L @ plant.D
    ok, big = _small(LD, float(np.max(np.abs(L))), tol)
    if ok:
        result.add(True, f"LD = 0{_up_to(big, 'largest entry')}: v does not enter through y - Cx̂.")
        return True
    from .. import examples

    pub = examples.DT_CASE_STUDY_PUBLISHED.L
    hint = (
        " Your L is the printed one, rounded to 4 decimals; rounding moves it off LD = 0. Use "
        "the gain of your solver."
        if _close(L, pub, 1e-9)
        else " Add the constraint Y @ D == 0 to the LMI (Y = PL), or build L as l N with N D = 0."
    )
    result.add(
        False,
        f"LD is not 0: LD = {format_matrix_line(LD)} (largest entry {big:.3g}), so the "
        f"disturbance v drives the error.{hint}",
    )
    return False


@_never_raises("Case study: the gain L from the LMI", "case_study.lmi")
def case_study_lmi(L: Any, P: Any = None, plant: Any = None, *, tol: float = 1e-6) -> CheckResult:
    """Check the LMI gain ``L``: ``LD = 0``, ``F = A1 - LC`` stable; with ``P``, the LMI holds.

    Parameters
    ----------
    L : array_like, shape (n, p)
        Your gain (``L = P^{-1} Y`` from the solver).
    P : array_like, shape (n, n), optional
        Your certificate: symmetric positive definite with
        ``[[-P, F^T P], [P F, -P]] <= 0``.
    plant : Plant, optional
        The plant; :func:`uio_teach.examples.dt_case_study` by default.
    tol : float, optional
        Tolerance of ``LD = 0`` and of the LMI (a solver meets them to about 1e-8).

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> pmo = ut.design_pmo(ut.examples.dt_case_study(), method="lmi")
    >>> checks.case_study_lmi(pmo.L, pmo.lmi_certificate).passed
    True
    """
    result = CheckResult("Case study: the gain L from the LMI")
    plant = _get_plant(result, plant, "dt_case_study")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    L = _read_matrix(result, "L", L, n, p, f"n x p = {n} x {p}")
    Pm = _read_matrix(result, "P", P, n, n, f"n x n = {n} x {n}") if P is not None else None
    if L is None or (P is not None and Pm is None):
        return result
    _LD(result, L, plant, tol)
    F = _error_matrix(plant, L)
    eig = np.linalg.eigvals(F)
    worst = float(np.max(np.abs(eig)))
    if worst < 1 - 1e-9:
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
            "non-strict and accepts such a gain: add a margin (block << -0.01 I).",
        )
    if Pm is not None:
        sym = float(np.max(np.abs(Pm - Pm.T)))
        low = float(np.min(np.linalg.eigvalsh((Pm + Pm.T) / 2)))
        if sym > tol * max(1.0, float(np.max(np.abs(Pm)))) or low <= 0:
            result.add(
                False,
                f"P is not symmetric positive definite (smallest eigenvalue {low:.3g}, "
                f"asymmetry {sym:.2g}): declare it cp.Variable((n, n), symmetric=True) with "
                "P >> 0.01 I.",
            )
        else:
            block = np.block([[-Pm, F.T @ Pm], [Pm @ F, -Pm]])
            top = float(np.max(np.linalg.eigvalsh((block + block.T) / 2)))
            if top <= tol * max(1.0, float(np.max(np.abs(Pm)))):
                result.add(True, "P certifies the LMI: [[-P, F'P], [PF, -P]] <= 0.")
            else:
                result.add(
                    False,
                    f"P does not certify this L: the LMI block has the eigenvalue {top:.3g} > 0. "
                    "Is L = np.linalg.solve(P.value, Y.value) from the same solve?",
                )
    return result


@_never_raises("Case study: moving the movable pole", "case_study.pole")
def case_study_pole(L: Any, pole: float, plant: Any = None, *, tol: float = 1e-6) -> CheckResult:
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
        Tolerance of ``LD = 0`` and of the poles.

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
    result = CheckResult("Case study: moving the movable pole")
    plant = _get_plant(result, plant, "dt_case_study")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    L = _read_matrix(result, "L", L, n, p, f"n x p = {n} x {p}")
    if L is None:
        return result
    pole = float(pole)
    decoupled = _LD(result, L, plant, tol)
    eig = np.sort_complex(np.linalg.eigvals(_error_matrix(plant, L)))
    has = np.abs(eig - pole) <= tol * max(1.0, abs(pole))
    fixed = np.abs(eig - 0.5) <= 1e-6
    if has.any() and (fixed & ~has).sum() >= 2:
        result.add(
            True,
            f"F = A1 - LC has the poles {format_poles(eig)}: the movable pole is at "
            f"{pole:g}, the two fixed poles stay at 0.5.",
        )
    elif has.any() and not decoupled:
        result.add(
            False,
            f"F has the poles {format_poles(eig)}: {pole:g} is there, but the poles at 0.5 moved "
            "too, which only a gain with LD != 0 can do (see above).",
        )
    else:
        result.add(
            False,
            f"F = A1 - LC has the poles {format_poles(eig)}, but the exercise asks to move the "
            f"movable pole to {pole:g} (the two at 0.5 stay): "
            f"ut.design_pmo(plant, poles=[{pole:g}]), or L = l N with the l that puts it there.",
        )
    return result


def _read_resp(result: CheckResult, response: Any):
    from .responses import _read_response

    return _read_response(result, response)


def _staircase(timepts: np.ndarray, amplitude: float, hold: int, seed: int) -> np.ndarray:
    from ..signals import piecewise_constant

    rng = np.random.default_rng(seed)
    switch = np.arange(0, timepts[-1] + 1, hold)
    levels = rng.uniform(-amplitude, amplitude, switch.size)
    return np.asarray(piecewise_constant(switch, levels)(timepts), float).ravel()


@_never_raises("Case study: the simulation with u2 and v", "case_study.simulation")
def case_study_simulation(
    response: Any,
    *,
    u2: tuple[float, float] | None = None,
    v: tuple[float, int, int] | None = None,
    initial_state: Any = None,
    decay: float = 0.01,
) -> CheckResult:
    """Check a run with both unknown signals: the error ignores ``u2`` and ``v`` and decays.

    Parameters
    ----------
    response : UIOResponse
        The result of :func:`uio_teach.simulate` on the case-study plant.
    u2 : (amplitude, frequency), optional
        The asked ``u2[k] = amplitude sin(frequency k)``.
    v : (amplitude, hold, seed), optional
        The asked staircase ``v`` (levels uniform in ``[-amplitude, amplitude]``,
        drawn by ``numpy.random.default_rng(seed)``, a new one every ``hold`` steps).
    initial_state : array_like, optional
        The asked ``x[0]``.
    decay : float, optional
        The largest final error relative to the initial one.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.experiments import CASE_STUDY as CS
    >>> pmo = ut.design_pmo(CS.plant(), method="lmi")
    >>> checks.case_study_simulation(CS.simulate(pmo)).passed
    True
    """
    from ..simulation import simulate

    result = CheckResult("Case study: the simulation with u2 and v")
    resp = _read_resp(result, response)
    if resp is None:
        return result
    t = np.asarray(resp.time, float)
    d = np.asarray(resp.inputs.d, float)
    vv = np.asarray(resp.inputs.v, float)
    if not np.any(d):
        result.add(False, "u2 is zero during the whole run: pass d=u2 to ut.simulate.")
    elif u2 is not None:
        want = float(u2[0]) * np.sin(float(u2[1]) * t)
        if np.allclose(d[0], want, rtol=0, atol=1e-9 * max(1.0, abs(float(u2[0])))):
            result.add(True, f"u2 is the asked {float(u2[0]):g} sin({float(u2[1]):g} k).")
        else:
            result.add(
                False,
                f"u2 is not the asked {float(u2[0]):g} sin({float(u2[1]):g} k): take its numbers "
                'from PARAMS["u2"].',
            )
    else:
        result.add(True, "u2 acts during the run.")
    if vv.size == 0 or not np.any(vv):
        result.add(False, "v is zero during the whole run: pass v=v to ut.simulate.")
    elif v is not None:
        want = _staircase(t, float(v[0]), int(v[1]), int(v[2]))
        if np.allclose(vv[0], want, rtol=0, atol=1e-12):
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
            result.add(True, f"x[0] = {_numbers(want_x0)}, as asked.")
        else:
            result.add(
                False,
                f"the plant starts from x[0] = {_numbers(resp.states[:, 0])}, but the exercise "
                f"asks for {_numbers(want_x0)}.",
            )
    quiet = simulate(
        resp.plant,
        resp.observer,
        resp.time,
        u=resp.inputs.u if resp.plant.m else None,
        initial_state=resp.states[:, 0],
        observer_state=resp.observer_states[:, 0],
    )
    diff = float(np.max(np.abs(resp.error - quiet.error)))
    decoupled = diff <= 1e-8 * max(1.0, float(np.max(np.abs(resp.states))))
    if decoupled:
        result.add(
            True,
            f"the error ignores u2 and v: run again without them, it is the same"
            f"{_up_to(diff, 'largest difference')}.",
        )
    else:
        result.add(
            False,
            f"the error depends on the unknown signals: run again without u2 and v, it changes "
            f"by up to {diff:.3g}. Is the observer designed for this plant, with LD = 0?",
        )
    e0 = float(np.max(np.abs(resp.error[:, 0])))
    e1 = float(np.max(np.abs(resp.error[:, -1])))
    if e0 <= 1e-12:
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
    return result


@_never_raises("Case study: the residual and D v", "case_study.residual")
def case_study_residual(Dv: Any, Nr: Any, response: Any) -> CheckResult:
    """Check ``D v`` (what the residual settles on) and ``N r`` (the part ``v`` cannot reach).

    Parameters
    ----------
    Dv : array_like, shape (p, N)
        ``D`` times the run's ``v``, one column per step.
    Nr : array_like, shape (1, N)
        The residual seen through a row ``N`` with ``N D = 0``.
    response : UIOResponse
        The run.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.experiments import CASE_STUDY as CS
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
    resp = _read_resp(result, response)
    if resp is None or missing:
        return result
    plant = resp.plant
    N = resp.time.size
    p = plant.p
    Dv_m = _read_matrix(result, "Dv", Dv, p, N, f"p x N = {p} x {N}: one column per step")
    Nr_m = _read_matrix(result, "Nr", Nr, 1, N, f"1 x N = 1 x {N}")
    if Dv_m is None or Nr_m is None:
        return result
    v = np.asarray(resp.inputs.v, float)
    ref = plant.D @ v
    if _close(Dv_m, ref, 1e-9):
        result.add(True, "Dv is D times the run's v.")
    else:
        result.add(False, "Dv is not D @ resp.inputs.v (the disturbance of this run times D).")
    r = np.asarray(resp.residual, float)
    late = resp.time >= resp.time[0] + 0.5 * (resp.time[-1] - resp.time[0])
    gap = float(np.max(np.abs(r - ref)[:, late]))
    result.add(
        None,
        f"over the second half of the run, max |r - Dv| = {gap:.2g}: r = Ce + Dv settles on Dv.",
    )
    from ..linalg import left_null

    Nd = left_null(plant.D)
    want = Nd @ r
    r_scale = max(1.0, float(np.max(np.abs(r))))
    got_big = float(np.max(np.abs(Nr_m)))
    want_big = float(np.max(np.abs(want)))
    if want_big <= 1e-9 * r_scale:
        match = got_big <= 1e-8 * r_scale
    else:
        k = float(np.vdot(want, Nr_m) / np.vdot(want, want))
        match = abs(k) > 1e-9 and np.allclose(Nr_m, k * want, rtol=0, atol=1e-8 * abs(k) * r_scale)
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
            f"{got_big:.3g}, N r reaches {want_big:.2g}): take N = ut.linalg.left_null(D) and "
            "Nr = N @ resp.residual.",
        )
    return result
