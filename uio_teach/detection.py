"""Fault detection with unknown input observers: faults, residuals, thresholds and alarms.

A fault ``f`` acts on the plant through its own directions (Chen and Patton's
notation ``R1``, ``R2``)::

    x' = A x + B u + E d + R1 f,        y = C x + D v + R2 f

An actuator fault ``i`` has ``R1 = B[:, i]``, a sensor fault ``j`` has
``R2 = e_j``. The UIO's residual ``r = y - C xhat`` obeys (``H D = 0``,
``K1 D = 0``, so ``v`` does not enter the error)::

    e' = F e + T R1 f - K1 R2 f - H R2 f',        r = C e + D v + R2 f

so an actuator or process fault shows in ``r`` unless ``T R1 = 0``, that is
unless it enters through ``E`` (``R1`` in the range of ``E``). This module
simulates faults (:func:`simulate_fault`), turns a residual into an alarm
(:func:`residual_rms`, :func:`residual_threshold`, :func:`detect`) and measures
how well that works (:func:`false_alarm_rate`, :func:`detection_time`). The
bank of observers that isolates a fault is in :mod:`uio_teach.isolation`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Any

import numpy as np

from ._display import call_repr
from ._validation import as_matrix, read_only
from .errors import InputError
from .observers import Observer
from .plant import Plant, check_plant
from .simulation import UIOResponse, check_timepts, input_samples, linear_response, simulate

__all__ = [
    "Fault",
    "actuator_fault",
    "sensor_fault",
    "process_fault",
    "simulate_fault",
    "observer_residual",
    "residual_rms",
    "Threshold",
    "residual_threshold",
    "Detection",
    "detect",
    "false_alarm_rate",
    "detection_time",
]


# faults -------------------------------------------------------------------------------------


class _Num(float):
    """A float shown with 4 significant digits in a repr."""

    def __repr__(self) -> str:
        return f"{float(self):.4g}"


@dataclass(frozen=True)
class Fault:
    """A scalar fault signal ``f(t)`` and the directions it acts through.

    ``x' = A x + B u + E d + state_direction f``,
    ``y = C x + D v + output_direction f``. Build one with
    :func:`actuator_fault`, :func:`sensor_fault` or :func:`process_fault`.

    Attributes
    ----------
    name : str
        A label such as ``"actuator 1"``.
    kind : str
        ``"actuator"``, ``"sensor"`` or ``"process"``.
    index : int or None
        The failed actuator (column of ``B``) or sensor (row of ``C``),
        counted from 0; ``None`` for a process fault.
    state_direction : numpy.ndarray
        Shape (n,): ``R1``.
    output_direction : numpy.ndarray
        Shape (p,): ``R2``.
    signal : collections.abc.Callable
        The fault's size against time, a vectorized callable (see
        :mod:`uio_teach.signals`).

    Examples
    --------
    >>> import uio_teach as ut
    >>> f = ut.actuator_fault(ut.examples.pa9(), 0, ut.signals.step(0.5, 2.0))
    >>> f.name, f.state_direction.tolist(), f.output_direction.tolist()
    ('actuator 1', [0.0, 4.0, 0.0], [0.0, 0.0])
    """

    name: str
    kind: str
    index: int | None
    state_direction: np.ndarray
    output_direction: np.ndarray
    signal: Callable[[np.ndarray], Any]

    def __repr__(self) -> str:
        return call_repr("Fault", [("name", self.name), ("kind", self.kind), ("index", self.index)])


def _check_index(name: str, index: Any, size: int, what: str) -> int:
    if isinstance(index, bool) or not isinstance(index, Integral):
        raise InputError(f"{name} must be an integer index, got {index!r}")
    if not 0 <= int(index) < size:
        raise InputError(
            f"{name} = {index} is out of range: the plant has {size} {what} (0 to {size - 1})"
        )
    return int(index)


def _checkinput_samples(signal: Any) -> Callable:
    if not callable(signal):
        raise InputError(
            f"signal must be a callable of time (e.g. ut.signals.step(1.0, 2.0)), got "
            f"{type(signal).__name__}"
        )
    return signal


def actuator_fault(plant: Plant, index: int, signal: Callable) -> Fault:
    """A fault of actuator ``index``: the input acts as ``u_i + f`` (``R1 = B[:, i]``).

    Parameters
    ----------
    plant : Plant
        The plant.
    index : int
        The failed actuator, counted from 0 (a column of ``B``).
    signal : callable
        The fault ``f(t)``, added to the actuator's input.

    Returns
    -------
    Fault

    Examples
    --------
    >>> import uio_teach as ut
    >>> ut.actuator_fault(ut.examples.pa9(), 1, ut.signals.step(1.0)).state_direction
    array([0., 0., 1.])
    """
    plant = check_plant(plant)
    i = _check_index("index", index, plant.m, "actuators (columns of B)")
    return Fault(
        name=f"actuator {i + 1}",
        kind="actuator",
        index=i,
        state_direction=read_only(plant.B[:, i]),
        output_direction=read_only(np.zeros(plant.p)),
        signal=_checkinput_samples(signal),
    )


def sensor_fault(plant: Plant, index: int, signal: Callable) -> Fault:
    """A fault of sensor ``index``: its reading becomes ``y_j + f`` (``R2 = e_j``).

    Parameters
    ----------
    plant : Plant
        The plant.
    index : int
        The failed sensor, counted from 0 (a row of ``C``).
    signal : callable
        The fault ``f(t)``, added to the sensor's reading.

    Returns
    -------
    Fault

    Examples
    --------
    >>> import uio_teach as ut
    >>> ut.sensor_fault(ut.examples.pa9(), 1, ut.signals.step(1.0)).output_direction
    array([0., 1.])
    """
    plant = check_plant(plant)
    j = _check_index("index", index, plant.p, "sensors (rows of C)")
    return Fault(
        name=f"sensor {j + 1}",
        kind="sensor",
        index=j,
        state_direction=read_only(np.zeros(plant.n)),
        output_direction=read_only(np.eye(plant.p)[j]),
        signal=_checkinput_samples(signal),
    )


def process_fault(
    plant: Plant, direction: Any, signal: Callable, *, name: str = "process"
) -> Fault:
    """A fault acting on the state along ``direction`` (``R1 = direction``).

    Parameters
    ----------
    plant : Plant
        The plant.
    direction : array_like, shape (n,)
        How the fault enters the state equation. ``plant.E[:, 0]`` gives a
        fault that a UIO decoupling ``E`` cannot see.
    signal : callable
        The fault ``f(t)``.
    name : str, optional
        A label.

    Returns
    -------
    Fault

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> ut.process_fault(plant, plant.E[:, 0], ut.signals.step(1.0), name="through E").name
    'through E'
    """
    plant = check_plant(plant)
    R1 = as_matrix("direction", direction, plant.n, 1, what="n: one entry per state")
    return Fault(
        name=str(name),
        kind="process",
        index=None,
        state_direction=read_only(R1[:, 0]),
        output_direction=read_only(np.zeros(plant.p)),
        signal=_checkinput_samples(signal),
    )


def faulty_plant(plant: Plant, fault: Fault) -> Plant:
    """The plant with the fault as one more unknown input and one more measurement disturbance.

    ``E_f = [E, R1]``, ``D_f = [D, R2]``: simulating it with ``d = [d; f]``
    and ``v = [v; f]`` simulates the fault.

    Parameters
    ----------
    plant : Plant
        The fault-free plant.
    fault : Fault
        A fault built for this plant.

    Returns
    -------
    Plant

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> faulty_plant(plant, ut.sensor_fault(plant, 0, ut.signals.step(1.0)))
    Plant('PA9 with sensor 1 fault', continuous-time, n=3, m=2, q=2, p=2, nv=1)
    """
    plant = check_plant(plant)
    if not isinstance(fault, Fault):
        raise InputError(f"fault must be a Fault (actuator_fault, ...), got {type(fault).__name__}")
    if fault.state_direction.shape != (plant.n,) or fault.output_direction.shape != (plant.p,):
        raise InputError(
            f"fault was built for a plant with n = {fault.state_direction.size} and "
            f"p = {fault.output_direction.size}, but this plant has n = {plant.n}, p = {plant.p}"
        )
    label = f"{plant.name} with {fault.name} fault" if plant.name else f"{fault.name} fault"
    return Plant(
        plant.A,
        plant.C,
        B=plant.B,
        E=np.hstack([plant.E, fault.state_direction[:, None]]),
        D=np.hstack([plant.D, fault.output_direction[:, None]]),
        dt=plant.dt,
        name=label,
    )


def simulate_fault(
    plant: Plant,
    observer: Observer,
    timepts: Any,
    fault: Fault | None = None,
    *,
    u: Any = None,
    d: Any = None,
    v: Any = None,
    initial_state: Any = None,
    observer_state: Any = None,
    noise: Any = None,
    seed: int | np.random.Generator | None = None,
) -> UIOResponse:
    """Simulate a plant with a fault together with an observer designed for the healthy plant.

    Parameters
    ----------
    plant : Plant
        The healthy plant (the observer's model).
    observer : Observer
        Any observer of the package, designed for ``plant``.
    timepts : array_like, shape (N,)
        Time points, as in :func:`uio_teach.simulate`.
    fault : Fault, optional
        The fault; ``None`` simulates the healthy plant.
    u, d, v : callable or array_like, optional
        Known input, unknown input and measurement disturbance, as in
        :func:`uio_teach.simulate`.
    initial_state : array_like, shape (n,), optional
        Plant state at ``timepts[0]``.
    observer_state : array_like, optional
        Observer state at ``timepts[0]``.
    noise : float or array_like, shape (p,), optional
        Standard deviation of white measurement noise per output.
    seed : int or numpy.random.Generator, optional
        Seed of the noise.

    Returns
    -------
    UIOResponse
        Its ``residual`` is ``y - C xhat`` with the faulty ``y``. With a fault,
        ``response.plant`` is the plant with the fault as an extra unknown
        input and measurement disturbance, and ``response.inputs.d[-1]``
        holds the fault's samples.

    Examples
    --------
    An actuator fault shows in the residual of PA9's UIO:

    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> uio = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> t = np.linspace(0, 10, 1001)
    >>> fault = ut.actuator_fault(plant, 1, ut.signals.step(1.0, 2.0))
    >>> resp = ut.simulate_fault(plant, uio, t, fault)
    >>> float(np.abs(resp.residual[:, t < 2]).max()), bool(np.abs(resp.residual).max() > 0.1)
    (0.0, True)
    """
    plant = check_plant(plant)
    if fault is None:
        return simulate(
            plant,
            observer,
            timepts,
            u=u,
            d=d,
            v=v,
            initial_state=initial_state,
            observer_state=observer_state,
            noise=noise,
            seed=seed,
        )
    true_plant = faulty_plant(plant, fault)
    t = check_timepts(timepts)
    f = input_samples("fault.signal", fault.signal, 1, t)
    d_all = np.vstack([input_samples("d", d, plant.q, t), f])
    v_all = np.vstack([input_samples("v", v, plant.nv, t), f])
    return simulate(
        true_plant,
        observer,
        t,
        u=u,
        d=d_all,
        v=v_all,
        initial_state=initial_state,
        observer_state=observer_state,
        noise=noise,
        seed=seed,
    )


def observer_residual(
    observer: Observer, timepts: Any, u: Any, y: Any, *, observer_state: Any = None
) -> np.ndarray:
    """Run an observer on recorded inputs and measurements and return its residual ``y - C xhat``.

    The observer is driven by ``[u; y]``, solved exactly for data linear
    between samples as in :func:`uio_teach.simulate` (both run on
    :func:`uio_teach.simulation.linear_response`), so it can be an observer for a different
    plant model than the one that produced the data: a member of a bank that
    reads only some inputs and outputs.

    Parameters
    ----------
    observer : Observer
        The observer; its plant fixes ``m``, ``p`` and ``C``.
    timepts : array_like, shape (N,)
        Time points.
    u : array_like, shape (m, N)
        Known inputs read by the observer.
    y : array_like, shape (p, N)
        Measurements read by the observer.
    observer_state : array_like, optional
        The observer's state at ``timepts[0]``; zero by default.

    Returns
    -------
    numpy.ndarray
        Shape (p, N): the residual.

    Examples
    --------
    The residual of the joint simulation, up to reading ``y`` as linear between samples:

    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> uio = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> t = np.linspace(0, 5, 501)
    >>> resp = ut.simulate(plant, uio, t, d=ut.signals.sinusoid(1.0, 2.0), initial_state=[1, 0, 0])
    >>> r = ut.observer_residual(uio, t, resp.inputs.u, resp.outputs)
    >>> float(np.abs(r - resp.residual).max()) < 1e-5  # y read as linear between samples
    True
    """
    if not isinstance(observer, Observer):
        raise InputError(
            "observer must be a uio_teach observer (design_uio, ...), got "
            f"{type(observer).__name__}"
        )
    pl = observer.plant
    t = check_timepts(timepts)
    N = t.size
    U = _samples("u", u, pl.m, N)
    Y = _samples("y", y, pl.p, N)
    if getattr(observer, "delay", 0):  # a delayed UIO: its estimate of x[k] (nan at the end)
        return Y - pl.C @ observer.aligned_estimates(Y, U, observer_state)
    real = observer.realization()
    nw = real.A.shape[0]
    w0 = (
        np.zeros(nw)
        if observer_state is None
        else as_matrix(
            "observer_state", observer_state, nw, 1, what=f"one value per observer state, {nw}"
        )[:, 0]
    )
    # the observer alone, driven by [u; y], on the package's one simulation engine
    S = np.vstack([U, Y])
    Bs = np.hstack([real.B_u, real.B_y])
    w = linear_response(real.A, Bs, t, S, w0, discrete=pl.is_discrete)
    xhat = real.C @ w + real.D_y @ Y
    return Y - pl.C @ xhat


def _samples(name: str, value: Any, rows: int, N: int) -> np.ndarray:
    if rows == 0 and value is None:
        return np.zeros((0, N))
    arr = as_matrix(
        name, value, rows, N, vector="row", what="one row per channel, one column per time point"
    )
    return np.asarray(arr)


# residual evaluation --------------------------------------------------------------------------


def _positive(name: str, value: Any) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, Real)
        or not np.isfinite(value)
        or (value <= 0)
    ):
        raise InputError(f"{name} must be a positive number, got {value!r}")
    return float(value)


def _residual_runs(name: str, residuals: Any, N: int) -> np.ndarray:
    """Residuals as an array of shape (runs, p, N)."""
    try:
        arr = np.array(residuals, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be an array of residuals: {exc}") from None
    if arr.ndim == 1:
        arr = arr[None, None, :]
    elif arr.ndim == 2:
        arr = arr[None]
    if arr.ndim != 3 or arr.shape[-1] != N:
        raise InputError(
            f"{name} must have shape (p, {N}) or (runs, p, {N}) (one column per time point), "
            f"got {np.shape(residuals)}"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} has non-finite values; a residual must be finite")
    return arr


def residual_rms(timepts: Any, residual: Any, window: float) -> np.ndarray:
    """The residual's norm, averaged over a sliding window: the evaluation function ``J(t)``.

    ``J(t) = sqrt( (1 / T_w) * integral of |r|^2 over [t - T_w, t] )`` with
    the window ``T_w``; before ``timepts[0] + T_w`` the average runs over the
    time elapsed so far. Averaging tames the noise, so that ``J`` can be
    compared with a threshold lower than the noise peaks.

    Parameters
    ----------
    timepts : array_like, shape (N,)
        Time points.
    residual : array_like, shape (p, N) or (runs, p, N)
        The residual ``y - C xhat`` (one run or several).
    window : float
        The window length ``T_w`` (seconds, or steps for ``dt=True``).

    Returns
    -------
    numpy.ndarray
        Shape (N,) for one run, (runs, N) for several.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> t = np.linspace(0, 4, 401)
    >>> J = ut.residual_rms(t, np.ones((2, t.size)), window=1.0)
    >>> float(J[-1].round(6))  # |r| = sqrt(2) everywhere
    1.414214
    """
    t = check_timepts(timepts)
    w = _positive("window", window)
    one = np.ndim(residual) <= 2
    R = _residual_runs("residual", residual, t.size)
    power = np.sum(R**2, axis=1)  # (runs, N)
    # running integral of |r|^2 (trapezoid rule; the residual is linear between samples)
    S = np.concatenate(
        [
            np.zeros((R.shape[0], 1)),
            np.cumsum(0.5 * (power[:, 1:] + power[:, :-1]) * np.diff(t), axis=1),
        ],
        axis=1,
    )
    start = np.maximum(t - w, t[0])
    S_start = np.stack([np.interp(start, t, s) for s in S])
    span = t - start
    J = np.empty_like(S)
    J[:, 0] = np.sqrt(power[:, 0])
    J[:, 1:] = np.sqrt(np.maximum(S[:, 1:] - S_start[:, 1:], 0) / span[1:])
    return J[0] if one else J


@dataclass(frozen=True)
class Threshold:
    """A detection threshold on the windowed residual norm ``J`` of :func:`residual_rms`.

    Attributes
    ----------
    value : float
        Alarm when ``J(t) > value``.
    window : float
        The window of :func:`residual_rms` the threshold was set for.
    design_rate : float
        The false-alarm rate it was designed for.
    per : str
        What the rate counts: ``"sample"``, the fraction of fault-free
        monitored samples in alarm, or ``"run"``, the fraction of fault-free
        runs with at least one alarm.
    start : float
        Samples before this time are not monitored (the observer's start-up).
    samples : int
        How many fault-free samples it was computed from.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> t = np.linspace(0, 10, 1001)
    >>> noise = np.random.default_rng(0).normal(0, 0.1, (5, 2, t.size))
    >>> thr = ut.residual_threshold(t, noise, false_alarm_rate=0.01, window=0.5)
    >>> thr.window, thr.design_rate, thr.per, thr.samples
    (0.5, 0.01, 'sample', 4755)
    """

    value: float
    window: float
    design_rate: float
    start: float
    samples: int
    per: str = "sample"

    def __post_init__(self) -> None:
        if (
            isinstance(self.value, bool)
            or not isinstance(self.value, Real)
            or not (np.isfinite(self.value) and self.value >= 0)
        ):
            raise InputError(f"value must be a finite number >= 0, got {self.value!r}")
        _positive("window", self.window)
        _rate(self.design_rate, "design_rate")
        _start(self.start, np.zeros(1), 1.0)
        _per(self.per)

    def __repr__(self) -> str:
        return call_repr(
            "Threshold",
            [
                ("value", _Num(self.value)),
                ("window", _Num(self.window)),
                ("design_rate", _Num(self.design_rate)),
                ("start", _Num(self.start)),
                ("samples", self.samples),
                ("per", self.per),
            ],
        )

    def __float__(self) -> float:
        return self.value


def residual_threshold(
    timepts: Any,
    residuals: Any,
    *,
    false_alarm_rate: float,
    window: float,
    start: float | None = None,
    per: str = "sample",
) -> Threshold:
    """Set a threshold from fault-free residuals so that a fraction ``false_alarm_rate`` exceeds it.

    With ``per="sample"`` the threshold is the ``1 - false_alarm_rate``
    quantile of the windowed norm ``J`` (:func:`residual_rms`) over every
    fault-free sample at or after ``start``: on fault-free data like these,
    ``J`` is above it that fraction of the time. With ``per="run"`` it is the
    same quantile of each run's largest ``J``: that fraction of fault-free
    runs raises an alarm at all. A per-sample rate of 1 % still lets most
    long runs raise some alarm; the per-run rate is the one an operator feels.

    Parameters
    ----------
    timepts : array_like, shape (N,)
        Time points.
    residuals : array_like, shape (runs, p, N) or (p, N)
        Residuals of fault-free runs (with measurement noise), e.g. a Monte
        Carlo set of :func:`simulate_fault` responses' ``residual``.
    false_alarm_rate : float
        The fraction of fault-free samples allowed to raise an alarm, in (0, 1).
    window : float
        Window of :func:`residual_rms`.
    start : float, optional
        Monitoring starts here (skip the observer's start-up transient);
        default ``timepts[0] + window``.
    per : {"sample", "run"}
        What ``false_alarm_rate`` counts: monitored samples or whole runs.

    Returns
    -------
    Threshold

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> t = np.linspace(0, 10, 1001)
    >>> rng = np.random.default_rng(1)
    >>> thr = ut.residual_threshold(t, rng.normal(0, 0.1, (100, 2, t.size)),
    ...                             false_alarm_rate=0.05, window=0.5)
    >>> fresh = rng.normal(0, 0.1, (100, 2, t.size))   # new fault-free runs: about 5 % in alarm
    >>> round(ut.false_alarm_rate(t, fresh, thr), 2)
    0.05
    """
    t = check_timepts(timepts)
    rate = _rate(false_alarm_rate)
    w = _positive("window", window)
    s = _start(start, t, w)
    R = _residual_runs("residuals", residuals, t.size)
    per = _per(per)
    J = residual_rms(t, R, w)[:, t >= s]
    if J.size == 0:
        raise InputError(f"start = {s:g} leaves no sample to monitor (timepts end at {t[-1]:g})")
    pool = J if per == "sample" else J.max(axis=1)
    value = float(np.quantile(pool, 1 - rate))
    return Threshold(value=value, window=w, design_rate=rate, start=s, samples=int(J.size), per=per)


def _per(per: Any) -> str:
    if per not in ("sample", "run"):
        raise InputError(f"per must be 'sample' or 'run', got {per!r}")
    return per


def _rate(value: Any, name: str = "false_alarm_rate") -> float:
    if isinstance(value, bool) or not isinstance(value, Real) or not 0 < value < 1:
        raise InputError(f"{name} must be a number between 0 and 1, got {value!r}")
    return float(value)


def _start(start: Any, t: np.ndarray, window: float) -> float:
    if start is None:
        return float(min(t[0] + window, t[-1]))
    if isinstance(start, bool) or not isinstance(start, Real) or not np.isfinite(start):
        raise InputError(f"start must be a finite time, got {start!r}")
    return float(start)


def _check_threshold(threshold: Any) -> Threshold:
    if not isinstance(threshold, Threshold):
        raise InputError(
            f"threshold must be a Threshold from residual_threshold, got {type(threshold).__name__}"
        )
    return threshold


@dataclass(frozen=True)
class Detection:
    """The result of :func:`detect`: the evaluated residual and the alarm it raises.

    Attributes
    ----------
    time : numpy.ndarray
        Shape (N,): the time points.
    evaluation : numpy.ndarray
        Shape (N,): the windowed residual norm ``J`` of :func:`residual_rms`.
    alarm : numpy.ndarray
        Shape (N,), bool: ``J > threshold`` at monitored time points.
    threshold : Threshold
        The threshold used.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> t = np.linspace(0, 10, 1001)
    >>> thr = ut.Threshold(value=0.5, window=0.2, design_rate=0.01, start=0.2, samples=1)
    >>> det = ut.detect(t, np.where(t > 4, 1.0, 0.0)[None], thr)
    >>> det.alarm_times.round(2).tolist(), bool(det.fired)
    ([4.06], True)
    """

    time: np.ndarray
    evaluation: np.ndarray
    alarm: np.ndarray
    threshold: Threshold

    def __repr__(self) -> str:
        first = self.first_alarm
        return call_repr(
            "Detection",
            [
                ("fired", self.fired),
                ("first_alarm", None if first is None else _Num(first)),
                ("alarm_samples", int(np.sum(self.alarm))),
                ("samples", int(self.alarm.size)),
                ("threshold", _Num(self.threshold.value)),
            ],
        )

    @property
    def fired(self) -> bool:
        """True if an alarm was raised at any monitored time point."""
        return bool(self.alarm.any())

    @property
    def alarm_times(self) -> np.ndarray:
        """Times at which the alarm switches on (rising edges)."""
        a = self.alarm.astype(int)
        rising = np.flatnonzero(np.diff(np.concatenate([[0], a])) == 1)
        return self.time[rising]

    @property
    def first_alarm(self) -> float | None:
        """The first alarm time, ``None`` if there was none."""
        times = self.alarm_times
        return float(times[0]) if times.size else None


def detect(timepts: Any, residual: Any, threshold: Threshold) -> Detection:
    """Evaluate a residual and compare it with a threshold: the alarm signal.

    Parameters
    ----------
    timepts : array_like, shape (N,)
        Time points.
    residual : array_like, shape (p, N)
        One run's residual.
    threshold : Threshold
        From :func:`residual_threshold`; its window and start are used.

    Returns
    -------
    Detection

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> uio = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> t = np.linspace(0, 10, 1001)
    >>> healthy = [ut.simulate_fault(plant, uio, t, noise=0.01, seed=k).residual
    ...            for k in range(10)]
    >>> thr = ut.residual_threshold(t, healthy, false_alarm_rate=0.01, window=0.5)
    >>> fault = ut.actuator_fault(plant, 1, ut.signals.step(0.5, 5.0))
    >>> resp = ut.simulate_fault(plant, uio, t, fault, noise=0.01, seed=99)
    >>> det = ut.detect(t, resp.residual, thr)
    >>> 5.0 < det.first_alarm < 6.0
    True
    """
    t = check_timepts(timepts)
    thr = _check_threshold(threshold)
    R = _residual_runs("residual", residual, t.size)
    if R.shape[0] != 1:
        raise InputError(f"residual must be one run, shape (p, {t.size}), got {np.shape(residual)}")
    J = residual_rms(t, R[0], thr.window)
    alarm = (J > thr.value) & (t >= thr.start)
    for arr in (J, alarm):
        arr.setflags(write=False)
    return Detection(time=t, evaluation=J, alarm=alarm, threshold=thr)


def false_alarm_rate(
    timepts: Any, residuals: Any, threshold: Threshold, *, per: str | None = None
) -> float:
    """The measured false-alarm rate: the fraction of fault-free samples (or runs) in alarm.

    Parameters
    ----------
    timepts : array_like, shape (N,)
        Time points.
    residuals : array_like, shape (runs, p, N) or (p, N)
        Residuals of fault-free runs, *not* those the threshold was set from.
    threshold : Threshold
        The threshold under test.
    per : {"sample", "run"}, optional
        Count monitored samples in alarm or runs with at least one alarm;
        default: what the threshold was designed for (``threshold.per``).

    Returns
    -------
    float
        A number in [0, 1].

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> t = np.linspace(0, 10, 1001)
    >>> thr = ut.Threshold(value=1.0, window=0.5, design_rate=0.01, start=0.5, samples=1)
    >>> ut.false_alarm_rate(t, np.zeros((3, 2, t.size)), thr)
    0.0
    """
    t = check_timepts(timepts)
    thr = _check_threshold(threshold)
    R = _residual_runs("residuals", residuals, t.size)
    J = residual_rms(t, R, thr.window)[:, t >= thr.start]
    if J.size == 0:
        raise InputError(f"threshold.start = {thr.start:g} leaves no sample to monitor")
    alarm = J > thr.value
    if _per(thr.per if per is None else per) == "run":
        return float(np.mean(alarm.any(axis=1)))
    return float(np.mean(alarm))


def detection_time(timepts: Any, residual: Any, threshold: Threshold, fault_time: float) -> float:
    """Time from the fault's onset to the first alarm at or after it (``inf`` if none).

    Parameters
    ----------
    timepts : array_like, shape (N,)
        Time points.
    residual : array_like, shape (p, N)
        The residual of a run with a fault.
    threshold : Threshold
        The threshold.
    fault_time : float
        When the fault starts.

    Returns
    -------
    float
        The delay, in the units of ``timepts``; ``inf`` if the alarm never
        sounds after ``fault_time``.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> t = np.linspace(0, 10, 1001)
    >>> thr = ut.Threshold(value=0.5, window=1.0, design_rate=0.01, start=1.0, samples=1)
    >>> r = np.where(t >= 4, 1.0, 0.0)[None]
    >>> round(ut.detection_time(t, r, thr, fault_time=4.0), 2)  # J = sqrt(delay / 1 s) > 0.5
    0.25
    >>> ut.detection_time(t, 0 * r, thr, fault_time=4.0)
    inf
    """
    t = check_timepts(timepts)
    if (
        isinstance(fault_time, bool)
        or not isinstance(fault_time, Real)
        or not (t[0] <= fault_time <= t[-1])
    ):
        raise InputError(
            f"fault_time must be a time within timepts ({t[0]:g} to {t[-1]:g}), got {fault_time!r}"
        )
    det = detect(t, residual, threshold)
    after = np.flatnonzero(det.alarm & (t >= fault_time))
    return float(t[after[0]] - fault_time) if after.size else float("inf")
