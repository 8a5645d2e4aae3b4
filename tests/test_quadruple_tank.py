"""The quadruple-tank process (Johansson 2000): the paper's numbers, the valves, the UIO."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import uio_teach as ut
from uio_teach.examples import QUADRUPLE_TANK_PUBLISHED, quadruple_tank, tank_time_constants
from uio_teach.explorers import compute_frame, scenario_of
from uio_teach.instructor import figures
from uio_teach.instructor.config import ConfigError, FigureConfig, config_schema
from uio_teach.worked.quadruple_tank import QUADRUPLE_TANK, valve_verdict

EPS = np.finfo(float).eps
SETTINGS = list(QUADRUPLE_TANK_PUBLISHED)


def _closed_form_zeros(T3: float, T4: float, g1: float, g2: float) -> np.ndarray:
    """Roots of (1 + s T3)(1 + s T4) = (1 - g1)(1 - g2) / (g1 g2), the paper's eq. for the zeros."""
    eta = (1 - g1) * (1 - g2) / (g1 * g2)
    return np.sort(np.roots([T3 * T4, T3 + T4, 1 - eta]).real)


def _zeros(plant) -> np.ndarray:
    return np.sort(ut.check_existence(plant).invariant_zeros.real)


@pytest.mark.parametrize("setting", SETTINGS)
def test_time_constants_are_the_papers(setting):
    """T_i = (A_i/a_i) sqrt(2 h_i0/g) from the printed data, printed in whole seconds.

    Every printed T is the computed one rounded, except T3 of P-: 23.89 s printed as 23
    (truncated); so the printed value is the rounded or the truncated one.
    """
    pub = QUADRUPLE_TANK_PUBLISHED[setting]
    T = tank_time_constants(setting)
    for computed, printed in zip(T, pub.T, strict=True):
        assert printed in (round(computed), math.floor(computed)), (computed, printed)
    A = quadruple_tank(setting).A
    assert np.allclose(-1 / np.diag(A), T, rtol=4 * EPS, atol=0)


def test_the_plants_matrices_follow_the_papers_linearization():
    pub = QUADRUPLE_TANK_PUBLISHED["P-"]
    plant = quadruple_tank("P-")
    T = tank_time_constants("P-")
    (A1, A2, A3, A4), (k1, k2), (g1, g2) = pub.A, pub.k, pub.gamma
    assert plant.A[0, 2] == pytest.approx(A3 / (A1 * T[2]), rel=4 * EPS)
    assert plant.A[1, 3] == pytest.approx(A4 / (A2 * T[3]), rel=4 * EPS)
    expected_E = [
        [g1 * k1 / A1, 0],
        [0, g2 * k2 / A2],
        [0, (1 - g2) * k2 / A3],
        [(1 - g1) * k1 / A4, 0],
    ]
    assert np.allclose(plant.E, expected_E, rtol=4 * EPS, atol=0)
    assert np.array_equal(plant.C, [[pub.kc, 0, 0, 0], [0, pub.kc, 0, 0]])
    assert (plant.m, plant.q, plant.p, plant.nv) == (0, 2, 2, 0)


@pytest.mark.parametrize("setting", SETTINGS)
def test_zeros_are_the_closed_form_ones(setting):
    pub = QUADRUPLE_TANK_PUBLISHED[setting]
    _, _, T3, T4 = tank_time_constants(setting)
    want = _closed_form_zeros(T3, T4, *pub.gamma)
    got = _zeros(quadruple_tank(setting))
    # the zeros of a 4-state pencil whose data are of size |A|: round-off ~ n eps |A| / gap
    A = quadruple_tank(setting).A
    gap = abs(want[1] - want[0])
    tol = 100 * 4 * EPS * np.linalg.norm(A, 2) * max(1.0, np.linalg.norm(A, 2) / gap)
    assert np.allclose(got, want, rtol=0, atol=tol)


@pytest.mark.parametrize("setting", SETTINGS)
def test_the_printed_zeros_agree_with_the_printed_time_constants(setting):
    """The zeros move with T3 and T4 only; printed in whole seconds (rounded, or truncated:
    T in [T - 0.5, T + 1)), they span an interval that holds the printed zeros (to their 3
    decimals) and ours."""
    pub = QUADRUPLE_TANK_PUBLISHED[setting]
    corners = np.array(
        [
            _closed_form_zeros(pub.T[2] + d3, pub.T[3] + d4, *pub.gamma)
            for d3, d4 in itertools.product((-0.5, 1.0), repeat=2)
        ]
    )
    low, high = corners.min(axis=0), corners.max(axis=0)
    half = 0.5 * 10.0**-pub.decimals
    printed = np.sort(pub.zeros)
    assert np.all(printed + half >= low) and np.all(printed - half <= high), (low, high)
    ours = _zeros(quadruple_tank(setting))
    assert np.all((ours >= low) & (ours <= high)), (ours, low, high)
    # the paper's 3 decimals, where the data pin them down: P+ reproduces them exactly
    if setting == "P+":
        assert np.array_equal(np.round(ours, 3), printed)


def test_the_verdict_flips_between_the_settings():
    minus = ut.check_existence(quadruple_tank("P-"))
    plus = ut.check_existence(quadruple_tank("P+"))
    assert minus.ok and minus.movable == 2 and np.all(minus.invariant_zeros.real < 0)
    assert not plus.ok and plus.movable == 2
    assert np.sum(plus.invariant_zeros.real > 0) == 1
    assert plus["invariant zeros stable"].holds is False and plus["rank condition"].holds


@pytest.mark.parametrize("ratio", [1.0, 0.6 / 0.7, 0.34 / 0.43, 1.7])
@pytest.mark.parametrize("delta", [1e-2, 1e-4, 1e-6])
def test_the_verdict_flips_at_gamma1_plus_gamma2_equal_one(ratio, delta):
    """Along gamma2 = ratio gamma1: a UIO exists just above the line, none just below."""

    def plant(total):
        g1 = total / (1 + ratio)
        return quadruple_tank(gamma1=g1, gamma2=ratio * g1)

    above, below = ut.check_existence(plant(1 + delta)), ut.check_existence(plant(1 - delta))
    assert above.ok and not below.ok
    # the zero that crosses is of the size of delta (it passes the origin linearly)
    crossing = [np.max(r.invariant_zeros.real) for r in (above, below)]
    assert crossing[0] < 0 < crossing[1]
    assert max(abs(z) for z in crossing) < 10 * delta


def test_on_the_line_no_uio_and_the_report_says_round_off_decides():
    report = ut.check_existence(quadruple_tank(gamma1=0.5, gamma2=0.5))
    assert not report.ok
    assert "round-off" in str(report)
    assert "origin" in valve_verdict(0.5, 0.5)


def test_the_uio_ignores_the_pumps():
    """The defining property: the estimation error does not depend on the unknown inputs."""
    plant = QUADRUPLE_TANK.plant()
    uio = ut.design_uio(plant, poles=QUADRUPLE_TANK.poles)
    loud = QUADRUPLE_TANK.simulate(uio)
    quiet = QUADRUPLE_TANK.simulate(uio, d=None)
    assert np.max(np.abs(loud.inputs.d)) > 0.25
    scale = np.max(np.abs(loud.states))
    assert np.max(np.abs(loud.error - quiet.error)) <= 1e3 * EPS * scale * loud.time.size
    luen = ut.design_luenberger(plant, poles=[-0.1, -0.2, -0.3, -0.4])
    drift = QUADRUPLE_TANK.simulate(luen).error - QUADRUPLE_TANK.simulate(luen, d=None).error
    assert np.max(np.abs(drift)) > 0.1  # an ordinary observer does feel them


@pytest.mark.parametrize("total", [1.3, 1.05, 1.01])
def test_near_the_line_the_uio_is_slow_whatever_its_poles(total):
    """The zero near the origin is an observer pole: its decay time grows as 1/(g1 + g2 - 1)."""
    g = total / 2
    plant = quadruple_tank(gamma1=g, gamma2=g)
    slow_zero = np.max(_zeros(plant))
    for poles in ([-0.1, -0.2], [-1.0, -2.0]):
        uio = ut.design_uio(plant, poles=poles)
        slowest = np.max(uio.poles().real)
        assert slowest == pytest.approx(slow_zero, rel=1e-6)
    # linear in the distance to the line, to first order: z ~ -4 (total - 1) / (T3 + T4)
    _, _, T3, T4 = tank_time_constants("P-")
    assert slow_zero == pytest.approx(-4 * (total - 1) / (T3 + T4), rel=0.5)


def test_bad_settings_and_valves_are_refused_in_words():
    with pytest.raises(ValueError, match=r"setting must be one of 'P-', 'P\+', got 'P0'"):
        quadruple_tank("P0")
    for bad in (0.0, 1.0, 1.2, -0.1, float("nan"), "0.5", True):
        with pytest.raises(ValueError, match="gamma1 must"):
            quadruple_tank(gamma1=bad)


def test_the_config_section_and_its_verdict():
    schema = config_schema()
    for key in ("gamma1", "gamma2", "poles", "pump1.step", "pump2.frequency", "initial_state"):
        assert f"quadruple_tank.{key}" in schema
    assert FigureConfig()["quadruple_tank.gamma1"] == 0.7
    with pytest.raises(ConfigError) as err:
        FigureConfig.from_dict({"quadruple_tank": {"gamma1": 0.43, "gamma2": 0.34}})
    text = str(err.value)
    assert "quadruple_tank.gamma1 = 0.43" in text and "outside the open left half-plane" in text
    with pytest.raises(ConfigError, match=r"quadruple_tank.gamma2: must be <= 0.99"):
        FigureConfig.from_dict({"quadruple_tank": {"gamma2": 1.0}})


def test_the_figures_are_registered():
    assert {"tank_error", "tank_zeros"} <= set(figures.FIGURES)


def test_the_explorer_says_when_no_uio_exists_and_why():
    good = compute_frame(scenario_of("quadruple_tank"))
    assert good.observer_message == "" and good.poles.size == 4
    bad_scenario = scenario_of("quadruple_tank", gamma1=0.43, gamma2=0.34)
    bad = compute_frame(bad_scenario)
    assert bad.observer_message.startswith("no UIO exists")
    assert "outside the open left half-plane" in bad.observer_message
    assert "0.77 < 1" in bad_scenario.note and "right half-plane" in bad_scenario.note
    # the Luenberger observer is still shown, and stable: no pole of it is the unstable zero
    assert bad.luenberger is not None and np.all(bad.luenberger_poles.real < 0)


def test_the_valve_sliders_of_the_live_explorer():
    pytest.importorskip("ipywidgets")
    from uio_teach.explorers import widgets

    ex = widgets.tank_explorer(static=False)
    assert {"gamma1", "gamma2"} <= set(ex.controls)
    assert ex.frame.observer_message == ""
    ex.set(gamma1=0.43, gamma2=0.34)
    assert ex.frame.observer_message.startswith("no UIO exists")
    assert "no UIO with a stable error exists" in ex.message.value
    ex.set(gamma1=0.7, gamma2=0.6)
    assert ex.frame.observer_message == "" and ex.frame.poles.size == 4
    ex.close()


def test_a_valve_moved_in_the_same_figure_draws_what_a_new_figure_draws():
    """The valve sliders keep the figure (a rebuild of every panel costs more than a third of
    the explorer): the picture is that of a figure built anew for the new plant, across the
    line where the zeros leave the left half-plane too."""
    from uio_teach.explorers import ExplorerFigure

    base = scenario_of("quadruple_tank")
    ef = ExplorerFigure(base, dpi=50)
    ef.update(compute_frame(base))
    ef.draw()
    for values in ({"gamma1": 0.43, "gamma2": 0.34}, {"gamma1": 0.9, "gamma2": 0.2}):
        moved = base.rebuild(**values)
        assert not np.allclose(moved.invariant_zeros, ef.scenario.invariant_zeros)
        assert ef.replace_scenario(moved)
        ef.update(compute_frame(moved))
        ef.draw()
        kept = np.asarray(ef.fig.canvas.buffer_rgba()).copy()
        new = ExplorerFigure(moved, dpi=50)
        new.update(compute_frame(moved))
        new.fig.canvas.draw()
        fresh = np.asarray(new.fig.canvas.buffer_rgba())
        for name, ax in ef.axes.items():  # the same ranges: chosen afresh for the new plant
            assert ax.get_ylim() == new.axes[name].get_ylim(), name
        zeros = ef._zeros.get_xydata()
        shown = np.sort_complex(zeros[:, 0] + 1j * zeros[:, 1])
        assert np.array_equal(shown, np.sort_complex(moved.invariant_zeros))
        # only the stacking of curves over the spines and the legends' antialiased edges differ
        assert np.any(kept != fresh, axis=-1).mean() < 0.005
    assert ef.full_draws == 1  # the valves redrew panels, never the whole figure


def test_a_scenario_of_another_shape_is_not_put_in_the_figure():
    from uio_teach.explorers import ExplorerFigure, scenario_of

    ef = ExplorerFigure(scenario_of("quadruple_tank"), dpi=50)
    before = ef.scenario
    assert not ef.replace_scenario(scenario_of("pa9"))
    assert ef.scenario is before


def test_the_static_explorer_slides_the_valve_across_the_line():
    from uio_teach.explorers.static import static_explorer

    scenario = scenario_of("quadruple_tank")
    assert scenario.static_plant_control.name == "gamma2"
    page = static_explorer(scenario, values=(0.2, 0.6), disturbances=("sinusoid",), narrow=False)
    below, above = page.frames
    assert below.caption.startswith("gamma1 + gamma2 = 0.9 < 1")
    assert "no UIO exists" in below.caption
    assert above.caption.startswith("gamma1 + gamma2 = 1.3 > 1") and "no UIO" not in above.caption
    assert below.png != above.png
    assert "gamma2 (gamma1 0.7)" in page.html


def test_at_the_unstable_end_of_the_pole_slider_the_error_grows_and_the_words_say_so():
    from uio_teach.explorers import error_grows

    scenario = scenario_of("quadruple_tank")
    p = scenario.pole_limits[1]
    assert p > 0
    frame = compute_frame(scenario, scenario.defaults.replace(poles=(p, -0.2)))
    assert error_grows(frame.response.error)
    assert "the error grows" in frame.observer_message
    shown = np.abs(frame.curves["uio.error"])
    N = shown.shape[1]
    assert shown[:, -N // 10 :].max() > 1.5 * shown[:, : N // 10].max()
