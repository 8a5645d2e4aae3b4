"""Benchmark: the time per honest notebook in a mixed class against a class of honest ones only.

Run with ``.venv/bin/python benchmarks/bench_grade.py`` (several minutes: every hand-in that runs
starts a sandbox, a fresh kernel and a checking process). ``uio-teach labs --groups N`` writes one
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

from uio_teach.instructor import cli, grade

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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--honest", type=int, default=10, help="honest hand-ins (default 10)")
    parser.add_argument("--jobs", type=int, default=2, help="hand-ins at a time (default 2)")
    parser.add_argument("--timeout", type=float, default=120, help="--timeout (default 120 s)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench-grade-") as tmp:
        root = Path(tmp)
        labs = root / "labs"
        groups = str(args.honest + 20)
        if cli.main(["labs", "--out", str(labs), "--groups", groups, "--seed", "1", "-q"]) != 0:
            return 1
        key = labs / "answer_key.csv"
        result = {}
        for mixed in (False, True):
            label = "mixed" if mixed else "honest only"
            folder = root / ("mixed" if mixed else "honest")
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
