"""The plain (Luenberger) observer, which ignores the unknown inputs."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import as_matrix, read_only
from ..errors import InputError
from ..linalg import observability_decomposition
from ..placement import place_observer_poles, requested_poles
from ..plant import Plant, check_plant
from ..verify import check_poles
from .base import Observer, ObserverRealization

__all__ = ["LuenbergerObserver", "design_luenberger"]


class LuenbergerObserver(Observer):
    """Plain (Luenberger) observer ``xhat' = A xhat + B u + L (y - C xhat)``.

    It ignores the unknown inputs, so its error is driven by them:
    ``e' = (A - L C) e + E d - L D v``. Built by :func:`design_luenberger`.

    Examples
    --------
    >>> import uio_teach as ut
    >>> ut.design_luenberger(ut.examples.pa9(), poles=[-1, -2, -3]).decouples
    False
    """

    family = "Luenberger observer"
    _display_names = ("L", "F")
    _designer = "design_luenberger(plant, poles=...) or design_luenberger(plant, L=...)"

    def __init__(self, plant: Plant, L: np.ndarray) -> None:
        super().__init__(plant)
        self._L = read_only(L)
        self._F = read_only(plant.A - L @ plant.C)

    @property
    def L(self) -> np.ndarray:
        """The output-injection gain."""
        return self._L

    @property
    def F(self) -> np.ndarray:
        """The error dynamics ``A - L C`` (without unknown inputs)."""
        return self._F

    @property
    def decouples(self) -> bool:
        return self.plant.q == 0 and self.plant.nv == 0

    @property
    def error_matrix(self) -> np.ndarray:
        return self.F

    def realization(self) -> ObserverRealization:
        pl = self.plant
        return ObserverRealization(
            A=self.F, B_u=pl.B, B_y=self.L, C=np.eye(pl.n), D_y=np.zeros((pl.n, pl.p))
        )


def design_luenberger(plant: Plant, poles: Any = None, *, L: Any = None) -> LuenbergerObserver:
    """Design a plain Luenberger observer, which ignores the unknown inputs.

    Parameters
    ----------
    plant : Plant
        Continuous or discrete plant.
    poles : array_like, optional
        Poles of ``A - L C`` (of its observable part).
    L : array_like, shape (n, p), optional
        An explicit gain instead of ``poles``.

    Returns
    -------
    LuenbergerObserver

    Raises
    ------
    ValueError
        Neither or both of ``poles`` and ``L`` given, a wrong number of poles,
        or ``L`` of the wrong shape.
    PlacementAccuracyError
        A ``ValueError``: the poles of ``A - L C`` obtained differ from those
        requested beyond the tolerance.

    Warns
    -----
    UnstableObserverWarning
        If the chosen poles or ``L`` leave the error dynamics unstable.
    PlacementAccuracyWarning
        The poles obtained are slightly off, more than round-off allows.

    Examples
    --------
    >>> import uio_teach as ut
    >>> obs = ut.design_luenberger(ut.examples.pa9(), poles=[-1, -2, -3])
    >>> obs.decouples
    False
    """
    plant = check_plant(plant)
    if (poles is None) == (L is None):
        raise InputError("give exactly one of poles= or L=")
    requested = None
    if L is None:
        split = observability_decomposition(plant.A, plant.C)
        L = place_observer_poles(plant.A, plant.C, poles, split=split, verify=False)
        requested = requested_poles(poles, split.unobservable_modes, split.Ao.shape[0])
    else:
        L = as_matrix("L", L, plant.n, plant.p, what="n x p")
    obs = LuenbergerObserver(plant, L)
    if requested is not None:
        check_poles(obs.F, requested, what="the Luenberger observer", stacklevel=3)
    obs.warn_if_unstable()
    return obs
