"""Reconstruct the unknown input from the state estimate, and measure when an estimate catches up.

Once the observer's estimate ``xhat`` has converged, the plant equation
``x' = A x + B u + E d`` can be solved for ``d`` (missile paper, eq. (17))::

    dhat = E^+ (xhat' - A xhat - B u)

which needs ``E`` of full column rank and the derivative of ``xhat``.
:func:`reconstruct_input` computes it with a numerical derivative or with a
filtered derivative; :func:`catch_time` says when an estimate has caught the true
signal (what Table II of the paper reads off its figures by eye), with a stated band.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import tolerances as tols
from ._validation import as_real_array, as_real_number, as_time
from .errors import InputError
from .linalg import pinv, rank
from .plant import Plant

__all__ = ["reconstruct_input", "InputEstimate", "catch_time"]


class InputEstimate:
    """The result of :func:`reconstruct_input`.

    Attributes
    ----------
    time : numpy.ndarray
        Shape (N,): the time points of the response.
    estimates : numpy.ndarray
        Shape (q, N): the reconstructed unknown input ``dhat`` (NaN where it is not defined:
        the last sample of a discrete-time reconstruction).
    actual : numpy.ndarray or None
        Shape (q, N): the true ``d`` applied in the simulation, when the response has it.
    error : numpy.ndarray or None
        Shape (q, N): ``estimates - actual``.
    method : str
        ``"derivative"`` or ``"filtered"``.
    tau : float or None
        The filter time constant (``"filtered"`` only).
    dt : float, bool or None
        The plant's ``dt`` (``None``: continuous time).

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> resp = ut.simulate(plant, obs, np.linspace(0, 20, 4001), d=ut.signals.sinusoid())
    >>> est = ut.reconstruct_input(plant, resp)
    >>> est.estimates.shape
    (1, 4001)
    >>> bool(np.abs(est.error[:, 2000:]).max() < 1e-3)
    True
    """

    def __init__(
        self,
        *,
        time: np.ndarray,
        estimates: np.ndarray,
        actual: np.ndarray | None,
        method: str,
        tau: float | None,
        dt: float | bool | None,
    ) -> None:
        self.time = time
        self.estimates = estimates
        self.actual = actual
        self.error = None if actual is None else estimates - actual
        self.method = method
        self.tau = tau
        self.dt = dt

    def plot(self, **kwargs: Any):
        """Draw each true unknown input with its reconstruction.

        Parameters
        ----------
        **kwargs
            Passed to ``uio_teach.plotting.plot_input_estimate`` (``fig``,
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
        ...                    np.linspace(0, 5, 501), d=ut.signals.sinusoid())
        >>> len(ut.reconstruct_input(plant, resp).plot().axes)
        1
        """
        # deferred on purpose: matplotlib is heavy and only plotting needs it
        from .plotting import plot_input_estimate

        return plot_input_estimate(self, **kwargs)

    def __repr__(self) -> str:
        how = self.method + (f", tau={self.tau:g}" if self.tau is not None else "")
        q, N = self.estimates.shape
        text = f"InputEstimate({how}, q={q}, {N} samples"
        if self.error is not None and np.any(np.isfinite(self.error)):
            half = self.error[:, N // 2 :]
            text += f", max|error| over the second half {np.nanmax(np.abs(half)):.3g}"
        return text + ")"


def _check_response(plant: Plant, response: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    try:
        t = np.asarray(response.time, dtype=float)
        xhat = np.asarray(response.estimates, dtype=float)
        u = np.asarray(response.inputs.u, dtype=float)
    except AttributeError:
        raise InputError(
            "response must be the result of uio_teach.simulate (with time, estimates and "
            f"inputs.u), got {type(response).__name__}"
        ) from None
    N = t.size
    if xhat.shape != (plant.n, N):
        raise InputError(
            f"response.estimates has shape {xhat.shape}, expected ({plant.n}, {N}) for this plant"
        )
    if u.shape != (plant.m, N):
        raise InputError(
            f"response.inputs.u has shape {u.shape}, expected ({plant.m}, {N}) for this plant"
        )
    return t, xhat, u


def _lowpass_coefficients(h: float, tau: float) -> tuple[float, float, float]:
    """``y[k+1] = lam y[k] + b0 x[k] + b1 x[k+1]``: ``tau y' = x - y``, x linear on the step."""
    a = h / tau
    lam = float(np.exp(-a))
    # 1 - (1 - exp(-a)) / a: the closed form cancels (relative error about 2 eps / a), the series
    # cut after a^5 is off by a^6 / 5040 (relative a^5 / 2520); both are 4e-14 at a = 1e-2
    if a < 1e-2:
        b1 = a / 2 - a**2 / 6 + a**3 / 24 - a**4 / 120 + a**5 / 720
    else:
        b1 = 1.0 + float(np.expm1(-a)) / a
    b0 = (1.0 - lam) - b1
    return lam, b0, b1


def _lowpass(t: np.ndarray, x: np.ndarray, tau: float, y0: np.ndarray) -> np.ndarray:
    """Exact solution of ``tau y' = x - y``, ``y(t0) = y0``, for ``x`` linear between samples."""
    from scipy.signal import lfilter  # deferred on purpose: scipy.signal takes a second to import

    steps = np.diff(t)
    h = (t[-1] - t[0]) / (t.size - 1)
    y = np.empty_like(x)
    y[:, 0] = y0
    if (
        np.max(np.abs(steps - h))
        <= tols.TIME_GRID_RTOL * h + 64 * np.finfo(float).eps * np.abs(t).max()
    ):
        lam, b0, b1 = _lowpass_coefficients(h, tau)
        zi = (b0 * x[:, 0] + lam * y0)[:, None]
        y[:, 1:] = lfilter([b1, b0], [1.0, -lam], x[:, 1:], axis=1, zi=zi)[0]
    else:  # non-uniform grid: one step at a time
        for k, hk in enumerate(steps):
            lam, b0, b1 = _lowpass_coefficients(hk, tau)
            y[:, k + 1] = lam * y[:, k] + b0 * x[:, k] + b1 * x[:, k + 1]
    return y


def reconstruct_input(
    plant: Plant,
    response: Any,
    *,
    method: str = "derivative",
    tau: float | None = None,
) -> InputEstimate:
    r"""Estimate the unknown input ``d`` from the observer's state estimate.

    Continuous time (missile paper, eq. (17))::

        dhat = E^+ (xhat' - A xhat - B u)

    * ``method="derivative"``: ``xhat'`` is the numerical derivative
      :func:`numpy.gradient` (second-order accurate central differences,
      second-order one-sided at the ends). Accurate for a smooth, noise-free
      estimate; but it amplifies measurement noise: white noise of standard
      deviation ``sigma`` on ``xhat`` becomes noise of about
      ``sigma / (sqrt(2) h)`` on the derivative, ``h`` the time step.
    * ``method="filtered"``: the same expression passed through the
      first-order low-pass ``1 / (tau s + 1)``. With ``xf`` the low-passed
      ``xhat`` (started at ``xhat(t0)``) and the low-passed
      ``A xhat + B u`` (started at 0)::

          dhat = E^+ ((xhat - xf) / tau - lowpass(A xhat + B u))

      since ``(xhat - xf) / tau`` is the filtered derivative
      ``s / (tau s + 1) xhat``. Both filters are solved exactly on the grid
      for signals linear between samples. The trade-off: noise above about
      ``1 / tau`` rad/s is attenuated (for white sample noise the noise on
      the derivative falls from about ``sigma / (sqrt(2) h)`` to about
      ``sigma / tau``, i.e. by ``tau / (sqrt(2) h)``), but ``dhat`` lags ``d``
      by about ``tau`` and a
      component of frequency ``w`` is scaled by ``1 / sqrt(1 + (w tau)**2)``.
      Choose ``tau`` well above ``h`` and well below the time scale of ``d``.

    Discrete time: the one-step form ``dhat[k] = E^+ (xhat[k+1] - A xhat[k]
    - B u[k])`` (the last sample is NaN); ``"filtered"`` then applies the
    low-pass ``y[k] = a y[k-1] + (1 - a) dhat[k]``, ``a = exp(-dt / tau)``,
    from rest (``dt=True`` counts as 1).

    Parameters
    ----------
    plant : Plant
        The plant model: ``A``, ``B`` and ``E`` are used.
    response : UIOResponse
        A simulation of this plant (:func:`uio_teach.simulate`): its
        ``time``, ``estimates`` and ``inputs.u`` are used, and ``inputs.d``
        is kept as the true input for comparison.
    method : {"derivative", "filtered"}
        How the derivative of ``xhat`` is taken.
    tau : float, optional
        Time constant of the low-pass filter (same time units as ``time``),
        required (> 0) with ``method="filtered"`` and not allowed otherwise.

    Returns
    -------
    InputEstimate

    Raises
    ------
    ValueError
        ``E`` does not have full column rank (then only ``E d`` can be
        recovered, not ``d``), the plant has no unknown input, a bad
        ``method`` or ``tau``, or a response that does not fit the plant.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.missile_autopilot()
    >>> obs = ut.design_ginverse(plant)
    >>> t = np.linspace(0, 0.5, 5001)
    >>> resp = ut.simulate(plant, obs, t, d=ut.examples.missile_inputs(),
    ...                    initial_state=ut.examples.MISSILE_PUBLISHED.x0)
    >>> est = ut.reconstruct_input(plant, resp)
    >>> late = t > 0.1
    >>> bool(np.abs(est.error[:, late]).max() < 0.05)
    True
    >>> ut.reconstruct_input(plant, resp, method="filtered", tau=1e-3).method
    'filtered'
    """
    from scipy.signal import lfilter  # deferred on purpose: scipy.signal takes a second to import

    if not isinstance(plant, Plant):
        raise InputError(f"plant must be a uio_teach.Plant, got {type(plant).__name__}")
    if method not in ("derivative", "filtered"):
        raise InputError(f"method must be 'derivative' or 'filtered', got {method!r}")
    if method == "filtered":
        ok = (
            isinstance(tau, (int, float, np.integer, np.floating))
            and not isinstance(tau, bool)
            and np.isfinite(tau)
            and tau > 0
        )
        if not ok:
            raise InputError(
                f"tau must be a positive time constant with method='filtered', got {tau!r}"
            )
        tau = float(tau)
    elif tau is not None:
        raise InputError("tau is the filter time constant: give it only with method='filtered'")
    if plant.q == 0:
        raise InputError("the plant has no unknown input (E has no columns): nothing to recover")
    if rank(plant.E) < plant.q:
        raise InputError(
            f"E has rank {rank(plant.E)} < q = {plant.q} (not full column rank): different "
            "unknown inputs d give the same E d, so only E d can be recovered, not d"
        )
    t, xhat, u = _check_response(plant, response)
    Ep = pinv(plant.E)
    drift = plant.A @ xhat + plant.B @ u

    if plant.is_discrete:
        est = np.full((plant.q, t.size), np.nan)
        est[:, :-1] = Ep @ (xhat[:, 1:] - drift[:, :-1])
        if method == "filtered":
            step = 1.0 if plant.dt is True else float(plant.dt)
            a = float(np.exp(-step / tau))
            est[:, :-1] = lfilter([1.0 - a], [1.0, -a], est[:, :-1], axis=1)
    elif method == "derivative":
        est = Ep @ (np.gradient(xhat, t, axis=1, edge_order=2) - drift)
    else:
        xf = _lowpass(t, xhat, tau, xhat[:, 0])
        gf = _lowpass(t, drift, tau, np.zeros(plant.n))
        est = Ep @ ((xhat - xf) / tau - gf)

    actual = None
    inputs = getattr(response, "inputs", None)
    d = getattr(inputs, "d", None)
    if d is not None and np.shape(d) == est.shape:
        actual = np.asarray(d, dtype=float)
    est.setflags(write=False)
    return InputEstimate(time=t, estimates=est, actual=actual, method=method, tau=tau, dt=plant.dt)


def catch_time(time: Any, actual: Any, estimate: Any, *, tol: float = 0.02) -> float | np.ndarray:
    """When an estimate has caught a signal: the last time the error leaves the tolerance band.

    The band is ``tol * max|actual|`` (per channel): the estimate stays within
    it after the returned time. Table II of the missile paper reads such times
    off its figures by eye and states no band; this one makes them precise.

    Parameters
    ----------
    time : array_like, shape (N,)
        Time points.
    actual : array_like, shape (N,) or (k, N)
        The true signal; rows are channels.
    estimate : array_like, same shape as ``actual``
        Its estimate. Trailing NaN samples (the undefined last sample of a
        discrete reconstruction) are not judged; any other NaN counts as
        outside the band (NaN is never "caught").
    tol : float, optional
        Relative tolerance, default 2 %.

    Returns
    -------
    float or numpy.ndarray
        The last time at which ``|estimate - actual|`` exceeds the band, 0.0
        if it never does (one value per channel for 2-D input). A value equal
        to ``time[-1]`` means the estimate never settled.

    Raises
    ------
    ValueError
        Mismatched shapes or lengths, more than 2 dimensions, a negative
        ``tol``, ``time`` not 1-D, finite and strictly increasing, non-numeric
        or complex data, a non-finite ``actual``, or an estimate without a
        finite sample; the message names the argument.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach import catch_time
    >>> t = np.linspace(0, 1, 101)
    >>> x = np.ones_like(t)
    >>> xhat = 1 - np.exp(-10 * t)   # error exp(-10 t) > 0.02 up to t = 0.39
    >>> float(catch_time(t, x, xhat))
    0.39
    >>> catch_time(t, np.vstack([x, x]), np.vstack([xhat, x])).tolist()
    [0.39, 0.0]
    """
    t = as_time("time", time, min_size=1)
    a = as_real_array("actual", actual)
    e = as_real_array("estimate", estimate, finite=False)
    if a.shape != e.shape:
        raise InputError(
            f"actual and estimate must have the same shape, got {a.shape} and {e.shape}"
        )
    if a.ndim not in (1, 2):
        raise InputError(f"actual must be 1-D or 2-D (rows = channels), got shape {a.shape}")
    if a.shape[-1] != t.size:
        raise InputError(
            f"actual and estimate must have one sample per time point ({t.size}), got {a.shape[-1]}"
        )
    if np.any(np.isinf(e)):
        raise InputError("estimate has an infinite value; only NaN (undefined samples) is allowed")
    tol = as_real_number("tol", tol, low=0.0)
    a2, e2 = np.atleast_2d(a), np.atleast_2d(e)
    band = tol * np.max(np.abs(a2), axis=1, keepdims=True)
    # trailing NaN samples are undefined (the last sample of a discrete reconstruction) and
    # are not judged; any other NaN counts as outside the band: NaN is never "caught"
    defined = np.isfinite(e2)
    if not np.any(defined):
        raise InputError("estimate has no finite sample: nothing can have caught the signal")
    end = t.size - int(np.argmax(defined.any(axis=0)[::-1]))  # one past the last defined sample
    with np.errstate(invalid="ignore"):
        outside = ~(np.abs(e2 - a2) <= band)  # NaN compares False: outside
    outside[:, end:] = False
    last = np.where(outside.any(axis=1), t[t.size - 1 - np.argmax(outside[:, ::-1], axis=1)], 0.0)
    # a channel whose only samples are NaN never caught anything
    never = ~defined[:, :end].any(axis=1)
    last = np.where(never, t[end - 1], last)
    return float(last[0]) if a.ndim == 1 else last
