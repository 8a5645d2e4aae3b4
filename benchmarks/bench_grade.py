"""Benchmark: grading 30 lab submissions one at a time and two at a time (`--jobs 1` vs `2`).

Run with ``.venv/bin/python benchmarks/bench_grade.py`` (a few minutes to half an hour, depending
on the machine: every submission starts a sandbox and a fresh kernel and runs the whole lab).
``uio-teach labs --groups N`` writes one PA9 variant per group; the solution notebooks are the
submissions, graded with the answer key, first with one job, then with two, into separate
gradebooks. The script checks that both gradebooks agree and that every solution passes, then
prints the two times and their ratio (the number the instructors' page quotes). ``--count`` and
``--lab`` change what is graded; ``--no-sandbox`` measures without bubblewrap.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

from uio_teach.instructor import cli, grade


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=30, help="submissions (default 30)")
    parser.add_argument("--lab", default="pa9", help="the lab (default pa9)")
    parser.add_argument("--no-sandbox", action="store_true", help="run without bubblewrap")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench-grade-") as tmp:
        root = Path(tmp)
        labs = root / "labs"
        code = cli.main(["labs", "--out", str(labs), "--groups", str(args.count), "-q"])
        if code != 0:
            return code
        subs = sorted((labs / args.lab / "solution").glob("*.ipynb"))
        key = labs / "answer_key.csv"
        seconds = {}
        tables = {}
        for jobs in (1, 2):
            out = root / f"grades_jobs{jobs}.csv"
            start = time.perf_counter()
            grade.grade(
                subs,
                out,
                answer_key=key,
                jobs=jobs,
                sandbox=not args.no_sandbox,
                timeout=1800,
                cell_timeout=900,
            )
            seconds[jobs] = time.perf_counter() - start
            tables[jobs] = _rows(out)
            print(
                f"jobs {jobs}: {len(subs)} submissions graded in {seconds[jobs]:.1f} s", flush=True
            )
        marks = tables[1]
        if marks != tables[2]:
            print("the two gradebooks differ", file=sys.stderr)
            return 1
        failed = [r["file"] for r in marks if r["total"] != r["out_of"]]
        if failed:
            print(f"solutions that did not pass every check: {failed}", file=sys.stderr)
            return 1
    print(
        f"\n{args.lab}, {len(subs)} solution notebooks, sandbox "
        f"{'off' if args.no_sandbox else 'on'}, {os.cpu_count()} CPUs, "
        f"load {os.getloadavg()[0]:.1f}, Python {platform.python_version()}\n"
        f"  jobs 1: {seconds[1]:7.1f} s ({seconds[1] / len(subs):.1f} s per submission)\n"
        f"  jobs 2: {seconds[2]:7.1f} s ({seconds[2] / len(subs):.1f} s per submission)\n"
        f"  jobs 1 / jobs 2: {seconds[1] / seconds[2]:.2f}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
