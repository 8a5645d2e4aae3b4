"""The Luenberger observer set beside an unknown input observer: which poles it gets.

A plain observer ``xhat' = A xhat + B u + L (y - C xhat)`` compared with an
unknown input observer should differ from it in one thing only, the
decoupling. :func:`luenberger_poles` therefore gives it the same error poles
as the unknown input observer -- the poles you set *and* the fixed poles (the
invariant zeros) -- with these rules: modes that no gain moves in the
Luenberger observer (unobservable modes of ``(A, C)``) are taken out of the
list; if the list is then longer than the number of poles ``(A, C)`` lets us
place, the fastest poles are dropped; if it is shorter (the g-inverse observer
has only ``n - rank(C)`` poles), extra real poles are added, faster than the
fastest one (1.5, 2, 2.5, ... times its real part in continuous time; half, a
quarter, ... of the smallest radius in discrete time). Repeated poles stay
repeated: the placement takes any multiplicity.

Examples
--------
>>> import uio_teach as ut
>>> from uio_teach.luenberger import luenberger_poles
>>> plant = ut.examples.pa9()
>>> luenberger_poles(plant, [-1, -2, -3]).real.round(6).tolist()
[-3.0, -2.0, -1.0]
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from . import tolerances as tols
from .linalg import observability_decomposition, sort_poles
from .plant import Plant

__all__ = ["luenberger_poles"]


def luenberger_poles(plant: Plant, observer_poles: Sequence[complex]) -> np.ndarray:
    """The poles given to the Luenberger observer compared with an unknown input observer.

    The rule (see :mod:`uio_teach.luenberger`): start from the unknown input
    observer's error poles, movable and fixed; take out the modes that stay fixed in the
    Luenberger observer (unobservable for ``(A, C)``); drop the fastest poles
    if there are too many, add faster real poles if there are too few.

    Parameters
    ----------
    plant : Plant
        The plant.
    observer_poles : sequence of complex
        The unknown input observer's error poles (conjugate pairs complete).

    Returns
    -------
    numpy.ndarray of complex
        As many poles as the observable part of ``(A, C)`` has, for
        :func:`uio_teach.design_luenberger`.

    Examples
    --------
    The missile's g-inverse observer has two poles; the Luenberger observer
    needs four:

    >>> import uio_teach as ut
    >>> from uio_teach.luenberger import luenberger_poles
    >>> plant = ut.examples.missile_autopilot()
    >>> g = ut.design_ginverse(plant)
    >>> luenberger_poles(plant, g.poles()).round(1).tolist()
    [(-211.2+0j), (-158.4+0j), (-105.6-142.1j), (-105.6+142.1j)]
    """
    discrete = plant.is_discrete
    split = observability_decomposition(plant.A, plant.C)
    n_place = split.Ao.shape[0]
    target = [complex(p) for p in sort_poles(np.asarray(observer_poles, complex)) if np.isfinite(p)]
    for f in split.unobservable_modes:
        if target:
            dist = [abs(p - f) for p in target]
            i = int(np.argmin(dist))
            if dist[i] <= tols.FIXED_POLE_RTOL * max(1.0, abs(f)):
                target.pop(i)

    def speed(p: complex) -> float:
        return -abs(p) if discrete else p.real

    while len(target) > n_place:
        fastest = min(target, key=speed)
        target.remove(fastest)
        if fastest.imag != 0:
            partner = min(target, key=lambda q: abs(q - fastest.conjugate()))
            target.remove(partner)
    if discrete:
        base = min((abs(p) for p in target), default=0.5)
    else:
        base = min((p.real for p in target), default=-1.0)
        base = base if base < 0 else -1.0
    k = 1
    while len(target) < n_place:
        if discrete:
            extra = base * 0.5**k if base > 0 else 0.05 * k
        else:
            extra = base * (1 + 0.5 * k)
        target.append(complex(extra, 0.0))
        k += 1
    return sort_poles(np.array(target, dtype=complex))
