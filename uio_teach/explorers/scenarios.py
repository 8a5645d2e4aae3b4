"""The explorers' scenarios: the course's three worked experiments, and any plant.

:func:`pa9_scenario`, :func:`case_study_scenario` and :func:`missile_scenario`
read their plant, time window, inputs, initial state and starting poles from
:mod:`uio_teach.experiments`; :func:`make_scenario` chooses sensible values for
any plant.

Examples
--------
>>> from uio_teach.explorers import missile_scenario
>>> s = missile_scenario()
>>> s.family, s.defaults.poles
('pmo', (-100.0, -120.0))
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..existence import check_existence
from ..experiments import CASE_STUDY, MISSILE, PA9, experiment_params
from ..linalg import is_stable, rank
from ..plant import Plant
from ..worked import WORKED, resolve
from .model import (
    FAMILIES,
    Channel,
    PlantControl,
    Scenario,
    Settings,
    default_poles,
    default_timepts,
    expand_poles,
)

__all__ = [
    "pa9_scenario",
    "case_study_scenario",
    "missile_scenario",
    "make_scenario",
    "plant_controls",
    "scenario_of",
    "experiment_scenario",
]


def scenario_of(name: str, **plant_values: float) -> Scenario:
    """The explorer's scenario of a worked example of :data:`uio_teach.worked.WORKED`.

    Parameters
    ----------
    name : str
        The worked example (``"pa9"``, ``"quadruple_tank"``, ...).
    **plant_values
        Physical parameters of its plant (its explorer's plant sliders).

    Returns
    -------
    Scenario

    Examples
    --------
    >>> from uio_teach.explorers.scenarios import scenario_of
    >>> scenario_of("quadruple_tank", gamma1=0.43, gamma2=0.34).existence.ok
    False
    """
    return WORKED[name].make_scenario(**plant_values)


def _range(experiment: Any, control: str) -> tuple[float, float]:
    """The range of an explorer control: the ``Param.range`` of the field that sets it."""
    for _, spec in experiment_params(experiment):
        if spec.control == control:
            return spec.range
    raise ValueError(f"{type(experiment).__name__} declares no field for the control {control!r}")


def plant_controls(experiment: Any) -> tuple[PlantControl, ...]:
    """The sliders of an experiment's physical parameters: its ``plant_fields`` with a range.

    Parameters
    ----------
    experiment : Experiment
        The worked experiment (its values are the sliders' values).

    Returns
    -------
    tuple of PlantControl

    Examples
    --------
    >>> from uio_teach.experiments import EXPERIMENTS
    >>> from uio_teach.explorers.scenarios import plant_controls
    >>> [(c.name, c.value) for c in plant_controls(EXPERIMENTS["quadruple_tank"])]
    [('gamma1', 0.7), ('gamma2', 0.6)]
    """
    specs = dict(experiment_params(experiment))
    return tuple(
        PlantControl(
            name=name,
            label=specs[name].key or name,
            doc=specs[name].help,
            limits=specs[name].range,
            value=float(getattr(experiment, name)),
        )
        for name in type(experiment).plant_fields
        if name in specs and specs[name].control == "plant"
    )


def _scenario(plant: Plant, family: str, **kwargs: Any) -> Scenario:
    if family not in FAMILIES:
        raise ValueError(f"observer_family must be one of {tuple(FAMILIES)}, got {family!r}")
    timepts = np.asarray(kwargs.pop("timepts"), dtype=float)
    timepts.setflags(write=False)
    x0 = np.asarray(kwargs.pop("initial_state"), dtype=float).ravel()
    x0.setflags(write=False)
    return Scenario(
        plant=plant,
        family=family,
        timepts=timepts,
        initial_state=x0,
        existence=check_existence(plant),
        **kwargs,
    )


def pa9_scenario() -> Scenario:
    """Practical Assignment 9: the decoupling UIO, three movable poles, ``d`` sinusoidal by default.

    The known input, initial state and starting poles are those of
    :data:`uio_teach.experiments.PA9` (``u = [1, 0.5 sin t]``,
    ``x(0) = [1, -1, 0.5]``, poles ``-1, -2, -3``), and so is the default
    disturbance, its sinusoid; the 10 s window is drawn on 1001 samples (half
    the experiment's resolution, for a quick redraw).

    Returns
    -------
    Scenario

    Examples
    --------
    >>> from uio_teach.explorers import pa9_scenario
    >>> s = pa9_scenario()
    >>> s.movable, s.defaults.poles
    (3, (-1.0, -2.0, -3.0))
    """
    return _scenario(
        PA9.plant(),
        "uio",
        name="pa9",
        title="PA9",
        timepts=PA9.grid(samples=1001),
        initial_state=PA9.initial_state,
        u=PA9.inputs,
        defaults=Settings(
            poles=PA9.poles,
            disturbance="sinusoid",
            amplitude=PA9.sine_amplitude,
            frequency=PA9.sine_frequency,
            period=2.5,
        ),
        pole_limits=(-10.0, 1.0),
        frequency_limits=(0.0, 10.0),
        amplitude_limits=_range(PA9, "amplitude"),
        disturbance_frequency_limits=_range(PA9, "frequency"),
        period_limits=(0.25, 5.0),
        noise_limits=_range(PA9, "noise"),
        tau_limits=None,
        decay_limits=None,
        d_channels=(Channel(),),
        v_channels=(),
        static_values=(-8.0, -4.0, -2.0, -1.0, -0.5, -0.2, 0.2, 0.5),
        static_control="pole",
    )


def case_study_scenario() -> Scenario:
    """The discrete-time case study: projection-operator observer, one movable pole or the LMI.

    Two fixed poles at 0.5 (the invariant zeros); ``d`` and ``v`` of the
    chosen type (``v`` at half the amplitude and twice the frequency). The
    steps ``k = 0 ... 40``, the initial state ``[1, -2, 3]`` and the default
    ``d``, the experiment's ``u2``, come from
    :data:`uio_teach.experiments.CASE_STUDY`. The alternative
    mode designs the gain from the LMI with a radius bound
    (``Settings(mode="lmi", decay=...)``).

    Returns
    -------
    Scenario

    Examples
    --------
    >>> from uio_teach.explorers import case_study_scenario
    >>> s = case_study_scenario()
    >>> s.movable, s.fixed_poles.real.round(6).tolist(), s.decay_limits
    (1, [0.5, 0.5], (0.3, 1.0))
    """
    return _scenario(
        CASE_STUDY.plant(),
        "pmo",
        name="case-study",
        title="Case study",
        timepts=CASE_STUDY.timepts,
        initial_state=CASE_STUDY.initial_state,
        u=None,
        defaults=Settings(
            poles=(0.0,),
            decay=0.9,
            disturbance="sinusoid",
            amplitude=CASE_STUDY.u2_amplitude,
            frequency=CASE_STUDY.u2_frequency,
            period=5.0,
        ),
        pole_limits=(-1.1, 1.1),
        frequency_limits=(0.0, 180.0),
        amplitude_limits=_range(CASE_STUDY, "amplitude"),
        disturbance_frequency_limits=_range(CASE_STUDY, "frequency"),
        period_limits=(1.0, 20.0),
        noise_limits=(0.0, 0.5),
        tau_limits=None,
        decay_limits=(0.3, 1.0),
        d_channels=(Channel(),),
        v_channels=(Channel(gain=0.5, speed=2.0),),
        static_values=(-0.9, -0.5, 0.0, 0.3, 0.5, 0.7, 0.9, 0.97, 1.05),
        static_control="pole",
    )


def missile_scenario() -> Scenario:
    """The missile autopilot: PMO with two movable poles, the unknown inputs reconstructed.

    The default disturbance is the paper's pair of damped sinusoids
    ``v1 = 10 exp(-2t) cos(10t)``, ``v2 = 50 exp(-5t) sin(100t)``, with the
    paper's initial state and the PMO poles ``-100, -120``, all from
    :data:`uio_teach.experiments.MISSILE` (the observers start at ``z(0) = 0``
    here); 0.5 s on 1001 samples. The unknown
    inputs are reconstructed from each observer's estimate with
    :func:`uio_teach.reconstruct_input` (filtered, ``tau`` = 2 ms).

    Returns
    -------
    Scenario

    Examples
    --------
    >>> from uio_teach.explorers import missile_scenario
    >>> s = missile_scenario()
    >>> s.defaults.poles, s.defaults.tau
    ((-100.0, -120.0), 0.002)
    """
    # the controls' amplitude and frequency are v1's; each channel is a multiple of them
    amplitude, _, frequency, _ = MISSILE.v_parameters[0]
    return _scenario(
        MISSILE.plant(),
        "pmo",
        name="missile",
        title="Missile autopilot",
        timepts=MISSILE.grid(samples=1001),
        initial_state=MISSILE.initial_state,
        u=None,
        defaults=Settings(
            poles=MISSILE.poles,
            disturbance="damped sinusoid",
            amplitude=amplitude,
            frequency=frequency,
            period=0.05,
            tau=0.002,
        ),
        pole_limits=(-400.0, 40.0),
        frequency_limits=(0.0, 300.0),
        amplitude_limits=(0.0, 50.0),
        disturbance_frequency_limits=(1.0, 200.0),
        period_limits=(0.01, 0.25),
        noise_limits=(0.0, 0.5),
        tau_limits=(0.0, 0.05),
        decay_limits=None,
        d_channels=tuple(
            Channel(gain=a / amplitude, speed=w / frequency, decay=rate / w, kind=kind)
            for a, rate, w, kind in MISSILE.v_parameters
        ),
        v_channels=(),
        static_values=(-400.0, -200.0, -100.0, -50.0, -20.0, -5.0, 5.0, 20.0),
        static_control="pole",
        input_symbol="v",
    )


def make_scenario(
    plant: Plant,
    observer_family: str = "uio",
    *,
    poles: Sequence[complex] | None = None,
    timepts: Any = None,
    initial_state: Any = None,
    u: Callable | None = None,
    reconstruct: bool = False,
    name: str = "plant",
    title: str | None = None,
) -> Scenario:
    """A scenario for any plant: sensible default poles, time window and control ranges.

    Continuous time: the default movable poles are ``-s, -1.5 s, -2 s, ...``
    with ``s`` the largest of 1, the plant's fastest mode and the fixed
    poles' moduli; the window lasts 8 time constants of the slowest observer
    pole (1001 samples). Discrete time: poles ``0.5, 0.4, 0.3, ...`` and
    enough steps for the slowest pole to decay to 0.1 %. The disturbance
    starts as a sinusoid with three periods in the window.

    Parameters
    ----------
    plant : Plant
        Any plant of the package.
    observer_family : {"uio", "pmo", "ginverse"}
        The unknown input observer to explore.
    poles : sequence of complex, optional
        The movable poles to start from (one entry per complex pair).
    timepts : array_like, optional
        The simulation grid (for a discrete plant, one point per step).
    initial_state : array_like, optional
        The plant's initial state; all ones by default.
    u : callable, optional
        The known input (a signal of :mod:`uio_teach.signals`); zero by
        default.
    reconstruct : bool
        Also reconstruct the unknown input (needs ``E`` of full column rank).
    name : str
        A short identifier.
    title : str, optional
        The figure title; the plant's name by default.

    Returns
    -------
    Scenario

    Raises
    ------
    ValueError
        ``plant`` is not a :class:`~uio_teach.Plant`, or an unknown family.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.explorers import make_scenario
    >>> s = make_scenario(ut.examples.pa9(), "pmo")
    >>> s.defaults.poles, round(float(s.timepts[-1]), 3)
    ((-2.0, -3.0, -4.0), 4.0)
    """
    if not isinstance(plant, Plant):
        raise ValueError(f"plant must be a uio_teach.Plant, got {type(plant).__name__}")
    if observer_family not in FAMILIES:
        raise ValueError(
            f"observer_family must be one of {tuple(FAMILIES)}, got {observer_family!r}"
        )
    report = check_existence(plant)
    discrete = plant.is_discrete
    k = 0 if observer_family == "ginverse" else report.movable
    fixed = report.fixed_modes
    if poles is None:
        eig = np.abs(np.linalg.eigvals(plant.A)) if plant.n else np.zeros(0)
        s = max([1.0, *eig.tolist(), *np.abs(fixed).tolist()])
        poles = default_poles(k, discrete, s, avoid=[*report.invariant_zeros, *fixed])
    poles = tuple(complex(p) if complex(p).imag else float(complex(p).real) for p in poles)
    every = np.concatenate([expand_poles(poles), fixed])
    stable = every[is_stable(every, discrete)] if every.size else every
    default_t = default_timepts(stable, discrete, plant.dt)
    if discrete:
        lim: tuple[float, float] = (-1.1, 1.1)
    else:
        scale = max(abs(p) for p in [1.0, *expand_poles(poles).tolist(), *fixed.tolist()])
        lim = (-4.0 * scale, 0.4 * scale)
    t = np.asarray(default_t if timepts is None else timepts, dtype=float)
    span = float(t[-1] - t[0]) if t.size > 1 else 1.0
    step = float(t[1] - t[0]) if t.size > 1 else 1.0
    x0 = np.ones(plant.n) if initial_state is None else initial_state
    w = 2 * math.pi * 3 / span
    if reconstruct and (plant.q == 0 or rank(plant.E) < plant.q):
        raise ValueError("reconstruct=True needs unknown inputs with E of full column rank")
    real_first = bool(k and not complex(poles[0]).imag)
    if not real_first:
        static: tuple[float, ...] = (0.0, 0.5, 1.0, 2.0, 4.0)
    elif discrete:
        static = tuple(sorted({-0.9, -0.5, 0.0, 0.5, 0.9, 1.05, float(complex(poles[0]).real)}))
    else:
        static = tuple(float(complex(poles[0]).real) * f for f in (-0.5, 0.5, 1.0, 2.0, 4.0))
    return _scenario(
        plant,
        observer_family,
        name=name,
        title=title or plant.name or "plant",
        timepts=t,
        initial_state=x0,
        u=u,
        defaults=Settings(poles=poles, frequency=w, period=span / 6, decay=0.9, tau=0.0),
        pole_limits=lim,
        frequency_limits=(0.0, 180.0) if discrete else (0.0, -lim[0]),
        amplitude_limits=(0.0, 5.0),
        disturbance_frequency_limits=(w / 10, min(10 * w, math.pi / step)),
        period_limits=(max(step, span / 60), span / 2),
        noise_limits=(0.0, 0.5),
        tau_limits=(0.0, span / 20) if reconstruct else None,
        decay_limits=(0.3, 1.0) if observer_family == "pmo" and discrete else None,
        d_channels=tuple(Channel(speed=1.0 + 0.5 * i) for i in range(plant.q)),
        v_channels=tuple(Channel(gain=0.5, speed=2.0 + 0.5 * i) for i in range(plant.nv)),
        static_values=static,
        static_control="pole" if real_first else "amplitude",
    )


def experiment_scenario(name: str, **plant_values: float) -> Scenario:
    """The explorer of a worked example, made from its experiment and its registry entry.

    The plant, the time grid, the known input, the initial state, the starting
    poles, the disturbance's amplitude and frequency (and their ranges, from
    the fields declared with ``control="amplitude"`` / ``"frequency"``) come
    from the experiment; one slider per physical parameter
    (:func:`plant_controls`); the rest from the entry's ``explorer`` options:
    ``title``, ``samples``, ``period``, ``pole_limits``, ``frequency_limits``,
    ``period_limits``, ``noise_limits``, ``d_channels`` (``(gain, speed)`` per
    unknown input), ``static_control`` and ``static_values`` (the static
    book's slider: ``"pole"``, or ``"plant:<name>"`` for a physical
    parameter) and ``note`` (``"module:function"`` called with the physical
    parameters: a sentence on this plant).

    Parameters
    ----------
    name : str
        The worked example (a key of :data:`uio_teach.worked.WORKED`).
    **plant_values
        Physical parameters of its plant.

    Returns
    -------
    Scenario

    Examples
    --------
    >>> from uio_teach.explorers.scenarios import experiment_scenario
    >>> s = experiment_scenario("quadruple_tank", gamma1=0.43, gamma2=0.34)
    >>> s.existence.ok, [c.value for c in s.plant_controls]
    (False, [0.43, 0.34])
    """
    entry = WORKED[name]
    options = dict(entry.explorer)
    run = entry.run().with_values(**plant_values)
    plant = run.plant()
    values = {spec.control: getattr(run, f) for f, spec in experiment_params(run) if spec.control}
    note = options.pop("note", None)
    physical = {f: getattr(run, f) for f in type(run).plant_fields}
    channels = options.pop("d_channels", ((1.0, 1.0),) * plant.q)
    noise_limits = options.pop("noise_limits", (0.0, 0.5))
    return _scenario(
        plant,
        entry.family,
        name=name.replace("_", "-"),
        title=options.pop("title", entry.title),
        timepts=run.grid(samples=options.pop("samples", None)),
        initial_state=run.initial_state,
        u=run.inputs,
        defaults=Settings(
            poles=run.poles,
            disturbance="sinusoid",
            amplitude=values.get("amplitude", 1.0),
            frequency=values.get("frequency", 1.0),
            period=options.pop("period"),
            noise=values.get("noise", 0.0) or 0.0,
        ),
        amplitude_limits=_range(run, "amplitude"),
        disturbance_frequency_limits=_range(run, "frequency"),
        noise_limits=_range(run, "noise") if "noise" in values else noise_limits,
        tau_limits=None,
        decay_limits=None,
        d_channels=tuple(Channel(gain=g, speed=v) for g, v in channels),
        v_channels=(),
        static_control=options.pop("static_control", "pole"),
        plant_controls=plant_controls(run),
        rebuild=functools.partial(experiment_scenario, name),
        note=resolve(note)(**physical) if note else "",
        **options,
    )
