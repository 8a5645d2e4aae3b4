"""Input checks shared by the package: clear errors instead of deep numpy tracebacks."""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Real
from typing import Any

import numpy as np

from . import tolerances as tols
from .errors import InputError

__all__ = [
    "as_matrix",
    "as_poles",
    "as_real_array",
    "as_time",
    "as_seed",
    "as_real_number",
    "shape_str",
]


def _refuse_non_real(name: str, value: Any, noun: str = "numeric") -> None:
    """Complex values and text are refused with a message naming the argument."""
    if isinstance(value, (str, bytes)):
        raise InputError(f"{name} must be {noun}, got the text {value!r}")
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):
        return  # ragged: the float conversion below names the argument
    if kind == "c":
        raise InputError(
            f"{name} must be {noun}, got complex values (the imaginary part would be dropped)"
        )
    if kind in "US":
        raise InputError(f"{name} must be {noun}, got text entries")
    if kind == "O":
        flat = np.asarray(value, dtype=object).ravel()
        if any(isinstance(v, (complex, np.complexfloating)) for v in flat):
            raise InputError(
                f"{name} must be {noun}, got complex values (the imaginary part would be dropped)"
            )
        if any(isinstance(v, (str, bytes)) for v in flat):
            raise InputError(f"{name} must be {noun}, got text entries")


def as_real_array(name: str, value: Any, *, finite: bool = True) -> np.ndarray:
    """``value`` as a float array; complex, text or (with ``finite``) non-finite values refused."""
    _refuse_non_real(name, value, "real numbers")
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must hold real numbers: {exc}") from None
    if finite and not np.all(np.isfinite(arr)):
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0]) if arr.ndim else ()
        raise InputError(f"{name} has a non-finite value at position {bad}; all must be finite")
    return arr


def as_real_number(
    name: str, value: Any, *, low: float | None = None, strict: bool = False
) -> float:
    """A finite real number (not a bool, not text), optionally ``>= low`` (``> low``)."""
    if isinstance(value, bool) or not isinstance(value, (Real, np.integer, np.floating)):
        raise InputError(f"{name} must be a real number, got {value!r}")
    x = float(value)
    if not np.isfinite(x):
        raise InputError(f"{name} must be finite, got {value!r}")
    if low is not None and (x <= low if strict else x < low):
        raise InputError(f"{name} must be {'>' if strict else '>='} {low:g}, got {value!r}")
    return x


def as_time(name: str, value: Any, *, min_size: int = 2, uniform: bool = False) -> np.ndarray:
    """A 1-D, finite, strictly increasing time vector (uniformly spaced if ``uniform``)."""
    if isinstance(value, (str, bytes)):
        raise InputError(f"{name} must be a 1-D array of times, got the text {value!r}")
    t = as_real_array(name, value, finite=False)
    if t.ndim != 1:
        raise InputError(f"{name} must be a 1-D array of times, got shape {t.shape}")
    if t.size < min_size:
        raise InputError(f"{name} must hold at least {min_size} time points, got {t.size}")
    if not np.all(np.isfinite(t)):
        k = int(np.argmax(~np.isfinite(t)))
        raise InputError(f"{name} must be finite numbers: {name}[{k}] = {t[k]}")
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0))
        raise InputError(
            f"{name} must be strictly increasing: {name}[{k}] = {t[k]:g} and "
            f"{name}[{k + 1}] = {t[k + 1]:g}"
        )
    if uniform and t.size > 2:
        h = (t[-1] - t[0]) / (t.size - 1)
        tol = tols.TIME_GRID_RTOL * h + 64 * np.finfo(float).eps * max(abs(t[0]), abs(t[-1]))
        if np.max(np.abs(steps - h)) > tol:
            raise InputError(
                f"{name} must be uniformly spaced, got steps from {steps.min():g} to "
                f"{steps.max():g}"
            )
    return t


def as_seed(name: str, value: Any) -> Any:
    """``None``, a non-negative integer or a ``numpy.random.Generator``."""
    if value is None or isinstance(value, np.random.Generator):
        return value
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise InputError(
            f"{name} must be None, a non-negative integer or a numpy.random.Generator, "
            f"got {value!r}"
        )
    return int(value)


def shape_str(shape: Sequence[Any]) -> str:
    """Format a shape as ``(3, 2)``, with ``?`` for a free dimension."""
    return "(" + ", ".join("?" if s is None else str(s) for s in shape) + ")"


def as_matrix(
    name: str,
    value: Any,
    rows: int | None = None,
    cols: int | None = None,
    *,
    vector: str = "column",
    what: str = "",
) -> np.ndarray:
    """Return ``value`` as a finite 2-D float array, or raise a ``ValueError`` naming it.

    Parameters
    ----------
    name : str
        Name of the matrix, used in the error message (e.g. ``"E"``).
    value : array_like
        The matrix. A scalar is a 1 x 1 matrix; a 1-D array is a column
        (``vector="column"``) or a row (``vector="row"``).
    rows, cols : int, optional
        Expected shape; ``None`` leaves a dimension free.
    vector : {"column", "row"}
        How a 1-D array is read.
    what : str
        Short explanation of the expected shape, appended to the error.
    """
    _refuse_non_real(name, value, "a real numeric matrix")
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a real numeric matrix: {exc}") from None
    if arr.ndim == 0:
        arr = arr.reshape(1, 1)
    elif arr.ndim == 1 and arr.size == 0:
        arr = np.zeros((rows or 0, cols or 0))
    elif arr.ndim == 1:
        arr = arr.reshape(-1, 1) if vector == "column" else arr.reshape(1, -1)
        # a 1-D array that fits as the other orientation is accepted too
        if (rows is not None and arr.shape[0] != rows) or (
            cols is not None and arr.shape[1] != cols
        ):
            alt = arr.T
            if (rows is None or alt.shape[0] == rows) and (cols is None or alt.shape[1] == cols):
                arr = alt
    elif arr.ndim > 2:
        raise InputError(f"{name} must be a 2-D matrix, got an array of shape {arr.shape}")
    if (rows is not None and arr.shape[0] != rows) or (cols is not None and arr.shape[1] != cols):
        expected = shape_str((rows, cols))
        extra = f" ({what})" if what else ""
        raise InputError(f"{name} has shape {arr.shape}, expected {expected}{extra}")
    if not np.all(np.isfinite(arr)):
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise InputError(
            f"{name} has a non-finite entry {arr[bad]} at position {bad}; "
            "all entries must be finite numbers"
        )
    arr.setflags(write=False)
    return arr


def as_poles(name: str, value: Any) -> np.ndarray:
    """Return requested poles as a 1-D complex array; conjugate pairs are required.

    A pair conjugate to within ``tolerances.CONJUGATE_RTOL`` (relative) is made exactly conjugate
    and a round-off imaginary part dropped, so the designs place exactly the
    poles the validator accepted.

    Examples
    --------
    >>> from uio_teach._validation import as_poles
    >>> p = as_poles("poles", [-1 + 2j, -1 - 2j + 1e-13j])
    >>> bool(p[0] == p[1].conjugate())
    True
    """
    if isinstance(value, (str, bytes)) or np.asarray(value).dtype.kind in "US":
        raise InputError(f"{name} must be a list of numbers, got {value!r}")
    try:
        poles = np.atleast_1d(np.array(value, dtype=complex)).ravel()
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a list of numbers: {exc}") from None
    if not np.all(np.isfinite(poles)):
        raise InputError(f"{name} must be finite numbers, got {value!r}")
    scale = max(1.0, float(np.max(np.abs(poles)))) if poles.size else 1.0
    tol = tols.CONJUGATE_RTOL * scale
    poles = poles.copy()
    unmatched = [int(i) for i in np.flatnonzero(np.abs(poles.imag) > tol)]
    while unmatched:
        i = unmatched.pop(0)
        p = poles[i]
        idx = [j for j in unmatched if abs(poles[j] - np.conj(p)) <= tol]
        if not idx:
            raise InputError(
                f"{name}: the complex pole {p:.6g} has no conjugate partner; complex poles "
                "must come in conjugate pairs so that the gain is real"
            )
        # a pair conjugate to within round-off is made exactly conjugate, so that the
        # design sees the same pair the validator accepted
        j = idx[0]
        unmatched.remove(j)
        mid = 0.5 * (p + np.conj(poles[j]))
        poles[i], poles[j] = mid, np.conj(mid)
    # values whose imaginary part is round-off are real
    poles[np.abs(poles.imag) <= tol] = poles[np.abs(poles.imag) <= tol].real
    return poles


def read_only(values: Any) -> np.ndarray:
    """A read-only float copy of ``values`` (results and designs cannot be changed in place).

    Examples
    --------
    >>> from uio_teach._validation import read_only
    >>> a = read_only([1, 2])
    >>> a.flags.writeable, a.dtype.name
    (False, 'float64')
    """
    arr = np.array(values, dtype=float)
    arr.setflags(write=False)
    return arr
