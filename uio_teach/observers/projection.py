"""The projection family: what the decoupling UIO and the PMO share, and their checks.

Both observers are ``xhat = z + H y`` with ``H [CE D] = [E 0]``,
``T = I - H C`` and ``F = T A - K1 C``; they differ in how they are written
and designed (:mod:`uio_teach.observers.uio`, :mod:`uio_teach.observers.pmo`).
Every design is verified on the data as given before it is returned
(:func:`verify_projection`).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from .. import tolerances as tols
from .._validation import as_matrix, read_only
from ..errors import InputError, UIOTeachError
from ..existence import ExistenceReport, UIOExistenceError, check_existence
from ..linalg import pinv
from ..placement import schur_coordinates
from ..plant import Plant
from ..verify import (
    DecouplingError,
    DecouplingLeak,
    check_decoupling,
    check_fixed_modes,
    check_identity,
    product_bound,
)
from .base import Observer, ObserverRealization

__all__ = [
    "ProjectionObserver",
    "verify_projection",
    "decoupled_gain",
    "require_existence",
]


class ProjectionObserver(Observer):
    """Shared algebra of the decoupling UIO and the PMO (they are the same observer).

    Not built directly: :func:`~uio_teach.design_uio` and :func:`~uio_teach.design_pmo`.

    ``xhat = z + H y`` with ``H E``-decoupling, ``T = I - H C``,
    ``F = T A - K1 C``, ``K = K1 + F H`` and ``z' = F z + T B u + K y``.
    """

    def __init__(self, plant: Plant, H: np.ndarray, K1: np.ndarray) -> None:
        super().__init__(plant)
        n = plant.n
        self._H = read_only(H)
        self._T = read_only(np.eye(n) - H @ plant.C)
        self._K1 = read_only(K1)
        self._F = read_only(self._T @ plant.A - K1 @ plant.C)
        self._K2 = read_only(self._F @ H)
        self._leak: DecouplingLeak | None = None

    @property
    def error_matrix(self) -> np.ndarray:
        return self._F

    @property
    def leak(self) -> DecouplingLeak | None:
        """How much of the unknown input can reach the estimation error, judged on the returned
        matrices (``uio_teach.verify.decoupling_leak``); set by the design."""
        return self._leak

    def realization(self) -> ObserverRealization:
        pl = self.plant
        return ObserverRealization(
            A=self._F,
            B_u=self._T @ pl.B,
            B_y=self._K1 + self._K2,
            C=np.eye(pl.n),
            D_y=self._H,
        )


def verify_projection(obs: ProjectionObserver, what: str, fixed: np.ndarray | None = None) -> None:
    """Verify a UIO/PMO on the data as given; raise ``PlacementAccuracyError`` if it fails.

    The identities ``H C E = E``, ``T E = 0``, ``H D = 0``, ``L D = 0``, each
    judged entry by entry against the size of its own terms
    (:func:`uio_teach.verify.product_bound`, the same verdict in any units),
    and, given ``fixed``, that every fixed mode is an eigenvalue of ``F``.
    """
    pl = obs.plant
    H, T, K1 = obs._H, obs._T, obs._K1
    # each identity against the entrywise size of its terms: the same verdict in any units
    if pl.q:
        HCE = product_bound((H, np.abs(pl.C) @ np.abs(pl.E)), pl.E)
        check_identity("H C E = E", H @ pl.C @ pl.E - pl.E, HCE, what=what)
        check_identity("T E = 0", T @ pl.E, HCE, what=what)
    if pl.nv:
        check_identity("H D = 0", H @ pl.D, product_bound((H, pl.D)), what=what)
        check_identity("L D = 0", K1 @ pl.D, product_bound((K1, pl.D)), what=what)
    # the fixed modes (the invariant zeros, decided in balanced units) must be error poles:
    # an error matrix without them does not decouple, whatever the identities say
    if fixed is not None:
        check_fixed_modes(obs.poles(), fixed, what=what)
    # from first principles, on the matrices returned: the unknown input's path to the error
    H, K = obs._H, obs._K1 + obs._K2
    nH, nC, nK = (float(np.linalg.norm(X, 2)) for X in (H, pl.C, obs._K1))
    nA = float(np.linalg.norm(pl.A, 2))
    if nH * nC > tols.AMPLIFICATION_LIMIT:
        cause = f"||H|| ||C|| = {nH * nC:.2g}: a C E small next to E makes H large"
    elif nK * nC > tols.AMPLIFICATION_LIMIT * max(nA, 1e-300):
        cause = (
            f"||K1|| ||C|| = {nK * nC:.2g} against ||A|| = {nA:.2g}: the placement needs a "
            "large gain (many states per output, poles close together or far from the plant's)"
        )
    else:
        cause = ""
    obs._leak = check_decoupling(
        pl.A,
        pl.E,
        pl.C,
        obs._F,
        K,
        np.eye(pl.n),
        H,
        discrete=pl.is_discrete,
        what=what,
        cause=cause,
        stacklevel=4,
    )


def verified_design(
    obs: ProjectionObserver,
    what: str,
    fixed: np.ndarray | None,
    again: Callable[[], ProjectionObserver] | None,
) -> ProjectionObserver:
    """``obs`` verified (:func:`verify_projection`); if it is refused as leaking and its gain was
    placed, the design placed again in Schur coordinates (``again``), if that one verifies.

    A multi-output placement's gain is not unique, and which one scipy's iterations reach depends
    on the order of the states: in a badly scaled plant one order gives a realization that
    amplifies round-off a hundred billion times, another a clean one
    (:func:`uio_teach.placement.schur_coordinates`). A design is refused only when the gain
    placed in Schur coordinates, the same in any state order, is refused too; the error then is
    the first one.
    """
    try:
        verify_projection(obs, what, fixed)
        return obs
    except DecouplingError as first:
        if again is None:
            raise
        refusal = first
    with schur_coordinates():
        try:
            other = again()
            verify_projection(other, what, fixed)
        except UIOTeachError:
            raise refusal from None
    return other


def _entries(M: np.ndarray) -> str:
    """The entries of a small matrix with 3 significant digits (a tiny non-zero shows as one)."""
    rows = np.atleast_2d(M)
    return "[" + "; ".join(", ".join(f"{x:.3g}" for x in row) for row in rows) + "]"


def decoupled_gain(name: str, plant: Plant, gain: Any) -> np.ndarray:
    """Check an explicit gain (shape n x p, ``gain D = 0``).

    A gain that meets ``gain D = 0`` only to printed precision (copied from a
    document, rounded to 4 decimals) is projected onto it, with a warning.
    """
    G = as_matrix(name, gain, plant.n, plant.p, what="n x p")
    if not plant.nv:
        return G
    scale = float(np.abs(G).max()) if G.size else 0.0  # the gain's own size, in any units
    GD = G @ plant.D
    residual = float(np.abs(GD).max())
    if residual <= tols.GAIN_EXACT_RTOL * scale:
        return G
    if residual <= tols.GAIN_ROUNDED_RTOL * scale:
        warnings.warn(
            f"{name} D = {_entries(GD)} is not exactly 0 (a rounded "
            f"gain?); using the nearest gain with {name} D = 0",
            UserWarning,
            stacklevel=3,
        )
        return G - GD @ pinv(plant.D)
    raise InputError(
        f"{name} D must be 0 so that the measurement disturbance does not enter the "
        f"error; got {name} D = {_entries(GD)}"
    )


def require_existence(plant: Plant, what: str) -> ExistenceReport:
    """The existence report of ``plant``; raise ``UIOExistenceError`` when no UIO exists."""
    report = check_existence(plant)
    if not report.ok:
        raise UIOExistenceError(report, what)
    return report
