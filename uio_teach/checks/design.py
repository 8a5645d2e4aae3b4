"""Check of requirement 1 of the PA9 lab: the matrices ``H``, ``T``, ``K1`` (``F``, ``K2``).

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach.checks import pa9_design
>>> plant = ut.examples.pa9()
>>> H = plant.E @ np.linalg.pinv(plant.C @ plant.E)
>>> T = np.eye(3) - H @ plant.C
>>> pa9_design(H, T, ut.examples.PA9_PUBLISHED.K1).passed
True
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import examples
from .. import tolerances as tols
from .._display import format_matrix_line, format_poles
from ..linalg import pinv, sort_poles
from .common import (
    CheckResult,
    as_poles,
    close,
    get_plant,
    looks_two_decimals,
    maxdiff,
    never_raises,
    read_matrix,
    same_plant,
    same_poles,
    stability,
    up_to,
)

__all__ = ["pa9_design"]


_OMITTED: Any = type("_Omitted", (), {"__repr__": lambda self: "<omitted>"})()


@never_raises("Practical Assignment 9: the observer design", "pa9.design")
def pa9_design(
    H: Any,
    T: Any,
    K1: Any,
    F: Any = _OMITTED,
    K2: Any = _OMITTED,
    plant: Any = None,
    *,
    poles: Any = None,
    tol: float | None = None,
) -> CheckResult:
    """Check a decoupling-observer design against the equations (8) of the assignment.

    The checks, in order: the shapes; ``(I - HC)E = 0`` (the disturbance is
    cancelled); ``T = I - HC``; ``F = TA - K1C``; ``K2 = FH``; ``F`` stable
    (its eigenvalues in the open left half-plane, or in the unit disk for a
    discrete plant); with ``poles``, the eigenvalues of ``F`` are the poles
    the exercise asks for. Each relation is checked against your own ``H`` and
    ``K1``, the two matrices you are free to choose: any ``H`` with
    ``HCE = E`` is accepted, not only ``E (CE)^+``.

    Parameters
    ----------
    H : array_like, shape (n, p)
        Your ``H``.
    T : array_like, shape (n, n)
        Your ``T``.
    K1 : array_like, shape (n, p)
        Your output-injection gain ``K1``.
    F : array_like, shape (n, n), optional
        Your ``F``; when omitted, ``TA - K1C`` is computed from your ``H`` and
        ``K1`` and only its stability is checked. Passing ``None`` (an answer
        not written yet) is a ✗.
    K2 : array_like, shape (n, p), optional
        Your ``K2``; when omitted, it is not checked. Passing ``None`` is a ✗.
    plant : Plant, optional
        The plant; the assignment's example :func:`uio_teach.examples.pa9` by
        default.
    poles : sequence of complex, optional
        The poles the exercise asks for (e.g. ``[-1, -2, -3]``): the eigenvalues
        of ``F`` must be these, each to ``tol`` relative.
    tol : float, optional
        Relative tolerance of the equalities (entries are compared with
        ``tol * max(1, largest entry)``). Full-precision NumPy results agree to
        about 1e-15; numbers typed with 2 decimals do not pass. Default
        ``tolerances.CHECK_RTOL``.

    Returns
    -------
    CheckResult
        One ✓ or ✗ message per check; ``.passed`` is True when all hold.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> plant = ut.examples.pa9()
    >>> A, C, E = plant.A, plant.C, plant.E
    >>> H = E @ np.linalg.pinv(C @ E)
    >>> T = np.eye(3) - H @ C
    >>> K1 = ut.examples.PA9_PUBLISHED.K1
    >>> F = T @ A - K1 @ C
    >>> print(checks.pa9_design(H, T, K1, F, F @ H))
    Practical Assignment 9: the observer design
      ✓ (I - HC)E = 0 (up to rounding): H cancels the disturbance.
      ✓ T = I - HC.
      ✓ F = TA - K1C.
      ✓ K2 = FH.
      ✓ F is stable: its eigenvalues -3.001, -1.991, -1 are in the open left half-plane, so the error e' = F e decays.
      => All 5 checks passed.

    A sign error in ``K2`` is named:

    >>> checks.pa9_design(H, T, K1, F, -F @ H).failures
    ['K2 is -FH: the sign is flipped. The condition (A - K1C - HCA)H - K2 = 0 of eq. (7) gives K2 = FH.']
    """  # noqa: E501
    tol = tols.CHECK_RTOL if tol is None else tol
    result = CheckResult("Practical Assignment 9: the observer design")
    plant = get_plant(result, plant)
    if plant is None:
        return result
    n, p = plant.n, plant.p
    what_np = f"n x p = {n} x {p}: one row per state, one column per output"
    what_nn = f"n x n = {n} x {n}"
    H = read_matrix(result, "H", H, n, p, what_np)
    T = read_matrix(result, "T", T, n, n, what_nn)
    K1 = read_matrix(result, "K1", K1, n, p, what_np)
    F_given = F is not _OMITTED
    K2_given = K2 is not _OMITTED
    F = read_matrix(result, "F", F, n, n, what_nn) if F_given else None
    K2 = read_matrix(result, "K2", K2, n, p, what_np) if K2_given else None
    wanted = _read_poles(result, poles, n) if poles is not None else None
    if poles is not None and wanted is None:
        return result
    if H is None or T is None or K1 is None or (F_given and F is None) or (K2_given and K2 is None):
        result.add(None, "Fix the shapes first; the design equations are checked afterwards.")
        return result
    _cancels(result, plant, H, tol)
    T_ok = _T_is_I_minus_HC(result, plant, H, T, tol)
    T_ref = np.eye(n) - H @ plant.C
    F_ref = T_ref @ plant.A - K1 @ plant.C
    if F_given:
        _F_is_TA_minus_K1C(result, plant, T, T_ok, K1, F, F_ref, tol)
    else:
        result.add(None, "F not given: F = TA - K1C is computed from your H and K1.")
    if K2_given:
        _K2_is_FH(result, H, K1, F if F_given else None, K2, F_ref, tol)
    eig = _stable(result, plant, F if F_given else F_ref, F_given)
    if wanted is not None:
        which = "F" if F_given else "F = TA - K1C"
        _poles_asked(result, eig, wanted, which, plant.A - K1 @ plant.C, F_ref, F_given, tol)
    return result


def _cancels(result: CheckResult, plant: Any, H: np.ndarray, tol: float) -> None:
    """Step 1: ``(I - HC)E = 0``, the disturbance cancelled."""
    C, E = plant.C, plant.E
    H_ref = E @ pinv(C @ E)
    R = (np.eye(plant.n) - H @ C) @ E
    big = float(np.max(np.abs(R))) if R.size else 0.0
    if big <= tol * max(1.0, float(np.max(np.abs(E))) if E.size else 1.0):
        result.add(True, f"(I - HC)E = 0{up_to(big, 'largest entry')}: H cancels the disturbance.")
        return
    if looks_two_decimals(H, H_ref):
        printed = same_plant(plant, examples.pa9())
        hint = (
            " Your H has only 2 decimals"
            + (", as the assignment prints it" if printed else "")
            + "; numbers cut or rounded to 2 decimals are not exact, so the disturbance is "
            "not fully cancelled. Compute H at full precision from E and C instead of typing it."
        )
    elif close(H, -H_ref, tols.CHECK_RTOL):
        hint = " Your H is -E(CE)^+: check the sign."
    else:
        hint = (
            " H must solve HCE = E. CE is not square, so it has no inverse: which generalized "
            "inverse gives a solution (see the toolbox chapter)?"
        )
    result.add(
        False,
        f"H does not satisfy (I - HC)E = 0: (I - HC)E = {format_matrix_line(R)} "
        f"(largest entry {big:.3g}), so the disturbance d still drives the error.{hint}",
    )


def _differs(name: str, ref: str, X: np.ndarray, Y: np.ndarray) -> str:
    """Where ``X`` and ``Y`` differ most, without giving the expected value away."""
    diff, idx = maxdiff(X, Y)
    size = "slightly (rounding?)" if diff <= 0.01 * max(1.0, float(np.max(np.abs(Y)))) else "a lot"
    return f"{name} is not {ref}: they differ most in entry [{idx[0]}, {idx[1]}], {size}"


def _T_is_I_minus_HC(
    result: CheckResult, plant: Any, H: np.ndarray, T: np.ndarray, tol: float
) -> bool:
    """Step 2: ``T = I - HC`` with the student's own ``H``."""
    eye = np.eye(plant.n)
    C = plant.C
    T_ref = eye - H @ C
    if close(T, T_ref, tol):
        result.add(True, "T = I - HC.")
        return True
    if close(T, -T_ref, tol):
        hint = " Your T is HC - I: the sign is flipped."
    elif close(T, H @ C, tol):
        hint = " Your T is HC; it must be I - HC."
    elif looks_two_decimals(T, T_ref) or looks_two_decimals(
        T, eye - plant.E @ pinv(C @ plant.E) @ C
    ):
        hint = " Your T has only 2 decimals; compute it from your H instead of typing it."
    else:
        hint = " Compute it from your own H, with the identity of size n."
    result.add(False, f"{_differs('T', 'I - HC', T, T_ref)}.{hint}")
    return False


def _F_is_TA_minus_K1C(
    result: CheckResult,
    plant: Any,
    T: np.ndarray,
    T_ok: bool,
    K1: np.ndarray,
    F: np.ndarray,
    F_ref: np.ndarray,
    tol: float,
) -> None:
    """Step 3: ``F = TA - K1C``."""
    A, C = plant.A, plant.C
    if close(F, F_ref, tol):
        result.add(True, "F = TA - K1C.")
        return
    if not T_ok and close(F, T @ A - K1 @ C, tol):
        hint = " It is TA - K1C with your T, but your T is wrong (see above): fix T first."
    elif close(F, A - K1 @ C, tol):
        hint = " Your F is A - K1C: the T is missing, F = TA - K1C."
    elif close(F, F_ref + 2 * K1 @ C, tol):
        hint = " Your F is TA + K1C: the sign of K1C is flipped."
    else:
        hint = " Compute it from your T, A, K1 and C, in the order of eq. (8)."
    result.add(False, f"{_differs('F', 'TA - K1C', F, F_ref)}.{hint}")


def _K2_is_FH(
    result: CheckResult,
    H: np.ndarray,
    K1: np.ndarray,
    F: np.ndarray | None,
    K2: np.ndarray,
    F_ref: np.ndarray,
    tol: float,
) -> None:
    """Step 4: ``K2 = FH``."""
    K2_ref = F_ref @ H
    if close(K2, K2_ref, tol):
        result.add(True, "K2 = FH.")
    elif close(K2, -K2_ref, tol):
        result.add(
            False,
            "K2 is -FH: the sign is flipped. The condition (A - K1C - HCA)H - K2 = 0 of "
            "eq. (7) gives K2 = FH.",
        )
    elif F is not None and close(K2, F @ H, tol):
        result.add(False, "K2 = FH with your F, but your F is wrong (see above): fix F first.")
    else:
        hint = (
            " Your K2 is K1 - FH; K2 alone is FH."
            if close(K2, K1 - K2_ref, tol)
            else " Which product of eq. (8) gives K2?"
        )
        result.add(False, f"{_differs('K2', 'FH', K2, K2_ref)}.{hint}")


def _stable(result: CheckResult, plant: Any, F_used: np.ndarray, F_given: bool) -> np.ndarray:
    """Step 5: ``F`` stable; returns its eigenvalues."""
    which = "F" if F_given else "F = TA - K1C"
    stable, eig, bad = stability(F_used, plant.is_discrete)
    region = "inside the unit circle" if plant.is_discrete else "in the open left half-plane"
    law = "e[k+1] = F e[k]" if plant.is_discrete else "e' = F e"
    if stable:
        result.add(
            True,
            f"{which} is stable: its eigenvalues {format_poles(eig)} are {region}, so the error "
            f"{law} decays.",
        )
    else:
        result.add(
            False,
            f"{which} is not stable: the eigenvalue{'s' if len(bad) > 1 else ''} "
            f"{format_poles(bad)} "
            f"{'are' if len(bad) > 1 else 'is'} not {region}, so the error {law} does not "
            "decay. Choose K1 so that TA - K1C has the poles of the exercise (pole placement "
            "for the pair (TA, C), by duality).",
        )
    return eig


def _read_poles(result: CheckResult, poles: Any, n: int) -> np.ndarray | None:
    """The poles an exercise asks for, as a sorted complex array (a ✗ if they are unusable)."""
    try:
        arr = as_poles(poles)
    except (TypeError, ValueError):
        result.add(False, f"poles must be a list of {n} numbers, got {poles!r}.")
        return None
    if arr.size != n or not np.all(np.isfinite(arr)):
        result.add(False, f"poles must be a list of {n} finite numbers, got {poles!r}.")
        return None
    return sort_poles(arr)


def _poles_asked(
    result: CheckResult,
    eig: np.ndarray,
    wanted: np.ndarray,
    which: str,
    F_without_T: np.ndarray,
    F_ref: np.ndarray,
    F_given: bool,
    tol: float,
) -> None:
    """A ✓ if the eigenvalues ``eig`` of ``F`` are the poles asked for (each to ``tol``
    relative), else a ✗ with the cause."""
    if same_poles(eig, wanted, tol):
        result.add(True, f"{which} has the poles asked for, {format_poles(wanted)}.")
        return
    if same_poles(np.linalg.eigvals(F_without_T), wanted, tol):
        hint = (
            " Your K1 places the poles of A - K1C, not of TA - K1C: place them for the pair "
            "(TA, C)."
        )
    elif (
        F_given
        and not same_poles(np.linalg.eigvals(F_ref), eig, tol)
        and same_poles(np.linalg.eigvals(F_ref), wanted, tol)
    ):
        hint = " TA - K1C has them, so your F is not TA - K1C (see above)."
    else:
        hint = " Place them for the pair (TA, C) with the poles of PARAMS (duality)."
    result.add(
        False,
        f"{which} has the poles {format_poles(eig)}, but the exercise asks for "
        f"{format_poles(wanted)}.{hint}",
    )
