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
import statistics
import tempfile
from pathlib import Path

from book_copy import book_commands, copy_sources, environment, run


def build(src: Path) -> float:
    """`make book` on ``src``; its seconds."""
    env = environment()
    return sum(run(command, env)[0] for command in book_commands(src))


def one_run() -> tuple[float, float]:
    with tempfile.TemporaryDirectory() as tmp:
        src = copy_sources(Path(tmp) / "book-src")
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
