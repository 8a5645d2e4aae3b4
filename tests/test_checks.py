"""The lab checks: they pass on a right answer and name each kind of mistake, never raising."""

import warnings

import numpy as np
import pytest
from matplotlib.figure import Figure

import uio_teach as ut
from uio_teach import checks
from uio_teach.checks import CheckResult

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


def test_any_decoupling_H_is_accepted():
    # H = C^+ also satisfies (I - HC)E = 0 here, since E has no x2 component
    Hc = np.linalg.pinv(C)
    result = checks.pa9_design(Hc, np.eye(3) - Hc @ C, np.zeros((3, 2)))
    assert "(I - HC)E = 0" in result.messages[0] and result.items[0][0] is True


def test_wrong_H_is_named():
    result = checks.pa9_design(np.zeros((3, 2)), np.eye(3), K1)
    assert not result.passed
    assert "H does not satisfy (I - HC)E = 0" in result.failures[0]
    assert "np.linalg.pinv(C @ E)" in result.failures[0]


def test_printed_two_decimal_matrices_are_explained():
    pub = ut.examples.PA9_PUBLISHED
    result = checks.pa9_design(pub.H, pub.T, pub.K1, pub.F, pub.K2)
    assert not result.passed
    assert "chopped" in result.failures[0]
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
        "e' = F e does not decay. Choose K1 so that TA - K1C has the poles you want, e.g. "
        "K1 = ct.place((T @ A).T, C.T, [-1, -2, -3]).T."
    ]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((H.T, T, K1), "H has shape (2, 3) but must be a 3 x 2 matrix"),
        ((H.T, T, K1), "It looks transposed: use H.T."),
        ((H, T[:2], K1), "T has shape (2, 3) but must be a 3 x 3 matrix"),
        ((H, T, K1.ravel()), "K1 is a 1-D array of shape (6,)"),
        ((H, T, [[1, 2], [3]]), "K1 could not be read as a matrix of numbers"),
        ((H, T, "K1"), "K1 must hold numbers, got 'K1'"),
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
    assert "at least one jump" in failures_text(checks.pa9_piecewise(const))


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
