"""Output-injection pole placement on the observable part of a pair ``(A, C)``."""

from __future__ import annotations

import warnings

import control as ct
import numpy as np
import scipy.linalg as sla
import scipy.signal as ssig

from ._display import format_complex, format_poles
from ._validation import as_matrix, as_poles
from .linalg import ObservabilitySplit, observability_decomposition
from .verify import POLE_RTOL, PlacementAccuracyError, check_poles

__all__ = ["place_observer_poles"]


def place_observer_poles(
    A: np.ndarray,
    C: np.ndarray,
    poles,
    *,
    split: ObservabilitySplit | None = None,
    fixed_name: str = "unobservable modes",
    verify: bool = True,
) -> np.ndarray:
    """Gain ``L`` such that ``eig(A - L C)`` = the requested poles plus the fixed modes.

    Only the observable part of ``(A, C)`` can be moved; ``poles`` lists those
    poles only. For convenience a list of all ``n`` poles that contains the
    fixed modes is accepted too.

    Parameters
    ----------
    A : array_like, shape (n, n)
    C : array_like, shape (p, n)
    poles : array_like
        Desired poles of the observable part (conjugate pairs for complex poles).
    split : ObservabilitySplit, optional
        A precomputed :func:`~uio_teach.linalg.observability_decomposition`.
    fixed_name : str
        How the fixed modes are called in error messages.
    verify : bool
        Compare ``eig(A - L C)`` with the requested poles and the fixed modes
        (``uio_teach.verify.check_poles``); the designs switch this off
        because they check their own error matrix.

    Returns
    -------
    numpy.ndarray, shape (n, p)

    Raises
    ------
    ValueError
        Wrong number of poles (the message says how many can be placed and
        which modes are fixed), unpaired complex poles, or a multiplicity the
        outputs cannot produce.
    PlacementAccuracyError
        The computed gain does not give the requested poles (a badly
        conditioned problem: many states per output, close poles, a badly
        scaled plant) or is not finite.

    Warns
    -----
    PlacementAccuracyWarning
        The poles obtained are slightly off (more than round-off allows).

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.placement import place_observer_poles
    >>> A = np.array([[0.0, 1.0], [-2.0, -3.0]]); C = np.array([[1.0, 0.0]])
    >>> L = place_observer_poles(A, C, [-5, -6])
    >>> np.sort(np.linalg.eigvals(A - L @ C).real).round(6).tolist()
    [-6.0, -5.0]
    """
    A = as_matrix("A", A, what="n x n")
    n = A.shape[0]
    if A.shape[1] != n:
        raise ValueError(f"A has shape {A.shape}, expected a square (n, n) matrix")
    C = as_matrix("C", C, None, n, vector="row", what="p x n")
    if split is None:
        split = observability_decomposition(A, C)
    poles = as_poles("poles", poles)
    no = split.Ao.shape[0]
    fixed = split.unobservable_modes
    if len(poles) == n and len(fixed) and no != n:
        poles = _strip_fixed(poles, fixed)
    if len(poles) != no:
        fixed_txt = (
            f"; the modes {format_poles(fixed, braces=True, empty='none')} are fixed ({fixed_name})"
            if len(fixed)
            else ""
        )
        raise ValueError(f"poles: {no} pole(s) can be placed, got {len(poles)}{fixed_txt}")
    if no == 0:
        return np.zeros((n, C.shape[0]))
    L = _gain(split, poles)
    target = np.concatenate([poles, fixed])
    if _error(A, C, L, target) > POLE_RTOL:
        # a badly scaled plant: place on the balanced pair (T^-1 A T, C T), L = T L_b
        t = _balance(A)
        if np.any(t != 1.0):
            Ab, Cb = A / t[:, None] * t[None, :], C * t[None, :]
            split_b = observability_decomposition(Ab, Cb)
            if split_b.Ao.shape[0] == no:
                try:
                    Lb = t[:, None] * _gain(split_b, poles)
                except PlacementAccuracyError:
                    Lb = None
                if Lb is not None and _error(A, C, Lb, target) < _error(A, C, L, target):
                    L = Lb
    if verify:
        with np.errstate(all="ignore"):
            F = A - L @ C
        check_poles(F, np.concatenate([poles, fixed]), what="the placement", stacklevel=3)
    return L


def _gain(split: ObservabilitySplit, poles: np.ndarray) -> np.ndarray:
    """Gain placing ``poles`` on the observable part of ``split`` (original coordinates)."""
    n = split.Vo.shape[0]
    if split.Ao.shape[0] == 0:
        return np.zeros((n, split.Co.shape[0]))
    # use independent output combinations only
    U, s, _ = np.linalg.svd(split.Co, full_matrices=False)
    k = int(np.sum(s > max(split.Co.shape) * np.finfo(float).eps * (s[0] if s.size else 0)))
    Uk = U[:, :k]
    Cr = Uk.T @ split.Co
    Lr = _place(split.Ao, Cr, poles, k)
    return split.Vo @ Lr @ Uk.T


def _error(A: np.ndarray, C: np.ndarray, L: np.ndarray, target: np.ndarray) -> float:
    """Largest relative distance between ``target`` and ``eig(A - L C)`` (matched)."""
    return _pole_error(A, C, L, target)


def _balance(A: np.ndarray) -> np.ndarray:
    """Diagonal similarity (powers of 2) that balances ``A``."""
    _, (t, _) = sla.matrix_balance(A, permute=False, separate=True)
    return np.asarray(t, float)


def _strip_fixed(poles: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    rest = list(poles)
    for f in fixed:
        dist = [abs(p - f) for p in rest]
        i = int(np.argmin(dist))
        if dist[i] > 1e-6 * max(1.0, abs(f)):
            return poles  # not a superset: let the count check complain
        rest.pop(i)
    return np.array(rest)


def _pole_error(Ao: np.ndarray, Cr: np.ndarray, Lr: np.ndarray, poles: np.ndarray) -> float:
    """Largest relative distance between the requested and the obtained poles (matched)."""
    from scipy.optimize import linear_sum_assignment

    with np.errstate(all="ignore"):
        F = Ao - Lr @ Cr
        if not np.all(np.isfinite(F)):
            return np.inf
        w = np.linalg.eigvals(F)
    cost = np.abs(poles[:, None] - w[None, :]) / np.maximum(1.0, np.abs(poles))[:, None]
    r, c = linear_sum_assignment(cost)
    return float(cost[r, c].max())


def _place(Ao: np.ndarray, Cr: np.ndarray, poles: np.ndarray, k: int) -> np.ndarray:
    """Gain of the observable part; python-control's and scipy's messages are translated."""
    with np.errstate(all="ignore"):
        values, counts = np.unique(np.round(poles, 9), return_counts=True)
    if k > 1 and np.any(counts > k):
        worst = values[np.argmax(counts)]
        raise ValueError(
            f"poles: {format_complex(worst)} is repeated {counts.max()} times but only {k} "
            "independent outputs can be used; choose poles with multiplicity at most "
            f"{k} (e.g. spread them slightly)"
        )
    candidates = []
    failures = []
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        # scipy warns "Convergence was not reached" and numpy about overflow; the result is
        # verified below instead, and the user gets one plain message
        warnings.simplefilter("ignore")
        if k == 1:
            # single output: Ackermann's formula accepts repeated poles; scipy's algorithm
            # is often more accurate for distinct poles: keep the better of the two
            try:
                candidates.append(np.asarray(ct.acker(Ao.T, Cr.T, poles), float).reshape(1, -1).T)
            except Exception as exc:  # noqa: BLE001 - translated below
                failures.append(str(exc))
            if counts.max() == 1:
                try:
                    res = ssig.place_poles(Ao.T, Cr.T, poles)
                    candidates.append(np.asarray(res.gain_matrix, float).reshape(1, -1).T)
                except Exception as exc:  # noqa: BLE001 - translated below
                    failures.append(str(exc))
        else:
            try:
                candidates.append(np.asarray(ct.place(Ao.T, Cr.T, poles), float).reshape(k, -1).T)
            except Exception as exc:  # noqa: BLE001 - translated below
                failures.append(str(exc))
    if not candidates:
        raise PlacementAccuracyError(
            f"poles: the pole placement failed numerically ({'; '.join(failures)}). The pair is "
            "observable to the rank tolerance, but so badly conditioned that the gain cannot "
            "be computed in double precision: place fewer poles per output, spread them "
            "apart, or scale the plant's states"
        )
    errors = [_pole_error(Ao, Cr, Lr, poles) for Lr in candidates]
    return candidates[int(np.argmin(errors))]
