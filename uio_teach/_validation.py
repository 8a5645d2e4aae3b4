"""Input checks shared by the package: clear errors instead of deep numpy tracebacks."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["as_matrix", "as_poles", "shape_str"]


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
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a real numeric matrix: {exc}") from None
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
        raise ValueError(f"{name} must be a 2-D matrix, got an array of shape {arr.shape}")
    if (rows is not None and arr.shape[0] != rows) or (cols is not None and arr.shape[1] != cols):
        expected = shape_str((rows, cols))
        extra = f" ({what})" if what else ""
        raise ValueError(f"{name} has shape {arr.shape}, expected {expected}{extra}")
    if not np.all(np.isfinite(arr)):
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise ValueError(
            f"{name} has a non-finite entry {arr[bad]} at position {bad}; "
            "all entries must be finite numbers"
        )
    arr.setflags(write=False)
    return arr


def as_poles(name: str, value: Any) -> np.ndarray:
    """Return requested poles as a 1-D complex array; conjugate pairs are required."""
    try:
        poles = np.atleast_1d(np.array(value, dtype=complex)).ravel()
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a list of numbers: {exc}") from None
    if not np.all(np.isfinite(poles)):
        raise ValueError(f"{name} must be finite numbers, got {value!r}")
    scale = max(1.0, float(np.max(np.abs(poles)))) if poles.size else 1.0
    tol = 1e-9 * scale
    unmatched = list(poles[np.abs(poles.imag) > tol])
    while unmatched:
        p = unmatched.pop(0)
        idx = [i for i, q in enumerate(unmatched) if abs(q - np.conj(p)) <= tol]
        if not idx:
            raise ValueError(
                f"{name}: the complex pole {p:.6g} has no conjugate partner; complex poles "
                "must come in conjugate pairs so that the gain is real"
            )
        unmatched.pop(idx[0])
    return poles
