"""A figure's words say what its picture shows: every claim is checked against the drawn curves.

The words of a figure (its text alternative and long description) are what a reader who cannot
see the picture gets instead of it. These tests read the words back, claim by claim, and check
each against the data the figure draws, recomputed here from the curves themselves (their
``get_xdata``/``get_ydata``), not from the code that wrote the words:

- each channel's colour and line style named in the words is the drawn one's;
- "decays to zero (below 2% of its peak from t = T s on)", "does not settle on zero: ... P% of
  its peak" and "is zero to rounding throughout" hold for the drawn curve, with T and P as
  printed;
- a state's range "x1 from A to B" is the drawn curve's;
- the explorer frames' words name the poles, zeros and guide lines their pole map and error
  panel draw, and the value and disturbance the frame shows;
- every figure of ``uio-teach figures`` names only colours and line styles it draws.

The checks run over classes of figures (every response figure of the course's experiments,
every explorer's default frame, every figure of the registry), so a new figure of the same kind
is checked too.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import uio_teach as ut
from uio_teach import plotting
from uio_teach.worked import WORKED
from uio_teach.worked.case_study import CASE_STUDY
from uio_teach.worked.missile import MISSILE
from uio_teach.worked.pa9 import PA9

# the names the words use, written out here independently of the package's tables
COLOUR = {
    "blue": "#0072b2",
    "vermillion": "#d55e00",
    "bluish green": "#009e73",
    "reddish purple": "#cc79a7",
    "orange": "#e69f00",
    "sky blue": "#56b4e9",
    "black": "#000000",
}
STYLE = {"solid": "-", "dashed": "--", "dash-dotted": "-.", "dotted": ":"}
SETTLED = 0.02  # "below 2% of its peak"


def _hex(line) -> str:
    from matplotlib.colors import to_hex

    return to_hex(line.get_color()).lower()


def _settling_words(x: np.ndarray, y: np.ndarray, *, discrete: bool) -> tuple[str, str]:
    """What the words may say of one drawn curve: ('decays', when), ('unsettled', share), or
    ('zero', '') -- recomputed from the curve."""
    a = np.abs(np.atleast_2d(y))
    worst = a.max(axis=0)
    peak = float(worst.max())
    above = np.flatnonzero(worst > SETTLED * peak)
    last = int(above[-1]) if above.size else -1
    n = worst.size
    if last + 1 >= n or n - last < max(2, n // 20):
        return "unsettled", f"{worst[-max(1, n // 10) :].max() / peak:.0%}"
    when = x[last + 1]
    return "decays", (f"step {when:g}" if discrete else f"t = {when:.3g} s")


def _check_channel_claim(claim: str, line, *, discrete: bool, scale: float) -> None:
    """One channel's claim (the part after its colour and style) against its drawn curve."""
    x = np.asarray(line.get_xdata(), float)
    y = np.asarray(line.get_ydata(), float)
    if claim.startswith("is zero to rounding"):
        assert np.abs(y).max() <= 1e-8 * scale, (claim, np.abs(y).max())
        return
    kind, value = _settling_words(x, y, discrete=discrete)
    if claim.startswith("decays to zero"):
        assert kind == "decays", (claim, kind, value)
        assert f"from {value} on" in claim, (claim, value)
    elif claim.startswith("does not settle on zero"):
        assert kind == "unsettled", (claim, kind, value)
        assert f"still {value} of its peak" in claim, (claim, value)
    else:
        raise AssertionError(f"a claim these tests cannot read: {claim!r}")


def _panel(fig, start: str):
    return [ax for ax in fig.axes if ax.get_ylabel().startswith(start)]


def _check_response_words(fig, resp) -> int:
    """Every claim of a response figure's words against its drawn curves; returns the count."""
    said = plotting.description(fig)
    assert said is not None
    discrete = resp.plant.dt not in (None, 0)
    checked = 0
    scale = float(np.abs(resp.states).max())
    # the state ranges: "x1 from A to B" is the drawn state's range
    for i, low, high in re.findall(r"x(\d+) from (\S+) to (\S+?)[,( ]", said.details):
        (ax,) = [a for a in fig.axes if a.get_ylabel().startswith(f"$x_{{{i}}}$")]
        y = np.asarray(ax.get_lines()[0].get_ydata(), float)
        assert (f"{y.min():.3g}", f"{y.max():.3g}") == (low, high), (i, low, high)
        checked += 1
    # each channel: its colour, its line style, what it does
    for panel, letter in (("Error panel: ", "e"), ("Residual panel: ", "r")):
        part = said.details.split(panel)[1].split(" Residual panel: ")[0].rstrip(".")
        (ax,) = _panel(fig, "error" if letter == "e" else "residual")
        lines = {line.get_label(): line for line in ax.get_lines()}
        for claim in part.split("; "):
            m = re.match(rf"{letter}(\d+) \(([a-z ]+), ([a-z-]+)\) (.*)$", claim)
            assert m, claim
            line = lines[f"${letter}_{{{m[1]}}}$"]
            assert COLOUR[m[2]] == _hex(line), (claim, _hex(line))
            assert STYLE[m[3]] == line.get_linestyle(), (claim, line.get_linestyle())
            _check_channel_claim(m[4], line, discrete=discrete, scale=scale)
            checked += 1
    # the text alternative's summary of all channels: every channel below 2% of the largest
    # peak from the time it names (recomputed over the panel's curves together)
    for what in ("error", "residual"):
        (ax,) = _panel(fig, what)
        curves = [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")]
        x = np.asarray(curves[0].get_xdata(), float)
        ys = np.array([ln.get_ydata() for ln in curves], float)
        m = re.search(
            rf"[Tt]he {what} (is zero to rounding throughout|decays to zero \([^)]*\)|"
            r"does not settle on zero: .*? of the largest peak|does not settle on zero: .*? of "
            r"its peak)",
            said.alt,
        )
        assert m, said.alt
        if "zero to rounding" in m[1]:
            assert np.abs(ys).max() <= 1e-8 * scale
        elif "decays to zero" in m[1]:
            kind, value = _settling_words(x, ys, discrete=discrete)
            assert kind == "decays" and f"from {value} on" in m[1], (m[1], kind, value)
        else:
            assert _settling_words(x, ys, discrete=discrete)[0] == "unsettled", m[1]
        checked += 1
    return checked


def _responses():
    pa9 = PA9.plant()
    uio = ut.design_uio(pa9, poles=PA9.poles)
    luen = ut.design_luenberger(pa9, poles=PA9.poles)
    case = CASE_STUDY.plant()
    missile = MISSILE.plant()
    pmo = ut.design_pmo(missile, poles=MISSILE.poles)
    return {
        "pa9 UIO, sinusoid": PA9.simulate(uio, d=PA9.d_sine),
        "pa9 UIO, steps": PA9.simulate(uio, d=PA9.d_piecewise),
        "pa9 Luenberger, sinusoid": PA9.simulate(luen, d=PA9.d_sine),
        "case study PMO": CASE_STUDY.simulate(ut.design_pmo(case, method="lmi")),
        "missile PMO": MISSILE.simulate(pmo),
    }


@pytest.fixture(scope="module")
def responses():
    return _responses()


@pytest.mark.parametrize(
    "name",
    [
        "pa9 UIO, sinusoid",
        "pa9 UIO, steps",
        "pa9 Luenberger, sinusoid",
        "case study PMO",
        "missile PMO",
    ],
)
def test_a_response_figures_words_are_its_curves(responses, name):
    """plot_response: colours, styles, ranges, settling times and "zero to rounding" as drawn."""
    resp = responses[name]
    fig = resp.plot(fig=plotting.new_figure(9.0, 6.0), title=name)
    assert _check_response_words(fig, resp) >= 2 * resp.plant.n + resp.plant.p


def test_the_words_of_a_response_fail_when_a_curve_changes(responses):
    """The check above can fail: a drawn error that no longer decays contradicts its words."""
    resp = responses["pa9 UIO, sinusoid"]
    fig = resp.plot(fig=plotting.new_figure(9.0, 6.0), title="PA9")
    (ax,) = _panel(fig, "error")
    line = ax.get_lines()[0]
    y = np.asarray(line.get_ydata(), float).copy()
    y[-len(y) // 4 :] = np.abs(y).max()  # the last quarter held at the peak
    line.set_ydata(y)
    with pytest.raises(AssertionError):
        _check_response_words(fig, resp)


def test_an_input_estimates_words_are_its_curves(responses):
    """plot_input_estimate: "the gap between v1 and its reconstruction ..." as drawn."""
    resp = responses["missile PMO"]
    est = ut.reconstruct_input(resp.plant, resp)
    fig = est.plot(symbol="v", title="reconstruction")
    said = plotting.description(fig).alt
    claims = re.findall(r"the gap between v(\d+) and its reconstruction ([^;]*)", said, re.I)
    assert len(claims) == est.estimates.shape[0], said
    for i, claim in claims:
        (ax,) = [a for a in fig.axes if a.get_ylabel().startswith(f"$v_{{{i}}}$")]
        actual, hat = ax.get_lines()[:2]
        assert _hex(hat) == COLOUR["black"] and hat.get_linestyle() == "--"  # "dashed in black"
        gap = np.asarray(hat.get_ydata(), float) - np.asarray(actual.get_ydata(), float)
        kind, value = _settling_words(np.asarray(actual.get_xdata(), float), gap, discrete=False)
        assert "decays to zero" in claim and kind == "decays" and f"from {value} on" in claim


def test_how_it_ends_says_what_a_reader_sees():
    """how_it_ends on signals whose fate is known in closed form."""
    t = np.linspace(0.0, 10.0, 1001)
    when = np.log(1 / SETTLED)  # exp(-t) is below 2% of its peak (1) from this time on
    words = plotting.how_it_ends(t, np.exp(-t))
    assert f"t = {t[np.searchsorted(t, when, side='right')]:.3g} s" in words, words
    assert "does not settle" in plotting.how_it_ends(t, np.sin(t))
    # several channels: every one below 2% of the largest peak, said so
    words = plotting.how_it_ends(t, [np.exp(-t), 0.1 * np.exp(-0.5 * t)])
    assert "every channel below 2% of the largest peak" in words, words
    assert plotting.how_it_ends(t, 1e-15 * np.ones((2, t.size)), 1.0).startswith("is zero")


def test_line_look_reads_the_drawn_curve():
    fig = plotting.new_figure()
    ax = fig.subplots()
    for name, colour in COLOUR.items():
        for style, ls in STYLE.items():
            (line,) = ax.plot([0, 1], color=colour, ls=ls)
            assert plotting.line_look(line) == f"{name}, {style}"
    (line,) = ax.plot([0, 1], "s--", color=COLOUR["vermillion"])
    assert plotting.line_look(line) == "vermillion, dashed, squares"


@pytest.fixture(scope="module")
def bank_figure():
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
    runs = {
        f"{kind} {i + 1}": ut.simulate_fault(
            plant,
            detector,
            t,
            (ut.sensor_fault if kind == "sensor" else ut.actuator_fault)(
                plant, i, ut.signals.step(0.3, 3.0)
            ),
            noise=0.01,
            seed=99,
        )
        for kind, i in (("actuator", 0), ("sensor", 0), ("sensor", 2))
    }
    runs["no fault"] = healthy[0]
    fig = plotting.plot_bank_alarms(t, runs, banks, ths, fault_time=3.0, fig=plotting.new_figure())
    return fig, ths[0][0].start


def test_the_bank_figures_words_are_its_curves(bank_figure):
    """plot_bank_alarms: who raises an alarm in each run, and which alarms end early, as drawn."""
    fig, start = bank_figure
    said = plotting.description(fig)
    runs = re.findall(r"Run (?:fault: )?(.*?): (.*?)(?= Run |$)", said.details)
    panels = {ax.get_title().removeprefix("fault: "): ax for ax in fig.axes if ax.get_visible()}
    assert [name for name, _ in runs] == list(panels)
    checked = 0
    for name, words in runs:
        loud = words.split(";")[0]
        for line in panels[name].get_lines():
            label = line.get_label()
            if not label.startswith("blind to "):
                continue
            member = label.removeprefix("blind to ")
            x = np.asarray(line.get_xdata(), float)
            y = np.asarray(line.get_ydata(), float)
            alarm = (y > 1.0) & (x >= start)
            named = re.search(rf"\b{member}\b", loud.split(" (")[0]) is not None
            assert named == bool(alarm.any()), (name, member, words)
            ended = re.search(rf"blind to {member} falls back below 1 at t = (\S+) s", words)
            if alarm.any() and alarm[-1]:
                assert ended is None, (name, member, words)
            elif alarm.any():
                assert ended and ended[1] == f"{x[alarm][-1]:.3g}", (name, member, words)
            checked += 1
    assert checked == 5 * len(runs)


@pytest.mark.parametrize("name", list(WORKED))
def test_an_explorer_frames_words_are_its_picture(name):
    """The static frame's words name the value, disturbance, poles, zeros and guides drawn."""
    from uio_teach.explorers import compute_frame, render, scenario_of
    from uio_teach.explorers.static import frame_alt, main_control_label

    sc = scenario_of(name)
    frame = compute_frame(sc)
    words = frame_alt(frame, main_control_label(sc, frame.settings), "VALUE")
    fig = render(sc, frame.settings)
    assert "= VALUE" in words.split(". ")[0], words  # the value next to the control's name
    # the disturbance named is the one in the figure's title
    title = fig._suptitle.get_text() if fig._suptitle else ""
    said_disturbance = words.split(" explorer, ")[1].split(", at ")[0]
    assert said_disturbance in title, (said_disturbance, title)
    # the pole map: crosses, plus signs and open circles at the numbers the words give
    marks = {}
    for ax in fig.axes:
        for line in ax.get_lines():
            if line.get_marker() in ("x", "+", "o") and line.get_linestyle() in ("None", ""):
                marks[line.get_marker()] = np.sort_complex(
                    np.asarray(line.get_xdata(), float) + 1j * np.asarray(line.get_ydata(), float)
                )
    for marker, what in (("x", "(crosses)"), ("+", "(plus signs)"), ("o", "(open circles)")):
        pole_map = (
            words.split("Pole map: ")[1].split(". Panels")[0] if "Pole map: " in words else ""
        )
        m = re.search(r"(?:poles|zeros) ([^;(]*) " + re.escape(what), pole_map)
        drawn = marks.get(marker, np.array([]))
        if not drawn.size:
            assert m is None, (what, words)
            continue
        assert m, (what, words)
        said = [complex(v) for v in _numbers(m[1])]
        np.testing.assert_allclose(np.sort_complex(said), drawn, rtol=5e-3, atol=5e-3)
    # the error panels: as many curves as the words say channels
    n = int(re.search(r"each of the (\d+) error channels", words)[1])
    assert n == sc.plant.n
    # the guide lines named are drawn over the observer's error, in the style named
    (panel,) = [ax for ax in fig.axes if ax.get_title().startswith(sc.observer_name)]
    guides = {  # the curves drawn: a legend entry without data draws nothing
        ln.get_label(): _dash_words(ln)
        for ln in panel.get_lines()
        if np.isfinite(np.asarray(ln.get_ydata(), float)).any()
    }
    named = re.findall(r"(rate of slowest (\w+) pole|certified)[^;(]* \(([\w-]+)\)", words)
    for _, which, style in named:
        key = f"slowest {which}" if which else "certified"
        assert guides.get(key) == style, (key, style, guides)
    shown = {k for k in guides if k in ("slowest moved", "slowest fixed", "certified")}
    assert shown == {f"slowest {w}" if w else "certified" for _, w, _ in named}, (shown, words)


def _dash_words(line) -> str:
    """A drawn line's style in words, from its dash pattern (on, off, on, off ... in points)."""
    _, dashes = line._dash_pattern
    if line.get_linestyle() in ("None", ""):
        return "no line"
    if not dashes:
        return "solid"
    if len(dashes) >= 4:
        return "dash-dotted"
    return "dotted" if dashes[0] <= 1.5 * line.get_linewidth() else "dashed"


def _numbers(text: str) -> list[str]:
    """The complex numbers of a list as format_poles prints them ("-1, -2 - 3j, -2 + 3j")."""
    out = []
    for part in text.split(", "):
        out.append(part.replace(" + ", "+").replace(" - ", "-").strip())
    return out


@pytest.mark.slow  # every course figure drawn
def test_every_course_figure_names_only_what_it_draws():
    """Every figure of ``uio-teach figures``: each colour-and-style pair its words name is a
    drawn curve's, and each "x1 ... x4" list of states has a panel per state."""
    from uio_teach.instructor import figures

    runs = figures._Runs(figures.FigureConfig())
    checked = 0
    for name, spec in figures.FIGURES.items():
        if spec.table:
            continue
        fig = spec.draw(runs)
        said = plotting.description(fig)
        assert said is not None, name
        text = f"{said.alt} {said.details}"
        drawn = {(_hex(line), line.get_linestyle()) for ax in fig.axes for line in ax.get_lines()}
        pairs = re.findall(r"\((" + "|".join(COLOUR) + r"), (" + "|".join(STYLE) + r")\)", text)
        for colour, style in pairs:
            assert (COLOUR[colour], STYLE[style]) in drawn, (name, colour, style)
            checked += 1
        for m in re.finditer(r"each state \(([^)]*)\)|one panel per state x1 to x(\d)", text):
            count = len(m[1].split(", ")) if m[1] else int(m[2])
            states = [ax for ax in fig.axes if re.match(r"\$x_\{\d\}\$", ax.get_ylabel())]
            assert len(states) == count, (name, m[0])
            checked += 1
    assert checked >= 10
