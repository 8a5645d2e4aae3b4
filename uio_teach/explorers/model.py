"""The explorer's model: what is explored (:class:`Scenario`) and the values of its controls.

* a :class:`Scenario` says *what* is explored: the plant, the observer family,
  the time grid, the initial state and the ranges of the controls (built by
  :mod:`uio_teach.explorers.scenarios`);
* a :class:`Settings` holds the values of the controls: the movable observer
  poles (or the LMI bound), the disturbance type, amplitude, frequency or
  switching period, the measurement-noise level and the filter time constant
  of the input reconstruction;
* a :class:`Channel` says how one unknown signal follows the disturbance
  controls, and :func:`disturbance_signals` makes those signals.

Examples
--------
>>> from uio_teach.explorers import Settings, expand_poles
>>> Settings(poles=(-1 + 2j, -3.0)).replace(amplitude=2.0).amplitude
2.0
>>> expand_poles([-1 + 2j, -3]).tolist()
[(-1+2j), (-1-2j), (-3+0j)]
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import signals
from ..errors import InputError
from ..existence import ExistenceReport
from ..observers.reduced import reduced_movable
from ..plant import Plant

__all__ = [
    "DISTURBANCES",
    "FAMILIES",
    "STARTS",
    "Channel",
    "PlantControl",
    "Settings",
    "Scenario",
    "expand_poles",
    "disturbance_signals",
    "default_poles",
    "default_timepts",
]

DISTURBANCES = ("sinusoid", "piecewise constant", "damped sinusoid", "random steps")
"""The disturbance types an explorer offers."""

FAMILIES = {
    "uio": "UIO",
    "pmo": "PMO",
    "ginverse": "g-inverse observer",
    "reduced": "reduced-order UIO",
}
"""Observer families, each argument value with its display name."""

STARTS = {
    "zero estimate": "the estimate starts at zero, so the first error is the state itself",
    "zero observer state": "the observer's own state starts at zero",
}
"""Where the observers start, each control value with what it means.

``"zero estimate"`` (the default) starts both observers at ``xhat(0) = 0``: the
initial error ``e(0) = x(0)`` then reaches every mode of the error dynamics that
``x(0)`` reaches, the movable ones included. ``"zero observer state"`` starts the
observer's state at zero (``z(0) = 0``): its first estimate is ``xhat(0) = H y(0)``
(``M y(0)``), and the initial error may lie in the fixed
modes alone, so that moving a pole changes nothing.
"""


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
    >>> from uio_teach.explorers import Channel
    >>> Channel(gain=5, speed=10, decay=0.05)   # the missile paper's v2 = 50 exp(-5t) sin(100t)
    Channel(gain=5, speed=10, decay=0.05, kind='sin')
    """

    gain: float = 1.0
    speed: float = 1.0
    decay: float = 0.2
    kind: str = "sin"


@dataclass(frozen=True)
class PlantControl:
    """A slider of a declared field of the experiment (a valve, a gain): moving it remakes the run.

    Attributes
    ----------
    name : str
        The keyword of the scenario's ``rebuild`` (a field of the experiment).
    label : str
        The slider's label.
    doc : str
        What it is, one line (the slider's tooltip).
    limits : (float, float)
        Its range.
    value : float
        Its value in this scenario.

    Examples
    --------
    >>> from uio_teach.explorers import PlantControl
    >>> PlantControl("gamma1", "gamma1", "valve 1", (0.1, 0.9), 0.7).value
    0.7
    """

    name: str
    label: str
    doc: str
    limits: tuple[float, float]
    value: float


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
    start : str
        Where the observers start, one of ``STARTS``.

    Examples
    --------
    >>> from uio_teach.explorers import Settings
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
    start: str = "zero estimate"

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
        >>> from uio_teach.explorers import Settings
        >>> Settings().replace(amplitude=2.0).amplitude
        2.0
        """
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True, eq=False)
class Scenario:
    """What an explorer explores: the plant, the observer, the time grid and the control ranges.

    Build one with :func:`~uio_teach.explorers.scenario_of` (a worked example)
    or :func:`make_scenario`.

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
        The plant's initial state (where the observers start is a control,
        ``Settings.start``).
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
    static_control : str
        The main control: ``"pole"``, the first movable pole; ``"amplitude"``
        (no movable pole), the disturbance amplitude; or ``"plant:<name>"``,
        the plant control ``<name>`` of ``plant_controls`` (each of the static
        book's frames then has its own plant).
    input_symbol : str
        The symbol of the unknown input in the figure (``"d"``, or ``"v"`` for
        the missile paper).
    plant_controls : tuple of PlantControl
        Sliders of the experiment's own fields, each declared with a range (a valve of
        the plant, ...); empty: the run is fixed.
    rebuild : callable or None
        ``rebuild(**values)``: the scenario with other values of the plant
        controls (the explorer swaps its scenario when one moves).
    note : str
        A sentence on this plant that the explorer shows above its messages
        (say, why no unknown input observer exists for these valves).
    cache : dict
        Designs kept between frames (the LMI's gain for each bound, which
        takes a solver run); empty at first.

    Examples
    --------
    >>> from uio_teach.explorers import scenario_of
    >>> s = scenario_of("missile")
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
    plant_controls: tuple[PlantControl, ...] = ()
    rebuild: Callable[..., Scenario] | None = field(default=None, repr=False)
    note: str = ""
    cache: dict = field(default_factory=dict, repr=False)

    @property
    def movable(self) -> int:
        """How many observer poles the controls set (0 for the g-inverse observer)."""
        if self.family == "reduced":
            return reduced_movable(self.plant, self.existence)
        return 0 if self.family == "ginverse" else self.existence.movable

    @property
    def fixed_poles(self) -> np.ndarray:
        """The observer poles no gain moves (the invariant zeros)."""
        return self.existence.fixed_modes

    @property
    def invariant_zeros(self) -> np.ndarray:
        """The plant's invariant zeros from the unknown inputs to the outputs."""
        return self.existence.invariant_zeros

    @property
    def static_plant_control(self) -> PlantControl | None:
        """The plant control the static book's slider moves (``None`` for a pole or
        the amplitude)."""
        if not self.static_control.startswith("plant:"):
            return None
        name = self.static_control.split(":", 1)[1]
        for control in self.plant_controls:
            if control.name == name:
                return control
        raise InputError(f"static_control names no plant control: {self.static_control!r}")

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
    >>> from uio_teach.explorers import expand_poles
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
        raise InputError(f"the switching period must be positive, got {settings.period!r}")
    count = int(math.ceil((t1 - t0) / period)) + 1
    if count > 100_000:
        raise InputError(f"the switching period {settings.period:g} is too short for this window")
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
    >>> from uio_teach.explorers import disturbance_signals, scenario_of
    >>> s = scenario_of("missile")
    >>> disturbance_signals(s, s.defaults)[0]   # the paper's unknown inputs
    [10 exp(-2 t) cos(10 t), 50 exp(-5 t) sin(100 t)]
    """
    kind = settings.disturbance
    if kind not in DISTURBANCES:
        raise InputError(f"unknown disturbance type {kind!r}; choose one of {DISTURBANCES}")
    for name in ("amplitude", "frequency", "period"):
        value = getattr(settings, name)
        if not isinstance(value, int | float | np.number) or not np.isfinite(value):
            raise InputError(f"the {name} must be a finite number, got {value!r}")
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


# default poles and time grid for any plant -----------------------------------------------

SAMPLES_PER_PERIOD = 20
"""The default grid samples the fastest oscillation of the default poles this finely."""


def default_poles(
    count: int, discrete: bool, size: float = 1.0, avoid: Sequence[complex] = ()
) -> tuple[float, ...]:
    """Starting values for ``count`` movable poles, none on (or next to) a value to avoid.

    Discrete time: real poles from 0.5 down in steps of 0.1 (then the values
    in between); continuous time: ``-size``, ``-1.5 size``, ``-2 size``, ...
    A candidate closer than 5 % of the scale (0.05 in discrete time) to an
    entry of ``avoid`` -- the plant's invariant zeros, which are fixed observer
    poles -- is skipped, so an explorer never opens with a pole on a fixed one.

    Parameters
    ----------
    count : int
        How many movable poles.
    discrete : bool
        Discrete time.
    size : float
        Continuous time: the magnitude of the first pole (the plant's fastest
        mode, at least 1).
    avoid : sequence of complex
        Values the poles keep away from.

    Returns
    -------
    tuple of float

    Examples
    --------
    >>> from uio_teach.explorers import default_poles
    >>> default_poles(1, True, avoid=[0.5])
    (0.4,)
    >>> default_poles(2, False, size=2.0, avoid=[-2.0])
    (-3.0, -4.0)
    """
    avoid = np.asarray(avoid, dtype=complex).ravel()
    if discrete:
        gap = 0.05
        candidates = [round(0.5 - 0.1 * i, 10) for i in range(5)]
        candidates += [round(0.45 - 0.1 * i, 10) for i in range(5)]
        candidates += [round(-0.1 - 0.1 * i, 10) for i in range(5)]
    else:
        gap = 0.05 * size
        candidates = [-size * (1 + 0.5 * i) for i in range(4 * count + 8)]
    out: list[float] = []
    for c in candidates:
        if len(out) == count:
            break
        near = [*avoid.tolist(), *out]
        if all(abs(c - z) > gap for z in near):
            out.append(float(c))
    while len(out) < count:  # more poles than candidates: fall back to a plain spread
        out.append(float(0.5 - 0.1 * len(out) if discrete else -size * (1 + 0.5 * len(out))))
    return tuple(out)


def default_timepts(
    poles: Sequence[complex], discrete: bool, dt: float | bool | None = None, samples: int = 1001
) -> np.ndarray:
    """A time grid that shows the error settle and samples its oscillations finely.

    Discrete time: enough steps (30 to 300) for the slowest stable pole to
    shrink the error a thousandfold. Continuous time: ``samples`` points over
    eight time constants of the slowest stable pole, but at most as long as
    gives :data:`SAMPLES_PER_PERIOD` samples a period of the fastest
    oscillating pole -- a lightly damped pair would otherwise stretch the
    window so far that its oscillation is drawn with a point or two a period,
    in wiggles that do not exist (aliasing). The explorer then says that the
    window is set by the oscillation and how long settling would take.

    Parameters
    ----------
    poles : sequence of complex
        Every observer pole (movable and fixed).
    discrete : bool
        Discrete time.
    dt : float or True, optional
        The sampling time of a discrete plant (``True``: steps).
    samples : int
        Continuous time: the number of points.

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> from uio_teach.explorers import default_timepts
    >>> float(default_timepts([-1.0, -2.0], False)[-1])
    8.0
    >>> t = default_timepts([-0.01 + 10j, -0.01 - 10j, -10.0], False)
    >>> round(float(t[-1]), 2), t.size        # 50 periods of 0.63 s, not 800 s
    (31.42, 1001)
    """
    every = np.asarray(poles, dtype=complex).ravel()
    if discrete:
        stable = every[np.abs(every) < 1]
        slowest = float(np.abs(stable).max()) if stable.size else 0.5
        steps = int(np.clip(np.ceil(np.log(1e-3) / np.log(max(slowest, 1e-3))), 30, 300))
        return np.arange(steps + 1.0) * (1.0 if dt is True or dt is None else float(dt))
    stable = every[every.real < 0]
    rate = float((-stable.real).min()) if stable.size else 1.0
    span = 8.0 / rate
    fastest = float(np.abs(stable.imag).max()) if stable.size else 0.0
    if fastest > 0:
        span = min(span, (samples - 1) * 2 * math.pi / (SAMPLES_PER_PERIOD * fastest))
    return np.linspace(0.0, span, samples)
