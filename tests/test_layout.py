"""The package's layout: algorithms below, explorers and instructor tooling above; each module
uses only the public names of the others and imports at its top; no test reads the clock to
decide whether it passed."""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "uio_teach"
TESTS = ROOT / "tests"

# What sits above it: nothing of the algorithm layer may import these.
ABOVE = {"explorers", "instructor", "grading", "checks", "__main__"}
# The algorithm layer (with the worked examples and plotting): every other top-level module.
ALGORITHMS = sorted(
    [p.stem for p in PACKAGE.glob("*.py") if p.stem not in ABOVE and p.stem != "__init__"]
    + [p.parent.name for p in PACKAGE.glob("*/__init__.py") if p.parent.name not in ABOVE]
)
MODULES = sorted(PACKAGE.rglob("*.py"))


def _module_name(path: Path, root: Path = PACKAGE) -> str:
    parts = path.relative_to(root.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _resolve(node: ast.ImportFrom, path: Path, root: Path) -> str:
    """The absolute module name of ``from ... import`` in ``path`` (relative imports resolved)."""
    if not node.level:
        return node.module or ""
    name = _module_name(path, root)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    base = package.split(".")
    base = base[: len(base) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(path: Path, root: Path = PACKAGE) -> set[str]:
    """Every module ``path`` imports (relative imports resolved), at any depth of the code."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            module = _resolve(node, path, root)
            found.add(module)
            found.update(f"{module}.{alias.name}" for alias in node.names)
    return found


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _ids(path: Path) -> str:
    return _module_name(path)


# layers -----------------------------------------------------------------------------------------


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


def room_crossings(root: Path = PACKAGE) -> list[str]:
    """Imports that tie the grader and the term's tooling together outside the command line.

    ``grading/`` may import nothing of ``instructor/``; of ``instructor/``, only ``cli.py`` may
    import ``grading/``. What the two share (the folder lock, the manifest, the hashes, where the
    book is) lives below both, in ``uio_teach.folders``.
    """
    top = root.name
    found = []
    for room, other, allowed in (
        ("grading", "instructor", ()),
        ("instructor", "grading", ("cli",)),
    ):
        for path in sorted((root / room).rglob("*.py")):
            if path.stem in allowed:
                continue
            crossing = sorted(
                m
                for m in _imports(path, root)
                if m == f"{top}.{other}" or m.startswith(f"{top}.{other}.")
            )
            if crossing:
                found.append(f"{room}/{path.relative_to(root / room)} imports {crossing}")
    return found


def test_the_grader_is_a_room_of_its_own():
    """Only the command line ties the term's tooling to the grader; what both need comes from a
    module below them (and the grader's engine starts none of the figures, the labs' parameters or
    the variants before the first hand-in)."""
    found = room_crossings()
    assert not found, (
        "the grader and the term's tooling import each other (move what they share down into "
        f"uio_teach.folders): {found}"
    )
    tied = sorted(
        path.name
        for path in (PACKAGE / "instructor").glob("*.py")
        if any(m.startswith("uio_teach.grading") for m in _imports(path))
    )
    assert tied == ["cli.py"]
    shared = {"uio_teach.folders"}
    for room in ("grading", "instructor"):
        assert any(shared & _imports(p) for p in (PACKAGE / room).glob("*.py")), room
    assert not (PACKAGE / "checks" / "grading.py").exists()


def test_the_room_check_sees_a_crossing_at_any_depth(tmp_path):
    root = tmp_path / "uio_teach"
    for room in ("grading", "instructor"):
        (root / room).mkdir(parents=True)
    (root / "grading" / "grade.py").write_text(
        "from ..folders import MANIFEST\n\ndef f():\n    from ..instructor.book import x\n"
    )
    (root / "grading" / "merge.py").write_text("import uio_teach.instructor\n")
    (root / "instructor" / "cli.py").write_text("from ..grading import grade\n")
    (root / "instructor" / "labs.py").write_text("from uio_teach.grading.rosters import read\n")
    assert room_crossings(root) == [
        "grading/grade.py imports ['uio_teach.instructor.book', 'uio_teach.instructor.book.x']",
        "grading/merge.py imports ['uio_teach.instructor']",
        "instructor/labs.py imports ['uio_teach.grading.rosters', "
        "'uio_teach.grading.rosters.read']",
    ]


def test_algorithm_layer_is_found():
    assert {"linalg", "observers", "simulation", "experiments", "luenberger"} <= set(ALGORITHMS)
    assert not {"explorers", "instructor", "checks"} & set(ALGORITHMS)


def test_each_thing_has_one_name():
    """The former module names are gone: one import path for each module."""
    gone = {"widgets", "explorer", "static_explorer", "figures", "labs", "cli"}
    assert not {p.stem for p in PACKAGE.glob("*.py")} & gone


# private names stay in their module -------------------------------------------------------------


def private_imports(path: Path, root: Path = PACKAGE) -> list[str]:
    """Where ``path`` uses a private name (``_name``) of another module of the package.

    Both ``from .module import _name`` and ``module._name`` (``module`` bound by an import of a
    package module) count; a private module's public names (``from ._display import
    format_poles``) do not.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"))
    top = root.name
    found, modules = [], set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            module = _resolve(node, path, root)
            if module.split(".")[0] != top:
                continue
            for alias in node.names:
                dotted = f"{module}.{alias.name}"
                if _is_module(root, dotted):
                    modules.add(alias.asname or alias.name)
                elif _private(alias.name):
                    found.append(f"line {node.lineno}: from {module} import {alias.name}")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == top:
                    modules.add(alias.asname or alias.name.split(".")[0])
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and _private(node.attr):
            base = node.value
            if isinstance(base, ast.Name) and base.id in modules:
                found.append(f"line {node.lineno}: {base.id}.{node.attr}")
    return found


def _is_module(root: Path, dotted: str) -> bool:
    """Whether ``dotted`` (``uio_teach.x._y``) names a module or package of the tree at ``root``."""
    relative = Path(*dotted.split(".")[1:])
    return (root / relative).with_suffix(".py").exists() or (
        root / relative / "__init__.py"
    ).exists()


@pytest.mark.parametrize("path", MODULES, ids=_ids)
def test_no_module_uses_a_private_name_of_another(path):
    found = private_imports(path)
    assert not found, f"{_module_name(path)} uses private names of other modules: {found}"


def test_the_private_name_check_sees_both_forms(tmp_path):
    root = tmp_path / "uio_teach"
    (root / "sub").mkdir(parents=True)
    (root / "_display.py").write_text("def format_poles(p): ...\n")
    (root / "sub" / "book.py").write_text("_HEADING = 1\n")
    (root / "sub" / "labs.py").write_text(
        "from . import book\nfrom .._display import format_poles\nfrom .book import _HEADING\n"
        "x = book._HEADING\ny = format_poles.__name__\n"
    )
    found = private_imports(root / "sub" / "labs.py", root)
    assert found == ["line 3: from uio_teach.sub.book import _HEADING", "line 4: book._HEADING"]


# imports at the top -----------------------------------------------------------------------------


def deferred_imports(path: Path) -> list[str]:
    """Imports below the module's top level with no comment on their line or above their block.

    Imports under a top-level ``if``/``try`` (``TYPE_CHECKING``, an optional dependency) are at
    the top; one inside a function or class is deferred and must say why in a comment.
    """
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    tree = ast.parse(text)
    top: set[int] = set()
    stack = list(tree.body)
    while stack:
        node = stack.pop()
        top.add(id(node))
        if isinstance(node, ast.If | ast.Try):
            stack.extend(node.body + node.orelse + getattr(node, "finalbody", []))
            for handler in getattr(node, "handlers", []):
                stack.extend(handler.body)
    imports = [n for n in ast.walk(tree) if isinstance(n, ast.Import | ast.ImportFrom)]
    starts = {line: n.lineno for n in imports for line in range(n.lineno, n.end_lineno + 1)}

    def says_why(lineno: int) -> bool:
        """A comment on the import's line, or above the block of imports it belongs to."""
        if "#" in lines[lineno - 1]:
            return True
        above = lineno - 1
        while above in starts:  # the import just above: the same block
            if "#" in lines[starts[above] - 1]:
                return True
            above = starts[above] - 1
        return above >= 1 and lines[above - 1].strip().startswith("#")

    return [
        f"line {node.lineno}: {lines[node.lineno - 1].strip()}"
        for node in imports
        if id(node) not in top and not says_why(node.lineno)
    ]


@pytest.mark.parametrize("path", MODULES, ids=_ids)
def test_imports_are_at_the_top_unless_deferred_on_purpose(path):
    found = deferred_imports(path)
    assert not found, (
        f"{_module_name(path)} imports inside functions without saying why "
        f"(move them to the top, or add a comment on the line): {found}"
    )


def test_the_import_check_accepts_a_deferral_that_says_why(tmp_path):
    path = tmp_path / "m.py"
    path.write_text(
        textwrap.dedent(
            """\
            from typing import TYPE_CHECKING
            if TYPE_CHECKING:
                import numpy
            def f():
                import json
                import cvxpy  # heavy: only for the LMI gain
                # ipywidgets only when an explorer is shown
                import ipywidgets
                from ipywidgets import (
                    Image,
                )
                import io
            def g():
                import yaml
            """
        )
    )
    assert deferred_imports(path) == ["line 5: import json", "line 14: import yaml"]


# tests do not watch the clock -------------------------------------------------------------------

CLOCKS = {"time", "perf_counter", "monotonic", "perf_counter_ns", "monotonic_ns", "time_ns"}


def _reads_clock(node: ast.AST, tainted: set[str]) -> bool:
    for sub in ast.walk(node):
        if isinstance(sub, ast.Call):
            func = sub.func
            if (
                isinstance(func, ast.Attribute)
                and func.attr in CLOCKS
                and isinstance(func.value, ast.Name)
                and func.value.id == "time"
            ):
                return True
            if isinstance(func, ast.Name) and func.id in CLOCKS - {"time"}:
                return True
        if isinstance(sub, ast.Name) and sub.id in tainted:
            return True
    return False


def _targets(node: ast.AST) -> set[str]:
    names = set()
    for sub in ast.walk(node):
        if isinstance(sub, ast.Name):
            names.add(sub.id)
    return names


def _clock_targets(target: ast.AST, value: ast.AST, tainted: set[str]) -> set[str]:
    """The names an assignment of a clock-derived ``value`` to ``target`` makes clock-derived.

    Unpacking follows a literal tuple element by element; unpacking anything else (a row of a
    fixture's result, say) is left alone, as which element holds the time is not known.
    """
    if isinstance(target, ast.Tuple | ast.List):
        if isinstance(value, ast.Tuple | ast.List) and len(value.elts) == len(target.elts):
            names = set()
            for sub_target, sub_value in zip(target.elts, value.elts, strict=True):
                if _reads_clock(sub_value, tainted):
                    names |= _clock_targets(sub_target, sub_value, tainted)
            return names
        return set()
    return _targets(target)


def clock_assertions(path: Path) -> list[str]:
    """Comparisons (``<``, ``<=``, ``>``, ``>=``) in ``path`` that depend on a wall-clock reading.

    A value is clock-derived when it comes from ``time.time``/``perf_counter``/``monotonic``, or
    from a name assigned such a value, or from a fixture or helper of the module that returns
    one. Comparisons in a ``while`` condition (waiting for an event, with a safety net) do not
    decide whether a test passes and do not count.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"))
    functions = [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)]
    sources: set[str] = set()  # functions and fixtures that hand out clock-derived values
    tainted_in: dict[str, set[str]] = {f.name: set() for f in functions}
    changed = True
    while changed:
        changed = False
        for func in functions:
            tainted = tainted_in[func.name]
            before = (len(tainted), func.name in sources)
            tainted |= {a.arg for a in func.args.args if a.arg in sources}
            for node in ast.walk(func):
                if isinstance(node, ast.Assign | ast.AugAssign | ast.AnnAssign):
                    value = node.value
                    if value is not None and _reads_clock(value, tainted | sources):
                        targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                        for target in targets:
                            tainted |= _clock_targets(target, value, tainted | sources)
                elif isinstance(node, ast.Return | ast.Yield) and node.value is not None:
                    if _reads_clock(node.value, tainted | sources):
                        sources.add(func.name)
            if (len(tainted), func.name in sources) != before:
                changed = True
    found = []
    for func in functions:
        tainted = tainted_in[func.name] | sources
        in_while = {
            id(sub) for n in ast.walk(func) if isinstance(n, ast.While) for sub in ast.walk(n.test)
        }
        for node in ast.walk(func):
            if isinstance(node, ast.Compare) and id(node) not in in_while:
                ordered = any(
                    isinstance(op, ast.Lt | ast.LtE | ast.Gt | ast.GtE) for op in node.ops
                )
                if ordered and _reads_clock(node, tainted):
                    found.append(f"{func.name}, line {node.lineno}")
    return sorted(set(found))


@pytest.mark.parametrize("path", sorted(TESTS.glob("test_*.py")), ids=lambda p: p.name)
def test_no_test_asserts_a_wall_clock_duration(path):
    found = clock_assertions(path)
    assert not found, (
        f"{path.name} decides on wall-clock time (a benchmark's job, in benchmarks/): {found}"
    )


def test_the_clock_check_follows_values_through_fixtures(tmp_path):
    path = tmp_path / "test_x.py"
    path.write_text(
        textwrap.dedent(
            """\
            import time
            def timed():
                start = time.perf_counter()
                run()
                return {"seconds": time.perf_counter() - start}
            def test_fast(timed):
                assert timed["seconds"] < 30
            def test_direct():
                t0 = time.monotonic()
                elapsed = time.monotonic() - t0
                if elapsed > 5:
                    raise AssertionError
            def rows():
                return {"first": (0, "folder", time.time())}
            def test_rows(rows):
                code, folder, seconds = rows["first"]
                assert code == 0 and len(folder) > 3
                assert max(row[2] for row in rows.values()) < 30
            def test_waits_for_an_event():
                deadline = time.monotonic() + 600
                while not done() and time.monotonic() < deadline:
                    pass
                assert done()
            """
        )
    )
    assert clock_assertions(path) == [
        "test_direct, line 11",
        "test_fast, line 7",
        "test_rows, line 18",
    ]


# markers ----------------------------------------------------------------------------------------


def test_each_process_is_classified_by_what_it_starts():
    import conftest

    python = sys.executable
    assert conftest.needs_of([python, "-m", "ipykernel_launcher", "-f", "k.json"]) == {
        "subprocess",
        "kernel",
    }
    assert conftest.needs_of([python, "-m", "uio_teach", "grade", "a.ipynb"]) >= {"kernel"}
    runner = ["bwrap", "--die-with-parent", python, "-m", "uio_teach.grading.runner", "--run"]
    assert conftest.needs_of(runner) >= {"kernel"}
    assert conftest.needs_of(["/venv/bin/jupyter-book", "build", "."]) >= {"book"}
    assert conftest.needs_of([python, "-m", "sphinx", "-b", "html", "src", "out"]) >= {"book"}
    driver = "/venv/lib/site-packages/playwright/driver/node"
    assert conftest.needs_of([driver, "cli.js", "run-driver"]) >= {"browser"}
    assert conftest.needs_of([python, "-m", "pip", "wheel", "."]) >= {"wheel"}
    assert conftest.needs_of([python, "-c", "print(1)"]) == {"subprocess"}
    assert conftest.needs_of(["pandoc", "--version"]) == set()  # a cached probe of the machine
    assert conftest.needs_of(["/usr/bin/bwrap", "--ro-bind", "/", "/", "/bin/true"]) == set()
    assert conftest.needs_of("jupyter-book build . -W") >= {"book"}  # a shell command line


class _Item:
    """The parts of a test item the guard reads."""

    def __init__(self, *marks: str) -> None:
        self.nodeid = "tests/test_x.py::test_x"
        self.stash = pytest.Stash()
        self._marks = [getattr(pytest.mark, m).mark for m in marks]

    def iter_markers(self):
        return iter(self._marks)


def test_a_process_started_without_its_marker_fails_the_test():
    import conftest

    book = ["jupyter-book", "build", "."]
    with pytest.raises(pytest.fail.Exception, match=r"@pytest\.mark\.book"):
        conftest.check_launch(book, _Item())
    with pytest.raises(pytest.fail.Exception, match=r"@pytest\.mark\.subprocess"):
        conftest.check_launch([sys.executable, "-c", "pass"], _Item("slow"))
    with pytest.raises(pytest.fail.Exception, match=r"@pytest\.mark\.kernel"):
        conftest.check_launch([sys.executable, "-m", "ipykernel_launcher"], _Item("book"))
    refused = _Item("browser")
    with pytest.raises(pytest.fail.Exception):
        conftest.check_launch(book, refused)
    assert refused.stash[conftest._violations]  # failed even if the exception is swallowed
    conftest.check_launch(book, _Item("book"))
    conftest.check_launch([sys.executable, "-c", "pass"], _Item("subprocess"))
    with pytest.raises(RuntimeError, match="at import time"):
        conftest.check_launch(book, None)  # at collection
    conftest.check_launch([sys.executable, "-c", "pass"], None)  # a probe of the machine


def test_the_guard_is_installed_on_every_process_start():
    import conftest

    assert subprocess.Popen._execute_child is conftest._guarded_execute_child


# tolerances -------------------------------------------------------------------------------------

COMPARISONS = {"assert_allclose", "allclose", "isclose", "approx", "assert_array_almost_equal"}
# Below this a hand-written tolerance is about the CPU's round-off, not the computation: such a
# comparison goes through tests/tolerance.py, which derives it from the data.
HAND_TOLERANCE_FLOOR = 1e-8
TOLERANCE_ARGS = {"rtol", "atol", "abs", "rel"}


def tight_hand_tolerances(path: Path) -> list[str]:
    """Float comparisons in ``path`` with a literal tolerance below the floor."""

    def tiny(node: ast.AST) -> bool:
        return any(
            isinstance(c, ast.Constant)
            and isinstance(c.value, float)
            and 0 < c.value < HAND_TOLERANCE_FLOOR
            for c in ast.walk(node)
        )

    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in COMPARISONS:
                bad = [k.arg for k in node.keywords if k.arg in TOLERANCE_ARGS and tiny(k.value)]
                if bad:
                    found.append(f"line {node.lineno}: {name}({', '.join(bad)}=...)")
        elif isinstance(node, ast.Compare) and any(
            isinstance(op, ast.Lt | ast.LtE) for op in node.ops
        ):
            if any(tiny(c) for c in node.comparators):
                found.append(f"line {node.lineno}: a comparison with a constant below the floor")
    return found


def test_no_comparison_of_results_uses_a_hand_tolerance_tuned_to_round_off():
    offenders = {
        path.name: found
        for path in sorted(TESTS.glob("test_*.py"))
        if (found := tight_hand_tolerances(path))
    }
    assert not offenders, (
        "tolerances below 1e-8 written by hand (use tests/tolerance.py, which derives them from "
        f"the size, length and conditioning of the computation): {offenders}"
    )


def test_a_tight_hand_tolerance_is_found(tmp_path):
    path = tmp_path / "test_x.py"
    path.write_text(
        textwrap.dedent(
            """\
            import numpy as np
            def test_a(a, b):
                np.testing.assert_allclose(a, b, atol=1e-12)
                np.testing.assert_allclose(a, b, rtol=1e-6)
                assert abs(a - b) < 1e-11 * abs(b)
                assert a == pytest.approx(b, rel=1e-3)
            """
        )
    )
    assert tight_hand_tolerances(path) == [
        "line 3: assert_allclose(atol=...)",
        "line 5: a comparison with a constant below the floor",
    ]
