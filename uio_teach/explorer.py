"""Explorers: move the observer poles and the disturbance, see the observer respond.

This module holds the pure part of the course's explorers, without any widget:

* a :class:`Scenario` says *what* is explored: the plant, the observer family,
  the time grid, the initial state and the ranges of the controls
  (:func:`pa9_scenario`, :func:`case_study_scenario`,
  :func:`missile_scenario`, or :func:`make_scenario` for any plant);
* a :class:`Settings` holds the values of the controls: the movable observer
  poles (or the LMI bound), the disturbance type, amplitude, frequency or
  switching period, the measurement-noise level and the filter time constant
  of the input reconstruction;
* :func:`compute_frame` designs the observer, designs a plain Luenberger
  observer with the same poles, simulates both with :func:`uio_teach.simulate`
  and returns a :class:`Frame`: the curves to draw (clipped for display) and
  short messages in plain words. It never raises for a value a student can
  set: a pole that makes the observer unstable or an infeasible LMI becomes a
  message;
* an :class:`ExplorerFigure` draws a frame and updates its lines in place
  (``set_data``), which is what makes the live explorer quick.

:mod:`uio_teach.widgets` wires ipywidgets controls to these functions and
:mod:`uio_teach.static_explorer` renders pre-computed frames for the static
book.

**The Luenberger comparison.** The plain observer ``xhat' = A xhat + B u +
L (y - C xhat)`` gets the same error poles as the unknown input observer: the
poles you set *and* the fixed poles (the invariant zeros), so that the only
difference between the two columns of the figure is the decoupling. The rule,
in :func:`uio_teach.explorer.luenberger_poles`: modes that no gain moves in the Luenberger
observer (unobservable modes of ``(A, C)``) are taken out of the list; if
the list is then longer than the number of poles ``(A, C)`` lets us place,
the fastest poles are dropped; if it is shorter (the g-inverse observer has
only ``n - rank(C)`` poles), extra real poles are added, faster than the
fastest one (1.5, 2, 2.5, ... times its real part in continuous time; half,
a quarter, ... of the smallest radius in discrete time). Poles repeated more
often than there are independent outputs are spread by a few percent.

Examples
--------
>>> import uio_teach as ut
>>> from uio_teach.explorer import compute_frame, pa9_scenario
>>> scenario = pa9_scenario()
>>> frame = compute_frame(scenario, scenario.defaults.replace(poles=(-2.0, -3.0, -4.0)))
>>> frame.poles.real.round(6).tolist()
[-4.0, -3.0, -2.0]
>>> frame.luenberger_poles.real.round(6).tolist()
[-4.0, -3.0, -2.0]
>>> frame.messages
()
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import textwrap
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from . import signals
from ._display import format_complex
from .examples import MISSILE_PUBLISHED, dt_case_study, missile_autopilot, pa9
from .existence import ExistenceReport, check_existence
from .linalg import _sort, is_stable, observability_decomposition, rank
from .lmi import LMIInfeasibleError
from .observers import (
    Observer,
    design_ginverse,
    design_luenberger,
    design_pmo,
    design_uio,
)
from .plant import Plant
from .reconstruction import InputEstimate, reconstruct_input
from .simulation import UIOResponse, simulate

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "DISTURBANCES",
    "FAMILIES",
    "Channel",
    "Settings",
    "Scenario",
    "Frame",
    "ExplorerFigure",
    "pa9_scenario",
    "case_study_scenario",
    "missile_scenario",
    "make_scenario",
    "expand_poles",
    "format_poles",
    "disturbance_signals",
    "luenberger_poles",
    "compute_frame",
    "render",
]

DISTURBANCES = ("sinusoid", "piecewise constant", "damped sinusoid", "random steps")
"""The disturbance types an explorer offers."""

FAMILIES = {"uio": "UIO", "pmo": "PMO", "ginverse": "g-inverse observer"}
"""Observer families (argument value: display name)."""

_WRAP = 34  # characters per line of a message drawn inside a panel
# Legends inside the panels are opaque and square: drawn over the curves, they hide exactly
# their box, which lets the fast redraw paint them back from the stored background.
_LEGEND = {
    "loc": "upper right",
    "fontsize": 7,
    "ncol": 2,
    "handlelength": 1.2,
    "framealpha": 1.0,
    "fancybox": False,
}


# settings --------------------------------------------------------------------------------


@dataclass(frozen=True)
class Channel:
    """How one unknown signal follows the disturbance controls.

    The disturbance controls set one amplitude ``A``, one frequency ``w`` and
    one switching period ``P``; channel ``i`` of ``d`` (or ``v``) then has
    amplitude ``gain * A``, frequency ``speed * w``, switching period
    ``P / speed`` and, for the damped sinusoid, the decay rate
    ``decay * speed * w``.

    Attributes
    ----------
    gain : float
        Amplitude relative to the amplitude control.
    speed : float
        Frequency relative to the frequency control (and inverse relative
        switching period).
    decay : float
        Decay rate of the damped sinusoid per unit of its frequency.
    kind : {"sin", "cos"}
        Sine or cosine for the (damped) sinusoid.

    Examples
    --------
    >>> from uio_teach.explorer import Channel
    >>> Channel(gain=5, speed=10, decay=0.05)   # the missile paper's v2 = 50 exp(-5t) sin(100t)
    Channel(gain=5, speed=10, decay=0.05, kind='sin')
    """

    gain: float = 1.0
    speed: float = 1.0
    decay: float = 0.2
    kind: str = "sin"


@dataclass(frozen=True)
class Settings:
    """The values of an explorer's controls.

    Attributes
    ----------
    poles : tuple of complex
        The movable observer poles. A complex entry stands for the conjugate
        pair (list it once; the sign of its imaginary part is ignored), so
        ``(-1+2j, -3)`` means the poles ``-1 ± 2j`` and ``-3``. Ignored in
        ``"lmi"`` mode and for the g-inverse observer.
    mode : {"poles", "lmi"}
        Place the poles, or (projection-operator observer) take the gain from
        the LMI of :func:`uio_teach.lmi_gain` with the bound ``decay``.
    decay : float
        The LMI bound: the pole radius in discrete time, the minimum decay
        rate in continuous time.
    disturbance : str
        One of :data:`DISTURBANCES`.
    amplitude : float
        Amplitude of the disturbance.
    frequency : float
        Angular frequency of the (damped) sinusoid, rad/s (rad/step when
        ``dt=True`` or ``dt=1``).
    period : float
        Switching period of the piecewise-constant and random-step
        disturbances (s, or steps).
    noise : float
        Standard deviation of the measurement noise on every output.
    tau : float
        Time constant of the low-pass filter of the input reconstruction;
        ``0`` takes the plain numerical derivative.
    seed : int
        Seed of the random steps and of the noise.

    Examples
    --------
    >>> from uio_teach.explorer import Settings
    >>> s = Settings(poles=(-1.0, -2.0, -3.0))
    >>> s.replace(disturbance="random steps").disturbance
    'random steps'
    """

    poles: tuple[complex, ...] = ()
    mode: str = "poles"
    decay: float = 0.9
    disturbance: str = "sinusoid"
    amplitude: float = 1.0
    frequency: float = 1.0
    period: float = 2.0
    noise: float = 0.0
    tau: float = 0.0
    seed: int = 0

    def replace(self, **changes: Any) -> Settings:
        """A copy with some values changed (:func:`dataclasses.replace`).

        Parameters
        ----------
        **changes
            New values of the fields.

        Returns
        -------
        Settings

        Examples
        --------
        >>> from uio_teach.explorer import Settings
        >>> Settings().replace(amplitude=2.0).amplitude
        2.0
        """
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True, eq=False)
class Scenario:
    """What an explorer explores: the plant, the observer, the time grid and the control ranges.

    Build one with :func:`pa9_scenario`, :func:`case_study_scenario`,
    :func:`missile_scenario` or :func:`make_scenario`.

    Attributes
    ----------
    name : str
        A short identifier (used in element ids).
    title : str
        The figure title.
    plant : Plant
        The plant.
    family : {"uio", "pmo", "ginverse"}
        The unknown input observer compared with the Luenberger observer.
    timepts : numpy.ndarray
        The simulation grid.
    initial_state : numpy.ndarray
        The plant's initial state (the observers start at zero).
    u : callable or None
        The known input.
    defaults : Settings
        The starting values of the controls.
    existence : ExistenceReport
        :func:`uio_teach.check_existence` of the plant.
    pole_limits : tuple of float
        Range of a real pole (continuous: also of a pair's real part;
        discrete: the largest value is also the largest radius).
    frequency_limits : tuple of float
        Continuous time: range of a complex pair's imaginary part.
    amplitude_limits, disturbance_frequency_limits, period_limits, noise_limits : tuple of float
        Ranges of the disturbance and noise controls.
    tau_limits : tuple of float or None
        Range of the reconstruction filter's time constant; ``None`` when the
        explorer does not reconstruct the unknown input.
    decay_limits : tuple of float or None
        Range of the LMI bound; ``None`` when there is no LMI mode.
    d_channels, v_channels : tuple of Channel
        How each channel of ``d`` and of ``v`` follows the disturbance
        controls.
    static_values : tuple of float
        The values of the main control in the static book's frames.
    static_control : {"pole", "amplitude"}
        The main control: the first movable pole, or (no movable pole) the
        disturbance amplitude.
    input_symbol : str
        The symbol of the unknown input in the figure (``"d"``, or ``"v"`` for
        the missile paper).

    Examples
    --------
    >>> from uio_teach.explorer import missile_scenario
    >>> s = missile_scenario()
    >>> s.movable, s.fixed_poles.round(1).tolist()
    (2, [(-105.6-142.1j), (-105.6+142.1j)])
    """

    name: str
    title: str
    plant: Plant
    family: str
    timepts: np.ndarray
    initial_state: np.ndarray
    u: Callable | None
    defaults: Settings
    existence: ExistenceReport
    pole_limits: tuple[float, float]
    frequency_limits: tuple[float, float]
    amplitude_limits: tuple[float, float]
    disturbance_frequency_limits: tuple[float, float]
    period_limits: tuple[float, float]
    noise_limits: tuple[float, float]
    tau_limits: tuple[float, float] | None
    decay_limits: tuple[float, float] | None
    d_channels: tuple[Channel, ...]
    v_channels: tuple[Channel, ...]
    static_values: tuple[float, ...]
    static_control: str
    input_symbol: str = "d"
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def movable(self) -> int:
        """How many observer poles the controls set (0 for the g-inverse observer)."""
        return 0 if self.family == "ginverse" else self.existence.movable

    @property
    def fixed_poles(self) -> np.ndarray:
        """The observer poles no gain moves: the invariant zeros."""
        return self.existence.fixed_modes

    @property
    def invariant_zeros(self) -> np.ndarray:
        """The plant's invariant zeros from the unknown inputs to the outputs."""
        return self.existence.invariant_zeros

    @property
    def discrete(self) -> bool:
        """True for a discrete-time plant."""
        return self.plant.is_discrete

    @property
    def reconstruct(self) -> bool:
        """True when the explorer reconstructs the unknown input (``tau_limits`` set)."""
        return self.tau_limits is not None

    @property
    def observer_name(self) -> str:
        """The display name of the observer family."""
        return FAMILIES[self.family]


# poles -----------------------------------------------------------------------------------


def expand_poles(poles: Sequence[complex]) -> np.ndarray:
    """All the poles meant by :attr:`Settings.poles`: each complex entry becomes its pair.

    Parameters
    ----------
    poles : sequence of complex
        Real poles and one entry per complex pair.

    Returns
    -------
    numpy.ndarray of complex

    Examples
    --------
    >>> from uio_teach.explorer import expand_poles
    >>> expand_poles([-1 + 2j, -3]).tolist()
    [(-1+2j), (-1-2j), (-3+0j)]
    """
    out: list[complex] = []
    for p in poles:
        p = complex(p)
        if p.imag != 0:
            out += [complex(p.real, abs(p.imag)), complex(p.real, -abs(p.imag))]
        else:
            out.append(complex(p.real, 0.0))
    return np.array(out, dtype=complex)


def _spread(poles: list[complex], discrete: bool) -> list[complex]:
    """Move the repeated copies of a pole apart by a few percent (conjugate pairs stay pairs)."""
    out: list[complex] = []
    seen: dict[complex, int] = {}
    for p in poles:
        if p.imag < 0:
            continue  # follows its upper partner
        key = complex(round(p.real, 9), round(p.imag, 9))
        j = seen.get(key, 0)
        seen[key] = j + 1
        if j:
            if discrete:
                re = p.real * (1 - 0.04 * j) if p.real else 0.02 * j
            else:
                re = p.real - 0.02 * j * max(1.0, abs(p))
            p = complex(re, p.imag)
        out += [p, p.conjugate()] if p.imag else [p]
    return out


def _too_repeated(poles: Sequence[complex], k: int) -> bool:
    if k < 2 or not len(poles):
        return False  # one output: Ackermann's formula takes any multiplicity
    _, counts = np.unique(np.round(np.asarray(poles, complex), 9), return_counts=True)
    return bool(np.any(counts > k))


def luenberger_poles(plant: Plant, observer_poles: Sequence[complex]) -> np.ndarray:
    """The poles given to the Luenberger observer compared with an unknown input observer.

    The rule (module documentation): start from the unknown input observer's
    error poles, movable and fixed; take out the modes that stay fixed in the
    Luenberger observer (unobservable for ``(A, C)``); drop the fastest poles
    if there are too many, add faster real poles if there are too few; spread
    poles repeated more often than there are independent outputs.

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
    >>> from uio_teach.explorer import luenberger_poles
    >>> plant = ut.examples.missile_autopilot()
    >>> g = ut.design_ginverse(plant)
    >>> luenberger_poles(plant, g.poles()).round(1).tolist()
    [(-211.2+0j), (-158.4+0j), (-105.6-142.1j), (-105.6+142.1j)]
    """
    discrete = plant.is_discrete
    split = observability_decomposition(plant.A, plant.C)
    n_place = split.Ao.shape[0]
    target = [complex(p) for p in _sort(np.asarray(observer_poles, complex)) if np.isfinite(p)]
    for f in split.unobservable_modes:
        if target:
            dist = [abs(p - f) for p in target]
            i = int(np.argmin(dist))
            if dist[i] <= 1e-6 * max(1.0, abs(f)):
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
    outputs = rank(plant.C)
    if _too_repeated(target, outputs):
        target = _spread(target, discrete)
    return _sort(np.array(target, dtype=complex))


# disturbances ----------------------------------------------------------------------------


def _channel_signal(
    kind: str,
    settings: Settings,
    channel: Channel,
    t0: float,
    t1: float,
    rng: np.random.Generator,
) -> signals.Signal:
    a = float(settings.amplitude) * channel.gain
    w = float(settings.frequency) * channel.speed
    if kind == "sinusoid":
        return signals.sinusoid(a, w, phase=math.pi / 2 if channel.kind == "cos" else 0.0)
    if kind == "damped sinusoid":
        return signals.damped_sinusoid(a, channel.decay * w, w, channel.kind)
    period = float(settings.period) / channel.speed
    if not np.isfinite(period) or period <= 0:
        raise ValueError(f"the switching period must be positive, got {settings.period!r}")
    count = int(math.ceil((t1 - t0) / period)) + 1
    if count > 100_000:
        raise ValueError(f"the switching period {settings.period:g} is too short for this window")
    times = t0 + period * np.arange(count)
    if kind == "piecewise constant":
        values = a * np.where(np.arange(count) % 2 == 0, 1.0, -1.0)
    else:  # random steps
        values = a * rng.uniform(-1.0, 1.0, count)
    return signals.piecewise_constant(times, values)


def disturbance_signals(
    scenario: Scenario, settings: Settings
) -> tuple[list[signals.Signal], list[signals.Signal]]:
    """The unknown signals of the settings: one signal per channel of ``d`` and of ``v``.

    Every channel has the chosen type (:data:`DISTURBANCES`), shaped by its
    :class:`Channel`. The random steps of channel ``i`` of ``d`` (``v``) draw
    their levels uniformly in ``[-A, A]`` from
    ``numpy.random.default_rng([seed, i])`` (``[seed, 100 + i]``).

    Parameters
    ----------
    scenario : Scenario
        The explorer's scenario.
    settings : Settings
        The control values.

    Returns
    -------
    d, v : list of Signal
        One :class:`uio_teach.signals.Signal` per channel.

    Raises
    ------
    ValueError
        An unknown disturbance type, a non-finite value or a switching period
        that is not positive.

    Examples
    --------
    >>> from uio_teach.explorer import disturbance_signals, missile_scenario
    >>> s = missile_scenario()
    >>> disturbance_signals(s, s.defaults)[0]   # the paper's unknown inputs
    [10 exp(-2 t) cos(10 t), 50 exp(-5 t) sin(100 t)]
    """
    kind = settings.disturbance
    if kind not in DISTURBANCES:
        raise ValueError(f"unknown disturbance type {kind!r}; choose one of {DISTURBANCES}")
    for name in ("amplitude", "frequency", "period"):
        value = getattr(settings, name)
        if not isinstance(value, int | float | np.number) or not np.isfinite(value):
            raise ValueError(f"the {name} must be a finite number, got {value!r}")
    t0, t1 = float(scenario.timepts[0]), float(scenario.timepts[-1])
    seed = int(settings.seed)
    d = [
        _channel_signal(kind, settings, c, t0, t1, np.random.default_rng([seed, i]))
        for i, c in enumerate(scenario.d_channels)
    ]
    v = [
        _channel_signal(kind, settings, c, t0, t1, np.random.default_rng([seed, 100 + i]))
        for i, c in enumerate(scenario.v_channels)
    ]
    return d, v


def _describe(kind: str, settings: Settings, discrete: bool) -> str:
    unit = "steps" if discrete else "s"
    a = f"{settings.amplitude:.3g}"
    if kind in ("sinusoid", "damped sinusoid"):
        per = "rad/step" if discrete else "rad/s"
        return f"{kind}, amplitude {a}, frequency {settings.frequency:.3g} {per}"
    return f"{kind}, amplitude {a}, switching every {settings.period:.3g} {unit}"


# scenarios -------------------------------------------------------------------------------


def _scenario(plant: Plant, family: str, **kwargs: Any) -> Scenario:
    if family not in FAMILIES:
        raise ValueError(f"observer_family must be one of {tuple(FAMILIES)}, got {family!r}")
    timepts = np.asarray(kwargs.pop("timepts"), dtype=float)
    timepts.setflags(write=False)
    x0 = np.asarray(kwargs.pop("initial_state"), dtype=float).ravel()
    x0.setflags(write=False)
    return Scenario(
        plant=plant,
        family=family,
        timepts=timepts,
        initial_state=x0,
        existence=check_existence(plant),
        **kwargs,
    )


def pa9_scenario() -> Scenario:
    """Practical Assignment 9: the decoupling UIO, three movable poles, ``d`` sinusoidal by default.

    Known input ``u = [1, 0.5 sin t]``, initial state ``[1, -1, 0.5]``,
    10 s on 1001 samples; the poles start at ``-1, -2, -3`` as in the
    assignment.

    Returns
    -------
    Scenario

    Examples
    --------
    >>> from uio_teach.explorer import pa9_scenario
    >>> s = pa9_scenario()
    >>> s.movable, s.defaults.poles
    (3, (-1.0, -2.0, -3.0))
    """
    return _scenario(
        pa9(),
        "uio",
        name="pa9",
        title="PA9",
        timepts=np.linspace(0.0, 10.0, 1001),
        initial_state=[1.0, -1.0, 0.5],
        u=signals.stack(signals.step(1.0), signals.sinusoid(0.5, 1.0)),
        defaults=Settings(
            poles=(-1.0, -2.0, -3.0),
            disturbance="sinusoid",
            amplitude=1.0,
            frequency=2.0,
            period=2.5,
        ),
        pole_limits=(-10.0, 1.0),
        frequency_limits=(0.0, 10.0),
        amplitude_limits=(0.0, 5.0),
        disturbance_frequency_limits=(0.1, 10.0),
        period_limits=(0.25, 5.0),
        noise_limits=(0.0, 0.2),
        tau_limits=None,
        decay_limits=None,
        d_channels=(Channel(),),
        v_channels=(),
        static_values=(0.5, -0.5, -1.0, -2.0, -4.0, -8.0),
        static_control="pole",
    )


def case_study_scenario() -> Scenario:
    """The discrete-time case study: projection-operator observer, one movable pole or the LMI.

    Two fixed poles at 0.5 (the invariant zeros); ``d`` and ``v`` of the
    chosen type (``v`` at half the amplitude and twice the frequency),
    initial state ``[1, -2, 3]``, steps ``k = 0 ... 40``. The alternative
    mode designs the gain from the LMI with a radius bound
    (``Settings(mode="lmi", decay=...)``).

    Returns
    -------
    Scenario

    Examples
    --------
    >>> from uio_teach.explorer import case_study_scenario
    >>> s = case_study_scenario()
    >>> s.movable, s.fixed_poles.real.round(6).tolist(), s.decay_limits
    (1, [0.5, 0.5], (0.3, 1.0))
    """
    return _scenario(
        dt_case_study(),
        "pmo",
        name="case-study",
        title="Case study",
        timepts=np.arange(41.0),
        initial_state=[1.0, -2.0, 3.0],
        u=None,
        defaults=Settings(
            poles=(0.0,),
            decay=0.9,
            disturbance="sinusoid",
            amplitude=2.0,
            frequency=0.6,
            period=5.0,
        ),
        pole_limits=(-1.1, 1.1),
        frequency_limits=(0.0, 180.0),
        amplitude_limits=(0.0, 5.0),
        disturbance_frequency_limits=(0.05, 3.0),
        period_limits=(1.0, 20.0),
        noise_limits=(0.0, 0.5),
        tau_limits=None,
        decay_limits=(0.3, 1.0),
        d_channels=(Channel(),),
        v_channels=(Channel(gain=0.5, speed=2.0),),
        static_values=(-0.9, -0.5, 0.0, 0.5, 0.9, 1.05),
        static_control="pole",
    )


def missile_scenario() -> Scenario:
    """The missile autopilot: PMO with two movable poles, the unknown inputs reconstructed.

    The default disturbance is the paper's pair of damped sinusoids
    ``v1 = 10 exp(-2t) cos(10t)``, ``v2 = 50 exp(-5t) sin(100t)``; the
    initial state is the paper's ``x0``; 0.5 s on 1001 samples. The unknown
    inputs are reconstructed from each observer's estimate with
    :func:`uio_teach.reconstruct_input` (filtered, ``tau`` = 2 ms).

    Returns
    -------
    Scenario

    Examples
    --------
    >>> from uio_teach.explorer import missile_scenario
    >>> s = missile_scenario()
    >>> s.defaults.poles, s.defaults.tau
    ((-100.0, -120.0), 0.002)
    """
    return _scenario(
        missile_autopilot(),
        "pmo",
        name="missile",
        title="Missile autopilot",
        timepts=np.linspace(0.0, 0.5, 1001),
        initial_state=MISSILE_PUBLISHED.x0,
        u=None,
        defaults=Settings(
            poles=(-100.0, -120.0),
            disturbance="damped sinusoid",
            amplitude=10.0,
            frequency=10.0,
            period=0.05,
            tau=0.002,
        ),
        pole_limits=(-400.0, 40.0),
        frequency_limits=(0.0, 300.0),
        amplitude_limits=(0.0, 50.0),
        disturbance_frequency_limits=(1.0, 200.0),
        period_limits=(0.01, 0.25),
        noise_limits=(0.0, 0.5),
        tau_limits=(0.0, 0.05),
        decay_limits=None,
        d_channels=(Channel(kind="cos"), Channel(gain=5.0, speed=10.0, decay=0.05)),
        v_channels=(),
        static_values=(20.0, -20.0, -50.0, -100.0, -200.0, -400.0),
        static_control="pole",
        input_symbol="v",
    )


def make_scenario(
    plant: Plant,
    observer_family: str = "uio",
    *,
    poles: Sequence[complex] | None = None,
    timepts: Any = None,
    initial_state: Any = None,
    u: Callable | None = None,
    reconstruct: bool = False,
    name: str = "plant",
    title: str | None = None,
) -> Scenario:
    """A scenario for any plant: sensible default poles, time window and control ranges.

    Continuous time: the default movable poles are ``-s, -1.5 s, -2 s, ...``
    with ``s`` the largest of 1, the plant's fastest mode and the fixed
    poles' moduli; the window lasts 8 time constants of the slowest observer
    pole (1001 samples). Discrete time: poles ``0.5, 0.4, 0.3, ...`` and
    enough steps for the slowest pole to decay to 0.1 %. The disturbance
    starts as a sinusoid with three periods in the window.

    Parameters
    ----------
    plant : Plant
        Any plant of the package.
    observer_family : {"uio", "pmo", "ginverse"}
        The unknown input observer to explore.
    poles : sequence of complex, optional
        The movable poles to start from (one entry per complex pair).
    timepts : array_like, optional
        The simulation grid (for a discrete plant, one point per step).
    initial_state : array_like, optional
        The plant's initial state; all ones by default.
    u : callable, optional
        The known input (a signal of :mod:`uio_teach.signals`); zero by
        default.
    reconstruct : bool
        Also reconstruct the unknown input (needs ``E`` of full column rank).
    name : str
        A short identifier.
    title : str, optional
        The figure title; the plant's name by default.

    Returns
    -------
    Scenario

    Raises
    ------
    ValueError
        ``plant`` is not a :class:`~uio_teach.Plant`, or an unknown family.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.explorer import make_scenario
    >>> s = make_scenario(ut.examples.pa9(), "pmo")
    >>> s.defaults.poles, round(float(s.timepts[-1]), 3)
    ((-2.0, -3.0, -4.0), 4.0)
    """
    if not isinstance(plant, Plant):
        raise ValueError(f"plant must be a uio_teach.Plant, got {type(plant).__name__}")
    if observer_family not in FAMILIES:
        raise ValueError(
            f"observer_family must be one of {tuple(FAMILIES)}, got {observer_family!r}"
        )
    report = check_existence(plant)
    discrete = plant.is_discrete
    k = 0 if observer_family == "ginverse" else report.movable
    fixed = report.fixed_modes
    if poles is None:
        if discrete:
            poles = tuple(max(0.05, 0.5 - 0.1 * i) for i in range(k))
        else:
            eig = np.abs(np.linalg.eigvals(plant.A)) if plant.n else np.zeros(0)
            s = max([1.0, *eig.tolist(), *np.abs(fixed).tolist()])
            poles = tuple(-s * (1 + 0.5 * i) for i in range(k))
    poles = tuple(complex(p) if complex(p).imag else float(complex(p).real) for p in poles)
    every = np.concatenate([expand_poles(poles), fixed])
    stable = every[is_stable(every, discrete)] if every.size else every
    if discrete:
        slowest = max((abs(p) for p in stable), default=0.5)
        steps = int(np.clip(np.ceil(np.log(1e-3) / np.log(max(slowest, 1e-3))), 30, 300))
        default_t = np.arange(steps + 1.0) * (1.0 if plant.dt is True else plant.dt)
        lim: tuple[float, float] = (-1.1, 1.1)
    else:
        rate = min((-p.real for p in stable), default=1.0)
        default_t = np.linspace(0.0, 8.0 / rate, 1001)
        scale = max(abs(p) for p in [1.0, *expand_poles(poles).tolist(), *fixed.tolist()])
        lim = (-4.0 * scale, 0.4 * scale)
    t = np.asarray(default_t if timepts is None else timepts, dtype=float)
    span = float(t[-1] - t[0]) if t.size > 1 else 1.0
    step = float(t[1] - t[0]) if t.size > 1 else 1.0
    x0 = np.ones(plant.n) if initial_state is None else initial_state
    w = 2 * math.pi * 3 / span
    if reconstruct and (plant.q == 0 or rank(plant.E) < plant.q):
        raise ValueError("reconstruct=True needs unknown inputs with E of full column rank")
    real_first = bool(k and not complex(poles[0]).imag)
    if not real_first:
        static: tuple[float, ...] = (0.0, 0.5, 1.0, 2.0, 4.0)
    elif discrete:
        static = (-0.9, -0.5, 0.0, 0.5, 0.9, 1.05)
    else:
        static = tuple(float(complex(poles[0]).real) * f for f in (-0.5, 0.5, 1.0, 2.0, 4.0))
    return _scenario(
        plant,
        observer_family,
        name=name,
        title=title or plant.name or "plant",
        timepts=t,
        initial_state=x0,
        u=u,
        defaults=Settings(poles=poles, frequency=w, period=span / 6, decay=0.9, tau=0.0),
        pole_limits=lim,
        frequency_limits=(0.0, 180.0) if discrete else (0.0, -lim[0]),
        amplitude_limits=(0.0, 5.0),
        disturbance_frequency_limits=(w / 10, min(10 * w, math.pi / step)),
        period_limits=(max(step, span / 60), span / 2),
        noise_limits=(0.0, 0.5),
        tau_limits=(0.0, span / 20) if reconstruct else None,
        decay_limits=(0.3, 1.0) if observer_family == "pmo" and discrete else None,
        d_channels=tuple(Channel(speed=1.0 + 0.5 * i) for i in range(plant.q)),
        v_channels=tuple(Channel(gain=0.5, speed=2.0 + 0.5 * i) for i in range(plant.r)),
        static_values=static,
        static_control="pole" if real_first else "amplitude",
    )


# frames ----------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Frame:
    """Everything one picture of an explorer shows, for one setting of the controls.

    ``curves`` maps ``"<who>.<what>"`` to an array with one row per channel
    (``who`` is ``"uio"`` for the unknown input observer, ``"lb"`` for the
    Luenberger observer; ``what`` is ``"error"``, ``"residual"`` or
    ``"input"``), or to ``None`` when that curve is not available (a design
    that failed). The arrays are clipped to ``limits[what]`` for display;
    the unclipped values are in the responses.

    Attributes
    ----------
    scenario : Scenario
        The scenario.
    settings : Settings
        The control values.
    time : numpy.ndarray
        The time points.
    observer, luenberger : Observer or None
        The designed observers (``None`` if the design failed).
    response, luenberger_response : UIOResponse or None
        Their simulations.
    input_estimate, luenberger_input_estimate : InputEstimate or None
        The reconstructed unknown inputs (explorers with ``tau_limits``).
    d, v : numpy.ndarray
        The applied unknown signals, one row per channel.
    curves : dict
        The display curves (see above).
    limits : dict
        The clipping bound of each kind of curve.
    poles, luenberger_poles : numpy.ndarray
        The observers' error poles (empty when the design failed).
    observer_message, luenberger_message : str
        A short message about each observer ("" when all is well).
    messages : tuple of str
        General notes: clipped curves, an error that has not settled, a bad
        control value.
    disturbance : str
        A description of the disturbance.

    Examples
    --------
    >>> from uio_teach.explorer import compute_frame, pa9_scenario
    >>> s = pa9_scenario()
    >>> frame = compute_frame(s, s.defaults.replace(poles=(0.5, -2.0, -3.0)))
    >>> print(frame.observer_message)
    this pole makes the UIO unstable: the error grows (pole 0.5 in the right half-plane)
    >>> frame.curves["uio.error"].shape
    (3, 1001)
    """

    scenario: Scenario
    settings: Settings
    time: np.ndarray
    observer: Observer | None
    luenberger: Observer | None
    response: UIOResponse | None
    luenberger_response: UIOResponse | None
    input_estimate: InputEstimate | None
    luenberger_input_estimate: InputEstimate | None
    d: np.ndarray
    v: np.ndarray
    curves: dict[str, np.ndarray | None]
    limits: dict[str, float]
    poles: np.ndarray
    luenberger_poles: np.ndarray
    observer_message: str
    luenberger_message: str
    messages: tuple[str, ...]
    disturbance: str

    @property
    def all_messages(self) -> tuple[str, ...]:
        """Every message, observer first."""
        out = []
        if self.observer_message:
            out.append(f"{self.scenario.observer_name}: {self.observer_message}")
        if self.luenberger_message:
            out.append(f"Luenberger observer: {self.luenberger_message}")
        return (*out, *self.messages)


def format_poles(poles: Sequence[complex]) -> str:
    """Poles as short text, round-off (below 1e-9 of the largest modulus) shown as 0.

    Parameters
    ----------
    poles : sequence of complex
        The poles.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorer import format_poles
    >>> format_poles([8.9e-16, 0.5, -1 + 2j])
    '0, 0.5, -1 + 2j'
    """
    z = np.asarray(poles, dtype=complex)
    if not z.size:
        return ""
    tiny = 1e-9 * max(1.0, float(np.abs(z).max()))
    z = np.where(np.abs(z.real) < tiny, 0.0, z.real) + 1j * np.where(
        np.abs(z.imag) < tiny, 0.0, z.imag
    )
    return ", ".join(format_complex(p, 3) for p in z)


def _stability_message(name: str, poles: np.ndarray, discrete: bool) -> str:
    if not poles.size:
        return ""
    bad = poles[~is_stable(poles, discrete)]
    if not bad.size:
        return ""
    growing = np.abs(bad) > 1 + 1e-9 if discrete else bad.real > 1e-9 * np.maximum(1, abs(bad))
    where = "outside the unit circle" if discrete else "in the right half-plane"
    edge = "on the unit circle" if discrete else "on the imaginary axis"
    if np.any(growing):
        grow = bad[growing]
        word = "pole" if grow.size == 1 else "poles"
        this = "this pole makes" if grow.size == 1 else "these poles make"
        return f"{this} the {name} unstable: the error grows ({word} {format_poles(grow)} {where})"
    word = "pole" if bad.size == 1 else "poles"
    return f"{word} {format_poles(bad)} {edge}: the {name} error does not decay"


def _design(scenario: Scenario, s: Settings) -> tuple[Observer | None, str]:
    plant = scenario.plant
    name = scenario.observer_name
    report = scenario.existence
    if not report.ok:
        why = "; ".join(f"{c.name}: {c.reason}" for c in report.failed)
        return None, f"no {name} exists for this plant ({why})"
    lmi = s.mode == "lmi"
    if s.mode not in ("poles", "lmi") or (lmi and scenario.decay_limits is None):
        return None, f"unknown mode {s.mode!r} for this explorer"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if scenario.family == "ginverse":
                obs: Observer = design_ginverse(plant)
            elif lmi:
                key = ("lmi", float(s.decay))
                if key not in scenario._cache:
                    try:
                        scenario._cache[key] = design_pmo(plant, method="lmi", decay=s.decay)
                    except LMIInfeasibleError as exc:
                        scenario._cache[key] = exc
                if isinstance(scenario._cache[key], Exception):
                    raise scenario._cache[key]
                obs = scenario._cache[key]
            else:
                poles = expand_poles(s.poles)
                design = design_uio if scenario.family == "uio" else design_pmo
                obs = design(plant, poles=poles)
    except LMIInfeasibleError as exc:
        fixed = scenario.fixed_poles
        text = str(exc)
        if fixed.size:
            region = (
                f"radius {np.abs(fixed).max():.3g}"
                if scenario.discrete
                else f"real part {fixed.real.max():.3g}"
            )
            text += f"; the fixed poles (invariant zeros) at {region} cannot move"
        return None, text
    except Exception as exc:  # a bad pole list, a failed placement: say it, do not raise
        return None, f"cannot design the {name}: {exc}"
    return obs, _stability_message(name, obs.poles(), scenario.discrete)


def _luenberger(scenario: Scenario, s: Settings, obs: Observer | None):
    plant = scenario.plant
    if obs is not None:
        target = obs.poles()
    else:
        if scenario.family == "ginverse" or s.mode == "lmi":
            wanted = expand_poles(scenario.defaults.poles)
        else:
            try:
                wanted = expand_poles(s.poles)
            except (TypeError, ValueError):
                wanted = expand_poles(scenario.defaults.poles)
        target = np.concatenate([wanted, scenario.fixed_poles])
    try:
        poles = luenberger_poles(plant, target)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            lb = design_luenberger(plant, poles=poles)
    except Exception as exc:
        return None, f"cannot design it: {exc}"
    return lb, _stability_message("Luenberger observer", lb.poles(), scenario.discrete)


def _clip(arr: np.ndarray, limit: float) -> tuple[np.ndarray, bool]:
    out = np.array(arr, dtype=float)
    with np.errstate(invalid="ignore"):
        hit = bool(np.any(~(np.abs(out) <= limit) & ~np.isnan(out)))
    np.clip(out, -limit, limit, out=out)
    return out, hit


def _finite_max(*arrays: np.ndarray | None) -> float:
    best = 0.0
    for a in arrays:
        if a is None or not np.size(a):
            continue
        a = np.abs(np.asarray(a, dtype=float))
        a = a[np.isfinite(a)]
        if a.size:
            best = max(best, float(a.max()))
    return best


def compute_frame(scenario: Scenario, settings: Settings | None = None) -> Frame:
    """Design, simulate and prepare the curves of one explorer picture; never raises.

    The unknown input observer of ``scenario.family`` is designed with the
    settings' poles (or the LMI bound), the Luenberger observer with the poles
    of :func:`uio_teach.explorer.luenberger_poles`; both are simulated with
    :func:`uio_teach.simulate` on the same plant, inputs, noise (same seed)
    and initial state, with observer states starting at zero. Errors,
    residuals (and reconstructed inputs) are clipped for display at ten times
    the largest plant state, output (and unknown input) of the simulation.
    Anything that goes wrong becomes a message.

    Parameters
    ----------
    scenario : Scenario
        What to explore.
    settings : Settings, optional
        The control values; ``scenario.defaults`` by default.

    Returns
    -------
    Frame

    Examples
    --------
    An LMI bound below the fixed poles' radius is infeasible: a message, no
    exception.

    >>> from uio_teach.explorer import case_study_scenario, compute_frame
    >>> s = case_study_scenario()
    >>> frame = compute_frame(s, s.defaults.replace(mode="lmi", decay=0.4))
    >>> frame.observer is None, "cannot move" in frame.observer_message
    (True, True)
    >>> frame.curves["uio.error"] is None, frame.curves["lb.error"].shape
    (True, (3, 41))
    """
    s = scenario.defaults if settings is None else settings
    try:
        return _compute(scenario, s)
    except Exception as exc:  # pragma: no cover - a last resort: every known case is handled
        plant = scenario.plant
        t = scenario.timepts
        return Frame(
            scenario=scenario,
            settings=s,
            time=t,
            observer=None,
            luenberger=None,
            response=None,
            luenberger_response=None,
            input_estimate=None,
            luenberger_input_estimate=None,
            d=np.zeros((plant.q, t.size)),
            v=np.zeros((plant.r, t.size)),
            curves={},
            limits={},
            poles=np.zeros(0, complex),
            luenberger_poles=np.zeros(0, complex),
            observer_message="",
            luenberger_message="",
            messages=(f"could not compute this picture: {exc}",),
            disturbance="",
        )


def _compute(scenario: Scenario, s: Settings) -> Frame:
    plant = scenario.plant
    t = scenario.timepts
    N = t.size
    notes: list[str] = []

    # the unknown signals
    d = np.zeros((plant.q, N))
    v = np.zeros((plant.r, N))
    description = ""
    try:
        d_sig, v_sig = disturbance_signals(scenario, s)
        if d_sig:
            d = np.vstack([f(t) for f in d_sig])
        if v_sig:
            v = np.vstack([f(t) for f in v_sig])
        description = _describe(s.disturbance, s, scenario.discrete)
    except (ValueError, TypeError) as exc:
        notes.append(f"disturbance: {exc}; no disturbance applied")
    noise = s.noise
    if not isinstance(noise, int | float | np.number) or not np.isfinite(noise) or noise < 0:
        notes.append(f"the noise level must be a number >= 0, got {noise!r}; no noise applied")
        noise = 0.0
    kwargs: dict[str, Any] = {
        "u": scenario.u,
        "d": d if plant.q else None,
        "v": v if plant.r else None,
        "initial_state": scenario.initial_state,
        "noise": float(noise) if noise > 0 else None,
        "seed": s.seed,
    }

    obs, obs_msg = _design(scenario, s)
    lb, lb_msg = _luenberger(scenario, s, obs)

    responses: dict[str, UIOResponse | None] = {"uio": None, "lb": None}
    for key, o in (("uio", obs), ("lb", lb)):
        if o is None:
            continue
        try:
            with np.errstate(all="ignore"):
                responses[key] = simulate(plant, o, t, **kwargs)
        except Exception as exc:
            text = f"the simulation failed: {exc}"
            if key == "uio":
                obs_msg = text
            else:
                lb_msg = text

    estimates: dict[str, InputEstimate | None] = {"uio": None, "lb": None}
    if scenario.reconstruct:
        tau = s.tau
        if not isinstance(tau, int | float | np.number) or not np.isfinite(tau) or tau < 0:
            notes.append(f"tau must be a time constant >= 0, got {tau!r}; no filter used")
            tau = 0.0
        for key, resp in responses.items():
            if resp is None:
                continue
            try:
                with np.errstate(all="ignore"):
                    estimates[key] = (
                        reconstruct_input(plant, resp, method="filtered", tau=float(tau))
                        if tau > 0
                        else reconstruct_input(plant, resp)
                    )
            except Exception as exc:
                notes.append(f"input reconstruction failed: {exc}")

    # display: clip at ten times the size of the plant's own signals
    ok = [r for r in responses.values() if r is not None]
    size_x = _finite_max(scenario.initial_state, *(r.states for r in ok))
    size_y = _finite_max(*(r.outputs for r in ok))
    size_d = max(_finite_max(d), abs(float(scenario.defaults.amplitude)))
    limits = {
        "error": 10 * (size_x or 1.0),
        "residual": 10 * (size_y or size_x or 1.0),
        "input": 10 * (size_d or 1.0),
    }
    curves: dict[str, np.ndarray | None] = {}
    clipped: set[str] = set()
    for key, resp in responses.items():
        est = estimates[key]
        parts = {
            "error": None if resp is None else resp.error,
            "residual": None if resp is None else resp.residual,
        }
        if scenario.reconstruct:
            parts["input"] = None if est is None else est.estimates
        for what, arr in parts.items():
            if arr is None:
                curves[f"{key}.{what}"] = None
                continue
            curves[f"{key}.{what}"], hit = _clip(arr, limits[what])
            if hit:
                clipped.add(what)
    if clipped:
        which = " and ".join(sorted(clipped))
        notes.append(f"{which} curves are clipped for display (they leave the plotted range)")
    resp = responses["uio"]
    if resp is not None and not obs_msg and not kwargs["noise"]:
        err = np.abs(resp.error)
        top = float(np.max(err)) if err.size else 0.0
        tail = float(np.max(err[:, -max(1, N // 10) :])) if err.size else 0.0
        if top > 0 and tail > 0.05 * top:
            notes.append(
                "the error has not settled by the end of the window: the slowest pole is slow"
            )
    if scenario.reconstruct and s.tau == 0 and kwargs["noise"]:
        notes.append(
            "the numerical derivative amplifies the noise: try a filter time constant tau > 0"
        )
    return Frame(
        scenario=scenario,
        settings=s,
        time=t,
        observer=obs,
        luenberger=lb,
        response=responses["uio"],
        luenberger_response=responses["lb"],
        input_estimate=estimates["uio"],
        luenberger_input_estimate=estimates["lb"],
        d=d,
        v=v,
        curves=curves,
        limits=limits,
        poles=obs.poles() if obs is not None else np.zeros(0, complex),
        luenberger_poles=lb.poles() if lb is not None else np.zeros(0, complex),
        observer_message=obs_msg,
        luenberger_message=lb_msg,
        messages=tuple(notes),
        disturbance=description,
    )


# drawing ---------------------------------------------------------------------------------


def _nice_range(arrays: Sequence[np.ndarray | None]) -> tuple[float, float]:
    """Axis limits around the data, snapped outward to half-decades (stable under small changes)."""
    lo, hi = np.inf, -np.inf
    for a in arrays:
        if a is None or not np.size(a):
            continue
        a = np.asarray(a, dtype=float)
        a = a[np.isfinite(a)]
        if a.size:
            lo, hi = min(lo, float(a.min())), max(hi, float(a.max()))
    if not np.isfinite(lo) or hi - lo < 1e-12 * max(1.0, abs(lo), abs(hi)):
        mid = 0.0 if not np.isfinite(lo) else lo
        lo, hi = mid - max(1.0, abs(mid)) * 0.5, mid + max(1.0, abs(mid)) * 0.5
        if not np.isfinite(lo):
            return -1.0, 1.0
    pad = 0.06 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    unit = 10.0 ** math.floor(math.log10(max(abs(lo), abs(hi)))) / 2
    return math.floor(lo / unit) * unit, math.ceil(hi / unit) * unit


def _keep_range(
    current: tuple[float, float], wanted: tuple[float, float], fresh: bool
) -> tuple[float, float]:
    """Keep the current limits while the data fit and fill at least a third of them."""
    lo, hi = wanted
    if fresh or lo < current[0] or hi > current[1]:
        return wanted
    if (hi - lo) < (current[1] - current[0]) / 3:
        return wanted
    return current


def _inside(inner: Any, outer: Any, slack: float = 1.0) -> bool:
    return bool(
        inner.x0 >= outer.x0 - slack
        and inner.x1 <= outer.x1 + slack
        and inner.y0 >= outer.y0 - slack
        and inner.y1 <= outer.y1 + slack
    )


class ExplorerFigure:
    """The explorer's figure: built once, then updated in place for each frame.

    Columns: the unknown input observer, the Luenberger observer (rows: the
    error ``e = x - xhat``, the residual ``r = y - C xhat`` and, when the
    scenario reconstructs it, the unknown input with its reconstruction), and
    a side column with the pole map (``x`` observer poles, ``+`` Luenberger
    poles, ``o`` invariant zeros, which are the fixed poles; unit circle in
    discrete time) and the applied unknown signals. Rows share their
    vertical scale, so the two observers compare at a glance.

    :meth:`update` only changes the data of existing lines and texts
    (``set_data``, ``set_text``) and rescales the axes; :meth:`draw` renders
    with Agg. The figure is a plain :class:`matplotlib.figure.Figure` (no
    pyplot), so it is never shown twice in a notebook.

    Parameters
    ----------
    scenario : Scenario
        What the figure shows.
    dpi : float
        Resolution.
    figsize : tuple of float, optional
        Size in inches; (9, 4.8), or (9, 6.2) with the reconstruction row.
    sticky : bool
        Keep an axis range while the new data fit it and fill at least a
        third of it (fewer redraws, for live use); ``False`` gives every frame
        its own range (for pictures that must not depend on the previous one).

    Attributes
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    axes : dict
        The axes by name: ``"uio.error"``, ``"lb.error"``, ``"uio.residual"``,
        ``"lb.residual"`` (``"uio.input"``, ``"lb.input"``), ``"poles"``,
        ``"signals"``.
    lines : dict
        The lines of each curve by the name of the curve, one per channel.

    Examples
    --------
    >>> from uio_teach.explorer import ExplorerFigure, compute_frame, pa9_scenario
    >>> s = pa9_scenario()
    >>> ef = ExplorerFigure(s)
    >>> ef.update(compute_frame(s))
    >>> line = ef.lines["uio.error"][0]
    >>> before = line.get_ydata().copy()
    >>> ef.update(compute_frame(s, s.defaults.replace(poles=(-4.0, -5.0, -6.0))))
    >>> line is ef.lines["uio.error"][0], bool((line.get_ydata() != before).any())
    (True, True)
    >>> ef.to_png()[:4]
    b'\\x89PNG'
    """

    def __init__(
        self,
        scenario: Scenario,
        *,
        dpi: float = 90,
        figsize: tuple[float, float] | None = None,
        sticky: bool = True,
    ) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from matplotlib.ticker import MaxNLocator

        self.scenario = scenario
        plant = scenario.plant
        rows = ["error", "residual"] + (["input"] if scenario.reconstruct else [])
        side = ["poles"] * (len(rows) - 1) + ["signals"]
        mosaic = [[f"uio.{r}", f"lb.{r}", s] for r, s in zip(rows, side, strict=True)]
        if figsize is None:
            figsize = (9.0, 6.2) if scenario.reconstruct else (9.0, 4.8)
        fig = Figure(figsize=figsize, dpi=dpi)
        FigureCanvasAgg(fig)
        axes = fig.subplot_mosaic(
            mosaic,
            gridspec_kw={
                "width_ratios": [1.0, 1.0, 0.85],
                "left": 0.075,
                "right": 0.985,
                "top": 0.86,
                "bottom": 0.17 if not scenario.reconstruct else 0.13,
                "wspace": 0.42,
                "hspace": 0.5,
            },
        )
        self.fig = fig
        self.axes = axes
        self.lines: dict[str, list] = {}
        discrete = scenario.discrete
        style = {"drawstyle": "steps-post"} if discrete else {}
        xlabel = "step k" if plant.dt is True else "time (s)"
        sym = scenario.input_symbol
        for r in rows:
            axes[f"lb.{r}"].sharey(axes[f"uio.{r}"])
        counts = {"error": plant.n, "residual": plant.p, "input": plant.q}
        labels = {
            "error": lambda i: f"$e_{{{i + 1}}}$",
            "residual": lambda i: f"$r_{{{i + 1}}}$",
            "input": lambda i: f"$\\hat{{{sym}}}_{{{i + 1}}}$",
        }
        ylabels = {
            "error": r"error $e = x - \hat{x}$",
            "residual": r"residual $r = y - C\hat{x}$",
            "input": f"${sym}$ and $\\hat{{{sym}}}$",
        }
        for who in ("uio", "lb"):
            for r in rows:
                ax = axes[f"{who}.{r}"]
                if r == "input":
                    self.lines[f"{who}.actual"] = [
                        ax.plot([], [], color="0.45", lw=1.0, ls=":", **style)[0]
                        for _ in range(plant.q)
                    ]
                self.lines[f"{who}.{r}"] = [
                    ax.plot([], [], color=f"C{i}", lw=1.1, label=labels[r](i), **style)[0]
                    for i in range(counts[r])
                ]
                ax.grid(True, alpha=0.3)
                ax.yaxis.set_major_locator(MaxNLocator(5))
                ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
                if r != rows[-1]:
                    ax.tick_params(labelbottom=False)
                if who == "uio":
                    ax.set_ylabel(ylabels[r], fontsize=8)
                    if counts[r]:
                        ax.legend(**_LEGEND)
            axes[f"{who}.{rows[-1]}"].set_xlabel(xlabel, fontsize=8)
        axes["uio.error"].set_title(
            f"{scenario.observer_name} (decouples {sym})", fontsize=9, fontweight="bold"
        )
        axes["lb.error"].set_title(
            f"Luenberger observer (ignores {sym})", fontsize=9, fontweight="bold"
        )
        self.notes = {
            who: axes[f"{who}.error"].text(
                0.5,
                0.5,
                "",
                transform=axes[f"{who}.error"].transAxes,
                ha="center",
                va="center",
                fontsize=7.5,
                color="C3",
                zorder=10,
                bbox={"facecolor": "white", "edgecolor": "C3", "alpha": 0.9},
                visible=False,
            )
            for who in ("uio", "lb")
        }

        # side column: pole map and unknown signals
        pz = axes["poles"]
        pz.set_xlabel("real part", fontsize=8)
        pz.set_ylabel("imaginary part", fontsize=8)
        pz.grid(True, alpha=0.3)
        if discrete:
            theta = np.linspace(0, 2 * np.pi, 181)
            pz.plot(np.cos(theta), np.sin(theta), color="0.5", lw=0.8)
        else:
            pz.axvline(0.0, color="0.5", lw=0.8)
        pz.axhline(0.0, color="0.8", lw=0.6)
        zeros = scenario.invariant_zeros
        pz.plot(
            zeros.real,
            zeros.imag,
            "o",
            ms=9,
            mfc="none",
            mec="C2",
            mew=1.5,
            label="zeros = fixed poles",
        )
        self.lines["poles"] = pz.plot(
            [], [], "x", ms=8, mew=1.8, color="C3", label=scenario.observer_name
        )
        self.lines["luenberger poles"] = pz.plot(
            [], [], "+", ms=9, mew=1.2, color="C0", label="Luenberger"
        )
        pz.legend(
            loc="lower center",
            bbox_to_anchor=(0.5, 1.0),
            ncol=2,
            fontsize=6,
            frameon=False,
            handlelength=1.0,
            columnspacing=0.8,
            borderaxespad=0.2,
        )
        sig = axes["signals"]
        sig.set_ylabel("unknown inputs", fontsize=8)
        self.lines["d"] = [
            sig.plot([], [], color=f"C{i}", lw=1.0, label=f"${sym}_{{{i + 1}}}$", **style)[0]
            for i in range(plant.q)
        ]
        self.lines["v"] = [
            sig.plot(
                [], [], color=f"C{i + plant.q}", lw=1.0, ls="--", label=f"$v_{{{i + 1}}}$", **style
            )[0]
            for i in range(plant.r)
        ]
        if plant.q + plant.r:
            sig.legend(**_LEGEND)
        sig.set_xlabel(xlabel, fontsize=8)
        sig.grid(True, alpha=0.3)
        sig.yaxis.set_major_locator(MaxNLocator(5))
        sig.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
        for ax in axes.values():
            ax.tick_params(labelsize=7)
        self.title = fig.suptitle("", fontsize=10)
        self.footer = fig.text(0.01, 0.005, "", fontsize=7.5, ha="left", va="bottom", color="C3")
        self.frame: Frame | None = None
        self.full_draws = 0
        self.partial_draws = 0
        self._background: Any = None
        self._keys: dict[str, tuple] = {}
        self._cells: dict | None = None
        self._fresh = True
        self.sticky = sticky
        self._legend_boxes: list[tuple[int, int, int, int]] = []

    def update(self, frame: Frame) -> None:
        """Show a frame: new data in the existing lines and texts, axes rescaled.

        Parameters
        ----------
        frame : Frame
            The result of :func:`compute_frame` for this figure's scenario.

        Examples
        --------
        >>> from uio_teach.explorer import ExplorerFigure, case_study_scenario, compute_frame
        >>> s = case_study_scenario()
        >>> ef = ExplorerFigure(s)
        >>> ef.update(compute_frame(s, s.defaults.replace(poles=(1.05,))))
        >>> ef.notes["uio"].get_visible()
        True
        """
        self.frame = frame
        t = frame.time
        empty = np.zeros(0)
        for name, lines in self.lines.items():
            if name in ("poles", "luenberger poles", "d", "v") or name.endswith(".actual"):
                continue
            arr = frame.curves.get(name)
            for i, line in enumerate(lines):
                if arr is None:
                    line.set_data(empty, empty)
                else:
                    line.set_data(t, arr[i])
        for who in ("uio", "lb"):
            if f"{who}.actual" in self.lines:
                show = frame.curves.get(f"{who}.input") is not None
                for i, line in enumerate(self.lines[f"{who}.actual"]):
                    line.set_data((t, frame.d[i]) if show else (empty, empty))
        for i, line in enumerate(self.lines["d"]):
            line.set_data(t, frame.d[i])
        for i, line in enumerate(self.lines["v"]):
            line.set_data(t, frame.v[i])
        self.lines["poles"][0].set_data(frame.poles.real, frame.poles.imag)
        lp = frame.luenberger_poles
        self.lines["luenberger poles"][0].set_data(lp.real, lp.imag)
        for who, message in (("uio", frame.observer_message), ("lb", frame.luenberger_message)):
            note = self.notes[who]
            note.set_text(textwrap.fill(message, _WRAP))
            note.set_visible(bool(message))
        self.title.set_text(
            f"{self.scenario.title}: {frame.disturbance}"
            + (f", noise {frame.settings.noise:.3g}" if frame.settings.noise else "")
        )
        self.footer.set_text(textwrap.fill("; ".join(frame.messages), 150))
        rows = {name.split(".")[1] for name in self.axes if name.startswith("uio.")}
        for row in rows:
            data = [frame.curves.get(f"{who}.{row}") for who in ("uio", "lb")]
            if row == "input":
                data.append(frame.d)
            ax = self.axes[f"uio.{row}"]
            ax.set_ylim(
                *_keep_range(ax.get_ylim(), _nice_range(data), self._fresh or not self.sticky)
            )
        sig = self.axes["signals"]
        wanted = _nice_range([frame.d, frame.v])
        sig.set_ylim(*_keep_range(sig.get_ylim(), wanted, self._fresh or not self.sticky))
        self._fresh = False
        if len(t) > 1:
            for name, ax in self.axes.items():
                if name != "poles":
                    ax.set_xlim(t[0], t[-1])
        self._scale_pole_map(frame)

    def _scale_pole_map(self, frame: Frame) -> None:
        """Limits covering the controls' range (a pole moves on a still map), wider if needed."""
        ax = self.axes["poles"]
        sc = self.scenario
        pts = np.concatenate([frame.poles, frame.luenberger_poles, sc.invariant_zeros])
        pts = pts[np.isfinite(pts)]
        if sc.discrete:
            r = max(1.25, sc.pole_limits[1] * 1.1, *(1.1 * np.abs(pts)).tolist())
            lim = _nice_range([np.array([-r, r])])
            ax.set_xlim(*lim)
            ax.set_ylim(*lim)
            return
        base_re = np.array([*sc.pole_limits, 0.0])
        zeros_im = float(np.abs(sc.invariant_zeros.imag).max()) if sc.invariant_zeros.size else 0
        base_im = max(
            0.5 * sc.frequency_limits[1],
            1.2 * zeros_im,
            0.3 * (sc.pole_limits[1] - sc.pole_limits[0]),
        )
        x0, x1 = _nice_range([base_re, pts.real])
        y = _nice_range([np.array([-base_im, base_im]), pts.imag, -pts.imag])[1]
        ax.set_xlim(x0, x1)
        ax.set_ylim(-y, y)

    def draw(self) -> None:
        """Render the figure with Agg, redrawing only what changed.

        A copy of the figure without its curves, markers and messages (axes,
        ticks, legends, titles) is kept. Each call paints the copy back,
        draws the curves, markers and messages on it, and paints the legends
        back over the curves (blitting). When an axis range changes, only that
        panel is redrawn into the copy (each panel owns a fixed cell of the
        figure), and a changed title or footer only its band. The first call,
        or a panel or text that would not fit its place, renders everything
        (``fig.canvas.draw()``). The figure stays an ordinary figure:
        ``fig.savefig`` draws everything.

        Examples
        --------
        >>> from uio_teach.explorer import ExplorerFigure, compute_frame, pa9_scenario
        >>> s = pa9_scenario()
        >>> ef = ExplorerFigure(s)
        >>> ef.update(compute_frame(s))
        >>> ef.draw()
        >>> ef.update(compute_frame(s, s.defaults.replace(poles=(-1.5, -2.0, -3.0))))
        >>> ef.draw()      # same axis ranges: only the changing artists are redrawn
        >>> ef.full_draws
        1
        """
        canvas = self.fig.canvas
        keys = {name: (*ax.get_xlim(), *ax.get_ylim()) for name, ax in self.axes.items()}
        keys["title"] = (self.title.get_text(),)
        keys["footer"] = (self.footer.get_text(),)
        changed = [name for name, key in keys.items() if self._keys.get(name) != key]
        if self._background is None or changed:
            dynamic = self._dynamic_artists()
            for artist in dynamic:
                artist.set_animated(True)
            try:
                if self._background is None or not self._cells or not self._redraw(changed):
                    canvas.draw()
                    self.full_draws += 1
                    if self._cells is None:
                        self._cells = self._find_cells()
                self._background = canvas.copy_from_bbox(self.fig.bbox)
                self._keys = keys
                self._legend_boxes = self._legend_regions()
            finally:
                for artist in dynamic:
                    artist.set_animated(False)
        else:
            canvas.restore_region(self._background)
        renderer = canvas.get_renderer()
        notes = list(self.notes.values())
        for artist in self._dynamic_artists():
            if artist.get_visible() and artist not in notes:
                artist.draw(renderer)
        for box in self._legend_boxes:  # the legends cover the curves, as in a full draw
            # xy: where the stored region's corner goes (the whole figure: no shift)
            canvas.restore_region(self._background, bbox=box, xy=(0, 0))
        for note in notes:
            if note.get_visible():
                note.draw(renderer)

    def _legend_regions(self) -> list[tuple[int, int, int, int]]:
        """The boxes of the legends inside panels, in Agg pixels (origin top left)."""
        renderer = self.fig.canvas.get_renderer()
        H = int(round(self.fig.bbox.height))
        out = []
        for ax in self.axes.values():
            legend = ax.get_legend()
            if legend is None or not legend.get_visible():
                continue
            box = legend.get_frame().get_window_extent(renderer)
            if not ax.bbox.contains(box.x0 + 1, box.y0 + 1):
                continue  # outside the panel: no curve crosses it
            x0, x1 = math.floor(box.x0), math.ceil(box.x1)
            y0, y1 = H - math.ceil(box.y1), H - math.floor(box.y0)
            out.append((x0, y0, x1, y1))
        return out

    def _redraw(self, names: list[str]) -> bool:
        """Redraw some panels or texts into the stored background; False if one leaves its place."""
        from matplotlib.patches import Rectangle
        from matplotlib.transforms import IdentityTransform

        canvas = self.fig.canvas
        renderer = canvas.get_renderer()
        canvas.restore_region(self._background)
        color = self.fig.get_facecolor()
        for name in names:
            box = self._cells[name]
            blank = Rectangle(
                (box.x0, box.y0),
                box.width,
                box.height,
                transform=IdentityTransform(),
                facecolor=color,
                edgecolor="none",
                antialiased=False,
            )
            blank.draw(renderer)
            artist = {"title": self.title, "footer": self.footer}.get(name) or self.axes[name]
            artist.draw(renderer)
            if not artist.get_visible() or (
                isinstance(artist, type(self.title)) and not artist.get_text()
            ):
                continue
            tight = (
                artist.get_tightbbox(renderer)
                if name in self.axes
                else artist.get_window_extent(renderer)
            )
            if tight is None or not _inside(tight, box):
                return False  # a wider tick label or a longer text: render everything
        self.partial_draws += 1
        return True

    def _find_cells(self) -> dict:
        """Each panel's cell and the title and footer bands (pixels), or {} if they overlap."""
        from matplotlib.transforms import Bbox

        renderer = self.fig.canvas.get_renderer()
        W, H = self.fig.bbox.width, self.fig.bbox.height
        tight = {name: ax.get_tightbbox(renderer) for name, ax in self.axes.items()}
        top = max(t.y1 for t in tight.values())
        bottom = min(t.y0 for t in tight.values())
        title = self.title.get_window_extent(renderer)
        if title.y0 <= top + 2:
            return {}
        title_cut = (top + title.y0) / 2
        footer_cut = bottom - 1
        pos = {name: ax.get_position() for name, ax in self.axes.items()}
        lefts = sorted({round(p.x0, 6) for p in pos.values()})
        columns = [[n for n, p in pos.items() if round(p.x0, 6) == x] for x in lefts]
        cuts = [0.0]
        for left, right in itertools.pairwise(columns):
            a = max(tight[n].x1 for n in left)
            b = min(tight[n].x0 for n in right)
            cuts.append((a + b) / 2)
        cuts.append(W)
        cells = {
            "title": Bbox.from_extents(0, title_cut, W, H),
            "footer": Bbox.from_extents(0, 0, W, footer_cut),
        }
        for c, names in enumerate(columns):
            for name in names:
                p = tight[name]
                above = [tight[n].y0 for n in names if tight[n].y0 >= p.y1 - 1e-6 and n != name]
                below = [tight[n].y1 for n in names if tight[n].y1 <= p.y0 + 1e-6 and n != name]
                y1 = (p.y1 + min(above)) / 2 if above else title_cut
                y0 = (p.y0 + max(below)) / 2 if below else footer_cut
                cells[name] = Bbox.from_extents(cuts[c], y0, cuts[c + 1], y1)
        if any(not _inside(tight[n], cells[n]) for n in self.axes):
            return {}
        return cells

    def _dynamic_artists(self) -> list:
        """What changes between frames and is drawn on the stored background: curves,
        markers and messages (legends, titles and the footer belong to the background)."""
        out: list = []
        for lines in self.lines.values():
            out += lines
        return [*out, *self.notes.values()]

    def to_png(
        self, *, colors: int | None = None, draw: bool = True, compress_level: int | None = None
    ) -> bytes:
        """The figure as PNG bytes, optionally with a reduced palette (much smaller files).

        Parameters
        ----------
        colors : int, optional
            Quantize to this many colours (e.g. 64) and optimize the PNG: for
            the static book's frames. ``None`` keeps full colour and encodes
            fast (for the live widget).
        draw : bool
            Render first; ``False`` reuses the last :meth:`draw`.
        compress_level : int, optional
            zlib level of the PNG (default 6 with ``colors``, 1 without).

        Returns
        -------
        bytes

        Examples
        --------
        >>> from uio_teach.explorer import ExplorerFigure, compute_frame, pa9_scenario
        >>> s = pa9_scenario()
        >>> ef = ExplorerFigure(s, dpi=60)
        >>> ef.update(compute_frame(s))
        >>> len(ef.to_png(colors=32)) < len(ef.to_png())
        True
        """
        import io

        from PIL import Image

        if draw:
            self.draw()
        rgba = np.asarray(self.fig.canvas.buffer_rgba())
        img = Image.fromarray(rgba[..., :3])
        buf = io.BytesIO()
        if colors:
            img = img.quantize(colors=colors, method=Image.Quantize.FASTOCTREE, dither=0)
            img.save(buf, format="png", compress_level=compress_level or 6)
        else:
            img.save(buf, format="png", compress_level=compress_level or 1)
        return buf.getvalue()


def render(scenario: Scenario, settings: Settings | None = None, *, dpi: float = 90) -> Figure:
    """One explorer picture as a new figure, built from scratch (no widget needed).

    Parameters
    ----------
    scenario : Scenario
        What to explore.
    settings : Settings, optional
        The control values; the scenario's defaults by default.
    dpi : float
        Resolution.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from uio_teach.explorer import missile_scenario, render
    >>> fig = render(missile_scenario())
    >>> len(fig.axes)
    8
    """
    ef = ExplorerFigure(scenario, dpi=dpi)
    ef.update(compute_frame(scenario, settings))
    return ef.fig
