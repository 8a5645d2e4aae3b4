"""The package's layout: algorithms below, explorers and instructor tooling above, small modules,
and every former import path still working."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "uio_teach"

# What sits above it: nothing of the algorithm layer may import these.
ABOVE = {
    "explorers",
    "instructor",
    "checks",
    "widgets",
    "explorer",
    "static_explorer",
    "figures",
    "labs",
    "cli",
    "__main__",
}
# The algorithm layer (with the worked examples and plotting): every other top-level module.
ALGORITHMS = sorted(
    [p.stem for p in PACKAGE.glob("*.py") if p.stem not in ABOVE and p.stem != "__init__"]
    + [p.parent.name for p in PACKAGE.glob("*/__init__.py") if p.parent.name not in ABOVE]
)


def _module_name(path: Path, root: Path = PACKAGE) -> str:
    parts = path.relative_to(root.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, root: Path = PACKAGE) -> set[str]:
    """Every module ``path`` imports (relative imports resolved), at any depth of the code."""
    name = _module_name(path, root)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            found.add(module)
            found.update(f"{module}.{alias.name}" for alias in node.names)
    return found


MODULES = sorted(PACKAGE.rglob("*.py"))


@pytest.mark.parametrize("name", ALGORITHMS)
def test_algorithms_import_nothing_above_them(name):
    paths = [PACKAGE / f"{name}.py"] if (PACKAGE / f"{name}.py").exists() else []
    paths += sorted((PACKAGE / name).glob("*.py")) if (PACKAGE / name).is_dir() else []
    above = sorted(
        m
        for path in paths
        for m in _imports(path)
        if m.startswith("uio_teach.") and m.split(".")[1] in ABOVE
    )
    assert not above, f"uio_teach.{name} imports {above}"


def test_the_layout_check_sees_a_forbidden_import(tmp_path):
    root = tmp_path / "uio_teach"
    (root / "explorers").mkdir(parents=True)
    (root / "fake.py").write_text("def f():\n    from .explorers import frames\n")
    (root / "explorers" / "deep.py").write_text("from ..instructor import cli\n")
    assert "uio_teach.explorers.frames" in _imports(root / "fake.py", root)
    assert "uio_teach.instructor.cli" in _imports(root / "explorers" / "deep.py", root)


@pytest.mark.parametrize("path", MODULES, ids=lambda p: _module_name(p))
def test_no_module_over_900_lines(path):
    lines = len(path.read_text(encoding="utf-8").splitlines())
    assert lines <= 900, f"{_module_name(path)} has {lines} lines"


def test_algorithm_layer_is_found():
    assert {"linalg", "observers", "simulation", "experiments", "luenberger"} <= set(ALGORITHMS)
    assert not {"figures", "widgets", "labs"} & set(ALGORITHMS)


def test_explorers_instructor_and_checks_use_public_names_of_linalg():
    above = [p for p in MODULES if p.parent != PACKAGE or p.stem in ABOVE | {"plotting"}]
    assert any("explorers" in str(p) for p in above)
    users = [
        _module_name(p)
        for p in above
        if any(m.endswith("linalg._sort") for m in _imports(p)) or "_sort(" in p.read_text()
    ]
    assert not users, f"use uio_teach.linalg.sort_poles in {users}"


# former import paths --------------------------------------------------------------------------

FORMER = {
    "uio_teach.widgets": ["Explorer", "pa9_explorer", "case_study_explorer", "missile_explorer"],
    "uio_teach.explorer": [
        "DISTURBANCES",
        "FAMILIES",
        "Channel",
        "Settings",
        "Scenario",
        "Frame",
        "ExplorerFigure",
        "pa9_scenario",
        "case_study_scenario",
        "missile_scenario",
        "make_scenario",
        "expand_poles",
        "format_poles",
        "disturbance_signals",
        "luenberger_poles",
        "compute_frame",
        "render",
    ],
    "uio_teach.static_explorer": ["StaticFrame", "StaticExplorer", "static_html"],
    "uio_teach.figures": [
        "FORMATS",
        "FIGURES",
        "FigureSpec",
        "FigureResult",
        "FigureConfig",
        "ConfigError",
        "OutputError",
        "load_config",
        "default_config_toml",
        "prepare_output_dir",
        "save_figure",
        "generate",
    ],
    "uio_teach.labs": ["VERSIONS", "BookIndex", "LabResult", "find_labs", "make_notebook"],
    "uio_teach.cli": ["main", "build_parser"],
}
NEW_HOME = {
    "uio_teach.widgets": "uio_teach.explorers.widgets",
    "uio_teach.explorer": "uio_teach.explorers",
    "uio_teach.static_explorer": "uio_teach.explorers.static",
    "uio_teach.figures": "uio_teach.instructor.figures",
    "uio_teach.labs": "uio_teach.instructor.labs",
    "uio_teach.cli": "uio_teach.instructor.cli",
}


@pytest.mark.parametrize("former", sorted(FORMER))
def test_former_modules_give_the_same_objects(former):
    old, new = importlib.import_module(former), importlib.import_module(NEW_HOME[former])
    for name in FORMER[former]:
        assert name in old.__all__, f"{former}.{name} is no longer listed"
        if name == "format_poles":
            continue  # the former explorer formatter: three digits of _display.format_poles
        if name == "luenberger_poles":
            algorithm = importlib.import_module("uio_teach.luenberger")
            assert old.luenberger_poles is algorithm.luenberger_poles
            continue
        assert getattr(old, name) is getattr(new, name), f"{former}.{name}"


def test_former_format_poles_is_the_one_formatter_with_three_digits():
    from uio_teach._display import format_poles
    from uio_teach.explorer import format_poles as former

    values = [8.9e-16, 0.123456, -1 + 2.34567j, -1 - 2.34567j]
    assert former(values) == format_poles(values, 3) == "0, 0.123, -1 + 2.35j, -1 - 2.35j"


def test_package_level_names_of_the_explorers_stay():
    import uio_teach as ut

    assert ut.pa9_explorer is ut.widgets.pa9_explorer
    assert ut.explorer.compute_frame is ut.explorers.compute_frame
    assert ut.static_explorer.static_html is ut.explorers.static.static_html


def test_python_dash_m_uio_teach_still_runs():
    proc = subprocess.run(
        [sys.executable, "-m", "uio_teach", "--help"], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    assert "figures" in proc.stdout and "labs" in proc.stdout
