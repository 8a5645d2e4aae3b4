"""The modes of an observer's error: which the start excites, which the controls move, how fast.

The error of a linear observer is ``e(t) = exp(F t) e(0)`` (``F^k e(0)`` in
discrete time); its modes are the eigenvalues of ``F``, the observer poles.
This module answers the questions the explorers' words are built on: which
modes does a start excite (:func:`excited_modes`), which poles of a list are
among another (:func:`match_poles`, :func:`remove_poles`,
:func:`pole_positions`), which is the slowest (:func:`slowest_pole`), how fast
a pole shrinks the error (:func:`pole_rate`) and how finely a grid samples an
oscillating mode (:func:`points_per_period`).

Examples
--------
>>> import numpy as np
>>> from uio_teach.explorers.modes import excited_modes, slowest_pole
>>> F = np.diag([-1.0, -3.0])
>>> excited_modes(F, [0.0, 1.0]).real.tolist(), slowest_pole(np.array([-1.0, -3.0]), False)
([-3.0], (-1+0j))
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "excited_modes",
    "match_poles",
    "remove_poles",
    "pole_positions",
    "slowest_pole",
    "pole_rate",
    "points_per_period",
    "damping_ratio",
]


def excited_modes(F: np.ndarray, e0: np.ndarray, *, tol: float = 1e-7) -> np.ndarray:
    """The eigenvalues of ``F`` that the initial error ``e0`` excites.

    The error ``e(t) = exp(F t) e0`` (``F^k e0``) moves only in the Krylov
    space of ``e0``: ``span{e0, F e0, F^2 e0, ...}``. Its dimension is the
    number of modes ``e0`` excites, and ``F`` restricted to it has exactly those
    modes as eigenvalues. The space is built by Arnoldi's method with
    re-orthogonalization; a new direction smaller than ``tol`` (relative to
    ``F`` and ``e0``) ends it.

    Parameters
    ----------
    F : array_like, shape (n, n)
        The error dynamics matrix.
    e0 : array_like, shape (n,)
        The initial error.
    tol : float
        Relative size below which a direction counts as not excited.

    Returns
    -------
    numpy.ndarray of complex
        The excited eigenvalues (empty for ``e0 = 0``).

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers import excited_modes
    >>> F = np.diag([0.5, -0.2, 0.9])
    >>> sorted(excited_modes(F, [1.0, 0.0, 1.0]).real.round(6).tolist())
    [0.5, 0.9]
    """
    F = np.asarray(F, dtype=float)
    e0 = np.asarray(e0, dtype=float).ravel()
    size = float(np.linalg.norm(e0))
    if not size or not np.isfinite(size):
        return np.zeros(0, complex)
    scale = max(float(np.linalg.norm(F, 2)), 1e-300)
    basis = [e0 / size]
    for _ in range(F.shape[0] - 1):
        w = F @ basis[-1]
        for _ in range(2):
            for q in basis:
                w = w - (q @ w) * q
        norm = float(np.linalg.norm(w))
        if norm <= tol * scale:
            break
        basis.append(w / norm)
    Q = np.column_stack(basis)
    return np.linalg.eigvals(Q.T @ F @ Q)


def match_poles(poles: np.ndarray, found: np.ndarray) -> np.ndarray:
    """For each pole: is it among ``found`` (each found value used once, nearest first)?

    Parameters
    ----------
    poles, found : numpy.ndarray of complex
        The poles, and the values to look for among them.

    Returns
    -------
    numpy.ndarray of bool

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.modes import match_poles
    >>> match_poles(np.array([0.5, 0.5, -0.2]), np.array([0.5])).tolist()
    [True, False, False]
    """
    out = np.zeros(poles.size, bool)
    left = list(found)
    scale = max(1.0, float(np.abs(poles).max())) if poles.size else 1.0
    for i in np.argsort(np.abs(poles), kind="stable"):
        if not left:
            break
        gaps = [abs(poles[i] - f) for f in left]
        j = int(np.argmin(gaps))
        if gaps[j] <= 1e-4 * scale + 1e-3 * abs(poles[i]):
            out[i] = True
            left.pop(j)
    return out


def remove_poles(poles: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """The poles with the nearest entry removed for each fixed pole.

    Parameters
    ----------
    poles, fixed : numpy.ndarray of complex
        All the poles, and those to take out.

    Returns
    -------
    numpy.ndarray of complex

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.modes import remove_poles
    >>> remove_poles(np.array([0.5, 0.2, 0.5]), np.array([0.5])).real.tolist()
    [0.2, 0.5]
    """
    left = list(poles)
    for z in fixed:
        if not left:
            break
        left.pop(int(np.argmin([abs(p - z) for p in left])))
    return np.array(left, dtype=complex)


def pole_positions(poles: np.ndarray, subset: np.ndarray) -> np.ndarray:
    """For each entry of ``subset``, the index of a distinct nearest entry of ``poles``.

    Parameters
    ----------
    poles, subset : numpy.ndarray of complex
        All the poles, and some of them.

    Returns
    -------
    numpy.ndarray of int

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.modes import pole_positions
    >>> pole_positions(np.array([-1.0, -2.0, -2.0]), np.array([-2.0, -2.0])).tolist()
    [1, 2]
    """
    left = list(range(poles.size))
    out = []
    for z in subset:
        if not left:
            break
        j = min(left, key=lambda i: abs(poles[i] - z))
        out.append(j)
        left.remove(j)
    return np.array(out, dtype=int)


def slowest_pole(poles: np.ndarray, discrete: bool) -> complex | None:
    """The slowest pole: the largest radius (discrete) or real part (continuous); None if none.

    Parameters
    ----------
    poles : numpy.ndarray of complex
        The poles.
    discrete : bool
        Discrete time.

    Returns
    -------
    complex or None

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.modes import slowest_pole
    >>> slowest_pole(np.array([0.2, -0.7]), True)
    (-0.7+0j)
    """
    if not poles.size:
        return None
    key = np.abs(poles) if discrete else poles.real
    return complex(poles[int(np.argmax(key))])


def pole_rate(p: complex, discrete: bool, t: np.ndarray) -> np.ndarray:
    """How a mode's size changes over the grid: ``|p|^k`` (k in steps from ``t[0]``) or
    ``exp(Re(p) (t - t[0]))``.

    Parameters
    ----------
    p : complex
        The pole.
    discrete : bool
        Discrete time.
    t : numpy.ndarray
        The time grid.

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.modes import pole_rate
    >>> pole_rate(0.5, True, np.arange(3.0)).tolist()
    [1.0, 0.5, 0.25]
    """
    tt = t - t[0]
    with np.errstate(all="ignore"):
        if discrete:
            step = tt[1] if tt.size > 1 else 1.0
            return np.abs(p) ** np.round(tt / step)
        return np.exp(complex(p).real * tt)


def points_per_period(p: complex, t: np.ndarray) -> float:
    """How many samples of the grid ``t`` one period of a continuous-time mode ``p`` spans.

    ``inf`` for a real pole (no oscillation) or a grid of one point.

    Parameters
    ----------
    p : complex
        The pole.
    t : numpy.ndarray
        The time grid (evenly spaced).

    Returns
    -------
    float

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.modes import points_per_period
    >>> round(points_per_period(-0.01 + 10j, np.linspace(0, 800, 1001)), 2)
    0.79
    """
    w = abs(complex(p).imag)
    if w == 0 or t.size < 2:
        return float("inf")
    return float(2 * np.pi / w / (t[1] - t[0]))


def damping_ratio(p: complex) -> float:
    """The damping ratio ``-Re(p) / |p|`` of a continuous-time pole (1 for ``p = 0``).

    Parameters
    ----------
    p : complex
        The pole.

    Returns
    -------
    float

    Examples
    --------
    >>> from uio_teach.explorers.modes import damping_ratio
    >>> round(damping_ratio(-0.01 + 10j), 4)
    0.001
    """
    p = complex(p)
    return 1.0 if p == 0 else -p.real / abs(p)
