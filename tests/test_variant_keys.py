"""Variants that vary: one group's right answers fail every other group's key, no draw is shared."""

from __future__ import annotations

import inspect
import itertools

import control as ct
import numpy as np
import pytest

import uio_teach as ut
from uio_teach import checks
from uio_teach.existence import decoupling
from uio_teach.instructor.lab_registry import LABS
from uio_teach.instructor.variants import draw_variants
from uio_teach.lab_params import MIN_INITIAL_ERROR
from uio_teach.lmi import lmi_gain

GROUPS = 4
SEED = 2027


@pytest.fixture(scope="module")
def variants():
    return {lab: draw_variants(LABS[lab], GROUPS, seed=SEED) for lab in LABS}


def pa9_solution(params):
    """What a right PA9 solution computes, with the package, from the group's PARAMS."""
    plant = ut.experiments.plant_from_params("pa9", params)
    A, C, E = plant.A, plant.C, plant.E
    H = E @ np.linalg.pinv(C @ E)
    T = np.eye(plant.n) - H @ C
    poles = [complex(p) for p in params["poles"]]
    K1 = ct.place((T @ A).T, C.T, poles).T
    F = T @ A - K1 @ C
    return {"H": H, "T": T, "K1": K1, "F": F, "K2": F @ H}


def case_study_solution(params):
    plant = ut.experiments.plant_from_params("case_study", params)
    dec = decoupling(plant)
    lmi = lmi_gain(dec.A1, plant.C, D=plant.D, dt=plant.dt)
    moved = ut.design_pmo(plant, poles=[params["pole"]])
    return {"M": dec.M, "A1": dec.A1, "L": lmi.L, "P": lmi.P, "Y": lmi.P @ lmi.L, "L_pole": moved.L}


def missile_solution(params):
    plant = ut.experiments.plant_from_params("missile", params)
    C, E = plant.C, plant.E
    Mv = ut.examples.MISSILE_PUBLISHED.Mv
    pmo = ut.design_pmo(plant, poles=[complex(p) for p in params["pmo_poles"]], Mv=Mv)
    Cg = np.linalg.pinv(C)
    Pc = np.eye(plant.n) - Cg @ C
    Kg = Pc @ E @ np.linalg.inv(C @ E)
    return {"M": pmo.M, "L": pmo.L, "F": pmo.F, "Cg": Cg, "Pc": Pc, "Kg": Kg}


def verdicts(lab, answer, params):
    """Every value-graded check of ``lab`` on ``answer``, against the key ``params``."""
    plant = ut.experiments.plant_from_params(lab, params)
    if lab == "pa9":
        a = answer
        return {
            "pa9.design": checks.pa9_design(
                a["H"], a["T"], a["K1"], a["F"], a["K2"], plant=plant, poles=params["poles"]
            ).passed
        }
    if lab == "case_study":
        return {
            "case_study.projection": checks.case_study_projection(answer["M"], plant).passed,
            "case_study.lmi": checks.case_study_lmi(
                answer["L"], answer["P"], plant, **traced(answer)
            ).passed,
            "case_study.pole": checks.case_study_pole(
                answer["L_pole"], params["pole"], plant
            ).passed,
        }
    return {
        "missile.pmo": checks.missile_pmo(
            answer["M"], answer["L"], answer["F"], poles=params["pmo_poles"], plant=plant
        ).passed,
        "missile.ginverse": checks.missile_ginverse(
            answer["Cg"], answer["Pc"], answer["Kg"], plant
        ).passed,
    }


def traced(answer):
    """The solver's ``Y`` for the LMI check, where the check traces ``L`` to it."""
    takes_y = "Y" in inspect.signature(checks.case_study_lmi).parameters
    return {"Y": answer["Y"]} if takes_y else {}


SOLVE = {"pa9": pa9_solution, "case_study": case_study_solution, "missile": missile_solution}


def cross_keys(lab, drawn):
    """Each group's solution against each group's key: (own keys passed, cross failures, total)."""
    params = [v.to_params() for v in drawn]
    answers = [SOLVE[lab](p) for p in params]
    own = failed = total = 0
    for i, j in itertools.product(range(len(drawn)), repeat=2):
        result = verdicts(lab, answers[i], params[j])
        if i == j:
            assert all(result.values()), (lab, i, result)
            own += 1
            continue
        for check, passed in result.items():
            total += 1
            failed += not passed
            assert not passed, f"group {i + 1}'s answer passes {check} of group {j + 1}"
    return own, failed, total


def checks_per_lab(lab):
    """How many value-graded checks ``verdicts`` runs for ``lab`` (on the course's numbers)."""
    params = LABS[lab].params().to_params()
    return len(verdicts(lab, SOLVE[lab](params), params))


@pytest.mark.parametrize("lab", list(LABS))
def test_every_lab_has_a_solution_of_the_tests_own(lab):
    assert lab in SOLVE, (
        f"the {lab} lab has no solution in tests/test_variant_keys.py: write {lab}_solution "
        "(what a right answer computes from a group's PARAMS), add it to SOLVE and its "
        "value-graded checks to verdicts (CONTRIBUTING.md, step 8)"
    )


@pytest.mark.parametrize("lab", [lab for lab in LABS if lab in SOLVE])
def test_each_group_solution_passes_its_own_key_and_fails_every_other(variants, lab):
    own, failed, total = cross_keys(lab, variants[lab])
    assert own == GROUPS
    assert failed == total == GROUPS * (GROUPS - 1) * checks_per_lab(lab)


@pytest.mark.slow
@pytest.mark.parametrize("lab", [lab for lab in LABS if lab in SOLVE])
def test_a_class_of_twelve_groups_has_twelve_keys(lab):
    own, failed, total = cross_keys(lab, draw_variants(LABS[lab], 12, seed=1))
    assert own == 12 and failed == total == 12 * 11 * checks_per_lab(lab)


@pytest.mark.parametrize("lab", list(LABS))
def test_no_two_groups_share_a_draw(variants, lab):
    drawn = variants[lab] + [LABS[lab].params()]  # nor the book's own numbers
    for a, b in itertools.combinations(drawn, 2):
        assert a.to_params() != b.to_params()
        for name, value in a.distinct().items():
            assert value != b.distinct()[name], (lab, name)
    plants = [v.plant() for v in variants[lab]]
    for a, b in itertools.combinations(plants, 2):
        assert a != b
    if lab != "case_study":
        poles = [
            tuple(sorted(map(complex, v.poles), key=lambda z: (z.real, z.imag)))
            for v in variants[lab]
        ]
        assert len(set(poles)) == GROUPS
    else:
        assert len({v.plant().D.tobytes() for v in variants[lab]}) == GROUPS


@pytest.mark.parametrize("lab", list(LABS))
def test_every_variant_keeps_the_teaching_point(variants, lab):
    for variant in variants[lab]:
        assert variant.problems() == []
        plant = variant.plant()
        report = ut.check_existence(plant)
        assert report.ok
        if lab == "pa9":
            assert report.movable == 3  # the rank and observability conditions hold
        elif lab == "case_study":
            fixed = report.fixed_modes
            assert report.movable == 1 and fixed.size == 2
            np.testing.assert_allclose(fixed, [0.5, 0.5], atol=1e-6)  # as the chapter tells
            pmo = ut.design_pmo(plant, method="lmi")  # the LMI is feasible, with L D = 0
            np.testing.assert_allclose(pmo.L @ plant.D, 0, atol=1e-6)
            moved = ut.design_pmo(plant, poles=[variant.pole])
            assert np.abs(moved.L).max() > 0.01  # moving the pole takes a gain
        else:
            CE = plant.C @ plant.E
            assert CE.shape == (2, 2) and np.linalg.matrix_rank(CE) == 2
            zeros = report.invariant_zeros
            assert zeros.size == 2 and np.all(zeros.real < 0)  # actuator-like, stable


def test_the_same_seed_draws_the_same_variants(variants):
    again = draw_variants(LABS["missile"], GROUPS, seed=SEED)
    assert [v.to_params() for v in again] == [v.to_params() for v in variants["missile"]]
    other = draw_variants(LABS["missile"], GROUPS, seed=SEED + 1)
    assert [v.to_params() for v in other] != [v.to_params() for v in variants["missile"]]


def test_the_key_follows_the_group_plant(variants):
    """The answer key's matrices are those of the group's own plant."""
    for lab in LABS:
        for variant in variants[lab]:
            key = variant.answers()
            solution = SOLVE[lab](variant.to_params())
            np.testing.assert_allclose(
                key["M" if lab != "pa9" else "H"], solution["M" if lab != "pa9" else "H"], atol=1e-8
            )


@pytest.mark.parametrize("lab", list(LABS))
def test_every_graded_value_differs_between_groups(variants, lab):
    """Not only the verdicts: each matrix a student computes is another for each group."""
    answers = [SOLVE[lab](v.to_params()) for v in variants[lab]]
    for a, b in itertools.combinations(answers, 2):
        for name in a:
            if name in ("P", "Y"):  # the LMI's certificate: any solution is right
                continue
            assert not np.allclose(a[name], b[name], atol=1e-3), (lab, name)


def pa9_runs(params, answer):
    """The PA9 lab's two runs, from z(0) = 0, with the group's own design."""
    plant = ut.experiments.plant_from_params("pa9", params)
    observer = ut.design_uio(plant, K1=answer["K1"])
    t = np.linspace(0, params["duration"], params["samples"])
    u = ut.signals.stack(ut.signals.step(1.0), ut.signals.sinusoid(0.5, 1.0))
    sine = ut.signals.sinusoid(params["sine"]["amplitude"], params["sine"]["frequency"])
    steps = ut.signals.piecewise_constant(
        params["piecewise"]["times"], params["piecewise"]["values"]
    )
    x0 = params["initial_state"]
    return (
        ut.simulate(plant, observer, t, u=u, d=sine, initial_state=x0),
        ut.simulate(plant, observer, t, u=u, d=steps, initial_state=x0),
    )


def pa9_run_verdicts(params):
    """The PA9 run checks of a group's own solution against its own key."""
    plant = ut.experiments.plant_from_params("pa9", params)
    answer = pa9_solution(params)
    resp_sine, resp_steps = pa9_runs(params, answer)
    common = {
        "poles": params["poles"],
        "initial_state": params["initial_state"],
        "H": answer["H"],
        "K1": answer["K1"],
        "plant": plant,
    }
    return resp_sine, {
        "pa9.simulation": checks.pa9_simulation(
            resp_sine,
            amplitude=params["sine"]["amplitude"],
            frequency=params["sine"]["frequency"],
            **common,
        ),
        "pa9.piecewise": checks.pa9_piecewise(
            resp_steps,
            sinusoidal=resp_sine,
            times=params["piecewise"]["times"],
            values=params["piecewise"]["values"],
            **common,
        ),
    }


def case_study_run_verdict(params):
    """The case study's run check of a group's own solution against its own key."""
    plant = ut.experiments.plant_from_params("case_study", params)
    pmo = ut.design_pmo(plant, L=case_study_solution(params)["L"])
    steps = np.arange(params["steps"] + 1)
    d_in = ut.signals.sinusoid(params["d"]["amplitude"], params["d"]["frequency"])
    rng = np.random.default_rng(params["v"]["seed"])
    switch = np.arange(0, steps[-1] + 1, params["v"]["hold"])
    levels = rng.uniform(-params["v"]["amplitude"], params["v"]["amplitude"], switch.size)
    v = ut.signals.piecewise_constant(switch, levels)
    run = ut.simulate(plant, pmo, steps, d=d_in, v=v, initial_state=params["initial_state"])
    return run, checks.case_study_simulation(
        run,
        d=(params["d"]["amplitude"], params["d"]["frequency"]),
        v=(params["v"]["amplitude"], params["v"]["hold"], params["v"]["seed"]),
        initial_state=params["initial_state"],
        plant=plant,
        observer=pmo,
    )


def test_the_first_groups_of_seed_3_start_with_a_pa9_error():
    # x(0) = [-0.5, 0.5, -0.5] along E = [1, -1, 1] once gave e(0) = T x(0) = 0
    for variant in draw_variants(LABS["pa9"], 2, seed=3):
        resp, results = pa9_run_verdicts(variant.to_params())
        assert np.max(np.abs(resp.error[:, 0])) >= MIN_INITIAL_ERROR
        assert all(r.passed for r in results.values()), {k: r.failures for k, r in results.items()}


@pytest.mark.parametrize("seed", range(30))
def test_every_group_run_passes_its_own_key_whatever_the_seed(seed):
    for variant in draw_variants(LABS["pa9"], 2, seed=seed):
        resp, results = pa9_run_verdicts(variant.to_params())
        assert np.max(np.abs(resp.error[:, 0])) >= MIN_INITIAL_ERROR, seed
        assert all(r.passed for r in results.values()), (seed, variant.initial_state)
    for variant in draw_variants(LABS["case_study"], 2, seed=seed):
        run, result = case_study_run_verdict(variant.to_params())
        assert np.max(np.abs(run.error[:, 0])) >= MIN_INITIAL_ERROR, seed
        assert result.passed, (seed, result.failures)


def test_a_start_along_e_is_no_fair_pa9_exercise():
    variant = LABS["pa9"].params()
    E = variant.plant().E.ravel()
    along = LABS["pa9"].params.from_params(
        dict(variant.to_params(), initial_state=[float(v) for v in E])
    )
    assert any("initial error" in p for p in along.problems())
    assert not variant.problems()
