"""The reusable drawing: names and labels, and panels that show exactly the simulated data."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import uio_teach as ut  # noqa: E402
from uio_teach import plotting  # noqa: E402
from uio_teach.experiments import CASE_STUDY, PA9  # noqa: E402


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
    assert {plotting.symbol("x", i) for i in range(3)} <= labels
