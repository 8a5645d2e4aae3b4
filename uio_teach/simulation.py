"""Simulate a plant together with an observer, exactly for the sampled inputs.

The plant and the observer form one linear system with state ``[x; z]`` (``z`` the
observer's own state) and inputs ``s = [u; d; v; noise]``::

    x' = A x + B u + E d                       (plant)
    y  = C x + D v + noise                     (measurement)
    z' = A_o z + B_u u + B_y y                 (observer)
    xhat = C_o z + D_y y

(``x[k+1] = ...``, ``z[k+1] = ...`` for a discrete plant). :func:`~uio_teach.simulate`
builds this joint system once and solves it on the time grid.

**Continuous time.** Between two samples the inputs are taken as linear (a
first-order hold, the convention of :func:`control.forced_response` and
:func:`scipy.signal.lsim`). Over one step ``h`` the joint system is then
solved exactly::

    z[k+1] = Phi z[k] + G0 s[k] + G1 s[k+1]

with ``Phi = expm(Az h)`` and ``G0``, ``G1`` read off one matrix exponential
of an augmented matrix. No Euler step and no error-controlled ODE solver is
involved: the only approximation is the straight line drawn between input
samples, so smooth inputs converge like ``h**2`` and piecewise-linear inputs
are simulated exactly (to rounding).

**Fast recursion.** The recursion ``z[k+1] = Phi z[k] + f[k]`` is run as a
block scan of matrix products, with no Python loop over the samples. In a
block of ``L`` steps every state is a power of ``Phi`` applied to the block's
first state plus powers of ``Phi`` applied to the block's inputs: for all blocks
at once, one product of the inputs with a block Toeplitz matrix. The blocks'
first states obey the same recursion with ``Phi^L``, ``L`` times shorter, solved
the same way. The measurements and estimates are folded into the last product,
so the states are read off directly. ``Phi`` is balanced first (a diagonal
scaling by powers of 2, exact), so that states of very different size keep
their accuracy; no eigenvectors are formed, so defective and non-normal
matrices need no special care. The one-step matrices are kept for the few
systems simulated last, so rerunning an observer on the same grid skips the
matrix exponential. A run whose powers of ``Phi`` leave the range of doubles
(a fast unstable pole over a long span) is run instead mode by mode in
balanced real Schur coordinates (:func:`scipy.signal.lfilter` for each real
pole and each complex pair), where a mode that nothing excites stays exactly
zero. While it runs, BLAS is limited to one thread (with threadpoolctl, when
installed): the products are small or thin, and on a 2-core machine
OpenBLAS's worker threads made the whole simulation about three to ten times
slower.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg as sla

from . import tolerances as tols
from ._display import format_complex
from ._validation import as_seed, as_time
from .errors import InputError, UIOTeachError
from .observers import Observer
from .plant import Plant

__all__ = [
    "simulate",
    "linear_response",
    "check_timepts",
    "input_samples",
    "joint_system",
    "foh_matrices",
    "UIOResponse",
    "SimulationInputs",
    "SimulationOverflowError",
]


class SimulationOverflowError(UIOTeachError, OverflowError):
    """The response leaves the floating-point range: an unstable pole, too long a time span.

    ``.poles`` are the unstable poles of the plant/observer system and ``.time`` the
    first time point at which the response is no longer a finite float.
    """

    def __init__(self, message: str, poles: np.ndarray, time: float) -> None:
        super().__init__(message)
        self.poles = poles
        self.time = time


SignalLike = Callable[[np.ndarray], Any] | Sequence[Callable[[np.ndarray], Any]] | Any


class SimulationInputs(NamedTuple):
    """The input samples of a simulation, one row per channel, one column per time point.

    Attributes
    ----------
    u : numpy.ndarray
        Shape (m, N): known inputs.
    d : numpy.ndarray
        Shape (q, N): unknown inputs acting on the state.
    v : numpy.ndarray
        Shape (r, N): measurement disturbances (through ``D``).
    noise : numpy.ndarray
        Shape (p, N): measurement noise added to each output.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> res = ut.simulate(plant, obs, np.linspace(0, 1, 11), d=ut.signals.step(1.0))
    >>> res.inputs.d.shape, res.inputs.u.shape
    ((1, 11), (2, 11))
    """

    u: np.ndarray
    d: np.ndarray
    v: np.ndarray
    noise: np.ndarray


class UIOResponse:
    """The result of :func:`simulate`: plant states, measurements and the observer's estimates.

    All signals are arrays with one row per channel and one column per time
    point (python-control's convention).

    Attributes
    ----------
    time : numpy.ndarray
        Shape (N,): the time points.
    states : numpy.ndarray
        Shape (n, N): plant state ``x``.
    outputs : numpy.ndarray
        Shape (p, N): measurement ``y = C x + D v + noise``.
    estimates : numpy.ndarray
        Shape (n, N): observer estimate ``xhat``.
    error : numpy.ndarray
        Shape (n, N): estimation error ``x - xhat``.
    residual : numpy.ndarray
        Shape (p, N): output residual ``y - C xhat``.
    inputs : SimulationInputs
        The samples of ``u``, ``d``, ``v`` and ``noise`` that were applied.
    observer_states : numpy.ndarray
        Shape (n_z, N): the observer's own state ``z`` (in every observer; the Luenberger
        observer's is ``xhat``).
    plant : Plant
        The simulated plant.
    observer : Observer
        The simulated observer.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> resp = ut.simulate(plant, obs, np.linspace(0, 10, 1001),
    ...                    d=ut.signals.sinusoid(1.0, 2.0), initial_state=[1, 0, 0])
    >>> resp.states.shape, resp.estimates.shape, resp.residual.shape
    ((3, 1001), (3, 1001), (2, 1001))
    >>> bool(np.abs(resp.error[:, -1]).max() < 1e-3)
    True
    """

    def __init__(
        self,
        *,
        time: np.ndarray,
        states: np.ndarray,
        outputs: np.ndarray,
        estimates: np.ndarray,
        inputs: SimulationInputs,
        observer_states: np.ndarray,
        plant: Plant,
        observer: Observer,
    ) -> None:
        self.time = time
        self.states = states
        self.outputs = outputs
        self.estimates = estimates
        self.error = states - estimates
        residual = plant.C @ estimates
        self.residual = np.subtract(outputs, residual, out=residual)
        self.inputs = inputs
        self.observer_states = observer_states
        self.plant = plant
        self.observer = observer

    @property
    def is_discrete(self) -> bool:
        """True if the simulated plant is discrete-time."""
        return self.plant.is_discrete

    def plot(self, **kwargs: Any):
        """Draw the states with their estimates, the error and the residual.

        Parameters
        ----------
        **kwargs
            Passed to ``uio_teach.plotting.plot_response`` (``fig``,
            ``axes``, ``title``).

        Returns
        -------
        matplotlib.figure.Figure

        Examples
        --------
        >>> import numpy as np
        >>> import uio_teach as ut
        >>> plant = ut.examples.pa9()
        >>> resp = ut.simulate(plant, ut.design_uio(plant, poles=[-1, -2, -3]),
        ...                    np.linspace(0, 5, 501), initial_state=[1, 0, 0])
        >>> fig = resp.plot()
        >>> len(fig.axes)
        5
        """
        # deferred on purpose: matplotlib is heavy and only plotting needs it
        from .plotting import plot_response

        return plot_response(self, **kwargs)

    def __repr__(self) -> str:
        t = self.time
        if self.plant.is_discrete:
            # a discrete run counts steps; the sampling period is said only when it is known
            dt = self.plant.dt
            period = "" if dt is True else f" of {dt:g} s"
            span = f"steps k = 0 ... {t.size - 1}{period}"
        else:
            span = f"t = {t[0]:g} ... {t[-1]:g} s"
        e0 = float(np.max(np.abs(self.error[:, 0])))
        e1 = float(np.max(np.abs(self.error[:, -1])))
        return (
            f"UIOResponse({self.observer.family} on {self.plant!r},\n"
            f"            {t.size} samples, {span}, "
            f"max|error| {e0:.3g} at start, {e1:.3g} at end)"
        )


# validation -----------------------------------------------------------------------------


def check_timepts(timepts: Any) -> np.ndarray:
    """Time points: a read-only 1-D array, finite and strictly increasing.

    >>> check_timepts([0, 1, 2]).tolist()
    [0.0, 1.0, 2.0]
    """
    t = as_time("timepts", timepts)
    t.setflags(write=False)
    return t


def _uniform_step(t: np.ndarray) -> float | None:
    """The step of a uniform grid (``None`` if the spacing varies beyond rounding)."""
    h = (t[-1] - t[0]) / (t.size - 1)
    tol = tols.TIME_GRID_RTOL * h + 64 * np.finfo(float).eps * max(abs(t[0]), abs(t[-1]))
    steps = np.diff(t)
    if max(steps.max() - h, h - steps.min()) <= tol:
        return float(h)
    return None


def _check_discrete_grid(plant: Plant, t: np.ndarray) -> float:
    h = _uniform_step(t)
    period = "dt=True, any uniform spacing" if plant.dt is True else f"dt = {plant.dt:g}"
    if h is None:
        steps = np.diff(t)
        raise InputError(
            f"timepts must lie on the sampling grid of the discrete plant ({period}): "
            f"got a non-uniform spacing (steps from {steps.min():g} to {steps.max():g})"
        )
    if plant.dt is not True and abs(h - plant.dt) > tols.TIME_GRID_RTOL * plant.dt:
        raise InputError(
            f"timepts must lie on the sampling grid of the discrete plant: their spacing "
            f"must equal dt = {plant.dt:g}, got {h:g} (e.g. timepts = np.arange(N) * dt)"
        )
    return h


def _finite_real(name: str, arr: Any) -> np.ndarray:
    """``arr`` as a float array; complex or non-numeric values raise a ValueError naming it."""
    if isinstance(arr, (str, bytes)):
        raise InputError(f"{name} must be numeric, got the text {arr!r}")
    if np.iscomplexobj(arr):
        raise InputError(f"{name} must be real, got complex values")
    if isinstance(arr, bool) or np.asarray(arr).dtype.kind in "USb":
        raise InputError(f"{name} must hold real numbers, got {np.asarray(arr).dtype} values")
    try:
        out = np.asarray(arr, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must hold real numbers: {exc}") from None
    return out


def _call(name: str, func: Callable, t: np.ndarray, k: int) -> np.ndarray:
    try:
        raw = func(t)
    except Exception as exc:
        raise InputError(
            f"calling {name} with the array of {t.size} time points failed ({exc}); a signal "
            "must be vectorized: it receives all the time points at once"
        ) from exc
    arr = _finite_real(f"{name}(t)", raw)
    if k == 1 and arr.shape == (t.size,):
        arr = arr.reshape(1, -1)
    if arr.shape != (k, t.size):
        accepted = f"({k}, {t.size})" + (f" or ({t.size},)" if k == 1 else "")
        hint = " (for a constant c, return c + 0 * t)" if arr.ndim == 0 else ""
        raise InputError(
            f"{name}(t) must return an array of shape {accepted} (one row per channel, one "
            f"column per time point), got shape {arr.shape}{hint}"
        )
    return arr


_WHAT = {
    "u": ("known input", "m", "B"),
    "d": ("unknown input", "q", "E"),
    "v": ("measurement disturbance", "r", "D"),
}


def input_samples(name: str, value: SignalLike, k: int, t: np.ndarray) -> np.ndarray:
    """Sample a signal argument (``u``, ``d``, ``v`` of :func:`simulate`) on the grid ``t``.

    Returns a validated ``(k, N)`` float array; ``name`` names it in messages.

    >>> input_samples("d", lambda t: 2 * t, 1, np.array([0.0, 1.0])).tolist()
    [[0.0, 2.0]]
    """
    N = t.size
    if value is None:
        return np.zeros((k, N))
    if k == 0:
        if not callable(value) and not (
            isinstance(value, (list, tuple)) and value and all(callable(f) for f in value)
        ):
            arr = np.asarray(value, dtype=object) if not isinstance(value, np.ndarray) else value
            if arr.size == 0 and arr.ndim in (1, 2) and (arr.ndim == 1 or arr.shape[1] in (0, N)):
                return np.zeros((0, N))  # an absent input given as an empty array
        what, dim, mat = _WHAT[name]
        raise InputError(
            f"{name} was given but the plant has no {what} ({dim} = 0, {mat} has no columns)"
        )
    if isinstance(value, (list, tuple)) and value and all(callable(f) for f in value):
        if len(value) != k:
            raise InputError(
                f"{name} is a list of {len(value)} signals, expected {k} (one per channel)"
            )
        arr = np.vstack([_call(f"{name}[{i}]", f, t, 1) for i, f in enumerate(value)])
    elif callable(value):
        arr = _call(name, value, t, k)
    else:
        arr = _finite_real(name, value)
        if arr.ndim == 1 and k == 1:
            arr = arr.reshape(1, -1)
        if arr.shape != (k, N):
            accepted = f"({k}, {N})" + (f" or ({N},)" if k == 1 else "")
            raise InputError(
                f"{name} must have shape {accepted} (one row per channel, one column per time "
                f"point), got {arr.shape}"
            )
    if not (np.isfinite(arr.min()) and np.isfinite(arr.max())):  # a NaN or an infinity
        i, j = (int(a) for a in np.argwhere(~np.isfinite(arr))[0])
        raise InputError(
            f"{name} has a non-finite value {arr[i, j]} in channel {i} at time point {j} "
            f"(t = {t[j]:g}); all values must be finite"
        )
    return arr


def _vector(name: str, value: Any, size: int, what: str) -> np.ndarray:
    if value is None:
        return np.zeros(size)
    arr = _finite_real(name, value)
    if arr.size != size or arr.ndim > 2 or (arr.ndim == 2 and 1 not in arr.shape):
        raise InputError(f"{name} must have length {size} ({what}), got shape {arr.shape}")
    arr = arr.ravel()
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must be finite, got {arr}")
    return arr


def _noise(noise: Any, seed: Any, p: int, N: int) -> np.ndarray:
    if noise is None:
        return np.zeros((p, N))
    sd = _finite_real("noise", noise)
    if sd.ndim == 0:
        sd = np.full(p, float(sd))
    if sd.shape != (p,):
        raise InputError(
            f"noise must be one standard deviation (a scalar) or one per output (length {p}), "
            f"got shape {sd.shape}"
        )
    if not np.all(np.isfinite(sd)) or np.any(sd < 0):
        raise InputError(f"noise standard deviations must be finite and >= 0, got {sd}")
    rng = np.random.default_rng(as_seed("seed", seed))
    return sd[:, None] * rng.standard_normal((p, N))


_BLAS_LIBRARIES: list | None = None


@contextmanager
def _one_blas_thread() -> Iterator[None]:
    """Limit BLAS to one thread (if threadpoolctl is installed).

    The products here are small or thin (8 x 10 x N); on a 2-core machine
    OpenBLAS's worker threads make them several times slower, not faster.
    The BLAS libraries are looked up once (the slow part of threadpoolctl);
    then each run only reads and sets their thread counts.
    """
    global _BLAS_LIBRARIES
    if _BLAS_LIBRARIES is None:
        try:
            # deferred on purpose: optional, and only needed once a simulation runs
            from threadpoolctl import ThreadpoolController
        except ImportError:  # pragma: no cover - threadpoolctl is optional
            _BLAS_LIBRARIES = []
        else:
            _BLAS_LIBRARIES = ThreadpoolController().select(user_api="blas").lib_controllers
    before = [lib.get_num_threads() for lib in _BLAS_LIBRARIES]
    try:
        for lib in _BLAS_LIBRARIES:
            lib.set_num_threads(1)
        yield
    finally:
        for lib, threads in zip(_BLAS_LIBRARIES, before, strict=True):
            lib.set_num_threads(threads)


# the joint system and its solution --------------------------------------------------------


def joint_system(plant: Plant, observer: Observer) -> tuple[np.ndarray, np.ndarray]:
    """The plant and observer as one system: state ``[x; w]``, inputs ``[u; d; v; noise]``.

    Parameters
    ----------
    plant : Plant
        The plant.
    observer : Observer
        An observer for a plant with the same dimensions.

    Returns
    -------
    Az : numpy.ndarray, shape (n + n_w, n + n_w)
        ``[[A, 0], [B_y C, A_o]]``.
    Bz : numpy.ndarray, shape (n + n_w, m + q + r + p)
        ``[[B, E, 0, 0], [B_u, 0, B_y D, B_y]]``.

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> Az, Bz = joint_system(plant, ut.design_uio(plant, poles=[-1, -2, -3]))
    >>> Az.shape, Bz.shape
    ((6, 6), (6, 5))
    """
    return _joint(plant, observer.realization())


def _joint(plant: Plant, realization: Any) -> tuple[np.ndarray, np.ndarray]:
    """:func:`joint_system` from the observer's realization, already at hand."""
    A_o, B_u, B_y, _, _ = realization
    n, nw = plant.n, A_o.shape[0]
    q, r, p = plant.q, plant.nv, plant.p
    m = plant.m
    Az = np.zeros((n + nw, n + nw))
    Az[:n, :n] = plant.A
    Az[n:, :n] = B_y @ plant.C
    Az[n:, n:] = A_o
    Bz = np.zeros((n + nw, m + q + r + p))
    Bz[:n, :m] = plant.B
    Bz[:n, m : m + q] = plant.E
    Bz[n:, :m] = B_u
    Bz[n:, m + q : m + q + r] = B_y @ plant.D
    Bz[n:, m + q + r :] = B_y
    return Az, Bz


def foh_matrices(A: np.ndarray, B: np.ndarray, h: float) -> tuple[np.ndarray, ...]:
    """Exact discretization of ``z' = A z + B s`` for inputs linear between samples.

    ``z(t + h) = Phi z(t) + G0 s(t) + G1 s(t + h)``, from one matrix
    exponential of the augmented matrix ``[[A h, B h, 0], [0, 0, I], [0, 0, 0]]``.

    Parameters
    ----------
    A : numpy.ndarray, shape (n, n)
        State matrix.
    B : numpy.ndarray, shape (n, k)
        Input matrix.
    h : float
        The step.

    Returns
    -------
    Phi, G0, G1 : numpy.ndarray
        ``Phi = expm(A h)``; ``G0 + G1 = integral of expm(A s) B over [0, h]``.

    Examples
    --------
    >>> import numpy as np
    >>> Phi, G0, G1 = foh_matrices(np.array([[-1.0]]), np.array([[1.0]]), 0.1)
    >>> bool(np.isclose(Phi[0, 0], np.exp(-0.1)))
    True
    >>> bool(np.isclose(G0[0, 0] + G1[0, 0], 1 - np.exp(-0.1)))
    True
    """
    n, k = B.shape
    M = np.zeros((n + 2 * k, n + 2 * k))
    M[:n, :n] = A * h
    M[:n, n : n + k] = B * h
    M[n : n + k, n + k :] = np.eye(k)
    eM = sla.expm(M)
    Phi = eM[:n, :n]
    G1 = eM[:n, n + k :]
    G0 = eM[:n, n : n + k] - G1
    return Phi, G0, G1


def _schur(Phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Schur form ``Phi = Z T Z^H``: real when every eigenvalue is real, complex otherwise."""
    T, Z = sla.schur(Phi, output="real")
    if np.any(np.diag(T, -1) != 0):
        T, Z = sla.schur(Phi, output="complex")
    return T, Z


def _interleave(M: np.ndarray, axis: int) -> np.ndarray:
    """Real and imaginary parts of a complex matrix interleaved along ``axis``."""
    return np.stack([M.real, M.imag], axis=axis + 1).reshape(
        (-1, M.shape[1]) if axis == 0 else (M.shape[0], -1)
    )


# A complex pair is run as one complex mode when its 2 x 2 eigenvector matrix has at most this
# condition number: rounding in the pair's forcing and state then grows by at most this factor
# (1e3 * eps = 2e-13 relative to the pair). Beyond it (a nearly defective pair: two almost equal
# real poles split by rounding) the triangular complex Schur form is used instead.
_PAIR_COND = 1e3


def _pair_mode(B: np.ndarray) -> tuple[complex, np.ndarray, np.ndarray] | None:
    """One complex mode of a real 2 x 2 block with complex eigenvalues ``mu``, ``conj(mu)``.

    ``B = W diag(mu, conj(mu)) W^-1`` with ``W = [w, conj(w)]``: a real state ``zeta`` of the
    block is ``2 Re(w eta)`` with ``eta = v . zeta`` (``v`` the first row of ``W^-1``), and
    ``eta`` obeys the scalar recursion of ``mu``. ``None`` if ``W`` is ill-conditioned.
    """
    a, b, c, d = B[0, 0], B[0, 1], B[1, 0], B[1, 1]
    disc = 0.25 * (a - d) ** 2 + b * c  # negative for a complex pair
    if not disc < 0 or b == 0:
        return None
    mu = complex(0.5 * (a + d), np.sqrt(-disc))
    w = np.array([b, mu - a])
    w /= np.linalg.norm(w)
    s = abs(w[0] ** 2 + w[1] ** 2)  # the singular values of W are sqrt(1 +- s)
    if not (1 - s) * _PAIR_COND**2 > 1 + s:
        return None
    det = w[0] * w[1].conjugate() - w[0].conjugate() * w[1]
    v = np.array([w[1].conjugate(), -w[0].conjugate()]) / det
    return mu, w, v


def _real_modes(T: np.ndarray) -> list[tuple[int, int, Any]] | None:
    """The diagonal blocks of a real Schur form, last first: ``(start, stop, mode)``.

    ``mode`` is the eigenvalue of a 1 x 1 block, or :func:`_pair_mode`'s result for a 2 x 2
    block; ``None`` if some complex pair is too ill-conditioned to run as one complex mode.
    """
    nz = T.shape[0]
    blocks = []
    i = 0
    while i < nz:
        if i + 1 < nz and T[i + 1, i] != 0:
            mode = _pair_mode(T[i : i + 2, i : i + 2])
            if mode is None:
                return None
            blocks.append((i, i + 2, mode))
            i += 2
        else:
            blocks.append((i, i + 1, T[i, i]))
            i += 1
    return blocks[::-1]


# Block lengths of the scan: a block's own response is one product with a block Toeplitz matrix
# of L x L blocks (cost ~ L per sample), the block starts one recursion L times shorter. The
# first level, over all samples, reads the inputs and writes the signals: short blocks keep
# its product small; the levels above run on few block starts, where longer blocks save steps.
_FIRST_BLOCK = 8
_BLOCK = 16
# The scan forms Phi^k for k up to the span of the run. Beyond this size a power could turn an
# unexcited unstable mode (0 * huge) into noise or NaN: the modal recursion takes over.
_GROWTH = 1e100
# Entries of a power of Phi below this are set to zero: they add nothing a double can hold to
# the states, and subnormal numbers would make the products many times slower.
_NEGLIGIBLE = 1e-290


class _Growth(Exception):
    """A power of ``Phi`` too large for the block scan."""


class _Plan:
    """The one-step matrices of a system on a uniform grid, and the scan's matrices per level.

    Level ``d`` runs ``x[k+1] = P_d x[k] + G_d u[k]`` with ``P_0 = D^-1 Phi D`` (balanced,
    ``D`` diagonal of powers of 2), ``G_0 = D^-1 Gam`` and, above it, ``P_d = P_(d-1)^L``,
    ``G_d = I``. A level of block length ``L`` keeps ``P_d^L`` and the matrix ``KW`` that
    maps one block's inputs (input channel by channel at level 0, time step by time step
    above) and its starting state to the ``L`` states that follow.
    """

    def __init__(self, Phi: np.ndarray, G0: np.ndarray, G1: np.ndarray | None) -> None:
        _, (scale, _) = sla.matrix_balance(Phi, permute=False, separate=True)
        if G1 is None:
            Gam, G1 = G0, np.zeros_like(G0)
        else:
            Gam = G0 + Phi @ G1
        self.Phi, self.G0, self.G1, self.scale = Phi, G0, G1, scale
        self.P = Phi * (scale[None, :] / scale[:, None])
        self.G = Gam / scale[:, None]
        self.levels: dict[tuple[int, int], tuple[int, np.ndarray, np.ndarray]] = {}

    def level(self, depth: int, L: int) -> tuple[np.ndarray, ...]:
        """``(P_d^L, KW, ...)`` of level ``depth`` for blocks of ``L`` steps."""
        key = (depth, L)
        if key not in self.levels:
            if depth == 0:
                self.levels[key] = _first_level(self.P, self.G, L)
            else:
                below = _FIRST_BLOCK if depth == 1 else _BLOCK
                self.levels[key] = _block_matrices(self.level(depth - 1, below)[0], L)
        return self.levels[key]


def _powers(P: np.ndarray, L: int) -> np.ndarray:
    """``P^0 ... P^L`` stacked; :class:`_Growth` if one exceeds ``_GROWTH`` or is not finite."""
    nx = P.shape[0]
    pw = np.empty((L + 1, nx, nx))
    pw[0] = np.eye(nx)
    pw[1] = P
    known = 1  # P^1 ... P^known are in place: the next ones are those times P^known
    while known < L:
        more = min(known, L - known)
        np.matmul(pw[1 : more + 1], pw[known], out=pw[known + 1 : known + more + 1])
        known += more
    if not np.abs(pw).max() <= _GROWTH:
        raise _Growth
    pw[np.abs(pw) < _NEGLIGIBLE] = 0.0
    return pw


def _first_level(P: np.ndarray, G: np.ndarray, L: int) -> tuple[np.ndarray, ...]:
    """``(P^L, KW, Kend)`` for blocks of ``L`` steps of ``x[k+1] = P x[k] + G s[k]``.

    A block's row ``[s_block, x[bL]]`` (inputs channel by channel, then the block's
    start) times ``KW`` gives ``[x[bL + i], s[bL + i]]`` for ``i = 0 ... L-1``: the
    states with the inputs beside them (copied exactly, by ones), ready for the outputs.
    ``KW = [K; W]``: ``K`` block Toeplitz with blocks ``(P^(i-1-j) G)^T`` for ``j < i``,
    ``W = [I, P^T, ... (P^(L-1))^T]``. ``s_block @ Kend`` is the block's end state
    ``x[bL + L]`` from rest.
    """
    nx, ns = G.shape
    pw = _powers(P, L)
    PG = np.concatenate([np.zeros((1, nx, ns)), pw[:L] @ G])  # P^(m-1) G, zero for m = 0
    lag = np.arange(L)[None, :] - np.arange(L)[:, None]  # i - j: input step j, state step i
    # KW[channel, j, i, state + input]
    KW = np.zeros((ns, L, L, nx + ns))
    KW[..., :nx] = PG.transpose(2, 0, 1)[:, np.maximum(lag, 0)]  # [channel, j, i, state]
    KW[:, lag < 0, :nx] = 0.0
    j = np.arange(L)
    KW[:, j, j, nx:] = np.eye(ns)[:, None, :]
    W = np.zeros((nx, L, nx + ns))
    W[:, :, :nx] = pw[:L].transpose(2, 0, 1)
    KW = np.vstack([KW.reshape(ns * L, L * (nx + ns)), W.reshape(nx, L * (nx + ns))])
    Kend = PG[L:0:-1].transpose(2, 0, 1).reshape(ns * L, nx)  # rows (channel, j): P^(L-1-j) G
    return pw[L], KW, Kend


def _block_matrices(P: np.ndarray, L: int) -> tuple[np.ndarray, np.ndarray]:
    """``(P^L, KW)`` for blocks of ``L`` steps of ``x[k+1] = P x[k] + u[k]``.

    A block's row ``[u[bL], ... u[bL + L-1], x[bL]]`` times ``KW`` gives its states
    ``x[bL + 1 ... bL + L]`` in a row: ``KW = [K; W]``, ``K`` block upper triangular
    Toeplitz with blocks ``(P^(i-j))^T`` and ``W = [P^T, (P^2)^T, ... (P^L)^T]``.
    """
    nx = P.shape[0]
    pw = _powers(P, L)
    lag = np.arange(L)[None, :] - np.arange(L)[:, None]  # i - j: input step j, state step i
    K = pw[:L].transpose(0, 2, 1)[np.maximum(lag, 0)]  # [j, i, input, state]
    K[lag < 0] = 0.0
    K = K.transpose(0, 2, 1, 3).reshape(L * nx, L * nx)
    W = pw[1:].transpose(2, 0, 1).reshape(nx, L * nx)
    return pw[L], np.vstack([K, W])


def _scan_steps(plan: _Plan, depth: int, U: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """States ``x[0 ... M]`` of ``x[k+1] = P_d x[k] + u[k]`` for the rows ``u[k]`` of ``U``.

    In blocks of ``L`` steps; the block starts ``x[bL]`` obey ``x[(b+1)L] = P_d^L x[bL] +
    e_b`` (``e_b`` the block's end state from rest), level ``depth + 1``; then all
    states are one product.
    """
    M, nx = U.shape
    L = min(_BLOCK, M)
    nb, r = divmod(M, L)
    PL, KW = plan.level(depth, L)
    A = np.empty((nb + (r > 0), (L + 1) * nx))
    A[:nb, : L * nx] = U[: nb * L].reshape(nb, L * nx)
    if r:
        A[nb, : r * nx] = U[nb * L :].ravel()
        A[nb, r * nx : L * nx] = 0.0
    _starts(plan, depth, A, A[:-1, : L * nx] @ KW[: L * nx, -nx:], x0)
    X = np.empty((A.shape[0] * L + 1, nx))
    X[0] = x0
    np.matmul(A, KW, out=X[1:].reshape(A.shape[0], L * nx))
    return X[: M + 1]


def _starts(plan: _Plan, depth: int, A: np.ndarray, ends: np.ndarray, x0: np.ndarray) -> None:
    """The block starts into the last columns of ``A``, from the blocks' ends from rest."""
    nx = x0.size
    if A.shape[0] == 1:
        A[0, -nx:] = x0
    else:
        A[:, -nx:] = _scan_steps(plan, depth + 1, ends, x0)


def _scan(plan: _Plan, S: np.ndarray, xi0: np.ndarray, W: np.ndarray) -> np.ndarray:
    """The signals ``W @ [xi'[k]; s[k]]`` (``xi' = D^-1 xi`` balanced), shape (N, rows).

    Time runs along the first axis. A parallel scan in blocks of ``L`` steps: inside a
    block the response from rest, ``x[bL + i] - P^i x[bL] = sum_j P^(i-1-j) G s[bL + j]``,
    is one product of all blocks' inputs with a block Toeplitz matrix; the block starts
    obey a recursion ``L`` times shorter, solved the same way (:func:`_scan_steps`). Every
    term is a power of ``P`` applied to a state or an input, as in the one-step recursion,
    with fewer roundings. The map ``W`` to the signals is folded into the last product, so
    that the states themselves are never stored.
    """
    ns, N = S.shape
    nx = plan.P.shape[0]
    L = min(_FIRST_BLOCK, N)
    nb, r = divmod(N, L)
    PL, KW, Kend = plan.level(0, L)
    A = np.empty((nb + (r > 0), ns * L + nx))
    blocks = A[:, : ns * L].reshape(A.shape[0], ns, L).transpose(1, 0, 2)  # [channel, block, step]
    blocks[:, :nb] = S[:, : nb * L].reshape(ns, nb, L)
    if r:
        blocks[:, nb, :r] = S[:, nb * L :]
        blocks[:, nb, r:] = 0.0
    x0 = xi0 / plan.scale
    _starts(plan, 0, A, A[:-1, : ns * L] @ Kend, x0)
    rows = W.shape[0]
    KWout = (KW.reshape(-1, nx + ns) @ W.T).reshape(KW.shape[0], L * rows)
    Y = np.empty((A.shape[0] * L, rows))
    np.matmul(A, KWout, out=Y.reshape(A.shape[0], L * rows))
    return Y[:N]


_PLANS: dict[tuple, _Plan] = {}
_PLANS_KEPT = 8  # systems whose one-step matrices are kept (the most recently used)
_PLANS_LOCK = threading.Lock()


def _plan(key: tuple, make: Callable[[], tuple]) -> _Plan:
    """The plan of a system and step, built once: recalled while the same observer is rerun."""
    with _PLANS_LOCK:
        plan = _PLANS.pop(key, None)
    if plan is None:
        plan = _Plan(*make())
    with _PLANS_LOCK:
        _PLANS[key] = plan  # most recent last
        while len(_PLANS) > _PLANS_KEPT:
            del _PLANS[next(iter(_PLANS))]
    return plan


def _recursion(
    plan: _Plan, S: np.ndarray, z0: np.ndarray, output: np.ndarray | None = None
) -> np.ndarray:
    """All states of ``z[k+1] = Phi z[k] + G0 s[k] + G1 s[k+1]``, ``z[0] = z0``.

    With ``output``, ``output @ [z; s]`` instead (see :func:`linear_response`).

    ``xi[k] = z[k] - G1 s[k]`` obeys ``xi[k+1] = Phi xi[k] + Gam s[k]`` with
    ``Gam = G0 + Phi G1``. ``Phi`` is first balanced (``D^-1 Phi D`` with a
    diagonal ``D`` of powers of 2, exact), so that states of very different
    size keep their own relative accuracy. The recursion is then run by the
    block scan :func:`_scan` (matrix products only, no eigenvectors: defective and
    non-normal ``Phi`` need no special care), and ``z = D xi' + G1 s`` is mapped
    to the outputs in one more product. When a power of ``Phi`` over the span grows
    too large for the scan (a fast unstable pole), :func:`_recursion_modes` runs it
    mode by mode instead.
    """
    nz = plan.P.shape[0]
    G1, scale = plan.G1, plan.scale
    # z = D xi' + G1 s, and on to the outputs if asked: W @ [xi'; s]
    if output is None:
        W = np.hstack([np.diag(scale), G1])
    else:
        W = np.hstack([output[:, :nz] * scale[None, :], output[:, :nz] @ G1 + output[:, nz:]])
    try:
        out = _scan(plan, S, z0 - G1 @ S[:, 0], W).T
    except _Growth:
        return _recursion_modes(plan.Phi, plan.G0, plan.G1, S, z0, output)
    # the first column exactly, not through the change of coordinates
    out[:, 0] = z0 if output is None else output @ np.concatenate([z0, S[:, 0]])
    return out


def _recursion_modes(
    Phi: np.ndarray,
    G0: np.ndarray,
    G1: np.ndarray | None,
    S: np.ndarray,
    z0: np.ndarray,
    output: np.ndarray | None = None,
) -> np.ndarray:
    """:func:`_recursion` mode by mode: for powers of ``Phi`` too large for the block scan.

    ``xi[k] = z[k] - G1 s[k]`` obeys ``xi[k+1] = Phi xi[k] + Gam s[k]`` with
    ``Gam = G0 + Phi G1``. ``Phi`` is first balanced (``D^-1 Phi D`` with a
    diagonal ``D`` of powers of 2, exact), so that states of very different
    size keep their own relative accuracy. In the real Schur coordinates
    ``zeta = Z^T D^-1 xi`` (orthogonal ``Z``) the recursion is ``zeta[k+1] = T
    zeta[k] + H s[k]`` with ``T`` block upper triangular: 1 x 1 blocks for real
    eigenvalues, 2 x 2 blocks for complex pairs.

    The blocks are solved last first (back substitution). A block's forcing
    ``H_i s[k] + sum_{j below} T_ij zeta_j[k]`` for every step is one matrix
    product with the rows already solved and the inputs. A 1 x 1 block is
    then a real scalar recursion; a 2 x 2 block is one complex scalar
    recursion (``zeta_i = 2 Re(w eta)``, see :func:`_pair_mode`), whose real
    and imaginary parts are kept as the block's coordinates (the coefficients
    that read them, ``T`` above the block and the output map, are turned to
    match). Each recursion runs in compiled code,
    :func:`scipy.signal.lfilter`, with no Python loop over the samples.
    Finally ``z = D Z zeta + G1 s``, one more matrix product. A complex pair
    with an ill-conditioned 2 x 2 eigenvector matrix (nearly defective) sends
    the whole recursion to :func:`_recursion_complex`, which keeps the
    triangular form.

    Memory is kept low (large temporaries are slow to allocate): one work
    array ``Q = [zeta; s]`` holds the solved coordinates followed by the
    inputs, so each block's forcing is one product with ``Q[below]``.
    """
    from scipy.signal import lfilter  # deferred on purpose: scipy.signal takes a second to import

    nz, ns, N = Phi.shape[0], S.shape[0], S.shape[1]
    _, (scale, _) = sla.matrix_balance(Phi, permute=False, separate=True)
    T, Z = sla.schur(Phi * (scale[None, :] / scale[:, None]), output="real")
    blocks = _real_modes(T)
    if blocks is None:
        return _map(output, _recursion_complex(Phi, G0, G1, S, z0), S)
    if G1 is None:
        Gam, xi0, G1 = G0, z0, np.zeros_like(G0)
    else:
        Gam, xi0 = G0 + Phi @ G1, z0 - G1 @ S[:, 0]
    Zin = Z.T / scale[None, :]  # zeta = Z^T D^-1 xi
    zeta0 = Zin @ xi0
    # the rows of M read [zeta; s]: block i's forcing is M[i, below] @ Q[below]
    M = np.hstack([T, Zin @ Gam])
    Zout = scale[:, None] * Z  # xi = D Z zeta
    Q = np.empty((nz + ns, N))
    Q[nz:] = S
    for i, j, mode in blocks:
        if j == i + 1:
            lam = mode
            g = M[i, j:] @ Q[j:, :-1]
            Q[i, 1:] = lfilter([1.0], [1.0, -lam], g, zi=[lam * zeta0[i]])[0]
            Q[i, 0] = zeta0[i]
        else:
            mu, w, v = mode
            # the forcing of eta = v . zeta_i, computed transposed: its rows are complex numbers
            c = v @ M[i:j, j:]
            g = Q[j:, :-1].T @ np.column_stack([c.real, c.imag])
            eta0 = v @ zeta0[i:j]
            eta = lfilter([1.0], [1.0, -mu], g.view(complex)[:, 0], zi=[mu * eta0])[0]
            Q[i : i + 2, 1:] = eta.view(float).reshape(-1, 2).T
            Q[i : i + 2, 0] = eta0.real, eta0.imag
            # zeta_i = 2 Re(w eta) = R [Re eta; Im eta]: whatever reads zeta_i now reads eta
            R = 2 * np.column_stack([w.real, -w.imag])
            M[:i, i:j] = M[:i, i:j] @ R
            Zout[:, i:j] = Zout[:, i:j] @ R
    # back to the original coordinates, z = D Z zeta + G1 s, and on to the outputs if asked
    W = np.hstack([Zout, G1])
    if output is not None:
        W = output[:, :nz] @ W
        W[:, nz:] += output[:, nz:]
    out = W @ Q
    # the first column exactly, not through the change of coordinates
    out[:, 0] = z0 if output is None else output @ np.concatenate([z0, S[:, 0]])
    return out


def _map(output: np.ndarray | None, z: np.ndarray, S: np.ndarray) -> np.ndarray:
    """``output @ [z; s]``, or ``z`` itself without an output map."""
    if output is None:
        return z
    return output[:, : z.shape[0]] @ z + output[:, z.shape[0] :] @ S


def _recursion_complex(
    Phi: np.ndarray, G0: np.ndarray, G1: np.ndarray | None, S: np.ndarray, z0: np.ndarray
) -> np.ndarray:
    """:func:`_recursion` in the complex Schur form, triangular: for nearly defective pairs.

    Every coordinate is a scalar recursion (complex ones take two real rows of
    the work array, real and imaginary part), coupled to the coordinates below
    it through ``T_ij``; no eigenvector matrix is formed, so its accuracy does
    not depend on how close to defective ``Phi`` is.
    """
    from scipy.signal import lfilter  # deferred on purpose: scipy.signal takes a second to import

    nz, ns, N = Phi.shape[0], S.shape[0], S.shape[1]
    T, Z = _schur(Phi)
    cplx = np.iscomplexobj(T)
    if G1 is None:
        Gam, xi0, G1 = G0, z0, np.zeros_like(G0)
    else:
        Gam, xi0 = G0 + Phi @ G1, z0 - G1 @ S[:, 0]
    H = Z.conj().T @ Gam
    zeta0 = Z.conj().T @ xi0
    w = 2 if cplx else 1  # rows per Schur coordinate
    Q = np.empty((w * nz + ns, N))
    Q[w * nz :] = S
    np.matmul(_interleave(H, 0) if cplx else H, S, out=Q[: w * nz])
    for i in range(nz - 1, -1, -1):
        rows = Q[w * i : w * i + w, :-1]  # forcing of coordinate i
        if i < nz - 1:
            # coupling to the coordinates below, already solved: sum_{j>i} T_ij zeta_j[k]
            t = T[i : i + 1, i + 1 :]
            coef = (
                np.vstack([_interleave(t.conj(), 1), _interleave(1j * t.conj(), 1)]) if cplx else t
            )
            # computed transposed, (N - 1, w): with w = 2 its rows are complex numbers
            c = Q[w * (i + 1) : w * nz, :-1].T @ coef.T
            c += rows.T
        else:
            c = np.ascontiguousarray(rows.T)
        g = c.view(complex)[:, 0] if cplx else c[:, 0]
        lam = T[i, i]
        out = lfilter([1.0], [1.0, -lam], g, zi=[lam * zeta0[i]])[0]
        if cplx:
            Q[2 * i, 0], Q[2 * i + 1, 0] = zeta0[i].real, zeta0[i].imag
            Q[2 * i : 2 * i + 2, 1:] = out.view(float).reshape(-1, 2).T
        else:
            Q[i, 0], Q[i, 1:] = zeta0[i], out
    # back to the original coordinates: z = Re(Z zeta) + G1 s
    Zr = _interleave(Z.conj(), 1) if cplx else Z
    z = np.hstack([Zr, G1]) @ Q
    z[:, 0] = z0  # exactly, not through the change of coordinates
    return z


def _stepwise(
    A: np.ndarray, B: np.ndarray, t: np.ndarray, S: np.ndarray, z0: np.ndarray
) -> np.ndarray:
    """The same first-order-hold solution on a non-uniform grid, one step at a time."""
    z = np.empty((A.shape[0], t.size))
    z[:, 0] = z0
    cache: dict[float, tuple[np.ndarray, ...]] = {}
    for k, h in enumerate(np.diff(t)):
        if h not in cache:
            cache[h] = foh_matrices(A, B, h)
        Phi, G0, G1 = cache[h]
        z[:, k + 1] = Phi @ z[:, k] + G0 @ S[:, k] + G1 @ S[:, k + 1]
    return z


def linear_response(
    A: np.ndarray,
    B: np.ndarray,
    timepts: np.ndarray,
    inputs: np.ndarray,
    initial_state: np.ndarray,
    *,
    discrete: bool = False,
    output: np.ndarray | None = None,
) -> np.ndarray:
    """All states of ``z' = A z + B s`` (``z[k+1] = A z[k] + B s[k]``) on a time grid.

    The one simulation engine of the package (:func:`~uio_teach.simulate` and
    :func:`~uio_teach.observer_residual` both run on it): in
    continuous time the inputs are taken as linear between samples and the
    system is solved exactly over each step (first-order hold, one matrix
    exponential per step size), with the block scan on a uniform grid
    (see the module documentation); in discrete time the recursion itself. BLAS is limited to one
    thread while it runs.

    Parameters
    ----------
    A : numpy.ndarray, shape (nz, nz)
    B : numpy.ndarray, shape (nz, ns)
    timepts : numpy.ndarray, shape (N,)
        Increasing time points (one per step in discrete time).
    inputs : numpy.ndarray, shape (ns, N)
        Input samples.
    initial_state : numpy.ndarray, shape (nz,)
    discrete : bool
    output : numpy.ndarray, shape (k, nz + ns), optional
        Return ``output @ [z; s]`` (signals read off the states and the
        inputs, such as measurements and estimates) instead of ``z``: it is
        folded into the scan's last product, so the states are never stored.

    Returns
    -------
    numpy.ndarray, shape (nz, N) or (k, N)
        Time along the second axis; stored time-major (the transpose of a
        C-ordered array) when the block scan computed it. May contain
        non-finite values when the response overflows; callers check the range.

    Raises
    ------
    SimulationOverflowError
        The one-step matrices themselves overflow (``.time`` is the second
        time point, ``.poles`` the eigenvalues of ``A`` with positive real part).

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.simulation import linear_response
    >>> t = np.linspace(0.0, 1.0, 11)
    >>> z = linear_response(np.array([[-1.0]]), np.zeros((1, 0)), t, np.zeros((0, 11)),
    ...                     np.array([1.0]))
    >>> bool(np.allclose(z[0], np.exp(-t)))
    True
    """
    t = np.asarray(timepts, float)
    S = np.asarray(inputs, float)
    z0 = np.asarray(initial_state, float)
    with _one_blas_thread(), np.errstate(all="ignore"):
        if discrete:
            key = ("discrete", A.shape, B.shape, A.tobytes(), B.tobytes())
            return _recursion(_plan(key, lambda: (A.copy(), B.copy(), None)), S, z0, output)
        h = _uniform_step(t)
        if h is None:
            return _map(output, _stepwise(A, B, t, S, z0), S)

        def one_step() -> tuple[np.ndarray, ...]:
            Phi, G0, G1 = foh_matrices(A, B, h)
            if not (np.all(np.isfinite(Phi)) and np.all(np.isfinite(G0 + G1))):
                poles = np.linalg.eigvals(A)
                raise SimulationOverflowError(
                    "the response leaves the floating-point range within one time step",
                    poles[poles.real > 0],
                    float(t[min(1, t.size - 1)]),
                )
            return Phi, G0, G1

        key = (h, A.shape, B.shape, A.tobytes(), B.tobytes())
        return _recursion(_plan(key, one_step), S, z0, output)


_BIG = 1e300  # beyond this a response is about to leave the float range (1.8e308)


def _check_range(z: np.ndarray, Az: np.ndarray, plant: Plant, t: np.ndarray) -> None:
    """Raise ``SimulationOverflowError`` if the response leaves the float range."""
    if -_BIG <= z.min() and z.max() <= _BIG:  # false for a NaN too; two passes, no temporaries
        return
    bad = ~np.isfinite(z) | (np.abs(z) > _BIG)
    if np.any(bad):
        k = int(np.argmax(bad.any(axis=0)))
        raise _overflow(Az, plant, t, k)


def _overflow(Az: np.ndarray, plant: Plant, t: np.ndarray, k: int) -> SimulationOverflowError:
    """The error explaining an overflow at time point ``k``: which poles, and when."""
    poles = np.linalg.eigvals(Az)
    discrete = plant.is_discrete
    growth = np.log(np.abs(poles)) if discrete else poles.real
    unstable = poles[growth > 0]
    n = plant.n
    # each plant pole names one unstable pole of the joint system; the rest are the observer's
    # (a pole that both have, e.g. an observer without gain on an unstable mode, is named twice)
    plant_poles = list(np.linalg.eigvals(Az[:n, :n]))
    words = []
    for pole in sorted(unstable, key=lambda z: -abs(z)):
        gaps = [abs(p - pole) for p in plant_poles]
        if gaps and min(gaps) <= tols.MODES_RTOL * max(1, abs(pole)):
            plant_poles.pop(int(np.argmin(gaps)))
            src = "plant"
        else:
            src = "observer"
        words.append(f"{format_complex(pole)} ({src})")
    rate = float(np.max(growth)) if growth.size else 0.0
    when = f"t = {t[k]:g}" if k < t.size else "the first step"
    expected = ""
    if rate > 0:
        span = (
            np.log(_BIG) / rate * (1.0 if not discrete else (1.0 if plant.dt is True else plant.dt))
        )
        expected = (
            f"; growing like exp({rate:.3g} t)"
            if not discrete
            else f"; growing like {np.exp(rate):.3g}^k"
        ) + f", a response of size 1 reaches 1e300 after about {span:.3g} time units"
    return SimulationOverflowError(
        f"the response leaves the floating-point range at {when}: the plant/observer system "
        f"has unstable pole(s) {', '.join(words) or 'none found'}{expected}. Simulate a "
        "shorter time span, or stabilize the plant or the observer",
        unstable,
        float(t[min(k, t.size - 1)]),
    )


def simulate(
    plant: Plant,
    observer: Observer,
    timepts: Any,
    *,
    u: SignalLike = None,
    d: SignalLike = None,
    v: SignalLike = None,
    initial_state: Any = None,
    observer_state: Any = None,
    noise: Any = None,
    seed: int | np.random.Generator | None = None,
) -> UIOResponse:
    """Simulate a plant and an observer together; exact for inputs linear between samples.

    The plant ``x' = A x + B u + E d``, ``y = C x + D v + noise`` (``x[k+1] =
    ...`` when discrete) drives the observer ``w' = A_o w + B_u u + B_y y``,
    ``xhat = C_o w + D_y y``. In continuous time the inputs are linear between
    the time points (first-order hold) and the joint system is solved exactly
    for them, by one matrix exponential and a block scan of matrix products (see the
    module documentation); in discrete time the recursion is the plant's own.

    Parameters
    ----------
    plant : Plant
        The true plant. It may differ from ``observer.plant`` (to study model
        errors) but must have the same ``n``, ``m``, ``p`` and time domain.
    observer : Observer
        Any observer of this package (``design_uio``, ``design_pmo``,
        ``design_ginverse``, ``design_luenberger``).
    timepts : array_like, shape (N,)
        Strictly increasing time points, at least 2. For a discrete plant
        they must be uniformly spaced with spacing ``dt`` (any uniform
        spacing when ``dt=True``: one time point per step). A non-uniform grid
        is accepted in continuous time (solved step by step, slower).
    u : callable, list of callables or array_like, optional
        Known input, ``m`` channels. A callable of time (a signal of
        :mod:`uio_teach.signals`, a :func:`~uio_teach.signals.stack`, or any
        vectorized function returning shape ``(m, N)``, or ``(N,)`` when
        ``m = 1``), a list of ``m`` scalar callables, or samples of shape
        ``(m, N)`` (1-D accepted when ``m = 1``). ``None`` means zero.
    d : callable, list of callables or array_like, optional
        Unknown input acting on the state, ``q`` channels; as ``u``.
    v : callable, list of callables or array_like, optional
        Measurement disturbance, ``r`` channels; as ``u``.
    initial_state : array_like, shape (n,), optional
        Plant state at ``timepts[0]``; zero by default.
    observer_state : array_like, shape (n_w,), optional
        Observer state ``w`` at ``timepts[0]``; zero by default. The first
        estimate is then ``xhat = D_y y`` (``H y`` for the UIO). For a delayed UIO
        (``design_uio(..., delay=L)``) it is the first estimate ``xhat[0]`` (n values), and
        column ``k`` of the estimates is the estimate of ``x[k]``, known ``L`` samples later:
        the last ``L`` columns are ``nan``.
    noise : float or array_like, shape (p,), optional
        Standard deviation of white Gaussian measurement noise, one value for
        all outputs or one per output. It is sampled at the time points and,
        like every input, linear between them. ``None`` means no noise.
    seed : int or numpy.random.Generator, optional
        Seed of :func:`numpy.random.default_rng` for the noise (a
        non-negative integer): the same seed gives the same noise.

    Returns
    -------
    UIOResponse
        States, outputs, estimates, error, residual and the applied inputs.

    Raises
    ------
    ValueError
        A signal of the wrong shape or with non-finite values, a callable
        returning the wrong shape, timepts that are not strictly increasing or
        (discrete plant) not on the sampling grid, an initial state of the wrong
        length, or a plant that does not match the observer. The message names
        the argument.
    OverflowError
        ``uio_teach.simulation.SimulationOverflowError``: the response leaves
        the floating-point range (an unstable pole over a long time span); the
        message names the unstable poles and the time.

    See Also
    --------
    uio_teach.reconstruct_input : estimate ``d`` from the response.

    Notes
    -----
    With the inputs linear between samples, ``z = [x; w]`` obeys
    ``z[k+1] = Phi z[k] + G0 s[k] + G1 s[k+1]`` exactly, with ``Phi, G0, G1``
    from one :func:`scipy.linalg.expm` of ``[[Az h, Bz h, 0], [0, 0, I],
    [0, 0, 0]]``. The result agrees with :func:`control.forced_response` on
    the same joint system (which uses the same convention) to rounding, and
    converges to the exact solution for smooth inputs like ``h**2``.

    Examples
    --------
    The decoupling property: the error does not depend on the unknown input.

    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> t = np.linspace(0, 20, 2001)
    >>> quiet = ut.simulate(plant, obs, t, initial_state=[1, 0, -1])
    >>> loud = ut.simulate(plant, obs, t, initial_state=[1, 0, -1],
    ...                    d=ut.signals.sinusoid(5.0, 3.0))
    >>> bool(np.allclose(quiet.error, loud.error, rtol=0, atol=1e-10))
    True
    >>> bool(np.allclose(quiet.states, loud.states, atol=0.1))
    False

    Discrete plants take one time point per step:

    >>> case = ut.examples.dt_case_study()
    >>> resp = ut.simulate(case, ut.design_pmo(case, method="lmi"), np.arange(30),
    ...                    d=np.ones(30), v=np.sin(np.arange(30)), initial_state=[1, 1, 1])
    >>> float(np.abs(resp.error[:, -1]).max()) < 1e-6
    True
    """
    if not isinstance(plant, Plant):
        raise InputError(f"plant must be a uio_teach.Plant, got {type(plant).__name__}")
    if not isinstance(observer, Observer):
        raise InputError(
            f"observer must be a uio_teach observer (design_uio, design_pmo, ...), "
            f"got {type(observer).__name__}"
        )
    design = observer.plant
    for dim in ("n", "m", "p"):
        if getattr(plant, dim) != getattr(design, dim):
            raise InputError(
                f"observer was designed for a plant with {dim} = {getattr(design, dim)}, but the "
                f"simulated plant has {dim} = {getattr(plant, dim)}"
            )
    if plant.is_discrete != design.is_discrete:
        raise InputError(
            "plant and observer must be both continuous-time or both discrete-time: plant "
            f"dt = {plant.dt!r}, observer designed for dt = {design.dt!r}"
        )

    as_seed("seed", seed)
    t = check_timepts(timepts)
    N = t.size
    if plant.is_discrete:
        _check_discrete_grid(plant, t)

    # the given inputs in one array; the recorded inputs are views of it, and those not given
    # are zero (read-only views of a single zero: no memory)
    m, q, r, p = plant.m, plant.q, plant.nv, plant.p
    channels = [("u", u, m), ("d", d, q), ("v", v, r), ("noise", noise, p)]
    given = [value is not None for _, value, _ in channels]
    keep = np.flatnonzero(np.repeat(given, [m, q, r, p]))
    S = np.empty((keep.size, N))
    recorded = {}
    row = 0
    for (name, value, size), is_given in zip(channels, given, strict=True):
        if not is_given:
            recorded[name] = np.broadcast_to(np.zeros(()), (size, N))
            continue
        if name == "noise":
            S[row : row + size] = _noise(noise, seed, p, N)
        else:
            S[row : row + size] = input_samples(name, value, size, t)
        recorded[name] = S[row : row + size]
        row += size
    S.setflags(write=False)
    inputs = SimulationInputs(**recorded)

    real = observer.realization()
    nw = real.A.shape[0]
    x0 = _vector(
        "initial_state", initial_state, plant.n, f"one value per plant state, n = {plant.n}"
    )
    # a delayed observer (delay L > 0) starts from its estimate xhat[0]: n values
    delay = getattr(observer, "delay", 0)
    w0 = _vector("observer_state", None if delay else observer_state, nw, "n_w values")
    z0 = np.concatenate([x0, w0])

    Az, Bz = _joint(plant, real)
    # the signals read off [z; s] = [x; w; u; d; v; noise], one row block each:
    # x, w, y = C x + D v + noise and xhat = C_o w + D_y y
    n = plant.n
    ns = m + q + r + p
    ny = np.zeros((p, n + nw + ns))
    ny[:, :n] = plant.C
    ny[:, n + nw + m + q : n + nw + m + q + r] = plant.D
    ny[:, n + nw + m + q + r :] = np.eye(p)
    nxhat = real.D_y @ ny
    nxhat[:, n : n + nw] += real.C
    output = np.vstack([np.eye(n + nw, n + nw + ns), ny, nxhat])
    # inputs that were not given are zero and add nothing: the engine sees the others alone
    output = np.hstack([output[:, : n + nw], output[:, n + nw + keep]])
    try:
        signals = linear_response(
            Az, Bz[:, keep], t, S, z0, discrete=plant.is_discrete, output=output
        )
    except SimulationOverflowError:
        raise _overflow(Az, plant, t, 1) from None
    with np.errstate(all="ignore"):
        # overflow is detected and explained here, not left to RuntimeWarnings and NaNs
        _check_range(signals, Az, plant, t)
    signals.setflags(write=False)
    x, w = signals[:n], signals[n : n + nw]
    y, xhat = signals[n + nw : n + nw + p], signals[n + nw + p :]
    if delay:  # the estimate of x[k] in column k (known L samples later); the last L are nan
        xhat0 = _vector("observer_state", observer_state, n, f"xhat[0], n = {n} values")
        xhat = observer.aligned_estimates(y, inputs.u, xhat0)
    return UIOResponse(
        time=t,
        states=x,
        outputs=y,
        estimates=xhat,
        inputs=inputs,
        observer_states=w,
        plant=plant,
        observer=observer,
    )
