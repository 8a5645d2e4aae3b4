"""Packaging: every run-time import is declared and pinned, and the wheel works outside the
checkout (figures, lab notebooks and the live explorer from any folder)."""

from __future__ import annotations

import ast
import importlib
import importlib.metadata
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def _name(requirement: str) -> str:
    """The normalised distribution name of a requirement string (PEP 503)."""
    bare = re.match(r"^\s*([A-Za-z0-9][A-Za-z0-9._-]*)", requirement).group(1)
    return re.sub(r"[-_.]+", "-", bare).lower()


def _declared() -> dict[str, set[str]]:
    project = PYPROJECT["project"]
    out = {"": {_name(r) for r in project["dependencies"]}}
    for extra, reqs in project.get("optional-dependencies", {}).items():
        out[extra] = {_name(r) for r in reqs}
    return out


def _third_party_imports() -> dict[str, set[str]]:
    """Top-level third-party module -> the package modules that import it."""
    found: dict[str, set[str]] = {}
    for path in sorted((ROOT / "uio_teach").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split(".")[0]
                if top in sys.stdlib_module_names or top in ("uio_teach", "__future__"):
                    continue
                found.setdefault(top, set()).add(path.relative_to(ROOT).as_posix())
    return found


def test_every_run_time_import_is_declared_in_pyproject():
    declared = _declared()
    everything = set().union(*declared.values())
    distributions = importlib.metadata.packages_distributions()
    imports = _third_party_imports()
    assert {"numpy", "control", "matplotlib", "ipywidgets", "jupytext"} <= set(imports)
    missing = {}
    for module, users in imports.items():
        dists = {_name(d) for d in distributions.get(module, [module])}
        if not dists & everything:
            missing[module] = sorted(users)
    assert not missing, f"imported but not declared in pyproject.toml: {missing}"


def test_the_plain_install_is_the_algorithms_and_the_rest_are_extras():
    declared = _declared()
    assert declared[""] == {"numpy", "scipy", "control", "cvxpy", "matplotlib"}
    assert {"ipywidgets", "ipympl"} <= declared["explorers"]
    assert not declared["explorers"] & declared[""]


def test_without_the_explorers_extra_the_live_explorers_say_so_in_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "ipywidgets", None)  # as if it were not installed
    monkeypatch.delitem(sys.modules, "uio_teach.explorers.widgets", raising=False)
    with pytest.raises(ImportError) as err:
        importlib.import_module("uio_teach.explorers.widgets")
    message = str(err.value)
    assert "\n" not in message and "pip install 'uio-teach[explorers]'" in message
    assert message.startswith("the live explorers need ipywidgets")
    assert err.value.__cause__ is None and err.value.__suppress_context__


def test_the_instructor_extra_holds_what_only_the_labs_need():
    declared = _declared()
    assert {"jupytext", "mdit-py-plugins", "nbformat", "pyyaml", "pybtex"} <= declared["instructor"]
    assert not declared["instructor"] & declared[""]


def _pins(path: Path) -> dict[str, str]:
    """Name -> version of every ``name==version`` line (hashes and comments skipped)."""
    pins = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        line = line.split("#")[0].strip().rstrip("\\").strip()
        if line and not line.startswith("--"):
            name, sep, version = line.partition("==")
            assert sep, f"{path.name}: {line!r} is not pinned to one version"
            pins[_name(name)] = version.split(";")[0].strip()
    return pins


def test_requirements_pin_every_declared_dependency():
    pins = _pins(ROOT / "requirements.in")
    for name in set().union(*_declared().values()):
        assert pins.get(name), f"{name} is declared in pyproject.toml but not pinned"


def test_the_lock_holds_every_pin_at_its_version_with_hashes():
    """requirements.txt is requirements.in resolved: the same versions, and every package hashed."""
    direct, lock = _pins(ROOT / "requirements.in"), _pins(ROOT / "requirements.txt")
    assert {name: lock.get(name) for name in direct} == direct
    assert len(lock) > len(direct)  # the indirect dependencies too
    lines = (ROOT / "requirements.txt").read_text(encoding="utf-8").splitlines()
    pinned = [i for i, line in enumerate(lines) if "==" in line and not line.startswith("#")]
    assert len(pinned) == len(lock)
    unhashed = [lines[i] for i in pinned if not lines[i + 1].startswith("    --hash=sha256:")]
    assert not unhashed, f"pinned without a hash: {unhashed}"
    assert "#    make lock" in lines[:6], "the lock names the command that refreshes it"


# the wheel, installed away from the checkout ---------------------------------------------------


@pytest.fixture(scope="module")
def installed(wheel_env, tmp_path_factory):
    """The run's wheel (``wheel_env``: built as the book builds it, installed in a virtual
    environment), run from a fresh folder: only the wheel's files and the environment's
    dependencies are importable, not the checkout."""
    work = tmp_path_factory.mktemp("elsewhere")
    return wheel_env.site, work, wheel_env


def _run(args, installed, **kwargs):
    _, work, wheel_env = installed
    proc = subprocess.run(
        [wheel_env.python, *args],
        cwd=work,
        env=wheel_env.env,
        capture_output=True,
        text=True,
        timeout=600,
        **kwargs,
    )
    assert proc.returncode == 0, proc.stderr
    return proc


@pytest.mark.slow
@pytest.mark.wheel
def test_the_wheel_is_the_package_imported(installed):
    target = installed[0]
    proc = _run(["-c", "import uio_teach; print(uio_teach.__file__)"], installed)
    assert Path(proc.stdout.strip()).is_relative_to(target)
    assert (target / "uio_teach" / "_course" / "book" / "lab_pa9.md").is_file()
    assert (target / "uio_teach" / "_course" / "references.bib").is_file()


@pytest.mark.slow
@pytest.mark.wheel
def test_the_wheel_lists_the_figures_from_any_folder(installed):
    target = installed[0]
    script = target / "bin" / "uio-teach"
    proc = _run([script, "figures", "--list"], installed)
    assert proc.stdout.split()[0] == "pa9_sine"


@pytest.mark.slow
@pytest.mark.wheel
def test_the_wheel_writes_the_lab_notebooks_from_any_folder(installed):
    from uio_teach.instructor.book import BookIndex

    chapter = BookIndex.from_book(ROOT / "book").chapters["lab_pa9"]
    target, work, _ = installed
    _run([target / "bin" / "uio-teach", "labs", "--out", "labs", "-q"], installed)
    for version in ("student", "solution"):
        notebooks = sorted((work / "labs" / version).glob("*.ipynb"))
        assert [p.name for p in notebooks] == [
            "lab_case_study.ipynb",
            "lab_missile.ipynb",
            "lab_pa9.ipynb",
        ]
        assert f"Exercise {chapter}.1" in notebooks[-1].read_text(encoding="utf-8")


@pytest.mark.slow
@pytest.mark.wheel
def test_the_wheel_shows_the_pa9_explorer(installed):
    code = (
        "import uio_teach as ut; from uio_teach.explorers.widgets import pa9_explorer; "
        "ex = pa9_explorer(); "
        "assert ex.frame is not None and 'text/html' in ex._repr_mimebundle_(); "
        "print(ut.__file__)"
    )
    proc = _run(["-c", code], installed)
    assert Path(proc.stdout.strip()).is_relative_to(installed[0])


@pytest.mark.slow
@pytest.mark.wheel
def test_the_wheel_carries_both_licences(installed):
    target = installed[0]
    (info,) = target.glob("uio_teach-*.dist-info")
    metadata = (info / "METADATA").read_text(encoding="utf-8")
    assert "License-Expression: BSD-3-Clause AND CC-BY-4.0" in metadata
    assert {p.name for p in (info / "licenses").iterdir()} == {"LICENSE", "LICENSE-BOOK.md"}


# licences ---------------------------------------------------------------------------------------


def test_the_code_and_the_book_have_their_licences():
    project = PYPROJECT["project"]
    assert project["license"] == "BSD-3-Clause AND CC-BY-4.0"
    for name in project["license-files"]:
        assert (ROOT / name).is_file(), name
    assert (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("BSD 3-Clause License")
    book = (ROOT / "LICENSE-BOOK.md").read_text(encoding="utf-8")
    assert "Creative Commons Attribution 4.0 International" in book
    assert "https://creativecommons.org/licenses/by/4.0/" in book


def test_every_page_of_the_book_names_its_licence():
    config = yaml.safe_load((ROOT / "_config.yml").read_text(encoding="utf-8"))
    footer = config["html"]["extra_footer"]
    assert "https://creativecommons.org/licenses/by/4.0/" in footer
    assert "BSD 3-Clause" in footer
