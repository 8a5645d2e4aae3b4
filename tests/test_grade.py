"""`uio-teach grade`: submissions run in a sandbox, their answers checked in the grader's process.

One grading run (module fixture) holds the lab's solution notebooks, the untouched student
notebook and submissions that attack the grader: a patched ``CheckResult``, ``PARAMS`` reset to
another group's numbers, probes of ``/proc``, the answer key, the solution notebook, other
submissions and the network, a fake ``kernel.pid``, signals to the grader's process group, a
sandbox that kills itself, a loop that ignores interrupts, memory exhaustion, a background thread
printing after the last cell. Each attack must fail to change a grade or to reach outside its
copy. No test here decides on how long anything took: the time limits given to the grader are
safety nets far above what the notebooks need, except where a notebook never ends.
"""

from __future__ import annotations

import csv
import hashlib
import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import nbformat
import pytest

from uio_teach.instructor import cli, grade
from uio_teach.instructor.labs import LABS
from uio_teach.instructor.sandbox import sandbox_problem

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")
needs_sandbox = pytest.mark.skipif(
    sandbox_problem() is not None, reason=f"no sandbox here: {sandbox_problem()}"
)
CHECKS = ("pa9.design", "pa9.simulation", "pa9.plot", "pa9.piecewise", "pa9.piecewise_plot")


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


def small(path: Path, group: str, *cells: str, design: bool = True) -> Path:
    """A short pa9 submission: set-up, parameters, (the design and its check), then ``cells``."""
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    nb.metadata["uio_teach"] = {"lab": "pa9", "group": group}
    add_cell(nb, SETUP)
    add_cell(nb, "PARAMS = {'poles': [-1.0, -2.0, -3.0]}", tags=("parameters",))
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
    # a key of this file's own: the course's numbers for group 1, other poles for group 2
    key = out / "answer_key.csv"
    course = LABS["pa9"].params().to_params()
    params = {
        ("pa9", "g01"): course,
        ("pa9", "g02"): dict(course, poles=[-4.0, -5.0, -6.0]),
    }
    with open(key, "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(["lab", "group", "params"])
        for (lab, group), values in params.items():
            writer.writerow([lab, group, json.dumps(values)])
    return {
        "out": out,
        "key": key,
        "params": params,
        "solution": {g: out / "pa9" / "solution" / f"pa9_{g}.ipynb" for g in ("g01", "g02")},
        "student": {g: out / "pa9" / "student" / f"pa9_{g}.ipynb" for g in ("g01", "g02")},
    }


def probe_source(labs: dict, others: list[Path], sleeper: int) -> str:
    """A cell that tries to reach outside its copy and raises with what it reached."""
    targets = {
        "key": str(labs["key"]),
        "solution": str(labs["solution"]["g01"]),
        "labs": str(labs["out"]),
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


@pytest.fixture(scope="module")
def graded(labs, tmp_path_factory) -> dict:
    """Every submission of this file graded in one run with the answer key (2 at a time)."""
    folder = tmp_path_factory.mktemp("handed_in")
    subs: dict[str, Path] = {}
    g1, g2 = labs["params"][("pa9", "g01")], labs["params"][("pa9", "g02")]

    # the solution, with a thread printing after the last cell and answers undone afterwards
    nb = nbformat.read(labs["solution"]["g01"], as_version=4)
    add_cell(
        nb,
        """\
        import threading, time
        def chatter():
            while True:
                print("still here", flush=True)
                time.sleep(0.001)
        threading.Thread(target=chatter, daemon=True).start()
        H = T = K1 = F = K2 = resp_sine = resp_steps = fig = None
        """,
    )
    subs["solution"] = folder / "solution" / "pa9_g01.ipynb"
    subs["solution"].parent.mkdir()
    nbformat.write(nb, subs["solution"])

    # group 2's solution with PARAMS reset to group 1's numbers after the parameters cell
    nb = nbformat.read(labs["solution"]["g02"], as_version=4)
    at = next(i for i, c in enumerate(nb.cells) if "parameters" in c.metadata.get("tags", []))
    add_cell(nb, f"PARAMS = {json.dumps(g1)}", at=at + 1)
    subs["params"] = folder / "params" / "pa9_g02.ipynb"
    subs["params"].parent.mkdir()
    nbformat.write(nb, subs["params"])

    # the untouched student notebook, and one that fakes every check in the kernel
    subs["student"] = folder / "student" / "pa9_g01.ipynb"
    subs["student"].parent.mkdir()
    subs["student"].write_bytes(labs["student"]["g01"].read_bytes())
    nb = nbformat.read(labs["student"]["g01"], as_version=4)
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
    subs["patched"] = folder / "patched" / "pa9_g01.ipynb"
    subs["patched"].parent.mkdir()
    nbformat.write(nb, subs["patched"])

    sleeper = subprocess.Popen(["sleep", "100000"], start_new_session=True)
    others = [subs["solution"], subs["student"]]
    subs["probe"] = small(folder / "probe.ipynb", "g01", probe_source(labs, others, sleeper.pid))
    subs["suicide"] = small(
        folder / "suicide.ipynb", "g02", "import os, signal\nos.kill(-1, signal.SIGKILL)"
    )
    subs["stubborn"] = small(
        folder / "stubborn.ipynb",
        "g01",
        "import signal, time\nsignal.signal(signal.SIGINT, signal.SIG_IGN)\n"
        "while True:\n    time.sleep(0.05)",
        "checks.pa9_plot(fig, response=resp_sine)",
    )
    subs["limits"] = small(
        folder / "limits.ipynb",
        "g02",
        """\
import json, resource
limits = [resource.getrlimit(getattr(resource, "RLIMIT_" + n)) for n in ("AS", "NPROC", "FSIZE")]
try:
    resource.setrlimit(resource.RLIMIT_AS, (resource.RLIM_INFINITY,) * 2)
    limits.append("raised")
except (ValueError, OSError):
    pass
raise RuntimeError("LIMITS " + json.dumps(limits))
""",
    )
    subs["raises"] = small(
        folder / "raises.ipynb",
        "g01",
        "plant = ut.experiments.plant_from_params('pa9', PARAMS)\n"
        "A, B, C, E = plant.A, plant.B, plant.C, plant.E\n"
        "H = np.linalg.inv(C @ E)",
        CHECK_DESIGN,
        design=False,
    )
    subs["garbage"] = folder / "pa9_g02.ipynb"
    subs["garbage"].write_text("{ not a notebook")
    for name in ("stubborn", "raises"):  # their last check cell is a check cell
        nb = nbformat.read(subs[name], as_version=4)
        nb.cells[-1].metadata["tags"] = ["check"]
        nbformat.write(nb, subs[name])

    protected = [labs["key"], labs["solution"]["g01"], labs["solution"]["g02"], *subs.values()]
    before = {p: sha(p) for p in protected}
    out = folder / "marks" / "grades.csv"
    try:
        results = grade.grade(
            list(subs.values()),
            out,
            answer_key=labs["key"],
            # limits far above what a cell or a notebook here needs on a busy machine: only
            # the cell that never ends reaches them, whatever the speed of the machine
            timeout=300,
            cell_timeout=150,
            jobs=2,
        )
        sleeper_alive = sleeper.poll() is None
    finally:
        sleeper.kill()
        sleeper.wait()
    feedback = out.parent / "grades_feedback"
    return {
        "subs": subs,
        "before": before,
        "after": {p: sha(p) for p in protected},
        "results": dict(zip(subs, results, strict=True)),
        "rows": dict(zip(subs, rows(out), strict=True)),
        "text": {
            name: Path(sub.feedback_file).read_text(encoding="utf-8")
            for name, sub in zip(subs, results, strict=True)
        },
        "sleeper_alive": sleeper_alive,
        "g1": g1,
        "g2": g2,
        "out": out,
        "feedback": feedback,
    }


def marks(row: dict[str, str]) -> list[str]:
    return [row[c] for c in CHECKS]


@needs_sandbox
def test_the_solution_passes_whatever_it_does_after_its_checks(graded):
    row = graded["rows"]["solution"]
    assert marks(row) == [grade.PASS] * len(CHECKS)
    assert row["total"] == row["out_of"] == str(len(CHECKS))
    # a thread printing after the last cell does not make the run look cut short
    assert row["status"] == "ok", graded["text"]["solution"]


@needs_sandbox
def test_the_untouched_student_notebook_fails_every_check(graded):
    row = graded["rows"]["student"]
    assert marks(row) == [grade.FAIL] * len(CHECKS) and row["total"] == "0"
    assert "is missing" in graded["text"]["student"]


@needs_sandbox
def test_patching_the_checks_in_the_kernel_changes_nothing(graded):
    assert marks(graded["rows"]["patched"]) == [grade.FAIL] * len(CHECKS)
    assert graded["rows"]["patched"]["total"] == "0"


@needs_sandbox
def test_another_groups_parameters_do_not_pass_this_groups_key(graded):
    assert graded["g1"]["poles"] != graded["g2"]["poles"]
    row = graded["rows"]["params"]
    assert row["group"] == "g02" and row["pa9.design"] == grade.FAIL
    assert graded["results"]["params"].params == graded["g2"]


@needs_sandbox
def test_nothing_outside_the_copy_is_reachable(graded):
    text = graded["text"]["probe"]
    line = next(x for x in text.splitlines() if x.startswith("  - code cell") and "PROBE" in x)
    reached = json.loads(line.split("PROBE ", 1)[1])
    assert reached.pop("proc") == [] and reached.pop("pids") < 100  # a process table of its own
    assert reached == {}, f"the submission reached {reached}"
    assert graded["after"] == graded["before"]  # the key, solutions and submissions untouched
    assert graded["sleeper_alive"]  # the pid it wrote into kernel.pid was not killed
    assert graded["rows"]["probe"]["pa9.design"] == grade.PASS  # it ran, in its sandbox


@needs_sandbox
def test_a_sandbox_that_kills_itself_loses_no_other_row(graded):
    row = graded["rows"]["suicide"]
    assert row["status"] == "error" and row["pa9.design"] == grade.PASS
    assert "could not be run to its end" in graded["text"]["suicide"]
    assert len(graded["rows"]) == len(graded["subs"])


@needs_sandbox
def test_a_cell_that_never_ends_is_stopped_and_graded_on_what_ran(graded):
    row = graded["rows"]["stubborn"]
    assert row["status"] == "timeout"
    assert marks(row) == [grade.PASS] + [grade.FAIL] * (len(CHECKS) - 1)
    text = graded["text"]["stubborn"]
    assert "time limit" in text and "fig is missing" in text


@needs_sandbox
def test_memory_processes_and_files_are_limited_for_good(graded):
    row = graded["rows"]["limits"]
    assert row["status"] == "error" and row["pa9.design"] == grade.PASS
    text = graded["text"]["limits"]
    line = next(x for x in text.splitlines() if x.startswith("  - code cell") and "LIMITS" in x)
    limits = json.loads(line.split("LIMITS ", 1)[1])
    default = grade.Limits()
    mib = 1024 * 1024
    assert limits == [
        [default.memory_mb * mib] * 2,
        [default.processes] * 2,
        [default.file_mb * mib] * 2,
    ]  # and the notebook could not raise them again


@needs_sandbox
def test_a_cell_that_raises_is_named_with_a_hint_not_a_traceback(graded):
    text = graded["text"]["raises"]
    assert graded["rows"]["raises"]["pa9.design"] == grade.FAIL
    assert "H is missing: code cell 3 raised LinAlgError" in text
    assert "Hint: np.linalg.inv needs a square" in text
    assert "Traceback" not in text and 'File "' not in text


@needs_sandbox
def test_every_submission_has_its_row_and_no_temporary_folder_is_left(graded):
    assert [r["file"] for r in graded["rows"].values()] == [str(p) for p in graded["subs"].values()]
    assert graded["rows"]["garbage"]["status"] == "unreadable"
    assert sorted(p.name for p in graded["out"].parent.iterdir()) == [
        "grades.csv",
        "grades_feedback",
    ]
    names = {p.name for p in graded["feedback"].iterdir()}
    assert len(names) == len(graded["subs"]) + 1 and "manifest.json" in names


@needs_sandbox
def test_a_grader_killed_mid_run_resumes_without_losing_a_row(tmp_path, monkeypatch):
    temp = tmp_path / "tmp"
    temp.mkdir()
    subs = [str(small(tmp_path / f"pa9_g{i:02d}.ipynb", f"g{i:02d}", "x = 1")) for i in range(1, 5)]
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
    assert 1 <= len(kept) < 4, grader.stderr.read().decode()
    assert any(p.name.startswith(grade.TEMP_PREFIX) for p in temp.iterdir())  # left by the kill
    monkeypatch.setattr("tempfile.tempdir", str(temp))
    again = grade.grade(subs, out, resume=True)
    done_before = {k["file"] for k in kept}
    assert [s.file for s in again] == [f for f in subs if f not in done_before]
    final = rows(out)
    assert [r["file"] for r in final] == subs
    assert all(r["pa9.design"] == grade.PASS for r in final)
    assert {r["file"]: r for r in final if r["file"] in {k["file"] for k in kept}} == {
        k["file"]: k for k in kept
    }
    assert list(temp.iterdir()) == []  # the killed run's folder removed, this run's too


def test_grade_usage_errors(tmp_path, capsys):
    assert cli.main(["grade", str(tmp_path / "nope.ipynb"), "--out", "g.csv"]) == 2
    assert "no such submission" in capsys.readouterr().err
    nb = small(tmp_path / "a.ipynb", "g01", design=False)
    code = cli.main(["grade", str(nb), "--out", "g.csv", "--groups-from", "missing.csv"])
    assert code == 2 and "missing.csv: no such file" in capsys.readouterr().err
    assert cli.main(["grade", str(nb), "--out", "g.csv", "--timeout", "0"]) == 2
    assert cli.main(["grade", str(nb), "--out", "g.csv", "--jobs", "0"]) == 2
    assert not Path("g.csv").exists()
    assert cli.main(["grade", "--help"]) == 0
    help_text = capsys.readouterr().out
    assert "RUNS THE STUDENTS' CODE" in help_text and "--no-sandbox" in help_text


def test_without_a_sandbox_grading_is_refused_unless_asked(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(grade, "sandbox_problem", lambda: "bubblewrap (bwrap) is not installed")
    nb = small(tmp_path / "pa9_g01.ipynb", "g01", design=False)
    out = tmp_path / "grades.csv"
    assert cli.main(["grade", str(nb), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "cannot isolate the submissions" in err and "--no-sandbox" in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()
    with pytest.raises(grade.SandboxRefused):
        grade.grade([nb], out)


def test_no_sandbox_grades_the_same_and_says_so_loudly(tmp_path, capsys):
    nb = small(tmp_path / "pa9_g01.ipynb", "g01")
    out = tmp_path / "grades.csv"
    assert cli.main(["grade", str(nb), "--out", str(out), "--no-sandbox", "-q"]) == 0
    err = capsys.readouterr().err
    assert "WARNING: --no-sandbox" in err and "your permissions" in err
    (row,) = rows(out)
    assert row["status"] == "ok" and row["pa9.design"] == grade.PASS and row["total"] == "1"
