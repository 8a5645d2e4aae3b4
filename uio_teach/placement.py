"""Output-injection pole placement on the observable part of a pair ``(A, C)``."""

from __future__ import annotations

import control as ct
import numpy as np

from ._display import format_complex, format_poles
from ._validation import as_poles
from .linalg import ObservabilitySplit, observability_decomposition

__all__ = ["place_observer_poles"]


def place_observer_poles(
    A: np.ndarray,
    C: np.ndarray,
    poles,
    *,
    split: ObservabilitySplit | None = None,
    fixed_name: str = "unobservable modes",
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

    Returns
    -------
    numpy.ndarray, shape (n, p)

    Raises
    ------
    ValueError
        Wrong number of poles (the message says how many can be placed and
        which modes are fixed), unpaired complex poles, or a multiplicity the
        outputs cannot produce.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.placement import place_observer_poles
    >>> A = np.array([[0.0, 1.0], [-2.0, -3.0]]); C = np.array([[1.0, 0.0]])
    >>> L = place_observer_poles(A, C, [-5, -6])
    >>> np.sort(np.linalg.eigvals(A - L @ C).real).round(6).tolist()
    [-6.0, -5.0]
    """
    A = np.asarray(A, float)
    C = np.atleast_2d(np.asarray(C, float))
    n = A.shape[0]
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
    # use independent output combinations only
    U, s, _ = np.linalg.svd(split.Co, full_matrices=False)
    k = int(np.sum(s > max(split.Co.shape) * np.finfo(float).eps * (s[0] if s.size else 0)))
    Uk = U[:, :k]
    Cr = Uk.T @ split.Co
    Lr = _place(split.Ao, Cr, poles, k)
    return split.Vo @ Lr @ Uk.T


def _strip_fixed(poles: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    rest = list(poles)
    for f in fixed:
        dist = [abs(p - f) for p in rest]
        i = int(np.argmin(dist))
        if dist[i] > 1e-6 * max(1.0, abs(f)):
            return poles  # not a superset: let the count check complain
        rest.pop(i)
    return np.array(rest)


def _place(Ao: np.ndarray, Cr: np.ndarray, poles: np.ndarray, k: int) -> np.ndarray:
    if k == 1:
        # single output: Ackermann's formula accepts repeated poles
        return np.asarray(ct.acker(Ao.T, Cr.T, poles), float).reshape(1, -1).T
    values, counts = np.unique(np.round(poles, 9), return_counts=True)
    if np.any(counts > k):
        worst = values[np.argmax(counts)]
        raise ValueError(
            f"poles: {format_complex(worst)} is repeated {counts.max()} times but only {k} "
            "independent outputs can be used; choose poles with multiplicity at most "
            f"{k} (e.g. spread them slightly)"
        )
    try:
        return np.asarray(ct.place(Ao.T, Cr.T, poles), float).reshape(k, -1).T
    except ValueError as exc:  # pragma: no cover - scipy's message is kept for the rare case
        raise ValueError(f"poles: placement failed: {exc}") from None
