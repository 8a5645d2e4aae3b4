"""New virtual environments for the tests that install the package's wheel (marked ``wheel``)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

VENV_LIMIT = 300  # seconds: a limit against a hung pip, not a timing


def new_venv(folder: Path, *, pip: bool) -> tuple[Path, Path]:
    """A new virtual environment of this interpreter in ``folder`` (with pip, or without):
    its interpreter and its site-packages folder."""
    command = [sys.executable, "-m", "venv", *([] if pip else ["--without-pip"]), folder]
    subprocess.run(command, check=True, timeout=VENV_LIMIT)
    python = folder / "bin" / "python"
    site = subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    return python, Path(site)
