"""A new worked example is one new module: the registry carries it to every place that lists them.

A throwaway example (a DC motor with an unknown load torque) is written as a module of a package
of its own, read by the registry (:func:`uio_teach.worked.discover`), and must then reach the term
config, ``uio-teach figures`` (its list and its files), the explorer, the API page and the tests'
parametrisations, with no other edit anywhere.
"""

from __future__ import annotations

import dataclasses
import importlib
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from uio_teach.explorers.scenarios import scenario_of
from uio_teach.instructor import cli, figures
from uio_teach.instructor.config import FigureConfig, config_schema
from uio_teach.worked import WORKED, RegistryError, discover

ROOT = Path(__file__).resolve().parents[1]

MOTOR = '''
"""A DC motor whose load torque nobody measures."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import ClassVar

import numpy as np

from uio_teach import signals
from uio_teach.experiments import Experiment, param
from uio_teach.plant import Plant
from uio_teach.worked import ExplorerOptions, FigureEntry, WorkedExample


def motor(inertia: float = 0.01) -> Plant:
    """Angle and speed measured; the voltage known, the load torque not."""
    return Plant(
        [[0.0, 1.0], [0.0, -0.1 / inertia]],
        [[1.0, 0.0], [0.0, 1.0]],
        B=[[0.0], [1.0 / inertia]],
        E=[[0.0], [-1.0 / inertia]],
        name=f"DC motor (J = {inertia:g})",
    )


@dataclass(frozen=True)
class MotorExperiment(Experiment):
    lab: ClassVar[str] = "probe_motor"
    plant_fields: ClassVar[tuple[str, ...]] = ("inertia",)
    tables: ClassVar[Mapping[str, str]] = MappingProxyType(
        {"": "a DC motor with an unknown load torque", "load": "the load torque"}
    )

    initial_state: np.ndarray = param((1.0, 0.0), "floats", "angle and speed", length=2)
    poles: tuple[complex, ...] | None = param((-20.0, -30.0), "poles", "UIO poles")
    duration: float = param(None, "float", "simulated time", unit="s", init=False, positive=True)
    samples: int = param(None, "int", "number of time points", init=False, minimum=2)
    inertia: float = param(
        0.01, "float", "rotor inertia", unit="kg m^2", positive=True, range=(0.005, 0.05)
    )
    load: float = param(
        0.2, "float", "size of the load step", unit="N m", key="load.size",
        range=(0.0, 1.0), control="amplitude",
    )
    load_frequency: float = param(
        2.0, "float", "frequency of the explorer's load", unit="rad/s", key="load.frequency",
        positive=True, range=(0.1, 10.0), control="frequency",
    )

    @property
    def unknown_inputs(self) -> Mapping[str, Callable]:
        return MappingProxyType({"load": signals.step(self.load, 0.5)})


DC_MOTOR = MotorExperiment(name="probe-motor", timepts=np.linspace(0.0, 2.0, 401))


def _error(runs):
    from uio_teach.plotting import new_figure, plot_error

    run = runs.run("probe_motor")
    fig = new_figure(6.0, 3.0)
    plot_error(fig.subplots(), run.simulate(runs.observer("probe_motor")))
    return fig


EXAMPLES = (
    WorkedExample(
        name="probe_motor",
        title="A DC motor",
        plant=motor,
        experiment=DC_MOTOR,
        family="uio",
        order=50,
        explorer=ExplorerOptions(
            period=0.5,
            pole_limits=(-100.0, 1.0),
            frequency_limits=(0.0, 50.0),
            period_limits=(0.1, 1.0),
            static_values=(-10.0, -20.0, -40.0),
        ),
        figures=(FigureEntry("motor_error", "DC motor: the UIO's error", _error),),
    ),
)
'''


@pytest.fixture
def motor_package(tmp_path, monkeypatch):
    """The package ``probe_examples`` with the module ``probe_motor``, read by the registry."""
    package = tmp_path / "probe_examples"
    package.mkdir()
    (package / "__init__.py").write_text('"""Worked examples of one\'s own."""\n')
    (package / "probe_motor.py").write_text(textwrap.dedent(MOTOR))
    monkeypatch.syspath_prepend(str(tmp_path))
    importlib.invalidate_caches()
    discover("probe_examples")
    yield tmp_path
    discover("probe_examples", remove=True)
    for name in [m for m in sys.modules if m.split(".")[0] == "probe_examples"]:
        del sys.modules[name]


def test_the_new_module_joins_the_registry(motor_package):
    assert list(WORKED)[-1] == "probe_motor"
    assert WORKED["probe_motor"].run().inertia == 0.01


def test_its_fields_are_keys_of_the_term_config(motor_package, capsys):
    schema = config_schema()
    for key in ("probe_motor.poles", "probe_motor.inertia", "probe_motor.load.size"):
        assert key in schema, key
    cfg = FigureConfig.from_dict({"probe_motor": {"inertia": 0.02, "load": {"size": 0.4}}})
    assert cfg["probe_motor.inertia"] == 0.02
    assert cli.main(["figures", "--print-config"]) == 0
    text = capsys.readouterr().out
    assert "[probe_motor]  # a DC motor with an unknown load torque" in text
    assert "[probe_motor.load]  # the load torque" in text


def test_its_figures_are_listed_and_drawn(motor_package, capsys, tmp_path):
    assert list(figures.FIGURES)[-1] == "motor_error"
    assert cli.main(["figures", "--list"]) == 0
    assert "motor_error" in capsys.readouterr().out
    (result,) = figures.generate(tmp_path / "out", ["motor_error"], fmt="svg", dpi=30)
    assert result.ok, result.error
    assert result.paths[0].name == "motor_error.svg"


def test_its_explorer_has_a_slider_per_declared_range(motor_package):
    scenario = scenario_of("probe_motor")
    assert scenario.amplitude_limits == (0.0, 1.0) and scenario.defaults.amplitude == 0.2
    assert [c.name for c in scenario.plant_controls] == ["inertia"]
    heavier = scenario.rebuild(inertia=0.04)
    assert heavier.plant.A[1, 1] == -0.1 / 0.04  # the same expression as the factory's


def test_the_api_page_lists_its_module(motor_package):
    sys.path.insert(0, str(ROOT / "_ext"))
    try:
        worked_api = importlib.import_module("worked_api")
    finally:
        sys.path.remove(str(ROOT / "_ext"))
    assert list(worked_api.worked_modules().items())[-1] == (
        "probe_examples.probe_motor",
        "A DC motor",
    )
    lines = worked_api.module_lines("probe_examples.probe_motor")
    assert ".. automodule:: probe_examples.probe_motor" in lines


@pytest.mark.subprocess
def test_the_tests_parametrise_over_it(motor_package):
    """Collected with the new example registered, the suites made for every example include it."""
    code = (
        "import sys, pytest\n"
        f"sys.path.insert(0, {str(motor_package)!r})\n"
        "from uio_teach.worked import discover\n"
        "discover('probe_examples')\n"
        "sys.exit(pytest.main(['--collect-only', '-q', '-p', 'no:cacheprovider', "
        "'tests/test_worked.py', 'tests/test_explorers.py']))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    ids = out.stdout
    assert (
        "test_every_declared_field_reaches_the_config_the_lab_and_the_explorer[probe_motor]" in ids
    )
    assert "test_every_config_key_changes_an_output[probe_motor.inertia]" in ids
    assert "[probe_motor]" in ids.split("test_explorers.py", 1)[1]


def test_a_figure_name_taken_twice_is_refused(motor_package):
    """Two figures of one name would leave one of them out of ``uio-teach figures`` unseen."""
    module = sys.modules["probe_examples.probe_motor"]
    (entry,) = module.EXAMPLES
    clash = dataclasses.replace(entry.figures[0], name="pa9_sine", description="another pa9_sine")
    module.EXAMPLES = (dataclasses.replace(entry, figures=(clash,)),)
    with pytest.raises(RegistryError, match="figures declared twice: pa9_sine"):
        discover()
    module.EXAMPLES = ({"name": "not an entry"},)
    with pytest.raises(RegistryError, match=r"probe_examples.probe_motor.EXAMPLES holds \{"):
        discover()
    module.EXAMPLES = (entry,)
    assert discover()[-1] == "probe_motor"


# a lab needs four files its module cannot hold: each one missing is said in words --------------


def test_every_lab_of_the_course_has_every_file_a_lab_needs():
    from uio_teach.instructor.lab_registry import LABS, missing_parts

    for lab in LABS.values():
        assert missing_parts(lab, ROOT / "book") == [], lab.id


def test_a_lab_without_its_files_is_told_what_is_missing(tmp_path):
    from uio_teach.instructor.lab_registry import Lab, missing_parts

    (tmp_path / "book").mkdir()
    (tmp_path / "_toc.yml").write_text("format: jb-book\nroot: book/index\n")
    from uio_teach.worked.pa9 import PA9Params

    lab = Lab("probe_motor", "lab_probe_motor.md", PA9Params, ("probe_motor.design",))
    missing = missing_parts(lab, tmp_path / "book")
    assert missing[0].startswith(
        f"the chapter {tmp_path / 'book' / 'lab_probe_motor.md'} of the probe_motor lab does not"
    )
    assert (
        "_toc.yml does not list the probe_motor lab's chapter: add `- file: book/lab_probe_motor`"
        in missing
    )
    assert any("uio_teach.checks has no function probe_motor_design" in m for m in missing)
    # the chapter written and listed, but with no parameters cell and no check cell
    (tmp_path / "book" / "lab_probe_motor.md").write_text(
        "# A lab\n\n```{code-cell} ipython3\nx = 1\n```\n"
    )
    (tmp_path / "_toc.yml").write_text(
        "root: book/index\nchapters:\n  - file: book/lab_probe_motor\n"
    )
    missing = missing_parts(lab, tmp_path / "book")
    assert any("exactly one code cell tagged `parameters`" in m for m in missing), missing
    assert any("has 0 code cells tagged `check`" in m for m in missing), missing
    assert not any("_toc.yml" in m or "the chapter" in m for m in missing), missing
