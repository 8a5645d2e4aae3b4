"""One picture of an explorer: design both observers, simulate them, prepare the curves.

:func:`compute_frame` designs the unknown input observer of the scenario with
the settings' poles (or the LMI bound) and a plain Luenberger observer with the
poles of :func:`uio_teach.luenberger.luenberger_poles`, simulates both with
:func:`uio_teach.simulate` and returns a :class:`Frame`: the curves to draw
(clipped for display) and short messages in plain words. It never raises for a
value a student can set: a pole that makes the observer unstable or an
infeasible LMI becomes a message.

Examples
--------
>>> from uio_teach.explorers import compute_frame, pa9_scenario
>>> scenario = pa9_scenario()
>>> frame = compute_frame(scenario, scenario.defaults.replace(poles=(-2.0, -3.0, -4.0)))
>>> frame.poles.real.round(6).tolist()
[-4.0, -3.0, -2.0]
>>> frame.luenberger_poles.real.round(6).tolist()
[-4.0, -3.0, -2.0]
>>> frame.messages
()
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._display import format_poles
from ..linalg import is_stable
from ..lmi import LMIInfeasibleError
from ..luenberger import luenberger_poles
from ..observers import (
    Observer,
    design_ginverse,
    design_luenberger,
    design_pmo,
    design_uio,
)
from ..reconstruction import InputEstimate, reconstruct_input
from ..simulation import UIOResponse, simulate
from .model import Scenario, Settings, _describe, disturbance_signals, expand_poles

__all__ = ["Frame", "compute_frame"]


@dataclass(frozen=True, eq=False)
class Frame:
    """Everything one picture of an explorer shows, for one setting of the controls.

    ``curves`` maps ``"<who>.<what>"`` to an array with one row per channel
    (``who`` is ``"uio"`` for the unknown input observer, ``"lb"`` for the
    Luenberger observer; ``what`` is ``"error"``, ``"residual"`` or
    ``"input"``), or to ``None`` when that curve is not available (a design
    that failed). The arrays are clipped to ``limits[what]`` for display;
    the unclipped values are in the responses.

    Attributes
    ----------
    scenario : Scenario
        The scenario.
    settings : Settings
        The control values.
    time : numpy.ndarray
        The time points.
    observer, luenberger : Observer or None
        The designed observers (``None`` if the design failed).
    response, luenberger_response : UIOResponse or None
        Their simulations.
    input_estimate, luenberger_input_estimate : InputEstimate or None
        The reconstructed unknown inputs (explorers with ``tau_limits``).
    d, v : numpy.ndarray
        The applied unknown signals, one row per channel.
    curves : dict
        The display curves (see above).
    limits : dict
        The clipping bound of each kind of curve.
    poles, luenberger_poles : numpy.ndarray
        The observers' error poles (empty when the design failed).
    observer_message, luenberger_message : str
        A short message about each observer ("" when all is well).
    messages : tuple of str
        General notes: clipped curves, an error that has not settled, a bad
        control value.
    disturbance : str
        A description of the disturbance.

    Examples
    --------
    >>> from uio_teach.explorers import compute_frame, pa9_scenario
    >>> s = pa9_scenario()
    >>> frame = compute_frame(s, s.defaults.replace(poles=(0.5, -2.0, -3.0)))
    >>> print(frame.observer_message)
    this pole makes the UIO unstable: the error grows (pole 0.5 in the right half-plane)
    >>> frame.curves["uio.error"].shape
    (3, 1001)
    """

    scenario: Scenario
    settings: Settings
    time: np.ndarray
    observer: Observer | None
    luenberger: Observer | None
    response: UIOResponse | None
    luenberger_response: UIOResponse | None
    input_estimate: InputEstimate | None
    luenberger_input_estimate: InputEstimate | None
    d: np.ndarray
    v: np.ndarray
    curves: dict[str, np.ndarray | None]
    limits: dict[str, float]
    poles: np.ndarray
    luenberger_poles: np.ndarray
    observer_message: str
    luenberger_message: str
    messages: tuple[str, ...]
    disturbance: str

    @property
    def all_messages(self) -> tuple[str, ...]:
        """Every message, observer first."""
        out = []
        if self.observer_message:
            out.append(f"{self.scenario.observer_name}: {self.observer_message}")
        if self.luenberger_message:
            out.append(f"Luenberger observer: {self.luenberger_message}")
        return (*out, *self.messages)


def _stability_message(name: str, poles: np.ndarray, discrete: bool) -> str:
    if not poles.size:
        return ""
    bad = poles[~is_stable(poles, discrete)]
    if not bad.size:
        return ""
    growing = np.abs(bad) > 1 + 1e-9 if discrete else bad.real > 1e-9 * np.maximum(1, abs(bad))
    where = "outside the unit circle" if discrete else "in the right half-plane"
    edge = "on the unit circle" if discrete else "on the imaginary axis"
    if np.any(growing):
        grow = bad[growing]
        word = "pole" if grow.size == 1 else "poles"
        this = "this pole makes" if grow.size == 1 else "these poles make"
        listed = format_poles(grow, 3)
        return f"{this} the {name} unstable: the error grows ({word} {listed} {where})"
    word = "pole" if bad.size == 1 else "poles"
    return f"{word} {format_poles(bad, 3)} {edge}: the {name} error does not decay"


def _design(scenario: Scenario, s: Settings) -> tuple[Observer | None, str]:
    plant = scenario.plant
    name = scenario.observer_name
    report = scenario.existence
    if not report.ok:
        why = "; ".join(f"{c.name}: {c.reason}" for c in report.failed)
        return None, f"no {name} exists for this plant ({why})"
    lmi = s.mode == "lmi"
    if s.mode not in ("poles", "lmi") or (lmi and scenario.decay_limits is None):
        return None, f"unknown mode {s.mode!r} for this explorer"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if scenario.family == "ginverse":
                obs: Observer = design_ginverse(plant)
            elif lmi:
                key = ("lmi", float(s.decay))
                if key not in scenario._cache:
                    try:
                        scenario._cache[key] = design_pmo(plant, method="lmi", decay=s.decay)
                    except LMIInfeasibleError as exc:
                        scenario._cache[key] = exc
                if isinstance(scenario._cache[key], Exception):
                    raise scenario._cache[key]
                obs = scenario._cache[key]
            else:
                poles = expand_poles(s.poles)
                design = design_uio if scenario.family == "uio" else design_pmo
                obs = design(plant, poles=poles)
    except LMIInfeasibleError as exc:
        fixed = scenario.fixed_poles
        text = str(exc)
        if fixed.size:
            region = (
                f"radius {np.abs(fixed).max():.3g}"
                if scenario.discrete
                else f"real part {fixed.real.max():.3g}"
            )
            text += f"; the fixed poles (invariant zeros) at {region} cannot move"
        return None, text
    except Exception as exc:  # a bad pole list, a failed placement: say it, do not raise
        return None, f"cannot design the {name}: {exc}"
    return obs, _stability_message(name, obs.poles(), scenario.discrete)


def _luenberger(scenario: Scenario, s: Settings, obs: Observer | None):
    plant = scenario.plant
    if obs is not None:
        target = obs.poles()
    else:
        if scenario.family == "ginverse" or s.mode == "lmi":
            wanted = expand_poles(scenario.defaults.poles)
        else:
            try:
                wanted = expand_poles(s.poles)
            except (TypeError, ValueError):
                wanted = expand_poles(scenario.defaults.poles)
        target = np.concatenate([wanted, scenario.fixed_poles])
    try:
        poles = luenberger_poles(plant, target)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            lb = design_luenberger(plant, poles=poles)
    except Exception as exc:
        return None, f"cannot design it: {exc}"
    return lb, _stability_message("Luenberger observer", lb.poles(), scenario.discrete)


def _clip(arr: np.ndarray, limit: float) -> tuple[np.ndarray, bool]:
    out = np.array(arr, dtype=float)
    with np.errstate(invalid="ignore"):
        hit = bool(np.any(~(np.abs(out) <= limit) & ~np.isnan(out)))
    np.clip(out, -limit, limit, out=out)
    return out, hit


def _finite_max(*arrays: np.ndarray | None) -> float:
    best = 0.0
    for a in arrays:
        if a is None or not np.size(a):
            continue
        a = np.abs(np.asarray(a, dtype=float))
        a = a[np.isfinite(a)]
        if a.size:
            best = max(best, float(a.max()))
    return best


def compute_frame(scenario: Scenario, settings: Settings | None = None) -> Frame:
    """Design, simulate and prepare the curves of one explorer picture; never raises.

    The unknown input observer of ``scenario.family`` is designed with the
    settings' poles (or the LMI bound), the Luenberger observer with the poles
    of :func:`uio_teach.luenberger.luenberger_poles`; both are simulated with
    :func:`uio_teach.simulate` on the same plant, inputs, noise (same seed)
    and initial state, with observer states starting at zero. Errors,
    residuals (and reconstructed inputs) are clipped for display at ten times
    the largest plant state, output (and unknown input) of the simulation.
    Anything that goes wrong becomes a message.

    Parameters
    ----------
    scenario : Scenario
        What to explore.
    settings : Settings, optional
        The control values; ``scenario.defaults`` by default.

    Returns
    -------
    Frame

    Examples
    --------
    An LMI bound below the fixed poles' radius is infeasible: a message, no
    exception.

    >>> from uio_teach.explorers import case_study_scenario, compute_frame
    >>> s = case_study_scenario()
    >>> frame = compute_frame(s, s.defaults.replace(mode="lmi", decay=0.4))
    >>> frame.observer is None, "cannot move" in frame.observer_message
    (True, True)
    >>> frame.curves["uio.error"] is None, frame.curves["lb.error"].shape
    (True, (3, 41))
    """
    s = scenario.defaults if settings is None else settings
    try:
        return _compute(scenario, s)
    except Exception as exc:  # pragma: no cover - a last resort: every known case is handled
        plant = scenario.plant
        t = scenario.timepts
        return Frame(
            scenario=scenario,
            settings=s,
            time=t,
            observer=None,
            luenberger=None,
            response=None,
            luenberger_response=None,
            input_estimate=None,
            luenberger_input_estimate=None,
            d=np.zeros((plant.q, t.size)),
            v=np.zeros((plant.r, t.size)),
            curves={},
            limits={},
            poles=np.zeros(0, complex),
            luenberger_poles=np.zeros(0, complex),
            observer_message="",
            luenberger_message="",
            messages=(f"could not compute this picture: {exc}",),
            disturbance="",
        )


def _compute(scenario: Scenario, s: Settings) -> Frame:
    plant = scenario.plant
    t = scenario.timepts
    N = t.size
    notes: list[str] = []

    # the unknown signals
    d = np.zeros((plant.q, N))
    v = np.zeros((plant.r, N))
    description = ""
    try:
        d_sig, v_sig = disturbance_signals(scenario, s)
        if d_sig:
            d = np.vstack([f(t) for f in d_sig])
        if v_sig:
            v = np.vstack([f(t) for f in v_sig])
        description = _describe(s.disturbance, s, scenario.discrete)
    except (ValueError, TypeError) as exc:
        notes.append(f"disturbance: {exc}; no disturbance applied")
    noise = s.noise
    if not isinstance(noise, int | float | np.number) or not np.isfinite(noise) or noise < 0:
        notes.append(f"the noise level must be a number >= 0, got {noise!r}; no noise applied")
        noise = 0.0
    kwargs: dict[str, Any] = {
        "u": scenario.u,
        "d": d if plant.q else None,
        "v": v if plant.r else None,
        "initial_state": scenario.initial_state,
        "noise": float(noise) if noise > 0 else None,
        "seed": s.seed,
    }

    obs, obs_msg = _design(scenario, s)
    lb, lb_msg = _luenberger(scenario, s, obs)

    responses: dict[str, UIOResponse | None] = {"uio": None, "lb": None}
    for key, o in (("uio", obs), ("lb", lb)):
        if o is None:
            continue
        try:
            with np.errstate(all="ignore"):
                responses[key] = simulate(plant, o, t, **kwargs)
        except Exception as exc:
            text = f"the simulation failed: {exc}"
            if key == "uio":
                obs_msg = text
            else:
                lb_msg = text

    estimates: dict[str, InputEstimate | None] = {"uio": None, "lb": None}
    if scenario.reconstruct:
        tau = s.tau
        if not isinstance(tau, int | float | np.number) or not np.isfinite(tau) or tau < 0:
            notes.append(f"tau must be a time constant >= 0, got {tau!r}; no filter used")
            tau = 0.0
        for key, resp in responses.items():
            if resp is None:
                continue
            try:
                with np.errstate(all="ignore"):
                    estimates[key] = (
                        reconstruct_input(plant, resp, method="filtered", tau=float(tau))
                        if tau > 0
                        else reconstruct_input(plant, resp)
                    )
            except Exception as exc:
                notes.append(f"input reconstruction failed: {exc}")

    # display: clip at ten times the size of the plant's own signals
    ok = [r for r in responses.values() if r is not None]
    size_x = _finite_max(scenario.initial_state, *(r.states for r in ok))
    size_y = _finite_max(*(r.outputs for r in ok))
    size_d = max(_finite_max(d), abs(float(scenario.defaults.amplitude)))
    limits = {
        "error": 10 * (size_x or 1.0),
        "residual": 10 * (size_y or size_x or 1.0),
        "input": 10 * (size_d or 1.0),
    }
    curves: dict[str, np.ndarray | None] = {}
    clipped: set[str] = set()
    for key, resp in responses.items():
        est = estimates[key]
        parts = {
            "error": None if resp is None else resp.error,
            "residual": None if resp is None else resp.residual,
        }
        if scenario.reconstruct:
            parts["input"] = None if est is None else est.estimates
        for what, arr in parts.items():
            if arr is None:
                curves[f"{key}.{what}"] = None
                continue
            curves[f"{key}.{what}"], hit = _clip(arr, limits[what])
            if hit:
                clipped.add(what)
    if clipped:
        which = " and ".join(sorted(clipped))
        notes.append(f"{which} curves are clipped for display (they leave the plotted range)")
    resp = responses["uio"]
    if resp is not None and not obs_msg and not kwargs["noise"]:
        err = np.abs(resp.error)
        top = float(np.max(err)) if err.size else 0.0
        tail = float(np.max(err[:, -max(1, N // 10) :])) if err.size else 0.0
        if top > 0 and tail > 0.05 * top:
            notes.append(
                "the error has not settled by the end of the window: the slowest pole is slow"
            )
    if scenario.reconstruct and s.tau == 0 and kwargs["noise"]:
        notes.append(
            "the numerical derivative amplifies the noise: try a filter time constant tau > 0"
        )
    return Frame(
        scenario=scenario,
        settings=s,
        time=t,
        observer=obs,
        luenberger=lb,
        response=responses["uio"],
        luenberger_response=responses["lb"],
        input_estimate=estimates["uio"],
        luenberger_input_estimate=estimates["lb"],
        d=d,
        v=v,
        curves=curves,
        limits=limits,
        poles=obs.poles() if obs is not None else np.zeros(0, complex),
        luenberger_poles=lb.poles() if lb is not None else np.zeros(0, complex),
        observer_message=obs_msg,
        luenberger_message=lb_msg,
        messages=tuple(notes),
        disturbance=description,
    )
