"""A catalogue of wrong answers to the PA9 lab: each gets a ✗ whose message names the mistake.

Every entry is what a lab group could hand in (a matrix left out, a sign flipped, poles other
than the asked ones, a figure with the wrong curves in a panel, ...) with the gist of the message
the check must give (``test_catalogue_feedback.py`` runs every entry, and the right but
different answers). The right answer passes every check.
"""

from __future__ import annotations

import control as ct
import numpy as np
from matplotlib.figure import Figure

import uio_teach as ut
from uio_teach import checks
from uio_teach.worked.pa9 import PA9Params

P = PA9Params().to_params()
POLES = P["poles"]
X0 = P["initial_state"]
AMP, FREQ = P["sine"]["amplitude"], P["sine"]["frequency"]
TIMES, VALUES = P["piecewise"]["times"], P["piecewise"]["values"]
PLANT = ut.examples.pa9()
A, C, E = PLANT.A, PLANT.C, PLANT.E
H = E @ np.linalg.pinv(C @ E)
T = np.eye(3) - H @ C
K1 = ct.place((T @ A).T, C.T, POLES).T
F = T @ A - K1 @ C
K2 = F @ H
TIME = np.linspace(0, P["duration"], P["samples"])
SINE = ut.signals.sinusoid(AMP, FREQ)
STEPS = ut.signals.piecewise_constant(TIMES, VALUES)
OBS = ut.design_uio(PLANT, K1=K1)


def sim(observer=OBS, d=SINE, x0=X0, timepts=TIME, **kw):
    return ut.simulate(PLANT, observer, timepts, d=d, initial_state=x0, **kw)


SINE_RESP = sim()
STEPS_RESP = sim(d=STEPS)


def design(h=H, t=T, k1=K1, f=F, k2=K2):
    return checks.pa9_design(h, t, k1, f, k2, plant=PLANT, poles=POLES)


def simulation(resp, h=H, k1=K1, plant=PLANT):
    return checks.pa9_simulation(
        resp,
        poles=POLES,
        amplitude=AMP,
        frequency=FREQ,
        initial_state=X0,
        H=h,
        K1=k1,
        plant=plant,
    )


def piecewise(resp, sinusoidal=SINE_RESP, h=H, k1=K1):
    return checks.pa9_piecewise(
        resp,
        sinusoidal=sinusoidal,
        times=TIMES,
        values=VALUES,
        poles=POLES,
        initial_state=X0,
        H=h,
        K1=k1,
        plant=PLANT,
    )


# a valid H other than E (CE)^+: any h with h CE = 1 gives H = E h with HCE = E
CE = C @ E
H_OTHER = E @ (np.array([[1.0, 1.0]]) / (np.array([[1.0, 1.0]]) @ CE).item())
T_OTHER = np.eye(3) - H_OTHER @ C
K1_OTHER = ct.place((T_OTHER @ A).T, C.T, POLES).T
F_OTHER = T_OTHER @ A - K1_OTHER @ C
OBS_OTHER = ut.UIO(PLANT, H_OTHER, K1_OTHER)
SINE_OTHER = sim(OBS_OTHER)
STEPS_OTHER = sim(OBS_OTHER, d=STEPS)


def figure(
    e_curves,
    r_curves,
    e_label="error e = x - x̂",
    r_label="residual r = y - C x̂",
    xlabel="time (s)",
    x=None,
    one_axes=False,
):
    fig = Figure()
    if one_axes:
        ax = fig.subplots()
        ax.plot(TIME if x is None else x, e_curves.T)
        ax.plot(TIME if x is None else x, r_curves.T)
        ax.set_ylabel(f"{e_label}, {r_label}")
        ax.set_xlabel(xlabel)
        return fig
    ax_e, ax_r = fig.subplots(2, 1, sharex=True)
    ax_e.plot(TIME if x is None else x, e_curves.T)
    ax_e.set_ylabel(e_label)
    ax_r.plot(TIME if x is None else x, r_curves.T)
    ax_r.set_ylabel(r_label)
    ax_r.set_xlabel(xlabel)
    return fig


def plot(fig, response=SINE_RESP):
    return checks.pa9_plot(fig, response=response, plant=PLANT)


def steps_figure(resp=STEPS_RESP, d_panel=True, title="UIO with a piecewise-constant disturbance"):
    fig = Figure()
    axes = fig.subplots(3 if d_panel else 2, 1, sharex=True)
    if d_panel:
        axes[0].plot(TIME, resp.inputs.d.T, color="k")
        axes[0].set_ylabel("disturbance d")
    axes[-2].plot(TIME, resp.error.T, label=["e1", "e2", "e3"])
    axes[-2].set_ylabel("error e = x - x̂")
    axes[-1].plot(TIME, resp.residual.T, label=["r1", "r2"])
    axes[-1].set_ylabel("residual r = y - C x̂")
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title(title)
    return fig


def steps_plot(fig, response=STEPS_RESP):
    return checks.pa9_piecewise_plot(fig, response, plant=PLANT)


def titled(fig, title, panel=0):
    fig.axes[panel].set_title(title)
    return fig


R = SINE_RESP
K1_A = ct.place(A.T, C.T, POLES).T  # placed for A, not TA
K1_FAST = ct.place((T @ A).T, C.T, [-4, -5, -6]).T
K1_UNSTABLE = ct.place((T @ A).T, C.T, [1, -2, -3]).T
LUEN = ut.design_luenberger(PLANT, poles=POLES)
H_NAN = H.copy()
H_NAN[1, 0] = np.nan

CATALOGUE = {
    # requirement 1: the design ------------------------------------------------------------------
    "H left out": (lambda: design(h=None), "H is missing"),
    "T left out": (lambda: design(t=None), "T is missing"),
    "K1 left out": (lambda: design(k1=None), "K1 is missing"),
    "F left out": (lambda: design(f=None), "F is missing"),
    "K2 left out": (lambda: design(k2=None), "K2 is missing"),
    "H transposed": (lambda: design(h=H.T), "It looks transposed"),
    "H copied with 2 decimals": (lambda: design(h=np.round(H, 2)), "2 decimals"),
    "H with a minus sign": (lambda: design(h=-H), "check the sign"),
    "H with another h, but T and K1 of E (CE)^+": (
        lambda: design(h=H_OTHER),
        "T is not I - HC",
    ),
    "poles given as words": (
        lambda: checks.pa9_design(H, T, K1, poles=["slow", "medium", "fast"]),
        "poles must be a list of 3 numbers",
    ),
    "the plant as a dict": (
        lambda: checks.pa9_design(H, T, K1, plant={"A": A}),
        "plant must be a uio_teach.Plant",
    ),
    "H with a NaN": (lambda: design(h=H_NAN), "every entry must be a finite number"),
    "H as ragged lists": (lambda: design(h=[[1, 2], [3]]), "could not be read as a matrix"),
    "H as text": (lambda: design(h="E @ pinv(C @ E)"), "must hold numbers"),
    "K1 complex": (lambda: design(k1=K1 + 1j), "complex entries"),
    "T = HC - I": (lambda: design(t=-T), "Your T is HC - I"),
    "T = HC": (lambda: design(t=H @ C), "Your T is HC"),
    "F = A - K1C": (lambda: design(f=A - K1 @ C), "the T is missing, F = TA - K1C"),
    "F = TA + K1C": (lambda: design(f=T @ A + K1 @ C), "the sign of K1C is flipped"),
    "K2 = -FH": (lambda: design(k2=-F @ H), "K2 is -FH: the sign is flipped"),
    "K2 = K1 - FH": (lambda: design(k2=K1 - F @ H), "Your K2 is K1 - FH"),
    "K1 placing -4, -5, -6": (
        lambda: design(k1=K1_FAST, f=T @ A - K1_FAST @ C, k2=(T @ A - K1_FAST @ C) @ H),
        "but the exercise asks for -4, -2.5, -1.5",
    ),
    "K1 placed for A instead of TA": (
        lambda: design(k1=K1_A, f=T @ A - K1_A @ C, k2=(T @ A - K1_A @ C) @ H),
        "places the poles of A - K1C, not of TA - K1C",
    ),
    "K1 with an unstable pole": (
        lambda: design(k1=K1_UNSTABLE, f=T @ A - K1_UNSTABLE @ C, k2=(T @ A - K1_UNSTABLE @ C) @ H),
        "F is not stable: the eigenvalue 1 is not in the open left half-plane",
    ),
    # requirement 2: the sinusoidal test ---------------------------------------------------------
    "simulation left out": (lambda: simulation(None), "got None"),
    "a Luenberger observer": (lambda: simulation(sim(LUEN)), "Your observer is a Luenberger"),
    "no disturbance": (lambda: simulation(sim(d=None)), "d is zero during the whole simulation"),
    "the piecewise d in the sinusoidal test": (
        lambda: simulation(STEPS_RESP),
        "d is piecewise constant, not a sinusoid",
    ),
    "another amplitude": (
        lambda: simulation(sim(d=ut.signals.sinusoid(2 * AMP, FREQ))),
        "is not the disturbance the exercise asks for",
    ),
    "another initial state": (
        lambda: simulation(sim(x0=[0.0, 1.0, 0.0])),
        "the plant starts from x(0) = [0, 1, 0], but the exercise asks for [0.5, 1, -1]",
    ),
    "a zero initial state": (
        lambda: simulation(sim(x0=[0.0, 0.0, 0.0])),
        "the error is zero at t = 0",
    ),
    "measurement noise": (lambda: simulation(sim(noise=0.01, seed=1)), "measurement noise"),
    "too short a simulation": (
        lambda: simulation(sim(timepts=np.linspace(0, 1, 201))),
        "has not decayed yet",
    ),
    "an observer with other poles": (
        lambda: simulation(sim(ut.design_uio(PLANT, poles=[-4, -5, -6]))),
        "the simulated observer has the poles -6, -5, -4, not the -1.5, -2.5, -4 of the exercise",
    ),
    "a valid other H, but design_uio(K1=K1) simulated": (
        lambda: simulation(sim(ut.design_uio(PLANT, K1=K1_OTHER)), h=H_OTHER, k1=K1_OTHER),
        "its H differs from yours",
    ),
    "x0 dropped": (
        lambda: simulation(ut.simulate(PLANT, OBS, TIME, d=SINE)),
        "was initial_state left out of ut.simulate?",
    ),
    "a run of another plant": (
        lambda: simulation(
            ut.simulate(
                ut.Plant(2 * A, B=PLANT.B, C=C, E=E),
                ut.design_uio(ut.Plant(2 * A, B=PLANT.B, C=C, E=E), poles=POLES),
                TIME,
                d=SINE,
                initial_state=X0,
            )
        ),
        "another plant than the one of the set-up cell",
    ),
    "the observer passed instead of the run": (
        lambda: simulation(OBS),
        "must be the result of ut.simulate",
    ),
    "poles as a string": (
        lambda: checks.pa9_simulation(SINE_RESP, poles="-1, -2, -3"),
        "could not read your answer: text where numbers are expected",
    ),
    # requirement 3: the figure -----------------------------------------------------------------
    "figure left out": (lambda: plot(None), "fig is missing (None)"),
    "outputs y in the residual panel": (
        lambda: plot(figure(R.error, R.outputs)),
        "the residual panel shows the outputs y (resp.outputs)",
    ),
    "panel labels swapped": (
        lambda: plot(figure(R.residual, R.error)),
        "the panels are swapped",
    ),
    "one axes instead of two": (
        lambda: plot(figure(R.error, R.residual, one_axes=True)),
        "one axes with curves; e and r belong in two panels",
    ),
    "time without a unit": (
        lambda: plot(figure(R.error, R.residual, xlabel="time")),
        "the x-label 'time' has no unit",
    ),
    "sample index under 'time (s)'": (
        lambda: plot(figure(R.error, R.residual, x=np.arange(TIME.size))),
        "plotted against the sample index",
    ),
    "-e in the error panel": (
        lambda: plot(figure(-R.error, R.residual)),
        "the error panel shows -e = x̂ - x",
    ),
    "x in the error panel": (
        lambda: plot(figure(R.states, R.residual)),
        "the error panel shows the states x (resp.states)",
    ),
    "x̂ in the error panel": (
        lambda: plot(figure(R.estimates, R.residual)),
        "the error panel shows the estimates x̂",
    ),
    "e2 left out": (
        lambda: plot(figure(R.error[[0, 2]], R.residual)),
        "the error panel lacks some error components: e2",
    ),
    "no x-label": (
        lambda: plot(figure(R.error, R.residual, xlabel="")),
        "have no x-label",
    ),
    "time in s labelled in ms": (
        lambda: plot(figure(R.error, R.residual, xlabel="time (ms)")),
        "the x-label says time in ms, but the curves are drawn against time in s",
    ),
    "time in ms labelled in s": (
        lambda: plot(figure(R.error, R.residual, x=1000 * TIME)),
        "the x-label says time in s, but the curves are drawn against time in ms",
    ),
    "a title naming the states over the error": (
        lambda: plot(titled(figure(R.error, R.residual), "states x and their estimates")),
        "does not fit the panel",
    ),
    "a title naming the residual over the error": (
        lambda: plot(titled(figure(R.error, R.residual), "residual")),
        "no panel is labelled as the error alone",
    ),
    "the title of the other experiment": (
        lambda: plot(titled(figure(R.error, R.residual), "piecewise-constant disturbance")),
        "the title names a piecewise-constant disturbance",
    ),
    "a UIO figure titled as the Luenberger observer": (
        lambda: plot(titled(figure(R.error, R.residual), "Luenberger observer, sinusoid")),
        "the title names a Luenberger observer",
    ),
    "the figure of another run": (
        lambda: plot(figure(STEPS_OTHER.error, STEPS_OTHER.residual)),
        "no curve of the error panel is the error e of the response",
    ),
    # requirement 4: the piecewise-constant test --------------------------------------------------
    "the sinusoid again": (lambda: piecewise(SINE_RESP), "so it is not piecewise constant"),
    "a constant d": (
        lambda: piecewise(sim(d=ut.signals.piecewise_constant([0], [1.0]))),
        "d is constant",
    ),
    "other switching times": (
        lambda: piecewise(sim(d=ut.signals.piecewise_constant([0, 1], [1.0, -1.0]))),
        "is not the disturbance the exercise asks for",
    ),
    "another initial state than in requirement 2": (
        lambda: piecewise(sim(d=STEPS, x0=[0.0, 1.0, 0.0])),
        "start the plant from different states",
    ),
    "a Luenberger observer in requirement 4": (
        lambda: piecewise(sim(LUEN, d=STEPS)),
        "the two simulations use different observers",
    ),
    "another time grid": (
        lambda: piecewise(sim(d=STEPS, timepts=np.linspace(0, P["duration"], 1001))),
        "use the same timepts in both",
    ),
    "x0 dropped in requirement 4": (
        lambda: piecewise(ut.simulate(PLANT, OBS, TIME, d=STEPS)),
        "was initial_state left out of ut.simulate?",
    ),
    # requirement 4: its figure ------------------------------------------------------------------
    "figure of requirement 4 left out": (lambda: steps_plot(None), "fig is missing (None)"),
    "the sinusoidal run in the figure of requirement 4": (
        lambda: steps_plot(steps_figure(), response=SINE_RESP),
        "the title names a piecewise-constant disturbance, but the run's d is a sinusoid",
    ),
    "states in the error panel of requirement 4": (
        lambda: steps_plot(
            _replace_curves(steps_figure(), 1, STEPS_RESP.states),
        ),
        "the error panel shows the states x",
    ),
    "requirement 4 titled as the sinusoidal test": (
        lambda: steps_plot(steps_figure(title="UIO with a sinusoidal disturbance")),
        "the title names a sinusoidal disturbance",
    ),
}


def _replace_curves(fig, panel, rows):
    for line, row in zip(fig.axes[panel].get_lines(), rows, strict=True):
        line.set_ydata(row)
    return fig


# right answers that differ from the book's ------------------------------------------------------
def _ms_figure():
    fig = figure(R.error, R.residual, xlabel="time (ms)", x=1000 * TIME)
    return fig


def _norm_figure():
    fig = figure(np.linalg.norm(R.error, axis=0)[None, :], R.residual)
    return fig


def _legend_only_figure():
    fig = figure(R.error, R.residual, e_label="", r_label="")
    ax_e, ax_r = fig.axes
    for line, name in zip(ax_e.get_lines(), ["e1", "e2", "e3"], strict=True):
        line.set_label(name)
    for line, name in zip(ax_r.get_lines(), ["r1", "r2"], strict=True):
        line.set_label(name)
    ax_e.legend()
    ax_r.legend()
    return fig


OBS_OTHER_K1 = ut.UIO(PLANT, H, K1 + 0 * K1)

RIGHT_BUT_DIFFERENT = {
    "a valid other H: the design": lambda: design(
        h=H_OTHER, t=T_OTHER, k1=K1_OTHER, f=F_OTHER, k2=F_OTHER @ H_OTHER
    ),
    "a valid other H: the sinusoidal test": lambda: simulation(SINE_OTHER, h=H_OTHER, k1=K1_OTHER),
    "a valid other H: the figure": lambda: plot(
        figure(SINE_OTHER.error, SINE_OTHER.residual), response=SINE_OTHER
    ),
    "a valid other H: the piecewise test": lambda: piecewise(
        STEPS_OTHER, sinusoidal=SINE_OTHER, h=H_OTHER, k1=K1_OTHER
    ),
    "a valid other H: the figure of requirement 4": lambda: steps_plot(
        steps_figure(STEPS_OTHER), response=STEPS_OTHER
    ),
    "F and K2 left to the check": lambda: checks.pa9_design(H, T, K1, plant=PLANT, poles=POLES),
    "the poles in another order": lambda: checks.pa9_design(
        H, T, K1, F, K2, plant=PLANT, poles=POLES[::-1]
    ),
    "time in ms labelled 'time (ms)'": lambda: plot(_ms_figure()),
    "time labelled 't [s]'": lambda: plot(figure(R.error, R.residual, xlabel="t [s]")),
    "the norm of the error instead of its components": lambda: plot(_norm_figure()),
    "labels in the legends only": lambda: plot(_legend_only_figure()),
    "a figure title that fits": lambda: plot(
        titled(figure(R.error, R.residual), "UIO, sinusoidal disturbance")
    ),
    "requirement 4 without the d panel": lambda: steps_plot(steps_figure(d_panel=False)),
    "the observer built with ut.UIO from the book's H": lambda: simulation(sim(OBS_OTHER_K1)),
}


def test_the_right_answer_passes_every_check():
    fig = figure(R.error, R.residual)
    results = (
        design(),
        simulation(SINE_RESP),
        plot(fig),
        piecewise(STEPS_RESP),
        steps_plot(steps_figure()),
    )
    for result in results:
        assert result.passed, str(result)


def test_the_checks_carry_their_ids():
    fig = figure(R.error, R.residual)
    ids = [r.check_id for r in (design(), simulation(R), plot(fig), piecewise(STEPS_RESP))]
    assert ids == ["pa9.design", "pa9.simulation", "pa9.plot", "pa9.piecewise"]
    assert checks.pa9_design(None, None, None).check_id == "pa9.design"  # also on a failure
