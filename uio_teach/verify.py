"""Checks run after every design: the poles obtained and the decoupling identities.

A gain is computed in floating point; for badly conditioned problems (many
states, one output, close poles, badly scaled plants) the computed gain may
not give the poles that were asked for. Every design therefore compares what
it obtained with what it promised:

* **Poles.** The obtained eigenvalues are matched one to one with the
  requested ones (fixed modes included). A pole is accepted when it lies within
  ``POLE_RTOL * max(1, |p|)`` of its request, or within the round-off bound of
  the eigenvalue problem, ``n * eps * ||F|| * kappa`` with a room of ``ROUNDOFF_ROOM``
  (``kappa`` the eigenvalue's
  condition number; a pole requested ``m`` times may move by
  ``(100 * n * eps * ||F||^m)^(1/m)``, the Hölder bound of a Jordan block), or when the
  requested value is an eigenvalue of a matrix within ``n * eps * ||F||`` of
  ``F`` (backward check) -- the last two only up to ``WARN_RTOL * max(1, |p|)``:
  an error of that size is what the problem's conditioning allows. Otherwise,
  within ``WARN_RTOL``: a ``PlacementAccuracyWarning``; beyond ``WARN_RTOL``,
  or a non-finite gain: a ``PlacementAccuracyError``. Both name requested
  and obtained poles and the conditioning.
* **Identities.** ``T E = 0``, ``H C E = E``, ``L D = 0`` (and their analogues)
  must hold to ``IDENTITY_RTOL`` relative to the product of the factors' norms,
  or a ``PlacementAccuracyError`` is raised.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np
import scipy.linalg as sla
from scipy.linalg import lapack
from scipy.optimize import linear_sum_assignment

from . import tolerances as tols
from ._display import format_complex
from .errors import UIOTeachError, UIOTeachWarning
from .linalg import is_stable

__all__ = [
    "POLE_RTOL",
    "WARN_RTOL",
    "IDENTITY_RTOL",
    "PlacementAccuracyWarning",
    "PlacementAccuracyError",
    "check_poles",
    "check_identity",
    "relative_residual",
    "product_bound",
    "check_fixed_modes",
    "LEAK_RTOL",
    "LEAK_REFUSE",
    "DecouplingLeak",
    "DecouplingWarning",
    "DecouplingError",
    "decoupling_leak",
    "check_decoupling",
]

POLE_RTOL = tols.POLE_RTOL
WARN_RTOL = tols.WARN_RTOL
IDENTITY_RTOL = tols.IDENTITY_RTOL
_EPS = tols.EPS
_TINY = float(np.finfo(float).tiny)


def _fmt(values) -> str:
    """Each value on its own scale (a huge pole must not print its neighbours as 0)."""
    return "{" + ", ".join(format_complex(v, 7) for v in values) + "}" if len(values) else "none"


class PlacementAccuracyWarning(UIOTeachWarning):
    """The obtained poles differ from the requested ones by more than round-off allows."""


class PlacementAccuracyError(UIOTeachError, ValueError):
    """A computed design fails its own check: wrong poles, non-finite gain or broken identity."""


def _condition_numbers(F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues of ``F`` and their condition numbers ``1 / |y^H x|`` (unit vectors)."""
    with np.errstate(all="ignore"):
        w, vl, vr = sla.eig(F, left=True, right=True)
        vl = vl / np.linalg.norm(vl, axis=0)
        vr = vr / np.linalg.norm(vr, axis=0)
        cos = np.abs(np.sum(vl.conj() * vr, axis=0))
        kappa = np.where(cos > 0, 1.0 / np.maximum(cos, 1e-300), np.inf)
    return w, kappa


def _clusters(req: np.ndarray, zeros=None, radius=None) -> np.ndarray:
    """Labels of the clusters of the requested values.

    Values equal to ``REAL_RTOL`` of their own size are one (a pole requested several times), and so
    are values within twice the round-off radius of one invariant zero (a repeated or defective
    fixed mode, whose computed values scatter by that radius).
    """
    n = req.size
    label = np.arange(n)
    for i in range(n):
        for j in range(i + 1, n):
            if abs(req[i] - req[j]) <= tols.REAL_RTOL * max(abs(req[i]), abs(req[j])):
                label[label == label[j]] = label[i]
    if zeros is not None and radius is not None and len(zeros) and len(radius) == len(zeros):
        zeros = np.asarray(zeros, complex)
        reach = 2 * np.where(np.isfinite(radius), np.asarray(radius, float), 0.0)
        for k, z in enumerate(zeros):
            near = np.flatnonzero(np.abs(req - z) <= reach[k])
            if near.size > 1:
                label[np.isin(label, label[near])] = label[near[0]]
    return np.unique(label, return_inverse=True)[1].ravel()


def check_poles(
    F: np.ndarray,
    requested,
    *,
    what: str = "the observer",
    stacklevel: int = 3,
    zeros=None,
    radius=None,
) -> np.ndarray:
    """Compare ``eig(F)`` with the requested poles; warn or raise beyond the tolerance.

    Parameters
    ----------
    F : array_like, shape (n, n)
        The matrix of the error dynamics.
    requested : array_like, shape (n,)
        The poles asked for, fixed modes included.
    what : str
        How the design is called in messages.
    stacklevel : int
        Passed to ``warnings.warn``.
    zeros, radius : array_like, optional
        The plant's invariant zeros and how far round-off moves each
        (:class:`uio_teach.linalg.ZeroSet`): fixed modes of a repeated or defective zero are
        verified as one cluster (its centre to round-off, its members within the Hoelder
        radius), not one by one.

    Returns
    -------
    numpy.ndarray
        The obtained poles, in the order of ``requested``.

    Raises
    ------
    PlacementAccuracyError
        A pole is off by more than ``WARN_RTOL`` relative (or ``F`` is not finite).

    Warns
    -----
    PlacementAccuracyWarning
        A pole is off by more than round-off allows but less than ``WARN_RTOL``.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.verify import check_poles
    >>> check_poles(np.diag([-1.0, -2.0]), [-2, -1]).real.tolist()
    [-2.0, -1.0]
    """
    F = np.asarray(F)
    req = np.asarray(requested, complex).ravel()
    if not np.all(np.isfinite(F)):
        raise PlacementAccuracyError(
            f"{what}: the computed gain is not finite (requested poles "
            f"{_fmt(req)} are out of the floating-point "
            "range for this plant); choose poles of a size comparable to the plant's"
        )
    n = F.shape[0]
    if n == 0:
        return np.zeros(0, complex)
    w, kappa = _condition_numbers(F)
    cost = np.abs(req[:, None] - w[None, :])
    rows, cols = linear_sum_assignment(cost)
    obtained = w[cols[np.argsort(rows)]]
    kap = kappa[cols[np.argsort(rows)]]
    normF = float(np.linalg.norm(F, 2))
    err = np.abs(obtained - req)
    # relative to each pole's own size (a slow pole is judged at its own scale, in any unit of
    # time); a pole requested at 0 (deadbeat) against ||F||, the only scale it has
    size = np.where(req != 0, np.abs(req), normF if normF > 0 else 1.0)
    round_off = n * _EPS * normF * np.where(np.isfinite(kap), kap, 1e300)
    tight = err <= tols.POLE_RTOL * np.abs(req)
    # a pole requested m times forms a Jordan block: a perturbation delta of F moves it by about
    # (delta ||F||^(m-1))^(1/m), far more than kappa (computed from nearby eigenvectors) says;
    # the gain of such a design (Ackermann's formula) is itself accurate to about 100 n eps ||F||
    with np.errstate(all="ignore"):  # huge poles overflow the rounding: they are not repeated
        scale = np.maximum(normF, np.abs(req))
        label = _clusters(req, zeros, radius)
        m = np.bincount(label)[label].astype(float)
        holder = (100 * n * _EPS * normF * scale ** (m - 1)) ** (1 / m) / tols.ROUNDOFF_ROOM
    round_off = np.where(m > 1, np.maximum(round_off, holder), round_off)
    explained = err <= tols.ROUNDOFF_ROOM * round_off
    # a cluster (a repeated pole, a defective fixed mode) is verified by what it promises: its
    # centre, well conditioned, to round-off, and its members within the Hoelder radius
    for c in np.unique(label[m > 1]):
        members = label == c
        centre = complex(np.mean(req[members]))
        moved = abs(complex(np.mean(obtained[members])) - centre)
        if moved <= tols.POLE_RTOL * abs(centre) + tols.ROUNDOFF_ROOM * n * _EPS * normF:
            room = tols.ROUNDOFF_ROOM * holder / tols.WARN_RTOL  # the Hoelder radius / WARN_RTOL
            size = np.where(members, np.maximum(size, room), size)
    for i in np.flatnonzero(~tight & ~explained & (err <= tols.WARN_RTOL * size)):
        # backward check: is the requested value an eigenvalue of a matrix close to F?
        smin = np.linalg.svd(F - req[i] * np.eye(n), compute_uv=False)[-1]
        explained[i] = smin <= tols.ROUNDOFF_ROOM * n * _EPS * max(normF, abs(req[i]))
    # an error at the round-off of F's eigenvalues themselves is no error, whatever the pole
    ok = (
        tight
        | (explained & (err <= tols.WARN_RTOL * size))
        | (err <= tols.ROUNDOFF_ROOM * n * _EPS * normF)
    )
    if np.all(ok):
        return obtained
    bad = ~ok
    worst = float(np.max(err[bad] / size[bad]))
    text = (
        f"{what}: the poles obtained differ from those requested beyond round-off: requested "
        f"{_fmt(req[bad])}, "
        f"obtained {_fmt(obtained[bad])} "
        f"(relative error up to {worst:.2g}; eigenvalue condition numbers up to "
        f"{float(np.max(kap[bad])):.2g}, ||F|| = {normF:.3g}). The placement problem is badly "
        "conditioned: spread the poles apart, choose them closer to the plant's own, or "
        "scale the plant's states"
    )
    if worst > tols.WARN_RTOL:
        raise PlacementAccuracyError(text)
    warnings.warn(text, PlacementAccuracyWarning, stacklevel=stacklevel)
    return obtained


def product_bound(*terms) -> np.ndarray:
    """Entrywise size of a sum of products, for :func:`relative_residual`.

    Each term is a matrix ``X`` (its entries' sizes ``|X_ij|``) or a pair
    ``(X, Y)`` standing for the product ``X Y``, whose entry ``(i, j)`` is at
    most ``||X_i,:|| ||Y_:,j||`` (Cauchy-Schwarz): round-off in any entry of
    row ``i`` of ``X`` (a computed gain) is judged against that row, not
    against the entry alone. Rows of ``X`` and columns of ``Y`` scale with the
    units of the states and inputs they belong to, so the bound does too.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.verify import product_bound
    >>> product_bound((np.array([[3.0, 4.0]]), np.eye(2)), np.array([[1.0, 0.0]])).tolist()
    [[6.0, 5.0]]
    """
    total = None
    for term in terms:
        if isinstance(term, tuple):
            X, Y = (np.abs(np.atleast_2d(np.asarray(a, float))) for a in term)
            part = np.outer(np.linalg.norm(X, axis=1), np.linalg.norm(Y, axis=0))
        else:
            part = np.abs(np.atleast_2d(np.asarray(term, float)))
        total = part if total is None else total + part
    return np.zeros((0, 0)) if total is None else total


def relative_residual(residual, bound) -> float:
    """Largest ``|R_ij| / bound_ij``: a residual judged entry by entry against its data.

    ``bound`` is the entrywise size of the terms that formed ``R``
    (:func:`product_bound`), e.g. ``product_bound((H, |C||E|), E)`` for
    ``R = H C E - E``. Round-off makes ``|R_ij|`` at most a few ``n eps``
    times ``bound_ij``, and the ratio does not change when states or inputs
    are measured in other units (diagonal scalings cancel entry by entry),
    unlike a ratio of whole-matrix norms.

    Parameters
    ----------
    residual : array_like
        The matrix that should be zero.
    bound : array_like or float
        Entrywise size of its terms (same shape), or one number.

    Returns
    -------
    float
        0 for an empty or exactly zero residual; ``inf`` when it is not finite
        or non-zero where its terms are all zero.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.verify import relative_residual
    >>> relative_residual(np.array([[1e-20, 0.0]]), np.array([[1e-4, 1e6]])) < 1e-15
    True
    """
    R = np.abs(np.asarray(residual, float))
    if R.size == 0:
        return 0.0
    if not np.all(np.isfinite(R)):
        return np.inf
    B = np.broadcast_to(np.abs(np.asarray(bound, float)), R.shape)
    with np.errstate(all="ignore"):
        ratio = np.where(R == 0, 0.0, R / B)
    ratio = np.where(np.isnan(ratio), np.inf, ratio)
    return float(np.max(ratio))


def check_identity(name: str, residual, scale, *, what: str = "the observer") -> float:
    """Raise if the identity's residual exceeds ``IDENTITY_RTOL`` of its data.

    Parameters
    ----------
    name : str
        The identity, e.g. ``"T E = 0"``.
    residual : array_like
        The matrix that should be zero.
    scale : float or array_like
        Either the product of the norms of the factors that form it, or,
        preferably, the entrywise bound of :func:`relative_residual` (then the
        check does not depend on the units of the data).
    what : str
        How the design is called in messages.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.verify import check_identity
    >>> check_identity("T E = 0", np.zeros((2, 1)), 1.0)
    0.0
    """
    R = np.asarray(residual, float)
    if R.size == 0:
        return 0.0
    if np.ndim(scale) == 0:
        res = float(np.linalg.norm(R, 2)) if np.all(np.isfinite(R)) else np.inf
        rel = res / scale if scale > 0 else (0.0 if res == 0 else np.inf)
    else:
        rel = relative_residual(R, scale)
    if not rel <= tols.IDENTITY_RTOL:
        raise PlacementAccuracyError(
            f"{what}: the identity {name} holds only to {rel:.2g} relative to its factors "
            f"(tolerance {tols.IDENTITY_RTOL:g}); the decoupling is lost to round-off, the data "
            "are too badly conditioned (scale the plant's states or outputs)"
        )
    return rel


def check_fixed_modes(values, fixed, *, what: str = "the observer") -> None:
    """Raise unless every fixed mode is among ``values`` (the observer's error poles).

    A decoupling observer cannot move the invariant zeros: they are always
    error poles. An error matrix without them does not decouple (its error
    depends on the unknown input), whatever its gain was meant to do.

    Parameters
    ----------
    values : array_like of complex
        The observer's error poles.
    fixed : array_like of complex
        The fixed modes (the invariant zeros).
    what : str
        How the design is called in messages.

    Raises
    ------
    PlacementAccuracyError

    Examples
    --------
    >>> from uio_teach.verify import check_fixed_modes
    >>> check_fixed_modes([-1.0, -2.0, -3.0], [-2.0])
    >>> try:
    ...     check_fixed_modes([-1.0, -3.0], [-2.0])
    ... except ValueError as err:
    ...     print(str(err)[:50])
    the observer: the fixed mode(s) {-2} are not error
    """
    w = np.asarray(values, complex).ravel()
    z = np.asarray(fixed, complex).ravel()
    if not z.size:
        return
    if w.size < z.size:
        missing, nearest = z, np.zeros(0)
    else:
        cost = np.abs(z[:, None] - w[None, :])
        rows, cols = linear_sum_assignment(cost)
        # relative to the larger of the mode and the observer's own scale (its largest pole)
        scale = float(np.max(np.abs(w))) or 1.0
        err = cost[rows, cols] / np.maximum(np.abs(z[rows]), scale)
        bad = err > tols.WARN_RTOL
        missing, nearest = z[rows[bad]], w[cols[bad]]
    if missing.size:
        raise PlacementAccuracyError(
            f"{what}: the fixed mode(s) {_fmt(missing)} are not error poles (nearest "
            f"{_fmt(nearest)}): the error would depend on the unknown input, so the observer "
            "is refused"
        )


LEAK_RTOL = tols.LEAK_RTOL
"""``uio_teach.tolerances.LEAK_RTOL``."""

LEAK_REFUSE = tols.LEAK_REFUSE
"""``uio_teach.tolerances.LEAK_REFUSE``."""


class DecouplingWarning(UIOTeachWarning):
    """The design decouples only to a stated fraction: it amplifies round-off (a small ``C E``)."""


class DecouplingError(PlacementAccuracyError):
    """The returned matrices do not decouple the estimation error from the unknown input."""


class DecouplingLeak(NamedTuple):
    """How much of the unknown input reaches the estimation error (:func:`decoupling_leak`).

    Attributes
    ----------
    leak : float
        Largest gain of ``G_de`` over the largest gain of ``G_dx`` at the test points, from the
        residuals of the stored matrices formed in extended precision.
    bound : float
        ``leak`` plus what the rounding of the residuals' computation can add: what the stored
        matrices can leak at most.
    amplification : float
        ``bound / eps``: how many double-precision rounding errors of the data the realization
        turns into a leak.
    """

    leak: float
    bound: float
    amplification: float


_EXACT_NORM_UP_TO = 60
"""Up to this many observer states the leak's bound uses the exact norm of each resolvent;
beyond, LAPACK's estimate of its 1-norm times ``3 sqrt(n)`` (an O(n^2) step per point)."""


def decoupling_leak(A, E, C, F, K, Co, Dy, M=None, discrete: bool = False) -> DecouplingLeak:
    """The unknown input's path to an observer's estimation error, from first principles.

    The observer ``w' = F w + K y + ...``, ``xhat = Co w + Dy y`` estimates ``theta x`` with
    ``theta = I - M C`` (``M = Dy`` for the UIO and the PMO): with ``eps = theta x - w``,
    ``eps' = F eps + R x + theta E d`` where ``R = theta A - F theta - K C``, and the estimation
    error is ``R0 x + Co eps`` with ``R0 = I - Dy C - Co theta``. All three residuals are zero
    for an observer that decouples. They are formed from the stored matrices in extended
    precision (``numpy.longdouble``), so that the rounding of forming them sits well below the
    double-precision rounding they measure, and their effect is evaluated at frequencies
    ``s = j w`` spread over the plant's and the observer's and at each resonance (``z = e^jw``
    in discrete time): ``G_de(s) = R0 G_dx(s) + Co (sI - F)^-1 (R G_dx(s) + theta E)`` against
    ``G_dx(s) = (sI - A)^-1 E``, largest gain against largest gain.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach.verify import decoupling_leak
    >>> obs = ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3])
    >>> pl = obs.plant
    >>> res = decoupling_leak(pl.A, pl.E, pl.C, obs.F, obs.K, np.eye(3), obs.H)
    >>> bool(res.bound < 1e-12)
    True
    """
    A, E, C, F, K, Co, Dy = (np.asarray(X, float) for X in (A, E, C, F, K, Co, Dy))
    M = Dy if M is None else np.asarray(M, float)
    n, q = E.shape
    if q == 0 or n == 0:
        return DecouplingLeak(0.0, 0.0, 0.0)
    if not all(np.all(np.isfinite(X)) for X in (A, E, C, F, K, Co, Dy, M)):
        return DecouplingLeak(np.inf, np.inf, np.inf)
    A, E, C, F, K, Co, Dy, M = _balanced(A, E, C, F, K, Co, Dy, M)
    ext = np.longdouble
    # the rounding of the residuals' own computation: sqrt(n) times the working precision times
    # the size of their terms (rounding errors of a sum add up like a random walk)
    gamma = 4 * np.sqrt(n + 2) * float(np.finfo(ext).eps)
    with np.errstate(all="ignore"):
        Ax, Ex, Cx, Fx, Kx, Cox, Dyx, Mx = (X.astype(ext) for X in (A, E, C, F, K, Co, Dy, M))
        eye = np.eye(n, dtype=ext)
        theta = eye - Mx @ Cx
        R = (theta @ Ax - Fx @ theta - Kx @ Cx).astype(float)
        R1 = (theta @ Ex).astype(float)
        R0 = (eye - Dyx @ Cx - Cox @ theta).astype(float)
        aT = np.eye(n) + np.abs(M) @ np.abs(C)
        aA, aF, aK, aC, aE = (np.abs(X) for X in (A, F, K, C, E))
        # how far each residual can be from its computed value
        Rb = gamma * float(np.linalg.norm(aT @ aA + aF @ aT + aK @ aC, 2))
        R1b = gamma * float(np.linalg.norm(aT @ aE, 2))
        R0b = gamma * float(np.linalg.norm(np.eye(n) + np.abs(Dy) @ aC + np.abs(Co) @ aT, 2))
        if not (np.isfinite(Rb) and np.isfinite(R1b) and np.isfinite(R0b)):
            return DecouplingLeak(np.inf, np.inf, np.inf)
        lam = np.concatenate([_resolved_modes(A, discrete), _resolved_modes(F, discrete)])
    points = _test_points(lam[np.isfinite(lam)], discrete)
    leak = bound = gain = 0.0
    # both resolvents through Schur forms computed once: each test point costs triangular
    # solves, O(n^2), instead of an inverse, O(n^3). Everything else is carried into the Schur
    # coordinates once too: with Y = (zI - S)^-1 V* E, X = V Y (so ||X|| = ||Y||), R X = R V Y
    # and R0 X = R0 V Y; a point then costs two triangular solves and three products with
    # q columns, and the diagonal of each shifted Schur form
    S, V = sla.schur(A.astype(complex), output="complex")
    T, U = sla.schur(F.astype(complex), output="complex")
    nF = T.shape[0]
    VE = V.conj().T @ E
    CoU = Co @ U
    RV = U.conj().T @ (R @ V)
    R1U = U.conj().T @ R1
    R0V = R0 @ V
    nCo = float(np.linalg.norm(CoU, 2))
    lam_A, lam_F = np.diag(S).copy(), np.diag(T).copy()
    # the 1-norm of zI - T: the off-diagonal column sums do not depend on z
    off_T = np.abs(np.triu(T, 1)).sum(axis=0)
    # zI - S and zI - T share their off-diagonal parts at every point: only the diagonal moves
    zS, zT = -S, -T
    diag_S, diag_T = np.diag_indices(n), np.diag_indices(nF)
    root_n = np.sqrt(max(nF, 1))
    # a test point on an eigenvalue to round-off (an undamped mode, a pole at the origin): the
    # transfer function is not defined there, and its neighbours carry its gain
    near_A = 100 * n * _EPS * max(float(np.linalg.norm(A, 2)), _TINY)
    near_F = 100 * n * _EPS * max(float(np.linalg.norm(F, 2)), _TINY)
    for z in points:
        if np.any(np.abs(lam_A - z) <= near_A) or np.any(np.abs(lam_F - z) <= near_F):
            continue
        zS[diag_S] = z - lam_A
        zT[diag_T] = z - lam_F
        with np.errstate(all="ignore"):
            Y = sla.solve_triangular(zS, VE, check_finite=False)
            W = sla.solve_triangular(zT, RV @ Y + R1U, check_finite=False)
            # ||(zI - F)^-1||_2 <= sqrt(n) ||(zI - T)^-1||_1, the 1-norm from LAPACK's estimate
            rcond, info = lapack.ztrcon(zT, norm="1", uplo="U", diag="N")
        if info != 0 or not rcond > 0:
            continue
        if nF <= _EXACT_NORM_UP_TO:
            # small: the exact norm (an inverse per point is cheap at this size)
            with np.errstate(all="ignore"):
                inv = sla.solve_triangular(zT, np.eye(nF), check_finite=False)
                n_inv = float(np.linalg.norm(inv, 2)) if np.all(np.isfinite(inv)) else np.inf
        else:
            n_inv = root_n * 3.0 / (rcond * float(np.max(off_T + np.abs(z - lam_F))))
        if not (np.all(np.isfinite(Y)) and np.all(np.isfinite(W)) and np.isfinite(n_inv)):
            continue
        nx = _norm2_thin(Y)
        gain = max(gain, nx)
        here = _norm2_thin(R0V @ Y + CoU @ W)
        leak = max(leak, here)
        bound = max(bound, here + R0b * nx + nCo * n_inv * (Rb * nx + R1b))
    if gain == 0:
        return DecouplingLeak(0.0, 0.0, 0.0)
    return DecouplingLeak(leak / gain, bound / gain, bound / gain / _EPS)


def _norm2_thin(X: np.ndarray) -> float:
    """``||X||_2`` of a tall thin matrix (q columns) from its q x q Gram matrix, not an SVD of
    ``X``: the square root of the largest eigenvalue of ``X^H X`` (to a relative ``q eps``)."""
    if X.shape[1] == 1:
        return float(np.linalg.norm(X))
    scale = float(np.max(np.abs(X))) if X.size else 0.0
    if not scale > 0 or not np.isfinite(scale):
        return scale
    Xs = X / scale
    return scale * float(np.sqrt(max(np.linalg.eigvalsh(Xs.conj().T @ Xs)[-1], 0.0)))


def _resolved_modes(X: np.ndarray, discrete: bool) -> np.ndarray:
    """The eigenvalues of ``X``, each one that round-off cannot tell from the origin (from 1
    in discrete time) put exactly there.

    A computed eigenvalue is within ``eps ||X|| / s`` of the exact one to first order, ``s`` the
    cosine between its left and right eigenvectors. A defective one (a Jordan block: ``s``
    near ``sqrt(eps)`` for a block of 2) spreads like ``eps^(1/k)``, and where it lands depends
    on the arithmetic (the CPU, the BLAS): a double integrator's two zeros come out exactly 0
    on one machine and ``+-1e-9`` on another. The test points taken at each mode's rate would
    then follow the round-off; a mode at rest to round-off gives no rate of its own.
    """
    n = X.shape[0]
    if n == 0:
        return np.zeros(0, complex)
    with np.errstate(all="ignore"):
        try:
            lam, vl, vr = sla.eig(X, left=True, right=True)
        except (ValueError, np.linalg.LinAlgError):  # pragma: no cover - finite data
            return np.linalg.eigvals(X)
        s = np.abs(np.sum(vl.conj() * vr, axis=0)) / (
            np.linalg.norm(vl, axis=0) * np.linalg.norm(vr, axis=0)
        )
        spread = 4 * n * _EPS * float(np.linalg.norm(X, 1)) / np.maximum(s, _EPS)
    rest = 1.0 if discrete else 0.0
    at_rest = np.abs(lam - rest) <= spread
    return np.where(at_rest, rest, lam).astype(complex)


def _balanced(A, E, C, F, K, Co, Dy, M):
    """Everything in the plant's balanced units (powers of 2, exact): the leak and its bound are
    then the same whatever units the states, inputs and outputs are measured in."""
    from .balancing import plant_scaling  # deferred: balancing imports the algorithms above
    from .plant import Plant

    n = A.shape[0]
    try:
        sc = plant_scaling(Plant(A, C, E=E))
    except (ValueError, FloatingPointError):  # pragma: no cover - data checked before
        return A, E, C, F, K, Co, Dy, M
    t, wy, wd = sc.t, sc.wy, sc.wd
    if F.shape != (n, n):  # pragma: no cover - every observer here estimates theta x
        return A, E, C, F, K, Co, Dy, M
    with np.errstate(all="ignore"):
        out = (
            A / t[:, None] * t[None, :],
            E / t[:, None] * wd[None, :],
            wy[:, None] * C * t[None, :],
            F / t[:, None] * t[None, :],
            K / t[:, None] / wy[None, :],
            Co / t[:, None] * t[None, :],
            Dy / t[:, None] / wy[None, :],
            M / t[:, None] / wy[None, :],
        )
    return out if all(np.all(np.isfinite(X)) for X in out) else (A, E, C, F, K, Co, Dy, M)


def _test_points(lam: np.ndarray, discrete: bool) -> np.ndarray:
    """Where the leak is evaluated: DC, every mode at its own rate, and a grid between.

    Continuous time: ``s = j w`` at ``w = 0``, at each mode's magnitude (a slow fixed mode
    ``1e-9`` from the origin sets a band at ``1e-9``, evaluated there, not skipped), a tenth and
    ten times it, at each resonance, and on a logarithmic grid over all of them. Discrete
    time: ``z = e^(j w)`` with ``w`` the same for each mode's distance from ``z = 1`` (its rate),
    its angle, and a grid over ``[0, pi]``.
    """
    if discrete:
        rate = np.abs(1.0 - lam)
        ang = np.abs(np.angle(lam))
    else:
        rate = np.abs(lam)
        ang = np.abs(lam.imag)
    rate = rate[(rate > 0) & np.isfinite(rate)]
    own = np.concatenate([rate, rate / 10, rate * 10, ang[ang > 0]])
    if rate.size:
        lo, hi = float(rate.min()) / 10, float(rate.max()) * 10
        own = np.concatenate([own, np.geomspace(lo, hi, 25)])
    if discrete:
        w = np.concatenate([[0.0], np.linspace(0.0, np.pi, 13), own[own <= np.pi]])
        return np.exp(1j * np.unique(w))
    return 1j * np.unique(np.concatenate([[0.0], own]))


def check_decoupling(
    A,
    E,
    C,
    F,
    K,
    Co,
    Dy,
    M=None,
    *,
    discrete: bool = False,
    what: str = "the observer",
    cause: str = "",
    stacklevel: int = 3,
) -> DecouplingLeak:
    """Refuse a design that leaks; warn when it decouples only to more than ``LEAK_RTOL``.

    Parameters
    ----------
    A, E, C : array_like
        The plant.
    F, K, Co, Dy, M : array_like
        The observer (see :func:`decoupling_leak`).
    what : str
        How the design is called in messages.
    cause : str
        What makes the realization amplify round-off (e.g. the size of ``H``), for the messages.

    Raises
    ------
    DecouplingError
        The stored matrices may leak more than ``LEAK_REFUSE`` of the state's response (the
        bound, round-off of the check included, not only the computed value).

    Warns
    -----
    DecouplingWarning
        The leak is certainly below ``LEAK_REFUSE`` but not below ``LEAK_RTOL``.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.verify import check_decoupling
    >>> A = np.diag([-1.0, -2.0]); E = np.array([[1.0], [0.0]]); C = np.array([[1.0, 0.0]])
    >>> Dy = np.array([[1.0], [0.0]])  # xhat = (y, w): the first state is measured
    >>> bool(check_decoupling(A, E, C, A, np.zeros((2, 1)), np.eye(2), Dy).bound < 1e-12)
    True
    """
    res = decoupling_leak(A, E, C, F, K, Co, Dy, M, discrete)
    if res.bound <= tols.LEAK_RTOL:
        return res
    why = f"the realization amplifies round-off by {res.amplification:.2g}" + (
        f" ({cause})" if cause else ""
    )
    lam = np.linalg.eigvals(np.asarray(A, float)) if np.all(np.isfinite(A)) else np.zeros(0)
    growing = lam[~is_stable(lam, discrete, margin=0.0)] if lam.size else lam
    if growing.size and not res.bound <= tols.LEAK_RTOL:
        # the leak is a fraction of the state's response; an unstable plant's state grows
        # without bound under a bounded unknown input, and that fraction of it with it
        raise DecouplingError(
            f"{what} does not decouple: the unknown input may reach the estimation error with "
            f"up to {res.bound:.2g} of its gain on the state, and the plant is unstable (modes "
            + ", ".join(f"{complex(z):.3g}" for z in growing[:4])
            + "): its state grows without bound under a bounded unknown input, and that "
            f"fraction of it with it, so the estimation error diverges; {why}. The design is "
            "refused"
        )
    if not res.bound <= tols.LEAK_REFUSE:
        raise DecouplingError(
            f"{what} does not decouple: the unknown input may reach the estimation error with "
            f"up to {res.bound:.2g} of its gain on the state ({res.leak:.2g} computed, judged on "
            f"the returned matrices at every frequency, DC included); {why}. The design is "
            "refused"
        )
    warnings.warn(
        f"{what} decouples only approximately: the unknown input may reach the estimation error "
        f"with up to {res.bound:.2g} of its gain on the state; {why}",
        DecouplingWarning,
        stacklevel=stacklevel,
    )
    return res
