"""The lab checks: they pass on a right answer and name each kind of mistake, never raising."""

import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

import uio_teach as ut
from uio_teach import checks
from uio_teach.checks import CheckResult
from uio_teach.checks.common import likely_cause, never_raises

PLANT = ut.examples.pa9()
A, C, E = PLANT.A, PLANT.C, PLANT.E
H = E @ np.linalg.pinv(C @ E)  # eq. (8) of the assignment
T = np.eye(3) - H @ C
K1 = ut.examples.PA9_PUBLISHED.K1
F = T @ A - K1 @ C
K2 = F @ H
X0 = [1.0, -1.0, 0.5]
TIME = np.linspace(0, 10, 1001)
SINE = ut.signals.sinusoid(1.0, 2.0)
STEPS = ut.signals.piecewise_constant([0, 3, 6], [1.0, -2.0, 0.5])


def failures_text(result: CheckResult) -> str:
    return "\n".join(result.failures)


@pytest.fixture(scope="module")
def uio():
    return ut.design_uio(PLANT, K1=K1)


@pytest.fixture(scope="module")
def sine_response(uio):
    return ut.simulate(PLANT, uio, TIME, d=SINE, initial_state=X0)


@pytest.fixture(scope="module")
def steps_response(uio):
    return ut.simulate(PLANT, uio, TIME, d=STEPS, initial_state=X0)


# CheckResult ----------------------------------------------------------------------------------


def test_check_result_is_printable_truthy_and_html():
    good = CheckResult("t", [(True, "a"), (None, "note")])
    bad = CheckResult("t", [(True, "a"), (False, "b <c>")])
    assert good.passed and bool(good) and not bad.passed and not bad
    assert good.messages == ["✓ a", "• note"]
    assert bad.failures == ["b <c>"]
    assert "All 1 checks passed." in str(good)
    assert "1 of 2 checks failed" in str(bad)
    assert "b &lt;c&gt;" in bad._repr_html_() and "✗" in bad._repr_html_()
    assert not CheckResult("nothing").passed  # nothing checked is not a pass


# pa9_design -----------------------------------------------------------------------------------


def test_design_passes_on_the_right_matrices():
    result = checks.pa9_design(H, T, K1, F, K2)
    assert result.passed, str(result)
    assert len(result.items) == 5


def test_design_accepts_lists_and_any_pole_placement():
    obs = ut.design_uio(PLANT, poles=[-1, -2, -3])  # python-control's K1, not MATLAB's
    assert checks.pa9_design(obs.H.tolist(), obs.T, obs.K1, obs.F, obs.K2).passed
    result = checks.pa9_design(H, T, K1)  # F and K2 are optional
    assert result.passed
    assert any("F not given" in m for m in result.messages)


def test_the_poles_asked_for_are_compared_to_the_tolerance_given():
    # pa9_design's docstring: the eigenvalues of F must be the poles asked for, each to ``tol``
    obs = ut.design_uio(PLANT, poles=[-1, -2, -3])
    off = [-1 * (1 + 1e-4), -2, -3]  # one pole 1e-4 relative away from F's
    strict = checks.pa9_design(obs.H, obs.T, obs.K1, poles=off)
    loose = checks.pa9_design(obs.H, obs.T, obs.K1, poles=off, tol=1e-3)
    assert not strict.passed and "asks for" in failures_text(strict)
    assert loose.passed, str(loose)


def test_the_missile_pmo_poles_are_compared_to_the_tolerance_given():
    plant = ut.examples.missile_autopilot()
    pmo = ut.design_pmo(plant, poles=[-100, -120])
    off = [-100 * (1 + 1e-4), -120]
    assert not checks.missile_pmo(pmo.M, pmo.L, pmo.F, poles=off).passed
    assert checks.missile_pmo(pmo.M, pmo.L, pmo.F, poles=off, tol=1e-3).passed


def test_two_decimals_of_a_groups_H_are_not_said_to_be_the_assignments():
    plant = ut.experiments.plant_from_params(
        "pa9", {"plant": {"A": A.tolist(), "E": [[2.5], [0.5], [1.0]]}}
    )
    exact = plant.E @ np.linalg.pinv(plant.C @ plant.E)
    text = failures_text(checks.pa9_design(np.round(exact, 2), T, K1, plant=plant))
    assert "only 2 decimals" in text and "assignment" not in text


def test_any_decoupling_H_is_accepted():
    # H = C^+ also satisfies (I - HC)E = 0 here, since E has no x2 component
    Hc = np.linalg.pinv(C)
    result = checks.pa9_design(Hc, np.eye(3) - Hc @ C, np.zeros((3, 2)))
    assert "(I - HC)E = 0" in result.messages[0] and result.items[0][0] is True


def test_wrong_H_is_named():
    result = checks.pa9_design(np.zeros((3, 2)), np.eye(3), K1)
    assert not result.passed
    assert "H does not satisfy (I - HC)E = 0" in result.failures[0]
    assert "generalized inverse" in result.failures[0]
    assert "pinv(C @ E)" not in result.failures[0]  # the idea, not the solution line


def test_printed_two_decimal_matrices_are_explained():
    pub = ut.examples.PA9_PUBLISHED
    result = checks.pa9_design(pub.H, pub.T, pub.K1, pub.F, pub.K2)
    assert not result.passed
    assert "only 2 decimals, as the assignment prints it" in result.failures[0]
    assert "only 2 decimals" in result.failures[1]


def test_wrong_T_is_named():
    result = checks.pa9_design(H, -T, K1)
    assert "T is not I - HC" in failures_text(result)
    assert "HC - I: the sign is flipped" in failures_text(result)
    result = checks.pa9_design(H, T + 0.1, K1)
    assert "T is not I - HC" in failures_text(result)


def test_wrong_F_is_named():
    result = checks.pa9_design(H, T, K1, A - K1 @ C)
    assert "F is not TA - K1C" in failures_text(result)
    assert "the T is missing" in failures_text(result)
    result = checks.pa9_design(H, T, K1, T @ A + K1 @ C)
    assert "sign of K1C is flipped" in failures_text(result)


def test_F_consistent_with_a_wrong_T_points_to_T():
    Tw = T + 0.1
    result = checks.pa9_design(H, Tw, K1, Tw @ A - K1 @ C)
    assert "your T is wrong" in failures_text(result)


def test_wrong_K2_is_named():
    result = checks.pa9_design(H, T, K1, F, -K2)
    assert result.failures == [
        "K2 is -FH: the sign is flipped. The condition (A - K1C - HCA)H - K2 = 0 of eq. (7) "
        "gives K2 = FH."
    ]
    result = checks.pa9_design(H, T, K1, F, K2 + 1)
    assert "K2 is not FH" in failures_text(result)


def test_unstable_F_names_the_eigenvalue():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ut.UnstableObserverWarning)
        bad = ut.design_uio(PLANT, poles=[0.5, -2, -3])
    result = checks.pa9_design(bad.H, bad.T, bad.K1, bad.F, bad.K2)
    assert result.failures == [
        "F is not stable: the eigenvalue 0.5 is not in the open left half-plane, so the error "
        "e' = F e does not decay. Choose K1 so that TA - K1C has the poles of the exercise "
        "(pole placement for the pair (TA, C), by duality)."
    ]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((H.T, T, K1), "H has shape (2, 3) but must be a 3 x 2 matrix"),
        ((H.T, T, K1), "It looks transposed: use H.T instead."),
        ((H, T[:2], K1), "T has shape (2, 3) but must be a 3 x 3 matrix"),
        ((H, T, K1.ravel()), "K1 is a 1-D array of shape (6,)"),
        ((H, T, [[1, 2], [3]]), "K1 could not be read as a matrix of numbers"),
        ((H, T, "K1"), "K1 must hold numbers, got text"),
        ((None, T, K1), "H is missing"),
        ((H, T, K1 * 1j), "K1 has complex entries"),
        ((H, T, np.full((3, 2), np.nan)), "K1[0, 0] is nan"),
        ((H, T, K1, F[:, :2]), "F has shape (3, 2)"),
    ],
)
def test_wrong_shapes_and_types_are_explained(args, message):
    result = checks.pa9_design(*args)
    assert not result.passed
    assert message in failures_text(result)


def test_a_wrong_call_gives_a_message_not_a_traceback():
    result = checks.pa9_design(H, T, K1, k2=K2)
    assert not result.passed
    assert "unexpected keyword argument 'k2'" in failures_text(result)
    result = checks.pa9_design(H, T, K1, plant="pa9")
    assert "plant must be a uio_teach.Plant" in failures_text(result)


def test_design_of_a_discrete_plant_uses_the_unit_disk():
    plant = ut.examples.dt_case_study()
    pmo = ut.design_pmo(plant, method="lmi")
    # the case study's M and L play the roles of H and K1
    result = checks.pa9_design(pmo.M, pmo.projection, pmo.L, pmo.F, pmo.F @ pmo.M, plant=plant)
    assert result.passed, str(result)
    assert "inside the unit circle" in result.messages[-1]


# pa9_simulation -------------------------------------------------------------------------------


def test_simulation_passes_for_a_uio(sine_response):
    result = checks.pa9_simulation(sine_response)
    assert result.passed, str(result)
    assert any("does not depend on d" in m for m in result.messages)


def test_luenberger_observer_fails_the_decoupling_test():
    luen = ut.design_luenberger(PLANT, poles=[-1, -2, -3])
    resp = ut.simulate(PLANT, luen, TIME, d=SINE, initial_state=X0)
    result = checks.pa9_simulation(resp)
    assert "the error depends on d" in failures_text(result)
    assert "Luenberger observer, which ignores d" in failures_text(result)
    assert "the disturbance keeps driving it" in failures_text(result)


def test_simulation_without_disturbance_or_initial_error(uio):
    result = checks.pa9_simulation(ut.simulate(PLANT, uio, TIME, initial_state=X0))
    assert "d is zero during the whole simulation" in failures_text(result)
    result = checks.pa9_simulation(ut.simulate(PLANT, uio, TIME, d=SINE))
    assert "the error is zero at t = 0" in failures_text(result)


def test_too_short_a_simulation_says_how_long(uio):
    resp = ut.simulate(PLANT, uio, np.linspace(0, 1, 101), d=SINE, initial_state=X0)
    result = checks.pa9_simulation(resp)
    assert "has not decayed yet" in failures_text(result)
    assert "simulate longer" in failures_text(result)


def test_simulation_with_a_piecewise_disturbance_is_redirected(steps_response):
    result = checks.pa9_simulation(steps_response)
    assert "d is piecewise constant, not a sinusoid" in failures_text(result)


def test_simulation_with_noise_is_refused(uio):
    resp = ut.simulate(PLANT, uio, TIME, d=SINE, initial_state=X0, noise=0.01, seed=1)
    assert "measurement noise" in failures_text(checks.pa9_simulation(resp))


def test_unstable_observer_is_blamed_for_the_growing_error():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ut.UnstableObserverWarning)
        bad = ut.design_uio(PLANT, poles=[0.5, -2, -3])
    resp = ut.simulate(PLANT, bad, TIME, d=SINE, initial_state=X0)
    assert "unstable (pole(s) 0.5)" in failures_text(checks.pa9_simulation(resp))


@pytest.mark.parametrize("thing", [None, np.zeros((3, 10)), "resp"])
def test_simulation_needs_a_response(thing):
    result = checks.pa9_simulation(thing)
    assert "must be the result of ut.simulate" in failures_text(result)


# pa9_piecewise --------------------------------------------------------------------------------


def test_piecewise_passes_and_matches_the_sinusoid(steps_response, sine_response):
    result = checks.pa9_piecewise(steps_response, sinusoidal=sine_response)
    assert result.passed, str(result)
    assert any("same as with the sinusoidal disturbance" in m for m in result.messages)
    alone = checks.pa9_piecewise(steps_response)
    assert alone.passed and any("pass sinusoidal=" in m for m in alone.messages)


def test_piecewise_needs_jumps(uio, sine_response):
    assert "not piecewise constant" in failures_text(checks.pa9_piecewise(sine_response))
    const = ut.simulate(PLANT, uio, TIME, d=ut.signals.step(1.0), initial_state=X0)
    assert "needs jumps" in failures_text(checks.pa9_piecewise(const))


def test_piecewise_comparison_needs_the_same_start_and_grid(uio, sine_response):
    other = ut.simulate(PLANT, uio, TIME, d=STEPS, initial_state=[0.0, 1.0, 0.0])
    result = checks.pa9_piecewise(other, sinusoidal=sine_response)
    assert "start the plant from different states" in failures_text(result)
    other = ut.simulate(PLANT, uio, np.linspace(0, 10, 501), d=STEPS, initial_state=X0)
    result = checks.pa9_piecewise(other, sinusoidal=sine_response)
    assert "different time points" in failures_text(result)


def test_piecewise_with_a_luenberger_observer_differs_from_the_sinusoid():
    luen = ut.design_luenberger(PLANT, poles=[-1, -2, -3])
    sine = ut.simulate(PLANT, luen, TIME, d=SINE, initial_state=X0)
    steps = ut.simulate(PLANT, luen, TIME, d=STEPS, initial_state=X0)
    result = checks.pa9_piecewise(steps, sinusoidal=sine)
    assert "the error depends on d" in failures_text(result)
    assert "differs from the sinusoidal test" in failures_text(result)


# pa9_plot -------------------------------------------------------------------------------------


def good_figure(resp, y_error="error e", y_residual="residual r") -> Figure:
    fig = Figure(figsize=(8, 5))
    ax_e, ax_r = fig.subplots(2, 1, sharex=True)
    ax_e.plot(resp.time, resp.error.T)
    ax_e.set_ylabel(y_error)
    ax_r.plot(resp.time, resp.residual.T)
    ax_r.set_ylabel(y_residual)
    ax_r.set_xlabel("time (s)")
    return fig


def test_plot_passes_on_a_labelled_figure(sine_response):
    fig = good_figure(sine_response)
    assert checks.pa9_plot(fig).passed
    result = checks.pa9_plot(fig, response=sine_response)
    assert result.passed, str(result)
    assert checks.pa9_plot(fig.axes).passed  # axes are accepted too


def test_plot_accepts_math_labels(sine_response):
    fig = good_figure(sine_response, "$e_i(t)$", "$r_j(t)$")
    assert checks.pa9_plot(fig, sine_response).passed


def test_plot_without_labels_fails(sine_response):
    fig = Figure()
    ax = fig.subplots()
    ax.plot(sine_response.time, sine_response.error.T)
    result = checks.pa9_plot(fig)
    text = failures_text(result)
    assert "one axes with curves; e and r belong in two panels" in text
    assert "axes 1 has no x-label" in text


def test_plot_with_a_non_time_x_label_fails(sine_response):
    fig = good_figure(sine_response)
    fig.axes[1].set_xlabel("x1")
    assert "does not say it is time" in failures_text(checks.pa9_plot(fig))


def test_plot_of_the_states_instead_of_the_error(sine_response):
    fig = Figure()
    ax_e, ax_r = fig.subplots(2, 1, sharex=True)
    ax_e.plot(sine_response.time, sine_response.states.T)
    ax_e.set_ylabel("error e")
    ax_r.plot(sine_response.time, sine_response.outputs.T)
    ax_r.set_ylabel("residual r")
    ax_r.set_xlabel("time (s)")
    result = checks.pa9_plot(fig, response=sine_response)
    assert checks.pa9_plot(fig).passed  # the labels alone look right ...
    text = failures_text(result)  # ... but the curves are x and y
    assert "the error panel shows the states x (resp.states)" in text
    assert "the residual panel shows the outputs y (resp.outputs)" in text


def test_plot_with_missing_components(sine_response):
    fig = good_figure(sine_response)
    fig.axes[0].lines[1].remove()
    result = checks.pa9_plot(fig, response=sine_response)
    assert "the error panel lacks some error components: e2." in failures_text(result)


@pytest.mark.parametrize("thing", [3, "figure"])
def test_plot_needs_a_figure(thing):
    assert "fig must be a matplotlib figure" in failures_text(checks.pa9_plot(thing))


def test_plot_of_none_says_the_figure_is_missing():
    assert "fig is missing (None)" in failures_text(checks.pa9_plot(None))


def test_empty_figure_fails():
    assert "the figure has no curves" in failures_text(checks.pa9_plot(Figure()))


def test_the_package_figure_passes(sine_response):
    fig = sine_response.plot()
    try:
        result = checks.pa9_plot(fig, response=sine_response)
        assert result.passed, str(result)
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_stacked_axes_need_only_the_bottom_x_label(sine_response):
    fig = Figure()
    ax_e, ax_r = fig.subplots(2, 1)  # not shared, but one column over the same time range
    ax_e.plot(sine_response.time, sine_response.error.T)
    ax_e.set_ylabel("error e")
    ax_r.plot(sine_response.time, sine_response.residual.T)
    ax_r.set_ylabel("residual r")
    ax_r.set_xlabel("time (s)")
    assert checks.pa9_plot(fig).passed
    ax_e.set_xlim(0, 5)  # a different time range needs its own label
    assert "axes 1 (error) has no x-label" in failures_text(checks.pa9_plot(fig))


# no traceback, whatever a group passes -----------------------------------------------------------

GARBAGE = [None, "H", 3, [[1, 2], [3]], {"a": 1}, np.zeros((7, 7)), object()]
CHECK_CALLS = {
    "pa9_design": lambda x: checks.pa9_design(x, x, x, x, x, plant=PLANT, poles=[-1, -2, -3]),
    "pa9_simulation": lambda x: checks.pa9_simulation(x, H=x, K1=x, plant=PLANT),
    "pa9_plot": lambda x: checks.pa9_plot(x, x, plant=PLANT),
    "pa9_piecewise": lambda x: checks.pa9_piecewise(x, x, plant=PLANT),
    "pa9_piecewise_plot": lambda x: checks.pa9_piecewise_plot(x, x),
    "case_study_projection": lambda x: checks.case_study_projection(x),
    "case_study_lmi": lambda x: checks.case_study_lmi(x, x, Y=x),
    "case_study_pole": lambda x: checks.case_study_pole(x, 0.3),
    "case_study_simulation": lambda x: checks.case_study_simulation(x, observer=x),
    "case_study_residual": lambda x: checks.case_study_residual(x, x, x),
    "case_study_plot": lambda x: checks.case_study_plot(x, x),
    "missile_pmo": lambda x: checks.missile_pmo(x, x, x, poles=[-100, -120]),
    "missile_ginverse": lambda x: checks.missile_ginverse(x, x, x),
    "missile_reconstruction": lambda x: checks.missile_reconstruction(x, x, observer=x),
    "missile_catch_times": lambda x: checks.missile_catch_times(x, x, x),
    "missile_noise": lambda x: checks.missile_noise(x, x, sigma=0.01),
    "missile_plot": lambda x: checks.missile_plot(x, x),
}


def test_every_public_check_is_exercised_here():
    public = {n for n in checks.__all__ if n.startswith(("pa9_", "case_study_", "missile_"))}
    assert public == set(CHECK_CALLS)


@pytest.mark.parametrize("name", list(CHECK_CALLS))
@pytest.mark.parametrize("garbage", range(len(GARBAGE)))
def test_garbage_gets_a_cross_not_a_traceback(name, garbage):
    result = CHECK_CALLS[name](GARBAGE[garbage])
    assert isinstance(result, checks.CheckResult)
    assert not result.passed and result.failures
    assert result.check_id == getattr(checks, name).check_id


@pytest.mark.parametrize(
    ("exc", "cause"),
    [
        (ValueError("matmul: Input operand 1 has a mismatch in its core dimension"), "wrong size"),
        (ValueError("could not convert string to float: 'x'"), "text where numbers"),
        (AttributeError("'PMO' object has no attribute 'time'"), "not the kind of object"),
        (TypeError("unsupported operand type(s)"), "of the wrong type"),
        (np.linalg.LinAlgError("Singular matrix"), "singular"),
    ],
)
def test_an_exception_is_named_by_its_likely_cause(exc, cause):
    assert cause in likely_cause(exc)


def test_a_raising_check_names_the_cause_in_its_cross():
    @never_raises("demo", check_id="demo.shape")
    def check(x):
        return checks.CheckResult(
            "demo", [(bool(np.ones((2, 3)) @ np.asarray(x) is not None), "ok")]
        )

    result = check(np.ones(4))
    assert result.failures[0].startswith("the check could not read your answer: a matrix")
    assert result.check_id == "demo.shape"


# the lab chapters call every check on the set-up cell's plant -------------------------------------

BOOK = Path(__file__).resolve().parent.parent / "book"


def check_calls(text: str) -> list[str]:
    """The text of every ``checks.<name>(...)`` call in the code cells of a chapter."""
    calls = []
    for cell in re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, flags=re.S):
        for start in re.finditer(r"\bchecks\.\w+\(", cell):
            depth, i = 1, start.end()
            while depth:
                depth += {"(": 1, ")": -1}.get(cell[i], 0)
                i += 1
            calls.append(cell[start.start() : i])
    return calls


@pytest.mark.parametrize("chapter", ["lab_pa9.md", "lab_case_study.md", "lab_missile.md"])
def test_every_check_cell_passes_the_set_up_plant(chapter):
    calls = check_calls((BOOK / chapter).read_text(encoding="utf-8"))
    assert len(calls) >= 5
    assert [c for c in calls if "plant=plant" not in c] == []
    assert all("PARAMS" in c or "poles" not in c for c in calls)


def test_a_rounded_projection_matrix_is_named_with_its_decimals_on_a_groups_plant():
    # the hint names the rounding, not "the printed M": a group's own M is printed nowhere
    # (the book's M, [[-0.5, 2.5]] in every row, is exact in decimals)
    plant = ut.experiments.plant_from_params(
        "case_study", {"plant": {"D": [[0.3], [1.0]], "E": [[2.0], [1.0], [2.0]]}}
    )
    E, D = plant.E, plant.D
    exact = np.hstack([E, np.zeros_like(E)]) @ np.linalg.pinv(np.hstack([plant.C @ E, D]))
    for k in (4, 2):
        result = checks.case_study_projection(np.round(exact, k), plant)
        assert f"rounded to {k} decimals" in failures_text(result), str(result)
    assert checks.case_study_projection(exact, plant).passed


# hints name the real cause, in the exercise's own terms ------------------------------------------


def test_a_gain_placed_by_hand_is_never_asked_about_an_lmi():
    placed = ut.design_pmo(ut.examples.dt_case_study(), poles=[0.3])
    result = checks.case_study_pole(placed.L + 0.1, 0.3)
    (ld,) = [m for m in result.failures if m.startswith("LD is not 0")]
    assert "LMI" not in ld and "L = l N" in ld
    lmi = ut.design_pmo(ut.examples.dt_case_study(), method="lmi")
    P = lmi.lmi_certificate
    result = checks.case_study_lmi(lmi.L + 0.1, P, Y=P @ (lmi.L + 0.1))
    (ld,) = [m for m in result.failures if m.startswith("LD is not 0")]
    assert "is it in your LMI?" in ld


def test_l_and_p_of_one_solve_are_not_asked_whether_they_are_of_one_solve():
    lmi = ut.design_pmo(ut.examples.dt_case_study(), method="lmi")
    P = lmi.lmi_certificate
    result = checks.case_study_lmi(lmi.L, P, Y=P @ lmi.L, margin=10.0)
    (failure,) = result.failures
    assert "same solve" not in failure and "lacks the margin" in failure
