"""Time ``import uio_teach`` in a fresh interpreter, against ``import control`` alone.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_import.py [--runs N]

Each run starts a new Python process, so nothing is cached in memory but what the operating
system keeps; the median of ``--runs`` runs is reported, with a bare interpreter's start-up
and ``import control`` (python-control, which the package builds on) for comparison. The last
line is the result as JSON, read by ``benchmarks/report.py``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

STATEMENTS = {
    "python": "pass",
    "control": "import control",
    "uio_teach": "import uio_teach",
}


def wall_time(statement: str) -> float:
    """Seconds for a new interpreter to run ``statement`` and exit."""
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", statement], check=True)
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="fresh processes per statement")
    args = parser.parse_args(argv)
    wall_time(STATEMENTS["uio_teach"])  # warm the file cache once
    result = {"runs": args.runs}
    for name, statement in STATEMENTS.items():
        times = [wall_time(statement) for _ in range(args.runs)]
        result[name] = statistics.median(times)
        print(f"{statement!r}: median {result[name]:.2f} s of {args.runs} runs", flush=True)
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
