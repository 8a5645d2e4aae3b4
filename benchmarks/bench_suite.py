"""Time the test commands (`make check`, `make test`) and weigh the API page.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_suite.py                   # the API page only
    .venv/bin/python benchmarks/bench_suite.py --target check --target test  # and the commands
    .venv/bin/python benchmarks/bench_suite.py --junit run.xml   # read a run's JUnit report
    .venv/bin/python benchmarks/bench_suite.py --checkout ../old --label before  # another checkout

For each target: the wall-clock time of the whole command, the CPU time of every process it
started (user + system, summed over the workers, the kernels and the book build), the machine's
load average before and after (the cores are shared: wall-clock grows with the load, CPU time
much less), and from pytest's JUnit report the tests run and the time summed per test module,
the ten largest listed. The API reference's size is that of its largest page,
``_build/html/book/api*.html``, when a build is there (``make book`` first). The last line
is the result as JSON, read by ``benchmarks/report.py``.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GOALS = {"check": 60.0, "test": 600.0}


def _load() -> float:
    try:
        return float(Path("/proc/loadavg").read_text().split()[0])
    except OSError:
        return float("nan")


def module_sums(junit: Path) -> tuple[int, dict[str, float]]:
    """Tests run and seconds summed per test module, from a JUnit XML report."""
    tree = ET.parse(junit)
    sums: dict[str, float] = collections.defaultdict(float)
    count = 0
    for case in tree.iter("testcase"):
        skipped = any(child.tag == "skipped" for child in case)
        if skipped:
            continue
        count += 1
        module = case.get("classname", "").split(".")
        name = next((part for part in module if part.startswith("test_")), ".".join(module))
        sums[name] += float(case.get("time", 0.0))
    return count, dict(sums)


def run_target(target: str, root: Path = ROOT) -> dict:
    """Run ``make <target>`` with a JUnit report; its wall-clock and CPU time and module sums."""
    with tempfile.TemporaryDirectory() as tmp:
        junit = Path(tmp) / "junit.xml"
        env = dict(os.environ, PYTEST_ADDOPTS=f"--junitxml={junit} -p no:cacheprovider")
        before_load = _load()
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        proc = subprocess.run(["make", target], cwd=root, env=env, check=False)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - usage.ru_utime) + (after.ru_stime - usage.ru_stime)
        count, sums = module_sums(junit) if junit.exists() else (0, {})
    return {
        "target": target,
        "status": proc.returncode,
        "wall": wall,
        "cpu": cpu,
        "tests": count,
        "load": [before_load, _load()],
        "modules": dict(sorted(sums.items(), key=lambda kv: -kv[1])[:10]),
        "goal": GOALS.get(target),
    }


def api_page(root: Path = ROOT) -> dict | None:
    """The largest page of the API reference (``book/api*.html``), when a build is there."""
    pages = sorted((root / "_build" / "html" / "book").glob("api*.html"))
    if not pages:
        return None
    largest = max(pages, key=lambda page: page.stat().st_size)
    return {"api_bytes": largest.stat().st_size, "api_page": f"book/{largest.name}"}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--target", action="append", choices=sorted(GOALS), default=None, help="make targets run"
    )
    parser.add_argument("--junit", type=Path, help="only read this JUnit report (no run)")
    parser.add_argument(
        "--checkout", type=Path, default=ROOT, help="run the commands in this checkout (before)"
    )
    parser.add_argument("--label", default="after", help="what the run measures (before, after)")
    args = parser.parse_args(argv)
    result: dict = {"cores": os.cpu_count(), "runs": [], "label": args.label}
    if args.junit:
        count, sums = module_sums(args.junit)
        total = sum(sums.values())
        print(f"{args.junit}: {count} tests, {total:.0f} s summed")
        for name, seconds in sorted(sums.items(), key=lambda kv: -kv[1])[:15]:
            print(f"  {name}: {seconds:.0f} s")
        return 0
    for target in args.target or []:
        run = run_target(target, args.checkout)
        result["runs"].append(run)
        print(
            f"{args.label}: make {target}: {run['wall']:.0f} s wall-clock, {run['cpu']:.0f} s CPU, "
            f"{run['tests']} tests, status {run['status']}, load {run['load'][0]:.1f} -> "
            f"{run['load'][1]:.1f} on {result['cores']} cores",
            flush=True,
        )
        for name, seconds in run["modules"].items():
            print(f"  {name}: {seconds:.0f} s summed")
    page = api_page(args.checkout)
    if page:
        result.update(page)
        print(f"API page: {page['api_bytes'] / 1000:.0f} kB of HTML")
    print(json.dumps(result))
    return 0 if all(r["status"] == 0 for r in result["runs"]) else 1


if __name__ == "__main__":
    sys.exit(main())
