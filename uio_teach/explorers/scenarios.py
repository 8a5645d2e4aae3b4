"""The explorers' scenarios: every worked example's, and any plant's.

:func:`scenario_of` makes the explorer of a worked example of
:data:`uio_teach.worked.WORKED` from its experiment and its explorer options
(:func:`experiment_scenario`); :func:`make_scenario` chooses sensible values
for any plant.

Examples
--------
>>> from uio_teach.explorers import scenario_of
>>> s = scenario_of("missile")
>>> s.family, s.defaults.poles
('pmo', (-100.0, -120.0))
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..errors import InputError
from ..existence import check_existence
from ..experiments import experiment_params
from ..linalg import is_stable, rank
from ..observers.reduced import reduced_movable
from ..plant import Plant
from ..worked import WORKED, RegistryError
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

    Raises
    ------
    uio_teach.worked.RegistryError
        An unknown worked example (the message lists the known ones), or a
        value for a field its experiment does not have.

    Examples
    --------
    >>> from uio_teach.explorers.scenarios import scenario_of
    >>> scenario_of("quadruple_tank", gamma1=0.43, gamma2=0.34).existence.ok
    False
    """
    _entry(name)
    return experiment_scenario(name, **plant_values)


def _entry(name: str):
    """The registry entry of a worked example, or a RegistryError naming the known ones."""
    if name not in WORKED:
        raise RegistryError(
            f"no worked example {name!r}; the worked examples are {', '.join(WORKED)}"
        )
    return WORKED[name]


def _range(experiment: Any, control: str) -> tuple[float, float]:
    """The range of an explorer control: the ``Param.range`` of the field that sets it."""
    for _, spec in experiment_params(experiment):
        if spec.control == control:
            return spec.range
    raise InputError(f"{type(experiment).__name__} declares no field for the control {control!r}")


def plant_controls(experiment: Any) -> tuple[PlantControl, ...]:
    """The sliders of an experiment's own fields: each declared field with a range and no control.

    A field declared with a ``range`` and no ``control`` (none of the
    explorer's own amplitude, frequency and noise controls) gets a slider of
    its own, whatever it is: a physical parameter of the plant (a field of
    ``plant_fields``), a time, a gain. Moving it remakes the scenario with the
    field's new value (``Scenario.rebuild``).

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
        for name, spec in specs.items()
        if spec.range is not None and not spec.control
    )


def _scenario(plant: Plant, family: str, **kwargs: Any) -> Scenario:
    if family not in FAMILIES:
        raise InputError(f"observer_family must be one of {tuple(FAMILIES)}, got {family!r}")
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
    pole (1001 samples; shorter when a lightly damped pair would otherwise get
    too few samples a period). Discrete time: poles ``0.5, 0.4, 0.3, ...`` and
    enough steps (30 to 300) for the slowest pole to shrink the error a
    thousandfold. A candidate pole next to a fixed pole is skipped (the case
    study starts at 0.4, beside its fixed poles at 0.5); see
    ``uio_teach.explorers.model.default_poles`` and
    ``default_timepts``. The disturbance
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
    >>> make_scenario(ut.examples.dt_case_study(), "pmo").defaults.poles
    (0.4,)
    """
    if not isinstance(plant, Plant):
        raise InputError(f"plant must be a uio_teach.Plant, got {type(plant).__name__}")
    if observer_family not in FAMILIES:
        raise InputError(
            f"observer_family must be one of {tuple(FAMILIES)}, got {observer_family!r}"
        )
    report = check_existence(plant)
    discrete = plant.is_discrete
    k = 0 if observer_family == "ginverse" else report.movable
    if observer_family == "reduced":
        k = reduced_movable(plant, report)
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
        raise InputError("reconstruct=True needs unknown inputs with E of full column rank")
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


def _channels(given: tuple[tuple[Any, ...], ...]) -> tuple[Channel, ...]:
    return tuple(Channel(*c) for c in given)


def experiment_scenario(name: str, **values: Any) -> Scenario:
    """The explorer of a worked example, made from its experiment and its explorer options.

    The plant, the time grid, the known input, the initial state, the starting
    poles, the disturbance's amplitude, frequency and noise (and their ranges,
    from the fields declared with ``control="amplitude"``, ``"frequency"`` or
    ``"noise"``) come from the experiment; a slider for each physical
    parameter (:func:`plant_controls`); the rest from the entry's
    :class:`~uio_teach.worked.ExplorerOptions`.

    Parameters
    ----------
    name : str
        The worked example (a key of :data:`uio_teach.worked.WORKED`).
    **values
        Fields of its experiment (the values of its sliders).

    Returns
    -------
    Scenario

    Raises
    ------
    uio_teach.worked.RegistryError
        An unknown worked example, a value for a field the experiment does not
        have, or an option that a declared field already sets (the range of a
        control given twice).

    Examples
    --------
    >>> from uio_teach.explorers.scenarios import experiment_scenario
    >>> s = experiment_scenario("quadruple_tank", gamma1=0.43, gamma2=0.34)
    >>> s.existence.ok, [c.value for c in s.plant_controls]
    (False, [0.43, 0.34])
    """
    entry = _entry(name)
    opts = entry.explorer
    run = entry.run()
    fields = {f for f, spec in experiment_params(run) if spec.range and not spec.control}
    unknown = sorted(set(values) - fields)
    if unknown:
        raise RegistryError(
            f"the {name} explorer has no slider {', '.join(map(repr, unknown))}; "
            f"its sliders: {', '.join(sorted(fields)) or 'none'}"
        )
    specs = dict(experiment_params(run))
    # a slider gives floats: an integer field takes its nearest integer
    values = {f: round(v) if specs[f].kind == "int" else v for f, v in values.items()}
    run = run.with_values(**values)
    plant = run.plant()
    declared = {spec.control: f for f, spec in experiment_params(run) if spec.control}
    limits = {
        "amplitude": opts.amplitude_limits,
        "frequency": opts.disturbance_frequency_limits,
        "noise": opts.noise_limits,
    }
    start = {"amplitude": opts.amplitude, "frequency": opts.frequency}
    for control, field_name in declared.items():
        option = {"frequency": "disturbance_frequency"}.get(control, control)
        if limits.get(control) is not None or start.get(control) is not None:
            raise RegistryError(
                f"the {name} explorer: the field {field_name!r} sets the {control} control "
                f"(its range and value); drop the options {option}_limits / {control}"
            )
    for control in ("amplitude", "frequency"):
        if control not in declared and (limits[control] is None or start[control] is None):
            option = {"frequency": "disturbance_frequency"}.get(control, control)
            raise RegistryError(
                f"the {name} explorer: no field declares the {control} control, so the options "
                f"{control!r} and '{option}_limits' are required"
            )

    if opts.poles is not None and run.poles is not None:
        raise RegistryError(
            f"the {name} explorer: its experiment sets the starting poles {run.poles}; "
            "drop the option poles (it is for an experiment without poles, an LMI gain)"
        )
    sliders = plant_controls(run)
    if opts.static_control.startswith("plant:"):
        wanted = opts.static_control.split(":", 1)[1]
        if wanted not in {c.name for c in sliders}:
            raise RegistryError(
                f"the {name} explorer: static_control {opts.static_control!r} names no slider; "
                f"its sliders: {', '.join(c.name for c in sliders) or 'none'}"
            )

    def value(control: str, default: float) -> float:
        given = getattr(run, declared[control]) if control in declared else start.get(control)
        return default if given is None else given

    physical = {f: getattr(run, f) for f in type(run).plant_fields}
    return _scenario(
        plant,
        entry.family,
        name=name.replace("_", "-"),
        title=opts.title or entry.title,
        timepts=run.grid(samples=opts.samples),
        initial_state=run.initial_state,
        u=run.inputs,
        defaults=Settings(
            poles=run.poles if opts.poles is None else opts.poles,
            decay=opts.decay,
            disturbance=opts.disturbance,
            amplitude=value("amplitude", 1.0),
            frequency=value("frequency", 1.0),
            period=opts.period,
            noise=value("noise", 0.0),
            tau=opts.tau,
        ),
        pole_limits=opts.pole_limits,
        frequency_limits=opts.frequency_limits,
        amplitude_limits=_range(run, "amplitude")
        if "amplitude" in declared
        else limits["amplitude"],
        disturbance_frequency_limits=(
            _range(run, "frequency") if "frequency" in declared else limits["frequency"]
        ),
        period_limits=opts.period_limits,
        noise_limits=(
            _range(run, "noise") if "noise" in declared else (limits["noise"] or (0.0, 0.5))
        ),
        tau_limits=opts.tau_limits,
        decay_limits=opts.decay_limits,
        d_channels=_channels(opts.d_channels) or (Channel(),) * plant.q,
        v_channels=_channels(opts.v_channels),
        static_values=opts.static_values,
        static_control=opts.static_control,
        input_symbol=opts.input_symbol,
        plant_controls=sliders,
        rebuild=functools.partial(experiment_scenario, name),
        note=opts.note(**physical) if opts.note else "",
    )
