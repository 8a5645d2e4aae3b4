"""A class graded in shards and merged is the class graded in one run; what one hand-in prints,
how it is named or what format it has changes no other row; the sandbox shows no course file,
whether the package is a checkout or a wheel installed in a virtual environment.

One small class (five hand-ins, four of which run) is graded through the command line as a
whole, then as two shards listed in another order, and merged: every file written must be the
same. The shards give each notebook they run the outcome of its kernel run in the whole run
(the same prepared notebook, recorded there): what a shard adds to the whole run is which
hand-ins it grades, what it reads of the others, the checking of the answers, its gradebook and
the merge, all of which run as they are; running the same notebooks in a kernel again would
check only that a notebook gives its answers twice.

Its hand-ins: the lab's solution under a Canvas bulk-download name marked late, a notebook with a
255-byte name that walks every readable path of the sandbox and prints past the output cap, a
notebook of format 3, a disguised copy of it from another group, and a file that is not a
notebook. No test here decides on how long anything took.
"""

from __future__ import annotations

import contextlib
import copy
import csv
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

from uio_teach.grading import grade, runner
from uio_teach.grading.gradebook import read_gradebook
from uio_teach.grading.merge import shard_of
from uio_teach.grading.sandbox import Limits, sandbox_problem
from uio_teach.instructor import cli
from uio_teach.instructor.labs import LABS

pytestmark = [pytest.mark.kernel, pytest.mark.filterwarnings("ignore::DeprecationWarning")]

ROOT = Path(__file__).resolve().parents[1]
LONG = "x" * 241 + "_pa9_g02.ipynb"  # 255 bytes, the longest name Linux allows
LATE = "ann_example_LATE_48213_9920131_pa9_g01.ipynb"


@pytest.fixture(scope="module")
def sandbox_here() -> None:
    problem = sandbox_problem()
    if problem is not None:
        pytest.skip(f"no sandbox here: {problem}")


def walker() -> str:
    """A cell that walks every readable path and raises with each course file it can read: a
    file named as a chapter, a lab notebook, a key or a hand-in of the course that speaks of
    the course, or a folder ``_course`` that holds the book."""
    names = sorted(p.name for p in (ROOT / "book").glob("*.md"))
    names += ["answer_key.csv", "_toc.yml", "references.bib", LATE]
    return f"""\
import json, os
names = set({names!r})
found = []
for root, dirs, files in os.walk("/"):
    if root in ("/proc", "/sys", "/dev") or root.startswith("/home/student"):
        dirs[:] = []
        continue
    for name in files + dirs:
        path = os.path.join(root, name)
        if name == "_course":
            try:
                if "book" in os.listdir(path):
                    found.append(path)
            except OSError:
                pass
        elif name in names or name.startswith("lab_") and name.endswith((".md", ".ipynb")):
            try:
                with open(path, "rb") as fh:
                    text = fh.read(1 << 16)
            except OSError:
                continue
            if b"uio_teach" in text or b"nknown input" in text or b"uio-teach" in text:
                found.append(path)
print("y" * 3_000_000)
raise RuntimeError("WALK " + json.dumps(found[:20]))
"""


DESIGN = """\
import numpy as np
import control as ct
import uio_teach as ut
from uio_teach import checks
plant = ut.experiments.plant_from_params("pa9", PARAMS)
A, C, E = plant.A, plant.C, plant.E
CE = C @ E
H = E @ np.linalg.pinv(CE)  # eq. (8)
T = np.eye(3) - H @ C
K1 = ct.place((T @ A).T, C.T, PARAMS["poles"]).T
F = T @ A - K1 @ C
K2 = F @ H
"""
DISGUISED = """\
import numpy as numpy_
import control as ct
import uio_teach as ut
from uio_teach import checks


plant = ut.experiments.plant_from_params( "pa9", PARAMS )
A, C, E = plant.A, plant.C, plant.E
prod = C@E
H = E @ numpy_.linalg.pinv(prod)
T = numpy_.eye(3) - (H @ C)   # the projection
K1 = ct.place((T@A).T, C.T, PARAMS["poles"]).T
F = T @ A - K1 @ C
K2 = F @ H
"""


def notebook(*cells: str) -> nbformat.NotebookNode:
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    poles = list(LABS["pa9"].params().to_params()["poles"])  # the lab's own, as the key's
    params = nbformat.v4.new_code_cell(f"PARAMS = {{'poles': {poles}}}")
    params.metadata["tags"] = ["parameters"]
    nb.cells = [params] + [nbformat.v4.new_code_cell(c) for c in cells]
    return nb


@pytest.fixture(scope="module")
def handed_in(tmp_path_factory) -> Path:
    base = tmp_path_factory.mktemp("class")
    labs = base / "labs"
    assert cli.main(["labs", "--out", str(labs), "-q"]) == 0
    folder = base / "handed_in"
    folder.mkdir()
    (folder / LATE).write_bytes((labs / "solution" / "lab_pa9.ipynb").read_bytes())
    nbformat.write(notebook(walker()), folder / LONG)
    old = nbformat.v4.downgrade(notebook(DESIGN))
    (folder / "pa9_g03.ipynb").write_text(json.dumps(old), encoding="utf-8")
    nbformat.write(notebook(DISGUISED), folder / "pa9_g04.ipynb")
    (folder / "pa9_g05.ipynb").write_text("{ not a notebook")
    (base / "groups.csv").write_text(
        "Group;Student;Name\ng01;s1;Ann Example\ng02;s2;Bo\ng03;s3;Cy\ng04;s4;Di\n",
        encoding="utf-8",
    )
    return folder


def _key(nb) -> str:
    """A prepared notebook's cells (their kinds and sources; each copy's cells get new ids)."""
    return json.dumps([[cell.cell_type, cell.source] for cell in nb.cells])


def run(*args: str, outcomes: dict | None = None, replay: bool = False) -> tuple[int, str]:
    """The command line; every kernel run of a hand-in recorded in ``outcomes`` (by its prepared
    notebook), or with ``replay`` given the outcome recorded there instead of a new run."""
    err = io.StringIO()
    real = grade.run_notebook

    def run_notebook(nb, folder, **kwargs):
        if replay and _key(nb) in outcomes:
            outcomes["replayed"] += 1
            return copy.deepcopy(outcomes[_key(nb)])
        outcome = real(nb, folder, **kwargs)
        if outcomes is not None and not replay:
            outcomes[_key(nb)] = copy.deepcopy(outcome)
        return outcome

    with pytest.MonkeyPatch.context() as mp:
        # the output cap lowered so a 3 MB print crosses it; generous time limits
        mp.setattr(grade, "Limits", lambda **kw: Limits(output_mb=1, processes=128, **kw))
        mp.setattr(grade, "run_notebook", run_notebook)
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = cli.main([*args, "--timeout", "300", "--cell-timeout", "150", "-q"])
    return code, err.getvalue()


@pytest.fixture(scope="module")
def graded(sandbox_here, handed_in) -> dict:
    """The class graded in one run (the files listed in one order), then in two shards (listed
    in another order), and the shards merged."""
    base = handed_in.parent
    roster = str(base / "groups.csv")
    files = sorted(str(p) for p in handed_in.iterdir())
    whole = base / "whole" / "grades.csv"
    outcomes = {"replayed": 0}
    code, err = run(
        "grade", *files, "--out", str(whole), "--roster", roster, "--jobs", "2", outcomes=outcomes
    )
    shards = []
    for k in (1, 2):
        out = base / "shards" / f"grades_{k}.csv"
        args = ["grade", *files[::-1], "--out", str(out), "--roster", roster, "--shard", f"{k}/2"]
        assert run(*args, outcomes=outcomes, replay=True)[0] == 0
        shards.append(out)
    merged = base / "merged" / "grades.csv"
    merge_code, merge_err = run_merge(shards[::-1], merged)
    with open(whole, newline="", encoding="utf-8") as fh:
        rows = {r["file"]: r for r in csv.DictReader(fh)}
    return {
        "code": code,
        "err": err,
        "rows": rows,
        "whole": whole,
        "shards": shards,
        "merged": merged,
        "merge": (merge_code, merge_err),
        "folder": handed_in,
        "replayed": outcomes["replayed"],
    }


def run_merge(shards, out) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = cli.main(["merge", *map(str, shards), "--out", str(out)])
    return code, err.getvalue()


def tree(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and not p.name.startswith(".")
    }


def row(graded: dict, name: str) -> dict[str, str]:
    return graded["rows"][str(graded["folder"] / name)]


def test_merged_shards_are_the_whole_run(graded):
    assert graded["code"] == 0 and graded["merge"][0] == 0, graded["merge"][1]
    assert graded["replayed"] == 4  # every notebook the shards ran, as prepared in the whole run
    shard_rows = [len(read_gradebook(s)[1]) for s in graded["shards"]]
    assert sum(shard_rows) == 5 and all(shard_rows)  # each hand-in in exactly one shard
    assert {shard_of(f, 2) for f in graded["rows"]} == {1, 2}
    # the merge keeps the class's order as the shards list it (here the reverse): the rest is
    # byte for byte the whole run's
    merged, whole = tree(graded["merged"].parent), tree(graded["whole"].parent)
    assert merged.keys() == whole.keys()
    for name in whole:
        if name.endswith("grades.csv"):
            assert sorted(merged[name].splitlines()) == sorted(whole[name].splitlines())
        elif not name.endswith("manifest.json"):
            assert merged[name] == whole[name], name
    same = json.loads(merged["grades_feedback/manifest.json"])
    theirs = json.loads(whole["grades_feedback/manifest.json"])
    assert same["options"]["columns"] == theirs["options"]["columns"]
    assert sorted(same["options"]["submissions"]) == sorted(theirs["options"]["submissions"])
    assert same["options"]["students"] == theirs["options"]["students"]


def test_every_hand_in_has_its_row_whatever_its_name_format_or_output(graded):
    assert len(graded["rows"]) == 5
    late = row(graded, LATE)
    assert (late["group"], late["status"], late["total"]) == ("g01", "ok", "5")
    feedback = graded["whole"].parent / "grades_feedback"
    assert "marked this hand-in late" in (feedback / f"{Path(LATE).stem}.txt").read_text("utf-8")
    long = row(graded, LONG)
    assert long["group"] == "g02" and long["status"] == "over limits"
    assert "output" in long["reason"] and "more than 1 MB" in long["reason"]
    old = row(graded, "pa9_g03.ipynb")
    assert old["pa9.design"] == grade.PASS  # format 3, converted and run
    unreadable = row(graded, "pa9_g05.ipynb")
    assert unreadable["status"] == "unreadable" and "not JSON" in unreadable["reason"]
    assert "4 rows need a look" in graded["err"] and "5 rows in grades.csv" in graded["err"]


def test_a_disguised_copy_is_checked_by_hand_naming_the_other_group(graded):
    for name, other in (("pa9_g03.ipynb", "g04"), ("pa9_g04.ipynb", "g03")):
        got = row(graded, name)
        assert got["status"] == "check by hand"
        assert f"the same code as group {other}" in got["reason"]


def test_no_course_file_is_readable_in_the_sandbox_of_a_checkout(graded):
    text = next(p for p in (graded["whole"].parent / "grades_feedback").glob("x*.txt"))
    walk = text.read_text(encoding="utf-8")
    assert "WALK []" in walk, walk


def test_a_failure_of_the_runner_is_the_graders_not_the_notebooks(tmp_path, monkeypatch):
    import nbclient

    class Broken(nbclient.NotebookClient):
        def execute(self, **_):
            raise MemoryError()

    monkeypatch.setattr(nbclient, "NotebookClient", Broken)
    monkeypatch.setattr(Limits, "apply", lambda self: None)
    monkeypatch.setattr(runner, "_private", lambda: None)  # this test process stays dumpable
    src = tmp_path / "submission.ipynb"
    nbformat.write(notebook("x = 1"), src)
    read_end, write_end = os.pipe()
    code = runner._execute(str(src), write_end, 10.0, "1,1,1,1,1,", "")
    with os.fdopen(read_end, encoding="utf-8") as records:  # the runner closed its end
        entries = [json.loads(line) for line in records]
    assert code == 3
    assert entries == [{"failed": "MemoryError"}]
    assert not [p.name for p in tmp_path.iterdir() if p.name != "submission.ipynb"]


# the wheel ------------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.wheel
@pytest.mark.subprocess
def test_no_course_file_is_readable_in_the_sandbox_of_a_wheel_in_a_venv(
    sandbox_here, tmp_path, handed_in, wheel_env
):
    """The wheel carries the lab chapters (for `uio-teach labs`): installed in a virtual
    environment that the sandbox mounts, they must still be out of reach."""
    python, site, env = wheel_env.python, wheel_env.site, wheel_env.env
    assert (site / "uio_teach" / "_course" / "book" / "lab_pa9.md").is_file()
    out = tmp_path / "marks" / "grades.csv"
    proc = subprocess.run(
        [python, "-m", "uio_teach", "grade", str(handed_in / LONG), "--out", str(out), "-q"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert proc.returncode == 0, proc.stderr
    where = subprocess.run(
        [python, "-c", "import uio_teach; print(uio_teach.__file__)"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert Path(where.strip()).is_relative_to(site)
    walk = next((out.parent / "grades_feedback").glob("x*.txt")).read_text(encoding="utf-8")
    assert "WALK []" in walk, walk


@pytest.mark.subprocess
def test_the_sandbox_hides_the_course_inside_a_mounted_environment(
    sandbox_here, tmp_path, monkeypatch
):
    """A site folder the sandbox mounts (a wheel's environment) that holds the package with its
    chapters: the walker finds them when nothing hides them, and nothing once the sandbox does."""
    from uio_teach.grading import sandbox

    site = tmp_path / "venv" / "lib" / "site-packages"
    chapter = site / "uio_teach" / "_course" / "book" / "lab_pa9.md"
    chapter.parent.mkdir(parents=True)
    chapter.write_text("# Lab: Practical Assignment 9\nunknown input observers\n")
    (site / "uio_teach" / "__init__.py").write_text("")
    monkeypatch.setattr(sys, "path", [*sys.path, str(site)])
    monkeypatch.setattr(sandbox, "hidden_paths", lambda: [site / "uio_teach"])
    work = tmp_path / "work"
    work.mkdir()
    (work / "walk.py").write_text(walker().replace('print("y" * 3_000_000)\n', ""))

    def walk() -> list[str]:
        proc = sandbox.Sandbox(work).popen(
            [sys.executable, "walk.py"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        _, err = proc.communicate(timeout=600)
        line = next(x for x in err.splitlines() if x.startswith("RuntimeError: WALK"))
        return json.loads(line.split("WALK ", 1)[1])

    assert walk() == []
    monkeypatch.setattr(sandbox, "_masks", lambda mounted: [])
    found = walk()  # the control: the walker sees the chapters where nothing hides them
    assert str(chapter) in found and str(chapter.parents[1]) in found
