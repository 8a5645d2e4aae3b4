"""The worked experiments: defined once, read by the figures, the explorers and the lab checks."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest
from tolerance import assert_rounding_close, assert_same_run

import uio_teach as ut
from uio_teach.experiments import Experiment
from uio_teach.explorers import scenario_of
from uio_teach.instructor import figures
from uio_teach.instructor.config import FigureConfig
from uio_teach.worked import WORKED, missile
from uio_teach.worked.case_study import CASE_STUDY
from uio_teach.worked.missile import MISSILE
from uio_teach.worked.pa9 import PA9

EXPERIMENTS = {"pa9": PA9, "case-study": CASE_STUDY, "missile": MISSILE}


@pytest.mark.parametrize("name", sorted(EXPERIMENTS))
def test_experiments_are_frozen_and_read_only(name):
    exp = EXPERIMENTS[name]
    assert isinstance(exp, Experiment) and exp.name == name
    with pytest.raises(dataclasses.FrozenInstanceError):
        exp.initial_state = np.zeros(3)
    for arr in (exp.timepts, exp.initial_state):
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 42.0
    assert exp.initial_state.shape == (exp.plant().n,)


def test_the_course_numbers():
    assert PA9.initial_state.tolist() == [1.0, -1.0, 0.5] and PA9.poles == (-1.0, -2.0, -3.0)
    assert (PA9.duration, PA9.timepts.size) == (10.0, 2001)
    assert MISSILE.poles == (-100.0, -120.0)
    np.testing.assert_array_equal(MISSILE.initial_state, ut.examples.MISSILE_PUBLISHED.x0)
    assert CASE_STUDY.poles is None and CASE_STUDY.timepts.tolist() == list(range(41))


def test_pa9_the_uio_ignores_both_disturbances():
    """The defining property, on the experiment: the same error whatever d."""
    obs = ut.design_uio(PA9.plant(), poles=PA9.poles)
    runs = [PA9.simulate(obs, d=d) for d in PA9.unknown_inputs.values()]
    quiet = PA9.simulate(obs, d=None)
    for run in runs:
        assert np.abs(run.inputs.d).max() > 0.5
        assert_same_run(run.error, quiet.error, run, quiet)
    assert np.abs(quiet.error[:, 0]).max() > 0.5  # the error starts away from zero


def test_case_study_v_is_a_seeded_staircase():
    v = CASE_STUDY.measurement_disturbance()
    k = CASE_STUDY.timepts
    values = v(k)
    held = values.reshape(-1)[:40].reshape(8, 5)
    assert np.all(held == held[:, :1]) and len(set(held[:, 0])) == 8
    assert np.abs(values).max() <= CASE_STUDY.v_amplitude
    np.testing.assert_array_equal(values, CASE_STUDY.measurement_disturbance()(k))
    assert not np.array_equal(values, CASE_STUDY.measurement_disturbance(seed=5)(k))


def test_missile_observer_starts_at_zero_estimate():
    plant = MISSILE.plant()
    pmo = ut.design_pmo(plant, poles=MISSILE.poles)
    resp = MISSILE.simulate(pmo, timepts=MISSILE.grid(samples=101))
    assert_same_run(resp.estimates[:, 0], 0.0, resp)  # zero to rounding
    assert_same_run(resp.error[:, 0], MISSILE.initial_state, resp)
    np.testing.assert_allclose(resp.inputs.d, np.vstack(MISSILE.v(resp.time)))


def test_grid_keeps_the_start_and_refines():
    assert PA9.grid() is PA9.timepts
    np.testing.assert_array_equal(PA9.grid(samples=1001), PA9.timepts[::2])
    np.testing.assert_array_equal(MISSILE.grid(samples=6001, duration=0.3)[-1], 0.3)


def test_simulate_overrides_any_keyword():
    obs = ut.design_uio(PA9.plant(), poles=PA9.poles)
    resp = PA9.simulate(obs, initial_state=[0.0, 0.0, 0.0], d=None)
    assert_same_run(resp.error, 0.0, resp)  # driven by u alone from rest: zero to rounding


# one place: the figures, explorers and checks read these values --------------------------------


@pytest.mark.subprocess
def test_changing_an_experiment_changes_the_figures_explorers_and_checks():
    """One place: a new PA9 initial state reaches the figures, the explorer and a check."""
    code = """
import dataclasses
import numpy as np
import uio_teach as ut
from uio_teach.worked import pa9
from uio_teach.worked import discover
# as an edit of the one line `PA9 = PA9Experiment(...)` would: the run, and the entry naming it
pa9.PA9 = dataclasses.replace(pa9.PA9, initial_state=[2.0, 0.0, -1.0])
pa9.EXAMPLES = (dataclasses.replace(pa9.EXAMPLES[0], experiment=pa9.PA9),)
discover()
from uio_teach.explorers import scenario_of
from uio_teach.instructor.config import FigureConfig
from uio_teach.instructor.figures import _Runs
assert scenario_of("pa9").initial_state.tolist() == [2.0, 0.0, -1.0]
cfg = FigureConfig()
assert cfg["pa9.initial_state"] == (2.0, 0.0, -1.0)
assert pa9._runs(_Runs(cfg))["uio_sine"].states[:, 0].tolist() == [2.0, 0.0, -1.0]
plant = pa9.PA9.plant()
obs = ut.design_uio(plant, poles=pa9.PA9.poles)
resp = ut.simulate(plant, obs, pa9.PA9.timepts, d=pa9.PA9.d_sine)
message = " ".join(ut.checks.pa9_simulation(resp).failures)
assert "initial state" in message, message
x0 = pa9.PA9.initial_state
resp = ut.simulate(plant, obs, pa9.PA9.timepts, d=pa9.PA9.d_sine, initial_state=x0)
assert ut.checks.pa9_simulation(resp, initial_state=x0).passed
"""
    subprocess.run([sys.executable, "-c", code], check=True)


def test_figure_defaults_are_the_experiments():
    cfg = FigureConfig()
    assert cfg["pa9.initial_state"] == tuple(PA9.initial_state)
    assert [complex(p) for p in cfg["pa9.poles"]] == [complex(p) for p in PA9.poles]
    assert cfg["pa9.samples"] == PA9.timepts.size and cfg["pa9.duration"] == PA9.duration
    assert cfg["pa9.sine.amplitude"] == PA9.sine_amplitude
    assert cfg["pa9.piecewise.times"] == PA9.switch_times
    assert cfg["case_study.initial_state"] == tuple(CASE_STUDY.initial_state)
    assert cfg["case_study.steps"] + 1 == CASE_STUDY.timepts.size
    assert cfg["seed"] == CASE_STUDY.seed
    assert [complex(p) for p in cfg["missile.pmo_poles"]] == [complex(p) for p in MISSILE.poles]
    resp = missile._runs(figures._Runs(cfg))["pmo"]["response"]
    assert_same_run(resp.estimates[:, 0], 0.0, resp)


def test_scenarios_read_the_experiments():
    pa9, case, missile = scenario_of("pa9"), scenario_of("case_study"), scenario_of("missile")
    np.testing.assert_array_equal(pa9.initial_state, PA9.initial_state)
    assert pa9.defaults.poles == PA9.poles
    assert (pa9.defaults.amplitude, pa9.defaults.frequency) == (1.0, 2.0)
    np.testing.assert_array_equal(case.initial_state, CASE_STUDY.initial_state)
    np.testing.assert_array_equal(case.timepts, CASE_STUDY.timepts)
    np.testing.assert_array_equal(missile.initial_state, MISSILE.initial_state)
    assert missile.defaults.poles == MISSILE.poles
    # the explorer's default disturbance is the paper's v1, v2
    from uio_teach.explorers import disturbance_signals

    d, _ = disturbance_signals(missile, missile.defaults)
    t = missile.timepts
    assert_rounding_close(np.vstack([f(t) for f in d]), MISSILE.v(t), terms=4)  # a few operations


# the plant of a lab, from its PARAMS ------------------------------------------------------------


@pytest.mark.parametrize("lab", [name for name, entry in WORKED.items() if entry.lab])
def test_plant_from_params_is_the_course_plant_by_default(lab):
    from uio_teach.experiments import plant_from_params

    course = WORKED[lab].plant  # the factory of uio_teach.examples the entry imports
    assert plant_from_params(lab) == course()
    assert plant_from_params(lab, {"poles": [-1.0]}) == course()
    assert plant_from_params(lab, {"plant": {}}) == course()


def test_plant_from_params_puts_the_given_matrices_in_place():
    from uio_teach.experiments import plant_from_params

    course = ut.examples.dt_case_study()
    A = [[0.4, 0.1, 0.0], [0.0, 0.5, 0.0], [0.0, 0.2, 0.3]]
    plant = plant_from_params("case_study", {"plant": {"A": A, "D": [[2.0], [0.5]]}})
    np.testing.assert_array_equal(plant.A, A)
    np.testing.assert_array_equal(plant.D, [[2.0], [0.5]])
    np.testing.assert_array_equal(plant.C, course.C)
    np.testing.assert_array_equal(plant.E, course.E)
    assert plant.dt == course.dt and plant.name == course.name


@pytest.mark.parametrize(
    "lab, params, match",
    [
        ("pa10", None, r"unknown lab 'pa10': expected one of pa9, case_study, missile"),
        ("pa9", [1, 2], r"must be a mapping"),
        ("pa9", {"plant": [[1.0]]}, r'PARAMS\["plant"\] of the pa9 lab must map matrix names'),
        ("pa9", {"plant": {"F": [[1.0]]}}, r"unknown matrix 'F'; expected some of A, B, C, D, E"),
        (
            "pa9",
            {"plant": {"E": [[1.0, 0.0]]}},
            r'\["E"\] of the pa9 lab has shape \(1, 2\), '
            r"expected \(3, 1\)",
        ),
        ("missile", {"plant": {"C": [[1, 0, 0, float("inf")], [0, 1, 0, 0]]}}, r"non-finite"),
        ("missile", {"plant": {"A": "A"}}, r'PARAMS\["plant"\]\["A"\] must be a real numeric'),
    ],
)
def test_plant_from_params_refuses_bad_input_clearly(lab, params, match):
    from uio_teach.experiments import plant_from_params

    with pytest.raises(ValueError, match=match):
        plant_from_params(lab, params)


def _bounded_fields():
    from uio_teach.experiments import EXPERIMENTS as ALL
    from uio_teach.experiments import experiment_params

    for section, exp in sorted(ALL.items()):
        for name, spec in experiment_params(exp):
            init = {f.name: f.init for f in dataclasses.fields(exp)}[name]
            if (
                init
                and spec.kind in ("int", "float")
                and (spec.maximum is not None or spec.minimum is not None or spec.positive)
            ):
                yield pytest.param(exp, name, spec, id=f"{section}.{name}")


@pytest.mark.parametrize(("exp", "name", "spec"), list(_bounded_fields()))
def test_a_field_beyond_its_declared_bounds_is_refused_however_the_run_is_made(exp, name, spec):
    """The term config checks the declared bounds; a run made in code must not slip past them."""
    from uio_teach.experiments import out_of_bounds

    if spec.maximum is not None:
        beyond = spec.maximum + max(1.0, abs(spec.maximum)) * 0.5
    else:
        beyond = (spec.minimum if spec.minimum is not None else 0.0) - 1.0
    if spec.kind == "int":
        beyond = int(np.ceil(beyond)) if spec.maximum is not None else int(np.floor(beyond))
    assert out_of_bounds(spec, beyond) is not None
    with pytest.raises(ValueError, match=rf"{name} .* must be"):
        exp.with_values(**{name: beyond})


def test_bounds_are_written_in_full():
    from uio_teach.experiments import Param, out_of_bounds

    seed = Param("int", "the seed", minimum=0, maximum=2**32 - 1)
    assert out_of_bounds(seed, 2**32) == "must be <= 4294967295, got 4294967296"
    valve = Param("float", "a valve", minimum=0.0, maximum=0.99)
    assert out_of_bounds(valve, 0.995) == "must be <= 0.99, got 0.995"
    assert out_of_bounds(valve, 0.99) is None and out_of_bounds(valve, 0.0) is None
