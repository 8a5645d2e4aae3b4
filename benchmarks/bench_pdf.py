"""Time ``make pdf``: every page of the book and the whole book printed as tagged PDFs.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_pdf.py

On a fresh copy of the sources in a temporary folder (the repository's own ``_build`` is not
touched) the book is built as ``make book`` builds it (not timed), then ``make pdf``'s build is
timed: the pages rewritten with their PDF links, every page and the whole book printed by
``_ext/pdf_print.py`` on every core. The reference, in the same run: the same site printed again
one PDF at a time (``--jobs 1``), which is what the parallel printing saves. Pages per second
count printed sheets (A4) over the time of the printing alone.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COPY = ["_config.yml", "_toc.yml", "references.bib", "book", "_ext", "_static", "uio_teach"]
COPY += ["pyproject.toml", "setup.py", "MANIFEST.in", "README.md", "LICENSE", "LICENSE-BOOK.md"]
PRINTED = re.compile(r"printed (\d+) PDF\(s\), (\d+) pages, into .* in ([\d.]+) s")


def run(command: list[str], env: dict[str, str]) -> tuple[float, str]:
    start = time.perf_counter()
    proc = subprocess.run(command, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if proc.returncode:
        sys.exit(f"`{' '.join(command)}` failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return seconds, proc.stdout + proc.stderr


def main() -> None:
    bindir = Path(sys.executable).parent
    env = dict(os.environ, PATH=f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}")
    env.pop("UIO_TEACH_PDF", None)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "book-src"
        src.mkdir()
        for name in COPY:
            path = ROOT / name
            if path.is_dir():
                shutil.copytree(path, src / name, ignore=shutil.ignore_patterns("__pycache__"))
            else:
                shutil.copy2(path, src / name)
        book = [str(bindir / "jupyter-book"), "build", str(src), "-W", "-n", "--keep-going"]
        run([sys.executable, str(src / "_ext" / "run_chapters.py")], env)
        run(book, env)  # make book
        total, log = run(book, {**env, "UIO_TEACH_PDF": "1"})  # make pdf, after make book
        found = PRINTED.search(log)
        if not found:
            sys.exit(f"no 'printed N PDF(s)' line in the build's output:\n{log[-3000:]}")
        pdfs, sheets, printing = int(found[1]), int(found[2]), float(found[3])
        site, out = src / "_build" / "html", Path(tmp) / "one-at-a-time"
        printer = [sys.executable, str(src / "_ext" / "pdf_print.py"), str(site), str(out)]
        _, log = run([*printer, "--jobs", "1"], env)
        one = PRINTED.search(log)
        if not one:
            sys.exit(f"no 'printed N PDF(s)' line from the printer:\n{log[-3000:]}")
    print(f"cores: {os.cpu_count()}")
    print(f"make pdf after make book: {total:.1f} s (printing {printing:.1f} s)")
    print(f"printed: {pdfs} PDFs, {sheets} pages, {sheets / printing:.2f} pages/s")
    print(f"one PDF at a time (--jobs 1): {float(one[3]):.1f} s")


if __name__ == "__main__":
    main()
