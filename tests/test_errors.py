"""The package's errors share one base (numeric ones stay ValueErrors), its warnings another."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

import uio_teach as ut
from uio_teach.checks.answers import AnswerError
from uio_teach.folders import FolderBusy, OutputError
from uio_teach.grading.grade import GradeError, SandboxRefused, UnsandboxedWarning
from uio_teach.grading.sandbox import SandboxUnavailable
from uio_teach.instructor.config import ConfigError
from uio_teach.instructor.lab_registry import LabError, LabUsageError

# each error with the built-in class that says what went wrong
ERRORS = {
    ut.InputError: ValueError,
    ut.LMIError: ValueError,
    ut.LMIInfeasibleError: ValueError,
    ut.LMISolverError: ValueError,
    ut.SimulationOverflowError: OverflowError,
    ConfigError: ValueError,
    AnswerError: ValueError,
    LabError: ValueError,
    LabUsageError: ValueError,
    GradeError: ValueError,
    SandboxRefused: ValueError,
    OutputError: OSError,
    FolderBusy: OSError,
    SandboxUnavailable: RuntimeError,
}


@pytest.mark.parametrize("error", list(ERRORS), ids=lambda e: e.__name__)
def test_every_error_has_the_common_base_and_its_builtin_kind(error):
    assert issubclass(error, ut.UIOTeachError)
    assert issubclass(error, ERRORS[error])


def _defined_in_the_package() -> list[type[BaseException]]:
    """Every exception and warning class a module of the package defines."""
    found = []
    for info in pkgutil.walk_packages(ut.__path__, prefix="uio_teach."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for value in vars(module).values():
            if (
                inspect.isclass(value)
                and issubclass(value, BaseException)
                and value.__module__ == module.__name__
                and not value.__name__.startswith(
                    "_"
                )  # a module's own control flow, never raised out
            ):
                found.append(value)
    return found


def test_every_error_and_warning_of_every_module_has_the_common_base():
    """Found by walking the package, so a new class cannot be left out of the list above."""
    stray = [
        f"{c.__module__}.{c.__name__}"
        for c in _defined_in_the_package()
        if c not in (ut.UIOTeachError, ut.UIOTeachWarning)
        and not issubclass(c, ut.UIOTeachWarning if issubclass(c, Warning) else ut.UIOTeachError)
    ]
    assert not stray, f"outside UIOTeachError / UIOTeachWarning: {stray}"


def test_no_module_raises_a_bare_builtin_value_or_type_error():
    """A bad argument is an ``InputError`` (a ``ValueError`` too), never a bare built-in one."""
    import ast
    from pathlib import Path

    bare = []
    for path in sorted(Path(ut.__file__).parent.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Raise) and node.exc is not None:
                target = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
                if isinstance(target, ast.Name) and target.id in {"ValueError", "TypeError"}:
                    bare.append(f"{path.name}:{node.lineno}")
    assert not bare, f"raise InputError (uio_teach.errors) instead: {bare}"


def test_warnings_have_the_common_base():
    assert issubclass(UnsandboxedWarning, ut.UIOTeachWarning)
    assert issubclass(ut.UIOTeachWarning, UserWarning)


def test_one_except_catches_a_bad_config_and_an_infeasible_lmi():
    from uio_teach.instructor.config import FigureConfig

    with pytest.raises(ut.UIOTeachError, match="seed: must be >= 0"):
        FigureConfig.from_dict({"seed": -1})
    # the case study's fixed modes sit at radius 0.5: no gain certifies a radius of 0.3
    with pytest.raises(ut.UIOTeachError) as err:
        ut.design_pmo(ut.examples.dt_case_study(), method="lmi", decay=0.3)
    assert isinstance(err.value, ut.LMIError)
