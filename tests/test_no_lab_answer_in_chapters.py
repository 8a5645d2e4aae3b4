"""No chapter prints a lab's answer: every number in the built chapters' outputs against the labs'.

A chapter runs the course's experiments; a lab asks a group for the same computations on its
own numbers (the lab's defaults, or a group's draw of ``uio-teach labs --groups``). This test
reads every number the built book's chapters print in their cells' outputs and compares it, at
the precision it is printed with, with every number a group must find: the answer key of the
lab (``LabParams.answers``), and for the missile the catch times of Table II and the noise RMS
its checks recompute. The matrices fixed by a source document alone (the printed ``H``, ``T``
of the assignment, the case study's ``M``, ``A1``, the missile paper's ``M``, ``Cg``, ``Pc``,
``Kg`` and the fixed modes) are the documents' own, which the chapters reproduce and a lab on
the document's plant reproduces too: they are left out for a group on that plant, and compared
for a group with a plant of its own.
"""

from __future__ import annotations

import dataclasses
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from test_book import PAGES

import uio_teach as ut
from uio_teach.instructor.lab_registry import LABS
from uio_teach.instructor.variants import draw_variants
from uio_teach.lab_params import lab_value
from uio_teach.worked import WORKED

pytestmark = [pytest.mark.book, pytest.mark.slow]

CHAPTERS = [page for page in PAGES if not Path(page).name.startswith("lab_")]
# the answers a document's plant decides alone (compared only for a group's own plant)
DOCUMENT_KEYS = {
    "pa9": {"H", "T"},
    "case_study": {"M", "A1", "fixed_modes"},
    "missile": {"M", "Cg", "Pc", "Kg", "fixed_modes"},
}
# entries of other answers that the plant decides alone: the middle column of PA9's F is that
# of T A (C does not read x2, so K1 C leaves it alone)
DOCUMENT_ENTRIES = {"pa9": {"F": (1, 4, 7)}, "case_study": {}, "missile": {}}
GROUPS, SEEDS = 6, (2027, 1)
SCALARS = "catch times and noise RMS"
# a simple fraction or a printed value's edge, told from rounding of the answers (6+ digits)
SMALL = 1e-8
MIN_DIGITS = 3  # a printed number of fewer significant digits says too little to give anything away

_NUMBER = re.compile(r"(?<![\w.])-?(?:\d+\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])")


class _Outputs(HTMLParser):
    """The text of a page's cell outputs (``div.cell_output``)."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.depth = 0  # > 0 inside an output
        self.parts: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        classes = dict(attrs).get("class") or ""
        if self.depth:
            self.depth += tag == "div"
        elif tag == "div" and "cell_output" in classes.split():
            self.depth = 1

    def handle_endtag(self, tag: str) -> None:
        if self.depth and tag == "div":
            self.depth -= 1

    def handle_data(self, data: str) -> None:
        if self.depth:
            self.parts.append(data)


def printed_numbers(html: str) -> list[tuple[float, float]]:
    """Each number printed in an output, with half a unit of its last printed digit."""
    parser = _Outputs()
    parser.feed(html)
    out = []
    for token in _NUMBER.findall(" ".join(parser.parts)):
        mantissa, _, exponent = token.lower().partition("e")
        digits = mantissa.lstrip("-").replace(".", "").strip("0")  # 0.500 and 100: one digit
        if len(digits) < MIN_DIGITS:
            continue
        decimals = len(mantissa.partition(".")[2])
        value = float(token)
        half = 0.5 * 10.0 ** (-decimals + (int(exponent) if exponent else 0))
        out.append((value, half))
    return out


def _missile_results(params) -> list[float]:
    """The catch times (from xhat(0) = 0) and the noise RMS (plain derivative, t >= 0.1 s)."""
    run = params.run()
    plant = run.plant()
    pmo = ut.design_pmo(plant, poles=list(params.poles), Mv=ut.examples.MISSILE_PUBLISHED.Mv)
    x0 = run.initial_state
    t = run.timepts
    start = -pmo.M @ plant.C @ x0
    resp = ut.simulate(plant, pmo, t, d=run.v, initial_state=x0, observer_state=start)
    vh = ut.reconstruct_input(plant, resp)
    tx = np.atleast_1d(ut.catch_time(t, resp.states, resp.estimates, tol=params.tol))
    tv = np.atleast_1d(ut.catch_time(t, vh.actual, vh.estimates, tol=params.tol))
    noisy = ut.simulate(
        plant, pmo, t, d=run.v, initial_state=x0, noise=params.noise_sigma, seed=params.noise_seed
    )
    late = t >= 0.1
    rms = np.sqrt(np.mean(ut.reconstruct_input(plant, noisy).error[:, late] ** 2, axis=1))
    return [*tx.tolist(), *tv.tolist(), *rms.tolist()]


def chapter_params(lab_id: str):
    """The lab's parameter class with the numbers of the chapter's run (the figures' defaults)."""
    cls = LABS[lab_id].params
    run = WORKED[lab_id].run()
    values = {name: lab_value(spec, getattr(run, name)) for name, spec in cls.declared()}
    return dataclasses.replace(cls(), **values)


def _answers(lab_id: str, params) -> dict[str, np.ndarray]:
    key = {
        name: np.asarray(value, dtype=complex).ravel() for name, value in params.answers().items()
    }
    key.pop("error_poles", None)  # the poles of PARAMS and the fixed modes: given, not found
    if lab_id == "missile":
        key[SCALARS] = np.asarray(_missile_results(params), dtype=complex)
    return key


def lab_answers(lab_id: str, params) -> dict[str, list[float]]:
    """Every number a group with ``params`` must find, by answer; on the course's plant, the
    answers and entries its source document decides alone are left out."""
    own_plant = bool(getattr(params, "matrices", ()))
    out = {}
    for name, values in _answers(lab_id, params).items():
        if not own_plant:
            if name in DOCUMENT_KEYS[lab_id]:
                continue
            drop = DOCUMENT_ENTRIES[lab_id].get(name, ())
            values = np.delete(values, list(drop))
        out[name] = [x for z in values for x in (z.real, z.imag) if not _simple(x)]
    return out


def _simple(x: float) -> bool:
    """Zero, or a fraction p/q with q <= 20: such entries (2/15, 9/7, ...) fill the matrices of
    small integer plants and match a printed number by chance, whatever the quantity."""
    return abs(x) <= SMALL or any(abs(x * q - round(x * q)) <= SMALL * q for q in range(1, 21))


def groups_of(lab_id: str) -> list[tuple[str, object]]:
    lab = LABS[lab_id]
    out = [("the lab's defaults", lab.params())]
    for seed in SEEDS:
        variants = draw_variants(lab, GROUPS, seed)
        out += [(f"group {g} of seed {seed}", v) for g, v in enumerate(variants, start=1)]
    return out


def test_the_number_reader_reads_what_a_page_prints():
    html = (
        '<div class="cell_output docutils container"><pre>K1 = [[ 1.97  0.32]'
        "\n [-2.04 -0.0317]] 1.5e-05 3 x0.25</pre></div><p>0.0317 in the text</p>"
    )
    got = printed_numbers(html)
    assert [v for v, _ in got] == [1.97, -2.04, -0.0317]  # 2-digit, integer, glued: left out
    assert [h for _, h in got] == pytest.approx([0.005, 0.005, 0.00005])


def printed_answers(lab_id: str, who: str, answers: dict, pages: dict) -> list[str]:
    """The answers of one group that a page prints: a matrix when three of its entries (or all,
    if fewer) are printed on the page, a list of single numbers (catch times, noise RMS) when
    two of them are. One entry alone matches some printed number by chance now and then (a
    simple fraction, a round pole)."""
    found = []
    for name, numbers in answers.items():
        distinct = {f"{a:.6g}" for a in numbers}
        need = 2 if name in (SCALARS, "noise_rms_predicted") else min(3, len(distinct))
        if not need:
            continue
        for page, printed in pages.items():
            hits = {
                (f"{a:.6g}", value)
                for a in numbers
                for value, half in printed
                if abs(value - a) <= half * (1 + SMALL)
            }
            # distinct entries matched by distinct printed numbers
            if min(len({h[0] for h in hits}), len({h[1] for h in hits})) >= need:
                shown = ", ".join(sorted({h[0] for h in hits}))
                found.append(f"{page}: {who}'s {name} ({shown})")
    return found


def _pages(built_book: Path) -> dict:
    return {
        page: printed_numbers((built_book / f"{page}.html").read_text("utf-8")) for page in CHAPTERS
    }


@pytest.mark.parametrize("lab_id", ["pa9", "missile"])
def test_the_chapters_print_their_own_runs_answers(lab_id, built_book):
    """The reader finds, on the chapters' pages, the answers of the chapter's own run (so that
    a lab with the chapter's numbers, as the labs had, fails the test below). The case study's
    chapter prints the poles it moves the one pole to, not the gain: its lab's pole differs."""
    pages = _pages(built_book)
    assert sum(len(v) for v in pages.values()) > 200
    answers = lab_answers(lab_id, chapter_params(lab_id))
    assert printed_answers(lab_id, "the chapter's run", answers, pages)


@pytest.mark.parametrize("lab_id", sorted(LABS))
def test_no_chapter_prints_a_lab_answer_for_any_group(lab_id, built_book):
    pages = _pages(built_book)
    found = []
    for who, params in groups_of(lab_id):
        found += printed_answers(lab_id, who, lab_answers(lab_id, params), pages)
    assert not found, f"the {lab_id} lab's answers printed by a chapter:\n" + "\n".join(
        sorted(set(found))[:30]
    )


def test_the_case_study_lab_moves_its_pole_elsewhere_than_the_chapter():
    chapter = chapter_params("case_study")
    assert LABS["case_study"].params().pole not in (chapter.pole, -chapter.pole)


def test_the_entries_left_out_are_the_documents():
    """The middle column of PA9's F is that of T A whatever the poles."""
    for params in (chapter_params("pa9"), LABS["pa9"].params()):
        plant = params.plant()
        H = plant.E @ np.linalg.pinv(plant.C @ plant.E)
        TA = (np.eye(3) - H @ plant.C) @ plant.A
        F = np.asarray(params.answers()["F"], dtype=float)
        assert np.allclose(F.ravel()[list(DOCUMENT_ENTRIES["pa9"]["F"])], TA[:, 1])
