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
>>> from uio_teach.explorers import compute_frame, scenario_of
>>> scenario = scenario_of("pa9")
>>> frame = compute_frame(scenario, scenario.defaults.replace(poles=(-2.0, -3.0, -4.0)))
>>> frame.poles.real.round(6).tolist()
[-4.0, -3.0, -2.0]
>>> frame.luenberger_poles.real.round(6).tolist()
[-4.0, -3.0, -2.0]
>>> frame.messages
()

From the default start (a zero estimate) the error reaches the movable modes, so
moving a pole changes the error:

>>> other = compute_frame(scenario, scenario.defaults.replace(poles=(-6.0, -3.0, -4.0)))
>>> bool(abs(frame.response.error - other.response.error).max() > 0.1)
True
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._display import format_poles
from ..linalg import is_stable
from ..lmi import LMIInfeasibleError, LMISolverError
from ..luenberger import luenberger_poles
from ..observers import (
    Observer,
    UnstableObserverWarning,
    design_ginverse,
    design_luenberger,
    design_pmo,
    design_reduced_uio,
    design_uio,
)
from ..reconstruction import InputEstimate, reconstruct_input
from ..simulation import UIOResponse, simulate
from ..verify import PlacementAccuracyWarning
from .messages import (
    ROUNDING,
    ErrorVerdict,
    clipped_notes,
    describe_disturbance,
    explain,
    lmi_message,
    overflow_message,
    sampling_notes,
    stability_message,
    unsettled_note,
    zero_notes,
)
from .model import STARTS, Scenario, Settings, disturbance_signals, expand_poles
from .modes import (
    excited_modes,
    match_poles,
    pole_positions,
    pole_rate,
    remove_poles,
    slowest_pole,
)

__all__ = ["Frame", "compute_frame", "finite_max"]


@dataclass(frozen=True, eq=False)
class Frame:
    r"""Everything one picture of an explorer shows, for one setting of the controls.

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
        General notes: clipped curves, an error that has not settled, a pole
        on an invariant zero, a bad control value.
    disturbance : str
        A description of the disturbance.
    movable_poles, fixed_poles : numpy.ndarray
        The unknown input observer's poles that the controls move, and those
        no gain moves (the invariant zeros).
    excited : numpy.ndarray of bool
        For each entry of ``poles``: does the observer's start reach that mode
        of the error (``excited_modes``)?
    initial_error : numpy.ndarray
        ``e(0) = x(0) - xhat(0)`` of the unknown input observer.
    guides : dict
        Curves drawn over ``|e|`` (label: values over ``time``): the rate of
        the slowest excited movable mode and of the slowest fixed one, or in
        LMI mode the certified envelope ``sqrt(cond P) rho^k |e(0)|``.
    explanation : str
        In words: which poles the controls move, which stay fixed, and which
        modes the start excites.
    verdict, luenberger_verdict : ErrorVerdict or None
        What each observer's simulated error does (``None`` without a
        simulation); every sentence about the error is derived from them.
    residual_zero : bool
        The unknown input observer's residual is zero to rounding (its panel
        then shows a flat line, not magnified rounding noise).

    Examples
    --------
    >>> from uio_teach.explorers import compute_frame, scenario_of
    >>> s = scenario_of("pa9")
    >>> frame = compute_frame(s, s.defaults.replace(poles=(0.5, -2.0, -3.0)))
    >>> print(frame.observer_message.replace("; ", ";\n"))
    this pole makes the UIO unstable: the error grows (pole 0.5 in the right half-plane;
    |e| from 1.5 to 32.8)
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
    movable_poles: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))
    fixed_poles: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))
    excited: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))
    initial_error: np.ndarray = field(default_factory=lambda: np.zeros(0))
    guides: dict[str, np.ndarray] = field(default_factory=dict)
    explanation: str = ""
    verdict: ErrorVerdict | None = None
    luenberger_verdict: ErrorVerdict | None = None
    residual_zero: bool = False

    @property
    def all_messages(self) -> tuple[str, ...]:
        """Every message, observer first."""
        out = []
        if self.observer_message:
            out.append(f"{self.scenario.observer_name}: {self.observer_message}")
        if self.luenberger_message:
            out.append(f"Luenberger observer: {self.luenberger_message}")
        return (*out, *self.messages)


# the pipeline: signals, designs, simulations, modes, words, display -------------------------


_REMEMBERED = 128  # designs kept per scenario: a slider's sweep and back, several times


def _remembered(scenario: Scenario, key: tuple, make: Callable[[], Any]) -> Any:
    """``make()``, remembered in the scenario's cache under ``key`` (the oldest dropped first).

    A design depends on the plant and the poles alone, so a change of the disturbance, the
    noise, the start or the filter does not design the observers again.
    """
    cache = scenario.cache
    try:
        if key in cache:
            return cache[key]
    except TypeError:  # an unhashable control value: nothing to remember it by
        return make()
    value = cache[key] = make()
    designs = [k for k in cache if isinstance(k, tuple) and k[:1] == key[:1]]
    for old in designs[: max(0, len(designs) - _REMEMBERED)]:
        del cache[old]
    return value


def _design(scenario: Scenario, s: Settings) -> tuple[Observer | None, str, list[str]]:
    """The unknown input observer, a message if it failed, and notes from its checks."""
    if scenario.family == "ginverse":
        key: tuple = ("design", "ginverse")
    elif s.mode == "lmi":
        key = ("design", "lmi", s.decay)
    else:
        key = ("design", s.mode, s.poles)
    obs, message, notes = _remembered(scenario, key, lambda: _design_now(scenario, s))
    return obs, message, list(notes)


def _design_now(scenario: Scenario, s: Settings) -> tuple[Observer | None, str, list[str]]:
    plant = scenario.plant
    name = scenario.observer_name
    report = scenario.existence
    notes: list[str] = []
    if not report.ok:
        why = "; ".join(f"{c.name}: {c.reason}" for c in report.failed)
        return None, f"no {name} exists for this plant ({why})", notes
    lmi = s.mode == "lmi"
    if s.mode not in ("poles", "lmi") or (lmi and scenario.decay_limits is None):
        return None, f"unknown mode {s.mode!r} for this explorer", notes
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            if scenario.family == "ginverse":
                obs: Observer = design_ginverse(plant)
            elif lmi:
                key = ("lmi", float(s.decay))
                if key not in scenario.cache:
                    try:
                        scenario.cache[key] = design_pmo(plant, method="lmi", decay=s.decay)
                    except (LMIInfeasibleError, LMISolverError) as exc:
                        scenario.cache[key] = exc
                if isinstance(scenario.cache[key], Exception):
                    raise scenario.cache[key]
                obs = scenario.cache[key]
            else:
                poles = expand_poles(s.poles)
                design = {"uio": design_uio, "reduced": design_reduced_uio}.get(
                    scenario.family, design_pmo
                )
                obs = design(plant, poles=poles)
    except (LMIInfeasibleError, LMISolverError) as exc:
        return None, lmi_message(scenario, float(s.decay), exc), notes
    except Exception as exc:  # a bad pole list, a failed placement: say it, do not raise
        return None, f"cannot design the {name}: {exc}", notes
    for w in caught:
        if issubclass(w.category, PlacementAccuracyWarning):
            notes.append(
                f"the {name}'s poles are placed only approximately here (a sensitive "
                "placement: close or repeated poles); the pole map shows where they landed"
            )
        # UnstableObserverWarning: said by the stability message, which agrees with the plot
    return obs, "", notes


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
        # no UIO: an unstable fixed pole (an unstable zero) is no pole a Luenberger observer has
        fixed = scenario.fixed_poles
        target = np.concatenate([wanted, fixed[is_stable(fixed, scenario.discrete)]])
    target = np.asarray(target, dtype=complex)
    key = ("luenberger", target.tobytes())
    return _remembered(scenario, key, lambda: _luenberger_now(plant, target))


def _luenberger_now(plant, target: np.ndarray):
    try:
        poles = luenberger_poles(plant, target)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UnstableObserverWarning)
            warnings.simplefilter("ignore", PlacementAccuracyWarning)
            lb = design_luenberger(plant, poles=poles)
    except Exception as exc:
        return None, f"cannot design it: {exc}"
    return lb, ""


def _observer_start(
    obs: Observer, plant, x0: np.ndarray, v0: np.ndarray, start: str
) -> tuple[np.ndarray | None, np.ndarray]:
    """The observer state that realizes the start, and the initial error ``x(0) - xhat(0)``."""
    real = obs.realization()
    y0 = plant.C @ x0 + (plant.D @ v0 if plant.nv else 0.0)
    if start == "zero observer state":
        w0 = None
        xhat0 = real.D_y @ y0
    else:  # zero estimate: C_o w0 = -D_y y0
        w0 = np.linalg.lstsq(real.C, -real.D_y @ y0, rcond=None)[0]
        xhat0 = real.C @ w0 + real.D_y @ y0
    return w0, x0 - xhat0


def _clip(arr: np.ndarray, limit: float) -> tuple[np.ndarray, bool]:
    out = np.array(arr, dtype=float)
    with np.errstate(invalid="ignore"):
        hit = bool(np.any(~(np.abs(out) <= limit) & ~np.isnan(out)))
    np.clip(out, -limit, limit, out=out)
    return out, hit


def finite_max(*arrays: np.ndarray | None) -> float:
    """The largest finite ``|value|`` over some arrays (``None`` and empty ones skipped); 0 if none.

    Parameters
    ----------
    *arrays : numpy.ndarray or None
        The arrays.

    Returns
    -------
    float

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.frames import finite_max
    >>> finite_max(np.array([1.0, -3.0, np.inf]), None)
    3.0
    """
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
    and initial state, both starting as ``Settings.start`` says (by
    default from a zero estimate). Errors, residuals (and reconstructed
    inputs) are clipped for display at ten times the largest plant state,
    output (and unknown input) of the simulation. Anything that goes wrong
    becomes a message. A message that says the error grows is only given when
    the simulated error does grow (``error_grows``); an unstable mode that
    the start does not excite is named as such.

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
    An LMI bound below the fixed poles' radius has no solution: a message, no
    exception.

    >>> from uio_teach.explorers import scenario_of, compute_frame
    >>> s = scenario_of("case_study")
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
            v=np.zeros((plant.nv, t.size)),
            curves={},
            limits={},
            poles=np.zeros(0, complex),
            luenberger_poles=np.zeros(0, complex),
            observer_message="",
            luenberger_message="",
            messages=(f"could not compute this picture: {exc}",),
            disturbance="",
        )


@dataclass
class _Run:
    """What the pipeline has found so far for one frame (filled step by step)."""

    scenario: Scenario
    settings: Settings
    notes: list[str] = field(default_factory=list)
    d: np.ndarray | None = None
    v: np.ndarray | None = None
    description: str = ""
    kwargs: dict[str, Any] = field(default_factory=dict)
    start: str = "zero estimate"
    observers: dict[str, Observer | None] = field(default_factory=dict)
    messages: dict[str, str] = field(default_factory=dict)
    responses: dict[str, UIOResponse | None] = field(default_factory=dict)
    starts: dict[str, np.ndarray] = field(default_factory=dict)
    overflowed: set[str] = field(default_factory=set)


def _signals(run: _Run) -> None:
    """Step 1: the unknown signals, the noise level and the start (a bad value becomes a note)."""
    sc, s = run.scenario, run.settings
    plant, t = sc.plant, sc.timepts
    run.d = np.zeros((plant.q, t.size))
    run.v = np.zeros((plant.nv, t.size))
    try:
        d_sig, v_sig = disturbance_signals(sc, s)
        if d_sig:
            run.d = np.vstack([f(t) for f in d_sig])
        if v_sig:
            run.v = np.vstack([f(t) for f in v_sig])
        run.description = describe_disturbance(s.disturbance, s, sc.discrete)
    except (ValueError, TypeError) as exc:
        run.notes.append(f"disturbance: {exc}; no disturbance applied")
    noise = s.noise
    if not isinstance(noise, int | float | np.number) or not np.isfinite(noise) or noise < 0:
        run.notes.append(f"the noise level must be a number >= 0, got {noise!r}; no noise applied")
        noise = 0.0
    if s.start in STARTS:
        run.start = s.start
    else:
        run.notes.append(f"unknown start {s.start!r}; the observers start from a zero estimate")
    run.kwargs = {
        "u": sc.u,
        "d": run.d if plant.q else None,
        "v": run.v if plant.nv else None,
        "initial_state": sc.initial_state,
        "noise": float(noise) if noise > 0 else None,
        "seed": s.seed,
    }


def _observers(run: _Run) -> None:
    """Step 2: design the unknown input observer and the Luenberger observer."""
    obs, obs_msg, design_notes = _design(run.scenario, run.settings)
    run.notes += design_notes
    lb, lb_msg = _luenberger(run.scenario, run.settings, obs)
    run.observers = {"uio": obs, "lb": lb}
    run.messages = {"uio": obs_msg, "lb": lb_msg}


def _simulate(run: _Run) -> None:
    """Step 3: simulate both observers from the chosen start; an overflow is one short line."""
    sc = run.scenario
    plant = sc.plant
    x0 = np.asarray(sc.initial_state, dtype=float)
    v0 = run.v[:, 0] if plant.nv else np.zeros(0)
    run.responses = {"uio": None, "lb": None}
    for key, o in run.observers.items():
        if o is None:
            continue
        try:
            w0, run.starts[key] = _observer_start(o, plant, x0, v0, run.start)
            with np.errstate(all="ignore"):
                run.responses[key] = simulate(plant, o, sc.timepts, observer_state=w0, **run.kwargs)
        except Exception as exc:
            if "floating-point range" in str(exc):
                run.overflowed.add(key)
                run.messages[key] = (
                    "its error overflows too, no curve"
                    if key == "lb" and "uio" in run.overflowed
                    else overflow_message(o.poles(), sc.discrete)
                )
            else:
                first = str(exc).split(". ")[0].split("\n")[0]
                run.messages[key] = f"the simulation failed ({first}), no curve"


def _modes(run: _Run) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Step 4: the poles, which the controls move, which are fixed, which the start excites."""
    sc = run.scenario
    obs = run.observers["uio"]
    poles = obs.poles() if obs is not None else np.zeros(0, complex)
    fixed = np.asarray(sc.fixed_poles, dtype=complex)
    movable = (
        np.zeros(0, complex)
        if obs is None or sc.family == "ginverse"
        else remove_poles(poles, fixed)
    )
    excited = np.zeros(poles.size, bool)
    e0 = run.starts.get("uio", np.zeros(0))
    if obs is not None and "uio" in run.starts:
        if obs.error_matrix.shape[0] != e0.size:  # a reduced-order observer: x - xhat = C_o eps
            e0 = np.linalg.lstsq(obs.realization().C, e0, rcond=None)[0]
        excited = match_poles(poles, excited_modes(obs.error_matrix, e0))
        scale = max(1.0, float(np.abs(poles).max()))
        for i in range(poles.size):  # a repeated pole: one excited copy excites that value
            excited[i] |= bool(np.any(excited & (np.abs(poles - poles[i]) <= 1e-6 * scale)))
        if run.kwargs["noise"]:
            excited[:] = True  # noise reaches every mode
    return poles, movable, fixed, excited, e0


def _reconstruct(run: _Run) -> dict[str, InputEstimate | None]:
    """Step 5 (explorers that reconstruct the unknown input): each observer's estimate of it."""
    estimates: dict[str, InputEstimate | None] = {"uio": None, "lb": None}
    if not run.scenario.reconstruct:
        return estimates
    tau = run.settings.tau
    if not isinstance(tau, int | float | np.number) or not np.isfinite(tau) or tau < 0:
        run.notes.append(f"tau must be a time constant >= 0, got {tau!r}; no filter used")
        tau = 0.0
    for key, r in run.responses.items():
        if r is None:
            continue
        try:
            with np.errstate(all="ignore"):
                estimates[key] = (
                    reconstruct_input(run.scenario.plant, r, method="filtered", tau=float(tau))
                    if tau > 0
                    else reconstruct_input(run.scenario.plant, r)
                )
        except Exception as exc:
            run.notes.append(f"input reconstruction failed: {exc}")
    if run.settings.tau == 0 and run.kwargs["noise"]:
        run.notes.append(
            "the numerical derivative amplifies the noise: try a filter time constant tau > 0"
        )
    return estimates


def _display(
    run: _Run, estimates: dict[str, InputEstimate | None]
) -> tuple[dict[str, np.ndarray | None], dict[str, float]]:
    """Step 6: the curves clipped at ten times the size of the plant's own signals."""
    sc = run.scenario
    N = sc.timepts.size
    ok = [r for r in run.responses.values() if r is not None]
    size_x = finite_max(sc.initial_state, *(r.states for r in ok))
    size_y = finite_max(*(r.outputs for r in ok))
    size_d = max(finite_max(run.d), abs(float(sc.defaults.amplitude)))
    limits = {
        "error": 10 * (size_x or 1.0),
        "residual": 10 * (size_y or size_x or 1.0),
        "input": 10 * (size_d or 1.0),
    }
    curves: dict[str, np.ndarray | None] = {}
    clipped: dict[str, set[str]] = {}
    for key, r in run.responses.items():
        parts = {
            "error": None if r is None else r.error,
            "residual": None if r is None else r.residual,
        }
        if sc.reconstruct:
            est = estimates[key]
            parts["input"] = None if est is None else est.estimates
        for what, arr in parts.items():
            if arr is None:
                curves[f"{key}.{what}"] = None
                continue
            curves[f"{key}.{what}"], _ = _clip(arr, limits[what])
            # said only when it lasts: a start's transient alone is not worth a note
            _, hit = _clip(np.asarray(arr)[..., N // 10 :], limits[what])
            if hit:
                clipped.setdefault(key, set()).add(what)
    run.notes += clipped_notes(clipped, sc.observer_name)
    return curves, limits


def _guides(run: _Run, poles, movable, fixed, excited, e0) -> dict[str, np.ndarray]:
    """Step 7: curves over |e|: the rates the poles set, or the LMI's certified envelope."""
    sc, s = run.scenario, run.settings
    t = sc.timepts
    discrete = sc.discrete
    obs = run.observers["uio"]
    guides: dict[str, np.ndarray] = {}
    size0 = float(np.linalg.norm(e0)) if e0.size else 0.0
    if obs is None or not size0 > 0:
        return guides
    P = getattr(obs, "lmi_certificate", None) if s.mode == "lmi" else None
    if P is not None:
        ev = np.linalg.eigvalsh(0.5 * (P + P.T))
        gain = float(np.sqrt(ev.max() / ev.min()))
        rho = float(s.decay)
        if discrete:
            rate = rho ** np.round((t - t[0]) / (t[1] - t[0]))
        else:
            rate = np.exp(-rho * (t - t[0]))
        guides[f"certified bound, {'radius' if discrete else 'rate'} {rho:.3g}"] = (
            gain * size0 * rate
        )
    slow_m = slowest_pole(movable[excited[pole_positions(poles, movable)]], discrete)
    if slow_m is not None and s.mode != "lmi":
        guides[f"rate of slowest moved pole {format_poles([slow_m], 3)}"] = size0 * pole_rate(
            slow_m, discrete, t
        )
    slow_f = slowest_pole(fixed[excited[pole_positions(poles, fixed)]], discrete)
    if slow_f is not None:
        guides[f"rate of slowest fixed pole {format_poles([slow_f], 3)}"] = size0 * pole_rate(
            slow_f, discrete, t
        )
    return guides


def _compute(scenario: Scenario, s: Settings) -> Frame:
    """The pipeline: each step fills ``_Run``; the words come from the simulated errors."""
    run = _Run(scenario, s)
    _signals(run)
    _observers(run)
    _simulate(run)
    poles, movable, fixed, excited, e0 = _modes(run)
    discrete = scenario.discrete
    t = scenario.timepts
    obs, lb = run.observers["uio"], run.observers["lb"]
    resp, lresp = run.responses["uio"], run.responses["lb"]
    estimates = _reconstruct(run)
    curves, limits = _display(run, estimates)
    scale = limits["error"] / 10
    verdict = ErrorVerdict.of(None if resp is None else resp.error, scale)
    lb_verdict = ErrorVerdict.of(None if lresp is None else lresp.error, scale)
    if obs is not None and resp is not None and not run.messages["uio"]:
        run.messages["uio"] = stability_message(
            scenario.observer_name, poles, excited, verdict, discrete
        )
    if lb is not None and lresp is not None and not run.messages["lb"]:
        lp = lb.poles()
        run.messages["lb"] = stability_message(
            "Luenberger observer", lp, np.ones(lp.size, bool), lb_verdict, discrete
        )
    notes = []
    if s.mode != "lmi" and scenario.family != "ginverse":
        try:
            notes += zero_notes(scenario, expand_poles(s.poles))
        except (TypeError, ValueError):
            pass
    if resp is not None and not run.messages["uio"] and not run.kwargs["noise"]:
        text = unsettled_note(verdict, resp.error, poles, excited, fixed, discrete, t)
        notes += [text] if text else []
    if resp is not None:
        notes += sampling_notes(poles, excited, discrete, t)
    residual_zero = bool(
        resp is not None
        and resp.residual.size
        and finite_max(resp.residual) <= ROUNDING * (limits["residual"] / 10)
    )
    return Frame(
        scenario=scenario,
        settings=s,
        time=t,
        observer=obs,
        luenberger=lb,
        response=resp,
        luenberger_response=lresp,
        input_estimate=estimates["uio"],
        luenberger_input_estimate=estimates["lb"],
        d=run.d,
        v=run.v,
        curves=curves,
        limits=limits,
        poles=poles,
        luenberger_poles=lb.poles() if lb is not None else np.zeros(0, complex),
        observer_message=run.messages["uio"],
        luenberger_message=run.messages["lb"],
        messages=tuple(run.notes[: len(run.notes)] + notes),
        disturbance=run.description,
        movable_poles=movable,
        fixed_poles=fixed,
        excited=excited,
        initial_error=e0,
        guides=_guides(run, poles, movable, fixed, excited, e0),
        explanation=explain(scenario, s, movable, fixed, poles, excited, residual_zero),
        verdict=verdict,
        luenberger_verdict=lb_verdict,
        residual_zero=residual_zero,
    )
