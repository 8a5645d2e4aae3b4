"""Checks of the missile lab: the PMO and the g-inverse observer on the paper's matrices.

* :func:`missile_pmo` -- ``M``, ``L``, ``F``: ``(I - MC)E = 0``,
  ``F = (I - MC)A - LC``, the asked poles next to the two fixed ones;
* :func:`missile_ginverse` -- ``Cg``, ``Pc``, ``K``: the Moore-Penrose inverse,
  ``Pc = I - Cg C``, condition (20) ``Pc E - K C E = 0``;
* :func:`missile_reconstruction` -- ``v̂`` of a noise-free run follows ``v``;
* :func:`missile_catch_times` -- the catch times of Table II, recomputed;
* :func:`missile_noise` -- the RMS error of ``v̂`` with measurement noise,
  against the prediction ``sigma rho_i / (sqrt(2) h)``.

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach import checks
>>> plant = ut.examples.missile_autopilot()
>>> C = plant.C
>>> Cg = np.linalg.pinv(C)
>>> Pc = np.eye(4) - Cg @ C
>>> K = Pc @ plant.E @ np.linalg.pinv(C @ plant.E)
>>> checks.missile_ginverse(Cg, Pc, K).passed
True
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._display import format_matrix_line, format_poles
from ._common import CheckResult, _close, _get_plant, _never_raises, _read_matrix, _up_to
from .design import _same_poles

__all__ = [
    "missile_pmo",
    "missile_ginverse",
    "missile_reconstruction",
    "missile_catch_times",
    "missile_noise",
]

NAMES = ("x1", "x2", "x3", "x4", "v1", "v2")


def _fixed_poles(plant) -> np.ndarray:
    from ..existence import check_existence

    return np.asarray(check_existence(plant).fixed_modes, complex)


@_never_raises("Missile: the projection-operator observer", "missile.pmo")
def missile_pmo(
    M: Any, L: Any, F: Any, *, poles: Any, plant: Any = None, tol: float = 1e-6
) -> CheckResult:
    """Check the PMO: ``(I - MC)E = 0``, ``F = (I - MC)A - LC``, the asked and the fixed poles.

    Parameters
    ----------
    M : array_like, shape (n, p)
        Your ``M = E (CE)^g + Mv (I - CE (CE)^g)``.
    L : array_like, shape (n, p)
        Your gain.
    F : array_like, shape (n, n)
        Your error matrix ``A1 - LC``.
    poles : sequence of complex
        The two movable poles the exercise asks for.
    plant : Plant, optional
        :func:`uio_teach.examples.missile_autopilot` by default.
    tol : float, optional
        Relative tolerance.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> plant = ut.examples.missile_autopilot()
    >>> pmo = ut.design_pmo(plant, poles=[-100, -120])
    >>> checks.missile_pmo(pmo.M, pmo.L, pmo.F, poles=[-100, -120]).passed
    True
    """
    result = CheckResult("Missile: the projection-operator observer")
    plant = _get_plant(result, plant, "missile_autopilot")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    A, C, E = plant.A, plant.C, plant.E
    M = _read_matrix(result, "M", M, n, p, f"n x p = {n} x {p}")
    L = _read_matrix(result, "L", L, n, p, f"n x p = {n} x {p}")
    F = _read_matrix(result, "F", F, n, n, f"n x n = {n} x {n}")
    if M is None or L is None or F is None:
        return result
    eye = np.eye(n)
    R = (eye - M @ C) @ E
    big = float(np.max(np.abs(R)))
    if big <= tol * max(1.0, float(np.max(np.abs(E)))):
        result.add(True, f"(I - MC)E = 0{_up_to(big, 'largest entry')}: v is projected out.")
    else:
        hint = (
            " Your M is C^g = pinv(C), which ignores E: M = E (CE)^g + Mv (I - CE (CE)^g)."
            if _close(M, np.linalg.pinv(C), 1e-9)
            else " M = E (CE)^g + Mv (I - CE (CE)^g), with (CE)^g = np.linalg.pinv(C @ E)."
        )
        result.add(
            False,
            f"(I - MC)E is not 0: it is {format_matrix_line(R)} (largest entry {big:.3g}), so v "
            f"still drives the error.{hint}",
        )
    A1 = (eye - M @ C) @ A
    F_ref = A1 - L @ C
    if _close(F, F_ref, tol):
        result.add(True, "F = (I - MC)A - LC.")
    elif _close(F, A - L @ C, tol):
        result.add(False, "F is A - LC: the projection is missing, F = (I - MC)A - LC.")
    elif _close(F, A1 + L @ C, tol):
        result.add(False, "F is (I - MC)A + LC: the sign of LC is flipped.")
    else:
        result.add(False, "F is not (I - MC)A - LC: compute F = (np.eye(n) - M @ C) @ A - L @ C.")
    wanted = np.array([complex(q) if not isinstance(q, str) else complex(q) for q in poles])
    fixed = _fixed_poles(plant)
    eig = np.linalg.eigvals(F_ref)
    if _same_poles(eig, np.concatenate([wanted, fixed])):
        result.add(
            True,
            f"(I - MC)A - LC has the asked poles {format_poles(wanted)} and the fixed pair "
            f"{format_poles(fixed)}.",
        )
    else:
        moved = _same_poles(np.linalg.eigvals(A - L @ C), np.concatenate([wanted, fixed]))
        hint = (
            " L places them for A - LC, not for A1 - LC."
            if moved
            else " ut.design_pmo(plant, poles=..., Mv=Mv) places the two movable ones."
        )
        result.add(
            False,
            f"(I - MC)A - LC has the poles {format_poles(eig)}, but the exercise asks for "
            f"{format_poles(wanted)} (next to the fixed pair {format_poles(fixed)}, which no L "
            f"moves).{hint}",
        )
    return result


@_never_raises("Missile: the generalized-inverse observer", "missile.ginverse")
def missile_ginverse(
    Cg: Any, Pc: Any, K: Any, plant: Any = None, *, tol: float = 1e-9
) -> CheckResult:
    """Check ``Cg = C^g``, ``Pc = I - Cg C`` and condition (20), ``Pc E - K C E = 0``.

    Parameters
    ----------
    Cg : array_like, shape (n, p)
        Your Moore-Penrose inverse of ``C``.
    Pc : array_like, shape (n, n)
        Your projection onto the null space of ``C``.
    K : array_like, shape (n, p)
        Your gain ``K = Pc E (CE)^g + Kv (I - CE (CE)^g)``.
    plant : Plant, optional
        :func:`uio_teach.examples.missile_autopilot` by default.
    tol : float, optional
        Relative tolerance.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach import checks
    >>> checks.missile_ginverse(np.zeros((4, 2)), np.eye(4), np.zeros((4, 2))).passed
    False
    """
    result = CheckResult("Missile: the generalized-inverse observer")
    plant = _get_plant(result, plant, "missile_autopilot")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    C, E = plant.C, plant.E
    Cg = _read_matrix(result, "Cg", Cg, n, p, f"n x p = {n} x {p}")
    Pc = _read_matrix(result, "Pc", Pc, n, n, f"n x n = {n} x {n}")
    K = _read_matrix(result, "K", K, n, p, f"n x p = {n} x {p}")
    if Cg is None or Pc is None or K is None:
        return result
    ref = np.linalg.pinv(C)
    if _close(Cg, ref, tol):
        result.add(True, "Cg is the Moore-Penrose inverse of C.")
    else:
        gen = _close(C @ Cg @ C, C, 1e-9)
        result.add(
            False,
            "Cg is a generalized inverse (C Cg C = C) but not the Moore-Penrose one: use "
            "np.linalg.pinv(C)."
            if gen
            else "Cg is not an inverse of C at all (C Cg C != C): Cg = np.linalg.pinv(C).",
        )
    eye = np.eye(n)
    if _close(Pc, eye - Cg @ C, tol):
        result.add(True, "Pc = I - Cg C: the projection onto the null space of C.")
    elif _close(Pc, Cg @ C, tol):
        result.add(
            False,
            "Pc is Cg C, the projection onto the measured coordinates: the unmeasured part is "
            "Pc = I - Cg C.",
        )
    else:
        result.add(False, "Pc is not I - Cg C: compute Pc = np.eye(n) - Cg @ C.")
    R = Pc @ E - K @ C @ E
    big = float(np.max(np.abs(R)))
    if big <= 1e-6 * max(1.0, float(np.max(np.abs(E)))):
        result.add(True, f"Pc E - K C E = 0{_up_to(big, 'largest entry')}: condition (20) holds.")
    else:
        CEg = np.linalg.pinv(C @ E)
        hint = (
            " Your K is E (CE)^g, the PMO's M: K = Pc E (CE)^g."
            if _close(K, E @ CEg, 1e-9)
            else " K = Pc E (CE)^g + Kv (I - CE (CE)^g)."
        )
        result.add(
            False,
            f"condition (20) fails: Pc E - K C E = {format_matrix_line(R)} (largest entry "
            f"{big:.3g}), so v reaches the error.{hint}",
        )
    return result


def _resp(result: CheckResult, response: Any, name: str = "response"):
    from .responses import _read_response

    return _read_response(result, response, name)


def _vhat(result: CheckResult, vhat: Any):
    if vhat is None or not all(hasattr(vhat, a) for a in ("estimates", "actual", "time", "error")):
        got = "None" if vhat is None else type(vhat).__name__
        result.add(
            False,
            f"vhat must be the result of ut.reconstruct_input(plant, run), got {got}.",
        )
        return None
    return vhat


def _paper_v(result: CheckResult, resp) -> bool:
    from .. import examples

    want = np.asarray(examples.missile_inputs()(resp.time), float)
    d = np.asarray(resp.inputs.d, float)
    if d.shape == want.shape and np.allclose(d, want, rtol=0, atol=1e-9):
        return True
    result.add(
        False,
        "the run's unknown inputs are not the paper's v1, v2: simulate with "
        "d=ut.examples.missile_inputs().",
    )
    return False


@_never_raises("Missile: reconstructing v1 and v2", "missile.reconstruction")
def missile_reconstruction(
    vhat: Any, response: Any, *, after: float = 0.1, tol: float = 0.02
) -> CheckResult:
    """Check ``v̂`` of a noise-free run: it reconstructs this run's ``v``, within ``tol`` late on.

    Parameters
    ----------
    vhat : InputEstimate
        The result of :func:`uio_teach.reconstruct_input` for ``response``.
    response : UIOResponse
        The run (the paper's ``v``, no noise).
    after : float, optional
        From when (s) the estimate must follow ``v``.
    tol : float, optional
        The largest error after ``after``, relative to each input's peak.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.experiments import MISSILE
    >>> plant = MISSILE.plant()
    >>> run = MISSILE.simulate(ut.design_pmo(plant, poles=MISSILE.poles))
    >>> checks.missile_reconstruction(ut.reconstruct_input(plant, run), run).passed
    True
    """
    result = CheckResult("Missile: reconstructing v1 and v2")
    resp = _resp(result, response)
    vh = _vhat(result, vhat)
    if resp is None or vh is None:
        return result
    if not _paper_v(result, resp):
        return result
    if np.any(np.asarray(resp.inputs.noise)):
        result.add(
            False,
            "the run has measurement noise: reconstruct from the noise-free run here (noise is "
            "the last exercise).",
        )
        return result
    if vh.time.shape != resp.time.shape or not np.allclose(vh.actual, resp.inputs.d):
        result.add(
            False, "vhat is not the reconstruction of this run: ut.reconstruct_input(plant, run)."
        )
        return result
    from ..reconstruction import reconstruct_input

    ref = reconstruct_input(resp.plant, resp, method=vh.method, tau=vh.tau)
    gap = float(np.max(np.abs(ref.estimates - vh.estimates)))
    if gap > 1e-6 * max(1.0, float(np.max(np.abs(ref.estimates)))):
        result.add(
            False,
            f"vhat is not the reconstruction of this run (it differs from "
            f"ut.reconstruct_input(plant, run) by up to {gap:.3g}): reconstruct from the run "
            "you pass.",
        )
        return result
    late = resp.time >= after
    err = np.max(np.abs(vh.error[:, late]), axis=1)
    peak = np.max(np.abs(vh.actual), axis=1)
    bad = [f"v{i + 1}" for i in range(err.size) if err[i] > tol * peak[i]]
    if bad:
        result.add(
            False,
            f"{', '.join(bad)} {'is' if len(bad) == 1 else 'are'} not followed after {after:g} s "
            f"(errors {', '.join(f'{e:.3g}' for e in err)}): has the observer converged?",
        )
    else:
        result.add(
            True,
            f"after {after:g} s, v̂ follows v1 and v2 within {tol:.0%} of their peaks (largest "
            f"errors {', '.join(f'{e:.2g}' for e in err)}).",
        )
    return result


@_never_raises("Missile: the catch times of Table II", "missile.catch_times")
def missile_catch_times(catch: Any, response: Any, vhat: Any, *, tol: float = 0.02) -> CheckResult:
    """Check the catch times of ``x1 ... x4, v1, v2`` of the PMO started from ``x̂(0) = 0``.

    Parameters
    ----------
    catch : mapping
        Your catch times by name (``"x1"``, ..., ``"v2"``), in s.
    response : UIOResponse
        The run they were read from: the PMO from ``x̂(0) = 0``.
    vhat : InputEstimate
        The reconstruction of that run.
    tol : float, optional
        The band, relative to each signal's peak (the exercise's).

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> from uio_teach import checks
    >>> checks.missile_catch_times({}, None, None).passed
    False
    """
    from ..reconstruction import catch_time

    result = CheckResult("Missile: the catch times of Table II")
    missing: list[str] = []
    if not isinstance(catch, Mapping):
        got = "None" if catch is None else type(catch).__name__
        result.add(
            False, f"catch must be a dict {{'x1': ..., 'v2': ...}} of times in s, got {got}."
        )
        missing = list(NAMES)
    else:
        missing = [k for k in NAMES if k not in catch]
        if missing:
            result.add(False, f"catch has no time for {', '.join(missing)}.")
    resp = _resp(result, response)
    vh = _vhat(result, vhat)
    if resp is None or vh is None or missing:
        return result
    if not _paper_v(result, resp):
        return result
    if float(np.max(np.abs(resp.estimates[:, 0]))) > 1e-9 * max(
        1.0, float(np.max(np.abs(resp.states)))
    ):
        result.add(
            False,
            f"the run starts the observer at x̂(0) = {format_matrix_line(resp.estimates[:, :1])}, "
            "not at x̂(0) = 0: pass observer_state = -M C x0 (q(0) = -M y(0)).",
        )
        return result
    t = resp.time
    tx = np.atleast_1d(catch_time(t, resp.states, resp.estimates, tol=tol))
    tv = np.atleast_1d(catch_time(t, vh.actual, vh.estimates, tol=tol))
    ref = dict(zip(NAMES, np.concatenate([tx, tv]), strict=True))
    h = float(t[1] - t[0])
    wrong = []
    for k in NAMES:
        try:
            got = float(catch[k])
        except (TypeError, ValueError):
            wrong.append(f"{k} is {catch[k]!r}, not a number")
            continue
        if not math.isfinite(got) or abs(got - ref[k]) > 1.5 * h:
            wrong.append(f"{k}: {got:.4g} s, but it catches up at {ref[k]:.4g} s")
    if wrong:
        result.add(
            False,
            f"catch times that differ from the run (band {tol:.0%} of each signal's peak): "
            + "; ".join(wrong)
            + '. Use ut.catch_time(t, actual, estimate, tol=PARAMS["tol"]).',
        )
    else:
        result.add(
            True,
            "the catch times are those of the run: "
            + ", ".join(f"{k} {ref[k]:.3f} s" for k in NAMES)
            + ".",
        )
    return result


@_never_raises("Missile: what noise does to the reconstruction", "missile.noise")
def missile_noise(
    rms: Any, response: Any, *, sigma: float, seed: int | None = None, after: float = 0.1
) -> CheckResult:
    """Check the RMS error of ``v̂`` with noise, and compare it with ``sigma rho_i / (sqrt(2) h)``.

    Parameters
    ----------
    rms : array_like, shape (2,)
        Your RMS error of ``v̂1``, ``v̂2`` over ``t >= after`` (plain derivative).
    response : UIOResponse
        The noisy run.
    sigma : float
        The asked noise level.
    seed : int, optional
        The asked seed of the noise.
    after : float, optional
        Start of the window (s).

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> from uio_teach import checks
    >>> checks.missile_noise(None, None, sigma=0.01).passed
    False
    """
    from ..reconstruction import reconstruct_input

    result = CheckResult("Missile: what noise does to the reconstruction")
    q = 2
    vals = _read_matrix(result, "rms", rms, 1, q, f"{q} numbers: v1, v2")
    resp = _resp(result, response)
    if resp is None or vals is None:
        return result
    noise = np.asarray(resp.inputs.noise, float)
    if not np.any(noise):
        result.add(False, "the run has no measurement noise: simulate with noise=sigma, seed=seed.")
        return result
    sd = float(np.std(noise))
    if abs(sd - float(sigma)) > 0.1 * float(sigma):
        result.add(
            False,
            f"the noise of the run has a standard deviation of {sd:.3g}, but the exercise asks "
            f"for sigma = {float(sigma):g}.",
        )
    else:
        result.add(True, f"the run has measurement noise with sigma = {float(sigma):g}.")
    if seed is not None:
        from ..simulation import simulate

        again = simulate(
            resp.plant,
            resp.observer,
            resp.time,
            d=resp.inputs.d,
            initial_state=resp.states[:, 0],
            observer_state=resp.observer_states[:, 0],
            noise=float(sigma),
            seed=int(seed),
        )
        if not np.allclose(np.asarray(again.inputs.noise), noise, rtol=0, atol=1e-12):
            result.add(
                False,
                f"the noise of the run is not the one of seed {int(seed)}: pass "
                'seed=PARAMS["noise"]["seed"] to ut.simulate.',
            )
    vh = reconstruct_input(resp.plant, resp)
    late = resp.time >= after
    ref = np.sqrt(np.mean(vh.error[:, late] ** 2, axis=1))
    if _close(vals.ravel(), ref, 1e-6):
        result.add(True, f"the RMS errors are those of the run: {ref[0]:.3g}, {ref[1]:.3g}.")
    else:
        result.add(
            False,
            f"the RMS errors {vals.ravel()[0]:.4g}, {vals.ravel()[1]:.4g} are not those of the "
            f"run's plain-derivative reconstruction over t >= {after:g} s ({ref[0]:.4g}, "
            f"{ref[1]:.4g}): np.sqrt(np.mean(vhat.error[:, t >= {after:g}] ** 2, axis=1)).",
        )
    h = float(resp.time[1] - resp.time[0])
    CE = resp.plant.C @ resp.plant.E
    rho = np.linalg.norm(np.linalg.pinv(CE), axis=1)
    predicted = float(sigma) / (math.sqrt(2) * h) * rho
    result.add(
        None,
        f"predicted sigma rho_i / (sqrt(2) h): {predicted[0]:.3g}, {predicted[1]:.3g} -- the "
        "differentiator amplifies the noise by 1/h.",
    )
    return result
