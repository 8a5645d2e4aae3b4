"""Feedback that teaches without answering: no message of a check gives a solution away.

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
def messages(lab: str) -> list[tuple[str, bool | None, str]]:
    """Every message of ``lab``'s catalogue, computed on first use (not at collection)."""
    module = LABS[lab]
    out = []
    for name, (make, _) in module.CATALOGUE.items():
        for ok, msg in make().items:
            out.append((name, ok, msg))
    for name, make in getattr(module, "RIGHT_BUT_DIFFERENT", {}).items():
        for ok, msg in make().items:
            out.append((name, ok, msg))
    return out


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
    for name, (make, _) in missile.CATALOGUE.items():
        result = make()
        if result.check_id != "missile.catch_times":
            continue
        for msg in result.failures:
            for text in NUMBER.findall(msg):
                x = float(text)
                assert not np.any(np.abs(times - x) <= 1.5 * h), f"{name}: {text} in {msg}"
