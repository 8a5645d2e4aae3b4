"""The projection-operator full-order observer (PMO) of the missile paper and the case study."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import as_matrix, read_only
from ..errors import InputError
from ..existence import decoupling
from ..linalg import one_blas_thread
from ..lmi import lmi_gain
from ..placement import place_pair_poles
from ..plant import Plant, check_plant
from ..verify import check_poles
from .projection import (
    ProjectionObserver,
    decoupled_gain,
    require_existence,
    verified_design,
)

__all__ = ["PMO", "design_pmo"]


class PMO(ProjectionObserver):
    """Projection-operator full-order observer (Hui and Żak; case study; missile paper).

    ``z' = F z + G y + (I - MC) B u``, ``xhat = z + M y`` with
    ``A1 = (I - MC) A``, ``F = A1 - L C`` and ``G = (I - MC) A M + L - L C M``
    (eq. (13) of the missile paper). Built by :func:`design_pmo`.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> pmo = ut.design_pmo(ut.examples.missile_autopilot(), poles=[-100, -120])
    >>> bool(np.allclose(pmo.projection @ pmo.plant.E, 0))
    True
    """

    family = "PMO"
    _display_names = ("M", "A1", "L", "F", "G")
    _designer = "design_pmo(plant, poles=...) or design_pmo(plant, L=...)"

    def __init__(
        self,
        plant: Plant,
        M: np.ndarray,
        L: np.ndarray,
        Mv: np.ndarray | None,
        certificate: np.ndarray | None,
    ) -> None:
        super().__init__(plant, M, L)
        self._Mv = None if Mv is None else read_only(Mv)
        self._certificate = None if certificate is None else read_only(certificate)

    @property
    def Mv(self) -> np.ndarray | None:
        """The free matrix of eq. (19) used, or None."""
        return self._Mv

    @property
    def lmi_certificate(self) -> np.ndarray | None:
        """The Lyapunov matrix ``P`` of :func:`lmi_gain` (``method="lmi"``), or None."""
        return self._certificate

    @property
    def M(self) -> np.ndarray:
        """The matrix ``M = E (CE)^g + Mv (I - CE (CE)^g)`` (with ``D``, ``M = [E 0][CE D]^+``)."""
        return self._H

    @property
    def projection(self) -> np.ndarray:
        """The oblique projection ``I - M C``, which annihilates ``E``."""
        return self._T

    @property
    def A1(self) -> np.ndarray:
        """``(I - M C) A``."""
        return read_only(self._T @ self.plant.A)

    @property
    def L(self) -> np.ndarray:
        """Output-injection gain."""
        return self._K1

    @property
    def F(self) -> np.ndarray:
        """The error dynamics ``F = A1 - L C``."""
        return self._F

    @property
    def G(self) -> np.ndarray:
        """The measurement gain ``G = (I - MC) A M + L - L C M`` of eq. (13)."""
        return read_only(self._K1 + self._K2)


@one_blas_thread()
def design_pmo(
    plant: Plant,
    poles: Any = None,
    *,
    L: Any = None,
    method: str = "place",
    Mv: Any = None,
    decay: float | None = None,
) -> PMO:
    """Design the projection-operator full-order observer (PMO).

    ``M = E (CE)^g + Mv (I - CE (CE)^g)`` (eq. (19) of the missile paper;
    with ``D``: ``M = [E 0][CE D]^+`` as in the case study),
    ``A1 = (I - MC) A`` and the gain ``L`` of the error dynamics
    ``e' = (A1 - L C) e``.

    Parameters
    ----------
    plant : Plant
        Continuous or discrete plant.
    poles : array_like, optional
        Movable error poles, as in :func:`design_uio` (``method="place"``).
    L : array_like, shape (n, p), optional
        An explicit gain.
    method : {"place", "lmi"}
        ``"place"``: place ``poles``; ``"lmi"``: take ``L`` from
        :func:`lmi_gain` (as in the case study), with ``decay`` as its bound.
    Mv : array_like, shape (n, p), optional
        The free matrix of eq. (19); it has no effect when ``CE`` is square
        and invertible (the missile example).
    decay : float, optional
        With ``method="lmi"``: the LMI's decay bound (see :func:`lmi_gain`).

    Returns
    -------
    PMO

    Raises
    ------
    UIOExistenceError
        A condition of :func:`check_existence` fails.
    LMIInfeasibleError
        ``method="lmi"`` and the LMI has no solution.
    LMISolverError
        ``method="lmi"`` and the solver failed (see :func:`lmi_gain`).
    ValueError
        Inconsistent arguments, wrong pole count or shapes.
    PlacementAccuracyError
        A ``ValueError``: the computed design fails its own check. The poles
        obtained differ from those requested beyond the tolerance, a fixed mode
        is not an error pole, a decoupling identity (``H C E = E``,
        ``T E = 0``; with ``D`` also ``H D = 0``, ``L D = 0``) holds only to
        more than round-off, or the returned matrices let the unknown input
        reach the error (``uio_teach.verify.DecouplingError``).

    Warns
    -----
    UnstableObserverWarning
        If the error dynamics are unstable.
    PlacementAccuracyWarning
        The poles obtained are slightly off, more than round-off allows.
    DecouplingWarning
        ``uio_teach.verify.DecouplingWarning``: the design decouples only to a
        stated fraction, because it amplifies round-off (a small ``C E``).

    Examples
    --------
    >>> import uio_teach as ut
    >>> pmo = ut.design_pmo(ut.examples.dt_case_study(), method="lmi")
    >>> pmo.L.round(4)
    array([[ 0.1667, -0.8333],
           [ 0.2833, -1.4167],
           [ 0.2667, -1.3333]])
    >>> pmo.poles().real.round(4).tolist()
    [0.0, 0.5, 0.5]
    """
    plant = check_plant(plant)
    if method not in ("place", "lmi"):
        raise InputError(f"method must be 'place' or 'lmi', got {method!r}")
    if method == "lmi" and (poles is not None or L is not None):
        raise InputError("method='lmi' computes L itself: do not give poles= or L=")
    if method == "place" and (poles is None) == (L is None):
        raise InputError("give exactly one of poles= or L= (or use method='lmi')")
    if decay is not None and method != "lmi":
        raise InputError("decay= is the LMI's bound: use it with method='lmi'")
    report = require_existence(plant, "a projection-operator observer")
    if Mv is not None:
        if plant.nv:
            raise InputError("Mv is not supported together with a measurement disturbance D")
        Mv = as_matrix("Mv", Mv, plant.n, plant.p, what="n x p")
    dec = decoupling(plant, Mv, zeros=report.invariant_zeros, radius=report.zero_radius)
    certificate = None
    if method == "lmi":
        res = lmi_gain(
            dec.A1,
            plant.C,
            D=plant.D if plant.nv else None,
            dt=plant.dt,
            decay=decay,
            fixed_modes=dec.pair.fixed_modes,
        )
        L, certificate = res.L, res.P
    requested = None
    if method == "lmi":
        pass
    elif L is None:
        L, requested = place_pair_poles(dec.pair, poles, given=(dec.A1, plant.C, dec.N))
    else:
        L = decoupled_gain("L", plant, L)
    obs = PMO(plant, dec.M, L, Mv, certificate)

    def again() -> PMO:
        gain, _ = place_pair_poles(dec.pair, poles, given=(dec.A1, plant.C, dec.N))
        return PMO(plant, dec.M, gain, Mv, certificate)

    obs = verified_design(
        obs, "the PMO", report.fixed_modes, again if requested is not None else None
    )
    if requested is not None:
        check_poles(
            obs.F,
            requested,
            what="the PMO",
            stacklevel=3,
            zeros=report.invariant_zeros,
            radius=report.zero_radius,
        )
    obs.refuse_if_unstable(requested)
    obs.warn_if_unstable()
    return obs
