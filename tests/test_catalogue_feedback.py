"""The three labs' catalogues of answers (``test_catalogue_<lab>.py``), and feedback that
teaches without answering: every wrong answer fails with a message that names the mistake, every
right but different answer passes, and no message of a check gives a solution away.

Every message the three lab catalogues produce (wrong answers and right-but-different ones) is
scanned for code that computes a graded quantity (a solution line such as a pseudo-inverse or a
pole placement written out) and for the values a group must compute (the entries of the right
matrices, the catch times, the RMS errors).
"""

from __future__ import annotations

import functools
import re

import numpy as np
import pytest
import test_catalogue_case_study as case_study
import test_catalogue_missile as missile
import test_catalogue_pa9 as pa9

LABS = {"pa9": pa9, "case_study": case_study, "missile": missile}
# the least each catalogue holds: wrong answers, right but different ones
SIZES = {"pa9": (65, 14), "case_study": (45, 10), "missile": (55, 9)}
WRONG = [(lab, name) for lab, module in LABS.items() for name in module.CATALOGUE]
RIGHT = [(lab, name) for lab, module in LABS.items() for name in module.RIGHT_BUT_DIFFERENT]

# code that computes a graded quantity: a matrix product, a call of a numerical routine, or an
# assignment from a library call
SOLUTION_LINE = [
    re.compile(r"@"),
    re.compile(r"\b(pinv|place|acker|solve|inv|left_null|obsv|sqrt|mean|eigvals|norm)\s*\("),
    re.compile(r"\b[A-Za-z_]\w*\s*=\s*(np|ct|cp|ut|scipy)\.\w"),
    re.compile(r"\b(np|ct|cp)\.\w+(\.\w+)*\s*\("),
]
NUMBER = re.compile(r"(?<![\w.\[])-?\d+\.\d+(?:e[-+]?\d+)?|(?<![\w.\[])-?\d+e[-+]?\d+")


@functools.cache
def result(lab: str, name: str):
    """The check's result on an answer of ``lab``'s catalogue (wrong, or right but different),
    computed on first use (not at collection), once for every test here."""
    module = LABS[lab]
    if name in module.CATALOGUE:
        return module.CATALOGUE[name][0]()
    return module.RIGHT_BUT_DIFFERENT[name]()


@functools.cache
def messages(lab: str) -> list[tuple[str, bool | None, str]]:
    """Every message of ``lab``'s catalogue."""
    module = LABS[lab]
    names = [*module.CATALOGUE, *module.RIGHT_BUT_DIFFERENT]
    return [(name, ok, msg) for name in names for ok, msg in result(lab, name).items]


def expected_values(lab: str) -> np.ndarray:
    """The numbers a group must compute, by lab."""
    if lab == "pa9":
        mats = [pa9.H, pa9.T, pa9.K1, pa9.F, pa9.K2]
    elif lab == "case_study":
        mats = [case_study.M, case_study.A1, case_study.L, case_study.L_SOLVED, case_study.L_MOVED]
    else:
        mats = [missile.M, missile.A1, missile.L, missile.F, missile.Cg, missile.Pc, missile.Kg]
        mats += [np.array(list(missile.CATCH.values())), missile.RMS]
    values = np.concatenate([np.ravel(m) for m in mats])
    return values[np.abs(values) > 1e-6]


def significant(text: str) -> int:
    digits = re.sub(r"e[-+]?\d+$", "", text).lstrip("-").replace(".", "").lstrip("0")
    return len(digits)


@pytest.mark.parametrize(("lab", "name"), WRONG, ids=[f"{lab}: {name}" for lab, name in WRONG])
def test_a_wrong_answer_fails_with_a_message_that_names_the_mistake(lab, name):
    gist = LABS[lab].CATALOGUE[name][1]
    got = result(lab, name)
    assert not got.passed, f"{name}: passed\n{got}"
    assert any(gist in msg for msg in got.failures), f"{name}: expected {gist!r}\n{got}"


@pytest.mark.parametrize(("lab", "name"), RIGHT, ids=[f"{lab}: {name}" for lab, name in RIGHT])
def test_a_right_but_different_answer_passes(lab, name):
    got = result(lab, name)
    assert got.passed, f"{name}: failed\n{got}"


@pytest.mark.parametrize("lab", list(LABS))
def test_the_catalogue_is_large_enough(lab):
    wrong, right = SIZES[lab]
    assert len(LABS[lab].CATALOGUE) >= wrong and len(LABS[lab].RIGHT_BUT_DIFFERENT) >= right


@pytest.mark.parametrize("lab", list(LABS))
def test_the_catalogues_produce_many_messages(lab):
    failures = [m for _, ok, m in messages(lab) if ok is False]
    assert len(failures) >= 40


@pytest.mark.parametrize("lab", list(LABS))
def test_no_message_holds_a_solution_line(lab):
    bad = [
        (name, msg)
        for name, ok, msg in messages(lab)
        if ok is not True and any(rule.search(msg) for rule in SOLUTION_LINE)
    ]
    assert not bad, "\n".join(f"{name}: {msg}" for name, msg in bad)


@pytest.mark.parametrize("lab", list(LABS))
def test_no_failure_gives_an_expected_value(lab):
    """A ✗ may quote the group's own numbers, never a value it must compute."""
    want = expected_values(lab)
    bad = []
    for name, ok, msg in messages(lab):
        if ok is not False:
            continue
        for text in NUMBER.findall(msg):
            if significant(text) < 3:
                continue
            x = float(text)
            if np.any(np.abs(want - x) <= 1e-4 * np.abs(want)):
                bad.append((name, text, msg))
    assert not bad, "\n".join(f"{name}: {text} in {msg}" for name, text, msg in bad)


def test_no_catch_time_failure_names_a_time():
    """The expected catch times are not in any ✗ (typing them in would pass the check)."""
    times = np.array(list(missile.CATCH.values()))
    h = missile.T[1] - missile.T[0]
    for name in missile.CATALOGUE:
        got = result("missile", name)
        if got.check_id != "missile.catch_times":
            continue
        for msg in got.failures:
            for text in NUMBER.findall(msg):
                x = float(text)
                assert not np.any(np.abs(times - x) <= 1.5 * h), f"{name}: {text} in {msg}"
