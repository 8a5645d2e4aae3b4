"""What the grader reads before anything runs: hand-in names as students and LMSs write them,
rosters and keys as spreadsheets save them, old notebooks, disguised copies, shards and merges.

No kernel starts here: the gradebooks merged are written through the gradebook's own API."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import nbformat
import pytest

from uio_teach.grading import copies, grade, merge
from uio_teach.grading.gradebook import (
    Gradebook,
    Submission,
    feedback_names,
    file_cell,
    shown,
)
from uio_teach.grading.lab_checks import course_labs, lab_checks
from uio_teach.grading.rosters import (
    GradeError,
    group_from_name,
    group_id,
    read_answer_key,
    read_roster,
)
from uio_teach.grading.runner import clean_notebook
from uio_teach.grading.survey import added_since, survey

# names --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name, expected",
    [
        ("pa9_g02.ipynb", ("pa9", "g02")),
        ("pa9_g2.ipynb", ("pa9", "g02")),
        ("PA9_G02.ipynb", ("pa9", "g02")),
        ("name_48213_9920131_pa9_g02.ipynb", ("pa9", "g02")),  # Canvas's bulk download
        ("name_LATE_48213_9920131_pa9_g02.ipynb", ("pa9", "g02")),
        ("smith_john_48213_9920131_pa9_g02-1.ipynb", ("pa9", "g02")),  # a re-submission
        ("Ann Example_123_assignsubmission_file_case_study_g11.ipynb", ("case_study", "g11")),
        ("pa9_g02 (2).ipynb", ("pa9", "g02")),
        ("x_missile_group_7.ipynb", ("missile", "g07")),
        ("lab5_g03.ipynb", ("lab5", "g03")),  # another lab: graded as an unknown lab
        ("lab_pa9.ipynb", ("", "")),
        ("notebook (3).ipynb", ("", "")),
        ("pa9.ipynb", ("", "")),
        ("pa9_Group-30.ipynb", ("pa9", "g30")),  # the group's own spelling, not a re-submission
        ("pa9_group_30.ipynb", ("pa9", "g30")),
        ("pa9_G30.ipynb", ("pa9", "g30")),
        ("pa9_Group 30.ipynb", ("pa9", "g30")),
        ("pa9_Group-30-1.ipynb", ("pa9", "g30")),  # and its re-submission
        ("pa9_G30 (2).ipynb", ("pa9", "g30")),
    ],
)
def test_the_group_is_read_from_names_as_students_and_lmss_write_them(name, expected):
    assert group_from_name(name) == expected
    assert group_from_name(f"some/folder/{name}") == expected


@pytest.mark.parametrize("spelling", ["Group-30", "group_30", "G30", "g030", "GROUP 30", "g30"])
def test_every_spelling_of_a_group_is_one_group(spelling):
    assert group_id(spelling) == "g30"


def test_a_name_from_a_macos_zip_meets_its_roster_line(tmp_path):
    """A macOS zip writes é as e and a combining accent (NFD); the roster, saved on Windows, as
    one character (NFC): the same hand-in, and the student's name is one name too."""
    roster = tmp_path / "groups.csv"
    roster.write_text(
        "file,lab,group,student,name\nJos\u00e9 notebook.ipynb,pa9,g07,s1,Jos\u00e9 Pe\u00f1a\n",
        encoding="utf-8-sig",
    )
    files, students = read_roster(roster)
    decomposed = tmp_path / "Jose\u0301 notebook.ipynb"
    nb = nbformat.v4.new_notebook()
    nbformat.write(nb, decomposed)
    handin = grade.read_handin(decomposed, files)
    assert (handin.lab, handin.group) == ("pa9", "g07")
    assert students == {"g07": [("s1", "Jos\u00e9 Pe\u00f1a")]}


def test_canvas_s_own_gradebook_export_is_a_roster_by_sis_id(tmp_path):
    """Saved as Canvas exports it: "Student" is the display name, "SIS User ID" the id; its
    second line is "Points Possible" and its test student is no student."""
    roster = tmp_path / "canvas_export.csv"
    roster.write_text(
        "Student,ID,SIS User ID,SIS Login ID,Section,Lab 9 (123)\n"
        "    Points Possible,,,,,5\n"
        '"Pe\u00f1a, Jos\u00e9",101,s2026001,jpena,Group 3,\n'
        '"Example, Ann",102,s2026002,aexample,group_3,\n'
        '"Student, Test",103,,test,Group 3,\n',
        encoding="utf-8-sig",
    )
    files, students = read_roster(roster)
    assert files == {}
    assert students == {"g03": [("s2026001", "Pe\u00f1a, Jos\u00e9"), ("s2026002", "Example, Ann")]}


def test_a_group_column_added_to_canvas_s_export_wins_over_its_section(tmp_path):
    roster = tmp_path / "canvas_export.csv"
    roster.write_text(
        "Student,ID,SIS User ID,SIS Login ID,Section,Group\nAnn,1,s1,a,Monday lab,G12\n",
        encoding="utf-8",
    )
    assert read_roster(roster)[1] == {"g12": [("s1", "Ann")]}


# what the students are told --------------------------------------------------------------------


@pytest.mark.parametrize("lab", sorted(course_labs()))
def test_each_lab_page_says_what_to_hand_in_how_to_name_it_and_how_it_is_marked(lab):
    """Read from the registry of labs and their check cells: a new lab needs the same words."""
    text = course_labs()[lab].read_text(encoding="utf-8")
    ids = lab_checks(lab).check_ids
    assert "**What you hand in.**" in text, f"lab_{lab}.md does not say what to hand in"
    assert f"`{lab}_g07.ipynb`" in text and "`<lab>_<group>.ipynb`" in text
    assert "**What is checked, and how it is marked.**" in text
    missing = [c for c in ids if f"`{c}`" not in text]
    assert not missing, f"lab_{lab}.md does not name the checks {missing} it is marked by"
    assert f"out of {len(ids)}." in text


# what a hand-in folder holds ------------------------------------------------------------------


def test_every_entry_of_a_hand_in_folder_at_any_depth_is_a_hand_in_or_a_reason(tmp_path):
    """Canvas's flat download, Moodle's download in folders, and what students upload besides."""
    root = tmp_path / "handed_in"
    moodle = root / "Ann Example_123_assignsubmission_file_"
    (moodle / "deeper").mkdir(parents=True)
    nb = nbformat.writes(nbformat.v4.new_notebook())
    files = {
        root / "pa9_g01.ipynb": nb,
        root / "PA9_G02.IPYNB": nb,
        moodle / "pa9_g03.ipynb": nb,
        moodle / "deeper" / "pa9_g04.Ipynb": nb,
        root / "pa9_g05.zip": "PK",
        root / "pa9_g06.py": "x = 1",
        root / "report.pdf": "%PDF",
        root / ".DS_Store": "",
        root / "README": "",
    }
    for path, text in files.items():
        path.write_text(text)
    (root / ".ipynb_checkpoints").mkdir()
    (root / ".ipynb_checkpoints" / "pa9_g01-checkpoint.ipynb").write_text(nb)
    (root / "__MACOSX").mkdir()
    (root / "__MACOSX" / "._pa9_g01.ipynb").write_text("")
    (root / "elsewhere").symlink_to(tmp_path)
    out = root / "grades.csv"
    out.write_text("file\n")
    (root / "grades_feedback").mkdir()
    found = survey(root, own=[out, root / "grades_feedback"])
    assert found.handins == sorted(found.handins)  # in a fixed order: the same rows each run
    assert {Path(f).name for f in found.handins} == {
        "pa9_g01.ipynb",
        "PA9_G02.IPYNB",
        "pa9_g03.ipynb",
        "pa9_g04.Ipynb",
    }
    why = {Path(p).name: w for p, w in found.others}
    every = {p.name for p in root.rglob("*")} - {Path(f).name for f in found.handins}
    every -= {"pa9_g01-checkpoint.ipynb", "._pa9_g01.ipynb"}  # inside folders not entered
    assert set(why) == every  # each entry once: a row or a line
    assert why["pa9_g05.zip"].startswith("an archive, not opened")
    assert why["pa9_g06.py"].startswith("a Python script, not a notebook")
    assert why["report.pdf"] == "a .pdf file, not a notebook: only .ipynb notebooks are graded"
    assert why[".ipynb_checkpoints"].startswith("Jupyter's checkpoints")
    assert why["__MACOSX"].startswith("what macOS adds to a zip")
    assert why["elsewhere"].startswith("a link: not followed")
    assert (
        why["grades.csv"]
        == why["grades_feedback"]
        == ("written by this grading run (its gradebook)")
    )
    assert why[moodle.name] == "a folder: its entries are listed on their own"
    assert found.counts() == "16 entries: 4 hand-ins, 2 folders, 10 other entries not graded"
    assert grade.handin_files(root) == found.handins
    (moodle / "pa9_g07.ipynb").write_text(nb)
    (root / "late.zip").write_text("PK")
    added = added_since(found, survey(root, own=[out, root / "grades_feedback"]))
    assert [(Path(p).name, w.split(":")[0]) for p, w in added] == [
        ("pa9_g07.ipynb", "added during the grading run"),
        ("late.zip", "added during the grading run"),
    ]


def test_names_of_any_legal_length_and_encoding_get_their_own_feedback_file(tmp_path):
    files = [
        "x" * 241 + "_pa9_g01.ipynb",  # 255 bytes
        "x" * 241 + "_pa9_g02.ipynb",  # the same first 200 bytes
        "é" * 118 + "_pa9_g03.ipynb",  # 255 bytes of two-byte characters
        "a\nb_pa9_g05.ipynb",  # a line break is legal in a name
        "a b_pa9_g05.ipynb",  # and this is another hand-in
        os.fsdecode(b"Jos\xe9_pa9_g04.ipynb"),  # Latin-1, not UTF-8
    ]
    assert all(len(os.fsencode(f)) <= 255 for f in files)
    names = feedback_names([shown(f) for f in files])  # a name not UTF-8 is shown escaped
    assert len(set(names.values())) == len(files)
    for name in names.values():
        assert len(os.fsencode(f".{name[:-4]}.html.part")) <= 255
    out = tmp_path / "grades.csv"
    with Gradebook(out, files, ["pa9.design"]) as book:
        for file in files:
            book.add(Submission(file, "pa9", "g01", "ok", expected=("pa9.design",)))
    table = list(csv.reader(out.open(encoding="utf-8")))
    assert [r[0] for r in table[1:]] == [file_cell(f) for f in files]
    assert len({r[0] for r in table[1:]}) == len(files)  # every hand-in its own row
    assert table[-1][0] == "Jos\\xe9_pa9_g04.ipynb"  # readable, distinct, valid UTF-8
    texts = sorted(p for p in (tmp_path / "grades_feedback").iterdir() if p.suffix == ".txt")
    assert len(texts) == len(files)
    text = (tmp_path / "grades_feedback" / names[shown(files[-1])]).read_text("utf-8")
    assert shown(files[-1]) in text


# rosters and keys ----------------------------------------------------------------------------


@pytest.mark.parametrize("sep", [",", ";", "\t", "|"])
@pytest.mark.parametrize("encoding", ["utf-8", "utf-8-sig", "utf-16", "cp1252"])
def test_a_roster_is_read_whatever_separator_and_encoding_a_spreadsheet_chose(
    tmp_path, sep, encoding
):
    lines = [["File", "Group", "Student", "Name"], ["x.ipynb", "g1", "s1", "Zoë Ärling"]]
    lines += [["", "G02", "s2", "Bo, Jr."]]
    path = tmp_path / "groups.csv"
    with open(path, "w", newline="", encoding=encoding) as fh:
        csv.writer(fh, delimiter=sep).writerows(lines)
    files, students = read_roster(path)
    assert files == {"x.ipynb": ("", "g01")}
    assert students == {"g01": [("s1", "Zoë Ärling")], "g02": [("s2", "Bo, Jr.")]}


@pytest.mark.parametrize(
    "text, words",
    [
        ("group,student\ng01,s1\ng02,s1\n", ["student s1", "listed twice", "line 2"]),
        ("group,student,name\ng01,s1,Ann\ng01,s1,Ann\n", ["s1 (Ann)", "listed twice"]),
        ("group,file\ng01,a.ipynb\ng01,a.ipynb\n", ["a.ipynb", "listed twice"]),
        ("group,file\ng01,a.ipynb\ng02,a.ipynb\n", ["a.ipynb", "two groups", "g01", "g02"]),
        ("gruppa;navn\n1;Ann\n", ["no column 'group'", "semicolon", "'gruppa'"]),
        ("group;name\ng01;Ann\n", ["'file' or 'student'"]),
        ("", ["empty"]),
    ],
)
def test_a_roster_that_cannot_be_used_is_refused_naming_the_row(tmp_path, text, words):
    path = tmp_path / "groups.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(GradeError) as info:
        read_roster(path)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message
    for word in words:
        assert word in message


def test_an_answer_key_saved_again_by_a_spreadsheet_is_read_and_a_repeat_refused(tmp_path):
    path = tmp_path / "answer_key.csv"
    rows = [["lab", "group", "params"], ["pa9", "g1", json.dumps({"poles": [-1, -2, -3]})]]
    with open(path, "w", newline="", encoding="utf-8-sig") as fh:
        csv.writer(fh, delimiter=";").writerows(rows)
    assert read_answer_key(path) == {("pa9", "g01"): {"poles": [-1, -2, -3]}}
    with open(path, "a", newline="", encoding="utf-8") as fh:
        csv.writer(fh, delimiter=";").writerow(["pa9", "g01", "{}"])
    with pytest.raises(GradeError, match="lab pa9, group g01 is listed twice"):
        read_answer_key(path)


# notebook formats ----------------------------------------------------------------------------


def _v3() -> dict:
    cells = [
        {"cell_type": "code", "input": "H = 1", "language": "python", "outputs": []},
        {"cell_type": "heading", "level": 2, "source": "Requirement 1"},
        {"cell_type": "markdown", "source": "text"},
    ]
    for cell in cells:
        cell["metadata"] = {}
    return {
        "nbformat": 3,
        "nbformat_minor": 0,
        "metadata": {"name": ""},
        "worksheets": [{"cells": cells, "metadata": {}}],
    }


def test_a_notebook_of_format_3_is_converted_and_says_so():
    nb, notes = clean_notebook(_v3())
    assert [(c.cell_type, c.source) for c in nb.cells] == [
        ("code", "H = 1"),
        ("markdown", "## Requirement 1"),
        ("markdown", "text"),
    ]
    assert notes == ["a notebook of format 3 (nbformat 3), converted to format 4 to run"]
    nbformat.validate(nb)


@pytest.mark.parametrize(
    "raw, words",
    [
        ({"nbformat": 2, "worksheets": []}, ["format 2", "too old", "save it again"]),
        ({"nbformat": 1}, ["format 1"]),
        ({"nbformat": 5, "cells": []}, ["format 5", "formats 4 and 3"]),
        ({"nbformat": "4", "cells": []}, ["format '4'"]),
        ({"cells": []}, ["no nbformat"]),
        ({"nbformat": 3, "worksheets": 5}, ["format 3", "could not be converted"]),
    ],
)
def test_other_formats_are_refused_naming_the_format(raw, words):
    with pytest.raises(ValueError) as info:
        clean_notebook(raw)
    for word in words:
        assert word in str(info.value)


def test_an_unreadable_format_is_the_rows_reason(tmp_path):
    path = tmp_path / "pa9_g01.ipynb"
    path.write_text(json.dumps({"nbformat": 2, "worksheets": []}))
    handin = grade.read_handin(path)
    assert handin.status == "unreadable" and handin.reason.startswith("a notebook of format 2")
    path.write_text(json.dumps(_v3()))
    handin = grade.read_handin(path)
    assert handin.status == "" and "converted to format 4" in handin.notes[0]


# copies ---------------------------------------------------------------------------------------

ORIGINAL = [
    "import numpy as np\nCE = C @ E\nH = E @ np.linalg.pinv(CE)  # eq. (8)\nT = np.eye(3) - H @ C",
    "def place(a, poles):\n    return ct.place(a.T, C.T, poles).T\nK1 = place(T @ A, [-1, -2, -3])",
]


@pytest.mark.parametrize(
    "disguised",
    [
        [  # other local names, comments, blank lines, another layout, a docstring
            "import numpy as numpy_\n\nprod = C@E   # CE\n\n"
            "H = E @ numpy_.linalg.pinv( prod )\nT = numpy_.eye(3) - (H @ C)",
            'def gain(matrix, wanted):\n    """Place the poles."""\n'
            "    return ct.place(matrix.T, C.T, wanted).T\n\n\nK1 = gain(T @ A, [-1, -2, -3])",
        ],
        [ORIGINAL[0] + "\n\n# done\n", ORIGINAL[1].replace("    ", "\t")],
    ],
)
def test_a_copy_is_caught_after_normalisation(disguised):
    keep = {"H", "T", "K1"}
    assert copies.fingerprint(disguised, keep=keep) == copies.fingerprint(ORIGINAL, keep=keep)


@pytest.mark.parametrize(
    "changed",
    [
        [ORIGINAL[0].replace("np.eye(3) - H @ C", "np.eye(3) + H @ C"), ORIGINAL[1]],
        [ORIGINAL[0], ORIGINAL[1].replace("[-1, -2, -3]", "[-1, -2, -4]")],
        [ORIGINAL[0].replace("H = ", "H2 = ").replace("H @", "H2 @"), ORIGINAL[1]],  # an answer
        [ORIGINAL[1], ORIGINAL[0]],  # the cells in another order
    ],
)
def test_different_work_is_not_a_copy(changed):
    keep = {"H", "T", "K1"}
    assert copies.fingerprint(changed, keep=keep) != copies.fingerprint(ORIGINAL, keep=keep)


def test_a_cell_that_is_not_python_is_compared_without_comments_and_spacing():
    assert copies.fingerprint(["x = (1  # a\n"]) == copies.fingerprint(["x=(1"])
    assert copies.fingerprint(["%matplotlib inline\ny = 2"]) == copies.fingerprint(["y = 2"])


# A group's own solution (not the chapter's): what a disguised copy of it must still be caught as.
OWN = [
    "import numpy as np\nimport control as ct\nimport uio_teach as ut",
    "M = np.linalg.pinv(C @ E)\nM = E @ M\nproj = np.eye(3) - M @ C\nscale = 1.0\n"
    "A1 = proj @ A * scale",
    "gains = ct.place(A1.T, C.T, [-1.0, -2.0, -3.0]).T\nF = A1 - gains @ C\nK2 = F @ M\n"
    "H, T, K1 = M, proj, gains",
    "run = ut.simulate(plant, obs, np.linspace(0, 10, 2001), d=0.5)\nerr = run.error\n"
    "worst = abs(err).max()\nsettled = worst < 1e-3 * scale",
]


def _disguise(kind: str) -> list[str]:
    cells = list(OWN)
    swap = {
        "1.0 as 1": lambda c: [x.replace("scale = 1.0", "scale = 1") for x in c],
        "0.5 as 1/2": lambda c: [x.replace("d=0.5", "d=1/2") for x in c],
        "two lines swapped": lambda c: [
            x.replace(
                "proj = np.eye(3) - M @ C\nscale = 1.0", "scale = 1.0\nproj = np.eye(3) - M @ C"
            )
            for x in c
        ],
        "an unused variable": lambda c: [*c[:2], c[2] + "\nunused = 42", *c[3:]],
        "an if False block": lambda c: [*c, "if False:\n    worst = 0\n    print(worst)"],
        "one extra print": lambda c: [*c, "print(worst)"],
        "a cell split": lambda c: [c[0], *c[1].replace("\nscale", "\0scale").split("\0"), *c[2:]],
        "two cells merged": lambda c: [c[0], c[1] + "\n" + c[2], c[3]],
        "np.dot for @": lambda c: [x.replace("M = E @ M", "M = np.dot(E, M)") for x in c],
        "a.dot(b) for @": lambda c: [x.replace("F @ M", "F.dot(M)") for x in c],
        "scipy's pinv": lambda c: [
            x.replace("np.linalg.pinv", "sla.pinv").replace(
                "import numpy as np", "import numpy as np\nimport scipy.linalg as sla"
            )
            for x in c
        ],
        "names and comments": lambda c: [
            "# the gain, then the error\n\n"
            + x.replace("proj", "projector").replace("gains", "L").replace("worst", "biggest")
            for x in c
        ],
        "all at once": lambda c: [
            "import scipy.linalg as sla\nimport numpy\nimport control as ct\n"
            "import uio_teach as ut",
            "M = sla.pinv(C @ E)\nM = numpy.dot(E, M)\nk = 1\nP = numpy.eye(3) - M @ C\n"
            "A1 = P @ A * k\nprint(A1)",
            "g = ct.place(A1.T, C.T, [-1, -2, -3]).T",
            "F = A1 - g @ C\nK2 = F.dot(M)\nH, T, K1 = M, P, g\nif 0:\n    H = None",
            "r = ut.simulate(plant, obs, numpy.linspace(0, 10, 2001), d=1/2)\ne = r.error\n"
            "w = abs(e).max()\nok = w < 1e-3 * k\nw",
        ],
    }
    return swap[kind](cells)


DISGUISES = [
    "1.0 as 1",
    "0.5 as 1/2",
    "two lines swapped",
    "an unused variable",
    "an if False block",
    "one extra print",
    "a cell split",
    "two cells merged",
    "np.dot for @",
    "a.dot(b) for @",
    "scipy's pinv",
    "names and comments",
    "all at once",
]


@pytest.fixture(scope="module")
def pa9_checks():
    return lab_checks("pa9")


@pytest.mark.parametrize("kind", DISGUISES)
def test_a_disguised_copy_of_a_group_s_own_solution_is_still_alike(kind, pa9_checks):
    keep = pa9_checks.names
    given = copies.statements(pa9_checks.given, keep=keep)
    disguised = _disguise(kind)
    assert disguised != OWN
    share, smaller = copies.similarity(
        copies.statements(OWN, keep=keep), copies.statements(disguised, keep=keep), given
    )
    assert share >= copies.SIMILAR and smaller >= copies.MIN_STATEMENTS, (kind, share, smaller)


def _handin(name: str, group: str, sources: list[str], keep) -> grade.Handin:
    h = grade.Handin(name, "pa9", group)
    h.code = copies.fingerprint(sources, keep=keep)
    h.units = copies.statements(sources, keep=keep)
    return h


def test_near_copies_are_checked_by_hand_naming_the_other_group_and_the_share(pa9_checks):
    keep = pa9_checks.names
    given = {"pa9": copies.statements(pa9_checks.given, keep=keep)}
    other = [  # another group's own work: other steps, other checks of the result
        "import numpy as np\nimport uio_teach as ut",
        "obs = ut.design_uio(plant, poles=[-2, -3, -4])\nH, T, K1 = obs.H, obs.T, obs.K1",
        "F, K2 = obs.F, obs.K2\nrun = obs.simulate(timepts)\nmisfit = np.linalg.norm(run.error)",
        "tail = run.error[:, -100:]\nassert np.all(np.abs(tail) < 1e-2)",
    ]
    handins = [
        _handin("pa9_g01.ipynb", "g01", OWN, keep),
        _handin("pa9_g02.ipynb", "g02", _disguise("all at once"), keep),
        _handin("pa9_g03.ipynb", "g03", other, keep),
    ]
    notes = grade._identity_notes(handins, given)
    assert notes["pa9_g03.ipynb"] == []
    (note,) = notes["pa9_g01.ipynb"]
    assert note.startswith("code much like group g02's (pa9_g02.ipynb): ")
    assert "% of their own statements alike" in note
    assert notes["pa9_g02.ipynb"][0].startswith("code much like group g01's (pa9_g01.ipynb)")


def test_untouched_templates_are_never_copies_of_each_other(pa9_checks):
    from uio_teach.folders import default_book_dir
    from uio_teach.instructor.lab_notebook import make_notebook

    template = make_notebook(default_book_dir() / "lab_pa9.md", "student")
    keep = pa9_checks.names
    given = {"pa9": copies.statements(pa9_checks.given, keep=keep)}
    sources = grade._own_code(template)
    handins = [_handin(f"pa9_g0{g}.ipynb", f"g0{g}", sources, keep) for g in (1, 2)]
    assert grade._identity_notes(handins, given) == {h.file: [] for h in handins}


# shards and merges ----------------------------------------------------------------------------

CLASS = [f"handed_in/pa9_g{i:02d}.ipynb" for i in range(1, 41)]


def test_every_hand_in_is_in_exactly_one_shard_whatever_the_order():
    for n in (1, 2, 3, 7):
        first = {f: merge.shard_of(f, n) for f in CLASS}
        again = {f: merge.shard_of(f, n) for f in reversed(CLASS)}
        assert first == again
        assert set(first.values()) <= set(range(1, n + 1))
        moved = {f: merge.shard_of("/elsewhere/" + Path(f).name, n) for f in CLASS}
        assert moved == first  # by the hand-in's name, not its folder
    assert len({merge.shard_of(f, 3) for f in CLASS}) == 3  # all shards get hand-ins


@pytest.mark.parametrize("text", ["0/2", "3/2", "2", "a/b", "1/0", "-1/2"])
def test_a_shard_out_of_range_is_a_usage_error(text):
    with pytest.raises(GradeError, match="shard"):
        merge.parse_shard(text)


def _book(out: Path, files, shard, *, students=None, sources=None, only=None) -> Path:
    subs = []
    for i, file in enumerate(files):
        if shard is not None and merge.shard_of(file, shard[1]) != shard[0]:
            continue
        if only is not None and file not in only:
            continue
        results = {"pa9.design": {"passed": i % 2 == 0, "items": [], "title": "design"}}
        subs.append(
            Submission(
                file,
                "pa9",
                f"g{i + 1:02d}",
                "ok" if i % 3 else "error",
                results=results,
                expected=("pa9.design",),
            )
        )
    with Gradebook(
        out, files, ["pa9.design"], students=students or {}, shard=shard, sources=sources
    ) as book:
        for sub in subs:
            book.add(sub)
    return out


def _tree(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_merged_shards_are_what_one_whole_run_writes(tmp_path):
    files = CLASS[:12]
    students = {"g01": [("s1", "Ann")], "g02": [("s2", "Bo"), ("s3", "Cy")]}
    sources = {"answer_key_sha256": "k", "roster_sha256": "r"}
    _book(tmp_path / "whole" / "grades.csv", files, None, students=students, sources=sources)
    parts = [
        _book(
            tmp_path / "parts" / f"grades_{k}.csv",
            files,
            (k, 3),
            students=students,
            sources=sources,
        )
        for k in (1, 2, 3)
    ]
    merge.merge(parts[::-1], tmp_path / "merged" / "grades.csv")
    assert _tree(tmp_path / "merged") == _tree(tmp_path / "whole")
    assert (tmp_path / "merged" / "grades_canvas.csv").is_file()


def test_a_pattern_that_also_matches_the_shards_exports_merges_the_gradebooks(tmp_path):
    # `uio-teach merge marks/grades_*.csv` also picks grades_1_groups.csv, grades_1_canvas.csv,
    # grades_1_moodle.csv
    files = CLASS[:8]
    students = {"g01": [("s1", "Ann")]}
    _book(tmp_path / "whole" / "grades.csv", files, None, students=students)
    for k in (1, 2):
        _book(tmp_path / "marks" / f"grades_{k}.csv", files, (k, 2), students=students)
    matched = sorted((tmp_path / "marks").glob("grades_*.csv"))
    assert len(matched) == 8  # two gradebooks, each with its three exports
    merge.merge(matched, tmp_path / "merged" / "grades.csv")
    assert _tree(tmp_path / "merged") == _tree(tmp_path / "whole")


def test_the_merge_command_counts_the_gradebooks_not_their_exports(tmp_path, capsys):
    from uio_teach.instructor import cli

    files = CLASS[:8]
    for k in (1, 2):
        _book(tmp_path / "marks" / f"grades_{k}.csv", files, (k, 2), students={"g01": []})
    matched = sorted(str(p) for p in (tmp_path / "marks").glob("grades_*.csv"))
    assert len(matched) > 2
    assert cli.main(["merge", *matched, "--out", str(tmp_path / "m" / "grades.csv")]) == 0
    assert "2 gradebooks merged into" in capsys.readouterr().out


def test_shards_that_do_not_fit_together_are_refused_naming_them(tmp_path):
    files = CLASS[:10]
    one = _book(tmp_path / "a" / "g_1.csv", files, (1, 2))
    two = _book(tmp_path / "a" / "g_2.csv", files, (2, 2))
    out = tmp_path / "m" / "grades.csv"
    with pytest.raises(merge.MergeError, match="shard 2/2 missing"):
        merge.merge([one], out)
    with pytest.raises(merge.MergeError, match="both shard 1/2"):
        merge.merge([one, one], out)
    other_split = _book(tmp_path / "b" / "g_1.csv", files, (1, 3))
    with pytest.raises(merge.MergeError, match="different splits"):
        merge.merge([one, two, other_split], out)
    other_class = _book(tmp_path / "c" / "g_2.csv", CLASS[:11], (2, 2))
    with pytest.raises(merge.MergeError, match="not shards of one grading: their submissions"):
        merge.merge([one, other_class], out)
    other_key = _book(tmp_path / "d" / "g_2.csv", files, (2, 2), sources={"answer_key_sha256": "x"})
    with pytest.raises(merge.MergeError, match="their answer key differ"):
        merge.merge([one, other_key], out)
    # a whole run's gradebook and a shard overlap
    whole = _book(tmp_path / "e" / "whole.csv", files, None)
    with pytest.raises(merge.MergeError, match="different splits"):
        merge.merge([whole, two], out)
    with pytest.raises(merge.MergeError, match="one of the gradebooks"):
        merge.merge([one, two], one)
    assert not out.exists()


def test_a_shard_whose_run_did_not_finish_is_refused(tmp_path):
    files = CLASS[:10]
    one = _book(tmp_path / "g_1.csv", files, (1, 2))
    mine = [f for f in files if merge.shard_of(f, 2) == 2]
    two = _book(tmp_path / "g_2.csv", files, (2, 2), only=mine[:-1])  # one row short
    with pytest.raises(merge.MergeError, match="no row in any gradebook"):
        merge.merge([one, two], tmp_path / "m.csv")
    with open(two, "a", encoding="utf-8") as fh:  # a run killed mid-row: CSV and manifest differ
        fh.write("x")
    with pytest.raises(merge.MergeError, match="did not finish"):
        merge.merge([one, two], tmp_path / "m.csv")


def test_resuming_a_shard_with_another_shard_is_refused(tmp_path):
    files = CLASS[:6]
    out = _book(tmp_path / "g.csv", files, (1, 2))
    with pytest.raises(Exception, match="resume it with the same --shard"):
        with Gradebook(out, files, ["pa9.design"], resume=True, shard=(2, 2)):
            pass


# the summary ------------------------------------------------------------------------------------


def test_the_summary_after_resume_counts_the_whole_gradebook(tmp_path, capsys):
    from uio_teach.instructor import cli

    folder = tmp_path / "handed_in"
    folder.mkdir()
    for group in ("g01", "g02"):
        (folder / f"pa9_{group}.ipynb").write_text("{ not a notebook")
    out = str(tmp_path / "grades.csv")
    args = ["grade", str(folder), "--out", out, "--no-sandbox", "-q"]
    assert cli.main(args) == 0
    assert (
        "2 rows need a look (2 unreadable) of the 2 rows in grades.csv" in capsys.readouterr().err
    )
    (folder / "pa9_g03.ipynb").write_text("[]")
    assert cli.main([*args, "--resume"]) == 0
    err = capsys.readouterr().err
    assert "3 rows need a look (3 unreadable) of the 3 rows in grades.csv" in err
    assert "no Canvas or Moodle import written" not in err  # -q: only what needs a look
    assert cli.main([*args[:-1], "--resume"]) == 0
    assert "no Canvas or Moodle import written: without --roster" in capsys.readouterr().err


def test_shard_and_merge_usage_errors_are_one_line(tmp_path, capsys):
    from uio_teach.instructor import cli

    assert cli.main(["grade", str(tmp_path), "--out", "g.csv", "--shard", "3/2"]) == 2
    assert "--shard: expected K/N with 1 <= K <= N, got 3/2" in capsys.readouterr().err
    assert cli.main(["merge", str(tmp_path / "none.csv"), "--out", "g.csv"]) == 2
    assert "no such gradebook" in capsys.readouterr().err
    one = _book(tmp_path / "g_1.csv", CLASS[:4], (1, 2))
    assert cli.main(["merge", str(one), "--out", str(tmp_path / "m.csv")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "shard 2/2 missing" in err
