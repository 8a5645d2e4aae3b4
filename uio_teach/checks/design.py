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

from .. import experiments
from .._display import format_matrix_line, format_poles
from ._common import (
    CheckResult,
    _close,
    _get_plant,
    _looks_two_decimals,
    _maxdiff,
    _never_raises,
    _numbers,
    _read_matrix,
    _stability,
    _up_to,
)

__all__ = ["pa9_design"]


_OMITTED: Any = type("_Omitted", (), {"__repr__": lambda self: "<omitted>"})()


@_never_raises("Practical Assignment 9: the observer design", "pa9.design")
def pa9_design(
    H: Any,
    T: Any,
    K1: Any,
    F: Any = _OMITTED,
    K2: Any = _OMITTED,
    plant: Any = None,
    *,
    poles: Any = None,
    tol: float = 1e-6,
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
        of ``F`` must be these, each to ``1e-6`` relative.
    tol : float, optional
        Relative tolerance of the equalities (entries are compared with
        ``tol * max(1, largest entry)``). Full-precision NumPy results agree to
        about 1e-15; numbers typed with 2 decimals do not pass.

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
    result = CheckResult("Practical Assignment 9: the observer design")
    plant = _get_plant(result, plant)
    if plant is None:
        return result
    n, p = plant.n, plant.p
    A, C, E = plant.A, plant.C, plant.E
    what_np = f"n x p = {n} x {p}: one row per state, one column per output"
    what_nn = f"n x n = {n} x {n}"
    H = _read_matrix(result, "H", H, n, p, what_np)
    T = _read_matrix(result, "T", T, n, n, what_nn)
    K1 = _read_matrix(result, "K1", K1, n, p, what_np)
    F_given = F is not _OMITTED
    K2_given = K2 is not _OMITTED
    F = _read_matrix(result, "F", F, n, n, what_nn) if F_given else None
    K2 = _read_matrix(result, "K2", K2, n, p, what_np) if K2_given else None
    wanted = _read_poles(result, poles, n, plant.is_discrete) if poles is not None else None
    if poles is not None and wanted is None:
        return result
    if H is None or T is None or K1 is None or (F_given and F is None) or (K2_given and K2 is None):
        result.add(None, "Fix the shapes first; the design equations are checked afterwards.")
        return result

    from ..linalg import pinv

    eye = np.eye(n)
    H_ref = E @ pinv(C @ E)

    # (I - HC) E = 0 ---------------------------------------------------------------------------
    R = (eye - H @ C) @ E
    big = float(np.max(np.abs(R))) if R.size else 0.0
    if big <= tol * max(1.0, float(np.max(np.abs(E))) if E.size else 1.0):
        result.add(
            True,
            f"(I - HC)E = 0{_up_to(big, 'largest entry')}: H cancels the disturbance.",
        )
    else:
        if _looks_two_decimals(H, H_ref):
            hint = (
                " Your H has the 2 decimals printed in the assignment; those numbers are "
                "chopped, not exact, so the disturbance is not fully cancelled. Keep full "
                "precision: H = E @ np.linalg.pinv(C @ E)."
            )
        elif _close(H, -H_ref, 1e-6):
            hint = " Your H is -E(CE)^+: drop the minus sign."
        else:
            hint = (
                " H must solve HCE = E; the assignment's choice is H = E (CE)^+, in NumPy "
                "H = E @ np.linalg.pinv(C @ E) (pinv, because CE is not square)."
            )
        result.add(
            False,
            f"H does not satisfy (I - HC)E = 0: (I - HC)E = {format_matrix_line(R)} "
            f"(largest entry {big:.3g}), "
            f"so the disturbance d still drives the error.{hint}",
        )

    # T = I - HC -------------------------------------------------------------------------------
    T_ref = eye - H @ C
    T_ok = _close(T, T_ref, tol)
    if T_ok:
        result.add(True, "T = I - HC.")
    else:
        diff, idx = _maxdiff(T, T_ref)
        where = f"T[{idx[0]}, {idx[1]}] is {T[idx]:.4g} but (I - HC)[{idx[0]}, {idx[1]}] is "
        where += f"{T_ref[idx]:.4g}"
        if _close(T, -T_ref, tol):
            hint = " Your T is HC - I: the sign is flipped."
        elif _close(T, H @ C, tol):
            hint = " Your T is HC; it must be I - HC."
        elif _looks_two_decimals(T, T_ref) or _looks_two_decimals(T, eye - H_ref @ C):
            hint = " Your T has only 2 decimals; compute it as T = np.eye(n) - H @ C."
        else:
            hint = " Compute it from your H: T = np.eye(n) - H @ C."
        result.add(False, f"T is not I - HC: {where} (difference {diff:.3g}).{hint}")

    # F = TA - K1C -----------------------------------------------------------------------------
    F_ref = T_ref @ A - K1 @ C
    if F_given:
        if _close(F, F_ref, tol):
            result.add(True, "F = TA - K1C.")
        else:
            diff, idx = _maxdiff(F, F_ref)
            if not T_ok and _close(F, T @ A - K1 @ C, tol):
                hint = " It is TA - K1C with your T, but your T is wrong (see above): fix T first."
            elif _close(F, A - K1 @ C, tol):
                hint = " Your F is A - K1C: the T is missing, F = TA - K1C."
            elif _close(F, T_ref @ A + K1 @ C, tol):
                hint = " Your F is TA + K1C: the sign of K1C is flipped."
            else:
                hint = " Compute it as F = T @ A - K1 @ C."
            result.add(
                False,
                f"F is not TA - K1C: F[{idx[0]}, {idx[1]}] is {F[idx]:.4g} but "
                f"(TA - K1C)[{idx[0]}, {idx[1]}] is {F_ref[idx]:.4g} "
                f"(difference {diff:.3g}).{hint}",
            )
    else:
        result.add(None, "F not given: F = TA - K1C is computed from your H and K1.")

    # K2 = FH ----------------------------------------------------------------------------------
    if K2_given:
        K2_ref = F_ref @ H
        if _close(K2, K2_ref, tol):
            result.add(True, "K2 = FH.")
        elif _close(K2, -K2_ref, tol):
            result.add(
                False,
                "K2 is -FH: the sign is flipped. The condition (A - K1C - HCA)H - K2 = 0 of "
                "eq. (7) gives K2 = FH.",
            )
        elif F_given and _close(K2, F @ H, tol):
            result.add(False, "K2 = FH with your F, but your F is wrong (see above): fix F first.")
        else:
            diff, idx = _maxdiff(K2, K2_ref)
            hint = (
                " Your K2 is K1 - FH; K2 alone is FH."
                if _close(K2, K1 - K2_ref, tol)
                else " Compute it as K2 = F @ H."
            )
            result.add(
                False,
                f"K2 is not FH: K2[{idx[0]}, {idx[1]}] is {K2[idx]:.4g} but (FH)[{idx[0]}, "
                f"{idx[1]}] is {K2_ref[idx]:.4g} (difference {diff:.3g}).{hint}",
            )

    # stability of F ---------------------------------------------------------------------------
    F_used = F if F_given else F_ref
    which = "F" if F_given else "F = TA - K1C"
    stable, eig, bad = _stability(F_used, plant.is_discrete)
    asked = wanted if wanted is not None else experiments.PA9.poles
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
            "decay. Choose K1 so that TA - K1C has the poles you want, e.g. "
            f"K1 = ct.place((T @ A).T, C.T, {_numbers(asked)}).T.",
        )
    if wanted is not None:
        _poles_asked(result, eig, wanted, which, A - K1 @ C, T_ref @ A - K1 @ C, F_given)
    return result


def _read_poles(result: CheckResult, poles: Any, n: int, discrete: bool) -> np.ndarray | None:
    """The poles an exercise asks for, as a sorted complex array (a ✗ if they are unusable)."""
    from ..linalg import sort_poles

    try:
        arr = np.array([complex(p) for p in np.ravel(np.asarray(poles, dtype=object))])
    except (TypeError, ValueError):
        result.add(False, f"poles must be a list of {n} numbers, got {poles!r}.")
        return None
    if arr.size != n or not np.all(np.isfinite(arr)):
        result.add(False, f"poles must be a list of {n} finite numbers, got {poles!r}.")
        return None
    return sort_poles(arr)


def _same_poles(got: np.ndarray, wanted: np.ndarray) -> bool:
    from ..linalg import sort_poles

    got = sort_poles(np.asarray(got, complex))
    if got.size != wanted.size:
        return False
    used = [False] * got.size
    for w in wanted:
        k = next(
            (i for i, g in enumerate(got) if not used[i] and abs(g - w) <= 1e-6 * max(1.0, abs(w))),
            None,
        )
        if k is None:
            return False
        used[k] = True
    return True


def _poles_asked(
    result: CheckResult,
    eig: np.ndarray,
    wanted: np.ndarray,
    which: str,
    F_without_T: np.ndarray,
    F_ref: np.ndarray,
    F_given: bool,
) -> None:
    """A ✓ if the eigenvalues ``eig`` of ``F`` are the poles asked for, else a ✗ with the cause."""
    if _same_poles(eig, wanted):
        result.add(True, f"{which} has the poles asked for, {format_poles(wanted)}.")
        return
    if _same_poles(np.linalg.eigvals(F_without_T), wanted):
        hint = (
            " Your K1 places the poles of A - K1C, not of TA - K1C: place them for the pair "
            "(TA, C), K1 = ct.place((T @ A).T, C.T, poles).T."
        )
    elif (
        F_given
        and not _same_poles(np.linalg.eigvals(F_ref), eig)
        and _same_poles(np.linalg.eigvals(F_ref), wanted)
    ):
        hint = " TA - K1C has them, so your F is not TA - K1C (see above)."
    else:
        hint = (
            " Place them with K1 = ct.place((T @ A).T, C.T, poles).T, with the poles of the "
            "exercise."
        )
    result.add(
        False,
        f"{which} has the poles {format_poles(eig)}, but the exercise asks for "
        f"{format_poles(wanted)}.{hint}",
    )
