"""What decides a row is the grader's alone, and sandboxes never share a user on one machine.

A notebook runs as the same user as the runner that drives its kernel, in the folder it may
write: the runner's records (the cells that raised, an output that was cut, its own failure)
go through a pipe only the runner holds, never through a file of that folder, so a cell that
forges them, or reaches for the pipe through ``/proc``, changes nothing. When the grader runs
as root each running hand-in has a user id of its own on the whole machine: two grading runs
at once never deal the same one (a hand-in holding processes in one run never counts against
another run's limit of processes).
"""

from __future__ import annotations

import csv
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import nbformat
import pytest

from uio_teach.grading import runner, sandbox
from uio_teach.grading.sandbox import UID_BASE, Limits, SandboxUser, sandbox_problem

pytestmark = [pytest.mark.kernel, pytest.mark.filterwarnings("ignore::DeprecationWarning")]


@pytest.fixture(scope="module")
def sandbox_here() -> None:
    problem = sandbox_problem()
    if problem is not None:
        pytest.skip(f"no sandbox here: {problem}")


def notebook(*sources: str):
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    nb.cells = [nbformat.v4.new_code_cell(textwrap.dedent(s)) for s in sources]
    return nb


# Every name the grader's records ever had in the run's folder, written with a forged verdict;
# then every pipe this process may open through /proc written with forged records.
FORGE = """\
import glob, json, os
forged = {"error": {"position": 1, "ename": "Forged", "evalue": "by the notebook"}}
for name in ("errors.jsonl", "runner-failed.json", "output-cut", "records", "../records"):
    try:
        with open(name, "w") as fh:
            fh.write(json.dumps(forged) + "\\n" + json.dumps({"failed": "forged"}) + "\\n")
    except OSError:
        pass
reached = []
for fd in glob.glob("/proc/[0-9]*/fd/*"):
    try:
        if not os.readlink(fd).startswith("pipe:"):
            continue
        with open(fd, "w") as fh:
            fh.write(json.dumps({"failed": "forged"}) + "\\n" + json.dumps({"cut": True}) + "\\n")
        reached.append(fd)
    except OSError:
        pass
"""


@pytest.mark.usefixtures("sandbox_here")
def test_nothing_a_notebook_writes_decides_its_status_or_reason(tmp_path):
    nb, positions = runner.prepare(
        notebook(FORGE, "raise ValueError('the real one')", "x = 1"), None, None
    )
    with SandboxUser() as user:
        outcome = runner.run_notebook(
            nb,
            tmp_path / "run",
            positions=positions,
            sandbox=True,
            timeout=300,
            cell_timeout=150,
            limits=Limits(),
            user=user,
        )
    assert outcome.status == "error"  # its own cell raised: the notebook's, and only that
    assert [(e.cell, e.ename, e.evalue) for e in outcome.errors] == [
        (2, "ValueError", "the real one")
    ]
    assert outcome.notes == []  # no "runner failed", no "output cut", nothing forged
    assert "final" in outcome.captures  # it ran to its end


@pytest.mark.usefixtures("sandbox_here")
def test_an_output_cut_is_recorded_by_the_runner_not_by_a_file(tmp_path):
    """The positive control: a record the runner writes does reach the grader."""
    nb, positions = runner.prepare(notebook("print('x' * (3 << 20))"), None, None, output_mb=1)
    with SandboxUser() as user:
        outcome = runner.run_notebook(
            nb,
            tmp_path / "run",
            positions=positions,
            sandbox=True,
            timeout=300,
            cell_timeout=150,
            limits=Limits(output_mb=1),
            user=user,
        )
    assert outcome.status == "over limits"
    assert outcome.notes[0].startswith("the notebook's output (what it printed or displayed)")
    assert not (tmp_path / "run").exists() or not list((tmp_path / "run").rglob("output-cut"))


# user ids --------------------------------------------------------------------------------------

HOLD = """\
import sys
from uio_teach.grading.sandbox import SandboxUser
with SandboxUser() as uid:
    print(uid, flush=True)
    sys.stdin.read()
"""


@pytest.mark.subprocess
@pytest.mark.skipif(os.geteuid() != 0, reason="user ids are dealt only when grading as root")
def test_no_two_processes_of_the_machine_hold_the_same_sandbox_user():
    holders = [
        subprocess.Popen(
            [sys.executable, "-c", HOLD], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
        )
        for _ in range(3)
    ]
    try:
        held = [int(p.stdout.readline()) for p in holders]
        with SandboxUser() as mine:
            assert len({*held, mine}) == 4 and min(held + [mine]) >= UID_BASE
    finally:
        for p in holders:
            p.communicate("")
    with SandboxUser() as again:  # the ids of ended runs are dealt again (the lowest free first;
        # other runs of the machine may hold or take ids meanwhile)
        assert UID_BASE <= again <= max(held + [mine])


def test_the_uid_folder_is_root_s_alone(tmp_path, monkeypatch):
    loose = tmp_path / "uids"
    loose.mkdir(mode=0o777)
    loose.chmod(0o777)
    monkeypatch.setattr(sandbox, "_UID_FOLDERS", (str(loose),))
    with pytest.raises(sandbox.SandboxUnavailable, match="not a folder of root's alone"):
        sandbox.uid_folder()


# two grading runs at once ----------------------------------------------------------------------

HOG = """\
import os, time
started = 0
while True:
    try:
        pid = os.fork()
    except OSError:
        break
    if pid == 0:
        time.sleep(3600)
        os._exit(0)
    started += 1
time.sleep(3600)
"""


def _uids_running() -> dict[int, int]:
    """How many processes each sandbox user id runs on the machine."""
    counts: dict[int, int] = {}
    for status in Path("/proc").glob("[0-9]*/status"):
        try:
            uid = next(int(line.split()[1]) for line in status.open() if line.startswith("Uid:"))
        except (OSError, StopIteration, ValueError):
            continue
        if uid >= UID_BASE:
            counts[uid] = counts.get(uid, 0) + 1
    return counts


def _grade(folder: Path, out: Path) -> subprocess.Popen:
    command = [sys.executable, "-m", "uio_teach", "grade", str(folder), "--out", str(out)]
    command += ["--timeout", "900", "--cell-timeout", "600", "-q"]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


@pytest.mark.slow
@pytest.mark.subprocess
@pytest.mark.usefixtures("sandbox_here")
@pytest.mark.skipif(os.geteuid() != 0, reason="user ids are dealt only when grading as root")
def test_two_grading_runs_at_once_never_share_a_sandbox_user(tmp_path):
    """Run A's hand-in holds every process its limit allows; run B, started while it does,
    grades an honest hand-in as if A were not there."""
    hog, honest = tmp_path / "a", tmp_path / "b"
    hog.mkdir()
    honest.mkdir()
    nbformat.write(notebook(HOG), hog / "pa9_g01.ipynb")
    nbformat.write(notebook("x = 1"), honest / "pa9_g01.ipynb")
    before = set(_uids_running())
    first = _grade(hog, tmp_path / "a.csv")
    try:
        limit = Limits().processes - 32  # the kernel's and the runner's threads count too
        full: dict[int, int] = {}
        while first.poll() is None and not full:  # until A's hand-in holds all it may
            time.sleep(0.5)
            full = {u: n for u, n in _uids_running().items() if u not in before and n >= limit}
        assert full, first.communicate()[0]
        second = _grade(honest, tmp_path / "b.csv")
        output = second.communicate()[0]
        assert second.returncode == 0, output
        with open(tmp_path / "b.csv", newline="", encoding="utf-8") as fh:
            (row,) = list(csv.DictReader(fh))
        assert row["status"] == "ok", row
        assert "BlockingIOError" not in output + row["reason"]
    finally:
        first.kill()  # its sandbox ends with it (bubblewrap's --die-with-parent)
        first.communicate()
