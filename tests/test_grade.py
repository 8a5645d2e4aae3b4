"""`uio-teach grade`: each submission run on a copy, its checks re-run, one gradebook row each.

The lab test grades the notebooks `uio-teach labs` writes (the solution passes every check, the
untouched student version fails); the small synthetic notebooks show what a grader must survive
(a cell that raises, loops or ignores the interrupt, deleted check cells, stored ✓ outputs, a file
that is not a notebook) and the answer key's parameters replacing the group's own.
"""

from __future__ import annotations

import csv
import hashlib
import json
import time
from pathlib import Path

import nbformat
import pytest

from uio_teach import checks
from uio_teach.checks import CheckResult
from uio_teach.instructor import cli, grade, output

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


def sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


# the results the checks return -----------------------------------------------------------------


def test_check_results_have_ids_and_json_and_are_collected():
    checks.clear_collected()
    assert checks.collected() == []
    first = checks.pa9_design(None, None, None)
    second = checks.pa9_simulation(None)
    made_by_hand = CheckResult("not a check function", [(True, "fine")])
    assert checks.collected() == [first, second]  # only what the check functions returned
    assert first.check_id == "pa9.design" and second.check_id == "pa9.simulation"
    data = first.to_dict()
    assert json.loads(json.dumps(data)) == data
    assert set(data) == {"check_id", "title", "passed", "items"}
    assert data["passed"] is False and data["items"][0]["ok"] is False
    assert all(set(item) == {"ok", "message"} for item in data["items"])
    assert made_by_hand.to_dict()["check_id"] is None
    checks.clear_collected()
    assert checks.collected() == []


# the lab: solution passes, untouched student notebook fails -------------------------------------


@pytest.fixture(scope="module")
def lab_notebooks(tmp_path_factory) -> tuple[Path, Path]:
    out = tmp_path_factory.mktemp("labs")
    assert cli.main(["labs", "--out", str(out), "-q"]) == 0
    solution = sorted(out.rglob("solution/*pa9*.ipynb"))[0]
    student = sorted(out.rglob("student/*pa9*.ipynb"))[0]
    return solution, student


def test_the_solution_passes_and_the_untouched_student_notebook_fails(
    lab_notebooks, tmp_path, capsys
):
    solution, student = lab_notebooks
    before = {p: sha(p) for p in (solution, student)}
    out = tmp_path / "grades.csv"
    start = time.perf_counter()
    code = cli.main(["grade", str(solution), str(student), "--out", str(out)])
    seconds = time.perf_counter() - start
    print(f"\ngraded 2 lab notebooks in {seconds:.1f} s ({seconds / 2:.1f} s per notebook)")
    assert code == 0, capsys.readouterr().err
    assert {p: sha(p) for p in (solution, student)} == before  # submissions untouched
    table = rows(out)
    assert [r["file"] for r in table] == [str(solution), str(student)]
    ids = [c for c in table[0] if c.startswith("pa9.")]
    assert len(ids) >= 4 and "pa9.design" in ids
    sol, stu = table
    assert sol["lab"] == stu["lab"] == "pa9"
    assert all(sol[i] == grade.PASS for i in ids) and sol["total"] == sol["out_of"] == str(len(ids))
    assert all(stu[i] == grade.FAIL for i in ids) and stu["total"] == "0"
    feedback = sorted((tmp_path / "grades_feedback").glob("*.txt"))
    assert len(feedback) == 2
    texts = {p.name: p.read_text(encoding="utf-8") for p in feedback}
    (text,) = [t for t in texts.values() if f"Submission: {student}" in t]
    assert "✗ pa9.design" in text and "is missing" in text


# what a grader must survive ---------------------------------------------------------------------

SETUP = """\
from uio_teach import checks
from uio_teach.checks import CheckResult
from uio_teach.checks._common import _never_raises

@_never_raises("demo: the value", check_id="demo.value")
def check_value(x):
    return CheckResult("demo: the value", [(x == 2, f"x is {x}; it must be 2")])
"""


def notebook(path: Path, *cells: tuple[str, list[str]], meta: dict | None = None) -> Path:
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    if meta is not None:
        nb.metadata["uio_teach"] = meta
    for source, tags in cells:
        cell = nbformat.v4.new_code_cell(source)
        if tags:
            cell.metadata["tags"] = tags
        nb.cells.append(cell)
    nbformat.write(nb, path)
    return path


@pytest.fixture(scope="module")
def graded(tmp_path_factory) -> dict:
    """Several awkward submissions of the demo lab, graded once with an answer key."""
    folder = tmp_path_factory.mktemp("submissions")
    params = ("PARAMS = {'x': 1}", ["parameters"])
    setup = (SETUP, [])
    answer = ("x = PARAMS['x']", [])
    check = ("check_value(x)", ["check"])
    subs = {
        # the key gives x = 2: passes although the group's own cell says 1
        "keyed": notebook(folder / "demo_g01.ipynb", setup, params, answer, check),
        # metadata names the group (the file name does not)
        "meta": notebook(
            folder / "renamed.ipynb",
            setup,
            params,
            answer,
            check,
            meta={"lab": "demo", "group": "g02"},
        ),
        "raises": notebook(
            folder / "demo_g03.ipynb", setup, params, ("raise RuntimeError('oops')", []), check
        ),
        "deleted": notebook(folder / "demo_g04.ipynb", setup, params, answer),
        "loops": notebook(
            folder / "demo_g05.ipynb", setup, params, answer, ("while True:\n    pass", []), check
        ),
        "outside": notebook(
            folder / "demo_g06.ipynb",
            setup,
            params,
            answer,
            ("check_value(-1)  # shown on purpose, not a check cell", []),
            check,
        ),
        "garbage": folder / "demo_g07.ipynb",
    }
    subs["garbage"].write_text("{ not a notebook")
    # a stored ✓ counts for nothing: the cell's code is what runs
    nb = nbformat.read(subs["deleted"], as_version=4)
    nb.cells[-1].outputs = [nbformat.v4.new_output("stream", text="✓ demo.value passed\n")]
    nbformat.write(nb, subs["deleted"])
    key = folder / "answer_key.csv"
    with open(key, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["lab", "group", "params", "x"])
        for g in range(1, 8):
            writer.writerow(["demo", f"g{g:02d}", json.dumps({"x": 2}), "2"])
    before = {name: sha(path) for name, path in subs.items()}
    out = folder / "out" / "grades.csv"
    start = time.perf_counter()
    results = grade.grade(list(subs.values()), out, answer_key=key, timeout=120, cell_timeout=15)
    return {
        "subs": subs,
        "before": before,
        "results": dict(zip(subs, results, strict=True)),
        "rows": dict(zip(subs, rows(out), strict=True)),
        "out": out,
        "seconds": time.perf_counter() - start,
    }


def test_every_submission_gets_a_row_and_none_is_touched(graded):
    assert {name: sha(path) for name, path in graded["subs"].items()} == graded["before"]
    header = list(next(iter(graded["rows"].values())))
    assert header == ["file", "lab", "group", "status", "demo.value", "total", "out_of"]
    feedback = graded["out"].parent / "grades_feedback"
    assert len(list(feedback.glob("*.txt"))) == len(graded["subs"])
    assert sorted(p.name for p in feedback.iterdir() if p.suffix != ".txt") == ["manifest.json"]
    print(f"\n{len(graded['subs'])} small notebooks graded in {graded['seconds']:.1f} s")


def test_the_answer_key_sets_each_groups_parameters(graded):
    keyed, meta = graded["rows"]["keyed"], graded["rows"]["meta"]
    assert (keyed["group"], meta["group"]) == ("g01", "g02")
    assert keyed["demo.value"] == meta["demo.value"] == grade.PASS
    assert graded["results"]["keyed"].params == {"x": 2}


@pytest.mark.parametrize(
    ("name", "status", "note"),
    [
        ("raises", "error", "raised RuntimeError: oops"),
        ("deleted", "ok", "not run"),
        ("loops", "error", "interrupted"),
        ("garbage", "unreadable", "not a notebook"),
    ],
)
def test_broken_submissions_are_graded_not_crashed(graded, name, status, note):
    row = graded["rows"][name]
    assert row["status"] == status
    if name == "loops":  # interrupted, then the next cells ran: x was right
        assert row["demo.value"] == grade.PASS and row["total"] == "1"
    else:  # the unreadable file is still group g07 of the demo lab, by its name
        assert row["demo.value"] == grade.FAIL and (row["total"], row["out_of"]) == ("0", "1")
    text = (graded["out"].parent / "grades_feedback" / f"{Path(row['file']).stem}.txt").read_text(
        encoding="utf-8"
    )
    assert note in text


def test_only_check_cells_count(graded):
    assert graded["rows"]["outside"]["demo.value"] == grade.PASS
    assert len(graded["results"]["outside"].results["demo.value"]) == 1


def test_a_notebook_over_the_time_limit_is_killed_and_graded(tmp_path):
    other = SETUP.replace("check_value", "check_other").replace("demo.value", "demo.other")
    cells = [(SETUP + other, []), ("x = 2", []), ("check_value(x)", ["check"])]
    last = ("check_other(x)", ["check"])
    stubborn = notebook(
        tmp_path / "demo_g01.ipynb",
        *cells,
        (
            "import signal, time\nsignal.signal(signal.SIGINT, signal.SIG_IGN)\nwhile True:\n"
            "    time.sleep(0.01)",
            [],
        ),
        last,
    )
    complete = notebook(tmp_path / "demo_g02.ipynb", *cells, last)
    start = time.perf_counter()
    sub, ok = grade.grade([stubborn, complete], tmp_path / "grades.csv", timeout=25, cell_timeout=3)
    elapsed = time.perf_counter() - start
    assert sub.status == "timeout" and elapsed < 90
    # graded on the check cells that ran; the one after the loop is a ✗ (known from the other)
    assert sub.verdicts() == {"demo.value": True, "demo.other": False}
    assert ok.status == "ok" and ok.verdicts() == {"demo.value": True, "demo.other": True}
    assert "time limit" in sub.feedback()


def test_grade_usage_errors(tmp_path, capsys):
    assert cli.main(["grade", str(tmp_path / "nope.ipynb"), "--out", "g.csv"]) == 2
    assert "no such submission" in capsys.readouterr().err
    nb = notebook(tmp_path / "a.ipynb", ("x = 1", []))
    code = cli.main(["grade", str(nb), "--out", "g.csv", "--groups-from", "missing.csv"])
    assert code == 2 and "missing.csv: no such file" in capsys.readouterr().err
    assert cli.main(["grade", str(nb), "--out", "g.csv", "--timeout", "0"]) == 2
    assert not Path("g.csv").exists()
    assert cli.main(["grade", "--help"]) == 0
    assert "RUNS THE STUDENTS' CODE" in capsys.readouterr().out


# the gradebook and its feedback folder are replaced together --------------------------------------


def snapshot(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (hidden ones too) -> its SHA-256."""
    return {p.relative_to(folder).as_posix(): sha(p) for p in folder.rglob("*") if p.is_file()}


def handed_in(folder: Path, *names: str) -> list[str]:
    """Files that are not notebooks: graded "unreadable" at once, without a kernel."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = [folder / f"{name}.ipynb" for name in names]
    for path in paths:
        path.write_text(f"{path.stem}: not a notebook")
    return [str(path) for path in paths]


def test_a_second_grading_leaves_only_its_own_feedback(tmp_path, capsys):
    out = tmp_path / "marks" / "grades.csv"
    first = handed_in(tmp_path / "first", "demo_g01", "demo_g02")
    second = handed_in(tmp_path / "second", "demo_g03")
    assert cli.main(["grade", *first, "--out", str(out), "-q"]) == 0
    feedback = out.parent / "grades_feedback"
    assert sorted(p.name for p in feedback.glob("*.txt")) == ["demo_g01.txt", "demo_g02.txt"]
    assert cli.main(["grade", *second, "--out", str(out), "-q"]) == 0, capsys.readouterr().err
    assert [r["group"] for r in rows(out)] == ["g03"]
    assert sorted(p.name for p in feedback.iterdir()) == ["demo_g03.txt", "manifest.json"]
    assert f"Submission: {second[0]}" in (feedback / "demo_g03.txt").read_text(encoding="utf-8")
    manifest = output.read_manifest(feedback)
    assert manifest is not None and manifest["command"] == "uio-teach grade"
    assert manifest["config"] == {"gradebook": "grades.csv", "gradebook_sha256": sha(out)}
    assert [f["name"] for f in manifest["files"]] == ["demo_g03.txt"]
    assert sorted(p.name for p in out.parent.iterdir()) == ["grades.csv", "grades_feedback"]


@pytest.mark.parametrize("where", ["writing a feedback text", "swapping the folder in"])
def test_a_failed_grading_leaves_the_previous_gradebook_and_feedback(tmp_path, monkeypatch, where):
    out = tmp_path / "marks" / "grades.csv"
    grade.grade(handed_in(tmp_path / "first", "demo_g01", "demo_g02"), out)
    before = snapshot(out.parent)
    assert "grades_feedback/demo_g02.txt" in before

    def fail(*args, **kwargs):
        raise OSError(28, "No space left on device")

    if where == "writing a feedback text":
        monkeypatch.setattr(grade.Submission, "feedback", fail)
    else:  # the CSV is already in place when the folder cannot be: it is put back
        monkeypatch.setattr(output.StagedFolder, "commit", fail)
    with pytest.raises(OSError, match="No space left"):
        grade.grade(handed_in(tmp_path / "second", "demo_g03"), out)
    assert snapshot(out.parent) == before


def test_a_failed_first_grading_writes_nothing(tmp_path, monkeypatch):
    out = tmp_path / "grades.csv"
    monkeypatch.setattr(output.StagedFolder, "commit", lambda self: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        grade.grade(handed_in(tmp_path / "in", "demo_g01"), out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]


@pytest.mark.parametrize("content", ["someone's notes", "figures"])
def test_a_folder_that_is_not_earlier_feedback_is_left_alone(
    tmp_path, monkeypatch, capsys, content
):
    out = tmp_path / "grades.csv"
    folder = tmp_path / "grades_feedback"
    folder.mkdir()
    if content == "figures":  # an output of uio-teach, but not of grading
        (folder / "a.png").write_bytes(b"png")
        output.write_manifest(folder, command="uio-teach figures", config={})
    else:
        (folder / "notes.txt").write_text("mine")
    before = snapshot(folder)

    def must_not_run(*args, **kwargs):
        raise AssertionError("a notebook ran although the gradebook cannot be written")

    monkeypatch.setattr(grade, "_grade_one", must_not_run)
    code = cli.main(["grade", *handed_in(tmp_path / "in", "demo_g01"), "--out", str(out), "-q"])
    err = capsys.readouterr().err
    assert code == 1 and "left alone" in err and str(folder) in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists() and snapshot(folder) == before
    with pytest.raises(output.OutputError, match="left alone"):
        grade.write_gradebook([grade.Submission("a.ipynb", "demo", "g01", "ok")], out)
    assert not out.exists() and snapshot(folder) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["grades_feedback", "in"]


def test_a_gradebook_that_is_a_folder_is_refused(tmp_path):
    (tmp_path / "grades.csv").mkdir()
    with pytest.raises(output.OutputError, match="is a folder"):
        grade.grade(handed_in(tmp_path / "in", "demo_g01"), tmp_path / "grades.csv")
