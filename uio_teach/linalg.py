"""Linear-algebra building blocks: ranks, projections, observability and invariant zeros.

Everything here works on plain arrays and is shared by the existence check and
the observer designs.

**Tolerance policy.** Every yes/no decision of the course (a rank, observability, detectability, the
invariant zeros, the fixed modes) is made by one rule:

* **Relative to the factors, not to the product.** A singular value ``s`` of a
  matrix ``M`` counts as zero when ``s <= max(M.shape) * eps * scale``, where
  ``scale`` is the size of the data ``M`` was computed from: ``||C|| ||E||`` for
  ``C E``, ``||A||`` for the steps of the observability staircase, ``||M||``
  for a matrix given as data. A product that is zero in exact arithmetic and
  ``5.6e-17`` in floating point is then rank 0, because ``5.6e-17`` is round-off
  of numbers of size ``||C|| ||E||``; judged against its own tiny norm it would
  look like a full-rank matrix.
* **Relative to the data's precision.** ``eps`` is the double precision
  (``2.2e-16``) in :func:`rank` and ``rank_decision``; the course's verdicts
  give it room for the rounding of the computation that made ``M``
  (:mod:`uio_teach.tolerances`: ``RANK_RTOL * eps``, times ``n`` for ``C E``,
  in the rank condition, ``STAIRCASE_RTOL * eps`` in the observability
  staircase). Data known to fewer digits can pass ``rtol`` (e.g. ``1e-4``
  for a matrix printed with four decimals) to ``rank_decision``.
* **Marginal verdicts say so.** A kept singular value less than
  ``MARGIN`` (``RANK_MARGIN``) times the threshold means that the verdict hangs on round-off:
  ``rank_decision`` returns the ratio ``s / threshold`` as ``margin`` and
  ``marginal=True``; the existence report then states the verdict *and* the
  margin instead of guessing.
* **Invariant zeros** are computed on a scaled copy of the system
  (``||A|| = ||B|| = ||C|| = 1`` after a diagonal balancing of ``A``), so that a
  large eigenvalue of ``A`` does not make the other blocks look like zero.
* **Computed designs are verified** (``uio_teach.verify``): the obtained
  poles against the requested ones with a tolerance that grows with the
  eigenvalue condition numbers, and the decoupling identities ``T E = 0``,
  ``H C E = E``, ``H D = 0``, ``L D = 0`` against ``IDENTITY_RTOL = 1e-8``
  relative to the factors.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg as sla

from . import tolerances as tols

__all__ = [
    "MARGIN",
    "DROP_MARGIN",
    "RankDecision",
    "rank_decision",
    "rank",
    "pinv",
    "left_null",
    "observability_matrix",
    "observability_decomposition",
    "invariant_zeros",
    "checked_zeros",
    "ZeroSet",
    "is_stable",
    "ObservabilitySplit",
    "sort_poles",
    "one_blas_thread",
]


MARGIN = tols.RANK_MARGIN
"""``uio_teach.tolerances.RANK_MARGIN``, for the names of this module's documentation."""

DROP_MARGIN = tols.DROP_MARGIN
"""``uio_teach.tolerances.DROP_MARGIN``."""


class RankDecision(NamedTuple):
    """A numerical rank with the evidence for it.

    Attributes
    ----------
    rank : int
        Number of singular values above ``threshold``.
    threshold : float
        ``max(shape) * rtol * scale``: singular values at or below it are round-off.
    margin : float
        Smallest kept singular value divided by ``threshold`` (``inf`` when the
        rank is 0 or no singular value was dropped by a hair): how far the
        verdict is from the boundary.
    marginal : bool
        ``margin < MARGIN`` or ``below < DROP_MARGIN``: the verdict hangs on
        round-off.
    below : float
        The threshold divided by the largest dropped singular value (``inf``
        when none was dropped or it is exactly 0): how far a rank-deficient
        verdict is from the boundary on the other side.

    Examples
    --------
    >>> from uio_teach.linalg import rank_decision
    >>> rank_decision([[1.0, 0.0], [0.0, 1e-14]]).marginal
    True
    """

    rank: int
    threshold: float
    margin: float
    marginal: bool
    below: float = np.inf


def _threshold(shape, scale: float, rtol: float | None = None) -> float:
    rtol = np.finfo(float).eps if rtol is None else float(rtol)
    return max(shape) * rtol * scale


def _tol(M: np.ndarray, s: np.ndarray) -> float:
    return _threshold(M.shape, s[0] if s.size else 0.0)


def rank_decision(
    M: np.ndarray, *, scale: float | None = None, rtol: float | None = None
) -> RankDecision:
    """Numerical rank of ``M`` decided relative to ``scale``, with its margin.

    Parameters
    ----------
    M : array_like
        The matrix (real or complex).
    scale : float, optional
        Size of the data ``M`` was computed from, e.g. ``||C|| ||E||`` for the
        product ``C E``. Default: ``||M||`` (the largest singular value).
    rtol : float, optional
        Relative precision of the data; default the double precision ``eps``.

    Returns
    -------
    RankDecision

    Examples
    --------
    The product ``C E`` below is zero in exact arithmetic; judged against the
    size of its factors it has rank 0:

    >>> import numpy as np
    >>> from uio_teach.linalg import rank_decision
    >>> C = np.array([[1.0, 1.0, 1.0]]); E = np.array([[0.1], [0.2], [-0.3]])
    >>> scale = np.linalg.norm(C, 2) * np.linalg.norm(E, 2)
    >>> rank_decision(C @ E, scale=scale).rank
    0
    """
    M = np.atleast_2d(np.asarray(M))
    M = M.astype(complex if np.iscomplexobj(M) else float)
    if M.size == 0:
        return RankDecision(0, 0.0, np.inf, False)
    s = np.linalg.svd(M, compute_uv=False)
    ref = float(s[0]) if scale is None else float(scale)
    tol = _threshold(M.shape, ref, rtol)
    r = int(np.sum(s > tol))
    margin = float(s[r - 1] / tol) if r and tol > 0 else np.inf
    below = float(tol / s[r]) if r < s.size and s[r] > 0 else np.inf
    marginal = bool(margin < tols.RANK_MARGIN or below < tols.DROP_MARGIN)
    return RankDecision(r, tol, margin, marginal, below)


def rank(M: np.ndarray, *, scale: float | None = None) -> int:
    """Numerical rank of ``M`` (0 for an empty matrix).

    Parameters
    ----------
    M : array_like
        The matrix (real or complex).
    scale : float, optional
        Size of the data ``M`` was computed from (see ``rank_decision``);
        default ``||M||``.

    Examples
    --------
    >>> from uio_teach.linalg import rank
    >>> rank([[1, 2], [2, 4]])
    1
    """
    return rank_decision(M, scale=scale).rank


def pinv(M: np.ndarray) -> np.ndarray:
    """Moore-Penrose inverse ``M^+`` (MATLAB's ``pinv``), also for empty matrices.

    Parameters
    ----------
    M : array_like, shape (a, b)
        The matrix.

    Returns
    -------
    numpy.ndarray, shape (b, a)

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.linalg import pinv
    >>> np.round(pinv([[2.0], [1.0]]), 3)
    array([[0.4, 0.2]])
    """
    M = np.atleast_2d(np.asarray(M, dtype=float))
    if M.size == 0:
        return np.zeros((M.shape[1], M.shape[0]))
    return np.linalg.pinv(M)


def left_null(M: np.ndarray) -> np.ndarray:
    """Orthonormal rows ``N`` spanning the left null space of ``M`` (``N @ M = 0``).

    For a matrix with no columns this is the identity.

    Parameters
    ----------
    M : array_like, shape (p, nv)
        The matrix to annihilate from the left (e.g. a measurement-disturbance
        matrix ``D``).

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.linalg import left_null
    >>> D = np.array([[1.0], [0.2]])
    >>> N = left_null(D)
    >>> N.shape, bool(np.allclose(N @ D, 0))
    ((1, 2), True)
    """
    M = np.atleast_2d(np.asarray(M, dtype=float))
    p = M.shape[0]
    if M.shape[1] == 0:
        return np.eye(p)
    U, s, _ = np.linalg.svd(M, full_matrices=True)
    k = int(np.sum(s > _tol(M, s))) if s.size else 0
    return U[:, k:].T.copy()


def observability_matrix(A: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Stacked ``[C; C A; ...; C A^(n-1)]`` (MATLAB's ``obsv``).

    Parameters
    ----------
    A : array_like, shape (n, n)
    C : array_like, shape (p, n)

    Examples
    --------
    >>> from uio_teach.linalg import observability_matrix
    >>> observability_matrix([[0.0, 1.0], [0.0, 0.0]], [[1.0, 0.0]])
    array([[1., 0.],
           [0., 1.]])
    """
    A = np.asarray(A, float)
    C = np.atleast_2d(np.asarray(C, float))
    blocks = [C]
    for _ in range(A.shape[0] - 1):
        blocks.append(blocks[-1] @ A)
    return np.vstack(blocks)


class ObservabilitySplit(NamedTuple):
    """Orthogonal observability decomposition of a pair ``(A, C)``.

    With ``V = [Vo, Vu]`` orthogonal, ``V.T @ A @ V = [[Ao, 0], [*, Au]]`` and
    ``C @ V = [Co, 0]``: the modes ``eig(Au)`` are unobservable (no output
    injection can move them), the pair ``(Ao, Co)`` is observable.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.linalg import observability_decomposition
    >>> split = observability_decomposition(np.diag([-1.0, -2.0]), [[1.0, 0.0]])
    >>> split.Ao.shape, split.Au.shape
    ((1, 1), (1, 1))
    """

    Vo: np.ndarray
    Vu: np.ndarray
    Ao: np.ndarray
    Co: np.ndarray
    Au: np.ndarray
    margin: float = np.inf
    """Smallest ratio (kept singular value / threshold) over the staircase's rank decisions."""

    @property
    def marginal(self) -> bool:
        """True when a rank decision of the staircase sat within ``MARGIN`` of round-off."""
        return bool(self.margin < tols.RANK_MARGIN)

    @property
    def unobservable_modes(self) -> np.ndarray:
        """Eigenvalues of ``Au``, sorted."""
        return sort_poles(np.linalg.eigvals(self.Au)) if self.Au.size else np.zeros(0, complex)


def observability_decomposition(
    A: np.ndarray, C: np.ndarray, *, rtol: float | None = None
) -> ObservabilitySplit:
    """Split ``(A, C)`` into its observable and unobservable parts.

    The unobservable subspace is computed by a staircase of orthogonal
    compressions (no powers of ``A``), so it is reliable for stiff plants
    such as the missile autopilot.

    Parameters
    ----------
    A : array_like, shape (n, n)
    C : array_like, shape (p, n)
    rtol : float, optional
        A singular value of a staircase step counts as zero below
        ``rtol * max(shape) * eps`` times the data's size; default
        ``uio_teach.tolerances.STAIRCASE_RTOL``.

    Returns
    -------
    ObservabilitySplit

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.linalg import observability_decomposition
    >>> split = observability_decomposition(np.diag([1.0, 2.0]), [[1.0, 0.0]])
    >>> split.unobservable_modes
    array([2.+0.j])
    """
    A = np.asarray(A, float)
    C = np.atleast_2d(np.asarray(C, float))
    n = A.shape[0]
    rtol = tols.STAIRCASE_RTOL if rtol is None else float(rtol)
    # Staircase: W spans the current candidate unobservable subspace (start: ker C).
    margins = [np.inf]
    W = _null(C, margins=margins, rtol=rtol) if C.shape[0] else np.eye(n)
    ref = max(np.linalg.norm(A, 2), np.linalg.norm(C, 2), np.finfo(float).tiny)
    while W.shape[1]:
        # keep the part of W that A maps back into W: ker((I - W W^T) A W)
        R = A @ W - W @ (W.T @ A @ W)
        K = _null(R, ref=ref, margins=margins, rtol=rtol)
        if K.shape[1] == W.shape[1]:
            break
        W = W @ K
    Vu = W
    Vo = _complement(Vu, n)
    return ObservabilitySplit(
        Vo=Vo,
        Vu=Vu,
        Ao=Vo.T @ A @ Vo,
        Co=C @ Vo,
        Au=Vu.T @ A @ Vu,
        margin=float(min(margins)),
    )


def _null(
    M: np.ndarray, ref: float | None = None, margins: list | None = None, rtol: float | None = None
) -> np.ndarray:
    """Orthonormal basis of the right null space of ``M`` (columns).

    With ``margins`` (a list), the ratio of the smallest kept singular value to
    the threshold is appended to it.
    """
    M = np.atleast_2d(M)
    n = M.shape[1]
    if M.shape[0] == 0 or n == 0:
        return np.eye(n)
    _, s, Vt = np.linalg.svd(M, full_matrices=True)
    scale = ref if ref is not None else (s[0] if s.size else 0.0)
    rtol = tols.STAIRCASE_RTOL if rtol is None else rtol
    tol = max(M.shape) * rtol * np.finfo(float).eps * max(scale, np.finfo(float).tiny)
    k = int(np.sum(s > tol))
    if margins is not None and k and tol > 0:
        margins.append(float(s[k - 1] / tol))
    return Vt[k:].T.copy()


def _complement(V: np.ndarray, n: int) -> np.ndarray:
    """Orthonormal basis of the orthogonal complement of range(V) in R^n."""
    if V.shape[1] == 0:
        return np.eye(n)
    Q, _ = np.linalg.qr(V, mode="complete")
    return Q[:, V.shape[1] :].copy()


def sort_poles(z: np.ndarray) -> np.ndarray:
    """Values (poles, eigenvalues, zeros) in a reproducible order: by real part, then imaginary.

    Imaginary parts that are round-off of a real value are dropped, and a conjugate pair always
    comes out negative imaginary part first.

    Parameters
    ----------
    z : array_like of complex
        The values.

    Returns
    -------
    numpy.ndarray of complex

    Examples
    --------
    >>> from uio_teach.linalg import sort_poles
    >>> sort_poles([-1 + 2j, -3, -1 - 2j]).tolist()
    [(-3+0j), (-1-2j), (-1+2j)]
    """
    z = _real_cleaned(z)
    return z[_order(z)]


def _real_cleaned(z) -> np.ndarray:
    """``z`` with imaginary parts that are round-off of a real value (``REAL_RTOL``) set to 0."""
    z = np.asarray(z, complex)
    with np.errstate(invalid="ignore"):
        real = np.abs(z.imag) <= tols.REAL_RTOL * np.abs(z)
    return np.where(real, z.real + 0j, z)


def _order(z: np.ndarray) -> np.ndarray:
    """Indices sorting ``z`` by real part, then imaginary part.

    Sorted on rounded keys relative to the largest finite value, so that a conjugate pair whose
    real parts differ by round-off always comes out in the same order (negative imaginary part
    first), whatever the unit.
    """
    finite = np.abs(z[np.isfinite(z)])
    scale = float(np.max(finite)) if finite.size and np.max(finite) > 0 else 1.0
    with np.errstate(invalid="ignore"):
        key_re = np.round(z.real / scale, 9)
    return np.lexsort((z.imag, key_re))


_sort = sort_poles  # former private name


def is_stable(values: np.ndarray, discrete: bool, margin: float | None = None) -> np.ndarray:
    """Elementwise: inside the stability region (open left half-plane or unit disk).

    A value within ``margin`` of the boundary, relative to its own size, counts as *not*
    stable: ``Re z < -margin |z|`` (the same in any unit of time) or ``|z| < 1 - margin``.

    Parameters
    ----------
    values : array_like of complex
        Poles or zeros.
    discrete : bool
        Judge against the unit disk (True) or the left half-plane (False).
    margin : float, optional
        Relative distance from the boundary still counted as unstable; default
        ``uio_teach.tolerances.STABILITY_MARGIN``.

    Examples
    --------
    >>> from uio_teach.linalg import is_stable
    >>> is_stable([-1.0, 0.0, 0.5, -1e-12], discrete=False).tolist()
    [True, False, False, True]
    >>> is_stable([-1.0, 0.0, 0.5], discrete=True).tolist()
    [False, True, True]
    """
    z = np.asarray(values, complex)
    margin = tols.STABILITY_MARGIN if margin is None else float(margin)
    if discrete:
        return np.abs(z) < 1.0 - margin
    return z.real < -margin * np.abs(z)


def invariant_zeros(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray | None = None
) -> np.ndarray:
    """Invariant zeros of ``(A, B, C, D)``, square or not, with multiplicity.

    The zeros are the finite values ``s`` at which the Rosenbrock matrix
    ``[[s I - A, -B], [C, D]]`` loses rank below its normal rank. The system
    is first reduced with the orthogonal staircase of Emami-Naeini and Van
    Dooren (1982), applied to the system and to its dual, until the
    feedthrough is square and invertible; the zeros are then the generalized
    eigenvalues of the regular pencil that remains, as many as its size (the
    count comes from the pencil's structure, a fast zero is never dropped).
    :func:`checked_zeros` says in addition how far round-off can move each.

    Parameters
    ----------
    A : array_like, shape (n, n)
    B : array_like, shape (n, m)
    C : array_like, shape (p, n)
    D : array_like, shape (p, m), optional
        Zero when omitted.

    Returns
    -------
    numpy.ndarray of complex
        The zeros, sorted by real then imaginary part (with multiplicity).

    Examples
    --------
    A non-square system (one input, two outputs) has generically no zero:

    >>> import numpy as np
    >>> from uio_teach.linalg import invariant_zeros
    >>> invariant_zeros(np.diag([-1.0, -2.0]), [[1.0], [1.0]], np.eye(2))
    array([], dtype=complex128)

    and a square one has its transmission zero:

    >>> invariant_zeros(np.diag([-1.0, -2.0]), [[1.0], [1.0]], [[1.0, 1.0]])
    array([-1.5+0.j])
    """
    return checked_zeros(A, B, C, D).zeros


def _reduce(A, B, C, D, tol, drops):
    """One Emami-Naeini/Van Dooren reduction until ``D`` has full row rank.

    Every singular value taken as 0 is appended to ``drops`` (the largest per decision).
    """
    A, B, C, D = (np.array(X, dtype=float) for X in (A, B, C, D))
    while True:
        n, m, p = A.shape[0], B.shape[1], C.shape[0]
        if p == 0:
            return A, B, C, D
        # compress the rows of D: U D = [[0], [D+]]
        if m:
            U, s, _ = np.linalg.svd(D, full_matrices=True)
            rho = int(np.sum(s > tol))
            drops.extend(s[rho : rho + 1])
        else:
            U, rho = np.eye(p), 0
        U = U[:, ::-1].T  # rows: null part first, range part last
        Cu, Du = U @ C, U @ D
        C1, C2, Dplus = Cu[: p - rho], Cu[p - rho :], Du[p - rho :]
        if p - rho == 0:
            return A, B, C, D
        if n == 0:
            return A, B, C2, Dplus
        # compress the columns of C1: C1 V = [0, Cbar] with Cbar of full column rank mu
        _, s, Vt = np.linalg.svd(C1, full_matrices=True)
        mu = int(np.sum(s > tol))
        drops.extend(s[mu : mu + 1])
        if mu == 0:  # those outputs are identically zero: drop them
            C, D = C2, Dplus
            continue
        V = Vt[::-1].T  # last mu columns: the directions C1 sees
        At, Bt, Ct = V.T @ A @ V, V.T @ B, C2 @ V
        k = n - mu
        A11, A21 = At[:k, :k], At[k:, :k]
        B1, B2 = Bt[:k], Bt[k:]
        A = A11
        B = B1
        C = np.vstack([A21, Ct[:, :k]])
        D = np.vstack([B2, Dplus])


class ZeroSet(NamedTuple):
    """Invariant zeros with the evidence for each (:func:`checked_zeros`).

    Attributes
    ----------
    zeros : numpy.ndarray of complex
        The zeros, as many as the pencil's structure says (a repeated zero by its multiplicity),
        none dropped however fast.
    radius : numpy.ndarray of float
        For each zero, how far a perturbation of the data within ``backward_error`` can move
        it (measured along its way to the stability boundary; a defective cluster's true
        radius, ``eps**(1/k)``-like, not a first-order estimate); ``inf`` when it is beyond
        what double precision resolves.
    distance : numpy.ndarray of float
        For each zero, its distance to the stability boundary (the imaginary axis or the unit
        circle).
    unresolved : numpy.ndarray of bool
        For each zero: so fast that a perturbation within ``backward_error`` can send it
        through infinity (it may be on either side, or not exist).
    backward_error : float
        The relative size (in balanced units) of the perturbation of the data the computed
        zeros are exact for: ``ZERO_RTOL (n + p) eps``.
    lost : int
        Zeros the structure puts at infinity by a rank decision within ``DROP_MARGIN`` of its
        threshold: a plant within round-off of the data has them, finite and fast, on either
        side of the boundary.
    crossing : bool
        A plant within ``backward_error`` of the data has a zero on the stability boundary.
    discrete : bool
        Which boundary: the unit circle (True) or the imaginary axis.
    scale : float
        The system's own rate, the spectral radius of ``A`` in continuous time (1 in discrete
        time): the zeros' sizes are judged against it.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.linalg import checked_zeros
    >>> zs = checked_zeros(np.diag([-1.0, -2.0]), [[1.0], [1.0]], [[1.0, 1.0]])
    >>> zs.zeros, zs.decided
    (array([-1.5+0.j]), True)
    """

    zeros: np.ndarray
    radius: np.ndarray
    distance: np.ndarray
    unresolved: np.ndarray
    backward_error: float
    lost: int = 0
    crossing: bool = False
    discrete: bool = False
    scale: float = 1.0
    fragile: np.ndarray | None = None
    """For each zero, whether a plant within ``backward_error`` of the data lacks it (a zero of
    a plant with more outputs than unknown inputs is not generic: it holds by the structure of
    the data, and a perturbation of that size removes it); ``None``: no zero is fragile."""
    validated: bool = False
    """True when ``radius`` is a proven bound (``uio_teach.enclosures``), not an estimate."""

    @property
    def undecided(self) -> np.ndarray:
        """For each zero, whether round-off of the data can move it across the boundary, or
        remove it while it may lie outside the stability region."""
        und = self.unresolved | (self.radius >= self.distance)
        if self.fragile is not None:
            und = und | (self.fragile & ~self.stable)
        return und

    @property
    def decided(self) -> bool:
        """True when no perturbation within the backward error changes which side any zero is on."""
        return not (self.lost or self.crossing or np.any(self.undecided))

    @property
    def stable(self) -> np.ndarray:
        """For each zero, whether it lies inside the stability region (its computed value)."""
        return is_stable(self.zeros, self.discrete, margin=0.0)


def _normalized_system(A, B, C, D, discrete):
    """Balance ``A`` (diagonal similarity), divide the time unit out, scale inputs and outputs.

    Returns the scaled ``(A, B, C, D)`` and the factor ``t`` the zeros are to be multiplied by:
    ``||A|| = 1`` in continuous time (the zeros of a plant whose time is measured in other
    units are the same numbers in units of its own rate), ``||B|| = ||C|| = 1``.
    """
    n = A.shape[0]
    if n:
        _, (bal, _) = sla.matrix_balance(A, permute=False, separate=True)
        A = A / bal[:, None] * bal[None, :]
        B = B / bal[:, None]
        C = C * bal[None, :]
    t = float(np.linalg.norm(A, 2)) if n and not discrete else 0.0
    t = t if t > 0 and np.isfinite(t) else 1.0
    A, B = A / t, B / t
    nb = float(np.linalg.norm(B, 2)) if B.size else 0.0
    nc = float(np.linalg.norm(C, 2)) if C.size else 0.0
    beta = 1.0 / nb if nb > 0 else 1.0
    gamma = 1.0 / nc if nc > 0 else 1.0
    return A, B * beta, C * gamma, D * (beta * gamma / t), t


def _pseudo(Af: np.ndarray, Ef: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Smallest perturbation ``||(dA, dE)||`` that makes each ``w`` an eigenvalue of the pencil.

    ``sigma_min(Af - w Ef) / sqrt(1 + |w|^2)`` (for ``Af``, ``Ef`` of norm about 1).
    """
    w = np.atleast_1d(np.asarray(w, complex))
    M = Af[None, :, :] - w[:, None, None] * Ef[None, :, :]
    with np.errstate(all="ignore"):
        s = np.linalg.svd(M, compute_uv=False)[:, -1]
    return s / np.sqrt(1.0 + np.abs(w) ** 2)


def _nearest_boundary(z: np.ndarray, discrete: bool) -> np.ndarray:
    if discrete:
        ang = np.where(z == 0, 0.0, np.angle(z))
        return np.exp(1j * ang)
    return 1j * z.imag


def _radius_toward(fun, z, b, eps_pert, discrete) -> float:
    """How far a perturbation of the pencil of size ``eps_pert`` moves ``z``, towards ``b``.

    The extent, along the ray from ``z`` through the nearest boundary point ``b`` (and beyond
    it), of the part of the pseudospectrum ``{w: fun(w) <= eps_pert}`` that holds ``z``:
    ``kappa eps_pert`` for a simple zero, about ``eps_pert**(1/k)`` for a defective cluster of
    ``k``, and never confused with another zero's part farther along the way.
    """
    d = abs(b - z)
    if d > 0:
        u = (b - z) / d
    elif discrete:
        u = z / abs(z) if z != 0 else 1.0
    else:
        u = 1.0
    lengths = np.geomspace(1e-30, 1e6, 73) * max(abs(z), 1.0)
    out = fun(z + lengths * u) > eps_pert
    if not np.any(out):
        return np.inf
    k = int(np.argmax(out))
    hi = lengths[k]
    lo = lengths[k - 1] if k else 0.0
    for _ in range(30):
        mid = np.sqrt(lo * hi) if lo > 0 else hi / 2
        if fun(np.array([z + mid * u]))[0] <= eps_pert:
            lo = mid
        else:
            hi = mid
    return float(hi)


def _boundary_samples(z: np.ndarray, discrete: bool) -> np.ndarray:
    """Points of the stability boundary (one half: the data are real) near the zeros and beyond."""
    if discrete:
        ang = np.concatenate([np.linspace(0.0, np.pi, 181), np.abs(np.angle(z))])
        return np.exp(1j * ang)
    mags = np.abs(z[np.isfinite(z)])
    near = np.concatenate([[0.0], np.abs(z.imag), np.outer(mags, [0.5, 1.0, 2.0]).ravel()])
    return 1j * np.concatenate([np.geomspace(1e-4, 1e4, 81), near])


def checked_zeros(
    A: np.ndarray,
    B: np.ndarray,
    C: np.ndarray,
    D: np.ndarray | None = None,
    *,
    discrete: bool = False,
) -> ZeroSet:
    """Invariant zeros of ``(A, B, C, D)``, each with how far round-off of the data can move it.

    The system is scaled first (``A`` balanced, its norm divided out in continuous time so
    that the units of time do not matter, ``||B|| = ||C|| = 1``, dependent input columns
    dropped), then reduced by the orthogonal staircase of :func:`invariant_zeros` with rank
    decisions at the backward error ``delta = ZERO_RTOL (n + p) eps``: the zeros are the
    eigenvalues of the regular pencil ``(Af, Ef)`` that remains, as many as its size, a
    repeated zero by its multiplicity. Round-off is then measured in the pencil's
    pseudospectrum: a value ``w`` is a zero of a plant within ``delta`` when
    ``sigma_min(Af - w Ef) <= delta sqrt(1 + |w|^2)``. Each zero's radius is how far that set
    reaches from it towards the stability boundary (a defective cluster's true radius, not a
    first-order estimate), and the set is sampled along the boundary: when it touches it, a
    plant within round-off has a zero on the boundary and the verdict cannot be decided.

    Parameters
    ----------
    A, B, C, D : array_like
        The system (``D`` zero when omitted).
    discrete : bool
        The stability boundary is the unit circle (True) or the imaginary axis.

    Returns
    -------
    ZeroSet

    Examples
    --------
    A zero at +1000 of a plant whose poles are near -1 (``C B`` small next to ``B``):

    >>> import numpy as np
    >>> from uio_teach.linalg import checked_zeros
    >>> A = np.array([[-1.0, 0.0], [1.0, -2.0]]); B = np.array([[1.0], [-1.002]])
    >>> zs = checked_zeros(A, B, [[1.0, 1.0]])
    >>> zs.zeros.real.round(6), zs.decided
    (array([999.]), True)
    """
    A = np.atleast_2d(np.asarray(A, float))
    n = A.shape[0]
    B = np.asarray(B, float).reshape(n, -1)
    C = np.asarray(C, float).reshape(-1, n)
    p = C.shape[0]
    D = np.zeros((p, B.shape[1])) if D is None else np.asarray(D, float).reshape(p, B.shape[1])
    eps = tols.EPS
    delta = tols.ZERO_RTOL * (n + p) * eps
    empty = ZeroSet(np.zeros(0, complex), np.zeros(0), np.zeros(0), np.zeros(0, bool), delta)
    empty = empty._replace(discrete=bool(discrete))
    if n == 0:
        return empty
    with np.errstate(all="ignore"):
        A, B, C, D, t = _normalized_system(A, B, C, D, discrete)
    if not all(np.all(np.isfinite(X)) for X in (A, B, C, D)):
        return empty._replace(lost=n)
    # independent input columns only (a repeated unknown input adds no zero)
    BD = np.vstack([B, D])
    if BD.size:
        _, s, Vt = np.linalg.svd(BD, full_matrices=False)
        r = int(np.sum(s > delta * s[0])) if s.size and s[0] > 0 else 0
        B, D = (BD @ Vt[:r].T)[:n], (BD @ Vt[:r].T)[n:]
    scale = float(np.linalg.norm(np.block([[A, B], [C, D]]), 2))
    thr = delta * scale
    drops: list[float] = []
    A1, B1, C1, D1 = _reduce(A, B, C, D, thr, drops)
    A2, B2, C2, D2 = _reduce(A1.T, C1.T, B1.T, D1.T, thr, drops)
    A2, B2, C2, D2 = A2.T, C2.T, B2.T, D2.T
    nr = A2.shape[0]
    # a rank decision close to its threshold: a zero may sit at infinity or be finite and fast
    lost = int(sum(1 for s in drops if s > thr / tols.DROP_MARGIN))
    z, radius, unresolved = np.zeros(0, complex), np.zeros(0), np.zeros(0, bool)
    crossing = False
    pencil = None
    if nr and D2.shape[0] == D2.shape[1]:  # else: no finite zeros, or normal-rank deficient
        pencil = _regular_pencil(A2, B2, C2, D2)
        z, radius, unresolved, crossing = _pencil_zeros(*pencil, delta, discrete)
    if B.shape[1] < p:
        # more outputs than inputs: a zero is not generic, and one that the structure of the
        # data has only to round-off is lost by the staircase's exact rank decisions; a plant
        # within the backward error has it, so it counts (and the designs find it fixed)
        more, r_more = _round_off_zeros(A, B, C, D, scale, delta, discrete, pencil)
        z = np.concatenate([z, more])
        radius = np.concatenate([radius, r_more])
        unresolved = np.concatenate([unresolved, np.zeros(more.size, bool)])
    b = _nearest_boundary(np.where(np.isfinite(z), z, 0.0), discrete)
    distance = np.where(np.isfinite(z), np.abs(z - b), np.inf)
    order = _order(z)
    return ZeroSet(
        zeros=(z * t)[order],
        radius=(radius * t)[order],
        distance=(distance * t)[order],
        unresolved=unresolved[order],
        backward_error=delta,
        lost=lost,
        crossing=crossing,
        discrete=bool(discrete),
        scale=1.0 if discrete else t * float(np.max(np.abs(np.linalg.eigvals(A)))),
    )


def _regular_pencil(A2, B2, C2, D2) -> tuple[np.ndarray, np.ndarray]:
    """The regular pencil ``(Af, Ef)`` of a reduced system with ``D`` square and invertible."""
    nr, mr = A2.shape[0], B2.shape[1]
    if mr == 0:
        Af, Ef = A2, np.eye(nr)
    else:
        # compress the columns of [C D] onto D: [C D] W = [0 Df]
        CD = np.hstack([C2, D2])
        Q, _ = np.linalg.qr(CD.T[:, ::-1], mode="complete")
        W = Q[:, ::-1]  # last mr columns span the row space of [C D]
        Af = (np.hstack([A2, B2]) @ W)[:, :nr]
        Ef = (np.hstack([np.eye(nr), np.zeros((nr, mr))]) @ W)[:, :nr]
    size = float(np.hypot(np.linalg.norm(Af, 2), np.linalg.norm(Ef, 2)))
    return Af / size, Ef / size


def _pencil_zeros(Af, Ef, delta, discrete):
    """Eigenvalues of the pencil, their radii, whether each is resolved, and boundary crossing."""
    nr = Af.shape[0]
    ab, vl, vr = sla.eig(Af, Ef, left=True, right=True, homogeneous_eigvals=True)
    alpha, beta = ab
    with np.errstate(all="ignore"):
        z = np.where(beta != 0, alpha / np.where(beta != 0, beta, 1.0), np.inf)
        # first-order chordal radius of each eigenvalue (Stewart and Sun): kappa delta
        num = np.linalg.norm(vl, axis=0) * np.linalg.norm(vr, axis=0)
        den = np.hypot(
            np.abs(np.sum(vl.conj() * (Af @ vr), axis=0)),
            np.abs(np.sum(vl.conj() * (Ef @ vr), axis=0)),
        )
        chord = np.where(den > 0, num / den, np.inf) * delta
        to_inf = np.abs(beta) / np.hypot(np.abs(alpha), np.abs(beta))
    unresolved = ~np.isfinite(z) | (to_inf <= chord)
    # real data: a zero with an imaginary part of round-off is real
    z = np.where(np.isfinite(z), _real_cleaned(z), z)
    b = _nearest_boundary(np.where(np.isfinite(z), z, 0.0), discrete)
    radius = np.full(nr, np.inf)

    def fun(w):
        return _pseudo(Af, Ef, w)

    for i in np.flatnonzero(~unresolved):
        radius[i] = _radius_toward(fun, z[i], b[i], delta, discrete)
    samples = _boundary_samples(z[~unresolved], discrete)
    crossing = bool(np.min(fun(samples)) <= delta) if samples.size else False
    return z, radius, unresolved, crossing


def _rosenbrock_residual(A, B, C, D, scale, w) -> np.ndarray:
    """Smallest singular value of ``[[w I - A, -B], [C, D]]`` relative to ``scale``, per ``w``.

    For ``|w|`` beyond 1 (the normalized system's size) the state columns are divided by ``|w|``
    (the pencil in homogeneous form): without it every Rosenbrock matrix at a large ``w`` is
    nearly singular, a zero or not.
    """
    n, m = B.shape
    w = np.atleast_1d(np.asarray(w, complex))
    a = 1.0 / np.maximum(np.abs(w), 1.0)
    top = (w[:, None, None] * np.eye(n) - A) * a[:, None, None]
    left = np.concatenate([top, np.broadcast_to(C, (w.size, *C.shape)) * a[:, None, None]], 1)
    right = np.broadcast_to(np.vstack([-B, D]), (w.size, n + C.shape[0], m))
    R = np.concatenate([left, right], 2)
    with np.errstate(all="ignore"):
        s = np.linalg.svd(R, compute_uv=False)[:, n + m - 1]
    return np.where(np.isfinite(s), s / scale, 0.0)


def _round_off_zeros(A, B, C, D, scale, delta, discrete, pencil):
    """Zeros of a tall system that hold to round-off only, with their radii.

    Candidates: the zeros of a random square-down ``(A, B, W C, W D)`` (every zero of the
    system is one of each square-down's); kept when the full Rosenbrock matrix is singular
    there within the backward error, in a neighbourhood that does not reach infinity, and the
    staircase's pencil does not already hold them.
    """
    n, m = B.shape
    p = C.shape[0]
    rng = np.random.default_rng(0)
    W = np.linalg.qr(rng.standard_normal((p, m)))[0].T
    M = np.block([[A, B], [W @ C, W @ D]])
    N = np.zeros_like(M)
    N[:n, :n] = np.eye(n)
    with np.errstate(all="ignore"):
        cand = sla.eigvals(M, N)
    cand = _real_cleaned(cand[np.isfinite(cand)])
    if not cand.size:
        return np.zeros(0, complex), np.zeros(0)

    def fun(w):
        return _rosenbrock_residual(A, B, C, D, scale, w)

    keep = fun(cand) <= delta
    if pencil is not None and np.any(keep):
        keep &= _pseudo(*pencil, cand) > delta
    found, radius = [], []
    for z in cand[keep]:
        # a value whose singular neighbourhood reaches infinity is the system's infinite zeros
        # seen through round-off (a small C B), not a finite zero
        if np.isinf(_radius_toward(fun, z, 2 * z if z != 0 else 1.0, delta, discrete)):
            continue
        found.append(z)
        radius.append(
            _radius_toward(fun, z, _nearest_boundary(np.array([z]), discrete)[0], delta, discrete)
        )
    return np.array(found, complex), np.array(radius, float)


_BLAS: Any = None


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Limit BLAS to one thread while the block (or decorated function) runs.

    The designs' linear algebra works on matrices of at most a few hundred rows, in loops:
    OpenBLAS's worker threads then cost more than they give, many times more when another
    process keeps the other core busy. Uses threadpoolctl (built once; a no-op without it).

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.linalg import one_blas_thread
    >>> with one_blas_thread():
    ...     float(np.linalg.norm(np.eye(3)))
    1.7320508075688772
    """
    global _BLAS
    if _BLAS is None:
        try:
            from threadpoolctl import ThreadpoolController  # deferred: only when a design runs
        except ImportError:  # pragma: no cover - threadpoolctl is optional
            _BLAS = False
        else:
            _BLAS = ThreadpoolController()
    if _BLAS is False:  # pragma: no cover
        yield
        return
    with _BLAS.limit(limits=1, user_api="blas"):
        yield
