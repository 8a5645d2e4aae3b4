"""Shared set-up of the tests: the markers each test declares, and what holds them to it.

Figures are drawn off screen (matplotlib's Agg backend), once for every test module.

Each test module declares what its tests need in ``pytestmark`` (a single test that needs more
carries its own ``@pytest.mark...``):

``kernel``
    starts a Jupyter kernel (executes a notebook: the chapters, the lab notebooks, grading);
``book``
    builds or executes the book (the ``built_book`` fixture below, one build per run);
``browser``
    drives headless Chromium (through Playwright);
``wheel``
    builds the package's wheel and runs it outside the checkout;
``subprocess``
    starts any other process (the command line, a fresh interpreter, a Sphinx build);
``doctest``
    runs the examples in the package's docstrings;
``slow``
    takes long for another reason (exhaustive sweeps, every figure drawn, every lab written).

``make check`` runs the tests that need none of kernel, browser, book, wheel, subprocess or
slow; ``make test`` runs every test not marked ``slow``, ``make test-slow`` the ``slow`` ones
(CI runs both; ``make test-all`` runs them in one go).

A declaration is checked, not trusted: every process the test process starts is looked at while
a test (or its fixtures) runs, and a test that starts a kernel, a book build, a browser, a wheel
build or any process without the marker saying so fails at once, with the marker it lacks. A
test module that starts one at import time fails its collection.
"""

from __future__ import annotations

import fcntl
import json
import os
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import NamedTuple

import matplotlib
import pytest

matplotlib.use("Agg")

# jsonschema (under nbformat) builds the grammars of an optional IRI-syntax checker when it is
# imported: seconds of collection for a format no notebook schema uses. The test process does
# without it (jsonschema skips that format check when the module cannot be imported).
sys.modules.setdefault("rfc3987_syntax", None)  # type: ignore[arg-type]

ROOT = Path(__file__).resolve().parents[1]
HTML = ROOT / "_build" / "html"
# A clean build executes every chapter; this is a limit against a hung kernel, not a timing.
BOOK_BUILD_LIMIT = 1800  # seconds

# The book's own extensions (_ext/): the printer serves the site and starts Chromium as the
# tests do, and the book's download builds the wheel the tests install. They and the tests'
# helpers (browsers, venvs) are imported by the fixtures that use them, so that this file
# also runs on its own (tests/test_scheduling.py runs a copy of it).
sys.path.insert(0, str(ROOT / "_ext"))


# --- what a process needs ----------------------------------------------------------------------


def needs_of(argv: str | bytes | Sequence[object]) -> set[str]:
    """The markers a test needs to start the process ``argv``.

    Every process needs ``subprocess``; a Jupyter kernel (started directly, or by the grader)
    ``kernel``; jupyter-book or Sphinx ``book``; Chromium or Playwright's driver ``browser``; a
    wheel build ``wheel``.
    """
    if isinstance(argv, str | bytes | os.PathLike):  # a shell command line, or one program
        try:
            argv = shlex.split(os.fsdecode(argv))
        except ValueError:
            argv = [argv]
    words = [os.fsdecode(a) if isinstance(a, bytes | os.PathLike) else str(a) for a in argv]
    names = {Path(w).name for w in words}
    text = " ".join(words)
    if is_probe(words):
        return set()
    needs = {"subprocess"}
    if (
        any("ipykernel" in w for w in words)
        or _module_command(words, "uio_teach", "grade")
        or _runs_module(words, "uio_teach.grading.runner")  # the grader's notebook runner
    ):
        needs.add("kernel")
    if (
        names & {"jupyter-book", "sphinx-build", "run_chapters.py"}  # the book's chapters, run
        or _runs_module(words, "jupyter_book", "sphinx")
    ):
        needs.add("book")
    if "chromium" in text or "playwright" in text:
        needs.add("browser")
    if (names & {"pip", "pip3"} or _runs_module(words, "pip", "build")) and "wheel" in words:
        needs.add("wheel")
    return needs


def is_probe(words: list[str]) -> bool:
    """A library's one-off look at the machine, cached for the process: ``tool --version``
    (jupytext asks pandoc), ``bwrap --help`` (which options this bubblewrap has), the sandbox's
    ``bwrap ... /bin/true``. Whichever test happens to come first would start it, so it needs
    no marker."""
    if len(words) == 2 and words[1] in ("--version", "--help"):
        return True
    return bool(words) and Path(words[0]).name == "bwrap" and words[-1] == "/bin/true"


def _runs_module(words: list[str], *modules: str) -> bool:
    """Whether ``words`` runs ``python -m <one of modules>``."""
    return any(a == "-m" and b in modules for a, b in zip(words, words[1:], strict=False))


def _module_command(words: list[str], module: str, command: str) -> bool:
    """Whether ``words`` runs ``python -m module command``."""
    return any(
        a == "-m" and b == module and c == command
        for a, b, c in zip(words, words[1:], words[2:], strict=False)
    )


# --- holding each test to its markers ----------------------------------------------------------

HEAVY = {"kernel", "book", "browser", "wheel"}
_running: list[pytest.Item] = []  # the test whose setup, call or teardown is running
_violations: pytest.StashKey[list[str]] = pytest.StashKey()


def check_launch(argv: object, item: pytest.Item | None) -> None:
    """Fail when ``item`` (``None``: no test, i.e. collection) may not start ``argv``."""
    needs = needs_of(argv)  # type: ignore[arg-type]
    if item is None:
        # At collection: a probe of the machine is allowed, the heavy resources are not.
        lacking = needs - {"subprocess"}
        if lacking:
            raise RuntimeError(
                f"a test module starts {_describe(argv)} at import time (needs "
                f"{', '.join(sorted(lacking))}); start it inside a marked test or fixture"
            )
        return
    declared = {mark.name for mark in item.iter_markers()}
    if declared & HEAVY:
        declared.add("subprocess")  # a kernel, a book build, a browser are processes
    lacking = needs - declared
    if lacking:
        message = (
            f"{item.nodeid} starts {_describe(argv)} without the marker(s) "
            f"{', '.join(f'@pytest.mark.{m}' for m in sorted(lacking))}: declare them in the test "
            "module's pytestmark or on the test (tests/conftest.py lists the markers)"
        )
        item.stash.setdefault(_violations, []).append(message)
        pytest.fail(message, pytrace=False)


def _describe(argv: object) -> str:
    words = [argv] if isinstance(argv, str | bytes) else list(argv)  # type: ignore[call-overload]
    text = " ".join(os.fsdecode(w) if isinstance(w, bytes) else str(w) for w in words)
    return f"`{text[:160]}`"


_execute_child = subprocess.Popen._execute_child  # type: ignore[attr-defined]


def _guarded_execute_child(self, args, *rest, **kwargs):  # noqa: ANN001, ANN202
    check_launch(args, _running[-1] if _running else None)
    return _execute_child(self, args, *rest, **kwargs)


def pytest_configure(config: pytest.Config) -> None:
    # Every process the test process starts goes through Popen._execute_child: subprocess.run,
    # jupyter_client's kernel launch, asyncio's subprocesses (Playwright's driver).
    subprocess.Popen._execute_child = _guarded_execute_child  # type: ignore[attr-defined]


def pytest_unconfigure(config: pytest.Config) -> None:
    subprocess.Popen._execute_child = _execute_child  # type: ignore[attr-defined]


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    _running.append(item)
    try:
        return (yield)
    finally:
        _running.pop()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo) -> Iterator:
    # A launch refused inside code that swallows exceptions (a thread, a retry loop) still fails
    # the test.
    report = yield
    violations = item.stash.get(_violations, [])
    if violations and report.when == "call" and report.passed:
        report.outcome = "failed"
        report.longrepr = "\n".join(violations)
    return report


# --- tests on two cores --------------------------------------------------------------------------


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist reads the groups
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Order the tests for ``pytest -n`` (pytest-xdist, ``--dist loadgroup
    --no-loadscope-reorder``, as ``make test`` runs them), and keep together those that share a
    costly fixture.

    The tests of a module that share a module-scoped fixture (the graded class, the written
    labs) are one group, run by one worker, and so are the checks of one page of the built book
    (one worker opens the page once per width). The first test that needs the book build comes
    first, so that one worker builds the book (``book_build``: one build for all workers) while
    the others run the groups and then the rest; the tests that read the built book come last,
    when the build is done, those of a module's costly fixture (its group) first. Without
    ``-n`` the order is the same and the marks change nothing.
    """
    first_book = next((i for i in items if "book_build" in getattr(i, "fixturenames", ())), None)

    def rank(item: pytest.Item) -> int:
        if item is first_book:
            return 0
        if "book_build" in getattr(item, "fixturenames", ()):
            # the longest of them first (a module's costly fixture: the wheel installed from
            # the book and every notebook run, the printed PDFs), the short page checks after
            return 3 if _shares_module_fixture(item) else 4
        return 1 if _shares_module_fixture(item) else 2

    for item in items:
        if _shares_module_fixture(item):
            item.add_marker(pytest.mark.xdist_group(item.module.__name__))  # type: ignore[attr-defined]
        elif "book_server" in getattr(item, "fixturenames", ()) and "page" in _params(item):
            # the checks of one built page: one worker, which opens the page once per width
            item.add_marker(pytest.mark.xdist_group(f"page {_params(item)['page']}"))
    items.sort(key=rank)  # stable: the collection's order within each rank
    workerinput = getattr(config, "workerinput", None)
    if workerinput is not None and "uio_teach_groups" in workerinput:
        # for the scheduler of the main process (below), which sees only the tests' ids
        groups = {}
        for item in items:
            marks = [
                m.args[0] if m.args else m.kwargs.get("name", "default")
                for m in item.iter_markers("xdist_group")
            ]
            if marks:
                groups[item.nodeid] = "_".join(sorted(map(str, marks)))
        path = Path(workerinput["uio_teach_groups"])
        part = path.with_name(f"{path.name}.{workerinput['workerid']}")
        part.write_text(json.dumps(groups), encoding="utf-8")
        part.replace(path)  # whole or not at all: every worker writes the same


# pytest-xdist's own ``loadgroup`` marks the groups by changing each test's id in a way
# pytest 9 no longer supports (the groups are silently ignored): the course's scheduler below
# reads the groups the workers wrote instead, through xdist's documented hooks.


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node) -> None:  # noqa: ANN001 (xdist's WorkerController)
    if node.config.getoption("dist") == "loadgroup":
        node.workerinput["uio_teach_groups"] = str(_groups_file())


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log):  # noqa: ANN001, ANN201
    if config.getoption("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class GroupScheduling(LoadScopeScheduling):
        """``loadgroup``: the tests of a group go to one worker, every other test on its own."""

        groups: dict[str, str] | None = None

        def _split_scope(self, nodeid: str) -> str:
            if self.groups is None:
                path = _groups_file()
                try:
                    self.groups = json.loads(path.read_text(encoding="utf-8"))
                except (OSError, ValueError) as exc:  # no worker wrote it: no groups
                    self.log(f"no test groups ({exc}): every test on its own")
                    self.groups = {}
                path.unlink(missing_ok=True)
            return self.groups.get(nodeid, nodeid)

    return GroupScheduling(config, log)


def _groups_file() -> Path:
    """Where the workers write the groups for the main process (named after its id)."""
    return Path(tempfile.gettempdir()) / f"uio-teach-xdist-groups-{os.getpid()}.json"


def _params(item: pytest.Item) -> dict:
    callspec = getattr(item, "callspec", None)
    return callspec.params if callspec is not None else {}


def _shares_module_fixture(item: pytest.Item) -> bool:
    info = getattr(item, "_fixtureinfo", None)
    if info is None or getattr(item, "module", None) is None:
        return False
    return any(
        d.scope in ("module", "package") for defs in info.name2fixturedefs.values() for d in defs
    )


# --- the book, built once per run ---------------------------------------------------------------


def jupyter_book() -> str:
    local = Path(sys.executable).parent / "jupyter-book"
    return str(local) if local.exists() else "jupyter-book"


class BookBuild(NamedTuple):
    """The one build of the book in a test run: its command, exit status and the log's tail."""

    command: list[str]
    returncode: int
    log: str


def run_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The test run's temporary folder, shared by every pytest-xdist worker."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def once_per_run(tmp_path_factory: pytest.TempPathFactory, name: str, make: Callable[[Path], dict]):
    """``make(folder)`` once per test run, its result (JSON) shared by every worker.

    With ``pytest -n`` the first worker to need it makes it in ``folder`` (in the run's shared
    temporary folder) and writes down the result; the others wait for it (a lock in that
    folder) and read it. A ``make`` that raises writes nothing: the next one to ask tries again.
    """
    shared = run_folder(tmp_path_factory)
    record = shared / f"{name}.json"
    with open(shared / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file is closed
        if record.is_file():
            return json.loads(record.read_text(encoding="utf-8"))
        result = make(shared / name)
        record.write_text(json.dumps(result), encoding="utf-8")
        return result


@pytest.fixture(scope="session")
def book_build(tmp_path_factory: pytest.TempPathFactory) -> BookBuild:
    """Build the book once per test run, as ``make book`` does, every chapter executed afresh.

    The execution cache is emptied and every page re-read (``--all``) first, so each chapter runs
    against the package as it is now, not as it was when the cache was filled: this build is
    what proves the chapters run (``test_chapters.py``), not a second execution of each.

    With ``pytest -n`` the first worker to need it builds the book; the others wait for it and
    read its result (:func:`once_per_run`).
    """
    made = once_per_run(tmp_path_factory, "book_build", lambda _: _build_book()._asdict())
    return BookBuild(**made)


def _build_book() -> BookBuild:
    shutil.rmtree(ROOT / "_build" / ".jupyter_cache", ignore_errors=True)
    shutil.rmtree(HTML / "reports", ignore_errors=True)
    # as `make book`: the chapters run on every core first, then the build reads them
    run = [sys.executable, str(ROOT / "_ext" / "run_chapters.py")]
    first = subprocess.run(run, cwd=ROOT, capture_output=True, text=True, timeout=BOOK_BUILD_LIMIT)
    command = [jupyter_book(), "build", ".", "--all", "-W", "-n", "--keep-going"]
    proc = subprocess.run(
        command, cwd=ROOT, capture_output=True, text=True, timeout=BOOK_BUILD_LIMIT
    )
    # a chapter that failed (or did not run) there is run again by the build, which reports it
    (ROOT / "_build" / "run_chapters.log").write_text(
        f"exit status {first.returncode}\n{first.stdout}\n{first.stderr}", encoding="utf-8"
    )
    log = (first.stdout + first.stderr)[-2000:] + (proc.stdout + proc.stderr)[-6000:]
    return BookBuild(command, proc.returncode, log)


@pytest.fixture(scope="session")
def built_book(book_build: BookBuild) -> Path:
    """The HTML folder of the one build; fails the test when the build failed.

    Shared by every test that reads the built pages (tests marked ``book``).
    """
    if book_build.returncode != 0:
        pytest.fail(
            f"`{' '.join(book_build.command)}` exited with {book_build.returncode}; tracebacks "
            f"of failed chapters are in {HTML / 'reports'}.\n{book_build.log}",
            pytrace=False,
        )
    return HTML


# --- the built book served, and one browser for every page test -----------------------------


@pytest.fixture(scope="session")
def book_server(built_book: Path) -> Iterator[str]:
    """Serve the built book on 127.0.0.1 at a free port, as the printer does; yield its base
    URL (without the last ``/``)."""
    from pdf_print import serve

    with serve(built_book) as url:
        yield url.rstrip("/")


@pytest.fixture(scope="session")
def browser() -> Iterator[object]:
    from browsers import launch, require_chromium

    require_chromium()
    from playwright.sync_api import sync_playwright

    # Playwright gives the browser a fresh temporary profile of its own.
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            yield browser
        finally:
            browser.close()


# --- the package's wheel, built once per run and installed in a virtual environment --------------


class WheelEnv(NamedTuple):
    """The package's wheel, as the book's build makes it, installed in a new virtual environment.

    ``python`` imports ``uio_teach`` from the wheel in ``site`` (the environment's
    site-packages, whose ``bin`` holds the wheel's command ``uio-teach``) and every other package
    from the test's own environment, after it; ``env`` runs it with no ``PYTHONPATH`` (so not
    from the checkout) and matplotlib off screen.
    """

    wheel: Path
    venv: Path
    python: Path
    site: Path
    env: dict[str, str]


@pytest.fixture(scope="session")
def wheel_env(tmp_path_factory: pytest.TempPathFactory) -> WheelEnv:
    """The one wheel of a test run (tests marked ``wheel``), built from a copy of the sources by
    the book's own ``_ext/downloads.py``, installed in one virtual environment for every test."""

    def make(folder: Path) -> dict:
        from downloads import build_wheel  # the book's: imports Sphinx
        from venvs import new_venv

        wheel = build_wheel(ROOT, folder / "dist", folder / "stamps")
        venv = folder / "venv"
        python, site = new_venv(venv, pip=False)
        pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q", "install"]
        subprocess.run([*pip, "--no-deps", "--no-index", "--target", site, wheel], check=True)
        # the course's dependencies from this environment, after the wheel
        Path(site, "zz_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
        return {"wheel": str(wheel), "venv": str(venv), "python": str(python), "site": str(site)}

    made = {k: Path(v) for k, v in once_per_run(tmp_path_factory, "wheel", make).items()}
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["MPLBACKEND"] = "Agg"
    return WheelEnv(**made, env=env)
