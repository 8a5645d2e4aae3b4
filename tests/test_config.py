"""One declaration per experiment field: the term config, --print-config and the lab parameters."""

from __future__ import annotations

import contextlib
import dataclasses
import tomllib

import pytest

from uio_teach import experiments
from uio_teach.experiments import experiment_params, param
from uio_teach.explorers import scenario_of
from uio_teach.instructor import cli
from uio_teach.instructor.config import (
    ConfigError,
    FigureConfig,
    config_schema,
    config_tables,
    default_config_toml,
    load_config,
)
from uio_teach.instructor.labs import LABS
from uio_teach.lab_params import lab_params_of
from uio_teach.worked import discover, pa9
from uio_teach.worked.case_study import CASE_STUDY
from uio_teach.worked.pa9 import PA9, PA9Experiment, PA9Params


@dataclasses.dataclass(frozen=True)
class PA9WithBias(PA9Experiment):
    """PA9 with one more field: the one edit that adds it everywhere."""

    bias: float = param(
        0.25, "float", "a constant added to d", unit="V", key="sine.bias", maximum=3.0
    )


@contextlib.contextmanager
def registered(experiment):
    """PA9's registry entry with ``experiment`` in place of its own, while the block runs."""
    own = pa9.EXAMPLES
    pa9.EXAMPLES = (dataclasses.replace(own[0], experiment=experiment),)
    discover()
    try:
        yield experiment
    finally:
        pa9.EXAMPLES = own
        discover()


@pytest.fixture
def with_bias():
    with registered(PA9WithBias(name="pa9", timepts=PA9.timepts)) as experiment:
        yield experiment


def test_a_new_field_is_a_key_of_the_config_with_its_type_bounds_and_help(with_bias):
    key = config_schema()["pa9.sine.bias"]
    assert (key.kind, key.default, key.maximum) == ("float", 0.25, 3.0)
    assert key.help == "a constant added to d [V]"
    assert FigureConfig()["pa9.sine.bias"] == 0.25
    assert FigureConfig.from_dict({"pa9": {"sine": {"bias": 1.5}}})["pa9.sine.bias"] == 1.5
    with pytest.raises(ConfigError, match=r"pa9.sine.bias: must be between -3 and 3, got 7"):
        FigureConfig.from_dict({"pa9": {"sine": {"bias": 7}}})


def test_a_new_field_is_printed_by_print_config(with_bias, capsys):
    assert cli.main(["figures", "--print-config"]) == 0
    text = capsys.readouterr().out
    section = text.split("[pa9.sine]", 1)[1].split("\n\n", 1)[0]
    assert "bias = 0.25  # a constant added to d [V]" in section
    assert tomllib.loads(text)["pa9"]["sine"]["bias"] == 0.25


def test_a_new_field_is_a_lab_parameter_read_from_the_config(with_bias, tmp_path):
    @lab_params_of(with_bias)
    class BiasParams(PA9Params):
        pass

    assert BiasParams().bias == 0.25
    assert BiasParams().to_params()["sine"] == {"amplitude": 1.0, "frequency": 2.0, "bias": 0.25}
    term = tmp_path / "term.toml"
    term.write_text("[pa9.sine]\nbias = 2.0\n")
    params = BiasParams.from_config(load_config(term))
    assert params.bias == 2.0 and params.to_params()["sine"]["bias"] == 2.0
    assert BiasParams.from_params(params.to_params()) == params
    # and the experiment itself runs with it
    assert with_bias.with_values(bias=2.0).bias == 2.0


def test_without_the_field_nothing_knows_it():
    assert "pa9.sine.bias" not in config_schema()
    assert "bias" not in PA9Params().to_params()["sine"]


def test_the_config_is_the_declared_fields():
    """Every config key comes from one declared field (or two declared alike: seed, style)."""
    schema = config_schema()
    declared = {}
    for section, experiment in experiments.EXPERIMENTS.items():
        for name, spec in experiment_params(experiment):
            key = spec.config_key(section, name)
            if key is not None:
                declared.setdefault(key, []).append((section, name))
    assert set(schema) == set(declared)
    assert sorted(k for k, v in declared.items() if len(v) > 1) == ["seed", "style"]
    # the tables of --print-config follow each other, none twice (valid TOML)
    assert tomllib.loads(default_config_toml())
    assert set(config_tables()) >= {k.rpartition(".")[0] for k in schema if "." in k}


def test_the_lab_parameters_are_the_declared_lab_fields():
    for params in (lab.params for lab in LABS.values()):
        names = [f.name for f in dataclasses.fields(params)]
        assert names == [n for n, s in experiment_params(params.experiment) if s.lab]
        assert params() == params.from_params(params().to_params())


def test_the_explorers_ranges_are_the_declared_ranges():
    ranges = {n: s.range for n, s in experiment_params(PA9)}
    scenario = scenario_of("pa9")
    assert scenario.amplitude_limits == ranges["sine_amplitude"]
    assert scenario.disturbance_frequency_limits == ranges["sine_frequency"]
    assert scenario.noise_limits == ranges["noise"]
    case = {n: s.range for n, s in experiment_params(CASE_STUDY)}
    assert scenario_of("case_study").amplitude_limits == case["d_amplitude"]


def test_a_key_declared_twice_differently_is_refused():
    @dataclasses.dataclass(frozen=True)
    class OtherSeed(PA9Experiment):
        seed: int | None = param(5, "int", "another seed", config="seed")

    with pytest.raises(ValueError, match="the config key 'seed' is declared twice, differently"):
        config_schema(
            {
                "pa9": OtherSeed(name="pa9", timepts=PA9.timepts),
                **{k: v for k, v in experiments.EXPERIMENTS.items() if k != "pa9"},
            }
        )


# a configured value is never replaced by a default unseen -----------------------------------------


@dataclasses.dataclass(frozen=True)
class PA9WithPhase(PA9Experiment):
    """PA9 with the sine's phase: one line, and every group of a term gets its configured value."""

    phase: float = param(0.0, "float", "phase of the sinusoid", unit="rad", key="sine.phase")


@pytest.fixture
def with_phase():
    with registered(PA9WithPhase(name="pa9", timepts=PA9.timepts)) as experiment:

        @lab_params_of(experiment)
        class PhaseParams(PA9Params):
            pass

        yield PhaseParams


def test_a_configured_field_the_draw_does_not_vary_reaches_every_group(with_phase, tmp_path):
    from uio_teach.instructor.lab_registry import Lab
    from uio_teach.instructor.variants import draw_variants

    term = tmp_path / "term.toml"
    term.write_text("seed = 11\n[pa9]\nduration = 12.0\n[pa9.sine]\nphase = 0.7\n")
    base = with_phase.from_config(load_config(term))
    assert base.phase == 0.7
    lab = Lab("pa9", "lab_pa9.md", with_phase, LABS["pa9"].check_ids)
    variants = draw_variants(lab, 3, seed=2027, base=base)
    for variant in variants:
        assert variant.phase == 0.7 and variant.to_params()["sine"]["phase"] == 0.7
        assert variant.duration == 12.0 and variant.seed == 11  # configured, not drawn
    # what the draw varies is drawn per group
    assert len({v.poles for v in variants}) == 3


@pytest.mark.parametrize("name", list(LABS))
def test_a_group_keeps_every_field_its_lab_does_not_draw(name):
    """Whatever fields a lab has, the draw replaces only those its class draws (``vary``)."""
    import numpy as np

    params = LABS[name].params
    base = params()
    drawn = params.vary(np.random.default_rng(1), base)
    variant = params.draw(np.random.default_rng(1), base)
    for field in dataclasses.fields(variant):
        if field.name not in drawn:
            assert getattr(variant, field.name) == getattr(base, field.name), field.name
    assert set(drawn) < {f.name for f in dataclasses.fields(variant)}


def test_params_with_an_unknown_or_a_missing_entry_are_refused():
    from uio_teach.lab_params import LabParamsError

    params = PA9Params().to_params()
    with pytest.raises(LabParamsError, match=r"unknown entry 'sine.phase'; expected some of"):
        PA9Params.from_params({**params, "sine": {**params["sine"], "phase": 0.7}})
    with pytest.raises(LabParamsError, match=r"unknown entry 'noise_level'"):
        PA9Params.from_params({**params, "noise_level": 0.1})
    del params["poles"]
    with pytest.raises(LabParamsError, match=r"'poles' is missing \(UIO poles"):
        PA9Params.from_params(params)
