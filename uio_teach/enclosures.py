"""Validated enclosures of eigenvalues and invariant zeros: disks no perturbation can leave.

A computed eigenvalue is exact for a nearby matrix, but how far it is from the eigenvalue of
the matrix given depends on the matrix: a simple eigenvalue moves like ``kappa * eps``, an
eigenvalue of a Jordan block of size ``k`` like ``eps**(1/k)``. The functions here do not
estimate that distance, they bound it, by an argument that holds for every perturbation up to
a stated size:

1. The matrix is brought to Schur form ``M = Q T Q^H`` and its eigenvalues grouped into
   clusters; ``T`` is block-diagonalized, ``T S = S B``, by Sylvester equations, and the
   residual of that computation is measured and added to the perturbation.
2. For ``mu`` at distance ``r`` from a cluster's centre,
   ``||(mu I - M)^{-1}|| <= sum_j kappa_j ||(mu I - B_j)^{-1}||`` with ``kappa_j`` the norm of
   cluster ``j``'s spectral projector, and for a triangular block with spread ``rho`` and
   strictly upper part ``nu``, ``||(mu I - B_j)^{-1}|| <= sum_i nu^i / (d - rho)^(i+1)``
   (Henrici), ``d`` the distance from ``mu`` to the block's centre.
3. When that bound is below ``1 / ||perturbation||`` on the whole circle of radius ``r``, no
   perturbed matrix has an eigenvalue on the circle: the cluster's eigenvalues stay inside,
   however the perturbation grows to its size (continuity). A cluster for which no radius
   works is merged with its nearest neighbour, and the argument made again.

:func:`zero_disks` applies this to the invariant zeros from unknown inputs to outputs of a
plant that meets the rank condition: on the structure-revealing reduction (the unknown
inputs eliminated, square or with more outputs than unknown inputs), the zeros are the
eigenvalues of a matrix ``Z`` (square plants) or the unobservable modes of a pair
``(Z, Cz)`` (tall plants), and a perturbation of the data of relative size ``delta`` moves
``Z`` by at most a computed amount.

Examples
--------
>>> import numpy as np
>>> from uio_teach.enclosures import eigenvalue_disks
>>> J = np.array([[-1.0, 1.0], [0.0, -1.0]])   # a Jordan block: a double eigenvalue
>>> disks = eigenvalue_disks(J, 1e-16)
>>> bool(disks.radius[0] > 1e-9), bool(disks.radius[0] < 1e-6)   # about sqrt(1e-16)
(True, True)
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg as sla
from scipy.linalg import lapack

from . import tolerances as tols
from .linalg import ZeroSet


def _real_cleaned(z: np.ndarray) -> np.ndarray:
    """Imaginary parts that are round-off of a real value set to 0 (``REAL_RTOL``)."""
    z = np.asarray(z, complex)
    with np.errstate(invalid="ignore"):
        real = np.abs(z.imag) <= tols.REAL_RTOL * np.abs(z)
    return np.where(real, z.real + 0j, z)


def _nearest_boundary(z: np.ndarray, discrete: bool) -> np.ndarray:
    if discrete:
        return np.exp(1j * np.where(z == 0, 0.0, np.angle(z)))
    return 1j * z.imag


def _order(z: np.ndarray) -> np.ndarray:
    """Indices sorting by real part (rounded to the largest value's scale), then imaginary."""
    finite = np.abs(z[np.isfinite(z)])
    scale = float(np.max(finite)) if finite.size and np.max(finite) > 0 else 1.0
    with np.errstate(invalid="ignore"):
        key = np.round(z.real / scale, 9)
    return np.lexsort((z.imag, key))


__all__ = [
    "Disks",
    "ReducedZeros",
    "eigenvalue_disks",
    "reduced_zero_system",
    "unobservable_part",
    "validated_zeros",
]

_SAFETY = 2.0
"""Factor on every first-order bound and on the perturbation (second-order terms, norms of
computed rather than exact factors)."""


class Disks(NamedTuple):
    """Eigenvalues with disks that hold them for every perturbation up to a size.

    Attributes
    ----------
    values : numpy.ndarray of complex
        The computed eigenvalues.
    centre : numpy.ndarray of complex
        For each eigenvalue, the centre of its cluster's disk.
    radius : numpy.ndarray of float
        For each eigenvalue, the radius of its cluster's disk (``inf`` when no disk could be
        proved, e.g. the perturbation is as large as the matrix).
    cluster : numpy.ndarray of int
        For each eigenvalue, its cluster (eigenvalues of one cluster share one disk, which
        holds exactly that many eigenvalues of every perturbed matrix).
    """

    values: np.ndarray
    centre: np.ndarray
    radius: np.ndarray
    cluster: np.ndarray


def _reorder(T: np.ndarray, Q: np.ndarray, labels: np.ndarray):
    """Reorder the Schur form so that each cluster's eigenvalues are contiguous."""
    n = T.shape[0]
    first = {}
    for i, c in enumerate(labels):
        first.setdefault(int(c), i)
    target = sorted(range(n), key=lambda i: (first[int(labels[i])], i))
    if target == list(range(n)):
        return T, Q, labels
    current = list(range(n))  # current[pos] = original index
    for pos, want in enumerate(target):
        at = current.index(want)
        if at != pos:
            T, Q, info = lapack.ztrexc(T, Q, at + 1, pos + 1)
            if info != 0:  # pragma: no cover - LAPACK refuses only ill-posed swaps
                raise np.linalg.LinAlgError("Schur reordering failed")
            current.insert(pos, current.pop(at))
    return T, Q, labels[np.array(target)]


def _block_transform(T: np.ndarray, bounds: list[int]) -> np.ndarray:
    """``S`` (unit upper block triangular) with ``T S = S diag(T_jj)`` for the given blocks."""
    n = T.shape[0]
    if len(bounds) <= 2:
        return np.eye(n, dtype=complex)
    mid_target = n / 2
    inner = bounds[1:-1]
    m = min(inner, key=lambda b: abs(b - mid_target))
    T11, T12, T22 = T[:m, :m], T[:m, m:], T[m:, m:]
    Y, scale, info = lapack.ztrsyl(T11, T22, -T12, isgn=-1)
    if info < 0 or scale == 0:  # pragma: no cover
        Y = np.full_like(T12, np.inf)
    else:
        Y = Y / scale
    S1 = _block_transform(T11, [b for b in bounds if b <= m])
    S2 = _block_transform(T22, [b - m for b in bounds if b >= m])
    S = np.zeros((n, n), complex)
    S[:m, :m] = S1
    S[m:, m:] = S2
    S[:m, m:] = Y @ S2
    return S


def _henrici(d: np.ndarray, rho: float, nu: float, k: int) -> np.ndarray:
    """Bound on ``||(mu I - B)^{-1}||`` for a triangular ``k x k`` block at distance ``d``."""
    x = np.asarray(d, float) - rho
    with np.errstate(all="ignore"):
        out = np.zeros_like(x)
        for i in range(k):
            out = out + nu**i / x ** (i + 1)
    return np.where(x > 0, out, np.inf)


def _cluster_radius(c, centres, rho, nu, size, kappa, budget) -> float:
    """The smallest radius whose circle around cluster ``c`` no perturbation reaches."""
    others = np.arange(centres.size) != c
    dist = np.abs(centres[others] - centres[c])
    reach = dist - rho[others]
    top = float(np.min(reach)) if reach.size else np.inf
    lo = rho[c]
    if not top > lo:
        return np.inf
    o_kappa, o_nu, o_size, o_rho = kappa[others], nu[others], size[others], rho[others]
    kmax = int(o_size.max()) if o_size.size else 1

    def bound(r):
        r = np.atleast_1d(np.asarray(r, float))
        own = kappa[c] * _henrici(r, rho[c], nu[c], size[c])
        if not reach.size:
            return own
        # every other block at its distance from the circle's nearest point (Henrici's sum)
        x = dist[None, :] - r[:, None] - o_rho[None, :]
        with np.errstate(all="ignore"):
            inv = 1.0 / x
            s = inv.copy()
            term = inv
            for i in range(1, kmax):
                term = term * (o_nu[None, :] * inv)
                s = s + np.where(o_size[None, :] > i, term, 0.0)
            s = np.where(x > 0, s, np.inf)
        return own + s @ o_kappa

    if np.isfinite(top):
        span = top
    else:  # one cluster: far enough for its own term, kappa (nu + 1)^k / budget, to be small
        span = 1e3 * (lo + (kappa[c] + 1.0) * (nu[c] + 1.0) ** size[c] * max(budget, 1e-300))
        span = max(span, 1e3 * (lo + nu[c]) + 1e-300)
    grid = lo + np.geomspace(1e-18 * max(span, 1e-300), span, 120)[:-1]
    ok = bound(grid) * budget < 1.0
    if not np.any(ok):
        return np.inf
    i = int(np.argmax(ok))
    hi = float(grid[i])
    low = float(grid[i - 1]) if i else lo
    fine = np.linspace(low, hi, 66)[1:]
    ok = bound(fine) * budget < 1.0
    return float(fine[int(np.argmax(ok))]) if np.any(ok) else hi


def eigenvalue_disks(M: np.ndarray, perturbation: float, *, basis: bool = False):
    """Disks holding the eigenvalues of every ``M + P`` with ``||P||_2 <= perturbation``.

    Parameters
    ----------
    M : array_like, shape (n, n)
        The matrix (real or complex).
    perturbation : float
        The size of the perturbation (2-norm, absolute). The rounding of the computation
        itself (Schur form, block diagonalization) is measured and added.
    basis : bool
        Also return ``(X, T, starts)``: ``X`` whose columns ``starts[j]:starts[j+1]`` span
        cluster ``j``'s invariant subspace, ``M X = X B`` with ``B`` the diagonal blocks of
        ``T`` (for each cluster, in that order).

    Returns
    -------
    Disks, or (Disks, (X, T, starts))

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.enclosures import eigenvalue_disks
    >>> disks = eigenvalue_disks(np.diag([-1.0, -2.0]), 1e-10)
    >>> bool(np.all((disks.radius >= 1e-10) & (disks.radius < 1e-9)))  # with room: a bound
    True
    """
    M = np.atleast_2d(np.asarray(M))
    n = M.shape[0]
    if n == 0:
        z = np.zeros(0)
        disks = Disks(z.astype(complex), z.astype(complex), z, z.astype(int))
        return (disks, (np.zeros((0, 0)), np.zeros((0, 0)), [0])) if basis else disks
    if not np.all(np.isfinite(M)):
        lam = np.full(n, np.nan + 0j)
        disks = Disks(lam, lam, np.full(n, np.inf), np.zeros(n, int))
        return (disks, (np.eye(n), np.diag(lam), [0, n])) if basis else disks
    with np.errstate(all="ignore"):
        return _disks(M, n, perturbation, basis)


def _disks(M, n, perturbation, basis):
    T, Q = sla.schur(M.astype(complex), output="complex")
    normM = float(np.linalg.norm(M))
    # the Schur form is exact for a matrix within this of M (backward stable, with room)
    base = _SAFETY * float(perturbation) + 10.0 * n * tols.EPS * normM
    labels = np.arange(n)
    for _ in range(n + 1):
        T, Q, labels = _reorder(T, Q, labels)
        starts = [0] + [i for i in range(1, n) if labels[i] != labels[i - 1]] + [n]
        S = _block_transform(T, starts)
        if not np.all(np.isfinite(S)):
            S = np.eye(n, dtype=complex)
            starts = [0, n]
            labels = np.zeros(n, int)
        Sinv = sla.solve_triangular(S, np.eye(n, dtype=complex), unit_diagonal=True)
        nb = len(starts) - 1
        B = np.zeros_like(T)
        for j in range(nb):
            a, b = starts[j], starts[j + 1]
            B[a:b, a:b] = T[a:b, a:b]
        resid = float(np.linalg.norm(T @ S - S @ B)) * float(np.linalg.norm(Sinv))
        budget = _SAFETY * (base + resid)
        lam = np.diag(T)
        centres = np.array([np.mean(lam[starts[j] : starts[j + 1]]) for j in range(nb)])
        rho = np.array(
            [np.max(np.abs(lam[starts[j] : starts[j + 1]] - centres[j])) for j in range(nb)]
        )
        nu = np.array(
            [
                np.linalg.norm(np.triu(T[starts[j] : starts[j + 1], starts[j] : starts[j + 1]], 1))
                for j in range(nb)
            ]
        )
        size = np.array([starts[j + 1] - starts[j] for j in range(nb)])
        kappa = np.array(
            [
                np.linalg.norm(S[:, starts[j] : starts[j + 1]])
                * np.linalg.norm(Sinv[starts[j] : starts[j + 1], :])
                for j in range(nb)
            ]
        )
        radii = np.array(
            [_cluster_radius(j, centres, rho, nu, size, kappa, budget) for j in range(nb)]
        )
        bad = np.flatnonzero(~np.isfinite(radii))
        if not bad.size or nb == 1:
            break
        # merge every failing cluster with its nearest neighbour, then prove again
        for c in bad:
            gap = np.abs(centres - centres[c]) - rho - rho[c]
            gap[c] = np.inf
            j = int(np.argmin(gap))
            keep, drop = labels[starts[c]], labels[starts[j]]
            labels = np.where(labels == drop, keep, labels)
    which = np.zeros(n, int)
    for j in range(len(starts) - 1):
        which[starts[j] : starts[j + 1]] = j
    lam = np.diag(T)
    disks = Disks(lam, centres[which], radii[which], which)
    if basis:
        return disks, (Q @ S, T, starts)
    return disks


class ReducedZeros(NamedTuple):
    """The zeros' structure-revealing reduction of a plant that meets the rank condition.

    The invariant zeros from the unknown inputs to the outputs are the eigenvalues of ``Z``
    when ``Cz`` has no rows (as many outputs as unknown inputs, after the measurement
    disturbance's outputs are taken out), else the unobservable modes of ``(Z, Cz)``.
    A perturbation of the data of relative size ``delta`` moves ``Z`` by at most ``dZ`` and
    ``Cz`` by at most ``dC`` (2-norm, first order with room).
    """

    Z: np.ndarray
    Cz: np.ndarray
    dZ: float
    dC: float


def _col_basis(X: np.ndarray, r: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``U`` orthogonal, with the first ``r`` columns spanning X's range; X's singular values."""
    U, s, _ = np.linalg.svd(X, full_matrices=True)
    return U, s, U[:, :r]


def reduced_zero_system(
    A: np.ndarray, E: np.ndarray, C: np.ndarray, D: np.ndarray, delta: float
) -> ReducedZeros | None:
    """The reduction of (balanced) data ``(A, E, C, D)`` whose zeros are those of the plant.

    ``D`` (outputs disturbed by ``v``) is eliminated with the outputs it reaches, ``E`` is
    compressed to its range (``x = U [x1; x2]``), the outputs that see ``x1`` are solved for
    it (``C1 x1 + C2 x2 = y``, ``C1`` of full column rank by the rank condition), and what
    remains is the pair ``Z = A22 - A21 C1^+ C2``, ``Cz`` (the outputs ``C1`` does not reach).
    Returns None when the rank condition does not hold to the data's precision (a factor of
    the amplification is not bounded).
    """
    n, q = E.shape
    p = C.shape[0]
    nA, nE, nC = (float(np.linalg.norm(X, 2)) if X.size else 0.0 for X in (A, E, C))
    dA, dE, dCd = delta * nA, delta * nE, delta * nC
    # the measurement disturbance: its outputs determine v and are taken out
    if D.size and np.any(D):
        U, s, _ = np.linalg.svd(D, full_matrices=True)
        rD = int(np.sum(s > tols.RANK_RTOL * max(D.shape) * tols.EPS * s[0]))
        C = U[:, rD:].T @ C
        if rD:
            tilt = delta * float(s[0]) / float(s[rD - 1])
            if tilt >= 0.5:
                return None
            dCd = dCd + 2 * tilt * nC
    # the unknown input's range: x = U [x1; x2]
    U, s, _ = np.linalg.svd(E, full_matrices=True)
    rE = int(np.sum(s > tols.RANK_RTOL * max(E.shape) * tols.EPS * s[0])) if s.size else 0
    theta = dE / float(s[rE - 1]) if rE else 0.0
    if theta >= 0.5:
        return None
    At = U.T @ A @ U
    Ct = C @ U
    # a tilt of range(E) by theta is a similarity of A and C by I + O(theta)
    dA = dA + 2 * theta * nA
    dCd = dCd + 2 * theta * nC
    A21, A22 = At[rE:, :rE], At[rE:, rE:]
    C1, C2 = Ct[:, :rE], Ct[:, rE:]
    if rE == 0:
        return ReducedZeros(A22, C2, _SAFETY * dA, _SAFETY * dCd)
    U1, s1, V1t = np.linalg.svd(C1, full_matrices=True)
    smin = float(s1[rE - 1]) if s1.size >= rE else 0.0
    if not smin > 0 or dCd / smin >= 0.5:
        return None
    g = 1.0 / (1.0 - dCd / smin)
    Ca, Cb = U1[:, :rE].T @ C2, U1[:, rE:].T @ C2
    X = V1t.T @ ((Ca) / s1[:rE, None])  # C1^+ C2 restricted to C1's range
    nX = float(np.linalg.norm(X, 2))
    n21 = float(np.linalg.norm(A21, 2))
    Z = A22 - A21 @ X
    # first order: dZ = dA22 - dA21 X - A21 C1^+ (dC2 - dC1 X), the rounding of the steps
    dZ = dA * (1.0 + nX) + n21 * g * (dCd / smin) * (1.0 + nX)
    dZ += 10.0 * (n + p) * tols.EPS * (nA + n21 * nX)
    dC = dCd * (1.0 + g * nX) + 10.0 * (n + p) * tols.EPS * nC * (1.0 + nX)
    return ReducedZeros(Z, Cb, _SAFETY * dZ, _SAFETY * dC)


def unobservable_part(Z: np.ndarray, Cz: np.ndarray, thr: float):
    """The unobservable block of ``(Z, Cz)`` by an orthogonal staircase in O(n^3) flops.

    The staircase of the dual pair ``(Z^T, Cz^T)`` (Householder reflections, each applied to
    the rows and columns it touches): a step's singular values at or below ``thr`` count as 0.
    Returns ``(Au, dropped, kept)``: the block whose eigenvalues are the unobservable modes,
    the largest singular value taken as 0, and the smallest kept.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.enclosures import unobservable_part
    >>> Au, dropped, kept = unobservable_part(np.diag([-1.0, -2.0]), np.array([[1.0, 0.0]]), 1e-12)
    >>> Au.round(12).tolist()
    [[-2.0]]
    """
    F = np.array(Z.T, dtype=float, copy=True)
    N = F.shape[0]
    Bk = np.array(Cz.T, dtype=float, copy=True)
    off = 0
    dropped, kept = 0.0, np.inf
    while off < N and Bk.shape[1]:
        U, s, _ = np.linalg.svd(Bk, full_matrices=False)
        r = int(np.sum(s > thr))
        if r < s.size:
            dropped = max(dropped, float(s[r]))
        if r == 0:
            break
        kept = min(kept, float(s[r - 1]))
        V = U[:, :r].copy()
        for j in range(r):
            x = V[j:, j]
            alpha = -np.copysign(np.linalg.norm(x), x[0] if x[0] != 0 else 1.0)
            v = x.copy()
            v[0] -= alpha
            nv = np.linalg.norm(v)
            if nv == 0:
                continue
            v /= nv
            V[j:, :] -= 2.0 * np.outer(v, v @ V[j:, :])
            a = off + j
            F[a:, :] -= 2.0 * np.outer(v, v @ F[a:, :])
            F[:, a:] -= 2.0 * np.outer(F[:, a:] @ v, v)
        Bk = F[off + r :, off : off + r]
        off += r
    return F[off:, off:].T.copy(), dropped, kept


def validated_zeros(
    A: np.ndarray,
    E: np.ndarray,
    C: np.ndarray,
    D: np.ndarray | None = None,
    *,
    discrete: bool = False,
):
    """Invariant zeros from ``(d, v)`` to ``y`` with proven disks, or None.

    For a plant that meets the rank condition (``[C E, D]`` of full column rank to the data's
    precision): every plant within the backward error ``ZERO_RTOL (n + p) eps`` (relative, in
    the units of the data given, which should be balanced) has each zero inside its disk
    (a zero of a Jordan block of size ``k`` gets a radius of order ``eps**(1/k)``). With more
    outputs than unknown inputs the zeros are the unobservable modes of the reduced pair and
    are ``fragile``: a plant that close has none. Returns None when the reduction's factors
    are not bounded at that precision (the rank condition is within round-off).

    Returns
    -------
    uio_teach.linalg.ZeroSet or None

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.enclosures import validated_zeros
    >>> A = np.array([[-1.0, 0.0], [0.0, -2.0]]); E = np.array([[1.0], [1.0]])
    >>> zs = validated_zeros(A, E, np.array([[1.0, 1.0]]))
    >>> zs.zeros.real.round(6).tolist(), bool(zs.radius[0] < 1e-12), zs.decided
    ([-1.5], True, True)
    """
    A = np.atleast_2d(np.asarray(A, float))
    n = A.shape[0]
    E = np.asarray(E, float).reshape(n, -1)
    C = np.asarray(C, float).reshape(-1, n)
    p = C.shape[0]
    D = np.zeros((p, 0)) if D is None else np.asarray(D, float).reshape(p, -1)
    delta = tols.ZERO_RTOL * (n + p) * tols.EPS
    if not all(np.all(np.isfinite(X)) for X in (A, E, C, D)):
        return None
    red = reduced_zero_system(A, E, C, D, delta)
    if red is None:
        return None
    if red.Cz.shape[0] and red.Z.shape[0]:
        disks = _tall_zero_disks(red, discrete)
        fragile = True
    else:
        disks = eigenvalue_disks(red.Z, red.dZ)
        fragile = False
    z = _real_cleaned(disks.values) if disks.values.size else disks.values
    radius = disks.radius + np.abs(disks.values - disks.centre)
    b = _nearest_boundary(np.where(np.isfinite(z), z, 0.0), discrete)
    distance = np.where(np.isfinite(z), np.abs(z - b), np.inf)
    order = _order(z) if z.size else np.zeros(0, int)
    rate = float(np.max(np.abs(np.linalg.eigvals(A)))) if n else 1.0
    return ZeroSet(
        zeros=z[order],
        radius=radius[order],
        distance=distance[order],
        unresolved=np.zeros(z.size, bool),
        backward_error=delta,
        discrete=bool(discrete),
        scale=1.0 if discrete else max(rate, np.finfo(float).tiny),
        fragile=np.full(z.size, fragile),
        validated=True,
    )


def _inside(centre: np.ndarray, radius: np.ndarray, discrete: bool) -> np.ndarray:
    """Whether each disk lies inside the stability region (its boundary excluded)."""
    with np.errstate(invalid="ignore"):
        if discrete:
            return np.abs(centre) + radius < 1.0
        return centre.real + radius < 0.0


def _tall_zero_disks(red: ReducedZeros, discrete: bool) -> Disks:
    """The unobservable modes of ``(Z, Cz)`` within the data's precision, with their disks.

    Every eigenvalue cluster of ``Z`` (its disk proven for ``dZ``) is tried: the number of its
    modes unobservable through ``Cz`` is read from the small pair ``(B_c, Cz X_c)`` on its
    invariant subspace. A cluster whose disk may leave the stability region is a zero only
    when the Hautus test fails there within the perturbation
    (``sigma_min([Z - c I; Cz]) - r <= dZ + dC``): a cluster that no plant that close leaves
    unobservable is not a zero of any of them.
    """
    Z, Cz, dZ, dC = red.Z, red.Cz, red.dZ, red.dC
    disks, (X, T, starts) = eigenvalue_disks(Z, dZ, basis=True)
    keep = np.zeros(Z.shape[0], bool)
    # (balanced data: Z and Cz of comparable size, their perturbations in one unit)
    thr = 10.0 * (dC + dZ)
    for j in range(len(starts) - 1):
        a, b = starts[j], starts[j + 1]
        Xc = X[:, a:b]
        nX = max(float(np.linalg.norm(Xc, 2)), np.finfo(float).tiny)
        Cc = Cz @ Xc / nX
        Bc = T[a:b, a:b] - disks.centre[a] * np.eye(b - a)
        nB = float(np.linalg.norm(Bc))
        # a nilpotent part within the perturbation is no structure of the data: normalising
        # it would blow round-off up to size 1 and make an unobservable cluster look observable
        Bc = Bc / nB if nB > thr else np.zeros_like(Bc)
        # the observability of the cluster's own pair: [Cc; Cc Bc; ...]
        blocks, cur = [Cc], Cc
        for _ in range(b - a - 1):
            cur = cur @ Bc
            blocks.append(cur)
        with np.errstate(all="ignore"):
            stack = np.vstack(blocks)
        if not np.all(np.isfinite(stack)):
            stack = Cc
        sv = np.linalg.svd(stack, compute_uv=False)
        k = (b - a) - int(np.sum(sv > thr))
        if k <= 0:
            if _inside(disks.centre[a : a + 1], disks.radius[a : a + 1], discrete)[0]:
                continue
            # clear of the region: only a failed Hautus test within the perturbation counts
            c = disks.centre[a]
            H = np.vstack([Z - c * np.eye(Z.shape[0]), Cz])
            smin = float(np.linalg.svd(H, compute_uv=False)[-1])
            if smin - disks.radius[a] > _SAFETY * (dZ + dC):
                continue
            k = b - a
        keep[a : a + k] = True
    idx = np.flatnonzero(keep)
    return Disks(disks.values[idx], disks.centre[idx], disks.radius[idx], disks.cluster[idx])
