"""`uio-teach grade` on a real class: one hand-in never stops, zeroes or misleads the others.

One grading run (module fixture, through the command line, two at a time) takes a hand-in folder
of 30 hand-ins mixing right, wrong, malformed, linked, copied and hostile ones (the table
``CLASS``): full solutions with a thread printing after the last cell, the untouched student
notebook, a notebook that patches the checks, parameters reset to another group's, tags that are
a number, cells that are not cells, a last cell that rewrites the executed copy and kills its
kernel, links to the instructor's solution and to a secret file, a broken link, a folder, a pipe
and a hard link named ``*.ipynb``, a group's notebook handed in under another group's name, the
same code from two groups, a group handing in twice, a hand-in named by the roster, a hand-in
with no group, probes of everything outside the copy, a fork bomb, a notebook filling its
``/tmp`` and its folder, a figure of 100 axes and a file name that is a spreadsheet formula.
Every hand-in must get its row, the right ones full marks, none of the others ``ok`` with full
marks, and the run must exit 0 and say how many rows need a look.

No test here decides on how long anything took: the time limits given to the grader are safety
nets far above what the notebooks need, except where a notebook never ends.
"""

from __future__ import annotations

import contextlib
import csv
import functools
import hashlib
import io
import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import nbformat
import pytest

from uio_teach.grading import grade, sandbox
from uio_teach.grading.gradebook import file_cell
from uio_teach.grading.sandbox import Limits, sandbox_problem
from uio_teach.instructor import cli
from uio_teach.instructor.labs import LABS

pytestmark = [pytest.mark.kernel, pytest.mark.filterwarnings("ignore::DeprecationWarning")]


@pytest.fixture(scope="session")
def sandbox_here() -> None:
    """Skip where hand-ins cannot be isolated (the probe starts Python in the sandbox, so it runs
    inside a marked test, not at collection)."""
    problem = sandbox_problem()
    if problem is not None:
        pytest.skip(f"no sandbox here: {problem}")


needs_sandbox = pytest.mark.usefixtures("sandbox_here")
CHECKS = ("pa9.design", "pa9.simulation", "pa9.plot", "pa9.piecewise", "pa9.piecewise_plot")
SECRET = "SECRET-LINE-of-the-instructor-7f3a"
LIMITS = functools.partial(Limits, processes=128, tmp_mb=32, disk_mb=96, file_mb=64)


def sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def add_cell(nb, source: str, *, at: int | None = None, tags: tuple[str, ...] = ()) -> None:
    cell = nbformat.v4.new_code_cell(textwrap.dedent(source))
    if tags:
        cell.metadata["tags"] = list(tags)
    nb.cells.insert(len(nb.cells) if at is None else at, cell)


SETUP = """\
import numpy as np
import control as ct
import uio_teach as ut
from uio_teach import checks
"""
DESIGN = """\
plant = ut.experiments.plant_from_params("pa9", PARAMS)
A, B, C, E = plant.A, plant.B, plant.C, plant.E
poles = [complex(s) if isinstance(s, str) else s for s in PARAMS["poles"]]
H = E @ np.linalg.pinv(C @ E)
T = np.eye(3) - H @ C
K1 = ct.place((T @ A).T, C.T, poles).T
F = T @ A - K1 @ C
K2 = F @ H
"""
CHECK_DESIGN = 'checks.pa9_design(H, T, K1, F, K2, poles=PARAMS["poles"])'


# the lab's own poles (the key of the ``labs`` fixture gives every group but g02 these)
LAB_POLES = list(LABS["pa9"].params().to_params()["poles"])


def small(path: Path, group: str | None, *cells: str, design: bool = True) -> Path:
    """A short pa9 hand-in: set-up, parameters, (the design and its check), then ``cells``."""
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    nb.metadata["uio_teach"] = {"lab": "pa9"} if group is None else {"lab": "pa9", "group": group}
    add_cell(nb, SETUP)
    add_cell(nb, f"PARAMS = {{'poles': {LAB_POLES}}}", tags=("parameters",))
    if design:
        add_cell(nb, DESIGN)
        add_cell(nb, CHECK_DESIGN, tags=("check",))
    for source in cells:
        add_cell(nb, source)
    nbformat.write(nb, path)
    return path


@pytest.fixture(scope="module")
def labs(tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("labs")
    assert cli.main(["labs", "--out", str(out), "--groups", "2", "--seed", "3", "-q"]) == 0
    # a key of this file's own: the course's numbers for every group, other poles for group 2
    key = out / "answer_key.csv"
    course = LABS["pa9"].params().to_params()
    params = {("pa9", f"g{i:02d}"): course for i in range(1, 31)}
    params[("pa9", "g02")] = dict(course, poles=[-4.0, -5.0, -6.0])
    with open(key, "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(["lab", "group", "params"])
        for (lab, group), values in params.items():
            writer.writerow([lab, group, json.dumps(values)])
    secret = out / "secret.txt"
    secret.write_text(SECRET + "\n")
    return {
        "out": out,
        "key": key,
        "params": params,
        "secret": secret,
        "solution": {g: out / "pa9" / "solution" / f"pa9_{g}.ipynb" for g in ("g01", "g02")},
        "student": {g: out / "pa9" / "student" / f"pa9_{g}.ipynb" for g in ("g01", "g02")},
    }


def probe_source(labs: dict, others: list[Path], sleeper: int) -> str:
    """A cell that tries to reach outside its copy and raises with what it reached."""
    targets = {
        "key": str(labs["key"]),
        "solution": str(labs["solution"]["g01"]),
        "labs": str(labs["out"]),
        "secret": str(labs["secret"]),
        **{f"other{i}": str(p) for i, p in enumerate(others)},
    }
    return f"""\
import glob, json, os, signal, socket
reached = {{}}
for name, path in {targets!r}.items():
    try:
        with open(path, "rb") as fh:
            fh.read(1)
        reached[name] = "read"
    except Exception as exc:
        pass
    try:
        with open(path, "a") as fh:
            fh.write("tampered")
        reached[name + ".write"] = "written"
    except Exception:
        pass
procs = []
for path in glob.glob("/proc/[0-9]*/cmdline"):
    try:
        text = open(path, "rb").read()
    except OSError:
        continue
    if b"answer_key" in text or b"pytest" in text or b"groups-from" in text:
        procs.append(path)
reached["proc"] = procs
reached["pids"] = sorted(int(p) for p in os.listdir("/proc") if p.isdigit())[-1]
reached["uid"] = os.getuid()
reached["caps"] = [l for l in open("/proc/self/status") if l.startswith("CapEff")][0].split()[1]
for where in ("kernel.pid", "../kernel.pid", "/tmp/kernel.pid"):
    try:
        with open(where, "w") as fh:
            fh.write("{sleeper}")
    except OSError:
        pass
for target in ({sleeper}, {os.getpgid(0)}):
    try:
        os.killpg(target, signal.SIGKILL)
        reached["killed" + str(target)] = True
    except OSError:
        pass
try:
    socket.create_connection(("1.1.1.1", 53), timeout=5)
    reached["network"] = True
except OSError:
    pass
raise RuntimeError("PROBE " + json.dumps(reached))
"""


FORK_BOMB = """\
import json, os, resource, time
started = 0
for _ in range(1500):
    try:
        pid = os.fork()
    except OSError:
        break
    if pid == 0:
        time.sleep(600)
        os._exit(0)
    started += 1
limits = [resource.getrlimit(getattr(resource, "RLIMIT_" + n)) for n in ("AS", "NPROC", "FSIZE")]
try:
    resource.setrlimit(resource.RLIMIT_NPROC, (resource.RLIM_INFINITY,) * 2)
    limits.append("raised")
except (ValueError, OSError):
    pass
raise RuntimeError("FORKS " + json.dumps({"started": started, "limits": limits}))
"""

FILLER = """\
import json, os
written = 0
try:
    with open("/tmp/fill", "wb") as fh:
        for _ in range(3 * 1024):
            fh.write(b"x" * (1 << 20))
            written += 1 << 20
except OSError:
    pass
os.remove("/tmp/fill")
raise RuntimeError("TMP " + json.dumps(written))
"""
FILL_HOME = """\
for n in range(8):
    with open(f"fill{n}", "wb") as fh:
        for _ in range(60):
            fh.write(b"x" * (1 << 20))
"""

TAMPER = """\
import json, os, signal
bad = {"nbformat": 4, "cells": [{"cell_type": "code", "metadata": {"tags": 5}, "outputs": 7}]}
for name in ("executed.ipynb", "executed.ipynb.part"):
    with open(name, "w") as fh:
        json.dump(bad, fh)
os.kill(-1, signal.SIGKILL)
"""

AXES = """\
import matplotlib.pyplot as plt
fig = plt.figure()
for k in range(100):
    fig.add_axes([0, 0, 0.01, 0.01])
"""


def unique(path: Path, source: Path, line: str, *extra: str) -> Path:
    """A copy of the notebook ``source`` with its own line of code (a group's own work)."""
    nb = nbformat.read(source, as_version=4)
    nb.metadata["uio_teach"]["group"] = path.stem.split("_")[1]
    add_cell(nb, line, at=1)
    for cell in extra:
        add_cell(nb, cell)
    nbformat.write(nb, path)
    return path


@pytest.fixture(scope="module")
def graded(labs, tmp_path_factory) -> dict:
    """The class of 30 graded in one run of the command line (2 at a time), with a roster."""
    folder = tmp_path_factory.mktemp("handed_in")
    subs: dict[str, Path] = {}
    sol1, sol2 = labs["solution"]["g01"], labs["solution"]["g02"]

    # right: full solutions, each a group's own work; one prints after its last cell
    subs["right1"] = unique(
        folder / "pa9_g01.ipynb",
        sol1,
        "mine = 'g01'",
        "import threading, time\n"
        "def chatter():\n"
        "    while True:\n"
        "        print('still here', flush=True)\n"
        "        time.sleep(0.001)\n"
        "threading.Thread(target=chatter, daemon=True).start()\n"
        "H = T = K1 = F = K2 = resp_sine = resp_steps = fig = None",
    )
    subs["right2"] = unique(folder / "pa9_g02.ipynb", sol2, "mine = 'g02'")
    subs["right3"] = unique(folder / "pa9_g03.ipynb", sol1, "mine = 'g03'")

    # wrong: the untouched template, the checks patched, another group's parameters
    subs["student"] = folder / "pa9_g04.ipynb"
    nb = nbformat.read(labs["student"]["g01"], as_version=4)
    nb.metadata["uio_teach"]["group"] = "g04"  # the template group 4 was given
    nbformat.write(nb, subs["student"])
    nb.metadata["uio_teach"]["group"] = "g06"
    add_cell(
        nb,
        """\
        import uio_teach.checks as _c
        from uio_teach.checks import CheckResult
        CheckResult.passed = property(lambda self: True)
        CheckResult.to_dict = lambda self: {"check_id": "pa9.design", "passed": True}
        for _name in dir(_c):
            if _name.startswith("pa9_"):
                setattr(_c, _name, lambda *a, **k: CheckResult("ok", [(True, "fine")]))
        """,
        at=1,
    )
    subs["patched"] = folder / "pa9_g06.ipynb"
    nbformat.write(nb, subs["patched"])
    subs["params"] = small(
        folder / "pa9_g05.ipynb",
        "g05",
        "PARAMS = {'poles': [-4.0, -5.0, -6.0]}\n" + DESIGN,
        CHECK_DESIGN,
        design=False,
    )

    # malformed: tags that are a number, cells that are not cells, not notebooks at all
    subs["tags"] = small(folder / "pa9_g07.ipynb", "g07")
    raw = json.loads(subs["tags"].read_text())
    raw["cells"][1]["metadata"]["tags"] = 5
    raw["cells"].append({"cell_type": "code", "source": {"x": 1}, "metadata": {}})
    raw["cells"].append({"cell_type": "weird", "source": "1/0"})
    raw["metadata"]["uio_teach"]["group"] = ["g07"]
    subs["tags"].write_text(json.dumps(raw))
    subs["garbage"] = folder / "pa9_g08.ipynb"
    subs["garbage"].write_text(f"{{ not a notebook {SECRET}")
    subs["json"] = folder / "pa9_g09.ipynb"
    subs["json"].write_text(json.dumps({"cells": 5, "note": SECRET}))
    subs["binary"] = folder / "pa9_g10.ipynb"
    subs["binary"].write_bytes(b"\xff\xfe\x00" + SECRET.encode() + bytes(range(256)))
    subs["tamper"] = small(folder / "pa9_g11.ipynb", "g11", TAMPER)
    subs["suicide"] = small(
        folder / "pa9_g12.ipynb", "g12", "import os, signal\nos.kill(-1, signal.SIGKILL)"
    )

    # linked: to the solution, to a secret, to nothing; a folder, a pipe, a second name
    outside = tmp_path_factory.mktemp("outside")
    hard = outside / "solution_copy.ipynb"
    hard.write_bytes(sol1.read_bytes())
    subs["link_solution"] = folder / "pa9_g13.ipynb"
    subs["link_solution"].symlink_to(sol1)
    subs["link_secret"] = folder / "pa9_g14.ipynb"
    subs["link_secret"].symlink_to(labs["secret"])
    subs["broken"] = folder / "pa9_g15.ipynb"
    subs["broken"].symlink_to(folder / "nowhere.ipynb")
    subs["folder"] = folder / "pa9_g16.ipynb"
    subs["folder"].mkdir()
    subs["pipe"] = folder / "pa9_g17.ipynb"
    os.mkfifo(subs["pipe"])
    subs["hard"] = folder / "pa9_g18.ipynb"
    os.link(hard, subs["hard"])

    # copied: group 1's notebook under group 19's name; one code from two groups; a group twice
    subs["renamed"] = small(folder / "pa9_g19.ipynb", "g01")
    # a copy disguised: other local names, a comment, blank lines, another layout
    subs["same_a"] = small(folder / "pa9_g20.ipynb", "g20", "shared = 1\nboth = shared * 2")
    subs["same_b"] = small(
        folder / "pa9_g21.ipynb", "g21", "common=1  # ours\n\n\nboth = (common*2)"
    )
    subs["twice_a"] = small(folder / "pa9_g22.ipynb", "g22", "first = 1")
    subs["twice_b"] = small(folder / "late hand-in.ipynb", "g22", "second = 1")
    subs["roster"] = small(folder / "notebook (3).ipynb", None, "by_roster = 24")
    subs["nogroup"] = small(folder / "handin.ipynb", None, "no_group = 25")

    # hostile: probes, a fork bomb, filling /tmp and the folder, a huge figure, a formula name
    sleeper = subprocess.Popen(["sleep", "100000"], start_new_session=True)
    others = [subs["right1"], subs["student"]]
    probe = probe_source(labs, others, sleeper.pid)
    subs["probe"] = small(folder / "pa9_g26.ipynb", "g26", probe)
    subs["forks"] = small(folder / "pa9_g27.ipynb", "g27", FORK_BOMB)
    subs["filler"] = small(folder / "pa9_g28.ipynb", "g28", FILLER, FILL_HOME)
    subs["axes"] = small(folder / "pa9_g29.ipynb", "g29", AXES)
    subs["formula"] = small(folder / '=HYPERLINK("http:x";"y").ipynb', None, "f = 26")
    assert len(subs) == 30

    roster = folder.parent / "groups.csv"
    roster.write_text(
        "file,lab,group,student,name\n"
        "notebook (3).ipynb,pa9,g24,s24,Ann Example\n"
        "late hand-in.ipynb,pa9,g22,,\n"
        ",,g01,s01,=cmd|' /C calc'!A0\n"
    )
    protected = [labs["key"], sol1, sol2, labs["secret"], hard]
    protected += [p for p in subs.values() if p.is_file() and not p.is_symlink()]
    before = {p: sha(p) for p in protected}
    out = folder.parent / "marks" / "grades.csv"
    err = io.StringIO()
    stdout = io.StringIO()
    try:
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(grade, "Limits", LIMITS)
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(stdout):
                # limits far above what a cell or a notebook here needs on a busy machine
                code = cli.main(
                    [
                        "grade",
                        str(folder),
                        "--out",
                        str(out),
                        "--groups-from",
                        str(labs["key"]),
                        "--roster",
                        str(roster),
                        "--timeout",
                        "300",
                        "--cell-timeout",
                        "150",
                        "--jobs",
                        "2",
                    ]
                )
        sleeper_alive = sleeper.poll() is None
    finally:
        sleeper.kill()
        sleeper.wait()
    table = {r["file"]: r for r in rows(out)}
    feedback = out.parent / "grades_feedback"
    by_name = {}
    for name, path in subs.items():
        cell = file_cell(str(path))
        by_name[name] = table.get(cell)
    texts = {}
    for name, path in subs.items():
        stem = Path(path).stem
        text_file = feedback / f"{stem}.txt"
        texts[name] = text_file.read_text(encoding="utf-8") if text_file.is_file() else ""
    return {
        "code": code,
        "stdout": stdout.getvalue(),
        "stderr": err.getvalue(),
        "subs": subs,
        "folder": folder,
        "rows": by_name,
        "table": rows(out),
        "text": texts,
        "before": before,
        "after": {p: sha(p) for p in protected},
        "sleeper_alive": sleeper_alive,
        "out": out,
        "feedback": feedback,
        "roster": roster,
        "labs": labs,
    }


def payload(line: str, word: str):
    """The JSON a cell raised after ``word`` (whatever follows it on the line)."""
    return json.JSONDecoder().raw_decode(line.split(word + " ", 1)[1])[0]


def marks(row: dict[str, str]) -> list[str]:
    return [row[c] for c in CHECKS]


def full(row: dict[str, str]) -> bool:
    return row["total"] == row["out_of"] and row["out_of"] != "0"


# the class as a whole ---------------------------------------------------------------------------

EXPECTED = {
    "right1": "ok",
    "right2": "ok",
    "right3": "ok",
    "student": ("ok", "error"),  # its checks may raise on None, or say ✗
    "patched": ("ok", "error"),
    "params": "ok",
    "tags": "ok",
    "garbage": "unreadable",
    "json": "unreadable",
    "binary": "unreadable",
    "tamper": "error",
    "suicide": "error",
    "link_solution": "refused",
    "link_secret": "refused",
    "broken": "refused",
    "folder": "refused",
    "pipe": "refused",
    "hard": "refused",
    "renamed": "check by hand",
    "same_a": "check by hand",
    "same_b": "check by hand",
    "twice_a": "check by hand",
    "twice_b": "check by hand",
    "roster": "ok",
    "nogroup": "check by hand",
    "probe": "error",
    "forks": "error",
    "filler": "over limits",
    "axes": "over limits",
    "formula": "check by hand",
}


@needs_sandbox
def test_every_hand_in_of_a_mixed_class_has_its_row_and_the_run_exits_0(graded):
    assert graded["code"] == 0, graded["stderr"]
    assert len(graded["table"]) == len(graded["subs"]) == 30
    assert all(row is not None for row in graded["rows"].values())
    got = {name: row["status"] for name, row in graded["rows"].items()}
    want = {n: e if isinstance(e, tuple) else (e,) for n, e in EXPECTED.items()}
    wrong = {n: s for n, s in got.items() if s not in want[n]}
    assert wrong == {}, {n: graded["rows"][n]["reason"] for n in wrong}
    look = sum(1 for s in got.values() if s not in ("ok", "error", "timeout"))
    assert f"{look} rows need a look" in graded["stderr"]
    assert all(row["reason"] for row in graded["table"] if row["status"] != "ok")


@needs_sandbox
def test_right_ones_get_full_marks_and_no_other_is_ok_with_full_marks(graded):
    for name in ("right1", "right2", "right3"):
        row = graded["rows"][name]
        assert row["status"] == "ok" and full(row), graded["text"][name]
    for name, row in graded["rows"].items():
        if not name.startswith("right"):
            assert not (row["status"] == "ok" and full(row)), name


@needs_sandbox
def test_resume_never_trips_over_the_same_hand_in_again(graded):
    before = graded["out"].read_bytes()
    again = grade.grade(
        graded["folder"],
        graded["out"],
        answer_key=graded["labs"]["key"],
        roster=graded["roster"],
        resume=True,
    )
    assert again == []  # every hand-in has its row: nothing runs again
    assert graded["out"].read_bytes() == before


# read: links, folders, devices, not notebooks ---------------------------------------------------


@needs_sandbox
def test_links_folders_pipes_and_second_names_are_refused_rows(graded):
    for name in ("link_solution", "link_secret", "broken", "folder", "pipe", "hard"):
        row = graded["rows"][name]
        assert row["status"] == "refused" and row["total"] == "0", name
    assert "a link" in graded["rows"]["link_solution"]["reason"]
    assert "folder" in graded["rows"]["folder"]["reason"]
    assert "hard link" in graded["rows"]["hard"]["reason"]


@needs_sandbox
def test_nothing_of_a_file_outside_the_folder_or_of_a_hand_in_is_printed(graded):
    everything = graded["stdout"] + graded["stderr"]
    everything += graded["out"].read_text(encoding="utf-8")
    for path in graded["feedback"].iterdir():
        everything += path.read_text(encoding="utf-8")
    for path in graded["out"].parent.glob("*.csv"):
        everything += path.read_text(encoding="utf-8")
    assert SECRET not in everything


@needs_sandbox
def test_malformed_notebooks_are_rows_not_tracebacks(graded):
    assert graded["rows"]["tags"]["pa9.design"] == grade.PASS  # tags 5 do not stop it
    assert "tags were ignored" in graded["text"]["tags"]
    assert "left out" in graded["text"]["tags"]
    for name in ("garbage", "json", "binary"):
        assert graded["rows"][name]["reason"].startswith("not a notebook"), name
    assert "Traceback" not in "".join(graded["text"].values())


@needs_sandbox
def test_a_notebook_that_rewrites_its_executed_copy_and_kills_its_kernel_is_one_row(graded):
    for name in ("tamper", "suicide"):
        row = graded["rows"][name]
        assert row["status"] == "error" and row["pa9.design"] == grade.PASS
        assert "could not be run to its end" in graded["text"][name]


# identity ---------------------------------------------------------------------------------------


@needs_sandbox
def test_the_group_is_the_file_name_and_disagreement_is_checked_by_hand(graded):
    row = graded["rows"]["renamed"]
    assert row["group"] == "g19" and row["status"] == "check by hand"
    assert "the notebook says group g01" in row["reason"]


@needs_sandbox
def test_the_same_code_from_two_groups_and_a_group_twice_are_checked_by_hand(graded):
    for name, other in (("same_a", "g21"), ("same_b", "g20")):
        assert f"the same code as group {other}" in graded["rows"][name]["reason"]
    for name in ("twice_a", "twice_b"):
        row = graded["rows"][name]
        assert row["group"] == "g22" and "more than once" in row["reason"]
    groups = {r["group"]: r for r in rows(graded["out"].parent / "grades_groups.csv")}
    assert groups["g22"]["status"] == "check by hand" and groups["g22"]["total"] == ""


@needs_sandbox
def test_the_roster_names_a_group_and_a_hand_in_without_one_is_never_ok(graded):
    row = graded["rows"]["roster"]
    assert (row["group"], row["status"], row["pa9.design"]) == ("g24", "ok", grade.PASS)
    nogroup = graded["rows"]["nogroup"]
    assert nogroup["status"] == "check by hand" and nogroup["total"] == "0"
    assert "no group" in nogroup["reason"]


@needs_sandbox
def test_the_lms_exports_hold_every_group_and_no_formula(graded):
    with open(graded["out"].parent / "grades_canvas.csv", newline="", encoding="utf-8") as fh:
        canvas = list(csv.reader(fh))
    assert canvas[1][0] == "Points Possible" and canvas[1][5] == "5"
    ann = next(r for r in canvas if r[2] == "s24")
    assert ann[0] == "Ann Example" and ann[5] == str(graded["rows"]["roster"]["total"])
    for path in graded["out"].parent.glob("*.csv"):
        with open(path, newline="", encoding="utf-8") as fh:
            for row in csv.reader(fh):
                for cell in row:
                    assert not (cell and cell[0] in "=+-@"), (path.name, cell)
    assert (graded["feedback"] / "pa9_g01.html").is_file()


# isolation and limits ---------------------------------------------------------------------------


@needs_sandbox
def test_nothing_outside_the_copy_is_reachable(graded):
    text = graded["text"]["probe"]
    line = next(x for x in text.splitlines() if x.startswith("  - code cell") and "PROBE" in x)
    reached = payload(line, "PROBE")
    assert reached.pop("proc") == [] and reached.pop("pids") < 100  # a process table of its own
    uid, caps = reached.pop("uid"), reached.pop("caps")
    assert int(caps, 16) == 0  # no capability at all
    assert uid != 0 or os.geteuid() != 0  # never root on the host
    assert reached == {}, f"the hand-in reached {reached}"
    assert graded["after"] == graded["before"]  # the key, solutions and hand-ins untouched
    assert graded["sleeper_alive"]  # the pid it wrote into kernel.pid was not killed
    assert graded["rows"]["probe"]["pa9.design"] == grade.PASS  # it ran, in its sandbox


@needs_sandbox
def test_processes_are_bounded_even_when_grading_as_root(graded):
    text = graded["text"]["forks"]
    line = next(x for x in text.splitlines() if "FORKS" in x)
    forks = payload(line, "FORKS")
    limit = LIMITS().processes
    assert forks["started"] < limit  # the kernel's own threads count too
    assert forks["limits"][1] == [limit, limit]  # and the notebook could not raise it
    mib = 1024 * 1024
    assert forks["limits"][0] == [LIMITS().memory_mb * mib] * 2
    assert forks["limits"][2] == [LIMITS().file_mb * mib] * 2
    assert graded["rows"]["forks"]["pa9.design"] == grade.PASS


@needs_sandbox
def test_tmp_and_all_writes_are_capped(graded):
    row = graded["rows"]["filler"]
    assert row["status"] == "over limits" and row["pa9.design"] == grade.PASS
    assert f"more than {LIMITS().disk_mb} MB" in row["reason"]
    text = graded["text"]["filler"]
    line = next(x for x in text.splitlines() if "TMP" in x)
    assert payload(line, "TMP") <= LIMITS().tmp_mb * 1024 * 1024


@needs_sandbox
def test_answers_over_the_caps_are_a_row_saying_so(graded):
    row = graded["rows"]["axes"]
    assert row["status"] == "over limits" and "100 axes" in row["reason"]
    assert row["pa9.design"] == grade.PASS  # the other answers are still checked


@needs_sandbox
def test_a_cell_that_raises_is_named_with_a_hint_not_a_traceback(graded):
    text = graded["text"]["patched"]
    assert "is missing" in text and "Traceback" not in text and 'File "' not in text
    assert graded["rows"]["params"]["pa9.design"] == grade.FAIL  # another group's poles


# runs of their own ------------------------------------------------------------------------------


def test_the_sandbox_mounts_parents_first_so_nothing_under_tmp_is_hidden(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "prefix", str(tmp_path / "venv"))
    box = sandbox.Sandbox(tmp_path / "work")
    mounts = [dest for _, _, dest in box._mounts()]
    assert mounts.index("/tmp") < mounts.index(str(tmp_path / "venv"))
    assert mounts.index("/home/student") < len(mounts)
    depth = [len(Path(m).parts) for m in mounts]
    assert depth == sorted(depth)


@needs_sandbox
def test_an_environment_under_tmp_is_still_there_inside(tmp_path, monkeypatch, request):
    env = tmp_path / "venv"
    (env / "lib").mkdir(parents=True)
    (env / "lib" / "marker_under_tmp.py").write_text("VALUE = 42\n")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.setattr(sys, "prefix", str(env))
    held = sandbox.SandboxUser()
    user = held.acquire()
    request.addfinalizer(held.release)
    if user is not None:
        os.chown(work, user, user)
        os.chmod(tmp_path, 0o755)
    code = (
        f"from uio_teach.grading.sandbox import drop_privileges; drop_privileges({user!r}); "
        f"import sys; sys.path.insert(0, {str(env / 'lib')!r}); "
        "import marker_under_tmp; print(marker_under_tmp.VALUE)"
    )
    done = sandbox.Sandbox(work, user=user).popen(
        [sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    out, err = done.communicate(timeout=120)
    assert done.returncode == 0 and out.strip() == b"42", err.decode()


def test_a_sandbox_that_cannot_run_python_refuses_with_a_clear_message(tmp_path, capsys):
    nb = small(tmp_path / "pa9_g01.ipynb", "g01", design=False)
    out = tmp_path / "grades.csv"
    grade._SELF_TEST.clear()
    sandbox._problem.cache_clear()
    try:
        with pytest.MonkeyPatch.context() as mp:  # an interpreter that is not there inside
            mp.setattr(sys, "executable", str(tmp_path / "gone" / "python"))
            assert cli.main(["grade", str(nb), "--out", str(out)]) == 2
    finally:
        grade._SELF_TEST.clear()
        sandbox._problem.cache_clear()
    err = capsys.readouterr().err
    assert "cannot isolate the hand-ins" in err and "gone/python" in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


@needs_sandbox
def test_ctrl_c_stops_at_once_and_keeps_every_finished_row(tmp_path):
    folder = tmp_path / "handed_in"
    folder.mkdir()
    small(folder / "pa9_g01.ipynb", "g01", design=False)
    small(folder / "pa9_g02.ipynb", "g02", "while True:\n    pass", design=False)
    out = tmp_path / "grades.csv"
    env = dict(os.environ, TMPDIR=str(tmp_path))
    grader = subprocess.Popen(
        [sys.executable, "-m", "uio_teach", "grade", str(folder), "--out", str(out), "-q"],
        env=env,
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    try:  # wait for the first row (an event), then press Ctrl-C
        while grader.poll() is None and not (out.is_file() and len(rows(out)) >= 1):
            try:
                grader.wait(timeout=0.2)
            except subprocess.TimeoutExpired:
                pass
        os.killpg(grader.pid, signal.SIGINT)
        code = grader.wait(timeout=120)  # a safety net: the endless cell has 60 s a cell
    finally:
        if grader.poll() is None:
            os.killpg(grader.pid, signal.SIGKILL)
            grader.wait()
    assert code == 130, grader.stderr.read().decode()
    assert [Path(r["file"]).name for r in rows(out)] == ["pa9_g01.ipynb"]
    assert not any(p.name.startswith(grade.TEMP_PREFIX) for p in tmp_path.iterdir())


@needs_sandbox
def test_a_cell_that_never_ends_is_stopped_and_graded_on_what_ran(tmp_path):
    nb = small(
        tmp_path / "pa9_g01.ipynb",
        "g01",
        "x = 1",
        "import signal, time\nsignal.signal(signal.SIGINT, signal.SIG_IGN)\n"
        "while True:\n    time.sleep(0.05)",
        design=False,
    )
    (sub,) = grade.grade([nb], tmp_path / "grades.csv", timeout=20, cell_timeout=3)
    assert sub.status == "timeout" and "time limit" in sub.feedback()


@needs_sandbox
def test_a_grader_killed_mid_run_resumes_without_losing_a_row(tmp_path, monkeypatch):
    temp = tmp_path / "tmp"
    temp.mkdir()
    subs = [
        str(small(tmp_path / f"pa9_g{i:02d}.ipynb", f"g{i:02d}", f"x = {i}", design=False))
        for i in (1, 2)
    ]
    out = tmp_path / "grades.csv"
    env = dict(os.environ, TMPDIR=str(temp))
    grader = subprocess.Popen(
        [sys.executable, "-m", "uio_teach", "grade", *subs, "--out", str(out)],
        env=env,
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    try:  # wait for the first row (an event, not a duration), then kill the whole grader
        while grader.poll() is None and not (out.is_file() and len(rows(out)) >= 1):
            try:
                grader.wait(timeout=0.2)
            except subprocess.TimeoutExpired:
                pass
    finally:
        os.killpg(grader.pid, signal.SIGKILL)
        grader.wait()
    kept = rows(out)
    assert len(kept) == 1, grader.stderr.read().decode()
    assert any(p.name.startswith(grade.TEMP_PREFIX) for p in temp.iterdir())  # left by the kill
    monkeypatch.setattr("tempfile.tempdir", str(temp))
    again = grade.grade(subs, out, resume=True)
    done_before = {k["file"] for k in kept}
    assert [s.file for s in again] == [f for f in subs if f not in done_before]
    final = rows(out)
    assert [r["file"] for r in final] == subs
    assert all(r["status"] == "ok" for r in final)
    assert {r["file"]: r for r in final if r["file"] in done_before} == {k["file"]: k for k in kept}
    assert list(temp.iterdir()) == []  # the killed run's folder removed, this run's too


def test_grade_usage_errors(tmp_path, capsys):
    assert cli.main(["grade", str(tmp_path / "nope.ipynb"), "--out", "g.csv"]) == 2
    assert "no such hand-in" in capsys.readouterr().err
    nb = small(tmp_path / "a.ipynb", "g01", design=False)
    code = cli.main(["grade", str(nb), "--out", "g.csv", "--groups-from", "missing.csv"])
    assert code == 2 and "missing.csv: no such file" in capsys.readouterr().err
    code = cli.main(["grade", str(nb), "--out", "g.csv", "--roster", "missing.csv"])
    assert code == 2 and "missing.csv: no such file" in capsys.readouterr().err
    assert cli.main(["grade", str(nb), "--out", "g.csv", "--timeout", "0"]) == 2
    assert cli.main(["grade", str(nb), "--out", "g.csv", "--jobs", "0"]) == 2
    assert cli.main(["grade", str(tmp_path), str(nb), "--out", "g.csv"]) == 2
    assert not Path("g.csv").exists()
    assert cli.main(["grade", "--help"]) == 0
    help_text = capsys.readouterr().out
    assert "RUNS THE STUDENTS' CODE" in help_text and "--no-sandbox" in help_text


def test_without_a_sandbox_grading_is_refused_unless_asked(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(
        grade, "_self_test", lambda limits, stop=None: "bubblewrap (bwrap) is not installed"
    )
    nb = small(tmp_path / "pa9_g01.ipynb", "g01", design=False)
    out = tmp_path / "grades.csv"
    assert cli.main(["grade", str(nb), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "cannot isolate the hand-ins" in err and "--no-sandbox" in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()
    with pytest.raises(grade.SandboxRefused):
        grade.grade([nb], out)


def test_no_sandbox_grades_the_same_says_so_loudly_and_no_group_is_never_ok(tmp_path, capsys):
    nb = small(tmp_path / "pa9_g01.ipynb", "g01")
    anonymous = small(tmp_path / "mine.ipynb", None, "x = 2")  # book's numbers, no group
    out = tmp_path / "grades.csv"
    code = cli.main(["grade", str(nb), str(anonymous), "--out", str(out), "--no-sandbox", "-q"])
    assert code == 0
    err = capsys.readouterr().err
    assert "WARNING: --no-sandbox" in err and "your permissions" in err
    assert "1 row needs a look (1 check by hand)" in err
    first, second = rows(out)
    assert first["status"] == "ok" and first["pa9.design"] == grade.PASS and first["total"] == "1"
    assert second["status"] == "check by hand" and "no group" in second["reason"]


def test_a_failure_of_the_grader_on_one_hand_in_is_that_rows_and_the_run_goes_on(
    tmp_path, monkeypatch, capsys
):
    def broken(nb, checks, params, **kwargs):
        if any("boom" in c.source for c in nb.cells):
            raise KeyError("a bug of the grader")
        return real(nb, checks, params, **kwargs)

    real = grade.prepare
    monkeypatch.setattr(grade, "prepare", broken)
    monkeypatch.setattr(grade, "read_handin", explode_on("pa9_g02", grade.read_handin))
    subs = [
        small(tmp_path / "pa9_g01.ipynb", "g01", "x = 'boom'", design=False),
        small(tmp_path / "pa9_g02.ipynb", "g02", design=False),
    ]
    out = tmp_path / "grades.csv"
    code = cli.main(["grade", *map(str, subs), "--out", str(out), "--no-sandbox", "-q"])
    assert code == 0
    first, second = rows(out)
    assert first["status"] == second["status"] == "grader error"
    assert "KeyError" in first["reason"] and "cannot be read" in second["reason"]
    assert "2 rows need a look (2 grader error)" in capsys.readouterr().err


def explode_on(stem: str, real):
    def read(path, roster=None, **kwargs):
        if Path(path).stem == stem:
            raise MemoryError
        return real(path, roster, **kwargs)

    return read
