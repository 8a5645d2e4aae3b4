"""The instructors' page's Slurm recipe, run on a one-node Slurm cluster: the same gradebook.

The test starts its own cluster in a temporary folder (Debian's ``munge``, ``slurmctld`` and
``slurmd``, as root, on ports of their own), takes the job script and the merge command from
``book/instructors.md`` as they are printed there, submits the script as a job array of
``uio-teach grade --shard K/N`` and merges the shards with ``uio-teach merge``: every file of the
merged gradebook (the CSV, its exports, the feedback and its manifest) must be the file one whole
run writes. Skipped where Slurm or munge is not installed (``apt-get install slurmd slurmctld
slurm-client munge``) or the test does not run as root (the daemons need it).
"""

from __future__ import annotations

import os
import re
import shutil
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from uio_teach.instructor import cli

pytestmark = [
    pytest.mark.slow,
    pytest.mark.subprocess,
    pytest.mark.kernel,
    pytest.mark.filterwarnings("ignore::DeprecationWarning"),
]

ROOT = Path(__file__).resolve().parents[1]
PROGRAMS = ("munged", "munge", "slurmctld", "slurmd", "sbatch", "sinfo")


def _recipe() -> tuple[str, str]:
    """The job script and the merge command as the instructors' page prints them."""
    text = (ROOT / "book" / "instructors.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```bash\n(.*?)```", text, re.S)
    script = next(b for b in blocks if "#SBATCH --array" in b)
    merge = next(b for b in blocks if "uio-teach merge" in b and "sbatch" in b)
    command = next(line for line in merge.splitlines() if line.startswith("uio-teach merge"))
    return script, command


@pytest.fixture(scope="module")
def slurm(tmp_path_factory) -> Iterator[dict[str, str]]:
    missing = [p for p in PROGRAMS if shutil.which(p) is None]
    if missing:
        pytest.skip(f"Slurm or munge is not installed here (no {', '.join(missing)})")
    if os.geteuid() != 0:
        pytest.skip("the test starts Slurm's daemons, which need root")
    base = tmp_path_factory.mktemp("slurm")
    for sub in ("state", "spool", "log", "munge"):
        (base / sub).mkdir()
    (base / "munge").chmod(0o700)
    key = base / "munge" / "munge.key"
    key.write_bytes(os.urandom(1024))
    key.chmod(0o600)
    host = socket.gethostname()
    ports = []
    for _ in range(2):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            ports.append(s.getsockname()[1])
    memory = int(Path("/proc/meminfo").read_text().split()[1]) // 1024
    conf = base / "slurm.conf"
    conf.write_text(
        f"""ClusterName=uioteach
SlurmctldHost={host}
SlurmctldPort={ports[0]}
SlurmdPort={ports[1]}
AuthType=auth/munge
AuthInfo=socket={base}/munge/munge.socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation={base}/state
SlurmdSpoolDir={base}/spool
SlurmctldPidFile={base}/slurmctld.pid
SlurmdPidFile={base}/slurmd.pid
SlurmctldLogFile={base}/log/slurmctld.log
SlurmdLogFile={base}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
NodeName={host} CPUs={os.cpu_count()} RealMemory={memory} State=UNKNOWN
PartitionName=debug Nodes={host} Default=YES MaxTime=INFINITE State=UP
"""
    )
    env = dict(os.environ, SLURM_CONF=str(conf))
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    daemons = []
    try:
        daemons.append(
            subprocess.Popen(
                ["munged", "--force", "--foreground", f"--key-file={key}"]
                + [f"--socket={base}/munge/munge.socket", f"--seed-file={base}/munge/seed"]
                + [f"--pid-file={base}/munge/munged.pid", f"--log-file={base}/log/munged.log"],
                env=env,
            )
        )
        while daemons[0].poll() is None and not (base / "munge" / "munge.socket").exists():
            time.sleep(0.1)  # until munge's socket is there
        daemons.append(subprocess.Popen(["slurmctld", "-D", "-i", "-f", str(conf)], env=env))
        daemons.append(subprocess.Popen(["slurmd", "-D", "-f", str(conf)], env=env))
        state = ""
        while all(d.poll() is None for d in daemons) and "idle" not in state:
            done = subprocess.run(
                ["sinfo", "-h", "-o", "%T"], env=env, capture_output=True, text=True
            )
            state = done.stdout
            time.sleep(0.5)
        if "idle" not in state:
            logs = {p.name: p.read_text()[-1500:] for p in (base / "log").glob("*.log")}
            pytest.fail(f"the one-node Slurm cluster did not start: {logs}")
        yield env
    finally:
        for daemon in reversed(daemons):
            daemon.terminate()
            try:
                daemon.wait(timeout=30)
            except subprocess.TimeoutExpired:
                daemon.kill()
                daemon.wait()


def test_the_slurm_recipe_gives_the_gradebook_of_one_run(slurm, tmp_path):
    course = tmp_path / "course"
    labs = course / "labs"
    assert cli.main(["labs", "--out", str(labs), "--groups", "3", "--seed", "5", "-q"]) == 0
    handed_in = course / "handed_in"
    handed_in.mkdir()
    for group in ("g01", "g02"):
        source = labs / "pa9" / "solution" / f"pa9_{group}.ipynb"
        (handed_in / source.name).write_bytes(source.read_bytes())
    (handed_in / "pa9_g03.ipynb").write_text("{ not a notebook")
    shutil.copy(labs / "answer_key.csv", course / "answer_key.csv")
    (course / "groups.csv").write_text(
        "group,student,name\ng01,s1,Ann\ng02,s2,Bo\ng03,s3,Cy\n", encoding="utf-8"
    )
    script, merge = _recipe()
    (course / "grade.sh").write_text(script, encoding="utf-8")
    whole = subprocess.run(
        [
            "uio-teach",
            "grade",
            "handed_in",
            "--out",
            "whole/grades.csv",
            "--groups-from",
            "answer_key.csv",
            "--roster",
            "groups.csv",
            "--jobs",
            "2",
            "-q",
        ],
        cwd=course,
        env=slurm,
        capture_output=True,
        text=True,
    )
    assert whole.returncode == 0, whole.stderr
    submitted = subprocess.run(
        ["sbatch", "--wait", "--output=slurm-%a.out", "grade.sh"],
        cwd=course,
        env=slurm,
        capture_output=True,
        text=True,
    )
    logs = {p.name: p.read_text()[-800:] for p in course.glob("slurm-*.out")}
    assert submitted.returncode == 0, (submitted.stderr, logs)
    shards = sorted(course.glob("marks/*/grades.csv"))
    assert len(shards) == int(re.search(r"--array=1-(\d+)", script)[1]), logs
    merged = subprocess.run(
        ["bash", "-c", merge], cwd=course, env=slurm, capture_output=True, text=True
    )
    assert merged.returncode == 0, merged.stderr

    def files(folder: Path) -> dict[str, bytes]:
        names = ["grades.csv", "grades_groups.csv", "grades_canvas.csv", "grades_moodle.csv"]
        found = {n: (folder / n).read_bytes() for n in names if (folder / n).is_file()}
        for path in sorted((folder / "grades_feedback").rglob("*")):
            if path.is_file():
                found[path.relative_to(folder).as_posix()] = path.read_bytes()
        return found

    one, many = files(course / "whole"), files(course)
    assert set(one) == set(many)
    assert [n for n in one if one[n] != many[n]] == []
    rows = (course / "grades.csv").read_text(encoding="utf-8").splitlines()
    assert len(rows) == 4  # the header and a row per hand-in
