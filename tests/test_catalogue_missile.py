"""A catalogue of wrong answers to the missile lab: each gets a ✗ that names the mistake."""

from __future__ import annotations

import numpy as np
import pytest

import uio_teach as ut
from uio_teach import checks
from uio_teach.instructor.lab_params import MissileParams

P = MissileParams().to_params()
POLES = P["pmo_poles"]
SIGMA, SEED = P["noise"]["sigma"], P["noise"]["seed"]
TOL = P["tol"]
PLANT = ut.examples.missile_autopilot()
A, C, E = PLANT.A, PLANT.C, PLANT.E
n, p = PLANT.n, PLANT.p
EYE = np.eye(n)
PUB = ut.examples.MISSILE_PUBLISHED
X0 = PUB.x0
V = ut.examples.missile_inputs()
T = np.linspace(0, P["duration"], P["samples"])
CE = C @ E
CEg = np.linalg.pinv(CE)
M = E @ CEg + PUB.Mv @ (np.eye(p) - CE @ CEg)
A1 = (EYE - M @ C) @ A
PMO = ut.design_pmo(PLANT, poles=POLES, Mv=PUB.Mv)
L = PMO.L
F = A1 - L @ C
Cg = np.linalg.pinv(C)
Pc = EYE - Cg @ C
K = Pc @ E @ CEg
NAMES = ["x1", "x2", "x3", "x4", "v1", "v2"]


def sim(observer=PMO, d=V, **kw):
    return ut.simulate(PLANT, observer, T, d=d, initial_state=X0, **kw)


RUN = sim()
VHAT = ut.reconstruct_input(PLANT, RUN)
RUN0 = sim(observer_state=-M @ C @ X0)
VHAT0 = ut.reconstruct_input(PLANT, RUN0)
NOISY = sim(noise=SIGMA, seed=SEED)
VHAT_NOISY = ut.reconstruct_input(PLANT, NOISY)
LATE = T >= 0.1
RMS = np.sqrt(np.mean(VHAT_NOISY.error[:, LATE] ** 2, axis=1))


def catch_times(run=RUN0, vhat=VHAT0, tol=TOL):
    tx = ut.catch_time(T, run.states, run.estimates, tol=tol)
    tv = ut.catch_time(T, vhat.actual, vhat.estimates, tol=tol)
    return dict(zip(NAMES, (float(x) for x in np.concatenate([tx, tv])), strict=True))


CATCH = catch_times()
L_A = ut.design_pmo(PLANT, poles=[-200, -220], Mv=PUB.Mv).L  # other poles


def pmo(m=M, gain=L, f=F, poles=POLES):
    return checks.missile_pmo(m, gain, f, poles=poles)


def changed(**new):
    out = dict(CATCH)
    out.update(new)
    return out


def without(key):
    return {k: v for k, v in CATCH.items() if k != key}


CATALOGUE = {
    # the PMO ---------------------------------------------------------------------------------
    "M left out": (lambda: pmo(m=None), "M is missing"),
    "L left out": (lambda: pmo(gain=None), "L is missing"),
    "F left out": (lambda: pmo(f=None), "F is missing"),
    "M = C^g": (lambda: pmo(m=Cg, f=(EYE - Cg @ C) @ A - L @ C), "Your M is C^g"),
    "M transposed": (lambda: pmo(m=M.T), "It looks transposed"),
    "F = A - LC": (lambda: pmo(f=A - L @ C), "F is A - LC: the projection is missing"),
    "F = A1 + LC": (lambda: pmo(f=A1 + L @ C), "the sign of LC is flipped"),
    "poles other than asked": (
        lambda: pmo(gain=L_A, f=A1 - L_A @ C),
        "but the exercise asks for -100, -120",
    ),
    "L = 0": (lambda: pmo(gain=np.zeros((n, p)), f=A1), "but the exercise asks for"),
    # the g-inverse observer ------------------------------------------------------------------
    "Cg left out": (lambda: checks.missile_ginverse(None, Pc, K), "Cg is missing"),
    "Pc left out": (lambda: checks.missile_ginverse(Cg, None, K), "Pc is missing"),
    "K left out": (lambda: checks.missile_ginverse(Cg, Pc, None), "K is missing"),
    "Pc = Cg C": (
        lambda: checks.missile_ginverse(Cg, Cg @ C, K),
        "Pc is Cg C, the projection onto the measured coordinates",
    ),
    "K = the PMO's M": (lambda: checks.missile_ginverse(Cg, Pc, M), "Your K is E (CE)^g"),
    "a generalized inverse that is not Moore-Penrose": (
        lambda: checks.missile_ginverse(Cg + Pc @ np.ones((n, p)), Pc, K),
        "not the Moore-Penrose one",
    ),
    "Cg = 0": (lambda: checks.missile_ginverse(np.zeros((n, p)), Pc, K), "not an inverse of C"),
    # the reconstruction ------------------------------------------------------------------------
    "vhat left out": (lambda: checks.missile_reconstruction(None, RUN), "vhat must be the result"),
    "the run left out": (lambda: checks.missile_reconstruction(VHAT, None), "got None"),
    "a run without v": (
        lambda: checks.missile_reconstruction(VHAT, sim(d=None)),
        "not the paper's v1, v2",
    ),
    "vhat of another run": (
        lambda: checks.missile_reconstruction(VHAT, RUN0),
        "vhat is not the reconstruction of this run",
    ),
    "the noisy run": (
        lambda: checks.missile_reconstruction(VHAT_NOISY, NOISY),
        "the run has measurement noise",
    ),
    # the catch times -----------------------------------------------------------------------------
    "catch left out": (
        lambda: checks.missile_catch_times(None, RUN0, VHAT0),
        "catch must be a dict",
    ),
    "v2 missing": (
        lambda: checks.missile_catch_times(without("v2"), RUN0, VHAT0),
        "catch has no time for v2",
    ),
    "a band of 5 %": (
        lambda: checks.missile_catch_times(catch_times(tol=0.05), RUN0, VHAT0, tol=TOL),
        "catch times that differ from the run",
    ),
    "the paper's numbers copied": (
        lambda: checks.missile_catch_times(dict(PUB.catch_pmo), RUN0, VHAT0),
        "catch times that differ from the run",
    ),
    "catch times of the run from q(0) = 0": (
        lambda: checks.missile_catch_times(catch_times(RUN, VHAT), RUN, VHAT),
        "not at x̂(0) = 0",
    ),
    "x3 in milliseconds": (
        lambda: checks.missile_catch_times(changed(x3=CATCH["x3"] * 1000), RUN0, VHAT0),
        "x3:",
    ),
    "a time as text": (
        lambda: checks.missile_catch_times(changed(v1="soon"), RUN0, VHAT0),
        "v1 is 'soon', not a number",
    ),
    # the noise ---------------------------------------------------------------------------------
    "rms left out": (lambda: checks.missile_noise(None, NOISY, sigma=SIGMA), "rms is missing"),
    "noise of another seed": (
        lambda: checks.missile_noise(RMS, sim(noise=SIGMA, seed=SEED + 1), sigma=SIGMA, seed=SEED),
        "the noise of the run is not the one of seed",
    ),
    "the noise-free run": (
        lambda: checks.missile_noise(RMS, RUN, sigma=SIGMA),
        "the run has no measurement noise",
    ),
    "another noise level": (
        lambda: checks.missile_noise(RMS, sim(noise=10 * SIGMA, seed=SEED), sigma=SIGMA),
        "but the exercise asks for sigma = 0.01",
    ),
    "RMS over the whole run": (
        lambda: checks.missile_noise(
            np.sqrt(np.mean(VHAT_NOISY.error**2, axis=1)), NOISY, sigma=SIGMA
        ),
        "are not those of the run's plain-derivative reconstruction",
    ),
    "the predicted numbers instead of the measured ones": (
        lambda: checks.missile_noise(
            SIGMA / (np.sqrt(2) * (T[1] - T[0])) * np.linalg.norm(np.linalg.inv(CE), axis=1),
            NOISY,
            sigma=SIGMA,
        ),
        "are not those of the run",
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
        pmo(),
        checks.missile_ginverse(Cg, Pc, K),
        checks.missile_reconstruction(VHAT, RUN),
        checks.missile_catch_times(CATCH, RUN0, VHAT0, tol=TOL),
        checks.missile_noise(RMS, NOISY, sigma=SIGMA, seed=SEED),
    ]
    for result in results:
        assert result.passed, str(result)
    assert [r.check_id for r in results] == [
        "missile.pmo",
        "missile.ginverse",
        "missile.reconstruction",
        "missile.catch_times",
        "missile.noise",
    ]


def test_the_error_is_the_same_whatever_the_unknown_inputs():
    quiet = sim(d=None)
    np.testing.assert_allclose(RUN.error, quiet.error, atol=1e-8 * np.abs(RUN.states).max())


def test_the_noise_rms_is_close_to_the_prediction():
    predicted = SIGMA / (np.sqrt(2) * (T[1] - T[0])) * np.linalg.norm(np.linalg.inv(CE), axis=1)
    np.testing.assert_allclose(RMS, predicted, rtol=0.15)
