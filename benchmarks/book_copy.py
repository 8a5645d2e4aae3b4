"""The set-up the book's benchmarks share: a fresh copy of the sources and `make book`'s commands.

``bench_book.py`` and ``bench_pdf.py`` build the book in a temporary folder, from a copy of the
sources (the repository's own ``_build`` is not touched), with the tools of the interpreter that
runs them first on ``PATH``, as ``make`` puts the virtual environment's.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# What a build of the book reads: the book and its extensions, the package its chapters import,
# and what the build's wheel of the package is made from (_ext/downloads.py).
SOURCES = ["_config.yml", "_toc.yml", "references.bib", "book", "_ext", "_static", "uio_teach"]
SOURCES += ["pyproject.toml", "setup.py", "MANIFEST.in", "README.md", "LICENSE", "LICENSE-BOOK.md"]
BIN = Path(sys.executable).parent


def copy_sources(dest: Path) -> Path:
    """Copy the book's sources into ``dest`` (created), without compiled files; return it."""
    dest.mkdir(parents=True)
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, dest / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(path, dest / name)
    return dest


def environment(**extra: str) -> dict[str, str]:
    """This environment with the interpreter's tools first on ``PATH``, and ``extra``."""
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    env.pop("UIO_TEACH_PDF", None)
    env.update(extra)
    return env


def book_commands(src: Path) -> list[list[str]]:
    """`make book` on ``src``: the chapters that changed run on every core, then the build."""
    return [
        [sys.executable, str(src / "_ext" / "run_chapters.py")],
        [str(BIN / "jupyter-book"), "build", str(src), "-W", "-n", "--keep-going"],
    ]


def run(command: list[str], env: dict[str, str]) -> tuple[float, str]:
    """Run ``command``; its wall-clock seconds and output. A failure ends the benchmark,
    naming the command and the end of its output."""
    start = time.perf_counter()
    proc = subprocess.run(command, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if proc.returncode:
        sys.exit(f"`{' '.join(command)}` failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return seconds, proc.stdout + proc.stderr
