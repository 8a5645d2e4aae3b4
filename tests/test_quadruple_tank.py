"""The quadruple-tank process (Johansson 2000): the paper's numbers, the valves, the UIO."""

from __future__ import annotations

import numpy as np
import pytest
from tolerance import assert_rounding_close, assert_same_run, assert_zero, size_of

import uio_teach as ut
from uio_teach.examples import (
    QUADRUPLE_TANK_PUBLISHED,
    TANK_OUTLETS,
    quadruple_tank,
    tank_operating_point,
    tank_time_constants,
)
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


def _nonlinear(h, v, g1, g2, setting="P-"):
    """The paper's eq. (1), written out here on its own: dh/dt of the four tanks."""
    pub = QUADRUPLE_TANK_PUBLISHED[setting]
    A, a, g = np.asarray(pub.A), np.asarray(TANK_OUTLETS), pub.g
    (k1, k2), (v1, v2) = pub.k, v
    out = a * np.sqrt(2 * g * np.asarray(h, float))
    return np.array(
        [
            (-out[0] + out[2] + g1 * k1 * v1) / A[0],
            (-out[1] + out[3] + g2 * k2 * v2) / A[1],
            (-out[2] + (1 - g2) * k2 * v2) / A[2],
            (-out[3] + (1 - g1) * k1 * v1) / A[3],
        ]
    )


VALVES = [(0.7, 0.6), (0.43, 0.34), (0.0, 0.6), (0.7, 0.0), (0.0, 0.0), (0.95, 0.9), (0.5, 0.5)]


@pytest.mark.parametrize("setting", SETTINGS)
def test_time_constants_are_the_papers_to_the_printed_digits(setting):
    """T_i = (A_i/a_i) sqrt(2 h_i0/g) at the steady state of the setting's valves and pumps,
    rounded to whole seconds as printed; the plant's diagonal is -1/T."""
    pub = QUADRUPLE_TANK_PUBLISHED[setting]
    T = tank_time_constants(setting)
    assert np.array_equal(np.round(T), pub.T), (T, pub.T)
    A = quadruple_tank(setting).A
    assert np.allclose(-1 / np.diag(A), T, rtol=4 * EPS, atol=0)


@pytest.mark.parametrize("setting", SETTINGS)
def test_zeros_are_the_papers_to_the_printed_digits(setting):
    pub = QUADRUPLE_TANK_PUBLISHED[setting]
    got = _zeros(quadruple_tank(setting))
    assert np.array_equal(np.round(got, pub.decimals), np.sort(pub.zeros)), got


def test_the_outlets_round_to_the_printed_ones_which_taken_exactly_miss_the_printed_t():
    """The model's outlet areas round to the printed ones; with the printed ones taken exactly,
    the steady state misses printed time constants (so the choice is needed, and said)."""
    pub = QUADRUPLE_TANK_PUBLISHED["P-"]
    assert np.array_equal(np.round(TANK_OUTLETS, 3), pub.a)
    A, g = np.asarray(pub.A), pub.g
    misses = 0
    for setting in SETTINGS:
        op = tank_operating_point(setting)
        a = np.asarray(pub.a, float)
        T_printed_a = A * op.flows / (a**2 * g)  # T = A q / (a^2 g) at the same flows
        misses += int(np.sum(np.round(T_printed_a) != QUADRUPLE_TANK_PUBLISHED[setting].T))
    assert misses > 0


def _reproduces_every_printed_value(a24: float) -> bool:
    """Whether outlets a2 = a4 = a24 give every printed time constant and zero of both settings."""
    for setting in SETTINGS:
        pub = QUADRUPLE_TANK_PUBLISHED[setting]
        op = tank_operating_point(setting)
        a = np.array([TANK_OUTLETS[0], a24, TANK_OUTLETS[2], a24])
        T = np.asarray(pub.A) * op.flows / (a**2 * pub.g)  # T = A q / (a^2 g) at the same flows
        g1, g2 = pub.gamma
        rhs = (1 - g1) * (1 - g2) / (g1 * g2)
        zeros = np.sort(np.roots([T[2] * T[3], T[2] + T[3], 1 - rhs]).real)
        same_zeros = np.array_equal(np.round(zeros, 3), pub.zeros)
        if not (np.array_equal(np.round(T), pub.T) and same_zeros):
            return False
    return True


def test_the_outlet_interval_the_docstring_states_is_the_one_that_works():
    """TANK_OUTLETS says every value from about 0.05715 to 0.05729 reproduces the printed
    numbers: both ends do, and a step of 0.00002 beyond either end does not."""
    assert _reproduces_every_printed_value(TANK_OUTLETS[1])
    assert _reproduces_every_printed_value(0.05716) and _reproduces_every_printed_value(0.05728)
    assert not _reproduces_every_printed_value(0.05713)
    assert not _reproduces_every_printed_value(0.05731)


@pytest.mark.parametrize("valves", VALVES)
@pytest.mark.parametrize("setting", SETTINGS)
def test_the_operating_point_is_a_steady_state_of_the_nonlinear_model(setting, valves):
    op = tank_operating_point(setting, gamma1=valves[0], gamma2=valves[1])
    rates = _nonlinear(op.h0, op.v0, *valves, setting=setting)
    flows = np.max(op.flows) / np.min(QUADRUPLE_TANK_PUBLISHED[setting].A)
    assert np.all(np.abs(rates) <= 1e3 * EPS * flows), rates
    assert np.all(op.h0 > 0)


@pytest.mark.parametrize("valves", [(0.7, 0.6), (0.43, 0.34), (0.0, 0.6), (0.9, 0.2)])
def test_the_plant_is_the_jacobian_of_the_nonlinear_model(valves):
    """A and E are the derivatives of eq. (1) at the steady state (central differences)."""
    op = tank_operating_point(gamma1=valves[0], gamma2=valves[1])
    plant = quadruple_tank(gamma1=valves[0], gamma2=valves[1])
    jac_h = np.empty((4, 4))
    for i in range(4):
        step = 1e-5 * op.h0[i]
        up, down = op.h0.copy(), op.h0.copy()
        up[i] += step
        down[i] -= step
        jac_h[:, i] = (_nonlinear(up, op.v0, *valves) - _nonlinear(down, op.v0, *valves)) / (
            2 * step
        )
    jac_v = np.empty((4, 2))
    for j in range(2):
        up, down = list(op.v0), list(op.v0)
        up[j] += 1e-3
        down[j] -= 1e-3
        jac_v[:, j] = (_nonlinear(op.h0, up, *valves) - _nonlinear(op.h0, down, *valves)) / 2e-3
    # central differences of the square roots: truncation ~ (step / h)^2 = 1e-10 relative,
    # rounding ~ eps |f| / step; linear in v: rounding only
    scale = np.abs(plant.A).max()
    assert np.allclose(plant.A, jac_h, rtol=1e-6, atol=1e-6 * scale)
    assert_rounding_close(plant.E, jac_v, size=np.abs(plant.E).max() * 1e3, terms=4)
    assert np.array_equal(plant.C, [[0.5, 0, 0, 0], [0, 0.5, 0, 0]])


def test_other_valves_and_voltages_move_the_operating_point():
    """The P+ valves with the P- pumps: another steady state, and its own zeros."""
    minus = tank_operating_point("P-")
    moved = tank_operating_point("P-", gamma1=0.43, gamma2=0.34)
    assert not np.allclose(minus.h0, moved.h0)
    _, _, T3, T4 = moved.T
    want = _closed_form_zeros(T3, T4, 0.43, 0.34)
    got = _zeros(quadruple_tank(gamma1=0.43, gamma2=0.34))
    A = quadruple_tank(gamma1=0.43, gamma2=0.34).A
    gap = abs(want[1] - want[0])
    assert_rounding_close(got, want, size=np.abs(A).max(), terms=16, gain=np.abs(A).max() / gap)
    assert np.allclose(-1 / np.diag(A), moved.T)
    volts = quadruple_tank(v0=(4.0, 2.5))
    assert np.allclose(-1 / np.diag(volts.A), tank_time_constants(v0=(4.0, 2.5)))
    assert "v0 4, 2.5 V" in volts.name


def test_a_closed_valve_is_a_plant_where_the_rank_condition_fails():
    for g1, g2 in ((0.0, 0.6), (0.7, 0.0), (0.0, 0.0)):
        plant = quadruple_tank(gamma1=g1, gamma2=g2)
        report = ut.check_existence(plant)
        assert not report.ok and report["rank condition"].holds is False
        assert np.linalg.matrix_rank(plant.C @ plant.E) == 2 - (g1 == 0) - (g2 == 0)
        assert "rank condition fails" in valve_verdict(g1, g2)


def test_a_valve_at_one_or_a_pump_at_zero_is_refused_naming_the_empty_tank():
    with pytest.raises(ValueError, match="gamma1 = 1 .* upper tank 4 is then empty"):
        quadruple_tank(gamma1=1.0)
    with pytest.raises(ValueError, match="gamma2 = 1 .* upper tank 3 is then empty"):
        quadruple_tank(gamma2=1)
    for bad in ((0.0, 3.0), (3.0, -1.0)):
        with pytest.raises(ValueError, match="v0 must be positive"):
            quadruple_tank(v0=bad)
    for bad in ("3", (1.0,), (1.0, float("nan"))):
        with pytest.raises(ValueError, match="v0 must be two"):
            quadruple_tank(v0=bad)


def test_deviations_that_empty_a_tank_are_refused_in_words():
    h0 = QUADRUPLE_TANK.operating_point().h0
    low = np.array(QUADRUPLE_TANK.initial_state)
    low[2] = -h0[2] - 0.01
    with pytest.raises(ValueError, match=r"initial_state: .* tank 3 at -0.01 cm, below empty"):
        QUADRUPLE_TANK.with_values(initial_state=low)
    low[2] = -h0[2]  # exactly empty is a level, not below one
    QUADRUPLE_TANK.with_values(initial_state=low)
    with pytest.raises(ValueError, match=r"pump1.step: a step of -3.5 V takes pump 1 to -0.5 V"):
        QUADRUPLE_TANK.with_values(step_size=-3.5)
    with pytest.raises(ValueError, match=r"pump2.amplitude: .* takes pump 2 to -1 V"):
        QUADRUPLE_TANK.with_values(sine_amplitude=4.0)
    # a run whose linear model drains a tank below empty
    run = QUADRUPLE_TANK.with_values(step_size=-2.9)
    uio = ut.design_uio(run.plant(), poles=run.poles)
    with pytest.raises(ValueError, match=r"the run takes tank \d to -[\d.]+ cm at t = "):
        run.simulate(uio)
    with pytest.raises(ConfigError, match="below empty"):
        FigureConfig.from_dict({"quadruple_tank": {"initial_state": [2.0, -13.0, 1.0, 1.5]}})


def test_both_observers_of_the_run_start_from_the_estimate_zero():
    plant = QUADRUPLE_TANK.plant()
    uio = ut.design_uio(plant, poles=QUADRUPLE_TANK.poles)
    luen = ut.design_luenberger(plant, poles=[-0.1, -0.2, -0.3, -0.4])
    for obs in (uio, luen):
        res = QUADRUPLE_TANK.simulate(obs)
        assert_rounding_close(
            res.error[:, 0], QUADRUPLE_TANK.initial_state, size=size_of(res.states), terms=4
        )


def test_from_z0_zero_the_uio_error_lives_in_the_upper_tanks_and_its_poles_do_nothing():
    """C E square: C H = I, so C T = 0; from z(0) = 0 the error starts in ker C = the upper
    tanks, which T A keeps, and K1 C e = 0 there: the movable poles never act."""
    plant = QUADRUPLE_TANK.plant()
    runs = []
    for poles in ((-0.1, -0.2), (-1.0, -3.0)):
        uio = ut.design_uio(plant, poles=poles)
        assert_zero(plant.C @ uio.T, plant.C, uio.H, plant.C, terms=4)
        runs.append(QUADRUPLE_TANK.simulate(uio, observer_state=None))
        assert_same_run(plant.C @ runs[-1].error, 0.0, runs[-1])
    gap = np.abs(runs[0].error - runs[1].error).max()
    assert gap <= 1e3 * EPS * np.abs(runs[0].states).max() * np.sqrt(runs[0].time.size)
    # from the estimate 0 the lower levels' error is there, and the poles do act on it
    a, b = (
        QUADRUPLE_TANK.simulate(ut.design_uio(plant, poles=p)) for p in ((-0.1, -0.2), (-1, -3))
    )
    assert np.abs(a.error - b.error).max() > 0.1


@pytest.mark.parametrize("valves", [(0.7, 0.3), (0.5, 0.5), (0.9, 0.1), (0.2, 0.8)])
@pytest.mark.parametrize("delta", [0.1, 1e-2, 1e-4])
def test_the_first_order_law_of_the_zero_and_its_second_order_error(valves, delta):
    """z ~ -(g1 + g2 - 1) / (g1 g2 (T3 + T4)); the exact zero differs from it by
    T3 T4 z^2 / (T3 + T4), which is small only near the line."""
    g1, g2 = valves[0] + delta / 2, valves[1] + delta / 2
    _, _, T3, T4 = tank_time_constants(gamma1=g1, gamma2=g2)
    z = np.max(_zeros(quadruple_tank(gamma1=g1, gamma2=g2)))
    first = -(g1 + g2 - 1) / (g1 * g2 * (T3 + T4))
    # z - first is the dropped second-order term, to the rounding of the zero itself
    assert_rounding_close(
        z - first, -T3 * T4 * z**2 / (T3 + T4), size=abs(z) + abs(first), terms=16, gain=1e3
    )
    # the factor 1/(g1 g2): the law -4 (g1 + g2 - 1)/(T3 + T4) holds only at g1 = g2 = 1/2
    assert first / (-4 * (g1 + g2 - 1) / (T3 + T4)) == pytest.approx(1 / (4 * g1 * g2))


@pytest.mark.parametrize("valves", [(0.7, 0.6), (0.43, 0.34), (0.9, 0.2), (0.3, 0.6)])
def test_the_relative_gain_is_g1_g2_over_g1_plus_g2_minus_1(valves):
    plant = quadruple_tank(gamma1=valves[0], gamma2=valves[1])
    G0 = -plant.C @ np.linalg.solve(plant.A, plant.E)  # the static gain
    rga = G0 * np.linalg.inv(G0).T
    g1, g2 = valves
    formula = g1 * g2 / (g1 + g2 - 1)
    assert_rounding_close(rga[0, 0], formula, size=abs(formula), terms=8, gain=np.linalg.cond(G0))
    assert np.allclose(rga.sum(axis=0), 1) and np.allclose(rga.sum(axis=1), 1)


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


def test_bad_settings_and_valves_are_refused_in_words():
    with pytest.raises(ValueError, match=r"setting must be one of 'P-', 'P\+', got 'P0'"):
        quadruple_tank("P0")
    for bad in (1.2, -0.1, float("nan"), "0.5", True):
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


def _reproduces_the_printed_numbers(a24: float) -> bool:
    """Whether outlets a_2 = a_4 = a24 give every printed T (whole seconds) and zero (2 digits),
    from the mass balance written out here (not the package's operating point)."""
    for pub in QUADRUPLE_TANK_PUBLISHED.values():
        A, g = np.asarray(pub.A), pub.g
        a = np.array([TANK_OUTLETS[0], a24, TANK_OUTLETS[2], a24])
        (g1, g2), (k1, k2), (v1, v2) = pub.gamma, pub.k, pub.v0
        q3, q4 = (1 - g2) * k2 * v2, (1 - g1) * k1 * v1
        q = np.array([g1 * k1 * v1 + q3, g2 * k2 * v2 + q4, q3, q4])
        T = A * q / (a**2 * g)  # (A/a) sqrt(2 h0/g) with h0 = (q/a)^2 / (2 g)
        zeros = _closed_form_zeros(T[2], T[3], g1, g2)
        if not np.array_equal(np.round(T), pub.T):
            return False
        if not all(float(f"{z:.2g}") == p for z, p in zip(zeros, np.sort(pub.zeros), strict=True)):
            return False
    return True


def test_the_outlet_areas_that_reproduce_the_paper_are_those_the_docstring_names():
    """TANK_OUTLETS' docstring: 0.057 exactly misses, 0.0572 and any value from 0.05715 to
    0.05729 reproduce every printed time constant and zero, 0.0571 and 0.0573 do not."""
    assert _reproduces_the_printed_numbers(TANK_OUTLETS[1])
    for a24 in np.linspace(0.05715, 0.05729, 15):
        assert _reproduces_the_printed_numbers(a24), a24
    for a24 in (0.057, 0.0571, 0.0573):
        assert not _reproduces_the_printed_numbers(a24), a24
