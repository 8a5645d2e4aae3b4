"""Output-injection pole placement on the observable part of a pair ``(A, C)``."""

from __future__ import annotations

import contextlib
import contextvars
import warnings
from collections.abc import Iterator

import numpy as np
import scipy.linalg as sla
from scipy.optimize import linear_sum_assignment

from . import tolerances as tols
from ._display import format_complex, format_poles
from ._validation import as_matrix, as_poles
from .balancing import BalancedPair
from .errors import InputError
from .linalg import ObservabilitySplit, observability_decomposition
from .verify import PlacementAccuracyError, check_poles

__all__ = ["place_observer_poles", "place_pair_poles", "requested_poles", "strip_fixed"]


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
    fixed modes is accepted too. Poles may be repeated any number of times
    (deadbeat included): beyond what the outputs give independently, a
    single-output design on a combination ``w C`` is made, after a preliminary
    injection ``L0`` that makes ``A - L0 C`` cyclic when ``A`` is not. A
    pole repeated ``m`` times is found to about ``eps^(1/m)`` only, as any
    Jordan block's.

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
        which modes are fixed) or unpaired complex poles.
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

    Two equal modes and two outputs, a triple pole:

    >>> A = np.diag([-1.0, -2.0, -2.0]); C = np.array([[1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    >>> L = place_observer_poles(A, C, [-4, -4, -4])
    >>> np.linalg.eigvals(A - L @ C).real.round(3).tolist()
    [-4.0, -4.0, -4.0]
    """
    A = as_matrix("A", A, what="n x n")
    n = A.shape[0]
    if A.shape[1] != n:
        raise InputError(f"A has shape {A.shape}, expected a square (n, n) matrix")
    C = as_matrix("C", C, None, n, vector="row", what="p x n")
    if split is None:
        split = observability_decomposition(A, C)
    poles = as_poles("poles", poles)
    no = split.Ao.shape[0]
    fixed = split.unobservable_modes
    if len(poles) == n and len(fixed) and no != n:
        poles = strip_fixed(poles, fixed)
    if len(poles) != no:
        fixed_txt = (
            f"; the modes {format_poles(fixed, braces=True, empty='none')} are fixed ({fixed_name})"
            if len(fixed)
            else ""
        )
        raise InputError(f"poles: {no} pole(s) can be placed, got {len(poles)}{fixed_txt}")
    if no == 0:
        return np.zeros((n, C.shape[0]))
    L = _gain(split, poles)
    target = np.concatenate([poles, fixed])
    if _error(A, C, L, target) > tols.POLE_RTOL:
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


def strip_fixed(poles: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """``poles`` without the fixed modes when it lists all of them, else ``poles`` unchanged.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.placement import strip_fixed
    >>> strip_fixed(np.array([-1, -2, -3 + 0j]), np.array([-2 + 0j])).real.tolist()
    [-1.0, -3.0]
    """
    rest = list(poles)
    # relative to the set's own scale (the largest value), the same in any unit of time
    scale = float(np.max(np.abs(np.concatenate([poles, fixed])), initial=0.0)) or 1.0
    for f in fixed:
        dist = [abs(p - f) for p in rest]
        i = int(np.argmin(dist))
        if dist[i] > tols.FIXED_POLE_RTOL * max(scale, abs(f)):
            return poles  # not a superset: let the count check complain
        rest.pop(i)
    return np.array(rest)


def _pole_error(Ao: np.ndarray, Cr: np.ndarray, Lr: np.ndarray, poles: np.ndarray) -> float:
    """Largest relative distance between the requested and the obtained poles (matched)."""
    with np.errstate(all="ignore"):
        F = Ao - Lr @ Cr
        if not np.all(np.isfinite(F)):
            return np.inf
        w = np.linalg.eigvals(F)
    cost = np.abs(poles[:, None] - w[None, :]) / np.maximum(1.0, np.abs(poles))[:, None]
    r, c = linear_sum_assignment(cost)
    return float(cost[r, c].max())


# scipy's YT method sweeps over all pairs of output directions, O(n^3) work per pair and
# sweep: above this many states it is given few sweeps (a placement of that size is
# ill-conditioned anyway; the result is verified against the requested poles)
_YT_MAX_STATES = 12
_YT_SWEEPS_LARGE = 6


def _multi_output(Ao: np.ndarray, Cr: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """Multi-output placement: scipy's YT, with fewer sweeps for large problems."""
    import scipy.signal as ssig  # deferred on purpose: scipy.signal takes a second to import

    n, k = Ao.shape[0], Cr.shape[0]
    sweeps = 30 if n <= _YT_MAX_STATES else _YT_SWEEPS_LARGE
    Q = np.eye(n)
    if _SCHUR.get():
        # in the coordinates of A's real Schur form, which the order of the states does not
        # change (YT's iterations depend on it: with several outputs the gain is not unique)
        Ao, Q = sla.schur(Ao, output="real")
        Cr = Cr @ Q
    res = ssig.place_poles(Ao.T, Cr.T, poles, method="YT", rtol=1e-3, maxiter=sweeps)
    return Q @ np.asarray(res.gain_matrix, float).reshape(k, -1).T


_SCHUR: contextvars.ContextVar[bool] = contextvars.ContextVar("schur_placement", default=False)


@contextlib.contextmanager
def schur_coordinates() -> Iterator[None]:
    """Within this block, multi-output placement works in the real Schur coordinates of ``A``.

    The gain of a multi-output placement is not unique, and scipy's YT iterations reach one that
    depends on the order of the states. In a badly scaled plant one order can give a gain that
    puts O(1) entries in the row of a state measured in tiny units, and a realization that
    amplifies round-off by 1e11; another order gives a clean one. The designs retry in Schur
    coordinates (the same in any state order, to round-off) when their first gain is refused.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.placement import place_observer_poles, schur_coordinates
    >>> A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, -2.0, -3.0]])
    >>> C = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    >>> with schur_coordinates():
    ...     L = place_observer_poles(A, C, [-1.0, -2.0, -3.0])
    >>> np.sort(np.linalg.eigvals(A - L @ C).real).round(6).tolist()
    [-3.0, -2.0, -1.0]
    """
    token = _SCHUR.set(True)
    try:
        yield
    finally:
        _SCHUR.reset(token)


def _cyclic(
    Ao: np.ndarray, Cr: np.ndarray, poles: np.ndarray, failures: list[str]
) -> list[np.ndarray]:
    """Single-output designs on ``w C`` (Ackermann): any multiplicity, e.g. deadbeat.

    A combination ``w`` of the outputs that keeps the pair observable exists
    when ``Ao`` is cyclic (one Jordan block per eigenvalue). When it is not
    (an eigenvalue with two independent eigenvectors, as in a plant with two
    identical modes), a preliminary output injection ``L0`` makes
    ``Ao - L0 C`` cyclic -- a random ``L0`` does so with probability one for an
    observable pair -- and the single-output design is made on that matrix:
    ``L = L0 + L_w w``. Seeded random ``w`` and ``L0`` are tried and the gains
    returned (the caller keeps the most accurate); why a try failed is
    appended to ``failures``.
    """
    import control as ct  # deferred on purpose: python-control takes a second to import

    rng = np.random.default_rng(0)
    n, k = Cr.shape[1], Cr.shape[0]
    size = max(float(np.linalg.norm(Ao, 2)), float(np.max(np.abs(poles), initial=0.0)), 1e-300)
    gain_size = size / max(float(np.linalg.norm(Cr, 2)), 1e-300)
    out = []
    for trial in range(8):
        w = np.ones(k) if trial == 0 else rng.standard_normal(k)
        w = w / np.linalg.norm(w)
        # trials 0-3: Ao as it is; 4-7: a preliminary injection L0 making it cyclic
        L0 = np.zeros((n, k)) if trial < 4 else gain_size * rng.standard_normal((n, k)) / k
        A0 = Ao - L0 @ Cr
        cw = (w @ Cr)[None, :]
        try:
            lw = np.asarray(ct.acker(A0.T, cw.T, poles), float).reshape(1, -1).T
        except Exception as exc:  # noqa: BLE001 - another direction is tried
            failures.append(f"single output w C: {exc}")
            continue
        if np.all(np.isfinite(lw)):
            out.append(L0 + lw @ w[None, :])
        else:
            failures.append("single output w C: a gain that is not finite")
    return out


def _place(Ao: np.ndarray, Cr: np.ndarray, poles: np.ndarray, k: int) -> np.ndarray:
    """Gain of the observable part; python-control's and scipy's messages are translated."""
    # deferred on purpose: python-control and scipy.signal take a second to import
    import control as ct
    import scipy.signal as ssig

    with np.errstate(all="ignore"):
        values, counts = np.unique(np.round(poles, 9), return_counts=True)
    candidates = []
    failures: list[str] = []
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
                failures.append(f"Ackermann: {exc}")
            if counts.max() == 1:
                try:
                    res = ssig.place_poles(Ao.T, Cr.T, poles)
                    candidates.append(np.asarray(res.gain_matrix, float).reshape(1, -1).T)
                except Exception as exc:  # noqa: BLE001 - translated below
                    failures.append(f"scipy place_poles: {exc}")
        else:
            if counts.max() <= k:
                try:
                    candidates.append(_multi_output(Ao, Cr, poles))
                except Exception as exc:  # noqa: BLE001 - translated below
                    failures.append(f"scipy place_poles (YT): {exc}")
            if not candidates or counts.max() > 1:
                # repeated poles beyond what the outputs give independently (deadbeat):
                # a cyclic single-output design on a combination of the outputs
                candidates.extend(_cyclic(Ao, Cr, poles, failures))
    candidates = [Lr for Lr in candidates if np.all(np.isfinite(Lr))]
    if not candidates:
        reasons = (
            "; ".join(dict.fromkeys(failures)) or "every method gave a gain that is not finite"
        )
        raise PlacementAccuracyError(
            f"poles: the pole placement failed numerically ({reasons}). The pair is "
            "observable to the rank tolerance, but so badly conditioned that the gain cannot "
            "be computed in double precision: place fewer poles per output, spread them "
            "apart, or scale the plant's states"
        )
    errors = [_pole_error(Ao, Cr, Lr, poles) for Lr in candidates]
    return candidates[int(np.argmin(errors))]


def requested_poles(poles, fixed: np.ndarray, movable: int) -> np.ndarray:
    """All poles the error dynamics must have: the movable ones requested plus the fixed modes.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.placement import requested_poles
    >>> requested_poles([-1, -2], np.array([-5 + 0j]), 2).real.tolist()
    [-1.0, -2.0, -5.0]
    """
    req = np.atleast_1d(np.asarray(poles, complex)).ravel()
    if len(req) == movable + len(fixed) and len(fixed):
        return req  # all n poles were given, the fixed modes among them
    return np.concatenate([req, fixed])


def place_pair_poles(
    pair: BalancedPair,
    poles,
    *,
    fixed_name: str = "invariant zeros",
    given: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Gain ``L`` (``L D = 0``) placing ``poles`` on the pair of a projection design.

    What can be placed (the movable poles and the fixed modes) is decided on
    the balanced pair (see :class:`uio_teach.balancing.BalancedPair`), so it
    does not depend on the units of the data. The gain itself is first
    computed on the pair as given, ``(A1, N C)``, as python-control's
    ``place`` would compute it; when that gain does not give the requested
    poles to ``POLE_RTOL`` (a badly scaled plant), or the pair as given does
    not split into the same movable and fixed parts, the gain is computed in
    balanced units instead.

    Parameters
    ----------
    pair : BalancedPair
    poles : array_like
        The movable poles (or all ``n``, the fixed modes among them).
    fixed_name : str
        How the fixed modes are called in messages.
    given : (A1, C, N), optional
        The pair in the plant's units: the error matrix's ``A1`` (``TA`` of a
        UIO), the plant's ``C`` and ``N`` (``N D = 0``, the identity without a
        measurement disturbance); the gain is then ``L = L_o N`` with ``L_o``
        placed on ``(A1, N C)``.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        The gain ``L`` (n x p, in the plant's units) and all the poles the
        error matrix must have (the requested ones and the fixed modes).

    Raises
    ------
    ValueError
        A wrong number of poles, or a requested pole on a fixed mode: no gain
        moves that mode, so asking for a pole there cannot be told apart from
        keeping the fixed mode and the design would not be verifiable.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach.placement import place_pair_poles
    >>> dec = ut.existence.decoupling(ut.examples.missile_autopilot())
    >>> L, want = place_pair_poles(dec.pair, [-10, -20])
    >>> len(want)
    4
    """
    poles = as_poles("poles", poles)
    fixed, no = pair.fixed_modes, pair.movable
    n = pair.A.shape[0]
    if len(poles) == n and len(fixed) and no != n:
        poles = strip_fixed(poles, fixed)
    if len(poles) != no:
        fixed_txt = (
            f"; the modes {format_poles(fixed, braces=True, empty='none')} are fixed ({fixed_name})"
            if len(fixed)
            else ""
        )
        raise InputError(f"poles: {no} pole(s) can be placed, got {len(poles)}{fixed_txt}")
    scale = float(np.max(np.abs(np.concatenate([poles, fixed])), initial=0.0)) or 1.0
    for z in fixed:
        close = np.abs(poles - z) <= tols.FIXED_POLE_RTOL * max(scale, abs(z))
        if np.any(close):
            raise InputError(
                f"poles: {format_complex(poles[close][0])} is requested on the fixed mode "
                f"{format_complex(z)} ({fixed_name}): no gain moves that mode, and a pole "
                "requested on it cannot be told apart from it. Choose the movable poles "
                "away from the fixed modes"
            )
    target = np.concatenate([poles, fixed])
    if given is not None:
        L = _place_given(given, pair, poles, target)
        if L is not None:
            return L, target
    Lb = place_observer_poles(
        pair.A, pair.C, poles / pair.sigma, split=pair.split, fixed_name=fixed_name, verify=False
    )
    return pair.gain(Lb), target


def _place_given(
    given: tuple[np.ndarray, np.ndarray, np.ndarray],
    pair: BalancedPair,
    poles: np.ndarray,
    target: np.ndarray,
) -> np.ndarray | None:
    """The gain placed on the pair as given, or None when it is not the right one."""
    A1, C, N = (np.asarray(X, float) for X in given)
    NC = N @ C
    if not (np.all(np.isfinite(A1)) and np.all(np.isfinite(NC))):
        return None
    with np.errstate(all="ignore"):
        split = observability_decomposition(A1, NC)
        if split.Ao.shape[0] != pair.movable:
            return None
        try:
            Lo = _gain(split, poles)
        except (PlacementAccuracyError, ValueError, np.linalg.LinAlgError):
            return None
        if not np.all(np.isfinite(Lo)) or _error(A1, NC, Lo, target) > tols.POLE_RTOL:
            return None
        return Lo @ N
