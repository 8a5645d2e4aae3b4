"""A student holding only the built book runs every chapter and lab.

The built book is served on 127.0.0.1. The package's wheel and every page's notebook are
downloaded from it over HTTP, as a browser saves them; the commands the introduction shows (read
from the built page) install the wheel into a new virtual environment; every notebook then runs
there from top to bottom, in a fresh folder, importing the package from the new environment; a
lab's notebook (its student version) runs with every check saying what is still missing.

Offline, the packages the wheel asks for (NumPy ... ipywidgets, JupyterLab) come from the test's
own environment, the one the lock installed: a folder of links to its installed distributions,
``uio_teach`` itself left out, is on the new environment's path. pip resolves the wheel's
requirements and its extra against them with ``--no-index``, so a requirement that the lock does
not install, or that the wheel does not declare, fails here as it would on a student's machine.
"""

from __future__ import annotations

import html
import json
import os
import re
import shlex
import subprocess
import sys
import sysconfig
import urllib.parse
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import nbformat
import pytest
from lab_outputs import assert_checks_say_what_is_missing
from venvs import new_venv

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "_ext"))

from pdf_print import site_pages  # noqa: E402

pytestmark = [
    pytest.mark.book,
    pytest.mark.wheel,
    pytest.mark.kernel,
    pytest.mark.subprocess,
    pytest.mark.slow,
]
NOTEBOOK_LIMIT = 900  # seconds for one notebook: a limit against a hung kernel, not a timing

# Runs in the new environment: one notebook, top to bottom, in its own folder, then says where
# the package it imported lives.
RUNNER = """
import json, sys
from pathlib import Path

import nbformat
from nbclient import NotebookClient

path = Path(sys.argv[1])
nb = nbformat.read(path, as_version=4)
nb.cells.append(nbformat.v4.new_code_cell(
    "import sys as _sys, uio_teach as _ut\\n"
    "print(_ut.__file__)\\n"
    "print(_sys.prefix)"
))
NotebookClient(nb, timeout=600, kernel_name="python3",
               resources={"metadata": {"path": str(path.parent)}}).execute()
nbformat.write(nb, path.with_suffix(".run.ipynb"))
last = "".join(o.get("text", "") for o in nb.cells[-1].outputs).split()
print(json.dumps({"package": last[0], "prefix": last[1]}))
"""


def _get(url: str) -> bytes:
    with urllib.request.urlopen(url, timeout=60) as response:  # the local server only
        return response.read()


def install_commands(page: str) -> tuple[str, list[str]]:
    """The wheel the introduction links, and the commands it shows under that link."""
    link = re.search(r'<a class="[^"]*package-wheel[^"]*" href="([^"]+)"', page)
    assert link, "the introduction links no wheel (class package-wheel)"
    after = page[link.end() :]
    block = re.search(r"<pre>(.*?)</pre>", after, re.S)
    assert block, "no commands under the wheel's link"
    text = html.unescape(re.sub(r"<[^>]+>", "", block[1]))
    return html.unescape(link[1]), [line.strip() for line in text.splitlines() if line.strip()]


def _overlay(folder: Path) -> Path:
    """Links to every installed distribution of this environment but ``uio_teach``."""
    folder.mkdir()
    site = Path(sysconfig.get_paths()["purelib"])
    for entry in site.iterdir():
        name = entry.name.lower()
        if name.startswith(("uio_teach", "uio-teach", "__editable__", "_uio_teach")):
            continue
        if entry.suffix == ".pth" or name == "__pycache__":
            continue
        (folder / entry.name).symlink_to(entry)
    return folder


@pytest.fixture(scope="module")
def student(built_book: Path, book_server: str, tmp_path_factory) -> dict:
    """The built book's wheel installed, as the introduction says, into a new environment."""
    base = tmp_path_factory.mktemp("student")
    work = base / "notebooks"
    work.mkdir()
    root = book_server + "/"
    pages = site_pages(built_book)
    intro = next(p for p in pages if p.name == "introduction")
    page_url = root + intro.path
    href, commands = install_commands(_get(page_url).decode("utf-8"))
    wheel_url = urllib.parse.urljoin(page_url, href)
    wheel = work / Path(urllib.parse.urlsplit(wheel_url).path).name
    wheel.write_bytes(_get(wheel_url))
    # the notebooks each page offers
    notebooks = []
    for page in pages:
        text = _get(root + page.path).decode("utf-8")
        for link in re.findall(r'href="([^"]+\.ipynb)"', text):
            url = urllib.parse.urljoin(root + page.path, html.unescape(link))
            target = work / Path(urllib.parse.urlsplit(url).path).name
            if target not in notebooks:
                target.write_bytes(_get(url))
                notebooks.append(target)
    env_dir = base / "env"
    python, purelib = new_venv(env_dir, pip=True)  # pip: the introduction's commands use it
    overlay = _overlay(base / "lock")
    Path(purelib, "uio_teach_test_lock.pth").write_text(f"{overlay}\n", encoding="utf-8")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["PATH"] = f"{env_dir / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env["MPLBACKEND"] = "Agg"
    env["PIP_NO_INDEX"] = "1"  # offline: only what is here
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    ran = []
    for command in commands:
        words = shlex.split(command, comments=True)
        if words[:2] == ["pip", "install"]:
            proc = subprocess.run(
                [python, "-m", *words],
                cwd=work,
                env=env,
                capture_output=True,
                text=True,
                timeout=600,
            )
            assert proc.returncode == 0, f"`{command}` failed:\n{proc.stdout}\n{proc.stderr}"
            ran.append(command)
    return {
        "python": python,
        "env": env,
        "env_dir": env_dir,
        "work": work,
        "wheel": wheel,
        "commands": commands,
        "ran": ran,
        "notebooks": notebooks,
    }


def test_the_introduction_installs_the_wheel_in_two_commands(student: dict) -> None:
    commands = student["commands"]
    assert len(commands) <= 3, commands
    (install,) = student["ran"]
    assert student["wheel"].name in install and "[explorers]" in install
    assert any(c.split()[:2] == ["jupyter", "lab"] for c in commands), commands
    assert student["wheel"].name.startswith("uio_teach-")
    # the wheel installed is the package of this checkout, with its lab chapters
    proc = subprocess.run(
        [student["python"], "-c", "import uio_teach, sys; print(uio_teach.__file__)"],
        cwd=student["work"],
        env=student["env"],
        capture_output=True,
        text=True,
        check=True,
    )
    package = Path(proc.stdout.strip())
    assert package.is_relative_to(student["env_dir"]), package
    assert (package.parent / "_course" / "book" / "lab_pa9.md").is_file()


def test_every_chapter_and_lab_notebook_runs_from_the_installed_wheel(student: dict) -> None:
    notebooks = student["notebooks"]
    names = {n.stem for n in notebooks}
    assert {"introduction", "pa9", "lab_pa9", "lab_case_study", "lab_missile"} <= names, names
    runner = student["work"].parent / "run_notebook.py"
    runner.write_text(RUNNER, encoding="utf-8")

    def run(notebook: Path) -> tuple[Path, subprocess.CompletedProcess]:
        proc = subprocess.run(
            [student["python"], runner, notebook],
            cwd=notebook.parent,
            env=student["env"],
            capture_output=True,
            text=True,
            timeout=NOTEBOOK_LIMIT,
        )
        return notebook, proc

    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        results = list(pool.map(run, notebooks))
    failed = {nb.name: proc.stderr[-3000:] for nb, proc in results if proc.returncode}
    assert not failed, "\n\n".join(f"{name}:\n{err}" for name, err in failed.items())
    for notebook, proc in results:
        where = json.loads(proc.stdout.strip().splitlines()[-1])
        assert Path(where["prefix"]) == student["env_dir"], (notebook.name, where)
        assert Path(where["package"]).is_relative_to(student["env_dir"]), (notebook.name, where)
    # a lab's notebook is its student version, as `uio-teach labs` writes it with the course's
    # numbers (test_labs.py runs the solution version): every check says what is still missing
    for notebook in notebooks:
        if notebook.stem.startswith("lab_"):
            ran = nbformat.read(notebook.with_suffix(".run.ipynb"), as_version=4)
            assert_checks_say_what_is_missing(ran)
