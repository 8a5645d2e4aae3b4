"""A catalogue of wrong answers to the missile lab: each gets a ✗ that names the mistake.

``test_catalogue_feedback.py`` runs every entry (and the right but different answers): this
module holds the catalogue and the right answer."""

from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from tolerance import assert_same_run

import uio_teach as ut
from uio_teach import checks
from uio_teach.worked import WORKED
from uio_teach.worked.missile import MissileParams

matplotlib.use("Agg")

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
Kg = Pc @ E @ CEg
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
GOBS = ut.design_ginverse(PLANT)
RUN_G = sim(observer=GOBS)
VHAT_G = ut.reconstruct_input(PLANT, RUN_G)
RUN_G0 = sim(observer=GOBS, observer_state=-M @ C @ X0)
VHAT_G0 = ut.reconstruct_input(PLANT, RUN_G0)
RUN_NO_X0 = ut.simulate(PLANT, PMO, T, d=V)
VHAT_NO_X0 = ut.reconstruct_input(PLANT, RUN_NO_X0)
PMO_OTHER = ut.design_pmo(PLANT, poles=[-200, -220], Mv=PUB.Mv)
RUN_OTHER0 = sim(observer=PMO_OTHER, observer_state=-M @ C @ X0)
VHAT_OTHER0 = ut.reconstruct_input(PLANT, RUN_OTHER0)
ASKED = {"plant": PLANT, "observer": PMO, "poles": POLES, "initial_state": X0}


def reconstruction(vhat=VHAT, run=RUN, **kw):
    return checks.missile_reconstruction(vhat, run, **{**ASKED, **kw})


def catch_check(catch=None, run=RUN0, vhat=VHAT0, **kw):
    catch = CATCH if catch is None else catch
    return checks.missile_catch_times(catch, run, vhat, tol=TOL, **{**ASKED, **kw})


def figure(vhat=VHAT, scale=1.0, xlabel="time (s)", title="v and v̂, PMO", rows=(0, 1), est=True):
    fig = Figure()
    axes = fig.subplots(2, 1, sharex=True)
    for i, ax in enumerate(axes):
        if i in rows:
            ax.plot(scale * vhat.time, vhat.actual[i], label=f"v{i + 1}")
        if est:
            ax.plot(scale * vhat.time, vhat.estimates[i], "--", label=f"v̂{i + 1}")
        ax.set_ylabel(f"v{i + 1}")
        ax.legend()
    axes[-1].set_xlabel(xlabel)
    if title:
        fig.suptitle(title)
    return fig


def plot(fig, vhat=VHAT):
    return checks.missile_plot(fig, vhat, plant=PLANT)


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
        "but the exercise asks for -90, -140",
    ),
    "L = 0": (lambda: pmo(gain=np.zeros((n, p)), f=A1), "but the exercise asks for"),
    # the g-inverse observer ------------------------------------------------------------------
    "Cg left out": (lambda: checks.missile_ginverse(None, Pc, Kg), "Cg is missing"),
    "Pc left out": (lambda: checks.missile_ginverse(Cg, None, Kg), "Pc is missing"),
    "Kg left out": (lambda: checks.missile_ginverse(Cg, Pc, None), "Kg is missing"),
    "Pc = Cg C": (
        lambda: checks.missile_ginverse(Cg, Cg @ C, Kg),
        "Pc is Cg C, the projection onto the measured coordinates",
    ),
    "Kg = the PMO's M": (lambda: checks.missile_ginverse(Cg, Pc, M), "Your Kg is E (CE)^g"),
    "a generalized inverse that is not Moore-Penrose": (
        lambda: checks.missile_ginverse(Cg + Pc @ np.ones((n, p)), Pc, Kg),
        "not the Moore-Penrose one",
    ),
    "Cg = 0": (lambda: checks.missile_ginverse(np.zeros((n, p)), Pc, Kg), "not an inverse of C"),
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
    "the g-inverse observer simulated where the PMO was asked": (
        lambda: reconstruction(VHAT_G, RUN_G),
        "the run simulates a g-inverse observer",
    ),
    "x0 dropped": (
        lambda: reconstruction(VHAT_NO_X0, RUN_NO_X0),
        "initial_state was left out?",
    ),
    "x0 dropped, no initial state given to the check": (
        lambda: reconstruction(VHAT_NO_X0, RUN_NO_X0, initial_state=None),
        "the plant starts from x(0) = 0",
    ),
    "z(0) = -M C x0 where z(0) = 0 was asked": (
        lambda: reconstruction(VHAT0, RUN0),
        "does not start from z(0) = 0",
    ),
    "a PMO with other poles": (
        lambda: reconstruction(ut.reconstruct_input(PLANT, sim(PMO_OTHER)), sim(PMO_OTHER)),
        "another PMO than yours",
    ),
    "a run of another plant": (
        lambda: reconstruction(VHAT, RUN, plant=ut.examples.pa9()),
        "another plant than the one of the set-up cell",
    ),
    "the observer passed where the run was asked": (
        lambda: reconstruction(VHAT, PMO),
        "must be the result of ut.simulate",
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
    "catch times of the run from z(0) = 0": (
        lambda: catch_check(catch_times(RUN, VHAT), RUN, VHAT),
        "x̂(0) = z(0) + M y(0) is not 0",
    ),
    "x3 in milliseconds": (
        lambda: catch_check(changed(x3=CATCH["x3"] * 1000)),
        "is it in ms instead of s?",
    ),
    "x1 typed one band too early": (
        lambda: catch_check(changed(x1=CATCH["x1"] - 0.01)),
        "x1 is too early",
    ),
    "v2 read too late": (lambda: catch_check(changed(v2=CATCH["v2"] + 0.01)), "v2 is too late"),
    "catch times of the g-inverse observer": (
        lambda: catch_check(catch_times(RUN_G0, VHAT_G0), RUN_G0, VHAT_G0),
        "the run simulates a g-inverse observer",
    ),
    "catch times of a PMO with other poles": (
        lambda: catch_check(catch_times(RUN_OTHER0, VHAT_OTHER0), RUN_OTHER0, VHAT_OTHER0),
        "another PMO than yours",
    ),
    "catch times of a PMO with other poles, no observer given": (
        lambda: catch_check(
            catch_times(RUN_OTHER0, VHAT_OTHER0), RUN_OTHER0, VHAT_OTHER0, observer=None
        ),
        "does not have the poles",
    ),
    "catch as a list": (lambda: catch_check(list(CATCH.values())), "catch must be a dict"),
    "catch times as arrays of the wrong size": (
        lambda: catch_check(changed(x1=np.array([0.1, 0.2]))),
        "not a number",
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
    "noise on the run from x̂(0) = 0": (
        lambda: checks.missile_noise(
            RMS, sim(noise=SIGMA, seed=SEED, observer_state=-M @ C @ X0), sigma=SIGMA
        ),
        "does not start from z(0) = 0",
    ),
    "noise on the g-inverse observer": (
        lambda: checks.missile_noise(RMS, sim(GOBS, noise=SIGMA, seed=SEED), sigma=SIGMA),
        "the run simulates a g-inverse observer",
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
    "rms as text": (
        lambda: checks.missile_noise("60, 90", NOISY, sigma=SIGMA),
        "rms must hold numbers",
    ),
    "the predicted numbers instead of the measured ones": (
        lambda: checks.missile_noise(
            SIGMA / (np.sqrt(2) * (T[1] - T[0])) * np.linalg.norm(np.linalg.inv(CE), axis=1),
            NOISY,
            sigma=SIGMA,
        ),
        "are not those of the run",
    ),
    # the figure of v and v̂ ----------------------------------------------------------------------
    "figure left out": (lambda: plot(None), "fig is missing (None)"),
    "only the estimates": (lambda: plot(figure(rows=())), "the figure lacks v1, v2"),
    "only v, no estimate": (lambda: plot(figure(est=False)), "the figure lacks v̂1, v̂2"),
    "no title": (lambda: plot(figure(title="")), "the figure has no title"),
    "time in s labelled in ms": (
        lambda: plot(figure(xlabel="time (ms)")),
        "the x-label says time in ms, but the curves are drawn against time in s",
    ),
    "time in ms labelled in s": (
        lambda: plot(figure(scale=1000.0)),
        "the x-label says time in s, but the curves are drawn against time in ms",
    ),
    "an x-label that is not time": (lambda: plot(figure(xlabel="v")), "does not say it is time"),
    "the g-inverse named in the title": (
        lambda: plot(figure(title="v and v̂, g-inverse observer")),
        "names the g-inverse observer",
    ),
    "the figure of another reconstruction": (
        lambda: plot(figure(vhat=VHAT0)),
        "the figure lacks",
    ),
}


# right answers that differ from the book's ------------------------------------------------------
RIGHT_BUT_DIFFERENT = {
    "the package's plot": lambda: plot(VHAT.plot(title="v and its reconstruction")),
    "time in ms labelled 'time (ms)'": lambda: plot(figure(scale=1000.0, xlabel="time (ms)")),
    "time labelled 't [s]'": lambda: plot(figure(xlabel="t [s]")),
    "the PMO from ut.design_pmo with the paper's Mv, checked by its poles": lambda: reconstruction(
        observer=None
    ),
    "catch times rounded to 4 decimals": lambda: catch_check(
        {k: round(v, 4) for k, v in CATCH.items()}
    ),
    "catch times as numpy floats": lambda: catch_check(
        {k: np.float64(v) for k, v in CATCH.items()}
    ),
    "catch times of another group's poles, against its own PMO": lambda: catch_check(
        catch_times(RUN_OTHER0, VHAT_OTHER0),
        RUN_OTHER0,
        VHAT_OTHER0,
        observer=PMO_OTHER,
        poles=[-200, -220],
    ),
    "Kg with a Kv term (CE is invertible here: it does nothing)": lambda: checks.missile_ginverse(
        Cg, Pc, Pc @ E @ CEg + np.ones((n, p)) @ (np.eye(p) - CE @ CEg)
    ),
    "rms as a list": lambda: checks.missile_noise(list(RMS), NOISY, sigma=SIGMA, seed=SEED),
}


def test_the_right_answer_passes_every_check():
    results = [
        pmo(),
        checks.missile_ginverse(Cg, Pc, Kg),
        reconstruction(),
        catch_check(),
        checks.missile_noise(RMS, NOISY, sigma=SIGMA, seed=SEED, plant=PLANT, observer=PMO),
        plot(figure()),
    ]
    for result in results:
        assert result.passed, str(result)
    # every check the lab declares (its registry entry), each once
    assert sorted(r.check_id for r in results) == sorted(WORKED["missile"].lab.check_ids)


def test_the_error_is_the_same_whatever_the_unknown_inputs():
    quiet = sim(d=None)
    assert_same_run(RUN.error, quiet.error, RUN, quiet)


def test_the_noise_rms_is_close_to_the_prediction():
    predicted = SIGMA / (np.sqrt(2) * (T[1] - T[0])) * np.linalg.norm(np.linalg.inv(CE), axis=1)
    np.testing.assert_allclose(RMS, predicted, rtol=0.15)
