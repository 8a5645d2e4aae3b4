"""Time ``uio-teach figures``: every course figure, the whole process from start to exit.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_figures.py [--runs N]

Each run is a new process writing every figure into a new folder, as an instructor runs it
(imports, configuration, drawing, writing, the manifest); the median of ``--runs`` runs is
reported. Goal on a 2-core machine: under 30 s. The last line is the result as JSON, read by
``benchmarks/report.py``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def one_run() -> tuple[float, int]:
    """Seconds for one ``uio-teach figures`` process, and the number of files it wrote."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "figures"
        command = [sys.executable, "-m", "uio_teach", "figures", "--out", str(out), "-q"]
        start = time.perf_counter()
        subprocess.run(command, check=True)
        seconds = time.perf_counter() - start
        return seconds, sum(1 for _ in out.iterdir())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args(argv)
    runs = [one_run() for _ in range(args.runs)]
    figures = subprocess.run(
        [sys.executable, "-m", "uio_teach", "figures", "--list"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.splitlines()
    result = {
        "runs": args.runs,
        "seconds": statistics.median(r[0] for r in runs),
        "figures": len(figures),
        "files": runs[0][1],
    }
    print(
        f"uio-teach figures: {result['figures']} figures, {result['files']} files, "
        f"median {result['seconds']:.1f} s of {args.runs} runs (goal < 30 s)"
    )
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
