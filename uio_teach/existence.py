"""When does an unknown input observer exist? The conditions, checked and explained."""

from __future__ import annotations

import html
from dataclasses import dataclass, field

import numpy as np

from ._display import LINE_WIDTH, fit_lines, format_poles
from .balancing import BalancedPair, Scaling, balanced_pair, balanced_plant, plant_scaling
from .errors import UIOTeachError
from .linalg import (
    DROP_MARGIN,
    MARGIN,
    ObservabilitySplit,
    checked_zeros,
    is_stable,
    left_null,
    one_blas_thread,
    pinv,
    rank_decision,
    sort_poles,
)
from .plant import Plant, check_plant
from .verify import IDENTITY_RTOL, product_bound, relative_residual

__all__ = [
    "Condition",
    "Decoupling",
    "ExistenceReport",
    "UIOExistenceError",
    "boundary_note",
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
    """

    name: str
    holds: bool | None
    reason: str
    required: bool = True
    margin: float | None = None
    """For a verdict that rests on a rank decision: the smallest ratio (kept singular value /
    rank threshold), or, when a value taken as 0 sits within ``DROP_MARGIN`` below the
    threshold, that ratio (threshold / dropped value); below ``uio_teach.linalg.MARGIN`` the
    verdict hangs on round-off and the reason says so. A rank-0 verdict carries it too."""
    undecided: bool = False
    """True when the verdict cannot be decided at this precision (``holds`` is then ``None``
    and the reason says why)."""

    @property
    def marginal(self) -> bool:
        """True when the verdict sits within the numerical margin of the rank threshold."""
        return self.margin is not None and self.margin < MARGIN

    @property
    def symbol(self) -> str:
        """The verdict in one character; ✓, ✗, – (not evaluated) or ○ (info, not met)."""
        if not self.required and self.holds is False:
            return "○"
        if self.undecided:
            return "?"
        return {True: "✓", False: "✗", None: "–"}[self.holds]


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
    pair = balanced_pair(A1, plant.C, plant.D, scaling, zeros)
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
            if np.all(np.isfinite(M)) and relative_residual(M @ G - Eb, bound) <= IDENTITY_RTOL:
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
        width = max(len(c.name) for c in self.conditions)
        lines = [head]
        indent = " " * (width + 6)
        for c in self.conditions:
            tag = "" if c.required else " (info)"
            text = f"  {c.symbol} {c.name.ljust(width)}  {c.reason}{tag}"
            # wrap long reasons under their column so the table fits the book's column
            lines.append(fit_lines(text, indent=indent))
        lines.append(f"  => {self.verdict}")
        return "\n".join(lines)

    __repr__ = __str__

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td>{c.symbol}</td><td>{html.escape(c.name)}</td>"
            f"<td>{html.escape(c.reason)}{'' if c.required else ' <i>(info)</i>'}</td></tr>"
            for c in self.conditions
        )
        verdict = self.verdict
        return (
            f"<div><b>Existence of an unknown input observer</b> for "
            f"{html.escape(repr(self.plant))}<table>"
            f"<tr><th></th><th>condition</th><th>why</th></tr>{rows}</table>"
            f"<b>&rArr; {verdict}</b></div>"
        )


class UIOExistenceError(UIOTeachError, ValueError):
    """No unknown input observer exists; ``.report`` says which condition failed."""

    def __init__(self, report: ExistenceReport, what: str = "an unknown input observer") -> None:
        self.report = report
        failed = report.failed
        reasons = "; ".join(f"{c.name}: {c.reason}" for c in failed)
        super().__init__(f"cannot design {what} for {report.plant!r}: {reasons}")


RANK_RTOL = 100.0
"""The rank condition's thresholds are ``RANK_RTOL * eps`` (``RANK_RTOL * n * eps`` for the
product ``C E``) times the size of the balanced data: round-off stays well below them."""

AMPLIFICATION_LIMIT = 1e6
"""Above this, the report says that any UIO of the plant amplifies round-off: ``H`` with
``H C E = E`` has ``||H|| ||C|| >= ||E|| ||C|| / ||C E||``-sized entries (a small ``C E``)."""

ZERO_MARGIN = 1e-6
"""A zero or fixed mode closer than this (relative to ``max(1, ||A||)`` in balanced units) to
the stability boundary is reported as marginal: round-off of the data could move it across."""


def boundary_note(
    values: np.ndarray, discrete: bool, size: float, radius: np.ndarray | None = None
) -> str:
    """A note for values within the numerical margin of the stability boundary.

    Parameters
    ----------
    values : array_like of complex
        Zeros or modes.
    discrete : bool
        Judge against the unit circle (True) or the imaginary axis.
    size : float
        The size of the plant's balanced ``A``; the margin is
        ``ZERO_MARGIN * max(1, size)``.
    radius : array_like, optional
        For each value, how far round-off of the data can move it
        (:class:`uio_teach.linalg.ZeroSet`): a value farther from the boundary than ``MARGIN``
        times that (plus ``ZERO_MARGIN`` of its own size) gets no note.

    Returns
    -------
    str
        Empty when no value is that close.

    Examples
    --------
    >>> from uio_teach.existence import boundary_note
    >>> boundary_note([-1e-9, -1.0], discrete=False, size=1.0)[:28]
    ' (within the numerical margi'
    """
    if not len(values):
        return ""
    values = np.asarray(values, complex)
    dist = np.abs(np.abs(values) - 1.0) if discrete else np.abs(values.real)
    close = dist <= ZERO_MARGIN * max(1.0, float(size))
    if radius is not None and len(radius) == len(values):
        # a zero far from the boundary compared with how far round-off can move it is clear
        close &= dist <= MARGIN * np.asarray(radius, float) + ZERO_MARGIN * np.maximum(
            1.0, np.abs(values)
        )
    if not np.any(close):
        return ""
    where = "unit circle" if discrete else "imaginary axis"
    return (
        f" (within the numerical margin: {format_poles(values[close], braces=True)} lie(s) "
        f"{float(np.max(dist[close])):.2g} from the {where}, so round-off of the data could "
        "change this verdict)"
    )


def _pair_name(plant: Plant) -> str:
    return "(A1, N C)" if plant.nv else "(TA, C)"


def _region(discrete: bool) -> str:
    return "the open unit disk" if discrete else "the open left half-plane"


def _margin_note(margin: float, what: str = "a singular value") -> str:
    if margin >= MARGIN:
        return ""
    return (
        f" (within the numerical margin: {what} is only {margin:.3g} times "
        "the rank threshold, so round-off of the data could change this verdict)"
    )


def rank_condition(bal: Plant) -> tuple[Condition, int]:
    """The rank condition, decided on the balanced plant ``bal``; returns it and rank(E).

    Parameters
    ----------
    bal : Plant
        The plant in balanced units (:func:`uio_teach.balancing.balanced_plant`):
        ranks are then judged against factors of comparable size, whatever
        the units of the data.

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
    C, E, D = bal.C, bal.E, bal.D
    nC, nE, nD = (float(np.linalg.norm(X, 2)) if X.size else 0.0 for X in (C, E, D))
    # data known to double precision; C E is a sum of n products, so its round-off
    # grows with n: the thresholds leave room for it (RANK_RTOL)
    eps = np.finfo(float).eps
    dE, dD = rank_decision(E, rtol=RANK_RTOL * eps), rank_decision(D, rtol=RANK_RTOL * eps)
    dG = rank_decision(
        np.hstack([C @ E, D]), scale=max(nC * nE, nD), rtol=RANK_RTOL * max(bal.n, 1) * eps
    )
    rE, rD, rG = dE.rank, dD.rank, dG.rank
    margin = min(dE.margin, dD.margin, dG.margin)
    below = min(dE.below, dD.below, dG.below)
    if bal.nv:
        lhs, rhs = f"rank([CE D]) = {rG}", f"rank(E) + rank(D) = {rE} + {rD}"
    else:
        lhs, rhs = f"rank(CE) = {rG}", f"rank(E) = {rE}"
    ok = rG == rE + rD
    if ok:
        reason = f"{lhs} = {rhs.split(' = ')[0]}: the unknown inputs can be decoupled"
    else:
        reason = (
            f"{lhs} but {rhs}: part of the unknown input does not show in the outputs "
            "at once, so it cannot be cancelled"
        )
    note = _margin_note(margin)
    if below < DROP_MARGIN:
        note += (
            f" (within the numerical margin: a singular value taken as 0 is only {below:.3g} "
            "times below the rank threshold, so round-off of the data could change this "
            "verdict)"
        )
        margin = min(margin, below)
    cond = Condition("rank condition", ok, reason + note, margin=margin)
    return cond, rE


def zero_condition(
    zeros: np.ndarray,
    discrete: bool,
    size: float,
    doubtful: np.ndarray | None = None,
    residuals: np.ndarray | None = None,
    radius: np.ndarray | None = None,
) -> Condition:
    """The condition "invariant zeros stable" for the given zeros.

    ``doubtful`` lists values that are zeros of plants within round-off of the data but not
    certainly of this one (:class:`uio_teach.linalg.ZeroSet`), with ``residuals`` the
    Rosenbrock matrix's smallest singular value there relative to the round-off threshold. When
    such a value, or a zero within the numerical margin of the stability boundary, would change
    the verdict, the condition is not decided (``holds=None``) and the reason says why.

    Examples
    --------
    >>> import numpy as np
    >>> zero_condition(np.array([-1.0 + 0j]), discrete=False, size=1.0).holds
    True
    """
    region = _region(discrete)
    doubtful = np.zeros(0, complex) if doubtful is None else np.asarray(doubtful, complex)
    zeros = np.asarray(zeros, complex)
    undecided = _undecided_zeros(zeros, discrete, size, doubtful, residuals, radius)
    if undecided:
        return Condition("invariant zeros stable", None, undecided, margin=1.0, undecided=True)
    if not len(zeros):
        return Condition("invariant zeros stable", True, "no invariant zeros")
    bad = zeros[~is_stable(zeros, discrete)]
    note = boundary_note(zeros, discrete, size, radius)
    listed = format_poles(zeros if not len(bad) else bad, braces=True, empty="none")
    if not len(bad):
        return Condition(
            "invariant zeros stable", True, f"zeros {listed} all lie in {region}" + note
        )
    return Condition(
        "invariant zeros stable",
        False,
        f"invariant zero(s) {listed} outside {region}: they are observer poles "
        "no gain can move, so the error would not decay" + note,
    )


def _undecided_zeros(zeros, discrete, size, doubtful, residuals, radius=None) -> str:
    """Why the zero condition cannot be decided at this precision ('' when it can)."""
    stable = is_stable(zeros, discrete)
    dist = np.abs(np.abs(zeros) - 1.0) if discrete else np.abs(zeros.real)
    if radius is not None and len(radius) == len(zeros):
        # how far round-off of the data can move each zero (its condition number)
        near = dist <= np.asarray(radius, float)
    else:
        near = dist <= ZERO_MARGIN * max(1.0, float(size))
    if np.all(stable):
        # the verdict "stable" would change with a doubtful unstable value or a zero on the edge
        flip = doubtful[~is_stable(doubtful, discrete)] if doubtful.size else doubtful
        edge = zeros[near]
    else:
        # "unstable" is certain when one unstable zero is certain and clear of the boundary
        if np.any(~stable & ~near):
            return ""
        flip, edge = np.zeros(0, complex), zeros[~stable]
    if not flip.size and not edge.size:
        return ""
    where = "unit circle" if discrete else "imaginary axis"
    parts = []
    if flip.size:
        res = np.asarray(residuals if residuals is not None else [], float)
        how = (
            f" (singular to {float(np.min(res)):.2g} times the round-off threshold)"
            if res.size
            else ""
        )
        parts.append(
            f"{format_poles(flip, braces=True)} outside {_region(discrete)} is an invariant zero "
            f"of a plant within round-off of the data{how}, not certainly of this one"
        )
    if edge.size:
        parts.append(
            f"zero(s) {format_poles(edge, braces=True)} lie within round-off of the {where}"
        )
    return "cannot be decided at this precision: " + "; ".join(parts)


def _agreeing_modes(fixed: np.ndarray, zeros: np.ndarray, scale: float) -> bool:
    """True when the fixed modes are the invariant zeros (same count, matched values)."""
    if len(fixed) != len(zeros):
        return False
    if not len(fixed):
        return True
    cost = np.abs(fixed[:, None] - zeros[None, :])
    return bool(np.all(np.min(cost, axis=1) <= 1e-5 * max(1.0, scale)))


def detectability_conditions(
    plant: Plant,
    dec: Decoupling,
    zeros: np.ndarray,
    size: float,
    zero_cond: Condition | None = None,
) -> tuple[list[Condition], np.ndarray, int]:
    """Detectability and observability of the pair the designs use (rank condition holds).

    The fixed modes are the unobservable modes of the balanced pair; in exact
    arithmetic they are the invariant zeros. When the two computations do not
    agree, the verdict hangs on round-off and the reasons say so.

    Returns
    -------
    (list of Condition, numpy.ndarray, int)
        The two conditions, the fixed modes and the number of movable poles.
    """
    discrete, region, pair = plant.is_discrete, _region(plant.is_discrete), _pair_name(plant)
    fixed, movable = dec.pair.fixed_modes, dec.pair.movable
    unstable = fixed[~is_stable(fixed, discrete)]
    margin = dec.pair.split.margin
    note = boundary_note(fixed, discrete, size) + _margin_note(
        margin, "a singular value of the observability staircase"
    )
    if not _agreeing_modes(fixed, zeros, dec.pair.sigma):
        # in exact arithmetic the fixed modes are the invariant zeros; the zeros are computed
        # with every decision checked (uio_teach.linalg.checked_zeros), the staircase is not
        found = format_poles(fixed, braces=True, empty="none")
        if zero_cond is None:
            zero_cond = zero_condition(zeros, discrete, size)
        listed_zeros = format_poles(zeros, braces=True, empty="none")
        why = (
            f"the fixed modes are the invariant zeros {listed_zeros}"
            f" (the observability staircase of {pair} finds {found}: its rank decisions do not "
            "resolve them)"
        )
        det = Condition(
            f"detectable {pair}",
            zero_cond.holds,
            why,
            margin=min(margin, 1.0),
            undecided=zero_cond.undecided,
        )
        obs = Condition(f"observable {pair}", not len(zeros), why, required=False, margin=1.0)
        return [det, obs], zeros, plant.n - len(zeros)
    listed = format_poles(fixed if not len(unstable) else unstable, braces=True, empty="none")
    if not len(unstable):
        reason = (
            f"unobservable modes {listed} lie in {region}"
            if len(fixed)
            else "observable, hence detectable"
        )
        det = Condition(f"detectable {pair}", True, reason + note, margin=margin)
    else:
        det = Condition(
            f"detectable {pair}",
            False,
            f"unobservable mode(s) {listed} outside {region}" + note,
            margin=margin,
        )
    if len(fixed):
        all_fixed = format_poles(fixed, braces=True, empty="none")
        reason = (
            f"{movable} of {plant.n} poles can be placed; {all_fixed} are fixed "
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
    ``||E|| ||C|| / sigma_min(C E)`` (in balanced units). Above ``AMPLIFICATION_LIMIT`` the UIO
    exists but is ill-conditioned: its matrices hold their identities only to that many
    rounding errors, and a design's check says how much the result leaks.

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
    ok = bool(amp <= AMPLIFICATION_LIMIT)
    if ok:
        reason = f"any UIO amplifies round-off by about {amp:.2g} at most"
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
    5. **E full column rank** (information): the unknown input can be
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
    sigma = scaling.sigma
    size = sigma * (float(np.linalg.norm(bal.A, 2)) if plant.n else 0.0)
    rank_cond, rE = rank_condition(bal)
    conds = [rank_cond]
    Bz = np.hstack([bal.E, np.zeros((plant.n, plant.nv))])
    Dz = np.hstack([np.zeros((plant.p, plant.q)), bal.D])
    zs = checked_zeros(bal.A, Bz, bal.C, Dz)
    zeros = sort_poles(zs.zeros * sigma)
    conds.append(
        zero_condition(zeros, discrete, size, zs.doubtful * sigma, zs.residuals, zs.radius * sigma)
    )
    fixed = np.zeros(0, complex)
    movable = 0
    if rank_cond.holds:
        more, fixed, movable = detectability_conditions(
            plant, decoupling(plant, scaling=scaling, zeros=zeros), zeros, size, conds[-1]
        )
        det = more[0]
        if conds[-1].undecided and not det.undecided:
            # in exact arithmetic the fixed modes are the invariant zeros: detectability is no
            # more certain than the zeros' stability
            more[0] = Condition(
                det.name,
                None,
                "cannot be decided at this precision: it is the stability of the invariant "
                f"zeros, which round-off decides ({det.reason})",
                margin=det.margin,
                undecided=True,
            )
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
    )
