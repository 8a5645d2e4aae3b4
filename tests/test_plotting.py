"""The reusable drawing: names and labels, and panels that show exactly the simulated data."""

from __future__ import annotations

import re

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from tolerance import assert_same_run

import uio_teach as ut  # noqa: E402
from uio_teach import plotting  # noqa: E402
from uio_teach.worked.case_study import CASE_STUDY  # noqa: E402
from uio_teach.worked.missile import MISSILE  # noqa: E402
from uio_teach.worked.pa9 import PA9  # noqa: E402


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
        assert line.get_linestyle() == ax_e.lines[j].get_linestyle()
        np.testing.assert_array_equal(line.get_ydata(), resp.error[j])  # drawn as computed
    # a row that mixes states gets a colour no error channel has
    colours = plotting.residual_colors(ut.examples.dt_case_study().C)
    states = {plotting.channel_style(i)["color"] for i in range(3)}
    assert colours[0] not in states and colours[1] == plotting.channel_style(0)["color"]


def test_rounding_noise_is_drawn_on_zero_and_named():
    plant = MISSILE.plant()
    resp = MISSILE.simulate(ut.design_pmo(plant, poles=MISSILE.poles), observer_state=None)
    peak = float(np.max(np.abs(resp.residual)))
    assert 0 < peak  # rounding noise, not an exact zero
    assert_same_run(resp.residual, 0, resp)  # r = Ce is zero to rounding
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


def test_bank_figure_draws_every_member_over_its_threshold_with_legible_text():
    """One panel per run, one legend, each curve J / threshold, no text under 9 px on the page."""
    from fault_bank import bank_setting

    s = bank_setting()
    plant, detector, t, banks, healthy, ths = (
        s.plant,
        s.detector,
        s.t,
        s.banks,
        s.healthy,
        s.thresholds,
    )
    fault = ut.sensor_fault(plant, 0, ut.signals.step(0.3, 3.0))
    runs = {"sensor 1": ut.simulate_fault(plant, detector, t, fault, noise=0.01, seed=99)}
    runs["no fault"] = healthy[0]
    runs["again"] = healthy[1]
    fig = plotting.plot_bank_alarms(t, runs, banks, ths, fault_time=3.0, fig=plotting.new_figure())
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 3 and len(fig.legends) == 1
    assert all(ax.get_legend() is None for ax in visible)
    members = [m for bank in banks for m in bank.members]
    legend = [text.get_text() for text in fig.legends[0].get_texts()]
    assert legend == [f"blind to {m.fault}" for m in members] + ["alarm level (J = threshold)"]
    # the curves are J / threshold of each member, in the order of the legend
    ax = visible[0]
    curves = [line for line in ax.get_lines() if line.get_label().startswith("blind to")]
    residuals = [r for bank in banks for r in bank.residuals(runs["sensor 1"])]
    for line, r, th in zip(curves, residuals, [th for g in ths for th in g], strict=True):
        expected = ut.residual_rms(t, r, th.window) / th.value
        np.testing.assert_allclose(line.get_ydata(), expected)
    assert ax.get_title() == "fault: sensor 1" and visible[1].get_title() == "no fault"
    # legible: the book shows the 9-inch figure (911 px at 100 dpi) in its 688 px column
    fig.set_size_inches(9, fig.get_size_inches()[1])
    scale = 688 / 911
    texts = [t_ for ax in visible for t_ in (ax.title, ax.xaxis.label, ax.yaxis.label)]
    texts += [lab for ax in visible for lab in ax.get_xticklabels() + ax.get_yticklabels()]
    texts += list(fig.legends[0].get_texts())
    sizes_px = [text.get_fontsize() * 100 / 72 * scale for text in texts if text.get_text()]
    assert min(sizes_px) >= 9, min(sizes_px)


@pytest.mark.slow  # every course figure drawn
def test_every_course_figure_is_clear_of_its_legends_described_and_apart_without_colour():
    """No legend covers a curve; the figure says in words what it shows (not a file name, and
    what the reader should see: how the error ends); no two curves of a panel differ by hue
    alone for a reader with deuteranopia, protanopia or tritanopia."""
    import matplotlib

    from uio_teach.colour_vision import curves_apart_by_hue_alone
    from uio_teach.instructor import figures

    config = figures.FigureConfig()
    runs = figures._Runs(config)
    drawn = [name for name, spec in figures.FIGURES.items() if not spec.table]
    assert drawn
    for name in drawn:
        with matplotlib.style.context(config["style"]):
            fig = figures.FIGURES[name].draw(runs)
        assert any(ax.get_legend() for ax in fig.axes) or fig.legends or name.endswith("zeros")
        assert plotting.covered_curves(fig) == [], name
        said = plotting.description(fig)
        assert said is not None and len(said.alt.split()) >= 20, (name, said)
        assert name not in said.alt and ".png" not in said.alt, said.alt
        if not name.endswith("zeros"):
            assert re.search(r"decays to zero|does not settle|zero to rounding", said.alt), said
        assert curves_apart_by_hue_alone(fig) == [], name


def test_the_legend_check_sees_a_legend_over_a_curve():
    fig = plotting.new_figure()
    ax = fig.subplots()
    ax.plot([0, 1], [1, 1], label="top", drawstyle="steps-post")
    ax.plot([0, 1], [0, 0], label="bottom")
    ax.legend(loc="upper right")
    assert plotting.covered_curves(fig) == [("top", "top")]
    plotting.legend_beside(ax)
    assert plotting.covered_curves(fig) == []
