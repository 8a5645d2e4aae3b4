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
import sys
import tempfile
from pathlib import Path

from book_copy import book_commands, copy_sources, environment, run

PRINTED = re.compile(r"printed (\d+) PDF\(s\), (\d+) pages, into .* in ([\d.]+) s")


def main() -> None:
    env = environment()
    with tempfile.TemporaryDirectory() as tmp:
        src = copy_sources(Path(tmp) / "book-src")
        commands = book_commands(src)
        for command in commands:  # make book
            run(command, env)
        total, log = run(commands[-1], environment(UIO_TEACH_PDF="1"))  # make pdf, after make book
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
