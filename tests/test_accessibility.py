"""Figures every reader can use: in words, apart without colour, readable on a phone.

* colour vision: the simulation of Machado, Oliveira and Fernandes (2009) keeps greys grey and
  confuses the pairs a dichromat confuses; the course's cycle is the Okabe-Ito palette with a
  line style per colour, in the package and in the book's ``matplotlibrc``; no two curves of a
  panel of an explorer differ by hue alone (every figure of the course: ``test_plotting.py``);
* words: the course's drawing functions describe their figures from the numbers they draw
  (what is plotted, and what the reader should see); a described figure is shown in a notebook
  as HTML with its text alternative, its long description and its phone layout;
* the phone layout stacks the panels in one column at the text size they were drawn with, and
  puts the figure back as it was.

The built pages are checked in a browser by ``test_book.py`` (axe-core, the pictures' text
alternatives, the structure) and ``test_student_edition.py`` (the screen).
"""

from __future__ import annotations

import html
import io
import re
from pathlib import Path

import numpy as np
import pytest

import uio_teach as ut
from uio_teach import colour_vision, figure_text, plotting
from uio_teach.worked import WORKED
from uio_teach.worked.pa9 import PA9

ROOT = Path(__file__).resolve().parents[1]
OKABE_ITO = {"#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#D55E00", "#CC79A7", "#000000"}


# --- colour vision -----------------------------------------------------------------------------


@pytest.mark.parametrize("reader", colour_vision.DEFICIENCIES)
def test_a_simulated_reader_sees_greys_as_greys(reader):
    # each of Machado's matrices maps white to white (its rows sum to one), so greys stay grey
    for level in (0.0, 0.2, 0.5, 0.8, 1.0):
        seen = colour_vision.simulate((level, level, level), reader)
        np.testing.assert_allclose(seen, level, atol=1e-3)


def test_the_pairs_a_dichromat_confuses_are_found():
    # matplotlib's default orange and green for a protanope, green and red for a deuteranope
    assert colour_vision.colour_distance("#ff7f0e", "#2ca02c", "protanopia") < 10
    assert colour_vision.colour_distance("#2ca02c", "#d62728", "deuteranopia") < 10
    assert colour_vision.colour_distance("#ff7f0e", "#2ca02c") > 50  # apart for normal vision
    with pytest.raises(ValueError, match="deficiency must be one of"):
        colour_vision.simulate("red", "achromatopsia")


def test_the_course_cycle_is_okabe_ito_with_a_line_style_per_colour():
    assert set(plotting.COLORS) <= OKABE_ITO
    assert "#F0E442" not in plotting.COLORS  # the yellow is too light on white
    assert len(set(plotting.COLORS)) == len(plotting.COLORS) == len(plotting.LINESTYLES)
    assert len({str(s) for s in plotting.LINESTYLES}) == len(plotting.LINESTYLES)
    # any two channels stay apart for every reader: by style, whatever their colours
    fig = plotting.new_figure()
    ax = fig.subplots()
    for i in range(len(plotting.COLORS)):
        ax.plot([0, 1], [i, i], **plotting.channel_style(i), label=f"c{i}")
    assert colour_vision.curves_apart_by_hue_alone(fig) == []


def test_the_books_matplotlibrc_has_the_course_cycle():
    import matplotlib as mpl

    rc = mpl.rc_params_from_file(ROOT / "book" / "matplotlibrc", use_default_template=False)
    cycle = rc["axes.prop_cycle"].by_key()
    assert [c.upper() for c in cycle["color"]] == [c.upper() for c in plotting.COLORS]
    assert [str(s) for s in cycle["linestyle"]] == [str(s) for s in plotting.LINESTYLES]


def test_the_check_needs_a_style_or_a_colour_difference_every_reader_sees():
    fig = plotting.new_figure()
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1], color=plotting.COLORS[0], label="a")
    ax.plot([0, 1], [1, 0], color=plotting.COLORS[2], label="b")  # blue, bluish green
    found = colour_vision.curves_apart_by_hue_alone(fig)
    assert [f[1:] for f in found] == [("a", "b", "tritanopia")]
    ax.lines[1].set_marker("o")
    assert colour_vision.curves_apart_by_hue_alone(fig) == []
    # twenty runs of one series, drawn alike, are one series, not twenty curves to tell apart
    ax.cla()
    for k in range(20):
        ax.plot([0, 1], [k, k + 1], color="C0", ls="-")
    assert colour_vision.curves_apart_by_hue_alone(fig) == []


@pytest.mark.slow  # every explorer drawn
@pytest.mark.parametrize("narrow", [False, True])
@pytest.mark.parametrize("name", list(WORKED))
def test_no_two_curves_of_an_explorer_differ_by_hue_alone(name, narrow):
    from uio_teach.explorers import compute_frame
    from uio_teach.explorers._figure import ExplorerFigure
    from uio_teach.explorers.scenarios import scenario_of

    sc = scenario_of(name)
    fig = ExplorerFigure(sc, dpi=60, sticky=False, narrow=narrow, lmi=False)
    fig.update(compute_frame(sc))
    assert colour_vision.curves_apart_by_hue_alone(fig.fig) == [], name


# --- figures in words --------------------------------------------------------------------------


def test_a_response_figure_says_what_the_error_does():
    plant = PA9.plant()
    uio = PA9.simulate(ut.design_uio(plant, poles=PA9.poles), d=PA9.d_sine)
    luen = PA9.simulate(ut.design_luenberger(plant, poles=PA9.poles), d=PA9.d_sine)
    said = plotting.description(uio.plot(title="UIO"))
    assert said.alt.startswith("UIO: against time, each state (x1, x2, x3)")
    assert "The error decays to zero" in said.alt, said.alt
    assert re.search(r"e2 \(vermillion, dashed\) decays to zero", said.details), said.details
    # the Luenberger observer's error follows d: the words say so
    said = plotting.description(luen.plot(title="Luenberger"))
    assert "The error does not settle on zero" in said.alt, said.alt
    import matplotlib.pyplot as plt

    plt.close("all")


def test_an_input_figure_and_the_banks_figure_say_what_they_show():
    plant = PA9.plant()
    resp = PA9.simulate(ut.design_uio(plant, poles=PA9.poles), d=PA9.d_sine)
    fig = ut.reconstruct_input(plant, resp).plot(symbol="v")
    alt = plotting.description(fig).alt
    assert "each unknown input (v1)" in alt and "decays to zero" in alt, alt
    # the bank: which members raise an alarm in which run
    sensors = ut.Plant(plant.A, np.eye(3), B=plant.B, E=plant.E)
    bank = ut.design_uio_bank(sensors, "sensor", poles=[-2, -3, -4])
    t = np.linspace(0, 4, 401)
    detector = ut.design_uio(sensors, poles=[-1, -2, -3])
    healthy = [ut.simulate_fault(sensors, detector, t, noise=0.01, seed=k) for k in range(20)]
    ths = bank.thresholds(healthy, false_alarm_rate=0.05, window=0.5)
    fig = plotting.plot_bank_alarms(t, {"no fault": healthy[0]}, [bank], [ths])
    said = plotting.description(fig)
    assert said.alt.startswith("Alarms of the bank of UIOs, one panel per run")
    assert said.details.startswith("Run no fault: ")
    # on a phone the legend of the whole figure takes one column: the picture fits a phone
    before = _drawn(fig)
    narrow = re.search(r'srcset="[^"]+" width="(\d+)"', figure_text.figure_html(fig))
    assert int(narrow.group(1)) <= 1.1 * figure_text.NARROW_WIDTH * fig.dpi, narrow.group(1)
    assert _drawn(fig) == before
    import matplotlib.pyplot as plt

    plt.close("all")


def test_describe_wants_words():
    fig = plotting.new_figure()
    with pytest.raises(ValueError, match="alt must say what the figure shows"):
        figure_text.describe(fig, "   ")
    figure_text.describe(fig, "First words.", "Long.")
    figure_text.describe(fig, "Second words.")  # keeps the long description
    assert figure_text.description(fig) == figure_text.FigureDescription("Second words.", "Long.")
    with pytest.raises(ValueError, match="no description"):
        figure_text.figure_html(plotting.new_figure())


def _drawn(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=40)
    return buffer.getvalue()


def test_the_html_holds_the_words_and_the_phone_layout_and_leaves_the_figure_as_it_was():
    resp = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles), d=PA9.d_sine)
    fig = plotting.plot_response(resp, fig=plotting.new_figure(9, 6), title='UIO "PA9" <run>')
    before = _drawn(fig)
    text = figure_html_of(fig)
    assert _drawn(fig) == before  # the phone layout was undone
    said = plotting.description(fig)
    assert f'alt="{html.escape(said.alt)}"' in text
    ident = re.search(r'aria-describedby="([\w-]+)"', text).group(1)
    assert f'<p id="{ident}">{html.escape(said.details)}</p>' in text
    assert "<summary>What the figure shows, in words</summary>" in text
    assert f'media="(max-width: {figure_text.NARROW_SCREEN_PX}px)"' in text
    assert "data-hue-alone" not in text


def figure_html_of(fig) -> str:
    return figure_text.figure_html(fig)


def test_the_phone_layout_is_one_column_with_the_text_as_drawn():
    resp = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles), d=PA9.d_sine)
    fig = plotting.plot_response(resp, fig=plotting.new_figure(9, 6))
    sizes = sorted({t.get_fontsize() for t in fig.findobj(lambda a: hasattr(a, "get_fontsize"))})
    with figure_text.narrow_layout(fig):
        columns = {ax.get_subplotspec().colspan.start for ax in fig.axes}
        rows = [ax.get_subplotspec().rowspan.start for ax in fig.axes]
        width = fig.get_size_inches()[0]
        inside = sorted(
            {t.get_fontsize() for t in fig.findobj(lambda a: hasattr(a, "get_fontsize"))}
        )
        legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
        above = all(
            lg.get_bbox_to_anchor().y0 >= ax.bbox.y1 - 1
            for ax, lg in zip(
                [ax for ax in fig.axes if ax.get_legend() is not None], legends, strict=True
            )
        )
    assert columns == {0} and sorted(rows) == list(range(len(fig.axes)))
    assert width == figure_text.NARROW_WIDTH
    assert inside == sizes  # the text keeps its size
    assert above  # a legend beside a panel moves above it
    # shown in a phone's column (358 CSS px of 390), the smallest text is at least 9 px
    smallest_px = min(sizes) * fig.dpi / 72 * min(1.0, 358 / (figure_text.NARROW_WIDTH * fig.dpi))
    assert smallest_px >= 9, smallest_px
    assert {ax.get_subplotspec().colspan.start for ax in fig.axes} == {0, 1}  # put back


def test_a_notebook_shows_a_described_figure_as_html():
    from IPython.core.interactiveshell import InteractiveShell

    shell = InteractiveShell.instance()
    try:
        fig = plotting.new_figure(4, 3)
        fig.subplots().plot([0, 1], [1, 0])
        data, meta = shell.display_formatter.format(fig)
        assert "text/html" not in data  # not described: a plain picture
        figure_text.describe(fig, "A line falling from 1 to 0.")
        data, meta = shell.display_formatter.format(fig)
        assert 'alt="A line falling from 1 to 0."' in data["text/html"]
        assert meta["image/png"]["alt"] == "A line falling from 1 to 0."
    finally:
        InteractiveShell.clear_instance()


def test_every_chapter_figure_is_described_in_its_cell():
    """A chapter that draws a figure itself (plt.subplots, plt.figure) describes it in the cell
    (``ut.plotting.describe``); the package's figures describe themselves."""
    missing = []
    for source in sorted((ROOT / "book").glob("*.md")):
        text = source.read_text(encoding="utf-8")
        for cell in re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, flags=re.S):
            drawn = re.search(r"plt\.(subplots|figure)\(", cell) and "plt.show()" in cell
            by_package = re.search(r"\.plot\(\s*fig=", cell)  # a package figure: described
            if drawn and not by_package and "describe(" not in cell:
                missing.append(f"{source.name}: {cell.strip().splitlines()[0][:60]}")
    assert not missing, f"figures drawn in a cell without a description: {missing}"


def test_no_prose_points_at_the_left_or_the_right_of_a_figure_alone():
    """On a phone a figure's panels are stacked: a sentence that names the left or the right
    panels says where they are on a phone too (or names the panels by what they show)."""
    found = []
    for source in sorted((ROOT / "book").glob("*.md")):
        for paragraph in re.split(r"\n\s*\n", source.read_text(encoding="utf-8")):
            words = " ".join(paragraph.split())
            for m in re.finditer(r"\b(on the (left|right)|Left:|Right:)", words):
                around = words[max(0, m.start() - 80) : m.end() + 80]
                if not re.search(r"phone|wide screen|side of|half-plane|\$", around):
                    found.append(f"{source.name}: {around}")
    assert not found, found


# --- names that keep their mathematics (_ext/a11y.py) -------------------------------------------


def _a11y_extension():
    import importlib.util

    spec = importlib.util.spec_from_file_location("uio_a11y_ext", ROOT / "_ext" / "a11y.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize(
    ("tex", "words"),
    [
        (r"\gamma_1 + \gamma_2 = 1", "gamma sub 1 plus gamma sub 2 equals 1"),
        (r"(TA, C)", "(T A, C)"),
        (r"0.5^k", "0.5 to the power k"),
        (r"M_v", "M sub v"),
        (r"K_{1}", "K sub 1"),
        (r"Dv", "D v"),
        (r"CE = 0", "C E equals 0"),
        (r"(I - MC)E = 0", "(I minus M C) E equals 0"),
        (r"\hat{x}", "x hat"),
        (r"E^{+}", "E pseudo-inverse"),
        (r"(CE)^T", "(C E) transpose"),
        (r"\operatorname{rank}(CE) = \operatorname{rank} E", "rank (C E) equals rank E"),
        (r"\frac{1}{s}", "1 over s"),
        (r"\mathbf{x}_{k+1}", "x sub k plus 1"),
    ],
)
def test_a_formula_is_said_in_words(tex, words):
    assert _a11y_extension().tex_words(tex) == words


def test_headings_and_links_holding_a_formula_are_named_with_it_in_words():
    ext = _a11y_extension()
    math = '<span class="math notranslate nohighlight">\\({}\\)</span>'
    page = (
        f'<h3><span class="section-number">4.5.1. </span>{math.format("H")} and '
        f'{math.format("T")}, and how the assignment printed them<a class="headerlink" '
        'href="#h" title="Link to this heading">#</a></h3>\n'
        f'<a class="reference internal nav-link" href="#v">Why {math.format("M_v")} and '
        f"{math.format('K_v')} do nothing here</a>\n"
        '<a href="#plain">No formula</a>\n'
        f'<a aria-label="given" href="#g">{math.format("x &lt; 1")}</a>'
    )
    named, count = ext.name_formulas(page)
    assert count == 2
    assert '<h3 aria-label="4.5.1. H and T, and how the assignment printed them">' in named
    assert 'aria-label="Why M sub v and K sub v do nothing here">' in named
    assert '<a href="#plain">No formula</a>' in named  # no formula: left alone
    assert named.count('aria-label="given"') == 1  # a name given already is kept
    assert ext.name_formulas(named) == (named, 0)  # done once
    assert ext.spoken_name(math.format("x &lt; 1")) == "x less than 1"


# --- the explorers say what the error did -------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "settings"),
    [
        ("pa9", {}),
        ("pa9", {"poles": (0.5, -2.0, -3.0)}),  # an unstable pole: the error grows
        ("case_study", {}),
        ("case_study", {"poles": (1.05,)}),
        ("missile", {}),
        ("quadruple_tank", {}),
    ],
)
def test_the_live_region_says_what_the_error_did_and_how_fast_from_the_data(name, settings):
    from uio_teach.explorers import compute_frame, scenario_of
    from uio_teach.explorers.static import frame_status

    sc = scenario_of(name)
    frame = compute_frame(sc, sc.defaults.replace(**settings) if settings else sc.defaults)
    said = frame_status(frame, "main control (others 1, 2)", "-1")
    assert said.startswith(f"main control = -1, {frame.disturbance}.")
    assert "(others" not in said and "poles" not in said  # the outcome, not the settings' list
    t = np.asarray(frame.time, dtype=float)
    for who, response in (
        (sc.observer_name, frame.response),
        ("Luenberger observer", frame.luenberger_response),
    ):
        if response is None:
            continue
        size = np.sqrt(np.sum(np.asarray(response.error, dtype=float) ** 2, axis=0))
        sentence = re.search(rf"{re.escape(who)}: the error ([^.]*(?:\.\d[^.]*)*)\.", said)
        assert sentence, (who, said)
        words = sentence.group(1)
        if not np.all(np.isfinite(size)):
            continue
        start, end = size[0], size[-1]
        # the verb and the numbers: the sizes |e| at the start and the end of the data
        numbers = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", words)]
        if "decays" in words or "grows" in words or "shrinks" in words:
            assert ("grows" in words) == (end > start), (who, words, start, end)
            assert any(np.isclose(n, start, rtol=6e-3) for n in numbers), (words, start)
            assert any(np.isclose(n, end, rtol=6e-3) for n in numbers), (words, end)
        # how fast: tenfold every tau, so that start * 10**(+-span / tau) is the end
        pace = re.search(r"ten times (smaller|larger) every ([\d.e+-]+) (s|steps)", words)
        if pace:
            tau = float(pace.group(2))
            sign = 1 if pace.group(1) == "larger" else -1
            predicted = np.log10(start) + sign * (t[-1] - t[0]) / tau
            # two significant digits of tau: the decades agree to about 5 %
            assert abs(predicted - np.log10(end)) <= max(0.05 * abs(np.log10(end / start)), 1e-6)
    import matplotlib.pyplot as plt

    plt.close("all")


def test_a_static_explorer_speaks_once_after_the_control_rests():
    from uio_teach.explorers import scenario_of
    from uio_teach.explorers.static import SETTLE_MS, static_explorer

    page = static_explorer(scenario_of("pa9"), values=(-1.0, 0.5), disturbances=("sinusoid",))
    text = page.html
    # one live region, the status; the caption (poles and notes) is not read at every step
    assert text.count('aria-live="polite"') == 1 and 'role="status"' in text
    assert '<output name="mainval" aria-live="off">' in text  # the slider says its value
    assert '<p class="uio-caption">' in text
    assert 'aria-label="controls of the PA9 explorer"' in text  # the form has a name
    for frame in page.frames:
        assert f'data-said="{html.escape(frame.said)}"' in text
        assert frame.said.split(". ")[0] == f"UIO pole 1 = {frame.label}, {'sinusoid'}" or (
            frame.said.startswith("UIO pole 1 = ")
        )
    # the words of the unstable frame: the error grows
    assert "the error grows" in page.frames[1].said
    # it speaks when the control has rested (a timer reset by every move), only if new words
    assert f"}},{SETTLE_MS});" in text.replace("&#x27;", "'")
    assert "o.textContent!==s" in text.replace("&#x27;", "'").replace("&quot;", '"')


def test_the_error_panels_name_their_channels():
    from uio_teach.explorers import compute_frame, scenario_of
    from uio_teach.explorers._figure import ExplorerFigure

    for name in ("pa9", "quadruple_tank"):
        sc = scenario_of(name)
        fig = ExplorerFigure(sc, dpi=60, sticky=False)
        fig.update(compute_frame(sc))
        for who in ("uio", "lb"):
            legend = fig.axes[f"{who}.error"].get_legend()
            assert legend is not None, (name, who)
            texts = [t.get_text() for t in legend.get_texts()]
            channels = [plotting.symbol("e", i) for i in range(sc.plant.n)]
            assert texts[: sc.plant.n] == channels, (name, who, texts)
    import matplotlib.pyplot as plt

    plt.close("all")


# --- areas of a figure stand out: 3:1 (WCAG 2.1, 1.4.11) ----------------------------------------


def test_a_shaded_band_stands_out_and_a_faint_one_is_found():
    fig = plotting.new_figure()
    ax = fig.subplots()
    plotting.shade_band(ax, 0.0, 0.5, "no UIO")
    assert plotting.low_contrast_areas(fig) == []
    ax.axvspan(0.6, 0.8, color=plotting.COLORS[3], alpha=0.08, label="faint")
    assert plotting.low_contrast_areas(fig) == [("faint", 1.08)]
    import matplotlib.pyplot as plt

    plt.close("all")


def test_the_packages_bands_stand_out():
    """The figures of the package that shade a region: the tank's "no UIO" band, the bank's
    start before monitoring begins (every area checked, named in the legend or not)."""
    from uio_teach.instructor.config import FigureConfig
    from uio_teach.instructor.figures import FIGURES, _Runs

    fig = FIGURES["tank_zeros"].draw(_Runs(FigureConfig()))
    for ax in fig.axes:
        for patch in ax.patches:
            patch.set_label("band")
    assert plotting.low_contrast_areas(fig) == []
    assert any(ax.patches for ax in fig.axes)
    import matplotlib.pyplot as plt

    plt.close("all")


def test_the_chapters_shade_areas_with_the_course_band_and_colours():
    """No chapter draws a faint band or picks matplotlib's named colours ("tab:red"): a band is
    ``ut.plotting.shade_band``, colours come from the course's palette."""
    found = []
    for source in sorted((ROOT / "book").glob("*.md")):
        text = source.read_text(encoding="utf-8")
        for cell in re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, flags=re.S):
            for m in re.finditer(r"axvspan\(|axhspan\(|[\"']tab:\w+[\"']", cell):
                found.append(f"{source.name}: {m.group(0)}")
    assert not found, found
