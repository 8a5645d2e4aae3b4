"""The decoupling unknown input observer of Practical Assignment 9 and its design."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import read_only
from ..errors import InputError
from ..existence import decoupling
from ..linalg import one_blas_thread
from ..placement import place_pair_poles
from ..plant import Plant, check_plant
from ..verify import check_poles
from .delayed import DelayedUIO, design_delayed_uio
from .projection import (
    ProjectionObserver,
    decoupled_gain,
    require_existence,
    verified_design,
)

__all__ = ["UIO", "design_uio"]


class UIO(ProjectionObserver):
    """Unknown-input decoupling observer of Practical Assignment 9.

    ``z' = F z + T B u + K y``, ``xhat = z + H y`` with ``H = E (CE)^+``,
    ``T = I - H C``, ``F = T A - K1 C``, ``K2 = F H``, ``K = K1 + K2``.
    Built by :func:`design_uio`.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> uio = ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3])
    >>> bool(np.allclose(uio.T @ uio.plant.E, 0))
    True
    """

    family = "UIO"
    _display_names = ("H", "T", "K1", "K2", "K", "F")
    _designer = "design_uio(plant, poles=...) or design_uio(plant, K1=...)"

    @property
    def H(self) -> np.ndarray:
        """``E (CE)^+`` (``[E 0][CE D]^+`` with a measurement disturbance)."""
        return self._H

    @property
    def T(self) -> np.ndarray:
        """``I - H C``."""
        return self._T

    @property
    def K1(self) -> np.ndarray:
        """Output-injection gain that places the poles of ``F``."""
        return self._K1

    @property
    def K2(self) -> np.ndarray:
        """``F H``."""
        return self._K2

    @property
    def K(self) -> np.ndarray:
        """``K1 + K2``."""
        return read_only(self._K1 + self._K2)

    @property
    def F(self) -> np.ndarray:
        """The error dynamics ``e' = F e``, with ``F = T A - K1 C``."""
        return self._F


@one_blas_thread()
def design_uio(
    plant: Plant, poles: Any = None, *, K1: Any = None, delay: int = 0
) -> UIO | DelayedUIO:
    """Design the unknown-input decoupling observer of Practical Assignment 9.

    ``H = E (CE)^+``, ``T = I - H C``, ``F = T A - K1 C``, ``K2 = F H``,
    ``K = K1 + K2``; the error obeys ``e' = F e`` whatever ``d`` is.
    With a measurement disturbance ``D``, ``H = [E 0][CE D]^+`` and ``K1 D = 0``.

    Parameters
    ----------
    plant : Plant
        Continuous or discrete plant.
    poles : array_like, optional
        The movable error poles: as many as the observable part of
        ``(TA, C)`` has (all ``n`` when the pair is observable). The other
        modes are fixed: they are the plant's invariant zeros (see
        :func:`check_existence`, ``fixed_modes``).
    K1 : array_like, shape (n, p), optional
        An explicit gain instead of ``poles`` (to reproduce a printed design).
    delay : int, optional
        ``L > 0``: a discrete-time UIO that estimates ``x[k]`` from the outputs up to
        ``y[k + L]``, for plants whose rank condition fails
        (:func:`~uio_teach.design_delayed_uio`, which it returns); 0, the default, is this UIO.

    Returns
    -------
    UIO
        (a :class:`~uio_teach.DelayedUIO` when ``delay > 0``)

    Raises
    ------
    UIOExistenceError
        A condition of :func:`check_existence` fails (rank condition, or an
        invariant zero outside the stability region).
    ValueError
        Neither or both of ``poles`` and ``K1`` given, a wrong number of
        poles, or ``K1`` of the wrong shape.
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
        If the chosen poles or ``K1`` leave the error dynamics unstable.
    PlacementAccuracyWarning
        The poles obtained are slightly off, more than round-off allows.
    DecouplingWarning
        ``uio_teach.verify.DecouplingWarning``: the design decouples only to a
        stated fraction, because it amplifies round-off (a small ``C E``).

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> obs.H.round(2)
    array([[0.94, 0.24],
           [0.  , 0.  ],
           [0.24, 0.06]])
    """
    if delay is not None and not (isinstance(delay, int | np.integer) and delay == 0):
        if K1 is not None:
            raise InputError("give poles= with delay= (a delayed UIO is designed by its poles)")
        return design_delayed_uio(plant, poles, delay)  # checks the delay and the plant
    plant = check_plant(plant)
    if (poles is None) == (K1 is None):
        raise InputError("give exactly one of poles= (the movable error poles) or K1=")
    report = require_existence(plant, "an unknown input observer")
    dec = decoupling(plant, zeros=report.invariant_zeros, radius=report.zero_radius)
    requested = None
    if K1 is None:
        K1, requested = place_pair_poles(dec.pair, poles, given=(dec.A1, plant.C, dec.N))
    else:
        K1 = decoupled_gain("K1", plant, K1)
    obs = UIO(plant, dec.M, K1)

    def again() -> UIO:
        gain, _ = place_pair_poles(dec.pair, poles, given=(dec.A1, plant.C, dec.N))
        return UIO(plant, dec.M, gain)

    obs = verified_design(
        obs, "the UIO", report.fixed_modes, again if requested is not None else None
    )
    if requested is not None:
        check_poles(
            obs.F,
            requested,
            what="the UIO",
            stacklevel=3,
            zeros=report.invariant_zeros,
            radius=report.zero_radius,
        )
    obs.refuse_if_unstable(requested)
    obs.warn_if_unstable()
    return obs
