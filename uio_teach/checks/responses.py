"""Checks of a PA9 simulation: the error does not depend on ``d`` and decays.

:func:`pa9_simulation` takes the response with a sinusoidal disturbance,
:func:`pa9_piecewise` the one with a piecewise-constant disturbance.

Examples
--------
>>> import uio_teach as ut
>>> from uio_teach.checks import pa9_simulation
>>> from uio_teach.worked.pa9 import PA9
>>> obs = ut.design_uio(PA9.plant(), poles=PA9.poles)
>>> pa9_simulation(PA9.simulate(obs, d=PA9.d_sine)).passed
True
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import tolerances as tols
from .._display import format_complex, format_poles
from ..signals import piecewise_constant
from .common import (
    CheckResult,
    as_poles,
    check_plant_of,
    close,
    never_raises,
    numbers,
    plural,
    read_response,
    rerun_without_unknown_inputs,
    same_observer,
    same_poles,
    stability,
    up_to,
)

__all__ = ["pa9_simulation", "pa9_piecewise"]


def _disturbance(result: CheckResult, resp) -> np.ndarray | None:
    if resp.plant.q == 0:
        result.add(False, "the simulated plant has no unknown input (E has no columns).")
        return None
    d = np.asarray(resp.inputs.d, float)
    if not np.any(d):
        result.add(
            False,
            "d is zero during the whole simulation, so the test says nothing about the "
            "disturbance: pass the disturbance of the exercise to ut.simulate (its d argument).",
        )
        return None
    return d


def _noise_free(result: CheckResult, resp) -> bool:
    if np.any(np.asarray(resp.inputs.noise)):
        result.add(
            False,
            "the simulation has measurement noise; the error then depends on the noise too, so "
            "the disturbance test is not clean. Simulate without noise=.",
        )
        return False
    return True


def _initial_error(result: CheckResult, resp) -> float:
    e0 = float(np.max(np.abs(resp.error[:, 0])))
    if e0 <= tols.CHECK_ZERO_ATOL:
        result.add(
            False,
            "the error is zero at t = 0, so nothing can be seen decaying: start the plant from "
            "the nonzero initial state of PARAMS.",
        )
    return e0


def _same_without_d(result: CheckResult, resp) -> bool:
    """Re-simulate with ``d = 0``; add a ✓/✗ on whether the error is unchanged."""
    diff, same = rerun_without_unknown_inputs(resp, keep_v=True)
    if same:
        result.add(
            True,
            f"the error does not depend on d: simulated again with d = 0, it is the same"
            f"{up_to(diff, 'largest difference')}.",
        )
        return True
    if not resp.observer.decouples:
        hint = (
            f" Your observer is a {resp.observer.family}, which ignores d; design a decoupling "
            "observer with ut.design_uio(plant, ...)."
        )
    elif resp.plant != resp.observer.plant:
        hint = (
            " The simulated plant is not the plant the observer was designed for: use the same "
            "plant (the same E) in ut.design_uio and ut.simulate."
        )
    else:
        hint = ""
    result.add(
        False,
        f"the error depends on d: simulated again with d = 0, it changes by up to "
        f"{diff:.3g}.{hint}",
    )
    return False


def _decays(result: CheckResult, resp, e0: float, decay: float, decoupled: bool = True) -> None:
    if e0 <= tols.CHECK_ZERO_ATOL:
        return
    e_end = float(np.max(np.abs(resp.error[:, -1])))
    t0, t1 = float(resp.time[0]), float(resp.time[-1])
    unit = _seconds(resp)
    if e_end <= decay * e0:
        result.add(
            True,
            f"the error decays: largest component {e0:.3g} at t = {t0:g}{unit}, "
            f"{e_end:.2g} at t = {t1:g}{unit}.",
        )
        return
    poles = resp.observer.poles()
    stable, _, bad = stability(resp.observer.error_matrix, resp.plant.is_discrete)
    if not stable:
        result.add(
            False,
            f"the error does not decay: the observer's error dynamics are unstable (pole(s) "
            f"{format_poles(bad)}). Its K1 must make F = TA - K1C stable (requirement 1).",
        )
        return
    if not decoupled:
        result.add(
            False,
            f"the error does not decay: {e_end:.3g} at the end against {e0:.3g} at the start, "
            "because the disturbance keeps driving it (see above).",
        )
        return
    if resp.plant.is_discrete:
        rho = float(np.max(np.abs(poles)))
        need = math.log(decay) / math.log(rho) if 0 < rho < 1 else 1.0
        need_txt = f"about {math.ceil(need)} steps"
    else:
        sigma = float(-np.max(poles.real))
        need_txt = f"about {math.log(1 / decay) / sigma:.2g} s"
    result.add(
        False,
        f"the error has not decayed yet: {e_end:.3g} at the end against {e0:.3g} at the start. "
        f"With the slowest error pole {format_complex(poles[np.argmax(poles.real)])} it needs "
        f"{need_txt} to shrink to {decay:.0%}: simulate longer.",
    )


def _seconds(resp: Any) -> str:
    """The unit of the run's time in a message: `` s``, or nothing for steps (``dt=True``)."""
    return "" if resp.plant.dt is True else " s"


def _jumps(d: np.ndarray) -> np.ndarray:
    """Indices ``k`` where some channel of ``d`` changes between samples ``k`` and ``k + 1``."""
    scale = max(1.0, float(np.max(np.abs(d))))
    return np.flatnonzero(
        np.any(np.abs(np.diff(d, axis=1)) > tols.CHECK_EXACT_RTOL * scale, axis=0)
    )


@never_raises("Practical Assignment 9: the test with a sinusoidal disturbance", "pa9.simulation")
def pa9_simulation(
    response: Any,
    *,
    decay: float = 0.01,
    poles: Any = None,
    amplitude: float | None = None,
    frequency: float | None = None,
    initial_state: Any = None,
    H: Any = None,
    K1: Any = None,
    plant: Any = None,
) -> CheckResult:
    """Check a simulation with a sinusoidal disturbance: does the error ignore ``d`` and decay?

    The checks: the disturbance ``d`` is nonzero and oscillates; the
    simulation is noise-free and starts with a nonzero error; the error is
    unchanged when the simulation is run again with ``d = 0`` (the defining
    property of an unknown input observer); the error has shrunk to
    ``decay`` times its initial size by the end.

    Parameters
    ----------
    response : UIOResponse
        The result of :func:`uio_teach.simulate`.
    decay : float, optional
        The largest final error, relative to the initial one (1 %).
    poles : sequence of complex, optional
        The observer poles the exercise asks for.
    amplitude, frequency : float, optional
        The sinusoid ``d(t) = amplitude sin(frequency t)`` the exercise asks for.
    initial_state : array_like, optional
        The plant's initial state the exercise asks for.
    H, K1 : array_like, optional
        Your design of requirement 1: the simulated observer must be built from
        them (any valid ``H`` of yours, not only ``E (CE)^+``).
    plant : Plant, optional
        The plant of the lab's set-up cell: the run must be of this plant.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.worked.pa9 import PA9
    >>> plant = PA9.plant()
    >>> obs = ut.design_uio(plant, poles=PA9.poles)
    >>> checks.pa9_simulation(PA9.simulate(obs, d=PA9.d_sine)).passed
    True
    >>> luen = ut.design_luenberger(plant, poles=PA9.poles)
    >>> checks.pa9_simulation(PA9.simulate(luen, d=PA9.d_sine)).passed
    False
    """
    result = CheckResult("Practical Assignment 9: the test with a sinusoidal disturbance")
    resp = read_response(result, response)
    if resp is None:
        return result
    d = _disturbance(result, resp)
    if d is not None:
        N = d.shape[1]
        changing = _jumps(d).size / max(1, N - 1)
        centred = d - d.mean(axis=1, keepdims=True)
        crossings = int(np.max(np.sum(np.diff(np.sign(centred), axis=1) != 0, axis=1)))
        if changing < 0.5:
            result.add(
                False,
                "d is piecewise constant, not a sinusoid: this test takes the sinusoid of "
                'PARAMS["sine"] (the piecewise-constant test is checked by pa9_piecewise).',
            )
        elif crossings < 2:
            result.add(
                False,
                "d does not oscillate within the simulated time: raise its frequency or "
                "simulate several periods.",
            )
        else:
            result.add(
                True, f"d oscillates like a sinusoid (it crosses its mean {crossings} times)."
            )
        if amplitude is not None and frequency is not None and resp.plant.q == 1:
            want = float(amplitude) * np.sin(float(frequency) * resp.time)
            _asked_signal(
                result, d[0], want, f"d(t) = {float(amplitude):g} sin({float(frequency):g} t)"
            )
    checked = _run_checks(result, resp, plant, poles, initial_state, H, K1)
    if checked is None:
        return result
    e0, decoupled = checked
    _decays(result, resp, e0, decay, decoupled)
    return result


@never_raises(
    "Practical Assignment 9: the test with a piecewise-constant disturbance", "pa9.piecewise"
)
def pa9_piecewise(
    response: Any,
    sinusoidal: Any = None,
    *,
    decay: float = 0.01,
    max_jumps: float = 0.1,
    times: Any = None,
    values: Any = None,
    poles: Any = None,
    initial_state: Any = None,
    H: Any = None,
    K1: Any = None,
    plant: Any = None,
) -> CheckResult:
    """Check a simulation with a piecewise-constant disturbance, and compare with the sinusoid.

    The checks: ``d`` is piecewise constant (it jumps at least once, and at
    no more than ``max_jumps`` of the samples); the error does not depend on
    ``d`` (simulated again with ``d = 0``); when ``sinusoidal`` is given, the
    error equals the error of that simulation (same time grid and initial
    states); the error decays.

    Parameters
    ----------
    response : UIOResponse
        The simulation with the piecewise-constant disturbance.
    sinusoidal : UIOResponse, optional
        The simulation with the sinusoidal disturbance, to compare the errors.
    decay : float, optional
        The largest final error, relative to the initial one (1 %).
    max_jumps : float, optional
        The largest fraction of samples at which ``d`` may change.
    times, values : sequence of float, optional
        The disturbance the exercise asks for,
        ``ut.signals.piecewise_constant(times, values)``.
    poles : sequence of complex, optional
        The observer poles the exercise asks for.
    initial_state : array_like, optional
        The plant's initial state the exercise asks for.
    H, K1 : array_like, optional
        Your design of requirement 1: the simulated observer must be built from
        them (any valid ``H`` of yours, not only ``E (CE)^+``).
    plant : Plant, optional
        The plant of the lab's set-up cell: the run must be of this plant.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> from uio_teach.worked.pa9 import PA9
    >>> obs = ut.design_uio(PA9.plant(), poles=PA9.poles)
    >>> sin = PA9.simulate(obs, d=PA9.d_sine)
    >>> pw = PA9.simulate(obs, d=PA9.d_piecewise)
    >>> checks.pa9_piecewise(pw, sinusoidal=sin).passed
    True
    >>> checks.pa9_piecewise(sin).failures[0][:35]
    'd changes at 100% of the time steps'
    """
    result = CheckResult("Practical Assignment 9: the test with a piecewise-constant disturbance")
    resp = read_response(result, response)
    if resp is None:
        return result
    d = _disturbance(result, resp)
    if d is not None:
        jumps = _jumps(d)
        frac = jumps.size / max(1, d.shape[1] - 1)
        if jumps.size == 0:
            result.add(
                False,
                "d is constant: a piecewise-constant test needs jumps; take the times and "
                'values of PARAMS["piecewise"].',
            )
        elif frac > max_jumps:
            result.add(
                False,
                f"d changes at {frac:.0%} of the time steps, so it is not piecewise constant "
                "(is it still the sinusoid?): take the piecewise-constant d of "
                'PARAMS["piecewise"].',
            )
        else:
            at = ", ".join(f"{resp.time[k + 1]:.3g}" for k in jumps[:6])
            more = ", ..." if jumps.size > 6 else ""
            unit = _seconds(resp)
            result.add(
                True,
                f"d is piecewise constant: {plural(jumps.size, 'jump')} (at t = {at}{more}{unit}).",
            )
        if times is not None and values is not None and resp.plant.q == 1:
            want = np.asarray(piecewise_constant(times, values)(resp.time), float).ravel()
            _asked_signal(
                result,
                d[0],
                want,
                f"the piecewise-constant d with times {numbers(times)} and values "
                f"{numbers(values)}",
            )
    checked = _run_checks(result, resp, plant, poles, initial_state, H, K1)
    if checked is None:
        return result
    e0, decoupled = checked
    if sinusoidal is None:
        result.add(
            None,
            "pass sinusoidal=<the response of the sinusoidal test> to check that both "
            "disturbances give the same error.",
        )
    else:
        other = read_response(result, sinusoidal, "sinusoidal")
        if other is not None:
            _compare(result, resp, other)
    _decays(result, resp, e0, decay, decoupled)
    return result


def _run_checks(
    result: CheckResult,
    resp: Any,
    plant: Any,
    poles: Any,
    initial_state: Any,
    H: Any,
    K1: Any,
) -> tuple[float, bool] | None:
    """✓/✗ on what both PA9 runs share: the plant, the set-up, no noise, the error without d.

    Returns the initial error and whether the error ignores ``d``; None when
    the plant or the noise already rules the run out.
    """
    if not check_plant_of(result, resp, plant):
        return None
    _asked_setup(result, resp, poles, initial_state, H, K1)
    if not _noise_free(result, resp):
        return None
    e0 = _initial_error(result, resp)
    return e0, _same_without_d(result, resp)


def _compare(result: CheckResult, resp, other) -> None:
    if resp.time.shape != other.time.shape or not np.allclose(resp.time, other.time):
        result.add(
            False,
            "the two simulations use different time points, so their errors cannot be "
            "compared sample by sample: use the same timepts in both.",
        )
        return
    if not np.allclose(resp.states[:, 0], other.states[:, 0]):
        result.add(
            False,
            f"the two simulations start the plant from different states, "
            f"{numbers(resp.states[:, 0])} here and {numbers(other.states[:, 0])} in the "
            "sinusoidal test, so their errors differ for that reason alone: use the same "
            "initial_state in both.",
        )
        return
    if not same_observer(resp.observer, other.observer):
        result.add(
            False,
            f"the two simulations use different observers (a {resp.observer.family} here, "
            f"a {other.observer.family} in the sinusoidal test): simulate the same decoupling "
            "observer in both.",
        )
        return
    if not np.allclose(resp.estimates[:, 0], other.estimates[:, 0]):
        result.add(
            False,
            "the two simulations start the observer from different states, so their errors "
            "differ for that reason alone: use the same observer_state (or none) in both.",
        )
        return
    diff = float(np.max(np.abs(resp.error - other.error)))
    scale = max(1.0, float(np.max(np.abs(resp.states))), float(np.max(np.abs(other.states))))
    if diff <= tols.CHECK_RUN_RTOL * scale:
        result.add(
            True,
            f"the error is the same as with the sinusoidal disturbance"
            f"{up_to(diff, 'largest difference')}: the observer does not see which "
            "disturbance acts.",
        )
    else:
        result.add(
            False,
            f"the error differs from the sinusoidal test by up to {diff:.3g}: are both "
            "simulations made with the same decoupling observer?",
        )


def _asked_signal(result: CheckResult, got: np.ndarray, want: np.ndarray, what: str) -> None:
    diff = float(np.max(np.abs(np.asarray(got, float) - want)))
    if diff <= tols.CHECK_EXACT_RTOL * max(1.0, float(np.max(np.abs(want)))):
        result.add(True, f"d is the disturbance the exercise asks for, {what}.")
    else:
        result.add(
            False,
            f"d is not the disturbance the exercise asks for, {what} (they differ by up to "
            f"{diff:.3g}): take its numbers from PARAMS.",
        )


def _asked_setup(
    result: CheckResult,
    resp: Any,
    poles: Any,
    initial_state: Any,
    H: Any = None,
    K1: Any = None,
) -> None:
    """✓/✗ on the initial state, the observer (the student's own design) and its poles."""
    if initial_state is not None:
        want = np.asarray(initial_state, float).ravel()
        got = resp.states[:, 0]
        if want.shape == got.shape and np.allclose(got, want, rtol=0, atol=tols.CHECK_EXACT_RTOL):
            result.add(True, f"the plant starts from x(0) = {numbers(want)}, as asked.")
        elif not np.any(got):
            result.add(
                False,
                "the plant starts from x(0) = 0, but the exercise asks for the initial state "
                "of PARAMS: was initial_state left out of ut.simulate?",
            )
        else:
            result.add(
                False,
                f"the plant starts from x(0) = {numbers(got)}, but the exercise asks for "
                f'{numbers(want)}: take it from PARAMS["initial_state"].',
            )
    mine = _own_design(result, resp.observer, H, K1)
    if poles is None:
        return
    got_poles = resp.observer.poles()
    want_poles = as_poles(poles)
    if same_poles(got_poles, want_poles):
        result.add(True, f"the observer has the poles asked for, {format_poles(want_poles)}.")
    elif mine is False:
        result.add(
            False,
            f"the simulated observer has the poles {format_poles(got_poles)}, not the "
            f"{format_poles(want_poles)} of the exercise, because it is not your design "
            "(see above).",
        )
    else:
        result.add(
            False,
            f"the observer has the poles {format_poles(got_poles)}, but the exercise asks "
            f"for {format_poles(want_poles)}: its K1 does not place them (see requirement 1).",
        )


def _own_design(result: CheckResult, observer: Any, H: Any, K1: Any) -> bool | None:
    """✓/✗: the simulated observer is built from the student's own ``H`` and ``K1``.

    Returns None when neither is given, else whether both agree.
    """
    given = [(name, value) for name, value in (("H", H), ("K1", K1)) if value is not None]
    if not given:
        return None
    differ = []
    for name, value in given:
        theirs = getattr(observer, name, None)
        try:
            mine = np.asarray(value, float)
        except (TypeError, ValueError):
            mine = None
        if (
            theirs is None
            or mine is None
            or not close(mine, np.asarray(theirs, float), tols.CHECK_RUN_RTOL)
        ):
            differ.append(name)
    if not differ:
        result.add(True, "the simulated observer is your design of requirement 1.")
        return True
    hint = (
        " ut.design_uio(plant, K1=K1) builds it with H = E(CE)^+; an observer with your own "
        "H and K1 is ut.UIO(plant, H, K1)."
        if "H" in differ and getattr(observer, "family", "") == "UIO"
        else " Build the observer from the H and K1 of requirement 1."
    )
    result.add(
        False,
        f"the simulated observer is not your design of requirement 1: its "
        f"{' and '.join(differ)} differ{'s' if len(differ) == 1 else ''} from yours.{hint}",
    )
    return False
