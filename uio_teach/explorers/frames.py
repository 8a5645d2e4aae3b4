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

From the default start (a zero estimate) the error reaches the movable modes, so
moving a pole changes the error:

>>> other = compute_frame(scenario, scenario.defaults.replace(poles=(-6.0, -3.0, -4.0)))
>>> bool(abs(frame.response.error - other.response.error).max() > 0.1)
True
"""

from __future__ import annotations

import warnings
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
    design_uio,
)
from ..reconstruction import InputEstimate, reconstruct_input
from ..simulation import UIOResponse, simulate
from ..verify import PlacementAccuracyWarning
from .model import STARTS, Scenario, Settings, _describe, disturbance_signals, expand_poles

__all__ = ["Frame", "compute_frame", "excited_modes", "error_grows"]


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
    movable_poles: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))
    fixed_poles: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))
    excited: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))
    initial_error: np.ndarray = field(default_factory=lambda: np.zeros(0))
    guides: dict[str, np.ndarray] = field(default_factory=dict)
    explanation: str = ""

    @property
    def all_messages(self) -> tuple[str, ...]:
        """Every message, observer first."""
        out = []
        if self.observer_message:
            out.append(f"{self.scenario.observer_name}: {self.observer_message}")
        if self.luenberger_message:
            out.append(f"Luenberger observer: {self.luenberger_message}")
        return (*out, *self.messages)


# the modes an initial error excites ------------------------------------------------------


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


def _match(poles: np.ndarray, found: np.ndarray) -> np.ndarray:
    """For each pole: is it among ``found`` (each found value used once, nearest first)?"""
    out = np.zeros(poles.size, bool)
    left = list(found)
    scale = max(1.0, float(np.abs(poles).max())) if poles.size else 1.0
    for i in np.argsort(np.abs(poles)):
        if not left:
            break
        gaps = [abs(poles[i] - f) for f in left]
        j = int(np.argmin(gaps))
        if gaps[j] <= 1e-4 * scale + 1e-3 * abs(poles[i]):
            out[i] = True
            left.pop(j)
    return out


def _remove(poles: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """The poles with one nearest entry removed for each fixed pole."""
    left = list(poles)
    for z in fixed:
        if not left:
            break
        left.pop(int(np.argmin([abs(p - z) for p in left])))
    return np.array(left, dtype=complex)


def error_grows(error: np.ndarray | None) -> bool:
    """Does the simulated error grow: is it larger at the end than at the start?

    The largest ``|e|`` over the last tenth of the window is compared with the
    largest over the first tenth: more than 1.5 times as large is growth; a
    non-finite error (it overflowed) is growth too.

    Parameters
    ----------
    error : numpy.ndarray or None
        The error, one row per channel.

    Returns
    -------
    bool

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers import error_grows
    >>> k = np.arange(41.0)
    >>> error_grows(np.array([1.05**k])), error_grows(np.array([0.9**k]))
    (True, False)
    """
    if error is None or not np.size(error):
        return False
    err = np.abs(np.asarray(error, dtype=float))
    if not np.all(np.isfinite(err)):
        return True
    N = err.shape[-1]
    part = max(1, N // 10)
    return bool(err[:, -part:].max() > 1.5 * err[:, :part].max() + 1e-300)


def _where(discrete: bool) -> tuple[str, str]:
    if discrete:
        return "outside the unit circle", "on the unit circle"
    return "in the right half-plane", "on the imaginary axis"


def _stability_message(
    name: str,
    poles: np.ndarray,
    excited: np.ndarray,
    grows: bool,
    discrete: bool,
) -> str:
    """What the observer's poles do to the error, in words that agree with the simulation."""
    if not poles.size:
        return ""
    bad = ~is_stable(poles, discrete)
    if not bad.any():
        return ""
    mag = np.abs(poles) - 1 if discrete else poles.real
    growing = bad & (mag > 1e-9 * np.maximum(1, np.abs(poles)))
    where, edge = _where(discrete)
    if growing.any():
        grow = poles[growing]
        listed = format_poles(grow, 3)
        word = "pole" if grow.size == 1 else "poles"
        if grows:
            this = "this pole makes" if grow.size == 1 else "these poles make"
            return f"{this} the {name} unstable: the error grows ({word} {listed} {where})"
        if not excited[growing].any():
            it = "it" if grow.size == 1 else "them"
            return (
                f"{word} {listed} {where}, but this start does not excite {it}: the error "
                "does not grow here (noise or another start would make it grow)"
            )
        return (
            f"{word} {listed} {where}: that mode grows, but slowly; within this window the "
            "error does not yet outgrow its start"
        )
    edge_poles = poles[bad]
    word = "pole" if edge_poles.size == 1 else "poles"
    if not excited[bad].any():
        return f"{word} {format_poles(edge_poles, 3)} {edge}, not excited from this start"
    return f"{word} {format_poles(edge_poles, 3)} {edge}: that part of the error does not decay"


def _lmi_message(scenario: Scenario, decay: float, exc: Exception) -> str:
    """An LMI that failed, in plain words (no solver status)."""
    discrete = scenario.discrete
    bound = f"radius {decay:.3g}" if discrete else f"decay rate {decay:.3g}"
    fixed = scenario.fixed_poles
    if isinstance(exc, LMIInfeasibleError):
        if fixed.size:
            worst = (
                f"radius {np.abs(fixed).max():.3g}"
                if discrete
                else f"decay rate {-fixed.real.max():.3g}"
            )
            return (
                f"no gain meets the bound {bound}: the fixed poles (invariant zeros, "
                f"{worst}) cannot move; choose a bound beyond them"
            )
        return f"no gain meets the bound {bound}"
    return (
        f"the LMI solver could not settle the bound {bound} numerically (this does not prove "
        "that no gain exists); try a slightly different bound"
    )


def _design(scenario: Scenario, s: Settings) -> tuple[Observer | None, str, list[str]]:
    """The unknown input observer, a message if it failed, and notes from its checks."""
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
                if key not in scenario._cache:
                    try:
                        scenario._cache[key] = design_pmo(plant, method="lmi", decay=s.decay)
                    except (LMIInfeasibleError, LMISolverError) as exc:
                        scenario._cache[key] = exc
                if isinstance(scenario._cache[key], Exception):
                    raise scenario._cache[key]
                obs = scenario._cache[key]
            else:
                poles = expand_poles(s.poles)
                design = design_uio if scenario.family == "uio" else design_pmo
                obs = design(plant, poles=poles)
    except (LMIInfeasibleError, LMISolverError) as exc:
        return None, _lmi_message(scenario, float(s.decay), exc), notes
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


def _zero_notes(scenario: Scenario, movable: np.ndarray) -> list[str]:
    """A note for each movable pole placed on (or next to) an invariant zero."""
    zeros = scenario.invariant_zeros
    out: list[str] = []
    seen: set[str] = set()
    for p in movable:
        if not zeros.size:
            break
        gaps = np.abs(zeros - p)
        j = int(np.argmin(gaps))
        z = zeros[j]
        if gaps[j] > 0.02 * max(1.0, abs(z)):
            continue
        text = (
            f"pole {format_poles([p], 3)} sits on the invariant zero {format_poles([z], 3)}, "
            "where a fixed pole already is: the error there decays no faster than that fixed "
            "mode, and a repeated pole is sensitive to small model errors"
        )
        if gaps[j] > 1e-9 * max(1.0, abs(z)):
            text = text.replace("sits on", "is next to")
        if text not in seen:
            seen.add(text)
            out.append(text)
    return out


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


def _rate(p: complex, discrete: bool, t: np.ndarray) -> np.ndarray:
    """``|p|^k`` (discrete, k counted in steps from t[0]) or ``exp(Re p t)``."""
    tt = t - t[0]
    with np.errstate(all="ignore"):
        if discrete:
            step = tt[1] if tt.size > 1 else 1.0
            return np.abs(p) ** np.round(tt / step)
        return np.exp(p.real * tt)


def _slowest(poles: np.ndarray, discrete: bool) -> complex | None:
    if not poles.size:
        return None
    key = np.abs(poles) if discrete else poles.real
    return complex(poles[int(np.argmax(key))])


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


def _explain(scenario: Scenario, s: Settings, movable, fixed, poles, excited) -> str:
    """Which poles the controls move, which stay fixed, which modes the start excites."""
    name = scenario.observer_name
    parts = []
    if scenario.family == "ginverse":
        parts.append(f"The {name} has no gain to tune: its poles are set by its structure.")
    elif movable.size:
        what = "The LMI bound picks" if s.mode == "lmi" else "The pole controls move"
        parts.append(f"{what} the {name} poles {format_poles(movable, 3)}.")
    else:
        parts.append(f"No pole of the {name} can be moved.")
    if fixed.size:
        parts.append(
            f"Fixed whatever the gain: {format_poles(fixed, 3)} (the invariant zeros, o on "
            "the pole map)."
        )
    if scenario.reconstruct:
        parts.append(
            "The input panels are zoomed on the true input (grey): larger swings of a "
            "reconstruction run off the panel."
        )
    if poles.size and excited.size == poles.size:
        start = STARTS.get(s.start, s.start)
        quiet = poles[~excited]
        quiet = quiet[_match(quiet, movable)] if quiet.size and movable.size else quiet[:0]
        if not quiet.size:
            parts.append(f"Start: {start}; the error has a part in every movable mode.")
        else:
            parts.append(
                f"Start: {start}; the error has no part in the movable modes "
                f"{format_poles(quiet, 3)}, so moving them changes nothing here."
            )
    return " ".join(parts)


def _compute(scenario: Scenario, s: Settings) -> Frame:
    plant = scenario.plant
    t = scenario.timepts
    N = t.size
    discrete = scenario.discrete
    notes: list[str] = []

    # the unknown signals
    d = np.zeros((plant.q, N))
    v = np.zeros((plant.nv, N))
    description = ""
    try:
        d_sig, v_sig = disturbance_signals(scenario, s)
        if d_sig:
            d = np.vstack([f(t) for f in d_sig])
        if v_sig:
            v = np.vstack([f(t) for f in v_sig])
        description = _describe(s.disturbance, s, discrete)
    except (ValueError, TypeError) as exc:
        notes.append(f"disturbance: {exc}; no disturbance applied")
    noise = s.noise
    if not isinstance(noise, int | float | np.number) or not np.isfinite(noise) or noise < 0:
        notes.append(f"the noise level must be a number >= 0, got {noise!r}; no noise applied")
        noise = 0.0
    start = s.start
    if start not in STARTS:
        notes.append(f"unknown start {start!r}; the observers start from a zero estimate")
        start = "zero estimate"
    kwargs: dict[str, Any] = {
        "u": scenario.u,
        "d": d if plant.q else None,
        "v": v if plant.nv else None,
        "initial_state": scenario.initial_state,
        "noise": float(noise) if noise > 0 else None,
        "seed": s.seed,
    }

    obs, obs_msg, design_notes = _design(scenario, s)
    notes += design_notes
    lb, lb_msg = _luenberger(scenario, s, obs)

    x0 = np.asarray(scenario.initial_state, dtype=float)
    v0 = v[:, 0] if plant.nv else np.zeros(0)
    responses: dict[str, UIOResponse | None] = {"uio": None, "lb": None}
    starts: dict[str, np.ndarray] = {}
    for key, o in (("uio", obs), ("lb", lb)):
        if o is None:
            continue
        try:
            w0, starts[key] = _observer_start(o, plant, x0, v0, start)
            with np.errstate(all="ignore"):
                responses[key] = simulate(plant, o, t, observer_state=w0, **kwargs)
        except Exception as exc:
            text = f"the simulation failed: {exc}"
            if key == "uio":
                obs_msg = text
            else:
                lb_msg = text

    # poles: movable and fixed, excited by the start, stable or not (as simulated)
    poles = obs.poles() if obs is not None else np.zeros(0, complex)
    fixed = np.asarray(scenario.fixed_poles, dtype=complex)
    if obs is None or scenario.family == "ginverse":
        movable = np.zeros(0, complex)
    else:
        movable = _remove(poles, fixed)
    excited = np.zeros(poles.size, bool)
    e0 = starts.get("uio", np.zeros(0))
    if obs is not None and "uio" in starts:
        excited = _match(poles, excited_modes(obs.error_matrix, e0))
        scale = max(1.0, float(np.abs(poles).max()))
        for i in range(poles.size):  # a repeated pole: one excited copy excites that value
            excited[i] |= bool(np.any(excited & (np.abs(poles - poles[i]) <= 1e-6 * scale)))
        if kwargs["noise"]:
            excited[:] = True  # noise reaches every mode
    resp = responses["uio"]
    if obs is not None and resp is not None and not obs_msg:
        obs_msg = _stability_message(
            scenario.observer_name, poles, excited, error_grows(resp.error), discrete
        )
    lresp = responses["lb"]
    if lb is not None and lresp is not None and not lb_msg:
        lb_msg = _stability_message(
            "Luenberger observer",
            lb.poles(),
            np.ones(lb.poles().size, bool),
            error_grows(lresp.error),
            discrete,
        )
    if s.mode != "lmi" and scenario.family != "ginverse":
        try:
            notes += _zero_notes(scenario, expand_poles(s.poles))
        except (TypeError, ValueError):
            pass

    estimates: dict[str, InputEstimate | None] = {"uio": None, "lb": None}
    if scenario.reconstruct:
        tau = s.tau
        if not isinstance(tau, int | float | np.number) or not np.isfinite(tau) or tau < 0:
            notes.append(f"tau must be a time constant >= 0, got {tau!r}; no filter used")
            tau = 0.0
        for key, r in responses.items():
            if r is None:
                continue
            try:
                with np.errstate(all="ignore"):
                    estimates[key] = (
                        reconstruct_input(plant, r, method="filtered", tau=float(tau))
                        if tau > 0
                        else reconstruct_input(plant, r)
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
    clipped: dict[str, set[str]] = {}
    for key, r in responses.items():
        est = estimates[key]
        parts = {
            "error": None if r is None else r.error,
            "residual": None if r is None else r.residual,
        }
        if scenario.reconstruct:
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
    for key, whats in clipped.items():
        whats.discard("input")  # the input panels are zoomed on the true input anyway
        if not whats:
            continue
        who = scenario.observer_name if key == "uio" else "Luenberger observer"
        which = " and ".join(sorted(whats))
        verb = "leaves" if len(whats) == 1 else "leave"
        notes.append(
            f"{who}: the {which} {verb} the plotted range (ten times the plant's own "
            "signals) and are cut off there".replace(
                "and are", "and is" if len(whats) == 1 else "and are"
            )
        )

    # guides over |e|: the rates the poles set, or the LMI's certified envelope
    guides: dict[str, np.ndarray] = {}
    size0 = float(np.linalg.norm(e0)) if e0.size else 0.0
    if obs is not None and size0 > 0:
        P = getattr(obs, "lmi_certificate", None) if s.mode == "lmi" else None
        if P is not None:
            ev = np.linalg.eigvalsh(0.5 * (P + P.T))
            gain = float(np.sqrt(ev.max() / ev.min()))
            rho = float(s.decay)
            rate = rho ** np.round((t - t[0]) / (t[1] - t[0])) if discrete else None
            if rate is None:
                rate = np.exp(-rho * (t - t[0]))
            guides[f"certified bound, {'radius' if discrete else 'rate'} {rho:.3g}"] = (
                gain * size0 * rate
            )
        slow_m = _slowest(movable[excited[_positions(poles, movable)]], discrete)
        if slow_m is not None and s.mode != "lmi":
            guides[f"rate of slowest moved pole {format_poles([slow_m], 3)}"] = size0 * _rate(
                slow_m, discrete, t
            )
        slow_f = _slowest(fixed[excited[_positions(poles, fixed)]], discrete)
        if slow_f is not None:
            guides[f"rate of slowest fixed pole {format_poles([slow_f], 3)}"] = size0 * _rate(
                slow_f, discrete, t
            )

    if resp is not None and not obs_msg and not kwargs["noise"]:
        err = np.abs(resp.error)
        top = float(np.max(err)) if err.size else 0.0
        tail = float(np.max(err[:, -max(1, N // 10) :])) if err.size else 0.0
        if top > 0 and tail > 0.05 * top:
            live = poles[excited]
            stable = live[is_stable(live, discrete)] if live.size else live
            slow = _slowest(stable, discrete)
            text = "the error has not settled by the end of the window"
            if slow is not None:
                factor = float(_rate(slow, discrete, t)[-1])
                kind = "fixed" if _match(np.array([slow]), fixed).any() else "movable"
                if factor > 0.05:
                    text += (
                        f": its slowest {kind} pole, {format_poles([slow], 3)}, shrinks it only "
                        f"to {100 * factor:.2g} % over the window"
                    )
            notes.append(text)
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
        poles=poles,
        luenberger_poles=lb.poles() if lb is not None else np.zeros(0, complex),
        observer_message=obs_msg,
        luenberger_message=lb_msg,
        messages=tuple(notes),
        disturbance=description,
        movable_poles=movable,
        fixed_poles=fixed,
        excited=excited,
        initial_error=e0,
        guides=guides,
        explanation=_explain(scenario, s, movable, fixed, poles, excited),
    )


def _positions(poles: np.ndarray, subset: np.ndarray) -> np.ndarray:
    """For each entry of ``subset``, the index of a distinct nearest entry of ``poles``."""
    left = list(range(poles.size))
    out = []
    for z in subset:
        if not left:
            break
        j = min(left, key=lambda i: abs(poles[i] - z))
        out.append(j)
        left.remove(j)
    return np.array(out, dtype=int)
