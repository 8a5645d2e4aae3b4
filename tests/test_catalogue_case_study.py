"""A catalogue of wrong answers to the case-study lab: each gets a ✗ that names the mistake.

``test_catalogue_feedback.py`` runs every entry (and the right but different answers): this
module holds the catalogue and the right answer."""

from __future__ import annotations

import warnings

import cvxpy as cp
import numpy as np
from matplotlib.figure import Figure
from tolerance import assert_same_run

import uio_teach as ut
from uio_teach import checks
from uio_teach.worked import WORKED
from uio_teach.worked.case_study import CaseStudyParams

P = CaseStudyParams().to_params()
POLE = P["pole"]
X0 = P["initial_state"]
D_ASKED = (P["d"]["amplitude"], P["d"]["frequency"])
V = (P["v"]["amplitude"], P["v"]["hold"], P["v"]["seed"])
PLANT = ut.examples.dt_case_study()
A, C, E, D = PLANT.A, PLANT.C, PLANT.E, PLANT.D
n, p = PLANT.n, PLANT.p
EYE = np.eye(n)
M = np.hstack([E, np.zeros((n, 1))]) @ np.linalg.pinv(np.hstack([C @ E, D]))
A1 = (EYE - M @ C) @ A
LMI = ut.design_pmo(PLANT, method="lmi")
L, P_LMI = LMI.L, LMI.lmi_certificate
N = ut.linalg.left_null(D)
L_MOVED = ut.design_pmo(PLANT, poles=[POLE]).L
STEPS = np.arange(P["steps"] + 1)
D_SIGNAL = ut.signals.sinusoid(*D_ASKED)


def staircase(amplitude, hold, seed):
    rng = np.random.default_rng(seed)
    switch = np.arange(0, STEPS[-1] + 1, hold)
    return ut.signals.piecewise_constant(switch, rng.uniform(-amplitude, amplitude, switch.size))


V_SIGNAL = staircase(*V)


def solve_lmi(solver="CLARABEL"):
    """The exercise's LMI, solved as a lab group does: the solver's P and Y."""
    P_var = cp.Variable((n, n), symmetric=True)
    Y_var = cp.Variable((n, p))
    block = cp.bmat([[-P_var, A1.T @ P_var - C.T @ Y_var.T], [P_var @ A1 - Y_var @ C, -P_var]])
    constraints = [block << -0.01 * np.eye(2 * n), Y_var @ D == 0, P_var >> 0.01 * EYE]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cp.Problem(cp.Minimize(0), constraints).solve(solver=solver)
    return P_var.value, Y_var.value


P_SOLVED, Y_SOLVED = solve_lmi()
L_SOLVED = np.linalg.solve(P_SOLVED, Y_SOLVED)
P_SCS, Y_SCS = solve_lmi("SCS")


def lmi(gain=L_SOLVED, P=P_SOLVED, Y=Y_SOLVED):
    return checks.case_study_lmi(gain, P, Y=Y, plant=PLANT)


def plot_residual(r=None, dv=None, nr=None, xlabel="step k", x=None, run=None):
    run = RUN if run is None else run
    fig = Figure()
    ax_r, ax_n = fig.subplots(2, 1, sharex=True)
    x = run.time if x is None else x
    r = run.residual if r is None else r
    dv = D @ run.inputs.v if dv is None else dv
    nr = N @ run.residual if nr is None else nr
    ax_r.plot(x, r.T, label=[f"r{i + 1}" for i in range(r.shape[0])])
    ax_r.plot(x, dv.T, "k--", label=[f"(Dv){i + 1}" for i in range(dv.shape[0])])
    ax_r.set_ylabel("residual r and Dv")
    ax_r.legend()
    ax_n.plot(x, nr.T)
    ax_n.set_ylabel("N r")
    ax_n.set_xlabel(xlabel)
    return fig


def plot(fig, run=None):
    return checks.case_study_plot(fig, RUN if run is None else run, plant=PLANT)


def sim(observer=LMI, d=D_SIGNAL, v=V_SIGNAL, x0=X0, steps=STEPS):
    return ut.simulate(PLANT, observer, steps, d=d, v=v, initial_state=x0)


RUN = sim()


def simulation(resp, observer=None):
    return checks.case_study_simulation(
        resp, d=D_ASKED, v=V, initial_state=X0, plant=PLANT, observer=observer
    )


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
    "M = E (CE)^+, D forgotten": (
        lambda: checks.case_study_projection(E @ np.linalg.pinv(C @ E)),
        "which ignores D",
    ),
    "M with a minus sign": (lambda: checks.case_study_projection(-M), "check the sign"),
    "M = C^+": (lambda: checks.case_study_projection(np.linalg.pinv(C)), "(I - MC)E is not 0"),
    "M with a NaN": (
        lambda: checks.case_study_projection(np.where(M > 0.4, np.nan, M)),
        "every entry must be a finite number",
    ),
    # L from the LMI ------------------------------------------------------------------------------
    "L left out": (lambda: checks.case_study_lmi(None), "L is missing"),
    "L = Y_var.value (P divided out forgotten)": (
        lambda: lmi(gain=Y_SOLVED),
        "Your L is Y itself",
    ),
    "L = P_lmi @ Y_var.value": (lambda: lmi(gain=P_SOLVED @ Y_SOLVED), "Your L is P Y"),
    "the LMI skipped (P_lmi = None), the package's gain": (
        lambda: lmi(gain=L, P=None, Y=None),
        "P is missing",
    ),
    "Y not passed": (lambda: lmi(Y=None), "Y is not given"),
    "L of another solve": (
        lambda: lmi(gain=np.linalg.solve(P_SCS, Y_SCS) + 0.05 * L_MOVED),
        "L is not P^-1 Y",
    ),
    "P and Y of another solve": (
        lambda: lmi(gain=L_SOLVED, P=P_SCS, Y=Y_SCS + 0.01),
        "L is not P^-1 Y",
    ),
    "L transposed": (lambda: checks.case_study_lmi(L.T), "It looks transposed"),
    "the printed L, rounded": (
        lambda: lmi(gain=ut.examples.DT_CASE_STUDY_PUBLISHED.L),
        "rounded to 4 decimals",
    ),
    "L without YD = 0": (
        lambda: lmi(gain=L + 0.1, P=P_LMI, Y=P_LMI @ (L + 0.1)),
        "is it in your LMI?",
    ),
    "a gain on the unit circle": (
        lambda: lmi(gain=L_EDGE, P=P_LMI, Y=P_LMI @ L_EDGE),
        "F = A1 - LC is not stable",
    ),
    "P not symmetric": (
        lambda: lmi(gain=L, P=P_BAD, Y=P_BAD @ L),
        "P is not symmetric positive",
    ),
    "P of another gain": (
        lambda: lmi(L_EDGE + 0.5 * L_MOVED, P_LMI, P_LMI @ (L_EDGE + 0.5 * L_MOVED)),
        "P does not certify this L",
    ),
    "P negative definite": (
        lambda: lmi(gain=L, P=-P_LMI, Y=-P_LMI @ L),
        "P is not symmetric positive",
    ),
    "P as a cvxpy variable, not its value": (
        lambda: lmi(P=cp.Variable((n, n), symmetric=True)),
        "P could not be read as a matrix",
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
    "the pole as a string": (
        lambda: checks.case_study_pole(L_MOVED, "0.3 please"),
        "could not read your answer",
    ),
    "a gain on y1 alone": (lambda: checks.case_study_pole(L_Y1, POLE), "LD is not 0"),
    "the factor l instead of L": (
        lambda: checks.case_study_pole(L_MOVED @ np.linalg.pinv(N), POLE),
        "L has shape (3, 1) but must be a 3 x 2 matrix",
    ),
    # the run ------------------------------------------------------------------------------------
    "run left out": (lambda: simulation(None), "got None"),
    "no d": (lambda: simulation(sim(d=None)), "d is zero during the whole run"),
    "no v": (lambda: simulation(sim(v=None)), "v is zero during the whole run"),
    "d with another amplitude": (
        lambda: simulation(sim(d=ut.signals.sinusoid(2 * D_ASKED[0], D_ASKED[1]))),
        "d is not the asked",
    ),
    "v with another seed": (
        lambda: simulation(sim(v=staircase(V[0], V[1], V[2] + 1))),
        "v is not the asked staircase",
    ),
    "another initial state": (
        lambda: simulation(sim(x0=[0.0, 1.0, 0.0])),
        "but the exercise asks for [2, 1, -1]",
    ),
    "an observer designed for another E": (
        lambda: simulation(
            ut.simulate(
                PLANT,
                ut.design_pmo(ut.Plant(A, C, E=[[1.0], [0.0], [0.0]], D=D, dt=1.0), poles=[0.2]),
                STEPS,
                d=D_SIGNAL,
                v=V_SIGNAL,
                initial_state=X0,
            )
        ),
        "the error depends on the unknown signals",
    ),
    "too few steps": (lambda: simulation(sim(steps=np.arange(3))), "the error has not decayed"),
    "x0 dropped": (lambda: simulation(sim(x0=None)), "initial_state left out?"),
    "the observer started from z[0] = -M y[0]": (
        lambda: simulation(
            ut.simulate(
                PLANT,
                LMI,
                STEPS,
                d=D_SIGNAL,
                v=V_SIGNAL,
                initial_state=X0,
                observer_state=-M @ C @ np.asarray(X0),
            )
        ),
        "but the exercise asks for z[0] = 0",
    ),
    "the moved-pole observer instead of the LMI one": (
        lambda: simulation(sim(observer=ut.design_pmo(PLANT, L=L_MOVED)), observer=LMI),
        "another PMO than the one built from your LMI gain",
    ),
    "a run of another plant": (
        lambda: simulation(
            ut.simulate(
                ut.Plant(0.9 * A, C, E=E, D=D, dt=1.0),
                ut.design_pmo(ut.Plant(0.9 * A, C, E=E, D=D, dt=1.0), poles=[0.2]),
                STEPS,
                d=D_SIGNAL,
                v=V_SIGNAL,
                initial_state=X0,
            )
        ),
        "another plant than the one of the set-up cell",
    ),
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
        "Dv is not D times the v of this run",
    ),
    "y seen through N": (
        lambda: residual(Nr=N @ RUN.outputs),
        "Nr is not the residual seen through a row N with N D = 0",
    ),
    "the first residual instead of N r": (
        lambda: residual(Nr=RUN.residual[:1]),
        "Nr is not the residual seen through a row N with N D = 0",
    ),
    # the figure of r, D v and N r ---------------------------------------------------------------
    "figure left out": (lambda: plot(None), "fig is missing (None)"),
    "the residual without D v": (
        lambda: plot(plot_residual(dv=np.zeros((0, STEPS.size)))),
        "but not next to D v",
    ),
    "y instead of r": (lambda: plot(plot_residual(r=RUN.outputs)), "shows the outputs y"),
    "no N r panel": (
        lambda: plot(plot_residual(nr=RUN.outputs[:1])),
        "no panel shows N r",
    ),
    "steps labelled as time in ms": (
        lambda: plot(plot_residual(xlabel="time (ms)")),
        "the x-label says time in ms",
    ),
    "an x-label without a unit": (
        lambda: plot(plot_residual(xlabel="time")),
        "has no unit",
    ),
    "curves against shifted steps": (
        lambda: plot(plot_residual(x=STEPS + 1.0)),
        "not plotted against the time points of the run",
    ),
    "the residual panel without labels": (
        lambda: plot(_unlabelled(plot_residual())),
        "does not say which curve is which",
    ),
}


def _unlabelled(fig):
    ax = fig.axes[0]
    ax.set_ylabel("")
    ax.get_legend().remove()
    for line in ax.get_lines():
        line.set_label("_nolegend_")
    return fig


# right answers that differ from the book's ------------------------------------------------------
RIGHT_BUT_DIFFERENT = {
    "the book's solve": lambda: lmi(),
    "another solver (SCS): another P, Y and L": lambda: lmi(
        np.linalg.solve(P_SCS, Y_SCS), P_SCS, Y_SCS
    ),
    "L = inv(P) @ Y": lambda: lmi(gain=np.linalg.inv(P_SOLVED) @ Y_SOLVED),
    "the package's LMI gain with its certificate": lambda: lmi(L, P_LMI, P_LMI @ L),
    "M from the package": lambda: checks.case_study_projection(
        ut.existence.decoupling(PLANT).M, plant=PLANT
    ),
    "the moved pole from a hand-made l N": lambda: checks.case_study_pole(
        (L_MOVED @ np.linalg.pinv(N)) @ N, POLE, plant=PLANT
    ),
    "the run of the observer built from the solver's gain": lambda: simulation(
        sim(observer=ut.design_pmo(PLANT, L=L_SOLVED)),
        observer=ut.design_pmo(PLANT, L=L_SOLVED),
    ),
    "N r with N scaled by -2": lambda: residual(Nr=-2 * N @ RUN.residual),
    "the figure with the step axis labelled 'k'": lambda: plot(plot_residual(xlabel="k")),
    "the figure with N r scaled by -2": lambda: plot(plot_residual(nr=-2 * N @ RUN.residual)),
}


def test_the_right_answer_passes_every_check():
    results = [
        checks.case_study_projection(M),
        lmi(),
        checks.case_study_pole(L_MOVED, POLE),
        simulation(RUN, observer=LMI),
        residual(),
        plot(plot_residual()),
    ]
    for result in results:
        assert result.passed, str(result)
    # the check ids the lab declares (its registry entry), in the order of its check cells
    assert tuple(r.check_id for r in results) == WORKED["case_study"].lab.check_ids


def test_the_error_is_the_same_whatever_the_unknown_inputs():
    """The defining property that the simulation check relies on, shown directly."""
    quiet = sim(d=None, v=None)
    louder = sim(d=ut.signals.sinusoid(5.0, 0.3), v=staircase(3.0, 2, 9))
    assert_same_run(RUN.error, quiet.error, RUN, quiet)
    assert_same_run(louder.error, quiet.error, louder, quiet)
