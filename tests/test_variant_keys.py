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
    K = Pc @ E @ np.linalg.inv(C @ E)
    return {"M": pmo.M, "L": pmo.L, "F": pmo.F, "Cg": Cg, "Pc": Pc, "K": K}


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
            answer["Cg"], answer["Pc"], answer["K"], plant
        ).passed,
    }


def traced(answer):
    """The solver's ``Y`` for the LMI check, where the check traces ``L`` to it."""
    takes_y = "Y" in inspect.signature(checks.case_study_lmi).parameters
    return {"Y": answer["Y"]} if takes_y else {}


SOLVE = {"pa9": pa9_solution, "case_study": case_study_solution, "missile": missile_solution}


@pytest.mark.parametrize("lab", list(LABS))
def test_each_group_solution_passes_its_own_key_and_fails_every_other(variants, lab):
    params = [v.to_params() for v in variants[lab]]
    answers = [SOLVE[lab](p) for p in params]
    failed = total = 0
    for i, j in itertools.product(range(GROUPS), repeat=2):
        result = verdicts(lab, answers[i], params[j])
        if i == j:
            assert all(result.values()), (lab, i, result)
            continue
        for check, passed in result.items():
            total += 1
            failed += not passed
            assert not passed, f"group {i + 1}'s answer passes {check} of group {j + 1}"
    assert failed == total == GROUPS * (GROUPS - 1) * len(result)


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
