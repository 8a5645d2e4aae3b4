"""Time `uio-teach figures` as a whole process: every figure of the course, regenerated.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_figures.py [--runs N] [--format png|pdf|svg]

Each run starts a fresh ``python -m uio_teach figures --out DIR`` into a new
temporary folder and measures the wall-clock time of the whole process (the
imports, the simulations, the drawing, the staging and the swap), next to
the time of ``python -c "import uio_teach"`` alone, so that the share of the
imports can be read as a ratio that does not depend on how fast or busy the
machine is. The goal for a quiet 2-core machine: the whole regeneration in
under 30 s. Nothing here is a test: a slow machine gives slow numbers.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _env() -> dict[str, str]:
    return dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])
    )


def timed(argv: list[str]) -> float:
    start = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, text=True, env=_env(), check=False)
    elapsed = time.perf_counter() - start
    if proc.returncode:
        sys.exit(f"{' '.join(argv)} failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    return elapsed


def one_run(fmt: str) -> tuple[float, float]:
    """Seconds for the whole `figures` process, and for `import uio_teach` alone."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "figures"
        whole = timed([sys.executable, "-m", "uio_teach", "figures", "--out", str(out), "-q",
                       "--format", fmt])  # fmt: skip
        files = sorted(p.name for p in out.iterdir())
        if "manifest.json" not in files:
            sys.exit(f"no manifest in {out}: {files}")
    imports = timed([sys.executable, "-c", "import uio_teach"])
    return whole, imports


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=3, help="how many runs (default: 3)")
    parser.add_argument("--format", default="png", choices=("png", "pdf", "svg"))
    args = parser.parse_args()
    wholes, imports = [], []
    for k in range(args.runs):
        whole, imp = one_run(args.format)
        wholes.append(whole)
        imports.append(imp)
        print(f"run {k + 1}: uio-teach figures {whole:.1f} s, import uio_teach {imp:.1f} s")
    w, i = statistics.median(wholes), statistics.median(imports)
    print(f"median of {args.runs}: uio-teach figures ({args.format}) {w:.1f} s as a whole process")
    print(f"  import uio_teach alone {i:.1f} s, {i / w:.0%} of the whole")
    print(f"  goal on a quiet 2-core machine: under 30 s; {'met' if w < 30 else 'not met'}")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"  load average during the runs: {load:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
