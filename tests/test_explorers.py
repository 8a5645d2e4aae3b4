"""The explorers' pure part: frames equal direct simulations, every setting gives a picture or a
message, the figure is updated in place and its fast drawing matches a full draw."""

from __future__ import annotations

import functools
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.linalg import expm
from threadpoolctl import threadpool_limits
from tolerance import (
    assert_rounding_close,
    assert_same_run,
    eigenvector_condition,
    roundoff,
    size_of,
)

import uio_teach as ut
from uio_teach.explorers import (
    DISTURBANCES,
    ExplorerFigure,
    Settings,
    compute_frame,
    disturbance_signals,
    expand_poles,
    make_scenario,
    render,
    scenario_of,
)
from uio_teach.worked import WORKED, RegistryError

# every worked example of the registry: a new one is explored and checked with no line here
SCENARIOS = {name: functools.partial(scenario_of, name) for name in WORKED}


@pytest.fixture(scope="module", params=sorted(SCENARIOS))
def scenario(request):
    return SCENARIOS[request.param]()


def assert_same(actual, expected, *, gain=1.0):
    """One simulation by two routes (the explorer's, and simulate's): equal to the rounding of
    its recursion, n**2-term products (n <= 4) over the samples; ``gain`` what the curve's
    computation amplifies rounding by (1 / dt for a derivative)."""
    actual = np.asarray(actual, float)
    assert_rounding_close(actual, expected, terms=16, steps=actual.shape[-1], gain=gain)


# frames equal what simulate returns -------------------------------------------------------


def pa9_run(d) -> tuple[ut.Plant, np.ndarray, dict]:
    """The PA9 explorer's run, written out for ``simulate``: the plant, the time points and the
    inputs (a known input, the disturbance ``d``, the plant's initial state)."""
    plant = ut.examples.pa9()
    t = np.linspace(0, 10, 1001)
    kwargs = dict(
        u=ut.signals.stack(ut.signals.step(1.0), ut.signals.sinusoid(0.5, 1.0)),
        d=d,
        initial_state=[1.0, -1.0, 0.5],
    )
    return plant, t, kwargs


def test_pa9_frame_equals_direct_simulation():
    sc = scenario_of("pa9")
    s = sc.defaults.replace(
        poles=(-1.5 + 2j, -4.0), amplitude=2.0, frequency=3.0, start="zero observer state"
    )
    frame = compute_frame(sc, s)
    plant, t, kwargs = pa9_run(d=ut.signals.sinusoid(2.0, 3.0))
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
    sc = scenario_of("case_study")
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
    sc = scenario_of("missile")
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
    assert_same(frame.curves["uio.input"], est.estimates, gain=1 / (t[1] - t[0]))
    assert frame.input_estimate.method == "filtered"


def test_noise_is_the_same_for_both_observers():
    sc = scenario_of("pa9")
    frame = compute_frame(sc, sc.defaults.replace(noise=0.1, seed=7))
    assert_same(frame.response.inputs.noise, frame.luenberger_response.inputs.noise)
    again = compute_frame(sc, sc.defaults.replace(noise=0.1, seed=7))
    assert_same(again.curves["uio.residual"], frame.curves["uio.residual"])


# messages instead of exceptions ----------------------------------------------------------


def test_unstable_pole_gives_a_message_and_clipped_curves():
    sc = scenario_of("pa9")
    frame = compute_frame(sc, sc.defaults.replace(poles=(1.0, -2.0, -3.0)))
    assert frame.observer_message.startswith("this pole makes the UIO unstable: the error grows")
    assert "Luenberger" in " ".join(frame.all_messages)
    raw = frame.response.error
    assert np.abs(raw).max() > frame.limits["error"]  # e^{10} ~ 2e4: it does explode
    assert np.abs(frame.curves["uio.error"]).max() <= frame.limits["error"]
    assert any("cut off" in m for m in frame.messages)


def test_pole_on_the_boundary_does_not_decay():
    sc = scenario_of("case_study")
    frame = compute_frame(sc, sc.defaults.replace(poles=(-1.0,)))
    assert "on the unit circle" in frame.observer_message
    assert "does not decay" in frame.observer_message


def test_lmi_mode_feasible_and_infeasible():
    sc = scenario_of("case_study")
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
        ({"poles": (-1.0, 0.0, -3.0)}, "pole 0 on the imaginary axis"),
        ({"poles": (math.nan, -2.0, -3.0)}, "finite"),
        ({"disturbance": "thunder"}, "unknown disturbance type"),
        ({"disturbance": "random steps", "period": 0.0}, "switching period must be positive"),
        ({"noise": -1.0}, "noise level"),
        ({"mode": "lmi"}, "unknown mode"),
    ],
)
def test_bad_values_become_messages(changes, expected):
    sc = scenario_of("pa9")
    frame = compute_frame(sc, sc.defaults.replace(**changes))
    assert expected in " ".join(frame.all_messages)
    assert frame.curves["lb.error"] is not None  # the comparison still shows


@pytest.mark.filterwarnings("error::uio_teach.verify.PlacementAccuracyWarning")
def test_a_triple_pole_is_placed():
    sc = scenario_of("pa9")
    frame = compute_frame(sc, sc.defaults.replace(poles=(-2.0, -2.0, -2.0)))
    assert frame.observer is not None and frame.observer_message == ""
    for obs in (frame.observer, frame.luenberger):
        F = obs.F
        # a triple pole moves by about (eps ||F||)^(1/3) under round-off: the conditioning
        bound = 100 * (np.finfo(float).eps * np.linalg.norm(F, 2)) ** (1 / 3)
        assert np.abs(np.linalg.eigvals(F) + 2.0).max() <= bound
        ut.verify.check_poles(F, [-2.0, -2.0, -2.0])  # neither warns (an error here) nor raises


def test_plant_without_uio_explains_why():
    plant = ut.Plant([[0, 1], [0, 0]], [[1, 0]], E=[[0], [1]], name="double integrator")
    sc = make_scenario(plant)
    frame = compute_frame(sc)
    assert sc.movable == 0
    assert frame.observer is None and "no UIO exists" in frame.observer_message
    assert "rank condition" in frame.observer_message
    assert frame.luenberger is not None and frame.luenberger.is_stable


def test_slow_pole_is_noted():
    sc = scenario_of("pa9")
    frame = compute_frame(sc, sc.defaults.replace(poles=(-0.1, -2.0, -3.0)))
    assert any("not settled" in m for m in frame.messages)


# the Luenberger rule, poles and signals ---------------------------------------------------


def test_expand_poles():
    assert expand_poles([-1 - 2j, 0.5]).tolist() == [-1 + 2j, -1 - 2j, 0.5]
    assert expand_poles([]).size == 0


def test_disturbance_types():
    sc = scenario_of("pa9")
    t = sc.timepts
    for kind in DISTURBANCES:
        (d,), v = disturbance_signals(sc, sc.defaults.replace(disturbance=kind, amplitude=2.0))
        values = d(t)
        assert v == []
        assert np.abs(values).max() <= 2.0 + roundoff(2.0, terms=2)  # amplitude times sin
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


@pytest.mark.parametrize("narrow", [False, True])
def test_every_panel_has_a_cell_of_its_own(scenario, narrow):
    """Each panel (the pole map drawn round in discrete time too) keeps to a cell, so a change of
    its range redraws that cell alone, not the whole figure."""
    ef = ExplorerFigure(scenario, dpi=60, narrow=narrow)
    ef.update(compute_frame(scenario))
    ef.draw()
    assert set(ef.axes) <= set(ef._cells), sorted(set(ef.axes) - set(ef._cells))
    moved = scenario.defaults.replace(amplitude=3 * scenario.defaults.amplitude)
    ef.update(compute_frame(scenario, moved))
    ef.draw()
    assert ef.full_draws == 1 and ef.partial_draws == 1


@pytest.mark.slow
def test_fast_draw_matches_a_full_draw(scenario):
    """Blitting and partial redraws give (almost exactly) the picture of a full draw."""
    ef = ExplorerFigure(scenario, dpi=60)
    values = scenario.static_values
    if scenario.static_control != "pole":  # the static slider is a valve: move the first pole
        first = complex(scenario.defaults.poles[0]).real
        values = tuple(first * f for f in (1.0, 2.0, 0.5, 4.0))
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
    sc = scenario_of("case_study")
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
@pytest.mark.slow
def test_every_setting_gives_a_picture_or_a_message(name):
    sc = SCENARIOS[name]()
    ef = ExplorerFigure(sc, dpi=40)

    # a sample (the edges and a seeded random subset are swept word by word below)
    @settings(
        max_examples=10,
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

    sc = scenario_of("case_study")
    frame = compute_frame(sc, sc.defaults.replace(poles=(1.05,), start="zero observer state"))
    assert not error_grows(frame.response.error)
    assert "does not excite" in frame.observer_message
    assert "grows" not in frame.observer_message.split(":")[0]
    assert not frame.excited[np.argmin(abs(frame.poles - 1.05))]
    # and the words next to the plot name the fixed modes
    assert "0.5, 0.5 (the invariant zeros" in frame.explanation


def test_a_pole_on_an_invariant_zero_gets_a_note():
    sc = scenario_of("case_study")
    frame = compute_frame(sc, sc.defaults.replace(poles=(0.5,)))
    assert any("sits on the invariant zero 0.5" in m for m in frame.messages)
    assert not any("invariant zero" in m for m in compute_frame(sc).messages)


def test_the_lmi_bound_shapes_the_certified_envelope():
    sc = scenario_of("case_study")
    ends = []
    for bound in (0.6, 0.8, 1.0):
        frame = compute_frame(sc, sc.defaults.replace(mode="lmi", decay=bound))
        (label,) = [k for k in frame.guides if "certified" in k]
        envelope = frame.guides[label]
        size = np.linalg.norm(frame.response.error, axis=0)
        # a true bound on the simulated error, up to the rounding of the run
        resp = frame.response
        gain = eigenvector_condition(frame.observer.error_matrix)
        slack = roundoff(
            size_of(resp.states, resp.estimates), terms=9, steps=frame.time.size, gain=gain
        )
        assert np.all(size <= envelope + slack)
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


# the sweep: no word contradicts the simulated error, on the course's plants and others --------


def _complex_zeros_plant():
    """Invariant zeros -1 ± 2j (an unobservable-from-y oscillation driven by the measured x3)."""
    A = [[-1, 2, 1], [-2, -1, 0.5], [0, 0, -2]]
    return ut.Plant(A, [[0, 0, 1]], E=[[0], [0], [1]], name="zeros -1 ± 2j")


def _lightly_damped_plant():
    """Invariant zeros -0.01 ± 10j: a lightly damped fixed pair."""
    A = [[-0.01, 10, 1], [-10, -0.01, 0], [0, 0, -2]]
    return ut.Plant(A, [[0, 0, 1]], E=[[0], [0], [1]], name="zeros -0.01 ± 10j")


def _discrete_complex_zeros_plant():
    A = [[0.6, 0.5, 1], [-0.5, 0.6, 0], [0, 0, 0.2]]
    return ut.Plant(A, [[0, 0, 1]], E=[[0], [0], [1]], dt=1, name="zeros 0.6 ± 0.5j")


def _ginverse_scenario():
    from uio_teach.explorers import widgets

    ex = widgets.missile_explorer(observer_family="ginverse", static=False, drag=False)
    ex.close()
    return ex.scenario


SWEEP = {
    **ALL,
    "missile g-inverse": lambda: _ginverse_scenario(),
    "zeros -1±2j": lambda: make_scenario(_complex_zeros_plant(), "uio"),
    "zeros -1±2j pmo": lambda: make_scenario(_complex_zeros_plant(), "pmo"),
    "lightly damped": lambda: make_scenario(_lightly_damped_plant(), "uio"),
    "discrete zeros": lambda: make_scenario(_discrete_complex_zeros_plant(), "pmo"),
}


def _sweep_settings(sc, count=6, seed=0):
    """The edges of every control's range one at a time, then a seeded random sample of them all.

    A property test of the same kind (``test_every_setting_gives_a_picture_or_a_message``) covers
    the values in between for the course's explorers.
    """
    rng = np.random.default_rng(seed)
    base = sc.defaults
    k = len(base.poles)
    lo, hi = sc.pole_limits
    ranges = {
        "amplitude": sc.amplitude_limits,
        "frequency": sc.disturbance_frequency_limits,
        "period": sc.period_limits,
        "noise": sc.noise_limits,
    }
    if sc.tau_limits:
        ranges["tau"] = sc.tau_limits
    out = [base, base.replace(start="zero observer state")]
    for i in range(k):  # each movable pole at both ends (the first also just inside the unstable
        # side, where a slow unstable mode may not yet outgrow the start), from both starts
        for p in (lo, hi, 0.02 * hi, 0.05 * hi) if i == 0 else (lo, hi):
            poles = list(base.poles)
            poles[i] = p
            out += [
                base.replace(poles=tuple(poles)),
                base.replace(poles=tuple(poles), start="zero observer state"),
            ]
    for name, (a, b) in ranges.items():
        out += [base.replace(**{name: a}), base.replace(**{name: b})]
    out += [base.replace(disturbance=kind) for kind in DISTURBANCES]
    if sc.decay_limits:
        out += [base.replace(mode="lmi", decay=v) for v in sc.decay_limits]
    for _ in range(count):
        poles = tuple(float(rng.uniform(lo, hi)) for _ in range(k))
        if k and not sc.discrete and rng.random() < 0.4:  # one complex pair
            poles = (complex(poles[0], rng.uniform(*sc.frequency_limits)), *poles[2:])
            poles = poles if len(expand_poles(poles)) == sc.movable else base.poles
        values = {name: float(rng.uniform(a, b)) for name, (a, b) in ranges.items()}
        out.append(
            base.replace(
                poles=poles,
                disturbance=str(rng.choice(DISTURBANCES)),
                start=str(rng.choice(["zero estimate", "zero observer state"])),
                seed=int(rng.integers(4)),
                **values,
            )
        )
    return out


def _sizes(error):
    size = np.sqrt(np.sum(np.asarray(error, float) ** 2, axis=0))
    return float(size[0]), float(size[-1]), float(size.max())


def _check_words(text, error, tol=0.01):
    """Every claim about the error in ``text`` holds for the simulated ``error``."""
    start, end, peak = _sizes(error)
    finite = np.isfinite(peak)
    if "the error grows" in text or "|e| grows" in text:
        assert not finite or end > (1 + tol) * start, text
    if "decays from" in text or "then decays to" in text:
        assert end < (1 - tol) * start, text
    if "not yet above its start" in text:
        assert peak <= (1 + tol) * start, text
    if "does not grow here" in text:
        assert end <= (1 + tol) * start, text
    if "ends about where it starts" in text:
        assert (1 - tol) * start <= end <= (1 + tol) * start, text
    if "zero to rounding" in text and "residual" not in text:
        assert peak <= 1e-6, text
    if "has not settled" in text:
        N = error.shape[1]
        size = np.sqrt(np.sum(error**2, axis=0))
        assert size[-max(1, N // 10) :].max() > 0.05 * peak, text


def _free_error(frame, idx):
    """``exp(F t) e(0)`` (``F^k e(0)``) at the grid points ``idx``, without simulating."""
    F = frame.observer.error_matrix
    e0 = frame.initial_error
    t = frame.time - frame.time[0]
    if frame.scenario.discrete:
        out, e = [], np.asarray(e0, float)
        for _ in t:
            out.append(e)
            e = F @ e
        return np.array(out).T[:, idx]
    with threadpool_limits(1):  # tiny matrices: BLAS threads only contend on a busy machine
        return np.array([expm(F * tk) @ e0 for tk in t[idx]]).T


def _largest_gain(frame, idx):
    """The largest ``||F^k||`` (``||exp(F t)||``) over the grid points ``idx``."""
    F = frame.observer.error_matrix
    t = frame.time - frame.time[0]
    if frame.scenario.discrete:
        return max(np.linalg.norm(np.linalg.matrix_power(F, k), 2) for k in idx)
    with threadpool_limits(1):
        return max(float(np.linalg.norm(expm(F * tk), 2)) for tk in t[idx])


@pytest.mark.parametrize("name", sorted(SWEEP))
def test_sweep_no_word_contradicts_the_simulated_error(name):
    from uio_teach.explorers.static import frame_alt, frame_caption

    sc = SWEEP[name]()
    for s in _sweep_settings(sc):
        frame = compute_frame(sc, s)
        alt = frame_alt(frame, "pole", "x")
        caption = frame_caption(frame)
        lb_alt = alt.split("Luenberger observer:")[1]
        for observer, resp, message, words in (
            (frame.observer, frame.response, frame.observer_message, alt.split("Luenberger")[0]),
            (frame.luenberger, frame.luenberger_response, frame.luenberger_message, lb_alt),
        ):
            if resp is None:
                assert message, s  # no curve: a message says why, in one line
                assert "\n" not in message and len(message) < 250
                assert "no curve" in words
                assert ("no design" in words) == (observer is None), words
                continue
            _check_words(message, resp.error)
            _check_words(words, resp.error)
        for note in frame.messages:
            _check_words(note, frame.response.error if frame.response else np.zeros((1, 2)))
        assert all(m in caption or m[:1].upper() + m[1:] in caption for m in frame.all_messages)
        # the decoupled error is the free response of the error dynamics, whatever d and v are
        if frame.response is not None and not s.noise and np.isfinite(frame.response.error).all():
            idx = np.arange(0, frame.time.size, max(1, frame.time.size // 40))
            free = _free_error(frame, idx)
            # Rounding: e = x - xhat is as uncertain as x and xhat are large; each of the N
            # samples adds errors of n-term products (n**2 with the exponentials) that the error
            # dynamics carry on, amplified by at most sup ||exp(F t)|| times the condition of
            # F's eigenvectors; the reference's scaling and squaring adds ||F|| t steps.
            F = frame.observer.error_matrix
            resp = frame.response
            steps = frame.time.size
            if not frame.scenario.discrete:
                steps += np.linalg.norm(F, 1) * (frame.time[-1] - frame.time[0])
            assert_rounding_close(
                resp.error[:, idx],
                free,
                size=size_of(resp.states, resp.estimates, free),
                terms=F.shape[0] ** 2,
                steps=steps,
                gain=_largest_gain(frame, idx) * np.linalg.cond(np.linalg.eig(F)[1]),
                what=str(s),
            )


def test_sweep_settings_cover_the_edges():
    sc = scenario_of("pa9")
    sample = _sweep_settings(sc)
    assert any(s.poles[0] == sc.pole_limits[0] for s in sample)
    assert any(s.poles[0] == sc.pole_limits[1] for s in sample)
    for name, (a, b) in {"amplitude": sc.amplitude_limits, "noise": sc.noise_limits}.items():
        assert {a, b} <= {getattr(s, name) for s in sample}
    assert {s.disturbance for s in sample} == set(DISTURBANCES)


def test_slow_unstable_pole_beside_complex_zeros_is_described_as_simulated():
    sc = make_scenario(_complex_zeros_plant(), "uio")
    for p in (0.02, 0.05):
        frame = compute_frame(sc, sc.defaults.replace(poles=(p,)))
        start, end, peak = _sizes(frame.response.error)
        text = frame.observer_message
        assert ("not yet above its start" in text) == (peak <= 1.01 * start), text
        _check_words(text, frame.response.error)


def test_lightly_damped_fixed_pair_is_sampled_finely_and_named():
    sc = make_scenario(_lightly_damped_plant(), "uio")
    t = sc.timepts
    period = 2 * np.pi / 10
    assert period / (t[1] - t[0]) >= 19.9  # no aliased wiggles
    frame = compute_frame(sc)
    assert "lightly damped fixed pair -0.01 ± 10j" in frame.explanation
    (note,) = [m for m in frame.messages if "not settled" in m]
    assert "no gain moves it" in note and "cannot make the error settle sooner" in note
    # a fast unstable pole: the curve runs off the plot, the words stay short
    frame = compute_frame(sc, sc.defaults.replace(poles=(sc.pole_limits[1],)))
    assert len(frame.all_messages) <= 4 and "the simulation failed" not in str(frame.all_messages)


def test_overflow_is_one_line():
    sc = make_scenario(_lightly_damped_plant(), "uio", timepts=np.linspace(0, 800, 1001))
    frame = compute_frame(sc, sc.defaults.replace(poles=(0.9,)))
    assert frame.response is None
    assert frame.observer_message.startswith("unstable (pole 0.9 in the right half-plane)")
    assert frame.luenberger_message == "its error overflows too, no curve"
    from uio_teach.explorers.static import frame_alt

    alt = frame_alt(frame, "pole", "0.9")
    assert alt.count("no curve (the error overflows)") == 2 and "no design" not in alt


def test_default_pole_is_never_on_an_invariant_zero():
    for plant in (
        _own_scenario().plant,
        _complex_zeros_plant(),
        _discrete_complex_zeros_plant(),
        ut.Plant([[0.5, 0], [0, 0.4]], [[1, 1]], E=[[1], [0]], dt=1),
    ):
        for family in ("uio", "pmo"):
            sc = make_scenario(plant, family)
            zeros = sc.invariant_zeros
            for p in expand_poles(sc.defaults.poles):
                assert np.all(np.abs(zeros - p) > 0.04 * max(1.0, abs(p))), (plant, p)
            frame = compute_frame(sc)
            assert not any("invariant zero" in m for m in frame.messages)
    sc = _own_scenario()
    assert sc.defaults.poles[0] in sc.static_values  # the static page opens on it


def test_zero_residual_is_drawn_flat_and_said():
    """From z(0) = 0 the missile PMO's residual is rounding noise (~1e-13): it is drawn as a flat
    line on the outputs' scale and said to be zero, not magnified into a trend."""
    sc = scenario_of("missile")
    ef = ExplorerFigure(sc, dpi=40)
    ef.update(compute_frame(sc))  # a sticky range from an ordinary frame first
    frame = compute_frame(sc, sc.defaults.replace(poles=(0.6, -120.0), start="zero observer state"))
    assert_same_run(frame.response.residual, 0, frame.response)  # zero to rounding
    assert frame.residual_zero and "residual is zero to rounding" in frame.explanation
    ef.update(frame)
    lo, hi = ef.axes["uio.residual"].get_ylim()
    assert hi - lo >= frame.limits["residual"] / 10  # the outputs' scale, not 1e-11
    assert not compute_frame(sc).residual_zero


@pytest.mark.slow  # every explorer drawn at both sizes over its settings
@pytest.mark.parametrize("name", sorted(SCENARIOS))
@pytest.mark.parametrize("narrow", [False, True])
def test_no_legend_covers_a_curve(name, narrow):
    # every picture of the static book (first, middle and last slider value, both
    # disturbance types): a band at the top of each panel keeps its legend clear of curves
    from uio_teach.explorers.scenarios import scenario_of
    from uio_teach.explorers.static import (
        NARROW_DPI,
        NARROW_FONTSCALE,
        WIDE_FONTSCALE,
        frame_settings,
    )
    from uio_teach.plotting import covered_curves

    sc = SCENARIOS[name]() if name in SCENARIOS else scenario_of(name)
    values = sc.static_values
    scale = NARROW_FONTSCALE if narrow else WIDE_FONTSCALE
    for value in (values[0], values[len(values) // 2], values[-1]):
        plant = sc
        if sc.static_plant_control is not None and sc.rebuild is not None:
            plant = sc.rebuild(**{sc.static_plant_control.name: value})
        fig = ExplorerFigure(
            plant, dpi=NARROW_DPI, sticky=False, fontscale=scale, narrow=narrow, lmi=False
        )
        assert fig.bands, "the panels' legends have bands"
        for kind in ("random steps", "sinusoid"):
            fig.update(compute_frame(plant, frame_settings(sc, sc.defaults, value, kind)))
            assert covered_curves(fig.fig) == [], (value, kind)


# --- every static frame of every explorer of the book: its words against its numbers -----------


def _book_explorers():
    from uio_teach.explorers import scenario_of

    own = ut.Plant([[0, 1], [-0.08, 0.6]], [[-0.5, 1]], E=[[0], [1]], dt=1)
    own_scenario = make_scenario(own, "uio")
    return {
        **{name: functools.partial(scenario_of, name) for name in WORKED},
        "existence": lambda: own_scenario,
    }


BOOK_EXPLORERS = _book_explorers()


def _static_frames(sc):
    """The frames of the book's static explorer (as ``static_explorer`` makes them), unrendered."""
    from uio_teach.explorers.static import frame_settings

    base = sc.defaults
    other = "sinusoid" if base.disturbance == "random steps" else "random steps"
    control = sc.static_plant_control
    for value in sc.static_values:
        plant_sc = sc.rebuild(**{control.name: value}) if control is not None else sc
        for kind in (base.disturbance, other):
            yield value, compute_frame(plant_sc, frame_settings(sc, base, value, kind))


def _all_stable(poles, discrete):
    from uio_teach.linalg import is_stable

    return bool(np.all(is_stable(np.asarray(poles), discrete))) if np.size(poles) else True


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(BOOK_EXPLORERS))
def test_every_static_frame_says_what_its_numbers_show(name):
    """Caption, messages and text alternative of every frame agree with the frame's numbers:
    "decays" only for an error whose poles are all stable (else it "shrinks within the window"),
    every claim on the error's size against the simulated error, "next to the invariant zero"
    only within the relative gap and only where a UIO exists, a frame without a UIO says so and
    says nothing of moving or fixing its poles, and the plant's note agrees with the existence
    check."""
    from uio_teach.explorers.messages import NEXT_TO
    from uio_teach.explorers.static import frame_alt, frame_caption

    sc = BOOK_EXPLORERS[name]()
    seen = 0
    for value, frame in _static_frames(sc):
        seen += 1
        fsc = frame.scenario
        alt = frame_alt(frame, "x", f"{value:g}")
        caption = frame_caption(frame)
        uio_part, lb_part = alt.split("Luenberger observer:")
        rows = (
            (frame.response, frame.poles, frame.observer_message, uio_part),
            (frame.luenberger_response, frame.luenberger_poles, frame.luenberger_message, lb_part),
        )
        for resp, poles, message, words in rows:
            if resp is None:
                continue
            stable = _all_stable(poles, fsc.discrete)
            for text in (message, words):
                _check_words(text, resp.error)
                if "decays" in text and "decays no faster" not in text:
                    assert stable, (name, value, text, poles)
        for note in frame.messages:
            _check_words(note, frame.response.error if frame.response else np.zeros((1, 2)))
        exists = fsc.existence.ok
        assert (frame.observer is not None) == exists or frame.observer_message, (name, value)
        for m in re.finditer(
            r"pole (\S+) (?:is next to|sits on) the invariant zero (\S+),", caption
        ):
            assert exists, (name, value, caption)
            p, z = complex(m.group(1)), complex(m.group(2))
            assert abs(p - z) <= NEXT_TO * max(abs(p), abs(z)) * 1.01 + 1e-3 * abs(z), m.group(0)
        if exists and frame.observer is not None:  # every pole that is that close is named
            for p in frame.settings.poles:
                gaps = np.abs(fsc.invariant_zeros - complex(p))
                if gaps.size and gaps.min() <= 0.5 * NEXT_TO * abs(complex(p)):
                    assert "invariant zero" in caption, (name, value, p)
        if not exists:
            assert "No " in frame.explanation and "exists for this plant" in frame.explanation
            for word in ("pole controls move", "Fixed whatever the gain", "next to the"):
                assert word not in caption, (name, value, word, caption)
        if fsc.note:
            assert ("a UIO exists" in fsc.note) == exists, fsc.note
            zeros = np.sort(fsc.existence.invariant_zeros.real)
            for num in re.findall(r"right half-plane at (\S+?),", fsc.note):
                assert float(num) == pytest.approx(zeros[-1], rel=5e-3)
    assert seen >= 2 * len(sc.static_values)


def test_an_unknown_worked_example_is_named_with_the_known_ones():
    """Not a bare KeyError: the package's error, naming the name given and the names it knows."""
    with pytest.raises(RegistryError, match=r"no worked example 'tank'; the worked examples are "):
        scenario_of("tank")
    with pytest.raises(RegistryError, match="pa9, case_study, missile, quadruple_tank"):
        scenario_of("nope")
