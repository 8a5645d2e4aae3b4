"""Test signals for the unknown inputs: vectorized callables of time with a readable repr."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from numbers import Real

import numpy as np

from ._validation import as_real_array
from .errors import InputError

__all__ = ["Signal", "sinusoid", "piecewise_constant", "damped_sinusoid", "step", "stack"]


class Signal:
    """A vectorized scalar signal ``s(t)``; ``repr`` reads like the formula.

    Calling it with an array of times returns an array of the same shape.

    Examples
    --------
    >>> from uio_teach import signals
    >>> s = signals.sinusoid(1.0, 2.0) + signals.step(0.5)
    >>> s
    1 sin(2 t) + 0.5 step(t - 0)
    >>> s([0.0, 1.0]).shape
    (2,)
    """

    def __init__(self, func: Callable[[np.ndarray], np.ndarray], text: str) -> None:
        self._func = func
        self._text = text

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        return np.broadcast_to(self._func(t), t.shape).astype(float)

    def __repr__(self) -> str:
        return self._text

    def __add__(self, other: Signal) -> Signal:
        if not isinstance(other, Signal):
            return NotImplemented
        return Signal(lambda t: self._func(t) + other._func(t), f"{self._text} + {other._text}")


def _num(name: str, value) -> float:
    """A finite real number (not text, not complex, not a bool), or a ValueError naming it."""
    if isinstance(value, bool) or not isinstance(value, (Real, np.integer, np.floating)):
        raise InputError(f"{name} must be a number, got {value!r}")
    v = float(value)
    if not np.isfinite(v):
        raise InputError(f"{name} must be finite, got {value!r}")
    return v


def sinusoid(
    amplitude: float = 1.0, frequency: float = 1.0, phase: float = 0.0, offset: float = 0.0
) -> Signal:
    """``offset + amplitude * sin(frequency * t + phase)`` (frequency in rad/s).

    Parameters
    ----------
    amplitude : float
    frequency : float
        Angular frequency in rad/s.
    phase : float
        Phase in rad.
    offset : float
        Constant added to the sinusoid.

    Examples
    --------
    >>> from uio_teach import signals
    >>> s = signals.sinusoid(2.0, 3.0)
    >>> s
    2 sin(3 t)
    >>> float(s(0.0))
    0.0
    """
    a, w, ph, c = (
        _num(k, v)
        for k, v in (
            ("amplitude", amplitude),
            ("frequency", frequency),
            ("phase", phase),
            ("offset", offset),
        )
    )
    text = f"{a:g} sin({w:g} t" + (f" + {ph:g}" if ph else "") + ")"
    if c:
        text = f"{c:g} + {text}"
    return Signal(lambda t: c + a * np.sin(w * t + ph), text)


def damped_sinusoid(
    amplitude: float = 1.0, decay: float = 1.0, frequency: float = 1.0, kind: str = "sin"
) -> Signal:
    """``amplitude * exp(-decay t) * sin(frequency t)`` (or ``cos``).

    The missile paper's unknown inputs are ``damped_sinusoid(10, 2, 10, "cos")``
    and ``damped_sinusoid(50, 5, 100, "sin")``.

    Parameters
    ----------
    amplitude : float
    decay : float
        Exponential decay rate in 1/s.
    frequency : float
        Angular frequency in rad/s.
    kind : {"sin", "cos"}

    Examples
    --------
    >>> from uio_teach import signals
    >>> signals.damped_sinusoid(10, 2, 10, "cos")
    10 exp(-2 t) cos(10 t)
    """
    a, s, w = _num("amplitude", amplitude), _num("decay", decay), _num("frequency", frequency)
    if kind not in ("sin", "cos"):
        raise InputError(f"kind must be 'sin' or 'cos', got {kind!r}")
    trig = np.sin if kind == "sin" else np.cos
    return Signal(
        lambda t: a * np.exp(-s * t) * trig(w * t), f"{a:g} exp({-s:g} t) {kind}({w:g} t)"
    )


def piecewise_constant(times: Sequence[float], values: Sequence[float]) -> Signal:
    """A signal that holds ``values[i]`` from ``times[i]`` on (0 before ``times[0]``).

    Parameters
    ----------
    times : sequence of float
        Increasing switching times.
    values : sequence of float
        The value held from each switching time; same length as ``times``.

    Examples
    --------
    >>> from uio_teach import signals
    >>> s = signals.piecewise_constant([0, 5, 10], [1.0, -0.5, 0.0])
    >>> s([0, 4.9, 5, 12]).tolist()
    [1.0, 1.0, -0.5, 0.0]
    """
    t_sw = as_real_array("times", times, finite=False).ravel()
    vals = as_real_array("values", values, finite=False).ravel()
    if t_sw.size == 0 or t_sw.shape != vals.shape:
        raise InputError(
            f"times and values must be non-empty and of the same length, got {t_sw.size} "
            f"and {vals.size}"
        )
    if not np.all(np.isfinite(t_sw)):
        raise InputError("times must be finite")
    if not np.all(np.isfinite(vals)):
        raise InputError("values must be finite")
    if np.any(np.diff(t_sw) <= 0):
        raise InputError("times must be strictly increasing")
    padded = np.concatenate([[0.0], vals])

    def f(t):
        return padded[np.searchsorted(t_sw, t, side="right")]

    pairs = ", ".join(f"{v:g} from t={s:g}" for s, v in zip(t_sw, vals, strict=True))
    return Signal(f, f"piecewise constant ({pairs})")


def step(amplitude: float = 1.0, time: float = 0.0) -> Signal:
    """``amplitude`` from ``time`` on, 0 before.

    Parameters
    ----------
    amplitude : float
    time : float
        Switching time.

    Examples
    --------
    >>> from uio_teach import signals
    >>> signals.step(2.0, 1.0)([0.5, 1.0]).tolist()
    [0.0, 2.0]
    """
    a, t0 = _num("amplitude", amplitude), _num("time", time)
    return Signal(lambda t: np.where(t >= t0, a, 0.0), f"{a:g} step(t - {t0:g})")


class _Stack:
    def __init__(self, parts: Sequence[Callable]) -> None:
        self.parts = list(parts)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        return np.stack([np.broadcast_to(np.asarray(s(t), float), t.shape) for s in self.parts])

    def __repr__(self) -> str:
        return "[" + "; ".join(repr(s) for s in self.parts) + "]"


def stack(*signals: Callable) -> Callable:
    """Stack scalar signals into one vector signal (one row per channel).

    Parameters
    ----------
    *signals : callable
        Scalar signals of time, one per channel.

    Examples
    --------
    >>> from uio_teach import signals
    >>> v = signals.stack(signals.step(1.0), signals.step(2.0))
    >>> v([0.0, 1.0]).tolist()
    [[1.0, 1.0], [2.0, 2.0]]
    """
    if not signals:
        raise InputError("stack needs at least one signal")
    return _Stack(signals)
