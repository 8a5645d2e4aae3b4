"""The tests run on two workers as ``make test`` schedules them (``tests/conftest.py``).

A small suite is written into a temporary folder beside a copy of the course's ``conftest.py``
and run with pytest-xdist as the Makefile runs it: the tests that share a module-scoped fixture
must run on one worker (one set-up, not one per worker), the first test that needs the book
build must be the first sent, and the tests of the built book the last.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.subprocess

HERE = Path(__file__).resolve().parent

SUITE = {
    "test_shared.py": """
        import json, os, pytest

        @pytest.fixture(scope="module")
        def costly():
            with open(os.environ["SETUPS"], "a") as fh:
                fh.write(os.environ.get("PYTEST_XDIST_WORKER", "main") + "\\n")
            return 1

        @pytest.mark.parametrize("i", range(8))
        def test_uses_it(costly, i):
            pass
        """,
    "test_many.py": """
        import pytest

        @pytest.mark.parametrize("i", range(30))
        def test_alone(i):
            pass
        """,
    "test_pages.py": """
        import pytest

        @pytest.fixture(scope="session")
        def book_build():
            return 1

        def test_builds(book_build):
            pass

        @pytest.mark.parametrize("page", ["a", "b"])
        def test_reads(book_build, page):
            pass
        """,
}


def test_module_fixtures_are_set_up_once_and_the_book_goes_first(tmp_path):
    suite = tmp_path / "suite"
    suite.mkdir()
    shutil.copy(HERE / "conftest.py", suite / "conftest.py")
    for name, text in SUITE.items():
        (suite / name).write_text(textwrap.dedent(text), encoding="utf-8")
    setups = tmp_path / "setups.txt"
    env = {**os.environ, "SETUPS": str(setups)}
    command = [
        sys.executable,
        "-m",
        "pytest",
        "-n",
        "2",
        "--dist",
        "loadgroup",
        "--no-loadscope-reorder",
        "-p",
        "no:cacheprovider",
        "-q",
        str(suite),
    ]
    proc = subprocess.run(command, cwd=suite, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "41 passed" in proc.stdout, proc.stdout[-2000:]
    assert setups.read_text().split() in (["gw0"], ["gw1"])  # one set-up, on one worker
    order = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"],
        cwd=suite,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    ).stdout.split()
    tests = [t for t in order if "::" in t]
    assert tests[0] == "test_pages.py::test_builds"
    assert tests[-2:] == ["test_pages.py::test_reads[a]", "test_pages.py::test_reads[b]"]
