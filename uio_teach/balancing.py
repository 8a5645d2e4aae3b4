"""Units do not matter: a plant balanced by diagonal scalings before any decision.

A plant written in other units (states in mm instead of km, outputs in
mrad instead of degrees) is the same plant: the same invariant zeros, the
same rank conditions, the same fixed modes. Floating-point decisions made on
the raw matrices, however, compare numbers of very different sizes and can
change with the units. Every decision of the course is therefore made on a
*balanced* copy of the plant, as SLICOT's zero routines balance the system
matrix before the staircase:

* a diagonal similarity ``x = T x_s`` (``T = diag(t)``, powers of 2, so exact)
  that balances the rows and columns of the system matrix
  ``[[A, E, 0], [C, 0, D]]`` state by state (Osborne's iteration, extended to
  the input columns and output rows);
* output scalings ``y_s = W_y y`` and unknown-input scalings ``d = W_d d_s``,
  ``v = W_v v_s`` that bring every output row and every input column to the
  size of ``A``;
* for decisions only, a time scaling ``A / sigma`` (``sigma`` a power of 2 near
  ``||A||``): eigenvalues and zeros scale by ``1 / sigma``, ranks do not
  change, and data in the overflow range (entries ``1e200``) become numbers
  of size 1.

The balanced matrices are::

    A_s = T^-1 A T,  B_s = T^-1 B,  E_s = T^-1 E W_d,
    C_s = W_y C T,   D_s = W_y D W_v.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.optimize import linear_sum_assignment

from . import tolerances as tols
from .linalg import ObservabilitySplit, left_null, observability_decomposition, sort_poles
from .plant import Plant

__all__ = [
    "Scaling",
    "plant_scaling",
    "balanced_plant",
    "BalancedPair",
    "balanced_pair",
    "modes_agree",
    "pow2",
]

_SWEEPS = 100
_TOL = 0.05  # log2 units: the iteration stops when no scaling moves by 3.5 %


def pow2(x: np.ndarray | float) -> np.ndarray:
    """The power of 2 nearest to each positive ``x`` (1 where ``x`` is 0 or not finite).

    Examples
    --------
    >>> from uio_teach.balancing import pow2
    >>> pow2([3.0, 0.0, 1e-3]).tolist()
    [4.0, 1.0, 0.0009765625]
    """
    x = np.asarray(x, float)
    ok = np.isfinite(x) & (x > 0)
    out = np.ones_like(x)
    out[ok] = np.exp2(np.round(np.log2(x[ok])))
    return out


class Scaling(NamedTuple):
    """Diagonal scalings of a plant's states, outputs and unknown inputs.

    Attributes
    ----------
    t : numpy.ndarray, shape (n,)
        State scaling, ``x = diag(t) x_s``.
    wy : numpy.ndarray, shape (p,)
        Output scaling, ``y_s = diag(wy) y``.
    wd : numpy.ndarray, shape (q,)
        Unknown-input scaling, ``d = diag(wd) d_s``.
    wv : numpy.ndarray, shape (nv,)
        Measurement-disturbance scaling, ``v = diag(wv) v_s``.
    sigma : float
        Time scaling used for decisions: ``A_s / sigma`` has norm near 1.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.balancing import plant_scaling
    >>> s = plant_scaling(ut.examples.pa9())
    >>> s.t.shape, s.wy.shape
    ((3,), (2,))
    """

    t: np.ndarray
    wy: np.ndarray
    wd: np.ndarray
    wv: np.ndarray
    sigma: float


def _log2abs(X) -> np.ndarray:
    """``log2 |X|`` entrywise, ``-inf`` for zeros (no overflow whatever the data's size)."""
    X = np.abs(np.asarray(X, float))
    with np.errstate(divide="ignore"):
        return np.log2(X)


def _lse(x: np.ndarray, axis: int | None = None) -> np.ndarray:
    """``0.5 log2(sum 2^(2 x))``: the log2 of a 2-norm from log2 entries (``-inf`` if empty)."""
    x = np.asarray(x, float)
    if x.size == 0:
        shape = () if axis is None else tuple(d for i, d in enumerate(x.shape) if i != axis)
        return np.full(shape, -np.inf)
    m = np.max(x, axis=axis, keepdims=True)
    m_safe = np.where(np.isfinite(m), m, 0.0)
    with np.errstate(all="ignore"):
        out = m_safe + 0.5 * np.log2(np.sum(np.exp2(2.0 * (x - m_safe)), axis=axis, keepdims=True))
    out = np.where(np.isfinite(m), out, -np.inf)
    return np.squeeze(out, axis=axis) if axis is not None else float(out.ravel()[0])


def _sweeps(LA, LE, LC, LD, diag, logs):
    """Run the balancing sweeps on log2 entries; returns the log2 scalings ``(t, wy, wd, wv)``."""
    lt, ly, ld, lv = (np.array(x, float) for x in logs)
    n, p, q, nv = lt.size, ly.size, ld.size, lv.size
    for _ in range(_SWEEPS):
        before = np.concatenate([lt, ly, ld, lv])
        # the size of the balanced A (its Frobenius norm; 1 when A is zero)
        As = LA + lt[None, :] - lt[:, None] if n else LA
        target = float(np.logaddexp2(2 * _lse(As), 2 * _lse(diag)) / 2) if n else -np.inf
        if not np.isfinite(target):
            target = 0.0
        # outputs: each row of [C_s, D_s] to the size of A_s
        rows = (
            np.logaddexp2(2 * _lse(LC + lt[None, :], axis=1), 2 * _lse(LD + lv[None, :], axis=1))
            / 2
            if p
            else np.zeros(0)
        )
        new = np.where(np.isfinite(rows), target - rows, ly)
        ly = new
        # unknown inputs: each column of E_s and of D_s to the size of A_s
        cols = _lse(LE - lt[:, None], axis=0) if q else np.zeros(0)
        new = np.where(np.isfinite(cols), target - cols, ld)
        ld = new
        cols = _lse(LD + ly[:, None], axis=0) if nv else np.zeros(0)
        new = np.where(np.isfinite(cols), target - cols, lv)
        lv = new
        # states, all at once (a damped Jacobi sweep of Osborne's iteration): balance
        # row j of [A_s, E_s] against column j of [A_s; C_s]
        if n:
            r = (
                np.logaddexp2(
                    2 * _lse(LA + lt[None, :], axis=1), 2 * _lse(LE + ld[None, :], axis=1)
                )
                / 2
                - lt
            )
            c = (
                np.logaddexp2(
                    2 * _lse(LA - lt[:, None], axis=0), 2 * _lse(LC + ly[:, None], axis=0)
                )
                / 2
                + lt
            )
            fr, fc = np.isfinite(r), np.isfinite(c)
            step = np.where(
                fr & fc,
                0.5 * (r - c),  # balance the row against the column
                np.where(fc, target - c, np.where(fr, r - target, 0.0)),  # an empty side
            )
            step = np.where(np.isfinite(step), 0.5 * step, 0.0)  # damped: all states move
            # a common factor of all state scalings is free (outputs and inputs absorb it):
            # keep it at 0, or the iteration drifts along it forever
            m = float(np.mean(step))
            step = step - m
            lt, ly, ld, lv = lt + step, ly + m, ld - m, lv - m
        moved = float(np.max(np.abs(np.concatenate([lt, ly, ld, lv]) - before), initial=0.0))
        if moved <= _TOL:
            break
    return lt, ly, ld, lv


def plant_scaling(plant: Plant) -> Scaling:
    """Scalings that balance the system matrix ``[[A, E, 0], [C, 0, D]]`` of ``plant``.

    Osborne's iteration in the 2-norm, state by state, with each output row
    and each unknown-input column brought to the size of the balanced ``A``
    (to 1 when ``A`` is zero), run on the logarithms of the entries (so data
    of any size, ``1e-300`` or ``1e300``, neither overflow nor underflow)
    until no factor moves by more than 3.5 %. The factors are then rounded to
    powers of 2, so scaling is exact.

    Parameters
    ----------
    plant : Plant

    Returns
    -------
    Scaling

    Examples
    --------
    The same plant in other state units gets scalings that undo them:

    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach.balancing import balanced_plant
    >>> pl = ut.examples.pa9()
    >>> s = np.array([1e3, 1.0, 1e-3])
    >>> other = ut.Plant(pl.A * s / s[:, None], pl.C * s, E=pl.E / s[:, None])
    >>> a, b = balanced_plant(pl)[0], balanced_plant(other)[0]
    >>> big = np.abs(a.A) > 1e-12  # the same entries, to within a power of 2 or so
    >>> bool(np.all(np.abs(np.log2(np.abs(a.A[big] / b.A[big]))) <= 1.5))
    True
    """
    n, p, q, nv = plant.n, plant.p, plant.q, plant.nv
    LA, LE, LC, LD = (_log2abs(X) for X in (plant.A, plant.E, plant.C, plant.D))
    diag = np.diag(LA).copy() if n else np.zeros(0)
    if n:
        LA = LA.copy()
        np.fill_diagonal(LA, -np.inf)
    lt, ly, ld, lv = np.zeros(n), np.zeros(p), np.zeros(q), np.zeros(nv)
    with np.errstate(invalid="ignore"):  # -inf - -inf of empty rows is masked out
        lt, ly, ld, lv = _sweeps(LA, LE, LC, LD, diag, (lt, ly, ld, lv))
    # a common factor of all state scalings is free (outputs and inputs absorb it): fix it
    if n:
        m = float(np.mean(lt))
        lt, ly, ld = lt - m, ly + m, ld - m
        lv = lv - m  # D_s = W_y D W_v keeps its size
    # powers of 2 at the end, so that scaling the data is exact
    t, wy, wd, wv = (np.exp2(np.round(x)) for x in (lt, ly, ld, lv))
    with np.errstate(all="ignore"):
        As = plant.A / t[:, None] * t[None, :] if n else plant.A
        size = float(np.max(np.abs(As))) if As.size else 0.0
    sigma = float(pow2(size)) if size > 0 else 1.0
    return Scaling(t=t, wy=wy, wd=wd, wv=wv, sigma=sigma)


def balanced_plant(plant: Plant, scaling: Scaling | None = None, *, time: bool = False):
    """The plant in balanced units, and the scaling used.

    Parameters
    ----------
    plant : Plant
    scaling : Scaling, optional
        Default :func:`plant_scaling` of ``plant``.
    time : bool
        Also divide every matrix by ``scaling.sigma`` (for decisions: a time
        scaling of ``A``, ``B``, ``E`` and an output scaling of ``C``, ``D``).
        Eigenvalues and invariant zeros of the result are those of the plant
        divided by ``sigma``.

    Returns
    -------
    (Plant, Scaling)

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.balancing import balanced_plant
    >>> bal, s = balanced_plant(ut.examples.missile_autopilot())
    >>> bal.n, float(s.sigma) > 0
    (4, True)
    """
    s = plant_scaling(plant) if scaling is None else scaling
    t, wy, wd, wv = s.t, s.wy, s.wd, s.wv
    f = 1.0 / s.sigma if time else 1.0
    with np.errstate(all="ignore"):
        A = plant.A / t[:, None] * t[None, :] * f
        B = plant.B / t[:, None] * f
        E = plant.E / t[:, None] * wd[None, :] * f
        C = wy[:, None] * plant.C * t[None, :] * f
        D = wy[:, None] * plant.D * wv[None, :] * f
    dt = plant.dt
    return Plant(A, C, B=B, E=E, D=D, dt=dt, name=plant.name), s


class BalancedPair(NamedTuple):
    """The pair ``(A1, N C)`` of a projection design, in balanced units.

    ``A = T^-1 A1 T / sigma`` and ``C = R C_plant T / sigma`` with
    ``R = N_b W_y`` (``N_b`` spans the left null space of the balanced ``D``,
    so ``R D = 0``). A gain ``L_b`` with ``eig(A - L_b C) = poles / sigma``
    gives the plant's gain ``L = T L_b R`` with ``eig(A1 - L C_plant) = poles``
    and ``L D = 0``.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.balancing import balanced_pair
    >>> pl = ut.examples.pa9()
    >>> pair = balanced_pair(pl.A, pl.C, pl.D)
    >>> pair.A.shape, pair.C.shape
    ((3, 3), (2, 3))
    """

    A: np.ndarray
    C: np.ndarray
    t: np.ndarray
    R: np.ndarray
    sigma: float
    split: ObservabilitySplit

    @property
    def fixed_modes(self) -> np.ndarray:
        """The modes no gain can move, in the plant's time units (sorted)."""
        return sort_poles(self.split.unobservable_modes * self.sigma)

    @property
    def movable(self) -> int:
        """How many poles a gain can place."""
        return int(self.split.Ao.shape[0])

    def gain(self, Lb: np.ndarray) -> np.ndarray:
        """The plant's gain ``T L_b R`` from a gain of the balanced pair."""
        return self.t[:, None] * (Lb @ self.R)


def balanced_pair(
    A1: np.ndarray,
    C: np.ndarray,
    D: np.ndarray,
    scaling: Scaling | None = None,
    zeros: np.ndarray | None = None,
    radius: np.ndarray | None = None,
) -> BalancedPair:
    """Balance the pair ``(A1, N C)`` (``N D = 0``) and split it into observable parts.

    Parameters
    ----------
    A1 : array_like, shape (n, n)
    C : array_like, shape (p, n)
    D : array_like, shape (p, nv)
    scaling : Scaling, optional
        The plant's scaling; by default one is computed for ``(A1, C, D)``.
    zeros : array_like, optional
        The plant's invariant zeros. In exact arithmetic they are the
        unobservable modes of the pair; when the staircase's rank decisions
        find other modes, it is run again with a tighter and a looser rank
        threshold and the split that agrees with the zeros is kept, so the
        number of movable poles always agrees with the list of zeros.
    radius : array_like, optional
        How far round-off moves each zero (:class:`uio_teach.linalg.ZeroSet`): modes agree
        with a zero within it (a repeated zero's modes scatter by ``eps**(1/k)``).

    Returns
    -------
    BalancedPair
    """
    A1 = np.asarray(A1, float)
    C = np.asarray(C, float)
    D = np.asarray(D, float).reshape(C.shape[0], -1)
    if scaling is None:
        scaling = plant_scaling(Plant(A1, C, D=D))
    t, wy = scaling.t, scaling.wy
    with np.errstate(all="ignore"):
        Ab = A1 / t[:, None] * t[None, :]
        size = float(np.max(np.abs(Ab))) if Ab.size else 0.0
        sigma = float(pow2(size)) if size > 0 else 1.0
        Ab = Ab / sigma
        Cb = wy[:, None] * C * t[None, :] / sigma
        Db = wy[:, None] * D
    Nb = left_null(Db)
    R = Nb * wy[None, :]
    Cn = Nb @ Cb
    split = observability_decomposition(Ab, Cn)
    if zeros is not None and not modes_agree(split.unobservable_modes * sigma, zeros, radius):
        for rtol in (1e1, 1e5, 1e7, 1e9):
            other = observability_decomposition(Ab, Cn, rtol=rtol)
            if modes_agree(other.unobservable_modes * sigma, zeros, radius):
                split = other._replace(margin=min(other.margin, 1.0))  # flagged: marginal
                break
        else:
            split = (
                _split_from_modes(Ab, Cn, np.asarray(zeros, complex) / sigma)
                or _split_of_size(Ab, Cn, len(zeros))
                or split
            )
    return BalancedPair(A=Ab, C=Cn, t=t, R=R, sigma=sigma, split=split)


def _split_from_modes(A: np.ndarray, C: np.ndarray, modes: np.ndarray):
    """The observability split whose unobservable modes are ``modes`` (distinct), or None.

    The unobservable subspace is spanned by the vectors ``v`` with ``(A - z I) v = 0`` and
    ``C v = 0`` for each mode ``z``: the smallest right singular vector of ``[z I - A; C]``
    (real and imaginary parts for a complex pair). Used when the staircase's rank decisions miss
    modes that the invariant zeros, computed with every decision checked, show.
    """
    n = A.shape[0]
    if not len(modes):
        return None
    vecs = []
    for z in modes:
        if z.imag < 0:
            continue  # its conjugate gives the same real plane
        M = np.vstack([z * np.eye(n) - A, C.astype(complex)])
        v = np.linalg.svd(M)[2][-1].conj()
        vecs.extend([v.real, v.imag] if z.imag > 0 else [v.real])
    k = len(modes)
    if len(vecs) != k:
        return None  # a complex mode without its conjugate: no real subspace
    V = np.array(vecs).T
    U, sv, _ = np.linalg.svd(V, full_matrices=True)
    if V.shape[1] != k or sv.size < k or sv[k - 1] <= tols.SPAN_RTOL * sv[0]:
        return None  # repeated modes: their vectors do not span the subspace
    Vu, Vo = U[:, :k], U[:, k:]
    split = ObservabilitySplit(
        Vo=Vo, Vu=Vu, Ao=Vo.T @ A @ Vo, Co=C @ Vo, Au=Vu.T @ A @ Vu, margin=1.0
    )
    return split if modes_agree(split.unobservable_modes, modes) else None


def _split_of_size(A: np.ndarray, C: np.ndarray, k: int):
    """The observability split whose unobservable part has ``k`` states, or None.

    For a repeated or defective zero, whose modes scatter by ``eps**(1/k)``: the staircase is
    run with rank thresholds from tight to loose and the first split of the right size (the
    zeros' count, from the pencil's structure) is kept, flagged as marginal.
    """
    for rtol in np.geomspace(1.0, 1e12, 13):
        split = observability_decomposition(A, C, rtol=float(rtol))
        if split.Au.shape[0] == k:
            return split._replace(margin=min(split.margin, 1.0))
    return None


def modes_agree(modes: np.ndarray, zeros: np.ndarray, radius: np.ndarray | None = None) -> bool:
    """True when ``modes`` and ``zeros`` are the same values (count and, matched, value).

    Matched one to one, each within ``MODES_RTOL`` (:mod:`uio_teach.tolerances`) of the
    larger of its size and the largest zero's (a scale of the system's own, so the same in
    any unit of time), or within twice its ``radius`` (how far round-off moves it).

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.balancing import modes_agree
    >>> modes_agree(np.array([-1.0, -2.0]), np.array([-2.0, -1.0 + 1e-9]))
    True
    """
    modes = np.asarray(modes, complex).ravel()
    zeros = np.asarray(zeros, complex).ravel()
    if modes.size != zeros.size:
        return False
    if not modes.size:
        return True
    top = float(np.max(np.abs(zeros)))
    allow = tols.MODES_RTOL * np.maximum(np.abs(zeros), top)
    if radius is not None and len(radius) == zeros.size:
        r = np.asarray(radius, float)
        allow = np.maximum(allow, 2 * np.where(np.isfinite(r), r, 0.0))
    if not np.all(np.isfinite(modes)) or not np.all(np.isfinite(zeros)):
        return False
    cost = (
        np.abs(modes[:, None] - zeros[None, :]) / np.maximum(allow, np.finfo(float).tiny)[None, :]
    )
    rows, cols = linear_sum_assignment(cost)
    return bool(np.all(cost[rows, cols] <= 1.0))
