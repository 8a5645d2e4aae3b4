"""The observer designs: decoupling UIO (PA9), projection operator (PMO), g-inverse, Luenberger.

Every observer is a linear system driven by the known input ``u`` and the
measurement ``y``::

    z' = A_o z + B_u u + B_y y,        xhat = C_o z + D_y y

(``z[k+1] = ...`` in discrete time). :meth:`Observer.realization` returns
these matrices, :meth:`Observer.as_statespace` the python-control system, and
:meth:`Observer.poles` the eigenvalues of the estimation-error dynamics
``e' = error_matrix @ e``.

The package is split by family: :mod:`.base` (the observer, its
realization), :mod:`.projection` (what the UIO and the PMO share),
:mod:`.uio`, :mod:`.pmo`, :mod:`.ginverse`, :mod:`.luenberger_observer`,
:mod:`.reduced` (the reduced-order UIO) and :mod:`.delayed` (the UIO that waits for
later samples).
Every name is importable from ``uio_teach.observers``.
"""

from __future__ import annotations

from .base import Observer, ObserverRealization, UnstableObserverWarning
from .delayed import (
    DelayedUIO,
    DelayedUIOExistenceError,
    DelayVerdict,
    delay_verdict,
    design_delayed_uio,
)
from .ginverse import GInverseObserver, design_ginverse
from .luenberger_observer import LuenbergerObserver, design_luenberger
from .pmo import PMO, design_pmo
from .projection import ProjectionObserver
from .reduced import ReducedUIO, design_reduced_uio
from .uio import UIO, design_uio

__all__ = [
    "Observer",
    "ObserverRealization",
    "UnstableObserverWarning",
    "ProjectionObserver",
    "UIO",
    "PMO",
    "GInverseObserver",
    "LuenbergerObserver",
    "design_uio",
    "design_pmo",
    "design_ginverse",
    "design_luenberger",
    "ReducedUIO",
    "design_reduced_uio",
    "DelayedUIO",
    "DelayVerdict",
    "DelayedUIOExistenceError",
    "delay_verdict",
    "design_delayed_uio",
]

# documented (and shown in tracebacks) under the name they are imported by
for _name in __all__:
    globals()[_name].__module__ = __name__
del _name
