"""The plants of the three source documents, exactly as printed, and their published extras.

* :func:`dt_case_study` -- *Case Study*: a discrete-time projection-operator UIO
  (3 states, unknown state input ``u2`` with matrix ``B2 = E``, measurement
  disturbance ``v`` with matrix ``D``); printed ``M``, ``L`` and poles in
  :data:`DT_CASE_STUDY_PUBLISHED`.
* :func:`pa9` -- *Estimation for control, Practical Assignment 9*: the
  continuous-time decoupling observer example; printed ``H, T, K1, K2, F`` in
  :data:`PA9_PUBLISHED` (2 decimals).
* :func:`missile_autopilot` -- De, Banerjee and Das (IJERA 4(1), 2014): the
  missile autopilot, with matrices as read back from the paper's scrambled
  text; ``Mv``, ``x0`` and the unknown inputs in :data:`MISSILE_PUBLISHED`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from . import signals
from ._validation import read_only
from .plant import Plant

__all__ = [
    "Published",
    "dt_case_study",
    "pa9",
    "missile_autopilot",
    "missile_inputs",
    "MISSILE_INPUTS",
    "DT_CASE_STUDY_PUBLISHED",
    "PA9_PUBLISHED",
    "MISSILE_PUBLISHED",
]


@dataclass(frozen=True)
class Published:
    """Values printed in a source document (``decimals``: as printed).

    Examples
    --------
    >>> from uio_teach import examples
    >>> examples.PA9_PUBLISHED.H
    array([[0.94, 0.23],
           [0.  , 0.  ],
           [0.23, 0.05]])
    """

    source: str
    decimals: int
    values: MappingProxyType = field(repr=False)

    def __getattr__(self, name: str) -> Any:
        try:
            return self.values[name]
        except KeyError:
            raise AttributeError(name) from None

    def __dir__(self):
        return list(self.values)


def dt_case_study() -> Plant:
    """Discrete-time plant of the case study (unit sampling period, ``dt=1``).

    ``x[k+1] = 0.5 I x[k] + [1 1 1]^T u2[k]``,
    ``y[k] = [[0 2 1], [1 0 0]] x[k] + [1 0.2]^T v[k]``.

    Examples
    --------
    >>> from uio_teach import examples
    >>> examples.dt_case_study()
    Plant('case study', discrete-time, dt=1, n=3, m=0, q=1, p=2, nv=1)
    """
    return Plant(
        0.5 * np.eye(3),
        [[0, 2, 1], [1, 0, 0]],
        E=[[1], [1], [1]],
        D=[[1], [0.2]],
        dt=1,
        name="case study",
    )


DT_CASE_STUDY_PUBLISHED = Published(
    source="Case Study: projection operator UIO for a DT system",
    decimals=4,
    values=MappingProxyType(
        {
            "M": read_only([[-0.5, 2.5], [-0.5, 2.5], [-0.5, 2.5]]),
            "L": read_only([[0.1667, -0.8333], [0.2833, -1.4167], [0.2667, -1.3333]]),
            "poles": read_only([0.0, 0.5, 0.5]),
        }
    ),
)
"""Printed ``M``, ``L`` and observer poles of the case study (4 decimals)."""


def pa9() -> Plant:
    """Continuous-time plant of Practical Assignment 9 (eq. (9)).

    Examples
    --------
    >>> from uio_teach import examples
    >>> examples.pa9()
    Plant('PA9', continuous-time, n=3, m=2, q=1, p=2, nv=0)
    """
    return Plant(
        [[0, 1, 0], [-2, -3, 0], [0, 0, -2]],
        [[1, 0, 0], [0, 0, 1]],
        B=[[0, 0], [4, 0], [0, 1]],
        E=[[2], [0], [0.5]],
        name="PA9",
    )


PA9_PUBLISHED = Published(
    source="Estimation for control - Practical Assignment 9, eqs. (10)-(11)",
    decimals=2,
    values=MappingProxyType(
        {
            "H": read_only([[0.94, 0.23], [0, 0], [0.23, 0.05]]),
            "T": read_only([[0.05, 0, -0.23], [0, 1, 0], [-0.23, 0, 0.94]]),
            "K1": read_only([[1.97, 0.32], [-2.04, -0.02], [-0.16, -0.86]]),
            "K2": read_only([[-1.82, -0.45], [0.04, 0.01], [-0.08, -0.02]]),
            "F": read_only([[-1.97, 0.05, 0.14], [0.04, -3, 0.02], [0.16, -0.23, -1.02]]),
            "poles": read_only([-3.0, -2.0, -1.0]),
        }
    ),
)
"""Printed ``H, T, K1, K2, F`` of Practical Assignment 9 (2 decimals, MATLAB ``place``)."""


def missile_autopilot() -> Plant:
    """Missile-autopilot plant of De, Banerjee and Das (2014), as read from the paper.

    The last two states are a fin actuator with natural frequency 180 rad/s
    and damping 0.6 (``180^2 = 32400``, ``2 * 0.6 * 180 = 216``).

    Examples
    --------
    >>> from uio_teach import examples
    >>> examples.missile_autopilot()
    Plant('missile autopilot', continuous-time, n=4, m=1, q=2, p=2, nv=0)
    """
    return Plant(
        [[0, 0, 0, 0], [-86, 0, -12, 0], [0, 0, 0, 1], [0, 0, -32400, -216]],
        [[1, 0, 0, 0], [0, 1, 0, 0]],
        B=[[0], [0], [0], [-45360]],
        E=[[1, 2], [3, 1], [1, 0], [5, 1]],
        name="missile autopilot",
    )


MISSILE_INPUTS = ((10.0, 2.0, 10.0, "cos"), (50.0, 5.0, 100.0, "sin"))
"""The paper's unknown inputs as ``(amplitude, decay rate, frequency, "cos"/"sin")``."""


def missile_inputs():
    """The paper's unknown inputs ``[v1; v2]`` as one vector signal (:data:`MISSILE_INPUTS`).

    ``v1(t) = 10 exp(-2t) cos(10t)``, ``v2(t) = 50 exp(-5t) sin(100t)``.

    Examples
    --------
    >>> from uio_teach import examples
    >>> examples.missile_inputs()
    [10 exp(-2 t) cos(10 t); 50 exp(-5 t) sin(100 t)]
    """
    return signals.stack(*(signals.damped_sinusoid(*p) for p in MISSILE_INPUTS))


MISSILE_PUBLISHED = Published(
    source="De, Banerjee, Das, IJERA 4(1) 2014, Section IV and Table II",
    decimals=2,
    values=MappingProxyType(
        {
            "Mv": read_only([[-5, 7], [2, 7], [5, 8], [5, 9]]),
            "x0": read_only([20, 0.25, 1.43, 100]),
            # Table II: time (s) after which each estimate "catches" the true signal
            "catch_pmo": MappingProxyType(
                {"x1": 0.03, "x2": 0.03, "x3": 0.04, "x4": 0.05, "v1": 0.08, "v2": 0.07}
            ),
            "catch_ginverse": MappingProxyType(
                {"x1": 0.0, "x2": 0.0, "x3": 0.04, "x4": 0.05, "v1": 0.04, "v2": 0.02}
            ),
        }
    ),
)
"""The missile paper's ``Mv``, ``x0`` and Table II catch times (seconds, read by eye)."""
