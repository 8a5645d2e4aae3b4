"""The reusable drawing: names and labels, and panels that show exactly the simulated data."""

from __future__ import annotations

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import uio_teach as ut  # noqa: E402
from uio_teach import plotting  # noqa: E402
from uio_teach.experiments import CASE_STUDY, MISSILE, PA9  # noqa: E402


def test_names_and_labels():
    assert plotting.symbol("e", 0) == "$e_{1}$"
    assert plotting.symbol("v", 1, hat=True) == r"$\hat{v}_{2}$"
    assert plotting.axis_label("residual") == r"residual $r = y - C\hat{x}$"
    assert plotting.axis_label("input", "v") == r"$v$ and $\hat{v}$"
    with pytest.raises(ValueError, match="what must be 'error', 'residual' or 'input'"):
        plotting.axis_label("errors")
    assert plotting.time_label(True) == "step k" and plotting.time_label(None) == "time (s)"


@pytest.mark.parametrize("experiment", [PA9, CASE_STUDY], ids=["pa9", "case-study"])
def test_error_and_residual_panels_show_the_response(experiment):
    plant = experiment.plant()
    obs = (
        ut.design_uio(plant, poles=experiment.poles)
        if experiment is PA9
        else ut.design_pmo(plant, method="lmi")
    )
    resp = experiment.simulate(obs)
    fig = plotting.new_figure()
    ax_e, ax_r = fig.subplots(2)
    plotting.plot_error(ax_e, resp)
    plotting.plot_residual(ax_r, resp)
    for ax, values, letter in ((ax_e, resp.error, "e"), (ax_r, resp.residual, "r")):
        assert [line.get_label() for line in ax.lines] == [
            plotting.symbol(letter, i) for i in range(values.shape[0])
        ]
        for line, row in zip(ax.lines, values, strict=True):
            np.testing.assert_array_equal(line.get_ydata(), row)
            assert line.get_drawstyle() == ("steps-post" if plant.is_discrete else "default")
    assert ax_e.get_ylabel() == plotting.axis_label("error")
    assert ax_r.get_legend() is not None


def test_the_standard_figure_uses_the_same_panels():
    resp = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles))
    fig = plotting.plot_response(resp)
    labels = {ax.get_ylabel() for ax in fig.axes}
    assert {plotting.axis_label("error"), plotting.axis_label("residual")} <= labels
    assert {plotting.with_unit(plotting.symbol("x", i)) for i in range(3)} <= labels


def test_a_residual_channel_has_the_colour_of_the_state_it_measures():
    resp = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles))
    fig = plotting.new_figure()
    ax_e, ax_r = fig.subplots(2)
    plotting.plot_error(ax_e, resp)
    plotting.plot_residual(ax_r, resp)
    C = PA9.plant().C
    for i, line in enumerate(ax_r.lines):
        (j,) = np.flatnonzero(C[i])  # PA9 measures x1 and x3: r1 = e1, r2 = e3
        assert line.get_color() == ax_e.lines[j].get_color()
        np.testing.assert_allclose(line.get_ydata(), resp.error[j], atol=1e-12)
    # a row that mixes states gets a colour no error channel has
    colours = plotting.residual_colors(ut.examples.dt_case_study().C)
    assert colours[0] not in {f"C{i}" for i in range(3)} and colours[1] == "C0"


def test_rounding_noise_is_drawn_on_zero_and_named():
    plant = MISSILE.plant()
    resp = MISSILE.simulate(ut.design_pmo(plant, poles=MISSILE.poles), observer_state=None)
    peak = float(np.max(np.abs(resp.residual)))
    assert 0 < peak < 1e-9 * np.max(np.abs(resp.outputs))  # r = Ce is zero to rounding
    ax_r = plotting.new_figure().subplots()
    plotting.plot_residual(ax_r, resp)
    low, high = ax_r.get_ylim()
    assert high - low >= 2e-3 * np.max(np.abs(resp.outputs))  # noise is not blown up
    assert any("zero to rounding" in text.get_text() for text in ax_r.texts)
    ax_e = plotting.new_figure().subplots()
    plotting.plot_error(ax_e, resp)  # a real error keeps its automatic range and says nothing
    assert not ax_e.texts
    assert ax_e.get_ylim()[1] - ax_e.get_ylim()[0] < 10 * np.ptp(resp.error)


def test_axes_say_steps_and_units():
    resp = CASE_STUDY.simulate(ut.design_pmo(CASE_STUDY.plant(), method="lmi"))
    fig = plotting.plot_response(resp)
    assert {ax.get_xlabel() for ax in fig.axes} - {""} == {"step k"}  # dt = 1: steps
    states = [ax.get_ylabel() for ax in fig.axes if ax.get_ylabel().startswith("$x")]
    assert states == [plotting.with_unit(plotting.symbol("x", i)) for i in range(3)]
    assert all(label.endswith("(model units)") for label in states)
    assert plotting.time_label(0.1) == "time (s)" and plotting.time_label(1.0) == "step k"


def test_the_course_figures_follow_the_same_conventions():
    from uio_teach.instructor import figures

    runs = figures._Runs(figures.FigureConfig())
    fig = figures.FIGURES["missile_error"].draw(runs)
    # the PMO starts from xhat(0) = 0: its errors on x1, x2 are real, so no panel says "zero"
    assert not any(ax.texts for ax in fig.axes)
    assert all(ax.get_ylabel().endswith("(model units)") for ax in fig.axes)
    fig = figures.FIGURES["pa9_sine"].draw(runs)
    ax_d, ax_e, ax_r = fig.axes
    assert ax_d.get_ylabel() == "disturbance $d$ (model units)"
    assert ax_r.lines[1].get_color() == ax_e.lines[2].get_color()  # r2 = e3
    fig = figures.FIGURES["case_response"].draw(runs)
    assert {ax.get_xlabel() for ax in fig.axes} - {""} == {"step k"}
