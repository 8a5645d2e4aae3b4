"""The reduced-order unknown input observer (Hou & Müller 1992): ``n - rank C`` states.

The measured outputs already give ``rank C`` combinations of the state; the reduced-order
observer estimates only the rest. In coordinates ``x = R y~ + V2 eta`` (``y~ = W y`` the
outputs free of the measurement disturbance, ``C~ = W C`` of full row rank, ``V2`` an
orthonormal basis of the null space of ``C~``), ``eta = P x`` with ``P = V2^T - Gamma C~`` and
``Gamma = V2^T E (C~ E)^+`` obeys an equation the unknown input does not enter (``P E = 0``,
which the rank condition makes possible). The part of ``y~'`` that ``d`` does not reach,
``Pi y~'`` (``Pi C~ E = 0``), measures ``Pi C~ A V2 eta``; an injection gain ``K1`` on it places
the poles, and the observer state ``w = eta_hat - K1 Pi y~`` needs no derivative of ``y``::

    w' = F w + G u + K y,        xhat = P_o w + Q y

with ``F = (P - K1 Pi C~) A V2``. The error ``eps = (P - K1 Pi C~) x - w`` obeys
``eps' = F eps`` whatever ``d`` is, and ``x - xhat = V2 eps``. The unobservable modes of the
pair ``(P A V2, Pi C~ A V2)`` are the plant's invariant zeros, as for the full-order UIO
(Darouach, Zasadzinski & Xu 1994): a reduced-order UIO exists exactly when a full-order one
does, with the same fixed modes.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .._validation import read_only
from ..existence import ExistenceReport
from ..linalg import (
    ObservabilitySplit,
    left_null,
    observability_decomposition,
    one_blas_thread,
    pinv,
    rank_decision,
)
from ..placement import place_observer_poles, requested_poles
from ..plant import Plant, check_plant
from ..verify import check_fixed_modes, check_identity, check_poles, product_bound
from .base import Observer, ObserverRealization
from .projection import require_existence

__all__ = ["ReducedUIO", "ReducedPair", "design_reduced_uio", "reduced_movable", "reduced_pair"]


class ReducedPair(NamedTuple):
    """The coordinates and the pair of the reduced-order design (:func:`reduced_pair`).

    ``W`` (``rank C~ x p``) keeps the outputs free of the measurement disturbance,
    ``Ct = W C`` (full row rank), ``V2`` spans its null space (``n x r``, orthonormal), ``R``
    is ``Ct^+ + V2 Gamma`` (``x = R y~ + V2 eta``), ``P = V2^T - Gamma Ct`` (``P E = 0``),
    ``Pi`` annihilates ``Ct E`` (orthonormal rows) and the pair is ``(A22, C2)`` with
    ``A22 = P A V2``, ``C2 = Pi Ct A V2``.
    """

    W: np.ndarray
    Ct: np.ndarray
    V2: np.ndarray
    R: np.ndarray
    P: np.ndarray
    Pi: np.ndarray
    A22: np.ndarray
    C2: np.ndarray
    split: ObservabilitySplit


def reduced_pair(plant: Plant) -> ReducedPair:
    """The pair whose output injection places the reduced-order UIO's poles.

    Computed whether or not a UIO exists (for teaching and tests: its unobservable
    modes are the invariant zeros, stable or not). When the rank condition fails, ``P E``
    is not zero and no choice of the gain decouples; :func:`design_reduced_uio` refuses
    such a plant before it gets here.

    Parameters
    ----------
    plant : Plant

    Returns
    -------
    ReducedPair

    Examples
    --------
    >>> import uio_teach as ut
    >>> rp = reduced_pair(ut.examples.pa9())
    >>> rp.A22.shape, rp.C2.shape
    ((1, 1), (1, 1))
    """
    plant = check_plant(plant)
    A, C, E = plant.A, plant.C, plant.E
    N = left_null(plant.D)  # outputs free of the measurement disturbance
    Cn = N @ C
    U, s, Vt = np.linalg.svd(Cn, full_matrices=True)
    rC = rank_decision(Cn).rank
    W = U[:, :rC].T @ N
    Ct = W @ C
    V2 = Vt[rC:].T.copy()
    CE = Ct @ E
    scale = float(np.linalg.norm(Ct, 2) * np.linalg.norm(E, 2)) if E.size else 0.0
    rCE = rank_decision(CE, scale=scale).rank if E.size else 0
    Gamma = V2.T @ E @ pinv(CE) if E.size else np.zeros((V2.shape[1], rC))
    P = V2.T - Gamma @ Ct
    R = pinv(Ct) + V2 @ Gamma
    if E.size:
        Uc, _, _ = np.linalg.svd(CE, full_matrices=True)
        Pi = Uc[:, rCE:].T.copy()
    else:
        Pi = np.eye(rC)
    A22 = P @ A @ V2
    C2 = Pi @ Ct @ A @ V2
    split = observability_decomposition(A22, C2)
    return ReducedPair(W, Ct, V2, R, P, Pi, A22, C2, split)


def reduced_movable(plant: Plant, report: ExistenceReport) -> int:
    """How many poles of the reduced-order UIO a gain places (0 when no UIO exists).

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.examples.missile_autopilot()
    >>> reduced_movable(plant, ut.check_existence(plant))
    0
    """
    return int(reduced_pair(plant).split.Ao.shape[0]) if report.ok else 0


class ReducedUIO(Observer):
    """Reduced-order unknown input observer: ``n - rank C`` states (Hou & Müller 1992).

    ``w' = F w + G u + K y``, ``xhat = P w + Q y``; the error obeys ``eps' = F eps``
    whatever the unknown input is, and ``x - xhat = P eps``. Built by
    :func:`design_reduced_uio`.

    Attributes
    ----------
    F : numpy.ndarray, shape (r, r)
        The observer's dynamics and its error dynamics, ``r = n - rank C``.
    G, K : numpy.ndarray
        The known-input and output gains of the observer state.
    P, Q : numpy.ndarray
        ``xhat = P w + Q y``; ``P`` (n x r) has orthonormal columns spanning the
        null space of ``C``.
    K1 : numpy.ndarray
        The injection gain that places the poles of ``F``.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> obs = ut.design_reduced_uio(ut.examples.pa9(), poles=[-4])
    >>> obs.order, obs.poles().real.round(6).tolist()
    (1, [-4.0])
    """

    family = "reduced-order UIO"
    _display_names = ("F", "G", "K", "P", "Q")
    _designer = "design_reduced_uio(plant, poles=...)"

    def __init__(self, plant: Plant, rp: ReducedPair, K1: np.ndarray) -> None:
        super().__init__(plant)
        A, B = plant.A, plant.B
        Kt = K1 @ rp.Pi  # gain on y~
        PK = rp.P - Kt @ rp.Ct
        F = PK @ A @ rp.V2
        self._K1 = read_only(K1)
        self._theta = read_only(PK)
        self._F = read_only(F)
        self._G = read_only(PK @ B)
        self._K = read_only((F @ Kt + PK @ A @ rp.R) @ rp.W)
        self._P = read_only(rp.V2)
        self._Q = read_only((rp.R + rp.V2 @ Kt) @ rp.W)

    @property
    def order(self) -> int:
        """The observer's number of states, ``n - rank C``."""
        return int(self._F.shape[0])

    @property
    def F(self) -> np.ndarray:
        """The error dynamics ``eps' = F eps`` (``F = (P - K1 Pi C) A V2``)."""
        return self._F

    @property
    def G(self) -> np.ndarray:
        """The known input's gain, ``(P - K1 Pi C) B``."""
        return self._G

    @property
    def K(self) -> np.ndarray:
        """The measurement's gain on the observer state."""
        return self._K

    @property
    def P(self) -> np.ndarray:
        """The observer state's map into the state estimate (n x r), ``xhat = P w + Q y``."""
        return self._P

    @property
    def Q(self) -> np.ndarray:
        """The measurement's direct part of the estimate, ``xhat = P w + Q y``."""
        return self._Q

    @property
    def K1(self) -> np.ndarray:
        """The injection gain placing the poles of the pair ``(P A V2, Pi C A V2)``."""
        return self._K1

    @property
    def theta(self) -> np.ndarray:
        """What the observer state estimates, ``w -> theta x`` (``theta E = 0``)."""
        return self._theta

    @property
    def error_matrix(self) -> np.ndarray:
        """The error dynamics ``F`` (``eps' = F eps`` for ``eps = theta x - w``).

        The estimation error is ``x - xhat = P eps``.
        """
        return self._F

    def realization(self) -> ObserverRealization:
        return ObserverRealization(A=self._F, B_u=self._G, B_y=self._K, C=self._P, D_y=self._Q)

    def _title(self) -> str:
        return super()._title().replace(" for ", f" of order {self.order} for ", 1)


def _verify(obs: ReducedUIO, report: ExistenceReport) -> None:
    """The identities that make the error independent of ``d``, on the returned matrices.

    ``theta E = 0``, ``theta A - F theta - K C = 0`` (``K D = 0``, ``Q D = 0`` with a
    measurement disturbance) and ``I - Q C - P theta = 0``; and the fixed modes among the poles.
    """
    pl, what = obs.plant, "the reduced-order UIO"
    th, F, K, P, Q = obs._theta, obs._F, obs._K, obs._P, obs._Q
    if pl.q:
        check_identity("theta E = 0", th @ pl.E, product_bound((th, pl.E)), what=what)
    check_identity(
        "theta A = F theta + K C",
        th @ pl.A - F @ th - K @ pl.C,
        product_bound((th, pl.A), (F, th), (K, pl.C)),
        what=what,
    )
    check_identity(
        "Q C + P theta = I",
        Q @ pl.C + P @ th - np.eye(pl.n),
        product_bound((Q, pl.C), (P, th), np.eye(pl.n)),
        what=what,
    )
    if pl.nv:
        check_identity("K D = 0", K @ pl.D, product_bound((K, pl.D)), what=what)
        check_identity("Q D = 0", Q @ pl.D, product_bound((Q, pl.D)), what=what)
    check_fixed_modes(obs.poles(), report.fixed_modes, what=what)


@one_blas_thread()
def design_reduced_uio(plant: Plant, poles: Any) -> ReducedUIO:
    """Design the reduced-order unknown input observer (Hou & Müller 1992).

    It has ``n - rank C`` states (``rank`` of the outputs free of the measurement
    disturbance when ``D`` is present) instead of ``n``: the measured combinations of the
    state are taken from ``y`` itself. It exists exactly when the full-order UIO does
    (:func:`check_existence`), and its fixed modes are the same invariant zeros.

    Parameters
    ----------
    plant : Plant
        Continuous or discrete plant.
    poles : array_like
        The movable error poles: ``n - rank C`` minus the number of invariant zeros
        (a list of all ``n - rank C`` poles with the zeros among them is accepted too).

    Returns
    -------
    ReducedUIO

    Raises
    ------
    UIOExistenceError
        No UIO exists (the rank condition fails, or an invariant zero is outside the
        stability region); the message names the condition.
    ValueError
        A wrong number of poles (the message says how many can be placed), unpaired
        complex poles, non-finite values.
    PlacementAccuracyError
        The computed design fails its own check (poles, ``theta E = 0`` and the other
        identities, the fixed modes).

    Warns
    -----
    UnstableObserverWarning
        The requested poles leave the error dynamics unstable.

    Examples
    --------
    >>> import uio_teach as ut
    >>> missile = ut.examples.missile_autopilot()
    >>> obs = ut.design_reduced_uio(missile, poles=[])  # both of its poles are fixed
    >>> obs.order, obs.poles().round(1).tolist()
    (2, [(-105.6-142.1j), (-105.6+142.1j)])
    """
    plant = check_plant(plant)
    report = require_existence(plant, "a reduced-order unknown input observer")
    rp = reduced_pair(plant)
    split = rp.split
    movable = split.Ao.shape[0]
    K1 = place_observer_poles(
        rp.A22, rp.C2, poles, split=split, fixed_name="invariant zeros", verify=False
    )
    obs = ReducedUIO(plant, rp, K1)
    _verify(obs, report)
    req = requested_poles(
        np.atleast_1d(np.asarray(poles, complex)), split.unobservable_modes, movable
    )
    check_poles(
        obs.F,
        req,
        what="the reduced-order UIO",
        stacklevel=3,
        zeros=report.invariant_zeros,
        radius=report.zero_radius,
    )
    obs.warn_if_unstable()
    return obs
