"""The plants of the course, with the values their sources print.

The three source documents' plants as printed (the missile's as read back from the paper's
scrambled text) and Johansson's quadruple tank, built from the paper's parameters:

* :func:`dt_case_study` -- *Case Study*: a discrete-time projection-operator UIO
  (3 states, unknown state input ``d`` with matrix ``E``, the script's ``u2`` and ``B2``;
  measurement disturbance ``v`` with matrix ``D``); printed ``M``, ``L`` and poles in
  :data:`DT_CASE_STUDY_PUBLISHED`.
* :func:`pa9` -- *Estimation for control, Practical Assignment 9*: the
  continuous-time decoupling observer example; printed ``H, T, K1, K2, F`` in
  :data:`PA9_PUBLISHED` (2 decimals).
* :func:`missile_autopilot` -- De, Banerjee and Das (IJERA 4(1), 2014): the
  missile autopilot, with matrices as read back from the paper's scrambled
  text; ``Mv``, ``x0`` and the unknown inputs in :data:`MISSILE_PUBLISHED`.
* :func:`quadruple_tank` -- Johansson (IEEE TCST 8(3), 2000): the
  quadruple-tank process linearized at the steady state of its valves and
  pump voltages (:func:`tank_operating_point`), both pump flows unknown
  (``E = B``); the paper's parameters, levels, time constants and zeros in
  :data:`QUADRUPLE_TANK_PUBLISHED`.
* ``varga_5_4`` -- Varga, *Solving Fault Diagnosis Problems* (Springer, 2024),
  Example 5.4: a plant given by transfer functions with feedthrough, one known input,
  one disturbance and two faults; the printed nullspace filter ``Q`` and ``Rf`` in
  ``VARGA_5_4_PUBLISHED``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from . import signals
from ._validation import read_only
from .errors import InputError
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
    "quadruple_tank",
    "tank_time_constants",
    "tank_operating_point",
    "TankOperatingPoint",
    "TANK_OUTLETS",
    "QUADRUPLE_TANK_PUBLISHED",
    "varga_5_4",
    "VARGA_5_4_PUBLISHED",
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

    ``x[k+1] = 0.5 I x[k] + [1 1 1]^T d[k]``,
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


def _tank_published(setting: str, values: dict[str, Any]) -> Published:
    shared = {
        "A": (28.0, 32.0, 28.0, 32.0),  # tank cross-sections, cm^2
        "a": (0.071, 0.057, 0.071, 0.057),  # outlet holes, cm^2
        "kc": 0.50,  # level sensors, V/cm
        "g": 981.0,  # cm/s^2
    }
    return Published(
        source=f"Johansson, IEEE TCST 8(3) 2000, setting {setting}",
        decimals=3,
        values=MappingProxyType({k: read_only(v) for k, v in {**shared, **values}.items()}),
    )


QUADRUPLE_TANK_PUBLISHED = MappingProxyType(
    {
        "P-": _tank_published(
            "P-",
            {
                "gamma": (0.70, 0.60),
                "h0": (12.4, 12.7, 1.8, 1.4),  # cm
                "v0": (3.00, 3.00),  # V
                "k": (3.33, 3.35),  # cm^3/(V s)
                "T": (62.0, 90.0, 23.0, 30.0),  # s, whole seconds
                "zeros": (-0.060, -0.018),  # 1/s
            },
        ),
        "P+": _tank_published(
            "P+",
            {
                "gamma": (0.43, 0.34),
                "h0": (12.6, 13.0, 4.8, 4.9),
                "v0": (3.15, 3.15),
                "k": (3.14, 3.29),
                "T": (63.0, 91.0, 39.0, 56.0),
                "zeros": (-0.056, 0.013),
            },
        ),
    }
)
"""The quadruple-tank paper's two settings, ``"P-"`` (minimum phase) and ``"P+"``.

Each holds the tank areas ``A`` and outlet areas ``a`` (cm^2), the sensor gain
``kc`` (V/cm), ``g`` (cm/s^2), the valve splits ``gamma``, the operating point
(levels ``h0`` in cm, pump voltages ``v0`` in V, pump gains ``k`` in cm^3/(V s)),
and the printed time constants ``T`` (s) and zeros (1/s)."""


TANK_OUTLETS = (0.071, 0.0572, 0.071, 0.0572)
"""The outlet areas ``a_1 .. a_4`` (cm^2) of the course's model.

The paper prints ``a_1 = a_3 = 0.071`` and ``a_2 = a_4 = 0.057`` to two
significant digits. With ``0.057`` exactly, the steady state of the mass
balance gives ``T_2 = 90.6`` s at P- (printed 90), ``T_2 = 92.0`` s and
``T_4 = 56.6`` s at P+ (printed 91 and 56) and the slower P- zero
``-0.01747`` (printed ``-0.018``). ``a_2 = a_4 = 0.0572``, which the printed
``0.057`` rounds, reproduces every printed time constant and zero of both
settings (so does any value from 0.05715 to 0.05729; 0.0571 misses the printed
``T_2 = 91`` at P+ and 0.0573 the printed P+ zero ``-0.056``)."""


@dataclass(frozen=True)
class TankOperatingPoint:
    """The steady state of the quadruple tank for given valves and pump voltages.

    Attributes
    ----------
    gamma : tuple of float
        The valve splits ``(gamma1, gamma2)``.
    v0 : tuple of float
        The pump voltages (V).
    k : tuple of float
        The pump gains (cm^3/(V s)).
    flows : numpy.ndarray
        The steady outflow of each tank, ``q_i = a_i sqrt(2 g h_i0)`` (cm^3/s).
    h0 : numpy.ndarray
        The steady levels (cm).
    T : numpy.ndarray
        The time constants ``T_i = (A_i / a_i) sqrt(2 h_i0 / g)`` (s).

    Examples
    --------
    >>> from uio_teach import examples
    >>> op = examples.tank_operating_point("P-")
    >>> op.h0.round(2).tolist(), op.T.round(1).tolist()
    ([12.26, 12.69, 1.63, 1.4], [62.4, 90.0, 22.8, 29.9])
    """

    gamma: tuple[float, float]
    v0: tuple[float, float]
    k: tuple[float, float]
    flows: np.ndarray
    h0: np.ndarray
    T: np.ndarray


def _positive_pair(name: str, value: Any) -> tuple[float, float]:
    try:
        pair = tuple(float(x) for x in value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be two numbers (V), got {value!r}") from None
    if len(pair) != 2 or isinstance(value, str) or not all(math.isfinite(x) for x in pair):
        raise InputError(f"{name} must be two finite numbers (V), got {value!r}")
    if min(pair) <= 0:
        raise InputError(
            f"{name} must be positive: a pump at 0 V leaves its upper tank empty, where the "
            f"outflow sqrt(2 g h) has no linearization; got {value!r}"
        )
    return pair  # type: ignore[return-value]


def tank_operating_point(
    setting: str = "P-",
    *,
    gamma1: float | None = None,
    gamma2: float | None = None,
    v0: tuple[float, float] | None = None,
) -> TankOperatingPoint:
    """The steady state of the nonlinear quadruple tank: levels and time constants.

    The mass balance of each tank (Johansson 2000, eq. (1))::

        A1 dh1/dt = -a1 sqrt(2 g h1) + a3 sqrt(2 g h3) + g1 k1 v1
        A2 dh2/dt = -a2 sqrt(2 g h2) + a4 sqrt(2 g h4) + g2 k2 v2
        A3 dh3/dt = -a3 sqrt(2 g h3) + (1 - g2) k2 v2
        A4 dh4/dt = -a4 sqrt(2 g h4) + (1 - g1) k1 v1

    is at rest when every tank lets out what flows in: ``q3 = (1 - g2) k2 v2``,
    ``q4 = (1 - g1) k1 v1``, ``q1 = g1 k1 v1 + q3``, ``q2 = g2 k2 v2 + q4``,
    and ``h_i0 = (q_i / a_i)^2 / (2 g)``. The outlet areas are
    :data:`TANK_OUTLETS`.

    Parameters
    ----------
    setting : {"P-", "P+"}
        The paper's setting whose pump gains (and, unless given, valves and
        pump voltages) are used.
    gamma1, gamma2 : float, optional
        The valve splits, from 0 (the whole flow to the upper tank) up to but
        not including 1 (at 1 the upper tank on the other side is empty, and
        its outflow has no linearization there).
    v0 : pair of float, optional
        The pump voltages (V), both positive.

    Returns
    -------
    TankOperatingPoint

    Raises
    ------
    ValueError
        An unknown setting, a valve outside ``[0, 1)`` or a pump voltage not
        positive, said in words.

    Examples
    --------
    >>> from uio_teach import examples
    >>> op = examples.tank_operating_point("P-", gamma1=0.43, gamma2=0.34)
    >>> op.h0.round(2).tolist()
    [12.08, 12.93, 4.45, 5.05]
    """
    pub = _tank_setting(setting)
    g1 = _valve("gamma1", pub.gamma[0] if gamma1 is None else gamma1, upper=4)
    g2 = _valve("gamma2", pub.gamma[1] if gamma2 is None else gamma2, upper=3)
    v1, v2 = _positive_pair("v0", pub.v0 if v0 is None else v0)
    k1, k2 = (float(x) for x in pub.k)
    q3, q4 = (1 - g2) * k2 * v2, (1 - g1) * k1 * v1
    flows = np.array([g1 * k1 * v1 + q3, g2 * k2 * v2 + q4, q3, q4])
    a = np.asarray(TANK_OUTLETS)
    g = float(pub.g)
    h0 = (flows / a) ** 2 / (2 * g)
    T = np.asarray(pub.A) / a * np.sqrt(2 * h0 / g)
    for arr in (flows, h0, T):
        arr.setflags(write=False)
    return TankOperatingPoint((g1, g2), (v1, v2), (k1, k2), flows, h0, T)


def tank_time_constants(
    setting: str = "P-",
    *,
    gamma1: float | None = None,
    gamma2: float | None = None,
    v0: tuple[float, float] | None = None,
) -> np.ndarray:
    """The time constants ``T_i = (A_i / a_i) sqrt(2 h_i0 / g)`` at the steady state, in s.

    The levels ``h_i0`` are those of :func:`tank_operating_point` for the
    setting's pumps and the given (or the setting's) valves and voltages.

    Parameters
    ----------
    setting : {"P-", "P+"}
    gamma1, gamma2, v0 : optional
        As for :func:`tank_operating_point`.

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> from uio_teach import examples
    >>> examples.tank_time_constants("P+").round(1).tolist()
    [62.8, 91.3, 38.7, 56.2]
    """
    return tank_operating_point(setting, gamma1=gamma1, gamma2=gamma2, v0=v0).T.copy()


def _tank_setting(setting: str) -> Published:
    if not isinstance(setting, str) or setting not in QUADRUPLE_TANK_PUBLISHED:
        raise InputError(
            f"setting must be one of {', '.join(map(repr, QUADRUPLE_TANK_PUBLISHED))}, "
            f"got {setting!r}"
        )
    return QUADRUPLE_TANK_PUBLISHED[setting]


def _valve(name: str, value: Any, *, upper: int) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise InputError(f"{name} must be a number from 0 up to (not including) 1, got {value!r}")
    value = float(value)
    if not 0.0 <= value < 1.0:
        if value == 1.0:
            raise InputError(
                f"{name} = 1 sends the whole of pump {name[-1]}'s flow to lower tank {name[-1]}: "
                f"upper tank {upper} is then empty, where its outflow sqrt(2 g h{upper}) has no "
                f"linearization; take {name} below 1"
            )
        raise InputError(
            f"{name} must lie from 0 up to (not including) 1 (the share of pump {name[-1]}'s "
            f"flow sent to lower tank {name[-1]}), got {value!r}"
        )
    return value


def quadruple_tank(
    setting: str = "P-",
    *,
    gamma1: float | None = None,
    gamma2: float | None = None,
    v0: tuple[float, float] | None = None,
) -> Plant:
    """The quadruple-tank process of Johansson (2000), linearized, both pump flows unknown.

    Linearized at its own steady state (:func:`tank_operating_point`) for the
    valves and pump voltages given, or the setting's. States are the level
    deviations ``h_i - h_i0`` (cm) of the four tanks, the outputs the two
    measured lower levels ``kc (h_1 - h_10)``, ``kc (h_2 - h_20)`` (V), the
    unknown inputs the two pump voltages' deviations (V), entering as the
    paper's ``B`` (``E = B``; no known input)::

        A = [[-1/T1, 0, A3/(A1 T3), 0], [0, -1/T2, 0, A4/(A2 T4)],
             [0, 0, -1/T3, 0], [0, 0, 0, -1/T4]]
        E = [[g1 k1/A1, 0], [0, g2 k2/A2], [0, (1-g2) k2/A3], [(1-g1) k1/A4, 0]]

    with ``T_i`` from :func:`tank_time_constants`. The valves split each pump's
    flow between a lower tank (``gamma``) and the upper tank on the other side;
    the invariant zeros solve ``(1 + s T3)(1 + s T4) = (1-g1)(1-g2)/(g1 g2)``,
    so one crosses into the right half-plane when ``g1 + g2 < 1``. A valve at
    0 sends nothing to its lower tank: ``C E`` is singular and the rank
    condition fails.

    Parameters
    ----------
    setting : {"P-", "P+"}
        The paper's minimum-phase (``"P-"``, gamma 0.70, 0.60, 3.00 V) or
        non-minimum-phase (``"P+"``, gamma 0.43, 0.34, 3.15 V) setting: its
        pump gains, and its valves and voltages unless given.
    gamma1, gamma2 : float, optional
        Other valve splits, from 0 up to (not including) 1.
    v0 : pair of float, optional
        Other pump voltages (V), both positive.

    Returns
    -------
    Plant

    Raises
    ------
    ValueError
        An unknown setting, a valve outside ``[0, 1)``, a voltage not positive.

    Examples
    --------
    >>> import uio_teach as ut
    >>> ut.examples.quadruple_tank("P+")
    Plant('quadruple tank (P+)', continuous-time, n=4, m=0, q=2, p=2, nv=0)
    >>> ut.check_existence(ut.examples.quadruple_tank("P-")).ok
    True
    >>> ut.check_existence(ut.examples.quadruple_tank("P+")).ok
    False
    >>> ut.examples.quadruple_tank(gamma1=0.43, gamma2=0.34).name
    'quadruple tank (P- pumps, gamma 0.43, 0.34)'
    """
    pub = _tank_setting(setting)
    op = tank_operating_point(setting, gamma1=gamma1, gamma2=gamma2, v0=v0)
    g1, g2 = op.gamma
    A1, A2, A3, A4 = (float(x) for x in pub.A)
    k1, k2 = op.k
    T1, T2, T3, T4 = op.T
    kc = float(pub.kc)
    changed = []
    if op.gamma != tuple(float(x) for x in pub.gamma):
        changed.append(f"gamma {g1:g}, {g2:g}")
    if op.v0 != tuple(float(x) for x in pub.v0):
        changed.append(f"v0 {op.v0[0]:g}, {op.v0[1]:g} V")
    name = f"quadruple tank ({setting}" + (f" pumps, {', '.join(changed)})" if changed else ")")
    return Plant(
        [
            [-1 / T1, 0, A3 / (A1 * T3), 0],
            [0, -1 / T2, 0, A4 / (A2 * T4)],
            [0, 0, -1 / T3, 0],
            [0, 0, 0, -1 / T4],
        ],
        [[kc, 0, 0, 0], [0, kc, 0, 0]],
        E=[[g1 * k1 / A1, 0], [0, g2 * k2 / A2], [0, (1 - g2) * k2 / A3], [(1 - g1) * k1 / A4, 0]],
        name=name,
    )


def varga_5_4():
    """Example 5.4 of Varga, *Solving Fault Diagnosis Problems*: a minimal realization.

    ``Gu = [(s+1)/(s-2); (s+2)/(s-3)]``, ``Gd = [(s-1)/(s+2); 0]``,
    ``Gf = [(s+1)/(s-2), 0; (s+2)/(s-3), 1]`` (the first fault acts as the
    known input does, the second on the second output). Written as
    ``(s+1)/(s-2) = 1 + 3/(s-2)``, ``(s+2)/(s-3) = 1 + 5/(s-3)`` and
    ``(s-1)/(s+2) = 1 - 3/(s+2)``, one state per pole.

    Returns
    -------
    control.StateSpace
        Inputs ``u, d, f1, f2``; outputs ``y1, y2``; 3 states.

    Examples
    --------
    >>> from uio_teach import examples
    >>> sys = examples.varga_5_4()
    >>> sys.input_labels, sorted(sys.poles().real.tolist())
    (['u', 'd', 'f1', 'f2'], [-2.0, 2.0, 3.0])
    """
    import control as ct  # deferred on purpose: python-control takes a second to import

    A = np.diag([2.0, 3.0, -2.0])
    B = np.array([[1.0, 0, 1, 0], [1, 0, 1, 0], [0, 1, 0, 0]])
    C = np.array([[3.0, 0, -3], [0, 5, 0]])
    D = np.array([[1.0, 1, 1, 0], [1, 0, 1, 1]])
    return ct.ss(A, B, C, D, inputs=["u", "d", "f1", "f2"], outputs=["y1", "y2"], name="varga_5_4")


VARGA_5_4_PUBLISHED = Published(
    source="Varga, Solving Fault Diagnosis Problems, Example 5.4",
    decimals=4,
    values=MappingProxyType(
        {
            # numerators and denominators, descending powers of s; Q's inputs are y1, y2, u
            "Q_num": ((0.0, 0.0), (1.0, -3.0), (-1.0, -2.0)),
            "Rf_num": ((1.0, 2.0), (1.0, -3.0)),
            "den": (1.0, 3.0),
            "poles": read_only([-3.0]),
        }
    ),
)
"""Printed ``Q = [0, (s-3)/(s+3), -(s+2)/(s+3)]`` and ``Rf = [(s+2)/(s+3), (s-3)/(s+3)]``
(4 significant digits, after dividing by ``Rf``'s first entry at infinity; the printed first
entry of ``Q``, ``(1.54e-16 s + 3.966e-17)/(s+3)``, is zero to rounding)."""
