"""When does an unknown input observer exist? The conditions, checked and explained."""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from . import tolerances as tols
from ._display import LINE_WIDTH, fit_lines, format_complex
from .balancing import (
    BalancedPair,
    Scaling,
    balanced_pair,
    balanced_plant,
    modes_agree,
    plant_scaling,
)
from .enclosures import validated_zeros
from .errors import UIOTeachError
from .linalg import (
    ObservabilitySplit,
    ZeroSet,
    checked_zeros,
    left_null,
    one_blas_thread,
    pinv,
    rank_decision,
)
from .plant import Plant, check_plant
from .verify import product_bound, relative_residual

__all__ = [
    "Condition",
    "Decoupling",
    "ExistenceReport",
    "UIOExistenceError",
    "check_existence",
    "decoupling",
    "detectability_conditions",
    "rank_condition",
    "zero_condition",
]


@dataclass(frozen=True)
class Condition:
    """One existence condition: its name, whether it holds and why.

    ``holds`` is ``None`` when the condition could not be evaluated because an
    earlier one failed. ``required=False`` marks information that does not
    decide existence (e.g. full observability).

    Examples
    --------
    >>> import uio_teach as ut
    >>> cond = ut.check_existence(ut.examples.pa9())["rank condition"]
    >>> cond.holds, cond.symbol
    (True, '✓')
    >>> print(cond)
    ✓ rank condition: rank(CE) = 1 = rank(E): the unknown inputs can be
      decoupled
    """

    name: str
    holds: bool | None
    reason: str
    required: bool = True
    margin: float | None = None
    """For a verdict that rests on a rank decision, the smallest ratio (kept singular value /
    rank threshold), or, when a value taken as 0 sits within ``DROP_MARGIN`` below the
    threshold, that ratio (threshold / dropped value); below
    ``uio_teach.tolerances.RANK_MARGIN`` the verdict hangs on round-off and the reason says
    so. A rank-0 verdict carries it too."""
    undecided: bool = False
    """True when the verdict cannot be decided at this precision (``holds`` is then ``None``
    and the reason says why)."""

    @property
    def marginal(self) -> bool:
        """True when the verdict sits within the numerical margin of the rank threshold."""
        return self.margin is not None and self.margin < tols.RANK_MARGIN

    @property
    def symbol(self) -> str:
        """The verdict in one character; ✓, ✗, ? (undecided, round-off could change it), – (not
        evaluated) or ○ (info, not met)."""
        if not self.required and self.holds is False:
            return "○"
        if self.undecided:
            return "?"
        return {True: "✓", False: "✗", None: "–"}[self.holds]

    def __str__(self) -> str:
        """The verdict, the condition and why, wrapped to the book's column."""
        return fit_lines(f"{self.symbol} {self.name}: {self.reason}")


@dataclass(frozen=True)
class Decoupling:
    """The decoupling step shared by every projection-type design.

    ``M = [E 0][CE D]^+ + Mv (I - [CE D][CE D]^+)``, ``A1 = (I - M C) A``,
    ``N`` (orthonormal rows) annihilates ``D`` so that gains of the form
    ``L = ell N`` satisfy ``L D = 0``; ``pair`` is the pair ``(A1, N C)`` in
    balanced units with its observability split (what a gain can move is
    decided there, so it does not depend on the units of the data).

    Examples
    --------
    >>> import uio_teach as ut
    >>> dec = ut.existence.decoupling(ut.examples.missile_autopilot())
    >>> dec.pair.movable, dec.pair.fixed_modes.round(1).tolist()
    (2, [(-105.6-142.1j), (-105.6+142.1j)])
    """

    M: np.ndarray
    A1: np.ndarray
    N: np.ndarray
    pair: BalancedPair

    @property
    def split(self) -> ObservabilitySplit:
        """The observability split of the balanced pair (balanced coordinates)."""
        return self.pair.split


def decoupling(
    plant: Plant,
    Mv: np.ndarray | None = None,
    scaling: Scaling | None = None,
    zeros: np.ndarray | None = None,
    radius: np.ndarray | None = None,
) -> Decoupling:
    """Compute ``M``, ``A1`` and the balanced pair ``(A1, N C)`` (rank condition assumed).

    Parameters
    ----------
    plant : Plant
    Mv : array_like, shape (n, p), optional
        The free matrix of the projection (no effect when ``[CE D]`` is square
        and invertible).
    scaling : Scaling, optional
        The plant's balancing (:func:`uio_teach.balancing.plant_scaling`).
    zeros : array_like, optional
        The plant's invariant zeros (``check_existence(plant).invariant_zeros``):
        the fixed modes of the pair are made to agree with them (see
        :func:`uio_teach.balancing.balanced_pair`).
    radius : array_like, optional
        How far round-off moves each zero (``ZeroSet.radius``): a repeated zero's fixed modes
        agree with it within that radius.

    Returns
    -------
    Decoupling

    Examples
    --------
    >>> import uio_teach as ut
    >>> dec = ut.existence.decoupling(ut.examples.pa9())
    >>> dec.M.shape, dec.A1.shape
    ((3, 2), (3, 3))
    """
    n, p = plant.n, plant.p
    if scaling is None:
        scaling = plant_scaling(plant)
    M = projection_gain(plant, scaling)
    if Mv is not None:
        G = np.hstack([plant.C @ plant.E, plant.D])
        M = M + Mv @ (np.eye(p) - G @ pinv(G))
    A1 = (np.eye(n) - M @ plant.C) @ plant.A
    N = left_null(plant.D)
    pair = balanced_pair(A1, plant.C, plant.D, scaling, zeros, radius)
    return Decoupling(M=M, A1=A1, N=N, pair=pair)


def projection_gain(plant: Plant, scaling: Scaling | None = None) -> np.ndarray:
    """``M = [E 0][CE D]^+``: the gain with ``M [CE D] = [E 0]`` (the rank condition assumed).

    The Moore-Penrose inverse is taken in the plant's own units (the printed
    designs of the course use it). When that loses the identity to round-off
    (badly scaled data) or overflows, ``M`` is computed in balanced units
    instead, ``M = T M_s W_y``: another generalized inverse with the same
    identity.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.existence import projection_gain
    >>> projection_gain(ut.examples.pa9()).round(2)
    array([[0.94, 0.24],
           [0.  , 0.  ],
           [0.24, 0.06]])
    """
    n, nv = plant.n, plant.nv
    with np.errstate(all="ignore"):
        G = np.hstack([plant.C @ plant.E, plant.D])
        Eb = np.hstack([plant.E, np.zeros((n, nv))])
        if np.all(np.isfinite(G)):
            M = Eb @ pinv(G)
            bound = product_bound((M, G), Eb)
            if (
                np.all(np.isfinite(M))
                and relative_residual(M @ G - Eb, bound) <= tols.IDENTITY_RTOL
            ):
                return M
    s = plant_scaling(plant) if scaling is None else scaling
    bal, _ = balanced_plant(plant, s)
    Gs = np.hstack([bal.C @ bal.E, bal.D])
    Ms = np.hstack([bal.E, np.zeros((n, nv))]) @ pinv(Gs)
    return s.t[:, None] * Ms * s.wy[None, :]


@dataclass(frozen=True)
class ExistenceReport:
    """Which conditions for an unknown input observer hold, and why.

    Attributes
    ----------
    plant : Plant
        The plant checked.
    conditions : tuple of Condition
        Every condition with its verdict and a one-line reason.
    invariant_zeros : numpy.ndarray
        Invariant zeros from the unknown inputs ``(d, v)`` to ``y``.
    fixed_modes : numpy.ndarray
        Error modes no observer gain can move: the unobservable modes of the
        pair the designs use, ``(TA, C)`` (``(A1, N C)`` with a measurement
        disturbance). Empty when the rank condition fails.
    ok : bool
        True when every required condition holds: a UIO with stable error
        dynamics exists.

    Examples
    --------
    >>> import uio_teach as ut
    >>> report = ut.check_existence(ut.examples.missile_autopilot())
    >>> report.ok, report.movable
    (True, 2)
    >>> [c.name for c in report.failed]
    []
    """

    plant: Plant
    conditions: tuple[Condition, ...]
    invariant_zeros: np.ndarray
    fixed_modes: np.ndarray
    movable: int = field(default=0)
    zero_set: ZeroSet | None = None
    """The zeros with their radii and distances (:func:`uio_teach.linalg.checked_zeros`)."""

    @property
    def zero_radius(self) -> np.ndarray | None:
        """How far round-off of the data can move each invariant zero (``None``
        when not computed)."""
        return None if self.zero_set is None else self.zero_set.radius

    @property
    def ok(self) -> bool:
        """True when every required condition holds."""
        return all(c.holds for c in self.conditions if c.required)

    @property
    def decided(self) -> bool:
        """False when a required condition cannot be decided at this precision."""
        return not any(c.undecided for c in self.conditions if c.required)

    @property
    def verdict(self) -> str:
        """The conclusion in words."""
        if self.ok:
            return "a UIO exists"
        if not self.decided and not any(c.holds is False for c in self.conditions if c.required):
            return "cannot be decided at this precision"
        return "no UIO with stable error dynamics exists"

    @property
    def delayed(self):
        """Whether a UIO that waits ``L`` samples exists when the plain one does not.

        The smallest ``L`` (discrete time), or what the missing derivatives would cost
        (continuous time); ``None`` when the plain UIO exists. See
        :func:`uio_teach.delay_verdict`."""
        from .observers.delayed import delay_verdict  # deferred: the observers import this

        return None if self.ok else delay_verdict(self.plant, self)

    @property
    def failed(self) -> tuple[Condition, ...]:
        """The required conditions that do not hold or cannot be decided."""
        return tuple(c for c in self.conditions if c.required and (c.holds is False or c.undecided))

    def __getitem__(self, name: str) -> Condition:
        for c in self.conditions:
            if c.name == name:
                return c
        raise KeyError(f"no condition named {name!r}; have {[c.name for c in self.conditions]}")

    def __str__(self) -> str:
        head = f"Existence of an unknown input observer for {self.plant!r}"
        if len(head) > LINE_WIDTH:
            head = fit_lines(f"Existence of an unknown input observer for\n  {self.plant!r}")
        return conditions_text(head, self.conditions, self.verdict)

    __repr__ = __str__

    def _repr_html_(self) -> str:
        title = "<b>Existence of an unknown input observer</b> for " + html.escape(repr(self.plant))
        return conditions_html(title, self.conditions, self.verdict)


def conditions_text(head: str, conditions: tuple[Condition, ...], verdict: str) -> str:
    """A report's table of conditions as text: a row per condition (its mark, name and why,
    long reasons wrapped under their column to fit the book's), then the verdict."""
    width = max(len(c.name) for c in conditions)
    lines = [head]
    indent = " " * (width + 6)
    for c in conditions:
        tag = "" if c.required else " (info)"
        lines.append(
            fit_lines(f"  {c.symbol} {c.name.ljust(width)}  {c.reason}{tag}", indent=indent)
        )
    lines.append(f"  => {verdict}")
    return "\n".join(lines)


def conditions_html(title: str, conditions: tuple[Condition, ...], verdict: str) -> str:
    """The same table in HTML (``title`` is HTML already)."""
    rows = "".join(
        f"<tr><td>{c.symbol}</td><td>{html.escape(c.name)}</td>"
        f"<td>{html.escape(c.reason)}{'' if c.required else ' <i>(info)</i>'}</td></tr>"
        for c in conditions
    )
    return (
        f"<div>{title}<table><tr><th></th><th>condition</th><th>why</th></tr>{rows}</table>"
        f"<b>&rArr; {html.escape(verdict)}</b></div>"
    )


class UIOExistenceError(UIOTeachError, ValueError):
    """No unknown input observer exists; ``.report`` says which condition failed."""

    def __init__(self, report: ExistenceReport, what: str = "an unknown input observer") -> None:
        self.report = report
        failed = report.failed
        reasons = "; ".join(f"{c.name}: {c.reason}" for c in failed)
        super().__init__(f"cannot design {what} for {report.plant!r}: {reasons}")


def _listed(values: np.ndarray, radius: np.ndarray | None = None) -> str:
    """Values on their own scale, a cluster within its radius (a repeated zero) once with ``xk``."""
    values = np.asarray(values, complex)
    if not values.size:
        return "none"
    radius = np.zeros(values.size) if radius is None else np.asarray(radius, float)
    parts, used = [], np.zeros(values.size, bool)
    for i in range(values.size):
        if used[i]:
            continue
        reach = max(float(radius[i]), 0.0) if np.isfinite(radius[i]) else 0.0
        group = ~used & (np.abs(values - values[i]) <= 2 * np.maximum(reach, radius))
        group[i] = True
        if np.sum(group) > 1 and not np.all(np.isfinite(radius[group])):
            group[:] = False
            group[i] = True
        used |= group
        k = int(np.sum(group))
        centre = complex(np.mean(values[group]))
        text = format_complex(centre)
        parts.append(f"{text} (x{k})" if k > 1 else text)
    return "{" + ", ".join(parts) + "}"


def _pair_name(plant: Plant) -> str:
    return "(A1, N C)" if plant.nv else "(TA, C)"


def _region(discrete: bool) -> str:
    return "the open unit disk" if discrete else "the open left half-plane"


def _margin_note(margin: float, what: str = "a singular value") -> str:
    if margin >= tols.RANK_MARGIN:
        return ""
    return (
        f" (within the numerical margin: {what} is only {margin:.3g} times "
        "the rank threshold, so round-off of the data could change this verdict)"
    )


def _exact(M: np.ndarray) -> list[list[Fraction]]:
    return [[Fraction(float(x)) for x in row] for row in np.atleast_2d(M)]


def _exact_rank(rows: list[list[Fraction]]) -> int:
    """The rank of a matrix of rationals, by exact Gaussian elimination."""
    rows = [list(r) for r in rows if any(r)]
    rank = 0
    ncol = len(rows[0]) if rows else 0
    for j in range(ncol):
        pivot = next((i for i in range(rank, len(rows)) if rows[i][j] != 0), None)
        if pivot is None:
            continue
        rows[rank], rows[pivot] = rows[pivot], rows[rank]
        for i in range(rank + 1, len(rows)):
            if rows[i][j]:
                f = rows[i][j] / rows[rank][j]
                rows[i] = [a - f * b for a, b in zip(rows[i], rows[rank], strict=True)]
        rank += 1
    return rank


def exact_rank_deficient(plant: Plant) -> bool:
    """True when ``rank([C E, D]) < rank(E) + rank(D)`` holds exactly for the data as stored.

    The products are formed in rational arithmetic from the stored doubles: a ``C E`` that is
    zero in exact arithmetic is told from one that is ``2^-52`` of its factors.
    """
    C, E, D = _exact(plant.C), _exact(plant.E), _exact(plant.D)
    p, n = plant.p, plant.n
    CE = [
        [sum((C[i][k] * E[k][j] for k in range(n)), Fraction(0)) for j in range(plant.q)]
        for i in range(p)
    ]
    G = [CE[i] + (D[i] if plant.nv else []) for i in range(p)]
    rE = _exact_rank(E) if plant.q else 0
    rD = _exact_rank(D) if plant.nv else 0
    return _exact_rank(G) < rE + rD


def rank_condition(bal: Plant, plant: Plant | None = None) -> tuple[Condition, int]:
    """The rank condition, decided on the balanced plant ``bal``; returns it and rank(E).

    Three ways: it holds when every singular value it needs is above its bound (the rounding
    of the product ``C E`` and of the data, ``RANK_RTOL n eps`` of the factors); it fails when
    a needed singular value is within the bound and the data as stored (``plant``) are
    rank-deficient in exact arithmetic; otherwise it cannot be decided (a plant within the
    bound has the rank, another does not), and the reason names the singular value and the
    bound.

    Parameters
    ----------
    bal : Plant
        The plant in balanced units (:func:`uio_teach.balancing.balanced_plant`):
        ranks are then judged against factors of comparable size, whatever
        the units of the data.
    plant : Plant, optional
        The data as given (for the exact check of a rank deficiency); default ``bal``.

    Returns
    -------
    (Condition, int)

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.balancing import balanced_plant
    >>> cond, rE = rank_condition(balanced_plant(ut.examples.pa9(), time=True)[0])
    >>> cond.holds, rE
    (True, 1)
    """
    plant = bal if plant is None else plant
    C, E, D = bal.C, bal.E, bal.D
    nC, nE, nD = (float(np.linalg.norm(X, 2)) if X.size else 0.0 for X in (C, E, D))
    # data known to double precision; C E is a sum of n products, so its round-off
    # grows with n: the thresholds leave room for it (RANK_RTOL)
    eps = np.finfo(float).eps
    rtol = tols.RANK_RTOL * eps
    dE, dD = rank_decision(E, rtol=rtol), rank_decision(D, rtol=rtol)
    G = np.hstack([C @ E, D])
    dG = rank_decision(G, scale=max(nC * nE, nD), rtol=tols.RANK_RTOL * max(bal.n, 1) * eps)
    rE, rD, rG = dE.rank, dD.rank, dG.rank
    margin = min(dE.margin, dD.margin, dG.margin)
    below = min(dE.below, dD.below, dG.below)
    if bal.nv:
        lhs, rhs = f"rank([CE D]) = {rG}", f"rank(E) + rank(D) = {rE} + {rD}"
        name = "[CE D]"
    else:
        lhs, rhs = f"rank(CE) = {rG}", f"rank(E) = {rE}"
        name = "CE"
    ok = rG == rE + rD
    undecided = False
    if ok:
        reason = f"{lhs} = {rhs.split(' = ')[0]}: the unknown inputs can be decoupled"
    else:
        reason = (
            f"{lhs} but {rhs}: part of the unknown input does not show in the outputs "
            "at once, so it cannot be cancelled"
        )
        if not exact_rank_deficient(plant):
            undecided = True
    if undecided:
        if rG < rE + rD:
            # a singular value of [CE D] that the ranks of E and D need lies within its bound
            s = np.linalg.svd(G, compute_uv=False) if G.size else np.zeros(0)
            k = min(rG, s.size - 1)
            which, scale, bound_ = name, max(nC * nE, nD), dG.threshold
            of = "||C|| ||E||" if not bal.nv else "its factors"
        else:
            # a singular value of E (or D) just below its own bound: a plant that close has
            # a larger rank(E) + rank(D)
            X, d_ = (E, dE) if dE.below <= dD.below else (D, dD)
            s = np.linalg.svd(X, compute_uv=False)
            k = min(d_.rank, s.size - 1)
            which = "E" if X is E else "D"
            scale, bound_ = (float(s[0]) if s.size else 1.0), d_.threshold
            of = f"||{which}||"
        sv = float(s[k]) if 0 <= k < s.size else 0.0
        cond = Condition(
            "rank condition",
            None,
            f"cannot be decided at this precision: singular value {k + 1} of {which} is "
            f"{sv / scale:.3g} of {of} (balanced units), within its bound "
            f"{bound_ / scale:.3g} (the rounding of the data and of the product {name}): a "
            "plant that close meets the rank condition, another does not",
            margin=min(margin, below),
            undecided=True,
        )
        return cond, rE
    note = _margin_note(margin)
    if below < tols.DROP_MARGIN:
        note += (
            f" (within the numerical margin: a singular value taken as 0 is only {below:.3g} "
            "times below the rank threshold, so round-off of the data could change this "
            "verdict)"
        )
        margin = min(margin, below)
    cond = Condition("rank condition", ok, reason + note, margin=margin)
    return cond, rE


def zero_condition(zs: ZeroSet) -> Condition:
    """The condition "invariant zeros stable", decided from the zeros and their radii.

    A zero is on a side of the stability boundary when no perturbation of the data within the
    backward error of the computation (:class:`uio_teach.linalg.ZeroSet`) moves it across: the
    verdict is "no" when one zero is certainly outside the stability region, "cannot be
    decided" when a perturbation within that bound can move a zero across the boundary (or
    through infinity), and the reason then says the bound and the distance.

    Parameters
    ----------
    zs : ZeroSet
        The zeros, from :func:`uio_teach.linalg.checked_zeros`.

    Returns
    -------
    Condition

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.linalg import checked_zeros
    >>> zs = checked_zeros(np.diag([-1.0, -2.0]), [[1.0], [1.0]], [[1.0, 1.0]])
    >>> zero_condition(zs).holds
    True
    """
    name = "invariant zeros stable"
    discrete, region = zs.discrete, _region(zs.discrete)
    where = "unit circle" if discrete else "imaginary axis"
    zeros, und, stable = zs.zeros, zs.undecided, zs.stable
    bound = f"{zs.backward_error:.1g}"
    fragile = np.zeros(zeros.size, bool) if zs.fragile is None else zs.fragile
    bad = ~stable & ~und & ~fragile
    if np.any(bad):
        return Condition(
            name,
            False,
            f"invariant zero(s) {_listed(zeros[bad], zs.radius[bad])} outside {region}: they "
            "are observer poles no gain can move, so the error would not decay"
            + _clear_note(zs, bad, where),
        )
    parts = []
    far = zs.unresolved
    if np.any(far):
        parts.append(
            f"zero(s) {_listed(zeros[far])} lie beyond what double precision resolves: a "
            f"perturbation of the data within its backward error ({bound} relative) sends them "
            "through infinity, so they may lie on either side or not exist"
        )
    gone = fragile & ~stable
    if np.any(gone):
        parts.append(
            f"zero(s) {_listed(zeros[gone], zs.radius[gone])} may lie outside {region}, but "
            "with more outputs than unknown inputs a zero holds only by the structure of the "
            f"data: a plant within its backward error ({bound} relative) has it, another has "
            "none, and the data themselves may have either"
        )
    near = und & ~far & ~gone
    for z, r, d in zip(zeros[near], zs.radius[near], zs.distance[near], strict=True):
        parts.append(
            f"zero {format_complex(z)} lies {d:.2g} from the {where}, and a perturbation of the "
            f"data within its backward error ({bound} relative) moves it by up to {r:.2g}, "
            "across"
        )
    if zs.lost:
        parts.append(
            f"{zs.lost} zero(s) sit at infinity by a rank decision within round-off: a plant "
            f"within {bound} (relative) of the data has them finite and fast, on either side"
        )
    if zs.crossing and not parts:
        parts.append(
            f"a plant within the data's backward error ({bound} relative) has an invariant zero "
            f"on the {where}"
        )
    if parts:
        return Condition(
            name,
            None,
            "cannot be decided at this precision: " + "; ".join(parts),
            margin=1.0,
            undecided=True,
        )
    if not len(zeros):
        return Condition(name, True, "no invariant zeros")
    return Condition(
        name,
        True,
        f"zeros {_listed(zeros, zs.radius)} all lie in {region}"
        + _clear_note(zs, np.ones(zeros.size, bool), where),
    )


def _clear_note(zs: ZeroSet, mask: np.ndarray, where: str) -> str:
    """For the zero closest to the boundary among ``mask``: its distance and its radius.

    Said only when it is close (within ``CLOSE_NOTE_RTOL`` of the system's own rate or of the
    largest zero): the verdict is decided, and the note shows by how much.
    """
    d, r, z = zs.distance[mask], zs.radius[mask], zs.zeros[mask]
    finite = np.abs(zs.zeros[np.isfinite(zs.zeros)])
    if not d.size or not finite.size:
        return ""
    i = int(np.argmin(d))
    if not d[i] <= tols.CLOSE_NOTE_RTOL * max(float(np.max(finite)), zs.scale):
        return ""
    return (
        f" (the closest, {format_complex(z[i])}, lies {d[i]:.2g} from the {where}; a "
        f"perturbation of the data within its backward error moves it by at most {r[i]:.2g})"
    )


def detectability_conditions(
    plant: Plant, dec: Decoupling, zs: ZeroSet, zero_cond: Condition
) -> tuple[list[Condition], np.ndarray, int]:
    """Detectability and observability of the pair the designs use (rank condition holds).

    The fixed modes are the unobservable modes of the balanced pair; in exact arithmetic they
    are the invariant zeros, so detectability is decided as the zeros' stability is
    (``zero_cond``), and the number of movable poles is ``n`` minus the number of zeros, counted
    by the pencil's structure: the report and every design agree on it.

    Returns
    -------
    (list of Condition, numpy.ndarray, int)
        The two conditions, the fixed modes and the number of movable poles.
    """
    pair = _pair_name(plant)
    zeros = zs.zeros
    fixed, movable = dec.pair.fixed_modes, dec.pair.movable
    margin = dec.pair.split.margin
    note = _margin_note(margin, "a singular value of the observability staircase")
    if not modes_agree(fixed, zeros, zs.radius):
        # the zeros are counted from the pencil's structure; the staircase of the pair did not
        # resolve them (a repeated zero, a fast one): the zeros are the fixed modes
        note = (
            f" (the observability staircase of {pair} finds "
            f"{_listed(fixed)}: its rank decisions do not resolve them)"
        )
        fixed, movable, margin = zeros, plant.n - len(zeros), min(margin, 1.0)
    near = [int(np.argmin(np.abs(zeros - f))) for f in fixed]
    listed = _listed(fixed, zs.radius[near] if len(near) else None)
    if zero_cond.undecided:
        det = Condition(
            f"detectable {pair}",
            None,
            "cannot be decided at this precision: the fixed modes are the invariant zeros "
            f"{_listed(zeros, zs.radius)}, whose side of the boundary round-off decides" + note,
            margin=margin,
            undecided=True,
        )
    elif zero_cond.holds:
        reason = f"unobservable modes {listed} are the invariant zeros, all stable"
        det = Condition(
            f"detectable {pair}",
            True,
            (reason if len(fixed) else "observable, hence detectable") + note,
            margin=margin,
        )
    else:
        det = Condition(
            f"detectable {pair}",
            False,
            f"unobservable modes {listed} are the invariant zeros, not all stable" + note,
            margin=margin,
        )
    if len(fixed):
        reason = (
            f"{movable} of {plant.n} poles can be placed; {listed} are fixed "
            "(they are the invariant zeros)"
        )
    else:
        reason = f"all {plant.n} observer poles can be placed"
    obs = Condition(
        f"observable {pair}", not len(fixed), reason + note, required=False, margin=margin
    )
    return [det, obs], fixed, movable


def conditioning_condition(bal: Plant) -> Condition:
    """How much any UIO of the (balanced) plant amplifies round-off (information).

    Every UIO has ``H`` with ``H C E = E`` and ``T = I - H C``; the smallest such ``H`` is
    ``E (C E)^+``, so the decoupling multiplies the data's round-off by at least
    ``||E|| ||C|| / sigma_min(C E)`` (in balanced units). Above ``AMPLIFICATION_LIMIT``
    (:mod:`uio_teach.tolerances`) the UIO exists but is ill-conditioned: its matrices hold
    their identities only to that many rounding errors, and a design's check says how much
    the result leaks.

    Examples
    --------
    >>> import uio_teach as ut
    >>> ut.check_existence(ut.examples.pa9())["well-conditioned decoupling"].holds
    True
    """
    E, C = bal.E, bal.C
    G = np.hstack([C @ E, bal.D])
    s = np.linalg.svd(G, compute_uv=False) if G.size else np.zeros(0)
    rG = rank_decision(
        G, scale=max(float(np.linalg.norm(C, 2) * np.linalg.norm(E, 2)), 1e-300)
    ).rank
    smin = float(s[rG - 1]) if rG else 0.0
    top = float(np.linalg.norm(E, 2) * np.linalg.norm(C, 2)) if E.size and C.size else 0.0
    amp = top / smin if smin > 0 else np.inf
    ok = bool(amp <= tols.AMPLIFICATION_LIMIT)
    if ok:
        reason = (
            f"the UIO of least ||H|| amplifies round-off by about {amp:.2g}, the least any UIO can"
        )
    else:
        reason = (
            f"a UIO exists only ill-conditioned: C E is {1 / amp:.2g} of ||C|| ||E||, so H "
            f"(H C E = E) is large and any realization amplifies round-off by about {amp:.2g}"
        )
    return Condition("well-conditioned decoupling", ok, reason, required=False)


@one_blas_thread()
def check_existence(plant: Plant) -> ExistenceReport:
    """Check the conditions under which an unknown input observer exists.

    The conditions, in order:

    1. **rank condition** ``rank(CE) = rank(E)`` (with a measurement
       disturbance, ``rank([CE D]) = rank(E) + rank(D)``): the unknown inputs
       can be decoupled from the estimation error.
    2. **invariant zeros stable**: every invariant zero of the plant from the
       unknown inputs to ``y`` lies in the open left half-plane (continuous)
       or the open unit disk (discrete).
    3. **detectability** of the pair the designs use, ``(TA, C)`` with
       ``T = I - HC`` (``(A1, N C)`` when ``D`` is present, ``N D = 0``): its
       unobservable modes are the fixed observer poles; they are exactly the
       invariant zeros of 2.
    4. **observability** of that pair (information): every pole can be placed.
    5. **well-conditioned decoupling** (information): how much a UIO must
       amplify the data's round-off, ``||E|| ||C|| / sigma_min(C E)`` at least
       (see ``conditioning_condition``).
    6. **E full column rank** (information): the unknown input can be
       reconstructed uniquely from the state estimate.

    Every decision is made on the plant in balanced units
    (``uio_teach.balancing``): the same plant with its states, outputs or
    unknown inputs in other units gets the same verdicts, and data in the
    overflow range are scaled before any product is formed.

    Parameters
    ----------
    plant : Plant
        The plant to check.

    Returns
    -------
    ExistenceReport

    Examples
    --------
    >>> import uio_teach as ut
    >>> report = ut.check_existence(ut.examples.dt_case_study())
    >>> report.ok
    True
    >>> report.fixed_modes.real.round(6).tolist()
    [0.5, 0.5]
    """
    plant = check_plant(plant)
    discrete = plant.is_discrete
    bal, scaling = balanced_plant(plant, time=True)
    rank_cond, rE = rank_condition(bal, plant)
    conds = [rank_cond]
    # the zeros in the plant's own time unit (the states, inputs and outputs balanced)
    bal0, _ = balanced_plant(plant, scaling)
    zs = None
    if rank_cond.holds:
        # proven disks on the structure-revealing reduction (square and tall plants alike)
        # (continuous time: in the balanced time unit, then back in the plant's)
        src = bal0 if discrete else bal
        zs = validated_zeros(src.A, src.E, src.C, src.D, discrete=discrete)
        if zs is not None and not discrete:
            f = scaling.sigma
            zs = zs._replace(
                zeros=zs.zeros * f,
                radius=zs.radius * f,
                distance=zs.distance * f,
                scale=zs.scale * f,
            )
    if zs is None:
        Bz = np.hstack([bal0.E, np.zeros((plant.n, plant.nv))])
        Dz = np.hstack([np.zeros((plant.p, plant.q)), bal0.D])
        zs = checked_zeros(bal0.A, Bz, bal0.C, Dz, discrete=discrete)
    if rank_cond.undecided:
        zero_cond = Condition(
            "invariant zeros stable",
            None,
            "not evaluated: the rank condition cannot be decided, and plants that close differ "
            f"in their zeros (these data's: {_listed(zs.zeros)})",
        )
    elif rank_cond.holds and not zs.validated:
        zero_cond = Condition(
            "invariant zeros stable",
            None,
            "cannot be decided at this precision: the rank condition holds by too little "
            "for the zeros to be bounded (a plant within round-off has some of them at "
            f"infinity); these data's zeros: {_listed(zs.zeros)}",
            margin=1.0,
            undecided=True,
        )
    else:
        zero_cond = zero_condition(zs)
    conds.append(zero_cond)
    zeros = zs.zeros
    fixed = np.zeros(0, complex)
    movable = 0
    if rank_cond.holds:
        dec = decoupling(plant, scaling=scaling, zeros=zeros, radius=zs.radius)
        more, fixed, movable = detectability_conditions(plant, dec, zs, zero_cond)
        conds.extend(more)
    else:
        why = "not evaluated: the rank condition fails"
        pair = _pair_name(plant)
        conds.append(Condition(f"detectable {pair}", None, why))
        conds.append(Condition(f"observable {pair}", None, why, required=False))
    if rank_cond.holds and plant.q:
        conds.append(conditioning_condition(bal))
    if plant.q:
        full = rE == plant.q
        reason = (
            f"rank(E) = {rE} = q: the unknown input can be reconstructed as E^+ (x' - A x - B u)"
            if full
            else f"rank(E) = {rE} < q = {plant.q}: only E d, not d itself, can be reconstructed"
        )
        conds.append(Condition("E full column rank", full, reason, required=False))
    return ExistenceReport(
        plant=plant,
        conditions=tuple(conds),
        invariant_zeros=zeros,
        fixed_modes=fixed,
        movable=movable,
        zero_set=zs,
    )
