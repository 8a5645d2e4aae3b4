"""One registry entry per worked example: every config key acts, every declared field arrives."""

from __future__ import annotations

import dataclasses
import functools
import io
import tempfile
from pathlib import Path

import matplotlib.style
import pytest
from tolerance import assert_rounding_close

from uio_teach.experiments import EXPERIMENTS, LAB_PLANTS, experiment_params, param, pole_text
from uio_teach.explorers import compute_frame
from uio_teach.explorers.scenarios import plant_controls, scenario_of
from uio_teach.instructor import figures
from uio_teach.instructor.config import OBSERVER_KEYS, FigureConfig, config_schema
from uio_teach.instructor.lab_registry import LABS
from uio_teach.worked import WORKED, ExplorerOptions, RegistryError, run_from_config

BOOK = Path(__file__).resolve().parent.parent / "book"
SCHEMA = config_schema()


def _other(key: str) -> object:
    """Another valid value of a config key, as TOML would give it (derived from its declaration)."""
    opt = SCHEMA[key]
    value = opt.default
    if opt.kind == "str":
        return "ggplot" if value != "ggplot" else "default"
    if opt.kind == "int":
        up = value + 1
        return up if opt.maximum is None or up <= opt.maximum else value - 1
    if opt.kind == "float":
        return 0.05 if value == 0 else value * 0.9
    if opt.kind == "floats":
        return [v * 0.9 for v in value]
    # poles: faster by 10 % (a discrete one absent by default: one inside the unit circle)
    if value is None:
        return [0.2]
    return [pole_text(complex(p) * 1.1) for p in value]


def _nested(key: str, value: object) -> dict:
    out: dict = {}
    node = out
    *tables, last = key.split(".")
    for part in tables:
        node = node.setdefault(part, {})
    node[last] = value
    return out


def _section(key: str) -> str | None:
    head = key.split(".", 1)[0]
    return head if "." in key and head in WORKED else None


def _lab_params(cfg: FigureConfig, name: str) -> dict:
    return LABS[name].params.from_config(cfg).to_params()


def _figure_bytes(cfg: FigureConfig, name: str, folder: Path) -> bytes:
    spec = figures.FIGURES[name]
    runs = figures._Runs(cfg)
    with matplotlib.style.context(cfg["style"]):
        if spec.table:
            return b"".join(p.read_bytes() for p in spec.draw(runs, folder))
        fig = spec.draw(runs)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=20, metadata={"Software": None})
        return buf.getvalue()


@functools.cache
def _default_figure(name: str) -> bytes:
    with tempfile.TemporaryDirectory() as folder:
        return _figure_bytes(FigureConfig(), name, Path(folder))


def test_the_registry_is_the_source_of_experiments_labs_observers_and_figures():
    assert list(EXPERIMENTS) == list(WORKED)
    assert set(LAB_PLANTS) == {n for n, e in WORKED.items() if e.lab} == set(LABS)
    for name, entry in WORKED.items():
        assert EXPERIMENTS[name] is entry.run() and entry.run().lab == name
        if entry.lab:
            assert LABS[name].source == entry.lab.source and (BOOK / entry.lab.source).is_file()
            assert LABS[name].params is entry.lab.params
        assert OBSERVER_KEYS[entry.poles_key()] == name
    assert list(figures.FIGURES) == [f.name for e in WORKED.values() for f in e.figures]
    assert set(OBSERVER_KEYS) == {e.poles_key() for e in WORKED.values()}


@pytest.mark.parametrize("name", list(WORKED))
def test_every_declared_field_reaches_the_config_the_lab_and_the_explorer(name):
    entry, experiment = WORKED[name], WORKED[name].run()
    scenario = scenario_of(entry.name)
    lab_fields = {f.name for f in dataclasses.fields(LABS[name].params)} if entry.lab else set()
    limits = {
        "amplitude": (scenario.amplitude_limits, scenario.defaults.amplitude),
        "frequency": (scenario.disturbance_frequency_limits, scenario.defaults.frequency),
        "noise": (scenario.noise_limits, None),
    }
    sliders = {c.name: c for c in scenario.plant_controls}
    for field, spec in experiment_params(experiment):
        key = spec.config_key(name, field)
        if key is not None:
            assert key in SCHEMA, (name, field)
        if spec.lab and entry.lab:
            assert field in lab_fields, (name, field)
        if spec.range is not None and not spec.control:  # a slider of its own
            assert sliders[field].limits == spec.range
            assert sliders[field].value == getattr(experiment, field)
        elif spec.control:
            (lo_hi, default) = limits[spec.control]
            assert lo_hi == spec.range, (name, field)
            if default is not None:
                assert default == getattr(experiment, field), (name, field)
    own = {f for f, spec in experiment_params(experiment) if spec.range and not spec.control}
    assert set(sliders) == own


def test_a_slider_of_its_own_remakes_the_run_and_a_plant_slider_the_plant():
    for name, entry in WORKED.items():
        scenario = scenario_of(entry.name)
        plant_fields = type(entry.run()).plant_fields
        for control in scenario.plant_controls:
            lo, hi = control.limits
            value = lo if control.value != lo else hi
            other = scenario.rebuild(**{control.name: value})
            assert [c.value for c in other.plant_controls if c.name == control.name] == [value]
            if control.name in plant_fields:
                assert other.plant != scenario.plant, (name, control.name)
            frame = compute_frame(other)
            assert frame.scenario is other


def test_a_declared_range_gives_a_slider_whatever_the_field():
    """The set of controls is not closed: a new field with a range is a slider of its own."""

    @dataclasses.dataclass(frozen=True)
    class Later(type(WORKED["pa9"].run())):
        start: float = param(1.0, "float", "when d starts", unit="s", range=(0.0, 5.0))

    later = Later(name="pa9", timepts=WORKED["pa9"].run().timepts)
    (slider,) = plant_controls(later)
    assert (slider.name, slider.limits, slider.value) == ("start", (0.0, 5.0), 1.0)
    with pytest.raises(ValueError, match="control must be one of"):
        param(1.0, "float", "x", range=(0.0, 1.0), control="plant")
    with pytest.raises(ValueError, match="needs an int or float field"):
        param((1.0,), "floats", "x", range=(0.0, 1.0))


def test_a_slider_value_for_a_field_without_one_is_refused():
    with pytest.raises(RegistryError, match=r"no slider 'gamma3'; its sliders: gamma1, gamma2"):
        scenario_of("quadruple_tank", gamma3=0.5)
    with pytest.raises(RegistryError, match=r"the pa9 explorer has no slider 'poles'"):
        scenario_of("pa9", poles=(-1.0, -2.0, -3.0))


@pytest.mark.slow
@pytest.mark.parametrize("key", list(SCHEMA))
def test_every_config_key_changes_an_output(key, tmp_path_factory):
    """A key is never accepted and ignored: it changes a lab's PARAMS or a figure's bytes."""
    cfg = FigureConfig.from_dict(_nested(key, _other(key)))
    assert cfg[key] != FigureConfig()[key]
    section = _section(key)
    names = [section] if section else list(WORKED)
    for name in names:
        if WORKED[name].lab and _lab_params(cfg, name) != _lab_params(FigureConfig(), name):
            return
    folder = tmp_path_factory.mktemp("figures")
    for name in names:
        for fig in WORKED[name].figures:
            if _figure_bytes(cfg, fig.name, folder) != _default_figure(fig.name):
                return
    pytest.fail(f"the config key {key} changes no lab's PARAMS and no figure")


def test_the_figures_run_is_the_config_through_the_declared_fields():
    cfg = FigureConfig.from_dict(
        {"quadruple_tank": {"gamma1": 0.8, "pump2": {"amplitude": 0.7}}, "seed": 9}
    )
    run = run_from_config("quadruple_tank", cfg)
    assert (run.gamma1, run.gamma2, run.sine_amplitude) == (0.8, 0.6, 0.7)
    # gamma1 k1 / A1: two roundings on each side of the comparison.
    assert_rounding_close(run.plant().E[0, 0], 0.8 * 3.33 / 28, terms=2)
    assert run_from_config("case_study", cfg).seed == 9


# the explorer's options: a typed object, every mistake named -------------------------------------

REQUIRED = {
    "period": 1.0,
    "pole_limits": (-10.0, 1.0),
    "frequency_limits": (0.0, 10.0),
    "period_limits": (0.1, 5.0),
    "static_values": (-1.0, -2.0),
}


@pytest.mark.parametrize("missing", sorted(REQUIRED))
def test_a_missing_explorer_option_is_named(missing):
    given = {k: v for k, v in REQUIRED.items() if k != missing}
    with pytest.raises(RegistryError, match=rf"explorer option '{missing}' is missing"):
        ExplorerOptions(**given)


def test_an_unknown_or_malformed_explorer_option_is_named():
    with pytest.raises(RegistryError, match=r"unknown explorer option 'noise_limit' \(did you"):
        ExplorerOptions(**REQUIRED, noise_limit=(0.0, 0.1))
    with pytest.raises(RegistryError, match=r"'pole_limits' must have low < high"):
        ExplorerOptions(**{**REQUIRED, "pole_limits": (1.0, -10.0)})
    with pytest.raises(RegistryError, match=r"'d_channels': each channel is \(gain, speed\)"):
        ExplorerOptions(**REQUIRED, d_channels=((1.0,),))
    with pytest.raises(RegistryError, match=r"'static_control' must be 'pole', 'amplitude'"):
        ExplorerOptions(**REQUIRED, static_control="valve")
    with pytest.raises(RegistryError, match=r"explorer must be ExplorerOptions, got dict"):
        dataclasses.replace(WORKED["pa9"], explorer=dict(REQUIRED))


def test_an_option_that_a_declared_field_sets_is_refused(monkeypatch):
    """PA9 declares its noise range: a noise_limits option beside it would be set twice."""
    entry = dataclasses.replace(
        WORKED["pa9"],
        explorer=dataclasses.replace(WORKED["pa9"].explorer, noise_limits=(0.0, 1.0)),
    )
    monkeypatch.setitem(WORKED._load(), "pa9", entry)
    with pytest.raises(RegistryError, match=r"the field 'noise' sets the noise control"):
        scenario_of(entry.name)


def test_every_worked_example_has_typed_explorer_options():
    for name, entry in WORKED.items():
        assert isinstance(entry.explorer, ExplorerOptions), name
        assert scenario_of(entry.name).title == (entry.explorer.title or entry.title)


def test_a_time_grid_given_twice_is_refused():
    run = WORKED["pa9"].run()
    with pytest.raises(ValueError, match="either as timepts or as samples/duration"):
        run.with_values(timepts=[0.0, 1.0], samples=11)
    with pytest.raises(ValueError, match=r"has no field 'sine_phase'"):
        run.with_values(sine_phase=0.7)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"poles": (-5.0, -6.0, -7.0)}, r"its experiment sets the starting poles"),
        ({"static_control": "plant:gamma1"}, r"static_control 'plant:gamma1' names no slider"),
    ],
)
def test_an_explorer_option_that_would_be_ignored_is_refused(monkeypatch, change, message):
    entry = dataclasses.replace(
        WORKED["pa9"], explorer=dataclasses.replace(WORKED["pa9"].explorer, **change)
    )
    monkeypatch.setitem(WORKED._load(), "pa9", entry)
    with pytest.raises(RegistryError, match=message):
        scenario_of(entry.name)
