"""Checks of the missile lab: the PMO and the g-inverse observer on the paper's matrices.

* :func:`missile_pmo` -- ``M``, ``L``, ``F``: ``(I - MC)E = 0``,
  ``F = (I - MC)A - LC``, the asked poles next to the two fixed ones;
* :func:`missile_ginverse` -- ``Cg``, ``Pc``, ``Kg``: the Moore-Penrose inverse,
  ``Pc = I - Cg C``, condition (20) ``Pc E - Kg C E = 0``;
* :func:`missile_reconstruction` -- ``v̂`` of a noise-free run follows ``v``;
* :func:`missile_catch_times` -- the catch times of Table II, recomputed;
* :func:`missile_noise` -- the RMS error of ``v̂`` with measurement noise,
  against the prediction ``sigma beta_i / (sqrt(2) h)`` (``beta_i`` the length of row
  ``i`` of ``(CE)^+``).

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach import checks
>>> plant = ut.examples.missile_autopilot()
>>> C = plant.C
>>> Cg = np.linalg.pinv(C)
>>> Pc = np.eye(4) - Cg @ C
>>> Kg = Pc @ plant.E @ np.linalg.pinv(C @ plant.E)
>>> checks.missile_ginverse(Cg, Pc, Kg).passed
True
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import tolerances as tols
from .._display import format_matrix_line, format_poles
from ..existence import check_existence
from ..reconstruction import catch_time, reconstruct_input
from ..simulation import simulate
from ..worked.missile import MISSILE
from .common import (
    CheckResult,
    as_poles,
    check_plant_of,
    close,
    get_plant,
    never_raises,
    numbers,
    read_matrix,
    read_response,
    same_observer,
    same_poles,
    up_to,
)
from .plots import figure_titles, panel_texts, plotted_axes, read_figure

__all__ = [
    "missile_pmo",
    "missile_ginverse",
    "missile_reconstruction",
    "missile_catch_times",
    "missile_noise",
    "missile_plot",
]

NAMES = ("x1", "x2", "x3", "x4", "v1", "v2")


def _fixed_poles(plant) -> np.ndarray:
    return np.asarray(check_existence(plant).fixed_modes, complex)


@never_raises("Missile: the projection-operator observer", "missile.pmo")
def missile_pmo(
    M: Any, L: Any, F: Any, *, poles: Any, plant: Any = None, tol: float | None = None
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
        Relative tolerance; default ``tolerances.CHECK_RTOL``.

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
    tol = tols.CHECK_RTOL if tol is None else tol
    result = CheckResult("Missile: the projection-operator observer")
    plant = get_plant(result, plant, "missile_autopilot")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    A, C, E = plant.A, plant.C, plant.E
    M = read_matrix(result, "M", M, n, p, f"n x p = {n} x {p}")
    L = read_matrix(result, "L", L, n, p, f"n x p = {n} x {p}")
    F = read_matrix(result, "F", F, n, n, f"n x n = {n} x {n}")
    if M is None or L is None or F is None:
        return result
    eye = np.eye(n)
    R = (eye - M @ C) @ E
    big = float(np.max(np.abs(R)))
    if big <= tol * max(1.0, float(np.max(np.abs(E)))):
        result.add(True, f"(I - MC)E = 0{up_to(big, 'largest entry')}: v is projected out.")
    else:
        hint = (
            " Your M is C^g, the inverse of C alone, which ignores E: M must satisfy MCE = E."
            if close(M, np.linalg.pinv(C), tols.CHECK_EXACT_RTOL)
            else " M must satisfy MCE = E: build it from E and the generalized inverse of CE."
        )
        result.add(
            False,
            f"(I - MC)E is not 0: it is {format_matrix_line(R)} (largest entry {big:.3g}), so v "
            f"still drives the error.{hint}",
        )
    A1 = (eye - M @ C) @ A
    F_ref = A1 - L @ C
    if close(F, F_ref, tol):
        result.add(True, "F = (I - MC)A - LC.")
    elif close(F, A - L @ C, tol):
        result.add(False, "F is A - LC: the projection is missing, F = (I - MC)A - LC.")
    elif close(F, A1 + L @ C, tol):
        result.add(False, "F is (I - MC)A + LC: the sign of LC is flipped.")
    else:
        result.add(False, "F is not (I - MC)A - LC with your M and L: recompute it from them.")
    wanted = as_poles(poles)
    fixed = _fixed_poles(plant)
    eig = np.linalg.eigvals(F_ref)
    if same_poles(eig, np.concatenate([wanted, fixed]), tol):
        result.add(
            True,
            f"(I - MC)A - LC has the asked poles {format_poles(wanted)} and the fixed pair "
            f"{format_poles(fixed)}.",
        )
    else:
        moved = same_poles(np.linalg.eigvals(A - L @ C), np.concatenate([wanted, fixed]), tol)
        hint = (
            " L places them for A - LC, not for A1 - LC."
            if moved
            else " Place the two movable ones with the poles of PARAMS (ut.design_pmo does it)."
        )
        result.add(
            False,
            f"(I - MC)A - LC has the poles {format_poles(eig)}, but the exercise asks for "
            f"{format_poles(wanted)} (next to the fixed pair {format_poles(fixed)}, which no L "
            f"moves).{hint}",
        )
    return result


@never_raises("Missile: the generalized-inverse observer", "missile.ginverse")
def missile_ginverse(
    Cg: Any, Pc: Any, Kg: Any, plant: Any = None, *, tol: float | None = None
) -> CheckResult:
    """Check ``Cg = C^g``, ``Pc = I - Cg C`` and condition (20), ``Pc E - Kg C E = 0``.

    Parameters
    ----------
    Cg : array_like, shape (n, p)
        Your Moore-Penrose inverse of ``C``.
    Pc : array_like, shape (n, n)
        Your projection onto the null space of ``C``.
    Kg : array_like, shape (n, p)
        Your gain ``Kg = Pc E (CE)^g + Kv (I - CE (CE)^g)``.
    plant : Plant, optional
        :func:`uio_teach.examples.missile_autopilot` by default.
    tol : float, optional
        Relative tolerance; default ``tolerances.CHECK_EXACT_RTOL``.

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
    tol = tols.CHECK_EXACT_RTOL if tol is None else tol
    result = CheckResult("Missile: the generalized-inverse observer")
    plant = get_plant(result, plant, "missile_autopilot")
    if plant is None:
        return result
    n, p = plant.n, plant.p
    C, E = plant.C, plant.E
    Cg = read_matrix(result, "Cg", Cg, n, p, f"n x p = {n} x {p}")
    Pc = read_matrix(result, "Pc", Pc, n, n, f"n x n = {n} x {n}")
    Kg = read_matrix(result, "Kg", Kg, n, p, f"n x p = {n} x {p}")
    if Cg is None or Pc is None or Kg is None:
        return result
    ref = np.linalg.pinv(C)
    if close(Cg, ref, tol):
        result.add(True, "Cg is the Moore-Penrose inverse of C.")
    else:
        gen = close(C @ Cg @ C, C, tols.CHECK_EXACT_RTOL)
        result.add(
            False,
            "Cg is a generalized inverse (C Cg C = C) but not the Moore-Penrose one, which "
            "is unique (and symmetric in C Cg and Cg C)."
            if gen
            else "Cg is not an inverse of C at all (C Cg C != C): the exercise asks for the "
            "Moore-Penrose inverse.",
        )
    eye = np.eye(n)
    if close(Pc, eye - Cg @ C, tol):
        result.add(True, "Pc = I - Cg C: the projection onto the null space of C.")
    elif close(Pc, Cg @ C, tol):
        result.add(
            False,
            "Pc is Cg C, the projection onto the measured coordinates: the unmeasured part is "
            "Pc = I - Cg C.",
        )
    else:
        result.add(False, "Pc is not I - Cg C with your Cg: recompute it from your Cg.")
    R = Pc @ E - Kg @ C @ E
    big = float(np.max(np.abs(R)))
    if big <= tols.CHECK_RTOL * max(1.0, float(np.max(np.abs(E)))):
        result.add(True, f"Pc E - Kg C E = 0{up_to(big, 'largest entry')}: condition (20) holds.")
    else:
        CEg = np.linalg.pinv(C @ E)
        hint = (
            " Your Kg is E (CE)^g, the PMO's M: the g-inverse observer projects E with Pc first."
            if close(Kg, E @ CEg, tols.CHECK_EXACT_RTOL)
            else " Kg must satisfy Kg C E = Pc E (eq. (20))."
        )
        result.add(
            False,
            f"condition (20) fails: Pc E - Kg C E = {format_matrix_line(R)} (largest entry "
            f"{big:.3g}), so v reaches the error.{hint}",
        )
    return result


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
    want = np.asarray(MISSILE.v(resp.time), float)
    d = np.asarray(resp.inputs.d, float)
    if d.shape == want.shape and np.allclose(d, want, rtol=0, atol=tols.CHECK_EXACT_RTOL):
        return True
    result.add(
        False,
        "the run's unknown inputs are not the paper's v1, v2 (our d1, d2): simulate with "
        "the inputs of the set-up cell as d.",
    )
    return False


def _run_as_asked(
    result: CheckResult,
    resp: Any,
    *,
    start: str,
    observer: Any = None,
    poles: Any = None,
    initial_state: Any = None,
) -> bool:
    """✓/✗ on what the exercise fixes about the run: the PMO, x(0), and where the observer starts.

    ``start`` is ``"z0"`` (the observer state z(0) = 0, ut.simulate's default) or ``"xhat0"``
    (the estimate x̂(0) = 0). Returns False if a ✗ was added.
    """
    ok = True
    family = str(getattr(resp.observer, "family", ""))
    if family != "PMO":
        result.add(
            False,
            f"the run simulates a {family or type(resp.observer).__name__}, but the exercise "
            "asks for the PMO of the first exercise.",
        )
        ok = False
    elif observer is not None and not same_observer(resp.observer, observer):
        result.add(
            False,
            "the run simulates another PMO than yours of the first exercise (its M or L "
            "differ): simulate your pmo.",
        )
        ok = False
    elif poles is not None:
        wanted = as_poles(poles)
        eig = np.asarray(resp.observer.poles(), complex)
        if not all(np.min(np.abs(eig - w)) <= tols.CHECK_RTOL * max(1.0, abs(w)) for w in wanted):
            result.add(
                False,
                f"the simulated PMO does not have the poles {format_poles(wanted)} of the "
                "exercise: simulate the PMO of the first exercise.",
            )
            ok = False
    x0 = resp.states[:, 0]
    if initial_state is not None:
        want = np.asarray(initial_state, float).ravel()
        if want.shape != x0.shape or not np.allclose(x0, want, rtol=0, atol=tols.CHECK_EXACT_RTOL):
            dropped = " (initial_state was left out?)" if not np.any(x0) else ""
            result.add(
                False,
                f"the plant starts from x(0) = {numbers(x0)}, but the exercise asks for the "
                f"paper's x0 (the set-up cell's x0){dropped}.",
            )
            ok = False
    elif not np.any(x0):
        result.add(
            False,
            "the plant starts from x(0) = 0: the exercise starts it from the paper's x0 "
            "(initial_state was left out?).",
        )
        ok = False
    scale = max(1.0, float(np.max(np.abs(resp.states))))
    z0 = np.asarray(resp.observer_states[:, 0], float)
    xhat0 = np.asarray(resp.estimates[:, 0], float)
    if start == "z0" and float(np.max(np.abs(z0))) > tols.CHECK_EXACT_RTOL * scale:
        hint = (
            " That is the start x̂(0) = 0 of the catch-time exercise."
            if float(np.max(np.abs(xhat0))) <= tols.CHECK_EXACT_RTOL * scale
            else ""
        )
        result.add(
            False,
            "the observer does not start from z(0) = 0 (ut.simulate's default), which this "
            f"exercise asks for.{hint}",
        )
        ok = False
    elif start == "xhat0" and float(np.max(np.abs(xhat0))) > tols.CHECK_EXACT_RTOL * scale:
        where = (
            "z(0) = 0"
            if float(np.max(np.abs(z0))) <= tols.CHECK_EXACT_RTOL * scale
            else "another z(0)"
        )
        result.add(
            False,
            f"the run starts the observer from {where}, so x̂(0) = z(0) + M y(0) is not 0: "
            "this exercise asks for x̂(0) = 0. Which z(0) cancels M y(0)?",
        )
        ok = False
    return ok


@never_raises("Missile: reconstructing v1 and v2", "missile.reconstruction")
def missile_reconstruction(
    vhat: Any,
    response: Any,
    *,
    after: float = 0.1,
    tol: float = 0.02,
    plant: Any = None,
    observer: Any = None,
    poles: Any = None,
    initial_state: Any = None,
) -> CheckResult:
    """Check ``v̂`` of a noise-free run of the PMO from ``z(0) = 0``: it follows ``v`` late on.

    The run must be of ``plant``, of the PMO (``observer``, when given; else one with the
    asked ``poles``), from ``initial_state`` (nonzero when not given) with the
    observer at ``z(0) = 0``, with the paper's ``v`` and no noise.

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
    plant : Plant, optional
        The plant of the lab's set-up cell.
    observer : PMO, optional
        Your PMO of the first exercise.
    poles : sequence of complex, optional
        The movable poles the exercise asks for.
    initial_state : array_like, optional
        The plant's initial state the exercise asks for.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.worked.missile import MISSILE
    >>> plant = MISSILE.plant()
    >>> pmo = ut.design_pmo(plant, poles=MISSILE.poles)
    >>> run = MISSILE.simulate(pmo, observer_state=None)  # z(0) = 0
    >>> checks.missile_reconstruction(ut.reconstruct_input(plant, run), run).passed
    True
    """
    result = CheckResult("Missile: reconstructing v1 and v2")
    resp = read_response(result, response)
    vh = _vhat(result, vhat)
    if resp is None or vh is None:
        return result
    if not check_plant_of(result, resp, plant) or not _paper_v(result, resp):
        return result
    if np.any(np.asarray(resp.inputs.noise)):
        result.add(
            False,
            "the run has measurement noise: reconstruct from the noise-free run here (noise is "
            "the last exercise).",
        )
        return result
    as_asked = _run_as_asked(
        result, resp, start="z0", observer=observer, poles=poles, initial_state=initial_state
    )
    if vh.time.shape != resp.time.shape or not np.allclose(vh.actual, resp.inputs.d):
        result.add(
            False, "vhat is not the reconstruction of this run: reconstruct from the run you pass."
        )
        return result
    ref = reconstruct_input(resp.plant, resp, method=vh.method, tau=vh.tau)
    gap = float(np.max(np.abs(ref.estimates - vh.estimates)))
    if gap > tols.CHECK_RTOL * max(1.0, float(np.max(np.abs(ref.estimates)))):
        result.add(
            False,
            f"vhat is not the reconstruction of this run (it differs from the run's "
            f"reconstruction by up to {gap:.3g}): reconstruct from the run you pass.",
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
    elif as_asked:
        result.add(
            True,
            f"after {after:g} s, v̂ follows v1 and v2 within {tol:.0%} of their peaks (largest "
            f"errors {', '.join(f'{e:.2g}' for e in err)}).",
        )
    return result


@never_raises("Missile: the catch times of Table II", "missile.catch_times")
def missile_catch_times(
    catch: Any,
    response: Any,
    vhat: Any,
    *,
    tol: float = 0.02,
    plant: Any = None,
    observer: Any = None,
    poles: Any = None,
    initial_state: Any = None,
) -> CheckResult:
    """Check the catch times of ``x1 ... x4, v1, v2`` of the PMO started from ``x̂(0) = 0``.

    Each time must be the run's own catch time to 1.5 sampling steps; a wrong
    one is reported as too early or too late, never with the expected value.

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
    plant : Plant, optional
        The plant of the lab's set-up cell.
    observer : PMO, optional
        Your PMO of the first exercise.
    poles : sequence of complex, optional
        The movable poles the exercise asks for.
    initial_state : array_like, optional
        The plant's initial state the exercise asks for.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> from uio_teach import checks
    >>> checks.missile_catch_times({}, None, None).passed
    False
    """
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
    resp = read_response(result, response)
    vh = _vhat(result, vhat)
    if resp is None or vh is None or missing:
        return result
    if not check_plant_of(result, resp, plant) or not _paper_v(result, resp):
        return result
    if not _run_as_asked(
        result, resp, start="xhat0", observer=observer, poles=poles, initial_state=initial_state
    ):
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
        if not math.isfinite(got):
            wrong.append(f"{k} is {got}, not a time")
        elif got > 50 * max(ref[k], h) and got <= 1000 * float(t[-1]) and got > float(t[-1]):
            wrong.append(f"{k} is later than the whole run: is it in ms instead of s?")
        elif got - ref[k] > 1.5 * h:
            wrong.append(f"{k} is too late")
        elif ref[k] - got > 1.5 * h:
            wrong.append(f"{k} is too early")
    if wrong:
        result.add(
            False,
            f"catch times that differ from the run by more than 1.5 steps (band {tol:.0%} of "
            "each signal's peak): "
            + "; ".join(wrong)
            + ". A catch time is the first time after which the estimate stays in the band "
            'for good; read it with ut.catch_time and the band of PARAMS["tol"].',
        )
    else:
        result.add(
            True,
            "the catch times are those of the run: "
            + ", ".join(f"{k} {ref[k]:.3f} s" for k in NAMES)
            + ".",
        )
    return result


@never_raises("Missile: what noise does to the reconstruction", "missile.noise")
def missile_noise(
    rms: Any,
    response: Any,
    *,
    sigma: float,
    seed: int | None = None,
    after: float = 0.1,
    plant: Any = None,
    observer: Any = None,
    initial_state: Any = None,
) -> CheckResult:
    """Check the RMS error of ``v̂`` with noise, and compare it with ``sigma beta_i / (sqrt(2) h)``.

    Parameters
    ----------
    rms : array_like, shape (2,)
        Your RMS error of ``v̂1``, ``v̂2`` over ``t >= after`` (plain derivative).
    response : UIOResponse
        The noisy run: the PMO from ``z(0) = 0``.
    sigma : float
        The asked noise level.
    seed : int, optional
        The asked seed of the noise.
    after : float, optional
        Start of the window (s).
    plant : Plant, optional
        The plant of the lab's set-up cell.
    observer : PMO, optional
        Your PMO of the first exercise.
    initial_state : array_like, optional
        The plant's initial state the exercise asks for.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> from uio_teach import checks
    >>> checks.missile_noise(None, None, sigma=0.01).passed
    False
    """
    result = CheckResult("Missile: what noise does to the reconstruction")
    q = 2
    vals = read_matrix(result, "rms", rms, 1, q, f"{q} numbers: v1, v2")
    resp = read_response(result, response)
    if resp is None or vals is None:
        return result
    if not check_plant_of(result, resp, plant):
        return result
    noise = np.asarray(resp.inputs.noise, float)
    if not np.any(noise):
        result.add(False, "the run has no measurement noise: simulate with the noise of PARAMS.")
        return result
    _run_as_asked(result, resp, start="z0", observer=observer, initial_state=initial_state)
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
        if not np.allclose(
            np.asarray(again.inputs.noise), noise, rtol=0, atol=tols.CHECK_ZERO_ATOL
        ):
            result.add(
                False,
                f"the noise of the run is not the one of seed {int(seed)}: take the seed of "
                "PARAMS.",
            )
    vh = reconstruct_input(resp.plant, resp)
    late = resp.time >= after
    ref = np.sqrt(np.mean(vh.error[:, late] ** 2, axis=1))
    got = vals.ravel()
    if close(got, ref, tols.CHECK_RTOL):
        result.add(True, f"the RMS errors are those of the run: {ref[0]:.3g}, {ref[1]:.3g}.")
    else:
        how = [
            f"v{i + 1} too {'large' if got[i] > ref[i] else 'small'}"
            for i in range(q)
            if abs(got[i] - ref[i]) > tols.CHECK_RTOL * max(1.0, abs(ref[i]))
        ]
        result.add(
            False,
            f"the RMS errors are not those of the run's plain-derivative reconstruction over "
            f"t >= {after:g} s ({', '.join(how)}): the RMS is the square root of the mean "
            "square of the error of v̂, over that window only, one number per input.",
        )
    h = float(resp.time[1] - resp.time[0])
    CE = resp.plant.C @ resp.plant.E
    beta = np.linalg.norm(np.linalg.pinv(CE), axis=1)  # row i of (CE)^+, as the exercise
    predicted = float(sigma) / (math.sqrt(2) * h) * beta
    ratio = got / predicted
    near = bool(np.all(np.abs(ratio - 1) <= 0.25))
    result.add(
        None,
        f"your RMS errors are {'within' if near else 'not within'} 25 % of the prediction "
        f"σ β_i / (√2 h) = {predicted[0]:.3g}, {predicted[1]:.3g} (β_i the length of row i of "
        "(CE)^+): the differentiator amplifies the noise by 1/h.",
    )
    return result


_V_LABEL = re.compile(r"\b[vd]\s*_?\{?\s*[12]|\bv\b|\bd\b|input|reconstruct", re.IGNORECASE)


@never_raises("Missile: the plot of v and its reconstruction", "missile.plot")
def missile_plot(fig: Any, vhat: Any, *, plant: Any = None) -> CheckResult:
    """Check the figure of ``v`` and ``v̂``: both inputs and their estimates, against time.

    The checks: every input ``v_i`` and its estimate ``v̂_i`` of ``vhat`` is a
    curve (the estimate not drawn in place of the input), against the run's time
    in the unit the x-label names; the panels are labelled as the unknown inputs;
    the figure has a title.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (``vhat.plot(...)`` makes one).
    vhat : InputEstimate
        The reconstruction that was plotted.
    plant : Plant, optional
        The plant of the lab's set-up cell (not used beyond a type check).

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.worked.missile import MISSILE
    >>> plant = MISSILE.plant()
    >>> run = MISSILE.simulate(ut.design_pmo(plant, poles=MISSILE.poles))
    >>> vhat = ut.reconstruct_input(plant, run)
    >>> checks.missile_plot(vhat.plot(title="v and v̂"), vhat).passed
    True
    """
    result = CheckResult("Missile: the plot of v and its reconstruction")
    if plant is not None and get_plant(result, plant) is None:
        return result
    vh = _vhat(result, vhat)
    fig = read_figure(result, fig)
    if fig is None or vh is None:
        return result
    t = np.asarray(vh.time, float)
    plotted = plotted_axes(result, fig, t)
    if plotted is None:
        return result
    axes, names = plotted
    N = t.size
    actual = np.asarray(vh.actual, float)
    est = np.asarray(vh.estimates, float)
    ys = [np.asarray(ln.get_ydata(), float) for ax in axes for ln in ax.get_lines()]
    ys = [y for y in ys if y.shape == (N,)]
    scale = max(1.0, float(np.max(np.abs(actual))))

    def drawn(row: np.ndarray) -> bool:
        return any(
            np.allclose(y, row, rtol=0, atol=tols.CHECK_EXACT_RTOL * scale, equal_nan=True)
            for y in ys
        )

    missing = [f"v{i + 1}" for i in range(actual.shape[0]) if not drawn(actual[i])]
    missing += [f"v̂{i + 1}" for i in range(est.shape[0]) if not drawn(est[i])]
    if missing:
        result.add(
            False,
            f"the figure lacks {', '.join(missing)}: draw each input next to its estimate "
            "(vhat.actual and vhat.estimates).",
        )
    else:
        result.add(True, "the figure shows v1, v2 and their estimates v̂1, v̂2.")
    unlabelled = [
        n
        for n, ax in zip(names, axes, strict=True)
        if not _V_LABEL.search(" ".join(panel_texts(ax)))
    ]
    if unlabelled:
        result.add(
            False,
            f"{', '.join(unlabelled)} {'does' if len(unlabelled) == 1 else 'do'} not say which "
            "input is drawn: label each panel (y-label or legend).",
        )
    title = " ".join(figure_titles(fig, axes)).strip()
    if not title:
        result.add(False, "the figure has no title: say what is drawn, and for which run.")
    elif re.search(r"g-?inverse|generali[sz]ed", title, re.IGNORECASE):
        result.add(
            False,
            f"the title {title!r} names the g-inverse observer, but the run is the PMO's.",
        )
    else:
        result.add(True, f"the figure has a title, {title!r}.")
    return result
