"""Answers out of a kernel as data and back: the checks give the same verdicts on the copies.

The lab chapters' own solution code runs here, in-process; its answers go through JSON
(:mod:`uio_teach.checks.answers`) and are graded by the chapters' own check cells
(:mod:`uio_teach.grading.lab_checks`) with the lab's parameters: every check passes, as it does on
the originals, and a wrong value still fails. The grader holds no copy of a check call.
"""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest

import uio_teach as ut
from uio_teach import checks
from uio_teach.checks import answers
from uio_teach.grading import lab_checks
from uio_teach.grading.lab_checks import (
    LabChecksError,
    Missing,
    course_checks,
    grade_answers,
    missing_message,
    read_lab_checks,
)
from uio_teach.instructor.labs import LABS

GRADED = course_checks()
PACKAGE = Path(lab_checks.__file__).resolve().parents[1]

BOOK = Path(__file__).resolve().parents[1] / "book"
CELL = re.compile(r"^```\{code-cell\}[^\n]*\n(.*?)^```$", re.S | re.M)


def chapter_cells(lab: str) -> list[str]:
    """The code cells of a lab chapter before its instructor notes (tag lines removed)."""
    text = (BOOK / LABS[lab].source).read_text(encoding="utf-8")
    text = text.split("## Instructor notes", 1)[0]
    cells = []
    for body in CELL.findall(text):
        lines = body.splitlines()
        while lines and (lines[0].startswith(":") or not lines[0].strip()):
            lines.pop(0)
        cells.append("\n".join(lines))
    return cells


def check_cells(lab: str) -> list[str]:
    return [c for c in chapter_cells(lab) if c.lstrip().startswith("checks.")]


@pytest.fixture(scope="module")
def solved() -> dict[str, dict]:
    """Each lab's solution run in-process: its namespace."""
    out = {}
    for lab in GRADED:
        ns: dict = {}
        for source in chapter_cells(lab):
            if source.lstrip().startswith("checks."):
                continue
            exec(compile(source, f"<{lab}>", "exec"), ns)  # noqa: S102 - the course's own code
        out[lab] = ns
    return out


def test_the_graders_labs_are_the_registrys():
    """The grader finds the labs by their chapters (it need not load the labs' parameters); the
    term's tooling registers them: the two agree, lab by lab and chapter by chapter."""
    labs = lab_checks.course_labs(BOOK)
    assert {lab: path.name for lab, path in labs.items()} == {
        lab: entry.source for lab, entry in LABS.items()
    }


def test_the_grader_runs_the_chapters_own_check_cells():
    """One source per check: the grader's check cells are the chapter's, in its order, with the
    registry's columns; the answers they read are the names the chapter's solutions define."""
    for lab, graded in GRADED.items():
        assert [c.source.strip() for c in graded.checks] == [c.strip() for c in check_cells(lab)]
        assert graded.check_ids == LABS[lab].check_ids
        solution_names: set[str] = set()
        for source in chapter_cells(lab):
            tree = ast.parse(source)
            solution_names |= {
                n.id
                for n in ast.walk(tree)
                if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)
            }
        for check in graded.checks:
            assert check.names, check.check_id
            assert set(check.names) <= solution_names, check.check_id
            assert "PARAMS" not in check.names and "plant" not in check.names


def test_no_check_call_is_written_twice():
    """No module of the package calls a lab's check function: the chapters' cells are the one
    place each call is written."""
    functions = {c.function for graded in GRADED.values() for c in graded.checks}
    for path in PACKAGE.rglob("*.py"):
        if path.parent.name == "checks":
            continue  # where the check functions are defined
        called = {
            getattr(node.func, "attr", getattr(node.func, "id", ""))
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
            if isinstance(node, ast.Call)
        } & functions
        assert not called, f"{path.relative_to(PACKAGE)} calls {sorted(called)}"


def test_every_check_call_a_group_runs_is_a_tagged_check_cell():
    """A check call outside the instructor notes that is not tagged would be run by the groups and
    never by the grader."""
    for lab in GRADED:
        text = (BOOK / LABS[lab].source).read_text(encoding="utf-8")
        text = text.split("## Instructor notes", 1)[0]
        for body in CELL.findall(text):
            if "checks." in body:
                assert body.startswith(":tags: [check]"), (lab, body[:60])


def _chapter(tmp_path, lab: str, edit) -> Path:
    path = tmp_path / LABS[lab].source
    path.write_text(edit((BOOK / LABS[lab].source).read_text(encoding="utf-8")), "utf-8")
    return path


def test_a_check_cell_changed_in_the_chapter_changes_the_grade(solved, tmp_path):
    ns = solved["pa9"]
    params = ns["PARAMS"]
    names = ["H", "T", "K1", "F", "K2"]
    good = read_lab_checks(BOOK / LABS["pa9"].source, "pa9")
    changed = read_lab_checks(
        _chapter(
            tmp_path,
            "pa9",
            lambda t: t.replace(
                'plant=plant, poles=PARAMS["poles"])', "plant=plant, poles=[-7, -8, -9])"
            ),
        ),
        "pa9",
    )
    design = {n: ns[n] for n in names}
    assert grade_answers(good, design, params)[0].passed
    assert not grade_answers(changed, design, params)[0].passed


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda t: t.replace(":tags: [parameters]", ""), "no code cell tagged parameters"),
        (lambda t: t.replace(":tags: [check]", ""), "no code cell tagged check"),
        (lambda t: t.replace("checks.pa9_plot(", "checks.missile_plot("), "not a check of lab pa9"),
        (lambda t: t.replace("checks.pa9_plot(", "checks.pa9_design("), "a second time"),
        (lambda t: t.replace("checks.pa9_plot(", "print("), "calls no check function"),
    ],
)
def test_a_chapter_the_grader_cannot_use_is_refused_naming_it(tmp_path, edit, message):
    with pytest.raises(LabChecksError, match=message) as info:
        read_lab_checks(_chapter(tmp_path, "pa9", edit), "pa9")
    assert str(info.value).startswith("lab_pa9.md")


@pytest.mark.parametrize("lab", list(GRADED))
def test_every_solution_passes_after_the_round_trip(solved, lab):
    ns = solved[lab]
    params = ns["PARAMS"]
    names = list(GRADED[lab].names)
    text = answers.dumps({n: ns[n] for n in names})
    json.loads(text)  # plain JSON, nothing else
    back = answers.loads(text, plant=None)
    originals = grade_answers(GRADED[lab], {n: ns[n] for n in names}, params)
    copies = grade_answers(GRADED[lab], back, params)
    assert [r.passed for r in originals] == [True] * len(GRADED[lab].checks)
    assert [r.check_id for r in copies] == list(GRADED[lab].check_ids)
    assert [r.passed for r in copies] == [True] * len(GRADED[lab].checks), [
        r.failures for r in copies if not r.passed
    ]
    assert checks.collected() == []  # the grader keeps no result of its own


def test_the_rebuilt_objects_are_the_packages_own(solved):
    ns = solved["pa9"]
    back = answers.loads(answers.dumps({"resp": ns["resp_sine"], "fig": ns["fig"]}))
    resp, fig = back["resp"], back["fig"]
    assert isinstance(resp, ut.UIOResponse) and isinstance(resp.observer, ut.UIO)
    np.testing.assert_array_equal(resp.states, ns["resp_sine"].states)
    np.testing.assert_array_equal(resp.observer.F, ns["resp_sine"].observer.F)
    for name in ("u", "d", "v", "noise"):
        np.testing.assert_array_equal(
            getattr(resp.inputs, name), getattr(ns["resp_sine"].inputs, name)
        )
    assert type(fig).__name__ == "Figure" and fig.canvas.get_renderer() is not None
    theirs = ns["fig"].axes
    assert [a.get_ylabel() for a in fig.axes] == [a.get_ylabel() for a in theirs]
    assert [a.get_xlabel() for a in fig.axes] == [a.get_xlabel() for a in theirs]
    assert [a.get_title() for a in fig.axes] == [a.get_title() for a in theirs]
    assert [[t.get_text() for t in a.get_legend().get_texts()] for a in fig.axes] == [
        [t.get_text() for t in a.get_legend().get_texts()] for a in theirs
    ]
    assert fig.axes[0].get_shared_x_axes().joined(fig.axes[0], fig.axes[1])
    np.testing.assert_array_equal(
        fig.axes[1].get_lines()[0].get_ydata(), theirs[1].get_lines()[0].get_ydata()
    )


def test_a_wrong_value_still_fails_after_the_round_trip(solved):
    ns = solved["pa9"]
    params = dict(ns["PARAMS"], poles=[-4.0, -5.0, -6.0])  # another group's key
    names = ["H", "T", "K1", "F", "K2"]
    back = answers.loads(answers.dumps({n: ns[n] for n in names}))
    (design,) = [
        r for r in grade_answers(GRADED["pa9"], back, params) if r.check_id == "pa9.design"
    ]
    assert not design.passed
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    bad = answers.loads(answers.dumps({"fig": fig, "resp_sine": ns["resp_sine"]}))
    plt.close(fig)
    plot = grade_answers(GRADED["pa9"], bad, ns["PARAMS"])[2]
    assert plot.check_id == "pa9.plot" and not plot.passed


@pytest.mark.parametrize(
    "value",
    [
        np.arange(6.0).reshape(2, 3),
        np.array([[1 + 2j, -0.5j]]),
        np.array([1, 2, 3]),
        np.array([True, False]),
        np.float64(2.5),
        float("nan"),
        -np.inf,
        {"a": [1, (2, "x")], "b": None},
        np.zeros((0, 3)),
        3 + 4j,
    ],
    ids=repr,
)
def test_plain_values_come_back_equal(value):
    back = answers.loads(answers.dumps({"v": value}))["v"]
    if isinstance(value, np.ndarray):
        assert back.dtype.kind == value.dtype.kind and back.shape == value.shape
        np.testing.assert_array_equal(back, value)
    elif isinstance(value, float) and np.isnan(value):
        assert np.isnan(back)
    else:
        assert back == value


def test_anything_else_comes_back_as_unsupported_never_as_code():
    back = answers.loads(answers.dumps({"g": (i for i in range(3)), "f": len}))
    assert all(isinstance(v, answers.Unsupported) for v in back.values())


@pytest.mark.parametrize(
    "doc",
    [
        "not json",
        json.dumps({"format": "pickle", "answers": {}}),
        json.dumps({"format": answers.FORMAT, "answers": {"x": {"__uio__": "pickle"}}}),
        json.dumps(
            {
                "format": answers.FORMAT,
                "answers": {
                    "x": {"__uio__": "array", "dtype": "object", "shape": [1], "data": "AA=="}
                },
            }
        ),
        json.dumps(
            {
                "format": answers.FORMAT,
                "answers": {
                    "x": {"__uio__": "array", "dtype": "float64", "shape": [9], "data": "AA=="}
                },
            }
        ),
        json.dumps(
            {
                "format": answers.FORMAT,
                "answers": {
                    "x": {"__uio__": "array", "dtype": "float64", "shape": [10**9], "data": ""}
                },
            }
        ),
        json.dumps({"format": answers.FORMAT, "answers": {"x": {"no": "tag"}}}),
    ],
)
def test_malformed_data_is_refused_in_one_line(doc):
    with pytest.raises(answers.AnswerError) as info:
        answers.loads(doc)
    assert "\n" not in str(info.value) and len(str(info.value)) < 120


def test_a_missing_answer_names_the_variable_the_cell_and_a_hint():
    params = LABS["pa9"].params().to_params()
    results = grade_answers(
        GRADED["pa9"],
        {"H": Missing("H", 4, "LinAlgError", "Last 2 dimensions of the array must be square")},
        params,
    )
    design = results[0].failures
    assert design[0].startswith("H is missing: code cell 4 raised LinAlgError")
    assert "pinv" in design[0]  # the idea: a generalized inverse
    assert design[1].startswith("T is missing: no cell assigned it")
    shapes = missing_message(
        Missing(
            "K1", 5, "ValueError", "matmul: Input operand 1 has a mismatch in its core dimension"
        )
    )
    assert "shapes" in shapes and ".shape" in shapes
    assert all(not r.passed for r in results)


def test_the_hint_for_inv_tells_a_singular_matrix_from_one_that_is_not_square():
    # the missile's CE and the case study's [CE D] are square: "not square" would be false there
    singular = missing_message(Missing("M", 3, "LinAlgError", "Singular matrix"))
    not_square = missing_message(
        Missing("H", 4, "LinAlgError", "Last 2 dimensions of the array must be square")
    )
    assert "singular matrix" in singular and "not square" not in singular
    assert "is not square" in not_square and "singular" not in not_square
    never = missing_message(Missing("H", 2, "NameError", "name 'CE' is not defined"))
    assert "spelling" in never and "from the top" in never


def test_the_graders_own_messages_hold_no_solution_line():
    solution_code = set()
    for lab in GRADED:
        for cell in chapter_cells(lab):
            solution_code |= {line.strip() for line in cell.splitlines() if "=" in line}
    messages = [
        missing_message(Missing(name, cell, ename, evalue))
        for name in ("H", "K1", "L", "M", "fig")
        for cell, ename, evalue in [
            (None, "", ""),
            (3, "LinAlgError", "Singular matrix"),
            (3, "ValueError", "matmul: shapes"),
            (3, "NameError", "name 'x' is not defined"),
            (3, "TimeoutError", "the cell ran longer"),
            (3, "KeyError", "'pole'"),
            (3, "ZeroDivisionError", "division by zero"),
        ]
    ]
    for message in messages:
        assert not any(code in message for code in solution_code if len(code) > 8), message
        assert not re.search(r"\w+\s*=\s*\S*(np\.|ct\.|@)", message), message
