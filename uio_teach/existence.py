"""When does an unknown input observer exist? The conditions, checked and explained."""

from __future__ import annotations

import html
import textwrap
from dataclasses import dataclass, field

import numpy as np

from ._display import format_poles
from .linalg import (
    MARGIN,
    ObservabilitySplit,
    invariant_zeros,
    is_stable,
    left_null,
    observability_decomposition,
    pinv,
    rank_decision,
)
from .plant import Plant

__all__ = ["Condition", "ExistenceReport", "UIOExistenceError", "check_existence"]


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
    rank threshold); below ``uio_teach.linalg.MARGIN`` the verdict hangs on round-off and
    the reason says so."""

    @property
    def marginal(self) -> bool:
        """True when the verdict sits within the numerical margin of the rank threshold."""
        return self.margin is not None and self.margin < MARGIN

    @property
    def symbol(self) -> str:
        """The verdict in one character; ✓, ✗, – (not evaluated) or ○ (info, not met)."""
        if not self.required and self.holds is False:
            return "○"
        return {True: "✓", False: "✗", None: "–"}[self.holds]


@dataclass(frozen=True)
class Decoupling:
    """The decoupling step shared by every projection-type design (internal).

    ``M = [E 0][CE D]^+ + Mv (I - [CE D][CE D]^+)``, ``A1 = (I - M C) A``,
    ``N`` annihilates ``D`` so that gains of the form ``L = L' N`` satisfy
    ``L D = 0``; ``split`` is the observability decomposition of ``(A1, N C)``.
    """

    M: np.ndarray
    A1: np.ndarray
    N: np.ndarray
    split: ObservabilitySplit


def decoupling(plant: Plant, Mv: np.ndarray | None = None) -> Decoupling:
    """Compute ``M``, ``A1`` and the observability split (rank condition assumed)."""
    n, p, r = plant.n, plant.p, plant.nv
    G = np.hstack([plant.C @ plant.E, plant.D])
    Eb = np.hstack([plant.E, np.zeros((n, r))])
    Gp = pinv(G)
    M = Eb @ Gp
    if Mv is not None:
        M = M + Mv @ (np.eye(p) - G @ Gp)
    A1 = (np.eye(n) - M @ plant.C) @ plant.A
    N = left_null(plant.D)
    split = observability_decomposition(A1, N @ plant.C)
    return Decoupling(M=M, A1=A1, N=N, split=split)


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
    def failed(self) -> tuple[Condition, ...]:
        """The required conditions that do not hold."""
        return tuple(c for c in self.conditions if c.required and c.holds is False)

    def __getitem__(self, name: str) -> Condition:
        for c in self.conditions:
            if c.name == name:
                return c
        raise KeyError(f"no condition named {name!r}; have {[c.name for c in self.conditions]}")

    def __str__(self) -> str:
        head = f"Existence of an unknown input observer for {self.plant!r}"
        if len(head) > 88:
            head = f"Existence of an unknown input observer for\n  {self.plant!r}"
        width = max(len(c.name) for c in self.conditions)
        lines = [head]
        indent = " " * (width + 6)
        for c in self.conditions:
            tag = "" if c.required else " (info)"
            text = f"  {c.symbol} {c.name.ljust(width)}  {c.reason}{tag}"
            # wrap long reasons under their column so the table fits a notebook page
            lines.extend(textwrap.wrap(text, 88, subsequent_indent=indent) or [text])
        verdict = "a UIO exists" if self.ok else "no UIO with stable error dynamics exists"
        lines.append(f"  => {verdict}")
        return "\n".join(lines)

    __repr__ = __str__

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td>{c.symbol}</td><td>{html.escape(c.name)}</td>"
            f"<td>{html.escape(c.reason)}{'' if c.required else ' <i>(info)</i>'}</td></tr>"
            for c in self.conditions
        )
        verdict = "a UIO exists" if self.ok else "no UIO with stable error dynamics exists"
        return (
            f"<div><b>Existence of an unknown input observer</b> for "
            f"{html.escape(repr(self.plant))}<table>"
            f"<tr><th></th><th>condition</th><th>why</th></tr>{rows}</table>"
            f"<b>&rArr; {verdict}</b></div>"
        )


class UIOExistenceError(ValueError):
    """No unknown input observer exists; ``.report`` says which condition failed."""

    def __init__(self, report: ExistenceReport, what: str = "an unknown input observer") -> None:
        self.report = report
        failed = report.failed
        reasons = "; ".join(f"{c.name}: {c.reason}" for c in failed)
        super().__init__(f"cannot design {what} for {report.plant!r}: {reasons}")


ZERO_MARGIN = 1e-6
"""A zero or fixed mode closer than this (relative to ``max(1, ||A||)``) to the stability
boundary is reported as marginal: round-off of the data could move it across."""


def _boundary_note(values: np.ndarray, discrete: bool, A: np.ndarray) -> str:
    """A note for values that sit within the numerical margin of the stability boundary."""
    if not len(values):
        return ""
    values = np.asarray(values, complex)
    dist = np.abs(np.abs(values) - 1.0) if discrete else np.abs(values.real)
    scale = max(1.0, float(np.linalg.norm(A, 2)))
    close = dist <= ZERO_MARGIN * scale
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
    if not isinstance(plant, Plant):
        raise ValueError(f"plant must be a uio_teach.Plant, got {type(plant).__name__}")
    discrete = plant.is_discrete
    region = "the open unit disk" if discrete else "the open left half-plane"
    C, E, D = plant.C, plant.E, plant.D
    # ranks decided relative to the factors (the tolerance policy of uio_teach.linalg)
    nC, nE, nD = (float(np.linalg.norm(X, 2)) if X.size else 0.0 for X in (C, E, D))
    dE, dD = rank_decision(E), rank_decision(D)
    dG = rank_decision(np.hstack([C @ E, D]), scale=max(nC * nE, nD))
    rE, rD, rG = dE.rank, dD.rank, dG.rank
    rank_margin = min(dE.margin, dD.margin, dG.margin)
    conds: list[Condition] = []

    if plant.nv:
        lhs, rhs = f"rank([CE D]) = {rG}", f"rank(E) + rank(D) = {rE} + {rD}"
    else:
        lhs, rhs = f"rank(CE) = {rG}", f"rank(E) = {rE}"
    rank_ok = rG == rE + rD
    if rank_ok:
        reason = f"{lhs} = {rhs.split(' = ')[0]}: the unknown inputs can be decoupled"
    else:
        reason = (
            f"{lhs} but {rhs}: part of the unknown input does not show in the outputs "
            "at once, so it cannot be cancelled"
        )
    if rank_margin < MARGIN:
        reason += (
            f" (within the numerical margin: a singular value is only {rank_margin:.3g} times "
            "the rank threshold, so round-off of the data could change this verdict)"
        )
    conds.append(Condition("rank condition", rank_ok, reason, margin=rank_margin))

    Bz = np.hstack([E, np.zeros((plant.n, plant.nv))])
    Dz = np.hstack([np.zeros((plant.p, plant.q)), D])
    zeros = invariant_zeros(plant.A, Bz, C, Dz)
    bad = zeros[~is_stable(zeros, discrete)]
    zero_note = _boundary_note(zeros, discrete, plant.A)
    if not len(zeros):
        conds.append(Condition("invariant zeros stable", True, "no invariant zeros"))
    elif not len(bad):
        conds.append(
            Condition(
                "invariant zeros stable",
                True,
                f"zeros {format_poles(zeros, braces=True, empty='none')} all lie in {region}"
                + zero_note,
            )
        )
    else:
        conds.append(
            Condition(
                "invariant zeros stable",
                False,
                f"invariant zero(s) {format_poles(bad, braces=True, empty='none')} outside "
                f"{region}: they are observer poles "
                "no gain can move, so the error would not decay" + zero_note,
            )
        )

    pair = _pair_name(plant)
    fixed = np.zeros(0, complex)
    movable = 0
    if rank_ok:
        dec = decoupling(plant)
        fixed = dec.split.unobservable_modes
        movable = dec.split.Ao.shape[0]
        unstable = fixed[~is_stable(fixed, discrete)]
        obs_margin = dec.split.margin
        note = _boundary_note(fixed, discrete, plant.A) + (
            f" (within the numerical margin: a singular value of the observability staircase "
            f"is only {obs_margin:.3g} times the rank threshold)"
            if obs_margin < MARGIN
            else ""
        )
        if not len(unstable):
            reason = (
                f"unobservable modes {format_poles(fixed, braces=True, empty='none')} "
                f"lie in {region}"
                if len(fixed)
                else "observable, hence detectable"
            )
            conds.append(Condition(f"detectable {pair}", True, reason + note, margin=obs_margin))
        else:
            conds.append(
                Condition(
                    f"detectable {pair}",
                    False,
                    f"unobservable mode(s) {format_poles(unstable, braces=True, empty='none')} "
                    f"outside {region}" + note,
                    margin=obs_margin,
                )
            )
        if len(fixed):
            reason = (
                f"{movable} of {plant.n} poles can be placed; "
                f"{format_poles(fixed, braces=True, empty='none')} are fixed "
                "(they are the invariant zeros)"
            )
        else:
            reason = f"all {plant.n} observer poles can be placed"
        conds.append(
            Condition(
                f"observable {pair}",
                not len(fixed),
                reason + note,
                required=False,
                margin=obs_margin,
            )
        )
    else:
        why = "not evaluated: the rank condition fails"
        conds.append(Condition(f"detectable {pair}", None, why))
        conds.append(Condition(f"observable {pair}", None, why, required=False))

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
