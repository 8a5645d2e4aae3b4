"""The live explorers (ipywidgets) and their static fallback (pre-computed frames in plain HTML).

Live: each explorer builds, a control set programmatically redraws the figure with exactly what
``ut.simulate`` returns for those settings, and any control value gives a picture or a message.
Static: the expected number of frames, no external URL, and -- in headless Chromium -- moving
the slider swaps the displayed frame.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser

import numpy as np
import pytest
from browsers import in_chromium
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_explorers import pa9_run
from tolerance import assert_rounding_close, size_of

import uio_teach as ut
from uio_teach.explorers import scenario_of, widgets
from uio_teach.explorers.static import static_explorer

EXPLORERS = {
    "pa9": widgets.pa9_explorer,
    "case": widgets.case_study_explorer,
    "missile": widgets.missile_explorer,
    "quadruple tank": lambda static=False: widgets.tank_explorer(static=static),
    "own plant": lambda static=False: widgets.explorer(
        ut.Plant(
            [[0, 1], [-2, -1]], [[1, 0], [0, 1]], E=[[0], [1]], D=[[0.5], [1]], name="my plant"
        ),
        "pmo",
        static=static,
    ),
    "missile g-inverse": lambda static=False: widgets.missile_explorer(
        observer_family="ginverse", static=static
    ),
}
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"


def ydata(ex, name):
    return np.array([line.get_ydata() for line in ex.figure.lines[name]])


def assert_same(actual, expected, *, gain=1.0):
    """One simulation by two routes (the explorer's, and simulate's): equal to the rounding of
    its recursion, n**2-term products (n <= 4) over the samples; ``gain`` what the curve's
    computation amplifies rounding by (1 / dt for a derivative)."""
    actual = np.asarray(actual, float)
    assert_rounding_close(actual, expected, terms=16, steps=actual.shape[-1], gain=gain)


# live: each explorer builds and its controls act -----------------------------------------


@pytest.mark.parametrize("name", sorted(EXPLORERS))
def test_explorer_builds(name):
    ex = EXPLORERS[name](static=False)
    assert bytes(ex.image.value[:4]) == b"\x89PNG"
    assert ex.frame is not None
    assert ex.figure.lines["lb.error"][0].get_xdata().size == ex.scenario.timepts.size
    for control in ex.controls.values():
        if hasattr(control, "continuous_update"):
            assert control.continuous_update is False


def test_pa9_pole_slider_redraws_with_what_simulate_returns():
    ex = widgets.pa9_explorer(static=False)
    before = ydata(ex, "uio.error")
    ex.controls["pole 1"].value = -4.0  # as a student's slider does
    after = ydata(ex, "uio.error")
    assert not np.allclose(before, after)
    plant, t, kwargs = pa9_run(d=ut.signals.sinusoid(1.0, 2.0))
    obs = ut.design_uio(plant, poles=[-4, -2, -3])
    # the default start: a zero estimate, xhat(0) = z(0) + H y(0) = 0
    z0 = -obs.H @ plant.C @ np.array(kwargs["initial_state"])
    uio = ut.simulate(plant, obs, t, observer_state=z0, **kwargs)
    lb = ut.simulate(plant, ut.design_luenberger(plant, poles=[-4, -2, -3]), t, **kwargs)
    # z(0) = -H C x(0): xhat(0) = z(0) + H C x(0) = 0 up to the rounding of 3-term products
    size = size_of(obs.H) * size_of(plant.C) * size_of(kwargs["initial_state"])
    assert_rounding_close(uio.estimates[:, 0], 0, size=size, terms=3)
    assert_same(after, np.abs(uio.error))  # |e| on the log axis
    assert_same(ydata(ex, "uio.residual"), uio.residual)
    assert_same(ydata(ex, "lb.error"), np.abs(lb.error))


def test_pa9_complex_pair_and_disturbance_controls():
    ex = widgets.pa9_explorer(static=False)
    ex.set(pattern=1, start="zero observer state")  # z(0) = 0, as simulate's default
    ex.set(**{"pole 1": -3.0, "pole 2 real part": -1.0, "pole 2 frequency": 2.0})
    ex.set(disturbance="random steps", amplitude=2.0, period=1.5)
    assert ex.controls["frequency"].layout.display == "none"
    assert ex.controls["period"].layout.display is None
    assert ex.settings.poles == (-3.0, -1 + 2j)
    rng = np.random.default_rng([0, 0])
    times = 1.5 * np.arange(8)
    d = ut.signals.piecewise_constant(times, 2.0 * rng.uniform(-1, 1, 8))
    plant, t, kwargs = pa9_run(d=d)
    uio = ut.simulate(plant, ut.design_uio(plant, poles=[-3, -1 + 2j, -1 - 2j]), t, **kwargs)
    assert_same(ex.figure.lines["d"][0].get_ydata(), d(t))
    assert_same(ydata(ex, "uio.error"), np.abs(uio.error))
    # a zero imaginary part is a double real pole
    ex.set(**{"pole 2 frequency": 0.0})
    assert ex.settings.poles == (-3.0, -1.0, -1.0)
    assert ex.frame.observer is not None


@pytest.mark.slow
def test_case_study_pole_and_lmi_mode():
    ex = widgets.case_study_explorer(static=False)
    ex.set(start="zero observer state")  # q(0) = 0, as simulate's default
    ex.controls["pole 1"].value = 0.4
    plant = ut.examples.dt_case_study()
    steps = np.arange(41)
    pmo = ut.simulate(
        plant,
        ut.design_pmo(plant, poles=[0.4]),
        steps,
        d=ut.signals.sinusoid(2.0, 0.6),
        v=ut.signals.sinusoid(1.0, 1.2),
        initial_state=[1.0, -2.0, 3.0],
    )
    assert_same(ydata(ex, "uio.error"), np.abs(pmo.error))
    ex.controls["mode"].value = "lmi"
    assert ex._pole_box.layout.display == "none"
    assert ex.controls["decay"].layout.display is None
    ex.controls["decay"].value = 0.8
    lmi = ut.design_pmo(plant, method="lmi", decay=0.8)
    # the same LMI solved twice: its poles agree to the solver's tolerance (~1e-8), not rounding
    np.testing.assert_allclose(np.sort(ex.frame.poles.real), np.sort(lmi.poles().real), atol=1e-6)
    ex.controls["decay"].value = 0.4
    assert "no gain meets the bound radius 0.4" in ex.message.value
    assert ex.figure.lines["uio.error"][0].get_xdata().size == 0


@pytest.mark.slow
def test_missile_filter_slider_redraws_the_reconstruction():
    ex = widgets.missile_explorer(static=False)
    ex.set(start="zero observer state")  # q(0) = 0, as simulate's default
    before = ydata(ex, "uio.input")
    ex.controls["tau"].value = 0.01
    after = ydata(ex, "uio.input")
    assert not np.allclose(before, after)
    plant = ut.examples.missile_autopilot()
    resp = ut.simulate(
        plant,
        ut.design_pmo(plant, poles=[-100, -120]),
        np.linspace(0, 0.5, 1001),
        d=ut.examples.missile_inputs(),
        initial_state=ut.examples.MISSILE_PUBLISHED.x0,
    )
    est = ut.reconstruct_input(plant, resp, method="filtered", tau=0.01)
    derivative = 1 / (resp.time[1] - resp.time[0])  # rounding in xhat, divided by the step
    assert_same(after, est.estimates, gain=derivative)
    ex.controls["tau"].value = 0.0  # plain derivative
    assert_same(
        ydata(ex, "uio.input"), ut.reconstruct_input(plant, resp).estimates, gain=derivative
    )


def test_unstable_pole_message_in_the_widget():
    ex = widgets.pa9_explorer(static=False)
    ex.controls["pole 1"].value = 1.0
    assert "this pole makes the UIO unstable: the error grows" in ex.message.value
    assert "the error grows" in ex.figure.footer.get_text()
    assert np.abs(ydata(ex, "uio.error")).max() <= ex.frame.limits["error"]


@pytest.mark.slow
def test_mimebundle_has_the_widget_and_the_static_frames():
    ex = widgets.case_study_explorer()
    bundle = ex._repr_mimebundle_()
    assert set(bundle) == {"text/plain", "text/html", WIDGET_VIEW}
    assert bundle[WIDGET_VIEW]["model_id"] == ex.widget.model_id
    assert bundle["text/html"].count('data-k="') == len(ex.scenario.static_values) * 2
    assert "kernel" in bundle["text/plain"]
    assert "text/html" not in widgets.case_study_explorer(static=False)._repr_mimebundle_()


@pytest.mark.subprocess
def test_lazy_import():
    import subprocess
    import sys

    code = (
        "import sys, uio_teach as ut; assert 'ipywidgets' not in sys.modules; "
        "ut.explorers.compute_frame; assert 'ipywidgets' not in sys.modules; "
        "from uio_teach.explorers.widgets import pa9_explorer; "
        "assert 'ipywidgets' in sys.modules"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


# live: every control value gives a picture or a message ----------------------------------


def _choices(control):
    """Extremes and random values of a slider, or the options of a dropdown."""
    if hasattr(control, "options"):
        values = [o[1] if isinstance(o, tuple) else o for o in control.options]
        return st.sampled_from(values)
    lo, hi = control.min, control.max
    return st.one_of(st.sampled_from([lo, hi]), st.floats(lo, hi))


@pytest.mark.parametrize("name", sorted(EXPLORERS))
@pytest.mark.slow
def test_every_control_value_gives_a_picture_or_a_message(name):
    ex = EXPLORERS[name](static=False)
    # the choices of the opening controls, fixed: a plant slider may remake the pole controls
    # (a valve that leaves no UIO leaves no pole to move), and hypothesis wants fixed strategies
    options = {key: _choices(control) for key, control in ex.controls.items()}

    @st.composite
    def changes(draw):
        out = []
        for _ in range(draw(st.integers(1, 4))):
            key = draw(st.sampled_from(sorted(options)))
            out.append((key, draw(options[key])))
        return out

    # a sample: the edges and a seeded random subset of every control's range are swept, word
    # by word, in test_explorers.py::test_sweep_no_word_contradicts_the_simulated_error
    @settings(
        max_examples=8,
        derandomize=True,
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow],
    )
    @given(changes())
    def check(steps):
        for key, value in steps:
            if key in ex.controls:  # the pattern control replaces the pole controls
                ex.controls[key].value = value
        frame = ex.frame
        assert "could not update" not in ex.message.value
        assert bytes(ex.image.value[:4]) == b"\x89PNG"
        assert frame.curves.get("uio.error") is not None or frame.observer_message
        assert frame.curves.get("lb.error") is not None or frame.luenberger_message
        assert frame.settings == ex.settings

    check()


# static fallback --------------------------------------------------------------------------


class _Links(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.urls: list[str] = []
        self.tags: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        for key, value in attrs:
            if key in ("src", "href", "data-src", "data-narrow", "srcset", "action"):
                self.urls.append(value or "")


@pytest.fixture(scope="module")
def pa9_static():
    return static_explorer(scenario_of("pa9"))


@pytest.mark.slow
def test_static_frames_count_size_and_no_external_url(pa9_static):
    page = pa9_static
    # the pole positions times two disturbance types: the default one and a contrasting one
    assert page.count == len(scenario_of("pa9").static_values) * 2 == 16
    parser = _Links()
    parser.feed(page.html)
    assert "script" not in parser.tags and "link" not in parser.tags
    assert parser.urls and all(u.startswith("data:image/png;base64,") for u in parser.urls)
    assert "http" not in page.html.lower()  # not even by chance inside the base64 text
    assert len(page.html) < 2 * 1024 * 1024
    assert len(re.findall(r'data-k="\d+-\d+"', page.html)) == 16


@pytest.mark.slow
def test_static_ids_are_unique_and_frames_differ():
    grid = {"values": (0.0, 0.9), "disturbances": ("sinusoid",), "narrow": False}
    a = static_explorer(scenario_of("case_study"), **grid)
    b = static_explorer(scenario_of("case_study"), **grid)
    assert a.element_id != b.element_id
    assert a.frames[0].png != a.frames[1].png
    assert a.frames[0].settings.poles == (0.0,) and a.frames[1].settings.poles == (0.9,)


@pytest.mark.slow
def test_static_missile_page_is_light():
    page = static_explorer(scenario_of("missile"))
    assert page.count == 16
    assert len(page.html) < 2 * 1024 * 1024
    assert any("cut off" in f.caption for f in page.frames)
    assert any("unstable" in f.caption for f in page.frames)


def test_static_rejects_bad_grids():
    with pytest.raises(ValueError, match="unknown disturbance"):
        static_explorer(scenario_of("pa9"), disturbances=("hail",))
    with pytest.raises(ValueError, match="at least one value"):
        static_explorer(scenario_of("pa9"), values=())


SET_RANGE = "el => { el.value = 'VALUE'; el.dispatchEvent(new Event('input', {bubbles: true})); }"


@pytest.mark.browser
@pytest.mark.slow
def test_static_slider_swaps_the_frame_in_chromium(tmp_path, pa9_static):
    page_file = tmp_path / "explorer.html"
    page_file.write_text(
        f"<!doctype html><html><body>{pa9_static.html}</body></html>", encoding="utf-8"
    )
    frames = {f.index: f for f in pa9_static.frames}
    eid = pa9_static.element_id
    requests: list[str] = []
    errors: list[str] = []

    def work(browser) -> None:
        tab = browser.new_page()
        tab.on("request", lambda r: requests.append(r.url))
        tab.on("pageerror", lambda exc: errors.append(str(exc)))
        tab.goto(page_file.as_uri())
        img = f"#{eid} img.uio-frame"
        start = tab.get_attribute(img, "src")
        assert start == frames[(3, 0)].data_url  # the default pole -1, sinusoid

        tab.eval_on_selector(
            f"#{eid} input[type=range]",
            SET_RANGE.replace("VALUE", "1"),
        )
        moved = tab.get_attribute(img, "src")
        assert moved != start and moved == frames[(1, 0)].data_url
        assert tab.inner_text(f"#{eid} output") == "-4"
        assert tab.inner_text(f"#{eid} .uio-caption") == frames[(1, 0)].caption
        assert tab.get_attribute(img, "alt") == frames[(1, 0)].alt
        source = f"#{eid} source"  # the phone picture follows the slider too
        assert tab.get_attribute(source, "srcset") == frames[(1, 0)].narrow_url

        tab.select_option(f"#{eid} select", "1")  # random steps
        assert tab.get_attribute(img, "src") == frames[(1, 1)].data_url

        # the slider's right end is the pole map's right: the unstable pole 0.5
        tab.eval_on_selector(
            f"#{eid} input[type=range]",
            SET_RANGE.replace("VALUE", "7"),
        )
        assert "unstable" in tab.inner_text(f"#{eid} .uio-caption")
        natural = tab.eval_on_selector(img, "el => el.naturalWidth")
        assert natural >= 1200

    in_chromium(work)
    assert not errors, errors
    assert all(u.startswith(("file:", "data:")) for u in requests), requests


# dragging poles: ipympl canvas when available, sliders alone otherwise ----------------------


@pytest.mark.slow
def test_drag_uses_an_ipympl_canvas_and_redraws_after_a_resize():
    pytest.importorskip("ipympl")
    ex = widgets.pa9_explorer(static=False, drag=True)
    assert ex.canvas is not None and ex.canvas in ex.widget.children
    ex.set(**{"pole 1": -3.0})
    ex.figure.fig.set_dpi(180)  # what a HiDPI page does to the canvas
    ex.set(**{"pole 1": -2.5})
    fast = np.asarray(ex.figure.fig.canvas.buffer_rgba()).copy()
    ex.figure.fig.canvas.draw()
    full = np.asarray(ex.figure.fig.canvas.buffer_rgba())
    assert fast.shape == full.shape and np.any(fast != full, axis=-1).mean() < 0.003
    ex.close()


def test_without_the_widget_backend_the_sliders_work_alone(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "ipympl.backend_nbagg", None)  # import fails
    assert widgets.drag_available() is False
    ex = widgets.pa9_explorer(static=False, drag=True)
    assert ex.canvas is None and ex.image in ex.widget.children
    ex.set(**{"pole 1": -4.0})
    assert bytes(ex.image.value[:4]) == b"\x89PNG"
    assert ex.settings.poles[0] == -4.0


@pytest.mark.slow
def test_rerunning_a_cell_frees_the_previous_explorer():
    import gc
    import weakref

    first = widgets.case_study_explorer(static=False)
    ref = weakref.ref(first.figure)
    del first
    widgets.case_study_explorer(static=False)
    gc.collect()
    assert ref() is None


@pytest.mark.parametrize("make", ["pa9_explorer", "case_study_explorer", "tank_explorer"])
def test_every_control_has_a_label_and_the_picture_is_put_in_words(make):
    """Every control carries its label (ipywidgets writes it as the control's <label>); the
    picture's text alternative is under it, in a live region read out when it changes."""
    from uio_teach.explorers import widgets

    options = {"static": False} if make == "tank_explorer" else {"static": False, "drag": False}
    ex = getattr(widgets, make)(**options)
    try:
        unnamed = [
            name
            for name, control in ex.controls.items()
            if not (getattr(control, "description", "") or "").strip()
        ]
        assert not unnamed, f"{make}: controls without a label: {unnamed}"
        before = ex.words.value
        assert 'role="status"' in before and 'aria-live="polite"' in before, before
        assert "explorer, " in before and "at observer poles = " in before, before
        assert "error" in before, before
        ex.set(**{"amplitude": 0.0})  # no disturbance: the Luenberger error decays too
        assert ex.words.value != before
        assert ex.words in ex.widget.children
    finally:
        ex.close()
