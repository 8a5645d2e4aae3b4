"""Time the book build: a clean build with execution, and a cached rebuild after a prose edit.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_book.py [--runs N]

Each run works on a fresh copy of the sources in a temporary folder, so the
repository's own ``_build`` is not touched. The cached rebuild appends a
sentence to one chapter (no code change), which must not re-execute any
notebook. Each build is what ``make book`` runs: ``_ext/run_chapters.py`` (the chapters that
changed, as many at a time as there are cores), then ``jupyter-book build``. Goals on a 2-core
machine: clean under 90 s, cached under 15 s.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COPY = ["_config.yml", "_toc.yml", "references.bib", "book", "_ext", "_static", "uio_teach"]
COPY += ["pyproject.toml"]


def build(src: Path) -> float:
    bindir = Path(sys.executable).parent
    env = dict(os.environ, PATH=f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}")
    start = time.perf_counter()
    # as `make book`: the chapters that changed run on every core, then the build
    for command in (
        [sys.executable, str(src / "_ext" / "run_chapters.py")],
        [str(bindir / "jupyter-book"), "build", str(src), "-W", "-n", "--keep-going"],
    ):
        proc = subprocess.run(command, env=env, capture_output=True, text=True)
        if proc.returncode:
            sys.exit(f"the book build failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return time.perf_counter() - start


def one_run() -> tuple[float, float]:
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "book-src"
        src.mkdir()
        for name in COPY:
            path = ROOT / name
            if path.is_dir():
                shutil.copytree(path, src / name, ignore=shutil.ignore_patterns("__pycache__"))
            else:
                shutil.copy2(path, src / name)
        clean = build(src)
        chapter = src / "book" / "pa9.md"
        chapter.write_text(chapter.read_text() + "\nA sentence added to time a rebuild.\n")
        cached = build(src)
    return clean, cached


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    results = [one_run() for _ in range(args.runs)]
    clean = statistics.median(r[0] for r in results)
    cached = statistics.median(r[1] for r in results)
    print(f"runs: {args.runs}")
    print(f"clean build with execution: median {clean:6.1f} s (goal < 90 s)")
    print(f"cached rebuild, prose edit: median {cached:6.1f} s (goal < 15 s)")


if __name__ == "__main__":
    main()
