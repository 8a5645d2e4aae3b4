"""Benchmark: grading against its floor, ``jupyter nbconvert --execute``; its start-up; its cost
per cell; the time per honest notebook in a mixed class against a class of honest ones only.

Run with ``.venv/bin/python benchmarks/bench_grade.py`` (several minutes: every hand-in that runs
starts a sandbox, a fresh kernel and a checking process; ``--parts`` picks some).

* ``startup``: the time from the command's start to the first hand-in's run, in a fresh
  interpreter (imports, reading the lab chapters' check cells, the hand-ins, the roster; the
  sandbox's own test runs beside the first hand-ins): goal 5 s.
* ``nbconvert``: the same honest notebooks graded one at a time and executed one at a time by
  ``jupyter nbconvert --execute`` (the floor: the kernel and the notebook's own work, no sandbox,
  no checks); goal: grading within 1.2x of it.
* ``cells``: an honest notebook with 2000 and with 4000 more tiny cells; the cost of the added
  cells must double, not quadruple (the notebook is not saved per cell).
* ``mixed``: ``uio-teach labs --groups N`` writes one
PA9 variant per group; the honest hand-ins are the solution notebooks of the first ``--honest``
groups (each with a line of its own), the others a mix of what a real class hands in: files that
are not notebooks, links to the instructor's files, a folder, a notebook whose tags are a
number, a group's notebook under another's name, the same code from two groups, a fork bomb, a
notebook filling its ``/tmp`` and its folder, a figure of 100 axes, a cell that never ends, a
kernel that kills itself. Both classes are graded with the answer key and ``--jobs`` (default 2).

It prints, for each class, the wall time per honest notebook (all the class's time divided by
its honest hand-ins) and the mean time each honest notebook took to grade, then the ratios mixed /
honest only (the number the instructors' page quotes); it fails if an honest notebook lost a
mark or a hostile one got ``ok`` with full marks.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import nbformat

from uio_teach.grading import grade
from uio_teach.instructor import cli

SETUP = "import numpy as np\nimport uio_teach as ut\nfrom uio_teach import checks\n"
HOSTILE_CELLS = {
    "forks": """\
        import os, time
        for _ in range(1500):
            try:
                if os.fork() == 0:
                    time.sleep(600)
                    os._exit(0)
            except OSError:
                break
        """,
    "fill": """\
        try:
            with open("/tmp/fill", "wb") as fh:
                for _ in range(3 * 1024):
                    fh.write(b"x" * (1 << 20))
        except OSError:
            pass
        for n in range(8):
            with open(f"fill{n}", "wb") as fh:
                fh.write(b"x" * (60 << 20))
        """,
    "axes": """\
        import matplotlib.pyplot as plt
        fig = plt.figure()
        for k in range(100):
            fig.add_axes([0, 0, 0.01, 0.01])
        """,
    "endless": """\
        import signal
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        while True:
            pass
        """,
    "suicide": "import os, signal\nos.kill(-1, signal.SIGKILL)\n",
    "plain": "x = 1\n",
}


def _notebook(cells: list[str], group: str | None, tags5: bool = False) -> dict:
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {
        "name": "python3",
        "display_name": "Python 3",
        "language": "python",
    }
    nb.metadata["uio_teach"] = {"lab": "pa9", **({"group": group} if group else {})}
    nb.cells.append(nbformat.v4.new_code_cell(SETUP))
    params = nbformat.v4.new_code_cell("PARAMS = {}")
    params.metadata["tags"] = ["parameters"]
    nb.cells.append(params)
    nb.cells += [nbformat.v4.new_code_cell(textwrap.dedent(c)) for c in cells]
    data = json.loads(nbformat.writes(nb))
    if tags5:
        data["cells"][1]["metadata"]["tags"] = 5
    return data


def _class(folder: Path, labs: Path, honest: int, mixed: bool) -> list[Path]:
    folder.mkdir()
    made = []
    for i in range(1, honest + 1):
        nb = nbformat.read(labs / "pa9" / "solution" / f"pa9_g{i:02d}.ipynb", as_version=4)
        nb.cells.insert(1, nbformat.v4.new_code_cell(f"mine = 'g{i:02d}'"))
        path = folder / f"pa9_g{i:02d}.ipynb"
        nbformat.write(nb, path)
        made.append(path)
    if not mixed:
        return made
    g = honest + 1

    def name() -> Path:
        nonlocal g
        g += 1
        return folder / f"pa9_g{g - 1:02d}.ipynb"

    name().write_text("{ not a notebook")
    name().write_bytes(bytes(range(256)))
    name().symlink_to(labs / "pa9" / "solution" / "pa9_g01.ipynb")
    name().symlink_to(labs / "answer_key.csv")
    name().mkdir()
    for kind in ("forks", "fill", "axes", "endless", "suicide"):
        path = name()
        path.write_text(json.dumps(_notebook([HOSTILE_CELLS[kind]], path.stem[4:])))
    path = name()
    path.write_text(json.dumps(_notebook([HOSTILE_CELLS["plain"]], path.stem[4:], tags5=True)))
    path = name()
    path.write_text(json.dumps(_notebook([HOSTILE_CELLS["plain"]], "g01")))  # renamed
    for _ in range(2):  # the same code from two groups
        path = name()
        path.write_text(json.dumps(_notebook(["shared = 1"], path.stem[4:])))
    (folder / "handin.ipynb").write_text(json.dumps(_notebook(["anon = 1"], None)))
    nb = nbformat.read(labs / "pa9" / "student" / "pa9_g01.ipynb", as_version=4)
    nbformat.write(nb, name())  # the untouched template
    return made


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


STARTUP = """\
import sys, time
start = time.perf_counter()
from uio_teach.grading import grade
seen = []
real = grade._grade_one
def first(*args):
    if not seen:
        seen.append(time.perf_counter() - start)
        print(f"STARTUP {seen[0]:.3f} {time.process_time():.3f}", flush=True)
    return real(*args)
grade._grade_one = first
from uio_teach.instructor import cli
sys.exit(cli.main(sys.argv[1:]))
"""


def _startup(folder: Path, key: Path, out: Path) -> tuple[float, float]:
    """Seconds from a fresh interpreter's start to the first hand-in's run, wall and CPU time of
    the process (medians of 3): on a busy machine the wall time is mostly waiting for a core."""
    import statistics
    import subprocess

    walls, cpus = [], []
    for n in range(3):
        args = [sys.executable, "-c", STARTUP, "grade", str(folder), "--out", str(out) + f"{n}"]
        args += ["--groups-from", str(key), "-q"]
        proc = subprocess.run(args, capture_output=True, text=True, timeout=1800)
        line = next(x for x in proc.stdout.splitlines() if x.startswith("STARTUP"))
        walls.append(float(line.split()[1]))
        cpus.append(float(line.split()[2]))
    return statistics.median(walls), statistics.median(cpus)


def _nbconvert(paths: list[Path], work: Path) -> float:
    """Mean seconds ``jupyter nbconvert --execute`` takes per notebook, one at a time."""
    import subprocess

    work.mkdir()
    total = 0.0
    for path in paths:
        start = time.perf_counter()
        subprocess.run(
            [
                sys.executable,
                "-m",
                "jupyter",
                "nbconvert",
                "--execute",
                "--to",
                "notebook",
                "--output-dir",
                str(work),
                "--ExecutePreprocessor.timeout=600",
                str(path),
            ],
            check=True,
            capture_output=True,
            cwd=work,
        )
        total += time.perf_counter() - start
    return total / len(paths)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--honest", type=int, default=10, help="honest hand-ins (default 10)")
    parser.add_argument("--jobs", type=int, default=2, help="hand-ins at a time (default 2)")
    parser.add_argument("--timeout", type=float, default=120, help="--timeout (default 120 s)")
    parser.add_argument(
        "--parts",
        default="startup,nbconvert,cells,mixed",
        help="what to measure (default: startup,nbconvert,cells,mixed)",
    )
    args = parser.parse_args(argv)
    parts = set(args.parts.split(","))
    failed = False
    with tempfile.TemporaryDirectory(prefix="bench-grade-") as tmp:
        root = Path(tmp)
        labs = root / "labs"
        groups = str(args.honest + 20)
        if cli.main(["labs", "--out", str(labs), "--groups", groups, "--seed", "1", "-q"]) != 0:
            return 1
        key = labs / "answer_key.csv"
        honest_folder = root / "honest"
        honest = _class(honest_folder, labs, args.honest, False)
        if "startup" in parts:
            wall, cpu = _startup(honest_folder, key, root / "startup.csv")
            load = os.getloadavg()[0]
            print(
                f"start-up before the first hand-in: {wall:.2f} s, of which {cpu:.2f} s of CPU "
                f"(goal 5 s; load {load:.1f} on {os.cpu_count()} CPUs)",
                flush=True,
            )
            busy = load > (os.cpu_count() or 1)
            failed |= (cpu if busy else wall) > 5
        if "nbconvert" in parts:
            floor = _nbconvert(honest, root / "nbconvert")
            subs = grade.grade(honest_folder, root / "one_at_a_time.csv", answer_key=key, jobs=1)
            mine = sum(s.seconds for s in subs) / len(subs)
            print(
                f"grading one at a time: {mine:.1f} s per notebook; jupyter nbconvert --execute "
                f"{floor:.1f} s: ratio {mine / floor:.2f} (goal 1.2)",
                flush=True,
            )
            failed |= mine / floor > 1.2
        if "cells" in parts:
            costs = {}
            for extra in (0, 2000, 4000):
                folder = root / f"cells{extra}"
                folder.mkdir()
                nb = nbformat.read(honest[0], as_version=4)
                nb.cells += [nbformat.v4.new_code_cell(f"c{i} = {i}") for i in range(extra)]
                nbformat.write(nb, folder / honest[0].name)
                (sub,) = grade.grade(folder, root / f"cells{extra}.csv", answer_key=key)
                costs[extra] = sub.seconds
            growth = (costs[4000] - costs[0]) / max(costs[2000] - costs[0], 1e-9)
            print(
                f"2000 more cells: +{costs[2000] - costs[0]:.1f} s, 4000 more: "
                f"+{costs[4000] - costs[0]:.1f} s: {growth:.2f}x for twice the cells "
                "(linear: 2; saved per cell: 4)",
                flush=True,
            )
            failed |= growth > 3
        if "mixed" in parts:
            failed |= _mixed(args, root, labs, key) != 0
    return 1 if failed else 0


def _mixed(args: argparse.Namespace, root: Path, labs: Path, key: Path) -> int:
    result = {}
    for mixed in (False, True):
        label = "mixed" if mixed else "honest only"
        folder = root / ("mixed_class" if mixed else "honest_class")
        honest = {os.fspath(p) for p in _class(folder, labs, args.honest, mixed)}
        out = root / f"grades_{folder.name}.csv"
        start = time.perf_counter()
        subs = grade.grade(
            folder,
            out,
            answer_key=key,
            jobs=args.jobs,
            timeout=args.timeout,
            cell_timeout=args.timeout / 2,
        )
        wall = time.perf_counter() - start
        mine = [s for s in subs if s.file in honest]
        lost = [s.file for s in mine if s.status != "ok" or s.total != len(s.expected)]
        cheats = [
            s.file
            for s in subs
            if s.file not in honest and s.status == "ok" and s.total == len(s.expected)
        ]
        if lost or cheats or len(_rows(out)) != len(subs):
            print(f"{label}: honest rows lost marks {lost}, others ok in full {cheats}")
            return 1
        per_wall = wall / len(mine)
        per_own = sum(s.seconds for s in mine) / len(mine)
        result[mixed] = (per_wall, per_own)
        print(
            f"{label}: {len(subs)} hand-ins ({len(mine)} honest) in {wall:.1f} s: "
            f"{per_wall:.1f} s of the run per honest notebook, each graded in "
            f"{per_own:.1f} s on average",
            flush=True,
        )
    wall_ratio = result[True][0] / result[False][0]
    own_ratio = result[True][1] / result[False][1]
    print(
        f"\npa9, {args.honest} honest solution notebooks, --jobs {args.jobs}, --timeout "
        f"{args.timeout:g}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}, "
        f"Python {platform.python_version()}\n"
        f"  time per honest notebook, mixed / honest only: {own_ratio:.2f} "
        f"(each notebook's own grading time), {wall_ratio:.2f} (the run's time per honest one)"
    )
    return 0 if own_ratio <= 2 else 1


if __name__ == "__main__":
    sys.exit(main())
