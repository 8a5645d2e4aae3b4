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
  (``2.2e-16``); data known to fewer digits can pass ``rtol`` (e.g. ``1e-4``
  for a matrix printed with four decimals) to ``rank_decision``.
* **Marginal verdicts say so.** A kept singular value less than
  ``MARGIN`` times the threshold means that the verdict hangs on round-off:
  ``rank_decision`` returns the ratio ``s / threshold`` as ``margin`` and
  ``marginal=True``; the existence report then states the verdict *and* the
  margin instead of guessing.
* **Invariant zeros** are computed on a scaled copy of the system
  (``||A|| = ||B|| = ||C|| = 1`` after a diagonal balancing of ``A``), so that a
  large eigenvalue of ``A`` does not make the other blocks look like zero.
* **Computed designs are verified** (``uio_teach.verify``): the obtained
  poles against the requested ones with a tolerance that grows with the
  eigenvalue condition numbers, and the decoupling identities ``T E = 0``,
  ``H C E = E``, ``L D = 0`` against ``1e-8`` relative to the factors.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg as sla

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
    "ZERO_RTOL",
    "ZERO_DOUBT",
    "is_stable",
    "ObservabilitySplit",
    "sort_poles",
    "one_blas_thread",
]


MARGIN = 1e4
"""A kept singular value below ``MARGIN`` times the rank threshold makes the verdict marginal."""

DROP_MARGIN = 10.0
"""A dropped singular value above ``1 / DROP_MARGIN`` of the rank threshold makes a rank-deficient
verdict marginal (round-off sits well below the threshold when ``rtol`` covers the data's
precision, e.g. ``100 n eps`` for a product over ``n`` terms)."""


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
    return RankDecision(r, tol, margin, bool(margin < MARGIN or below < DROP_MARGIN), below)


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
        return bool(self.margin < MARGIN)

    @property
    def unobservable_modes(self) -> np.ndarray:
        """Eigenvalues of ``Au``, sorted."""
        return sort_poles(np.linalg.eigvals(self.Au)) if self.Au.size else np.zeros(0, complex)


def observability_decomposition(
    A: np.ndarray, C: np.ndarray, *, rtol: float = 1e3
) -> ObservabilitySplit:
    """Split ``(A, C)`` into its observable and unobservable parts.

    The unobservable subspace is computed by a staircase of orthogonal
    compressions (no powers of ``A``), so it is reliable for stiff plants
    such as the missile autopilot.

    Parameters
    ----------
    A : array_like, shape (n, n)
    C : array_like, shape (p, n)
    rtol : float
        A singular value of a staircase step counts as zero below
        ``rtol * max(shape) * eps`` times the data's size.

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
    M: np.ndarray, ref: float | None = None, margins: list | None = None, rtol: float = 1e3
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
    z = np.asarray(z, complex)
    # clean tiny imaginary parts of real values
    z = np.where(np.abs(z.imag) <= 1e-10 * np.maximum(1.0, np.abs(z)), z.real + 0j, z)
    # sort on rounded keys so that a conjugate pair whose real parts differ by round-off
    # always comes out in the same order (negative imaginary part first)
    scale = max(1.0, float(np.max(np.abs(z)))) if z.size else 1.0
    key_re = np.round(z.real / scale, 9)
    return z[np.lexsort((z.imag, key_re))]


_sort = sort_poles  # former private name


def is_stable(values: np.ndarray, discrete: bool, margin: float = 1e-9) -> np.ndarray:
    """Elementwise: inside the stability region (open left half-plane or unit disk).

    A value within ``margin`` (relative) of the boundary counts as *not* stable.

    Parameters
    ----------
    values : array_like of complex
        Poles or zeros.
    discrete : bool
        Judge against the unit disk (True) or the left half-plane (False).
    margin : float
        Relative distance from the boundary still counted as unstable.

    Examples
    --------
    >>> from uio_teach.linalg import is_stable
    >>> is_stable([-1.0, 0.0, 0.5], discrete=False).tolist()
    [True, False, False]
    >>> is_stable([-1.0, 0.0, 0.5], discrete=True).tolist()
    [False, True, True]
    """
    z = np.asarray(values, complex)
    if discrete:
        return np.abs(z) < 1.0 - margin
    return z.real < -margin * np.maximum(1.0, np.abs(z))


def invariant_zeros(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray | None = None
) -> np.ndarray:
    """Invariant zeros of ``(A, B, C, D)``, square or not.

    The zeros are the finite values ``s`` at which the Rosenbrock matrix
    ``[[s I - A, -B], [C, D]]`` loses rank below its normal rank. The system
    is first reduced with the orthogonal staircase of Emami-Naeini and Van
    Dooren (1982), applied to the system and to its dual, until the
    feedthrough is square and invertible; the zeros are then the finite
    generalized eigenvalues of a regular pencil.

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
    A = np.atleast_2d(np.asarray(A, float))
    n = A.shape[0]
    B = np.asarray(B, float).reshape(n, -1)
    C = np.asarray(C, float).reshape(-1, n)
    D = np.zeros((C.shape[0], B.shape[1])) if D is None else np.asarray(D, float)
    D = D.reshape(C.shape[0], B.shape[1])
    # Scale first (see the module's tolerance policy): a diagonal similarity balances A,
    # then input and output scalings bring ||B|| and ||C|| to ||A||. The zeros do not change,
    # and no block is judged against another block's size.
    A, B, C, D = _scaled_system(A, B, C, D)
    scale = max(1.0, np.linalg.norm(np.block([[A, B], [C, D]]), 2))
    A1, B1, C1, D1 = _reduce(A, B, C, D, scale)
    A2, B2, C2, D2 = _reduce(A1.T, C1.T, B1.T, D1.T, scale)
    A2, B2, C2, D2 = A2.T, C2.T, B2.T, D2.T
    nr, mr = A2.shape[0], B2.shape[1]
    if nr == 0:
        return np.zeros(0, complex)
    if D2.shape[0] != D2.shape[1]:  # normal-rank deficient: fall back on what remains
        return np.zeros(0, complex)
    if mr == 0:
        return sort_poles(np.linalg.eigvals(A2))
    # compress the columns of [C D] onto D: [C D] W = [0 Df]
    CD = np.hstack([C2, D2])
    Q, _ = np.linalg.qr(CD.T[:, ::-1], mode="complete")
    W = Q[:, ::-1]  # last mr columns span the row space of [C D]
    AB = np.hstack([A2, B2]) @ W
    IB = np.hstack([np.eye(nr), np.zeros((nr, mr))]) @ W
    Af, Ef = AB[:, :nr], IB[:, :nr]
    w = sla.eigvals(Af, Ef)
    w = w[np.isfinite(w) & (np.abs(w) < 1e12 * scale)]
    return sort_poles(w)


def _reduce(A, B, C, D, scale):
    """One Emami-Naeini/Van Dooren reduction until ``D`` has full row rank."""
    A, B, C, D = (np.array(X, dtype=float) for X in (A, B, C, D))
    tol = max(A.shape[0] + C.shape[0], 1) * 1e3 * np.finfo(float).eps * scale
    while True:
        n, m, p = A.shape[0], B.shape[1], C.shape[0]
        if p == 0:
            return A, B, C, D
        # compress the rows of D: U D = [[0], [D+]]
        if m:
            U, s, _ = np.linalg.svd(D, full_matrices=True)
            rho = int(np.sum(s > tol))
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


ZERO_RTOL = 10.0
"""A candidate ``z`` is an invariant zero when the smallest singular value of the scaled
Rosenbrock matrix at ``z`` is at most ``ZERO_RTOL * (n + p) * eps`` of its size (the backward
error of a double-precision computation); between that and ``ZERO_DOUBT`` times more it is a zero
of a plant within round-off of the data, but not certainly of this one."""

ZERO_DOUBT = 1e3
"""How far above the zero threshold a candidate still counts as doubtful (see ``ZERO_RTOL``)."""


class ZeroSet(NamedTuple):
    """Invariant zeros with the evidence for each (:func:`checked_zeros`).

    Attributes
    ----------
    zeros : numpy.ndarray of complex
        The zeros: values at which the scaled Rosenbrock matrix is singular to round-off, found by
        a random square-down of the outputs and confirmed on the full (non-square) matrix and by
        the orthogonal staircase or a second square-down.
    doubtful : numpy.ndarray of complex
        Values at which the Rosenbrock matrix is singular to within ``ZERO_DOUBT`` times the
        round-off threshold, or that one method finds and the other does not: zeros of plants
        within round-off of the data, on which no verdict should rest.
    residuals : numpy.ndarray of float
        For each doubtful value, the smallest singular value of the scaled Rosenbrock matrix
        divided by its threshold.
    threshold : float
        The relative singular value below which a value is a zero.
    radius : numpy.ndarray of float
        For each zero, how far round-off of the data (``threshold`` relative to the scaled
        system) can move it, from its condition number ``||u|| ||v|| / |u_x^H v_x|`` (``u``,
        ``v`` the left and right singular vectors of the Rosenbrock matrix at the zero).

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.linalg import checked_zeros
    >>> zs = checked_zeros(np.diag([-1.0, -2.0]), [[1.0], [1.0]], [[1.0, 1.0]])
    >>> zs.zeros, zs.doubtful.size
    (array([-1.5+0.j]), 0)
    """

    zeros: np.ndarray
    doubtful: np.ndarray
    residuals: np.ndarray
    threshold: float
    radius: np.ndarray = np.zeros(0)


def _scaled_system(A, B, C, D):
    """Balance ``A`` (diagonal similarity) and scale ``B``, ``C`` to its size; zeros unchanged."""
    n = A.shape[0]
    if n:
        _, (bal, _) = sla.matrix_balance(A, permute=False, separate=True)
        A = A / bal[:, None] * bal[None, :]
        B = B / bal[:, None]
        C = C * bal[None, :]
    alpha = max(float(np.linalg.norm(A, 2)), 1.0) if n else 1.0
    nb = float(np.linalg.norm(B, 2)) if B.size else 0.0
    nc = float(np.linalg.norm(C, 2)) if C.size else 0.0
    beta = alpha / nb if nb > 0 else 1.0
    gamma = alpha / nc if nc > 0 else 1.0
    return A, B * beta, C * gamma, D * (beta * gamma)


def _rosenbrock_residual(A, B, C, D, size, z) -> float:
    """Smallest singular value of ``[[z I - A, -B], [C, D]]`` relative to its size.

    For ``|z|`` beyond the system's size the state columns are divided by ``|z| / size`` (the
    pencil in homogeneous form): without it every Rosenbrock matrix at a large ``z`` is nearly
    singular (its smallest singular value falls like ``1 / |z|^2``), a zero or not.
    """
    n = A.shape[0]
    alpha = size / max(abs(z), size)
    R = np.block(
        [[(z * np.eye(n) - A) * alpha, -B], [(C * alpha).astype(complex), D.astype(complex)]]
    )
    if not np.all(np.isfinite(R)):
        return 0.0
    s = np.linalg.svd(R, compute_uv=False)
    return float(s[-1]) / size


def _zero_condition(A, B, C, D, W, z) -> float:
    """Condition number ``||u|| ||v|| / |u_x^H v_x|`` of ``z`` as a zero of the square-down ``W``.

    ``u``, ``v``: left and right singular vectors of the smallest singular value of the square
    Rosenbrock matrix; a perturbation ``delta`` of the pencil moves ``z`` by about
    ``kappa * ||delta||``.
    """
    n = A.shape[0]
    # in homogeneous form, as in _rosenbrock_residual: the state columns scaled by alpha
    size = max(1.0, float(np.linalg.norm(np.block([[A, B], [W @ C, W @ D]]), 2)))
    alpha = size / max(abs(z), size)
    R = np.block(
        [
            [(z * np.eye(n) - A) * alpha, -B],
            [(W @ C * alpha).astype(complex), (W @ D).astype(complex)],
        ]
    )
    if not np.all(np.isfinite(R)):
        return np.inf
    U, _, Vh = np.linalg.svd(R)
    k = abs(np.vdot(U[:n, -1], Vh[-1, :n].conj()))
    return 1.0 / k if k > 0 else np.inf


def _square_down_zeros(A, B, C, D, W, limit) -> np.ndarray:
    """Finite generalized eigenvalues of the Rosenbrock pencil of ``(A, B, W C, W D)``."""
    n, m = B.shape
    M = np.block([[A, B], [W @ C, W @ D]])
    N = np.zeros_like(M)
    N[:n, :n] = np.eye(n)
    with np.errstate(all="ignore"):
        w = sla.eigvals(M, N)
    return w[np.isfinite(w) & (np.abs(w) < limit)]


def _match(values: np.ndarray, pool: np.ndarray, rtol: float, floor: float) -> np.ndarray:
    """For each value, whether a distinct element of ``pool`` lies within ``rtol`` of it."""
    pool = list(pool)
    found = np.zeros(len(values), bool)
    for i, z in enumerate(values):
        if not pool:
            break
        d = [abs(z - x) / max(abs(z), floor) for x in pool]
        j = int(np.argmin(d))
        if d[j] <= rtol:
            found[i] = True
            pool.pop(j)
    return found


def checked_zeros(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray | None = None
) -> ZeroSet:
    """Invariant zeros of ``(A, B, C, D)`` with every decision checked, fast zeros included.

    Two independent methods on a scaled system (``A`` balanced, ``||B|| = ||C|| = ||A||``, input
    columns compressed to full rank): the orthogonal staircase of :func:`invariant_zeros`, and
    the generalized eigenvalues of the square Rosenbrock pencils of random square-downs
    ``(A, B, W C, W D)`` (every zero of the system is a zero of each square-down). Each candidate
    ``z`` is then judged on the full Rosenbrock matrix: it is a zero when that matrix is
    singular at ``z`` to round-off (its smallest singular value at most ``ZERO_RTOL (n + p) eps``
    of its size) and a second square-down finds it too; a candidate within ``ZERO_DOUBT`` of that
    threshold, or found by one method and refuted by the other, is listed as doubtful.

    A zero a million times faster than the poles (a small ``C B`` next to ``B``) is found: the
    pencil of a square-down is regular and well scaled, and the Rosenbrock matrix's singular
    value is judged relative to ``|z|``.

    Parameters
    ----------
    A, B, C, D : array_like
        The system (``D`` zero when omitted).

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
    >>> zs.zeros.real.round(6), zs.doubtful.size
    (array([999.]), 0)
    """
    A = np.atleast_2d(np.asarray(A, float))
    n = A.shape[0]
    B = np.asarray(B, float).reshape(n, -1)
    C = np.asarray(C, float).reshape(-1, n)
    p = C.shape[0]
    D = np.zeros((p, B.shape[1])) if D is None else np.asarray(D, float).reshape(p, B.shape[1])
    eps = np.finfo(float).eps
    empty = np.zeros(0, complex)
    staircase = invariant_zeros(A, B, C, D)
    A, B, C, D = _scaled_system(A, B, C, D)
    # independent input columns only (a repeated unknown input adds no zero)
    BD = np.vstack([B, D])
    if BD.size:
        _, s, Vt = np.linalg.svd(BD, full_matrices=False)
        r = int(np.sum(s > max(BD.shape) * eps * 100 * s[0])) if s.size and s[0] > 0 else 0
        B, D = (BD @ Vt[:r].T)[:n], (BD @ Vt[:r].T)[n:]
    m = B.shape[1]
    size = max(1.0, float(np.linalg.norm(np.block([[A, B], [C, D]]), 2)))
    tau = ZERO_RTOL * (n + p) * eps
    if n == 0 or m == 0 or p < m:
        return ZeroSet(staircase, empty, np.zeros(0), tau)
    rng = np.random.default_rng(0)
    # normal rank: a Rosenbrock matrix singular at random points has no isolated zeros
    probe = size * (rng.standard_normal(2) + 1j * rng.standard_normal(2))
    if min(_rosenbrock_residual(A, B, C, D, size, s) for s in probe) <= tau * ZERO_DOUBT:
        return ZeroSet(staircase, empty, np.zeros(0), tau)
    # beyond |z| ~ size / tau the homogeneous pencil's state columns are round-off: no test tells
    # a zero from an infinite one
    resolve = size / (tau * ZERO_DOUBT)
    limit = size / eps

    def square_down() -> tuple[np.ndarray, np.ndarray]:
        W = np.linalg.qr(rng.standard_normal((p, m)))[0].T if p > m else np.eye(p)
        return _square_down_zeros(A, B, C, D, W, limit), W

    (first, W1), second = square_down(), (square_down()[0] if p > m else None)
    # the staircase's zeros join the candidates when the square-down did not find them
    extra = staircase[~_match(staircase, first, 1e-6, size * 1e-8)]
    cand = np.concatenate([first, extra])
    rho = np.array([_rosenbrock_residual(A, B, C, D, size, z) for z in cand]) / tau
    # a zero of the system is a zero of every square-down
    again = (
        _match(cand, second, 1e-6, size * 1e-8) if second is not None else np.ones(len(cand), bool)
    )
    fast = np.abs(cand) > resolve
    confirmed = (rho <= 1.0) & again & ~fast
    doubtful = ~confirmed & (((rho <= ZERO_DOUBT) & ~fast) | (fast & again & (p > m)))
    zc = cand[confirmed]
    kappa = np.array([_zero_condition(A, B, C, D, W1, z) for z in zc])
    rc = 10 * tau * np.maximum(np.abs(zc), size) * kappa
    zeros = sort_poles(zc)
    near = [int(np.argmin(np.abs(zc - z))) for z in zeros]
    return ZeroSet(zeros, sort_poles(cand[doubtful]), rho[doubtful], tau, rc[near])


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
