"""The explorers' pure part: frames equal direct simulations, every setting gives a picture or a
message, the figure is updated in place and its fast drawing matches a full draw."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import uio_teach as ut
from uio_teach.explorers import (
    DISTURBANCES,
    ExplorerFigure,
    Settings,
    case_study_scenario,
    compute_frame,
    disturbance_signals,
    expand_poles,
    make_scenario,
    missile_scenario,
    pa9_scenario,
    render,
)

SCENARIOS = {
    "pa9": pa9_scenario,
    "case": case_study_scenario,
    "missile": missile_scenario,
}


@pytest.fixture(scope="module", params=sorted(SCENARIOS))
def scenario(request):
    return SCENARIOS[request.param]()


def assert_same(actual, expected):
    np.testing.assert_allclose(actual, expected, rtol=1e-12, atol=1e-12)


# frames equal what simulate returns -------------------------------------------------------


def test_pa9_frame_equals_direct_simulation():
    sc = pa9_scenario()
    s = sc.defaults.replace(
        poles=(-1.5 + 2j, -4.0), amplitude=2.0, frequency=3.0, start="zero observer state"
    )
    frame = compute_frame(sc, s)
    plant = ut.examples.pa9()
    t = np.linspace(0, 10, 1001)
    kwargs = dict(
        u=ut.signals.stack(ut.signals.step(1.0), ut.signals.sinusoid(0.5, 1.0)),
        d=ut.signals.sinusoid(2.0, 3.0),
        initial_state=[1.0, -1.0, 0.5],
    )
    uio = ut.simulate(plant, ut.design_uio(plant, poles=[-1.5 + 2j, -1.5 - 2j, -4]), t, **kwargs)
    lb = ut.simulate(
        plant, ut.design_luenberger(plant, poles=[-1.5 + 2j, -1.5 - 2j, -4]), t, **kwargs
    )
    assert frame.all_messages == ()
    assert_same(frame.curves["uio.error"], uio.error)
    assert_same(frame.curves["uio.residual"], uio.residual)
    assert_same(frame.curves["lb.error"], lb.error)
    assert_same(frame.curves["lb.residual"], lb.residual)
    np.testing.assert_allclose(np.sort_complex(frame.poles), np.sort_complex(uio.observer.poles()))
    # the decoupling the explorer is about: the UIO error ignores d, the Luenberger one does not
    assert np.abs(uio.error[:, 500:]).max() < 1e-3
    assert np.abs(lb.error[:, 500:]).max() > 0.1


def test_case_study_frame_equals_direct_simulation():
    sc = case_study_scenario()
    s = sc.defaults.replace(poles=(0.3,), amplitude=1.5, frequency=0.8, start="zero observer state")
    frame = compute_frame(sc, s)
    plant = ut.examples.dt_case_study()
    steps = np.arange(41)
    kwargs = dict(
        d=ut.signals.sinusoid(1.5, 0.8),
        v=ut.signals.sinusoid(0.75, 1.6),
        initial_state=[1.0, -2.0, 3.0],
    )
    pmo = ut.simulate(plant, ut.design_pmo(plant, poles=[0.3]), steps, **kwargs)
    assert_same(frame.curves["uio.error"], pmo.error)
    assert_same(frame.curves["uio.residual"], pmo.residual)
    # the Luenberger observer gets the PMO's whole spectrum that (A, C) lets it place
    assert np.allclose(np.sort(frame.luenberger_poles.real), [0.3, 0.5, 0.5])
    lb = ut.simulate(plant, ut.design_luenberger(plant, poles=[0.3, 0.5]), steps, **kwargs)
    assert_same(frame.curves["lb.error"], lb.error)


def test_missile_frame_reproduces_the_paper_inputs_and_reconstruction():
    sc = missile_scenario()
    frame = compute_frame(sc, sc.defaults.replace(start="zero observer state"))
    plant = ut.examples.missile_autopilot()
    t = np.linspace(0, 0.5, 1001)
    resp = ut.simulate(
        plant,
        ut.design_pmo(plant, poles=[-100, -120]),
        t,
        d=ut.examples.missile_inputs(),
        initial_state=ut.examples.MISSILE_PUBLISHED.x0,
    )
    assert_same(frame.d, ut.examples.missile_inputs()(t))
    assert_same(frame.curves["uio.error"], resp.error)
    est = ut.reconstruct_input(plant, resp, method="filtered", tau=0.002)
    assert_same(frame.curves["uio.input"], est.estimates)
    assert frame.input_estimate.method == "filtered"


def test_noise_is_the_same_for_both_observers():
    sc = pa9_scenario()
    frame = compute_frame(sc, sc.defaults.replace(noise=0.1, seed=7))
    assert_same(frame.response.inputs.noise, frame.luenberger_response.inputs.noise)
    again = compute_frame(sc, sc.defaults.replace(noise=0.1, seed=7))
    assert_same(again.curves["uio.residual"], frame.curves["uio.residual"])


# messages instead of exceptions ----------------------------------------------------------


def test_unstable_pole_gives_a_message_and_clipped_curves():
    sc = pa9_scenario()
    frame = compute_frame(sc, sc.defaults.replace(poles=(1.0, -2.0, -3.0)))
    assert frame.observer_message.startswith("this pole makes the UIO unstable: the error grows")
    assert "Luenberger" in " ".join(frame.all_messages)
    raw = frame.response.error
    assert np.abs(raw).max() > frame.limits["error"]  # e^{10} ~ 2e4: it does explode
    assert np.abs(frame.curves["uio.error"]).max() <= frame.limits["error"]
    assert any("cut off" in m for m in frame.messages)


def test_pole_on_the_boundary_does_not_decay():
    sc = case_study_scenario()
    frame = compute_frame(sc, sc.defaults.replace(poles=(-1.0,)))
    assert "on the unit circle" in frame.observer_message
    assert "does not decay" in frame.observer_message


def test_lmi_mode_feasible_and_infeasible():
    sc = case_study_scenario()
    ok = compute_frame(sc, sc.defaults.replace(mode="lmi", decay=0.7))
    assert ok.observer_message == ""
    assert np.abs(ok.poles).max() <= 0.7 + 1e-6
    bad = compute_frame(sc, sc.defaults.replace(mode="lmi", decay=0.45))
    assert bad.observer is None
    # plain words: the bound, the fixed poles that block it; no solver status
    assert "no gain meets the bound radius 0.45" in bad.observer_message
    assert "radius 0.5) cannot move" in bad.observer_message
    assert "infeasible" not in bad.observer_message and "_" not in bad.observer_message
    assert bad.curves["uio.error"] is None and bad.curves["lb.error"] is not None


@pytest.mark.parametrize(
    "changes, expected",
    [
        ({"poles": (-1.0, -2.0)}, "3 pole(s) can be placed, got 2"),
        ({"poles": (-2.0, -2.0, -2.0)}, "repeated 3 times"),
        ({"poles": (math.nan, -2.0, -3.0)}, "finite"),
        ({"disturbance": "thunder"}, "unknown disturbance type"),
        ({"disturbance": "random steps", "period": 0.0}, "switching period must be positive"),
        ({"noise": -1.0}, "noise level"),
        ({"mode": "lmi"}, "unknown mode"),
    ],
)
def test_bad_values_become_messages(changes, expected):
    sc = pa9_scenario()
    frame = compute_frame(sc, sc.defaults.replace(**changes))
    assert expected in " ".join(frame.all_messages)
    assert frame.curves["lb.error"] is not None  # the comparison still shows


def test_plant_without_uio_explains_why():
    plant = ut.Plant([[0, 1], [0, 0]], [[1, 0]], E=[[0], [1]], name="double integrator")
    sc = make_scenario(plant)
    frame = compute_frame(sc)
    assert sc.movable == 0
    assert frame.observer is None and "no UIO exists" in frame.observer_message
    assert "rank condition" in frame.observer_message
    assert frame.luenberger is not None and frame.luenberger.is_stable


def test_slow_pole_is_noted():
    sc = pa9_scenario()
    frame = compute_frame(sc, sc.defaults.replace(poles=(-0.1, -2.0, -3.0)))
    assert any("not settled" in m for m in frame.messages)


# the Luenberger rule, poles and signals ---------------------------------------------------


def test_expand_poles():
    assert expand_poles([-1 - 2j, 0.5]).tolist() == [-1 + 2j, -1 - 2j, 0.5]
    assert expand_poles([]).size == 0


def test_disturbance_types():
    sc = pa9_scenario()
    t = sc.timepts
    for kind in DISTURBANCES:
        (d,), v = disturbance_signals(sc, sc.defaults.replace(disturbance=kind, amplitude=2.0))
        values = d(t)
        assert v == []
        assert np.abs(values).max() <= 2.0 + 1e-12
        assert np.abs(values).max() > 0.5
    square = disturbance_signals(sc, sc.defaults.replace(disturbance="piecewise constant"))[0][0]
    assert square([0.0, 2.6, 5.1]).tolist() == [1.0, -1.0, 1.0]
    steps = lambda seed: disturbance_signals(  # noqa: E731
        sc, sc.defaults.replace(disturbance="random steps", seed=seed)
    )[0][0](t)
    assert_same(steps(3), steps(3))
    assert not np.allclose(steps(3), steps(4))


# the figure ------------------------------------------------------------------------------


def test_figure_is_updated_in_place(scenario):
    ef = ExplorerFigure(scenario, dpi=60)
    ef.update(compute_frame(scenario))
    lines = {k: list(v) for k, v in ef.lines.items()}
    texts = (ef.title, ef.footer)
    before = [line.get_ydata().copy() for line in ef.lines["uio.error"]]
    other = scenario.static_values[1]  # a stable value, not the default
    assert other != scenario.defaults.poles[0]
    frame = compute_frame(
        scenario, scenario.defaults.replace(poles=(other, *scenario.defaults.poles[1:]))
    )
    ef.update(frame)
    assert {k: list(v) for k, v in ef.lines.items()} == lines  # the same Line2D objects
    assert texts == (ef.title, ef.footer)
    after = [line.get_ydata() for line in ef.lines["uio.error"]]
    assert any(not np.array_equal(a, b) for a, b in zip(after, before, strict=True))
    for i, line in enumerate(ef.lines["uio.error"]):  # |e| on the log axis
        assert_same(line.get_ydata(), np.abs(frame.curves["uio.error"][i]))
    assert_same(ef.lines["lb.residual"][-1].get_ydata(), frame.curves["lb.residual"][-1])


def test_fast_draw_matches_a_full_draw(scenario):
    """Blitting and partial redraws give (almost exactly) the picture of a full draw."""
    ef = ExplorerFigure(scenario, dpi=60)
    values = scenario.static_values
    for kind in ("sinusoid", "random steps"):
        for value in values[:4]:
            s = scenario.defaults.replace(
                poles=(value, *scenario.defaults.poles[1:]), disturbance=kind
            )
            ef.update(compute_frame(scenario, s))
            ef.draw()
            fast = np.asarray(ef.fig.canvas.buffer_rgba()).copy()
            ef.fig.canvas.draw()
            full = np.asarray(ef.fig.canvas.buffer_rgba())
            # only the stacking of lines over the axes' spines and the legends' antialiased
            # edges may differ (curves that run off the zoomed input panels cross them)
            assert np.any(fast != full, axis=-1).mean() < 0.005
    assert ef.full_draws + ef.partial_draws < 8  # most draws were blits


def test_render_and_missing_curves():
    sc = case_study_scenario()
    fig = render(sc, sc.defaults.replace(mode="lmi", decay=0.4))
    assert len(fig.axes) == 6
    ef = ExplorerFigure(sc)
    ef.update(compute_frame(sc, sc.defaults.replace(mode="lmi", decay=0.4)))
    assert ef.lines["uio.error"][0].get_xdata().size == 0  # no design, no curve
    assert "no gain meets the bound" in ef.footer.get_text()


# every setting: a picture or a message, never an exception --------------------------------


def _settings_strategy(sc):
    lo, hi = sc.pole_limits
    pole = st.one_of(st.sampled_from([lo, hi, 0.0]), st.floats(lo, hi))
    pair = st.builds(complex, st.floats(lo, hi), st.floats(0.0, sc.frequency_limits[1]))
    k = sc.movable
    poles = st.one_of(
        st.tuples(*[pole] * k),
        st.tuples(pair, *[pole] * (k - 2)) if k >= 2 else st.tuples(*[pole] * k),
    )

    def rng(limits):
        a, b = limits
        return st.one_of(st.sampled_from([a, b]), st.floats(a, b))

    return st.builds(
        Settings,
        poles=poles,
        mode=st.sampled_from(["poles", "lmi"] if sc.decay_limits else ["poles"]),
        decay=rng(sc.decay_limits or (0.5, 1.0)),
        disturbance=st.sampled_from(DISTURBANCES),
        amplitude=rng(sc.amplitude_limits),
        frequency=rng(sc.disturbance_frequency_limits),
        period=rng(sc.period_limits),
        noise=rng(sc.noise_limits),
        tau=rng(sc.tau_limits or (0.0, 0.0)),
        seed=st.integers(0, 3),
    )


@pytest.mark.parametrize("name", sorted(SCENARIOS))
def test_every_setting_gives_a_picture_or_a_message(name):
    sc = SCENARIOS[name]()
    ef = ExplorerFigure(sc, dpi=40)

    @settings(
        max_examples=25,
        derandomize=True,
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow],
    )
    @given(_settings_strategy(sc))
    def check(s):
        frame = compute_frame(sc, s)
        ef.update(frame)
        ef.draw()
        shown = [frame.curves.get(k) for k in ("uio.error", "lb.error")]
        # a curve for each observer, or a message saying why not
        assert shown[0] is not None or frame.observer_message
        assert shown[1] is not None or frame.luenberger_message
        for curve in frame.curves.values():
            if curve is not None:
                assert np.nanmax(np.abs(curve), initial=0.0) <= max(frame.limits.values())

    check()


# the movable pole moves the decoupled observer's error; words agree with the plot ------------


def _own_scenario():
    plant = ut.Plant([[0, 1], [-0.08, 0.6]], [[-0.5, 1]], E=[[0], [1]], dt=1)
    return make_scenario(plant, "uio")


ALL = {**SCENARIOS, "own": _own_scenario}


@pytest.mark.parametrize("name", sorted(ALL))
def test_sweeping_the_first_movable_pole_changes_the_decoupled_error(name):
    sc = ALL[name]()
    lo, hi = sc.pole_limits
    edge = 1.0 if sc.discrete else 0.0
    stable = [v for v in np.linspace(lo, min(hi, edge), 9)[1:-1]]
    errors = []
    for p in stable:
        frame = compute_frame(sc, sc.defaults.replace(poles=(p, *sc.defaults.poles[1:])))
        assert frame.observer is not None and frame.observer_message == ""
        assert frame.excited.all()  # the default start reaches every mode
        errors.append(frame.response.error)
    for a, b in zip(errors, errors[1:], strict=False):
        assert np.abs(a - b).max() > 1e-4 * np.abs(a).max()  # it was 1e-15 from z(0) = 0


@pytest.mark.parametrize("name", sorted(ALL))
def test_at_the_unstable_end_the_message_and_the_plotted_error_agree(name):
    from uio_teach.explorers import error_grows

    sc = ALL[name]()
    p = sc.pole_limits[1]
    frame = compute_frame(sc, sc.defaults.replace(poles=(p, *sc.defaults.poles[1:])))
    assert error_grows(frame.response.error)
    assert "the error grows" in frame.observer_message
    shown = np.abs(frame.curves["uio.error"])
    N = shown.shape[1]
    assert shown[:, -N // 10 :].max() > 1.5 * shown[:, : N // 10].max()


def test_an_unexcited_unstable_mode_is_named_and_the_error_does_not_grow():
    from uio_teach.explorers import error_grows

    sc = case_study_scenario()
    frame = compute_frame(sc, sc.defaults.replace(poles=(1.05,), start="zero observer state"))
    assert not error_grows(frame.response.error)
    assert "does not excite" in frame.observer_message
    assert "grows" not in frame.observer_message.split(":")[0]
    assert not frame.excited[np.argmin(abs(frame.poles - 1.05))]
    # and the words next to the plot name the fixed modes
    assert "0.5, 0.5 (the invariant zeros" in frame.explanation


def test_a_pole_on_an_invariant_zero_gets_a_note():
    sc = case_study_scenario()
    frame = compute_frame(sc, sc.defaults.replace(poles=(0.5,)))
    assert any("sits on the invariant zero 0.5" in m for m in frame.messages)
    assert not any("invariant zero" in m for m in compute_frame(sc).messages)


def test_the_lmi_bound_shapes_the_certified_envelope():
    sc = case_study_scenario()
    ends = []
    for bound in (0.6, 0.8, 1.0):
        frame = compute_frame(sc, sc.defaults.replace(mode="lmi", decay=bound))
        (label,) = [k for k in frame.guides if "certified" in k]
        envelope = frame.guides[label]
        size = np.linalg.norm(frame.response.error, axis=0)
        assert np.all(size <= envelope * (1 + 1e-9))  # a true bound on the simulated error
        ends.append(envelope[-1])
    assert ends[0] < ends[1] < ends[2]


def test_dragging_a_pole_on_the_pole_map_moves_its_slider():
    from types import SimpleNamespace

    from uio_teach.explorers import widgets

    ex = widgets.pa9_explorer(static=False, drag=False)
    ax = ex.figure.axes["poles"]
    x, y = ax.transData.transform((-2.0, 0.0))  # pole 2
    press = SimpleNamespace(inaxes=ax, x=x, y=y, button=1, xdata=-2.0, ydata=0.0)
    ex.on_press(press)
    ex.on_motion(SimpleNamespace(inaxes=ax, x=x, y=y, button=1, xdata=-5.0, ydata=0.3))
    ex.on_release(press)
    assert ex.settings.poles == (-1.0, -5.0, -3.0)
    assert ex.controls["pole 2"].value == -5.0
    assert np.isclose(np.sort(ex.frame.poles.real), [-5.0, -3.0, -1.0]).all()
    # a press far from every pole grabs nothing
    far = ax.transData.transform((-9.0, 9.0))
    ex.on_press(SimpleNamespace(inaxes=ax, x=far[0], y=far[1], button=1, xdata=-9.0, ydata=9.0))
    ex.on_motion(SimpleNamespace(inaxes=ax, x=0, y=0, button=1, xdata=-7.0, ydata=0.0))
    assert ex.settings.poles == (-1.0, -5.0, -3.0)
