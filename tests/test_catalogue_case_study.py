"""A catalogue of wrong answers to the case-study lab: each gets a ✗ that names the mistake."""

from __future__ import annotations

import numpy as np
import pytest

import uio_teach as ut
from uio_teach import checks
from uio_teach.instructor.lab_params import CaseStudyParams

P = CaseStudyParams().to_params()
POLE = P["pole"]
X0 = P["initial_state"]
U2 = (P["u2"]["amplitude"], P["u2"]["frequency"])
V = (P["v"]["amplitude"], P["v"]["hold"], P["v"]["seed"])
PLANT = ut.examples.dt_case_study()
A, C, B2, D = PLANT.A, PLANT.C, PLANT.E, PLANT.D
n, p = PLANT.n, PLANT.p
EYE = np.eye(n)
M = np.hstack([B2, np.zeros((n, 1))]) @ np.linalg.pinv(np.hstack([C @ B2, D]))
A1 = (EYE - M @ C) @ A
LMI = ut.design_pmo(PLANT, method="lmi")
L, P_LMI = LMI.L, LMI.lmi_certificate
N = ut.linalg.left_null(D)
L_MOVED = ut.design_pmo(PLANT, poles=[POLE]).L
STEPS = np.arange(P["steps"] + 1)
U2_SIGNAL = ut.signals.sinusoid(*U2)


def staircase(amplitude, hold, seed):
    rng = np.random.default_rng(seed)
    switch = np.arange(0, STEPS[-1] + 1, hold)
    return ut.signals.piecewise_constant(switch, rng.uniform(-amplitude, amplitude, switch.size))


V_SIGNAL = staircase(*V)


def sim(observer=LMI, d=U2_SIGNAL, v=V_SIGNAL, x0=X0, steps=STEPS):
    return ut.simulate(PLANT, observer, steps, d=d, v=v, initial_state=x0)


RUN = sim()


def simulation(resp):
    return checks.case_study_simulation(resp, u2=U2, v=V, initial_state=X0)


def residual(Dv=None, Nr=None, run=RUN):
    Dv = D @ run.inputs.v if Dv is None else Dv
    Nr = N @ run.residual if Nr is None else Nr
    return checks.case_study_residual(Dv, Nr, run)


# a gain on the pole circle, with LD = 0 (the LMI as printed accepts it)
NC = N @ C
L_EDGE = -NC.T @ N / (NC @ NC.T).item()
# the l of L = l N applied to y1 alone, which v reaches
L_Y1 = (L_MOVED @ np.linalg.pinv(N)) @ np.array([[1.0, 0.0]])
P_BAD = P_LMI.copy()
P_BAD[0, 1] += 1.0

CATALOGUE = {
    # M ---------------------------------------------------------------------------------------
    "M left out": (lambda: checks.case_study_projection(None), "M is missing"),
    "M transposed": (lambda: checks.case_study_projection(M.T), "It looks transposed"),
    "M = B2 (CB2)^+, D forgotten": (
        lambda: checks.case_study_projection(B2 @ np.linalg.pinv(C @ B2)),
        "which ignores D",
    ),
    "M with a minus sign": (lambda: checks.case_study_projection(-M), "drop the minus sign"),
    "M = C^+": (lambda: checks.case_study_projection(np.linalg.pinv(C)), "(I - MC)B2 is not 0"),
    "M with a NaN": (
        lambda: checks.case_study_projection(np.where(M > 0.4, np.nan, M)),
        "every entry must be a finite number",
    ),
    # L from the LMI ------------------------------------------------------------------------------
    "L left out": (lambda: checks.case_study_lmi(None), "L is missing"),
    "L transposed": (lambda: checks.case_study_lmi(L.T), "It looks transposed"),
    "the printed L, rounded": (
        lambda: checks.case_study_lmi(ut.examples.DT_CASE_STUDY_PUBLISHED.L),
        "rounded to 4 decimals",
    ),
    "L without YD = 0": (lambda: checks.case_study_lmi(L + 0.1), "Add the constraint Y @ D == 0"),
    "a gain on the unit circle": (
        lambda: checks.case_study_lmi(L_EDGE),
        "F = A1 - LC is not stable",
    ),
    "P not symmetric": (lambda: checks.case_study_lmi(L, P_BAD), "P is not symmetric positive"),
    "P of another gain": (
        lambda: checks.case_study_lmi(L_EDGE + 0.5 * L_MOVED, P_LMI),
        "P does not certify this L",
    ),
    "P negative definite": (
        lambda: checks.case_study_lmi(L, -P_LMI),
        "P is not symmetric positive",
    ),
    # the movable pole ----------------------------------------------------------------------------
    "L_moved left out": (lambda: checks.case_study_pole(None, POLE), "L is missing"),
    "the LMI gain, pole not moved": (
        lambda: checks.case_study_pole(L, POLE),
        f"asks to move the movable pole to {POLE:g}",
    ),
    "the pole moved elsewhere": (
        lambda: checks.case_study_pole(ut.design_pmo(PLANT, poles=[-0.3]).L, POLE),
        "F = A1 - LC has the poles -0.3, 0.5, 0.5",
    ),
    "a gain on y1 alone": (lambda: checks.case_study_pole(L_Y1, POLE), "LD is not 0"),
    "the factor l instead of L": (
        lambda: checks.case_study_pole(L_MOVED @ np.linalg.pinv(N), POLE),
        "L has shape (3, 1) but must be a 3 x 2 matrix",
    ),
    # the run ------------------------------------------------------------------------------------
    "run left out": (lambda: simulation(None), "got None"),
    "no u2": (lambda: simulation(sim(d=None)), "u2 is zero during the whole run"),
    "no v": (lambda: simulation(sim(v=None)), "v is zero during the whole run"),
    "u2 with another amplitude": (
        lambda: simulation(sim(d=ut.signals.sinusoid(2 * U2[0], U2[1]))),
        "u2 is not the asked",
    ),
    "v with another seed": (
        lambda: simulation(sim(v=staircase(V[0], V[1], V[2] + 1))),
        "v is not the asked staircase",
    ),
    "another initial state": (
        lambda: simulation(sim(x0=[0.0, 1.0, 0.0])),
        "but the exercise asks for [1, -2, 3]",
    ),
    "an observer designed for another E": (
        lambda: simulation(
            ut.simulate(
                PLANT,
                ut.design_pmo(ut.Plant(A, C, E=[[1.0], [0.0], [0.0]], D=D, dt=1.0), poles=[0.2]),
                STEPS,
                d=U2_SIGNAL,
                v=V_SIGNAL,
                initial_state=X0,
            )
        ),
        "the error depends on the unknown signals",
    ),
    "too few steps": (lambda: simulation(sim(steps=np.arange(3))), "the error has not decayed"),
    # the residual --------------------------------------------------------------------------------
    "Dv left out": (
        lambda: checks.case_study_residual(None, N @ RUN.residual, RUN),
        "Dv is missing",
    ),
    "Nr left out": (
        lambda: checks.case_study_residual(D @ RUN.inputs.v, None, RUN),
        "Nr is missing",
    ),
    "v instead of Dv": (
        lambda: residual(Dv=RUN.inputs.v),
        "Dv has shape (1, 41) but must be a 2 x 41 matrix",
    ),
    "the residual instead of Dv": (
        lambda: residual(Dv=RUN.residual),
        "Dv is not D @ resp.inputs.v",
    ),
    "y seen through N": (
        lambda: residual(Nr=N @ RUN.outputs),
        "Nr is not the residual seen through a row N with N D = 0",
    ),
    "the first residual instead of N r": (
        lambda: residual(Nr=RUN.residual[:1]),
        "Nr is not the residual seen through a row N with N D = 0",
    ),
}


def test_the_catalogue_is_large_enough():
    assert len(CATALOGUE) >= 25


@pytest.mark.parametrize("name", list(CATALOGUE))
def test_a_wrong_answer_fails_with_a_message_that_names_the_mistake(name):
    make, gist = CATALOGUE[name]
    result = make()
    assert not result.passed, f"{name}: passed\n{result}"
    assert any(gist in msg for msg in result.failures), f"{name}: expected {gist!r}\n{result}"


def test_the_right_answer_passes_every_check():
    results = [
        checks.case_study_projection(M),
        checks.case_study_lmi(L, P_LMI),
        checks.case_study_pole(L_MOVED, POLE),
        simulation(RUN),
        residual(),
    ]
    for result in results:
        assert result.passed, str(result)
    assert [r.check_id for r in results] == [
        "case_study.projection",
        "case_study.lmi",
        "case_study.pole",
        "case_study.simulation",
        "case_study.residual",
    ]


def test_the_error_is_the_same_whatever_the_unknown_inputs():
    """The defining property that the simulation check relies on, shown directly."""
    quiet = sim(d=None, v=None)
    louder = sim(d=ut.signals.sinusoid(5.0, 0.3), v=staircase(3.0, 2, 9))
    np.testing.assert_allclose(RUN.error, quiet.error, atol=1e-12)
    np.testing.assert_allclose(louder.error, quiet.error, atol=1e-12)
