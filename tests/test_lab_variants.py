"""The labs' numbers: parameter classes, the term config, one variant per group, the answer key."""

from __future__ import annotations

import ast
import csv
import json
import re
from pathlib import Path

import control as ct
import jupytext
import nbformat
import numpy as np
import pytest
from lab_outputs import tags

import uio_teach as ut
from uio_teach import checks
from uio_teach.instructor import cli, labs
from uio_teach.instructor.config import load_config
from uio_teach.worked.case_study import CaseStudyParams
from uio_teach.worked.missile import MissileParams
from uio_teach.worked.pa9 import PA9Params

BOOK = labs.default_book_dir()


def params_cell(nb):
    cells = [c for c in nb.cells if "parameters" in tags(c)]
    assert len(cells) == 1
    return cells[0]


def params_of(nb) -> dict:
    tree = ast.parse(params_cell(nb).source)
    (node,) = tree.body
    assert [t.id for t in node.targets] == ["PARAMS"]
    return ast.literal_eval(node.value)


@pytest.mark.parametrize("lab", list(labs.LABS.values()), ids=list(labs.LABS))
def test_the_chapter_numbers_are_the_defaults_of_the_parameter_class(lab):
    """The book's PARAMS cell and the parameter class (from uio_teach.experiments) agree."""
    myst = jupytext.read(BOOK / lab.source)
    assert params_of(myst) == lab.params().to_params()


@pytest.mark.parametrize("cls", [lab.params for lab in labs.LABS.values()], ids=list(labs.LABS))
def test_params_round_trip_through_json(cls):
    params = cls().to_params()
    again = json.loads(json.dumps(params))
    assert cls.from_params(again) == cls()
    assert not cls().problems()


def test_complex_poles_travel_as_strings():
    p = PA9Params(poles=(complex(-1, 2), complex(-1, -2), -3.0))
    assert p.to_params()["poles"] == ["-1+2j", "-1-2j", -3.0]
    assert PA9Params.from_params(p.to_params()) == p
    answers = p.answers()
    assert answers["error_poles"] == [-3.0, "-1-2j", "-1+2j"]


@pytest.mark.parametrize("lab", list(labs.LABS.values()), ids=list(labs.LABS))
def test_the_registry_names_the_check_ids_of_the_check_cells(lab):
    nb = labs.make_notebook(BOOK / lab.source, "student")
    ids = []
    for cell in nb.cells:
        if "check" in tags(cell):
            (name,) = re.findall(r"\bchecks\.(\w+)\(", cell.source)
            ids.append(getattr(checks, name).check_id)
    assert tuple(ids) == lab.check_ids


def test_every_lab_notebook_has_one_parameters_cell_and_its_lab_in_the_metadata(tmp_path):
    results = labs.write_labs(tmp_path)
    for result in results:
        for path in (result.student, result.solution):
            nb = nbformat.read(path, as_version=4)
            params_cell(nb)
            lab = labs.lab_of(result.source)
            assert nb.metadata.uio_teach["lab"] == lab.id


# the term config --------------------------------------------------------------------------------

TERM = """\
seed = 9
style = "ggplot"
[pa9]
poles = [-2.0, -3.0, -4.0]
noise = 0.05
[pa9.sine]
amplitude = 0.5
frequency = 3.0
[case_study]
poles = [0.1]
[missile]
pmo_poles = [-90.0, -130.0]
duration = 0.4
samples = 8001
[missile.noise]
sigma = 0.02
seed = 11
"""


def test_the_term_config_sets_the_numbers_of_every_lab(tmp_path):
    config = tmp_path / "term.toml"
    config.write_text(TERM)
    assert cli.main(["labs", "--out", str(tmp_path / "out"), "--config", str(config), "-q"]) == 0
    for version in labs.VERSIONS:
        pa9 = params_of(nbformat.read(tmp_path / "out" / version / "lab_pa9.ipynb", 4))
        assert pa9["poles"] == [-2.0, -3.0, -4.0] and pa9["sine"] == {
            "amplitude": 0.5,
            "frequency": 3.0,
        }
        case = params_of(nbformat.read(tmp_path / "out" / version / "lab_case_study.ipynb", 4))
        assert case["pole"] == 0.1 and case["v"]["seed"] == 9
        missile = params_of(nbformat.read(tmp_path / "out" / version / "lab_missile.ipynb", 4))
        assert missile["pmo_poles"] == [-90.0, -130.0]
    assert PA9Params.from_config(load_config(config)).poles == (-2.0, -3.0, -4.0)


def test_every_config_key_of_a_lab_reaches_its_params(tmp_path):
    """pa9.noise, the seeds, missile.duration/samples, the noise of the missile lab and style."""
    config = tmp_path / "term.toml"
    config.write_text(TERM)
    cfg = load_config(config)
    pa9 = PA9Params.from_config(cfg).to_params()
    assert (pa9["noise"], pa9["seed"], pa9["style"]) == (0.05, 9, "ggplot")
    case = CaseStudyParams.from_config(cfg).to_params()
    assert (case["v"]["seed"], case["pole"], case["style"]) == (9, 0.1, "ggplot")
    missile = MissileParams.from_config(cfg).to_params()
    assert (missile["duration"], missile["samples"]) == (0.4, 8001)
    assert missile["noise"] == {"sigma": 0.02, "seed": 11} and missile["style"] == "ggplot"
    # every key of the config that a lab's experiment declares for its lab is read
    for params in (PA9Params, CaseStudyParams, MissileParams):
        for name, spec in params.declared():
            key = spec.config_key(params.lab, name)
            if key is not None and key != "case_study.poles":
                assert key in cfg, key
    # a style file travels as its settings (the students do not have the file)
    style = tmp_path / "term.mplstyle"
    style.write_text("axes.grid: True\nlines.linewidth: 2  # thicker\n")
    config.write_text(f'style = "{style.name}"\n')
    params = PA9Params.from_config(load_config(config)).to_params()
    assert params["style"] == {"axes.grid": "True", "lines.linewidth": "2"}
    assert PA9Params.from_params(json.loads(json.dumps(params))).to_params() == params


def test_the_checks_follow_the_config_poles():
    """A design for the default poles fails the check of a term with other poles."""
    plant = ut.examples.pa9()
    A, C, E = plant.A, plant.C, plant.E
    H = E @ np.linalg.pinv(C @ E)
    T = np.eye(3) - H @ C
    K1 = ct.place((T @ A).T, C.T, PA9Params().poles).T
    F = T @ A - K1 @ C
    term = PA9Params(poles=(-2.0, -3.0, -4.0)).to_params()
    assert checks.pa9_design(H, T, K1, F, F @ H, poles=PA9Params().to_params()["poles"]).passed
    result = checks.pa9_design(H, T, K1, F, F @ H, poles=term["poles"])
    assert "but the exercise asks for -4, -3, -2" in "\n".join(result.failures)


def test_numbers_that_make_no_fair_lab_are_a_usage_error(tmp_path, capsys):
    config = tmp_path / "term.toml"
    config.write_text("[pa9]\nduration = 1.0\n")
    code = cli.main(["labs", "--out", str(tmp_path / "out"), "--config", str(config)])
    err = capsys.readouterr().err
    # refused before anything is written, by the config check or the lab's own fairness check
    assert code == 2 and "pa9" in err and "duration" in err, err
    assert not (tmp_path / "out").exists()


def test_a_configured_value_the_groups_do_not_keep_is_said(tmp_path, capsys):
    """Each group draws its own poles: the term's poles are not silently dropped, they are named."""
    config = tmp_path / "term.toml"
    config.write_text("[pa9]\npoles = [-2.0, -3.0, -4.0]\n[pa9.sine]\nfrequency = 2.5\n")
    args = ["labs", "--out", str(tmp_path / "out"), "--config", str(config), "-q"]
    assert cli.main(args) == 0
    assert "note" not in capsys.readouterr().err  # one notebook per lab: every value is kept
    assert cli.main([*args, "--groups", "2", "--seed", "4"]) == 0
    err = capsys.readouterr().err
    assert "note: pa9.poles = [-2, -3, -4] is not kept: each group's variant" in err, err
    assert "note: pa9.sine.frequency = 2.5 is not kept" in err, err
    assert "missile" not in err and "case_study" not in err  # nothing of theirs was set


def test_a_configured_value_the_notebooks_do_not_read_is_said():
    cfg = load_config_text("[pa9]\nnoise = 0.05\n")
    (note,) = labs.config_notes(labs.LABS["pa9"], cfg, groups=False)
    assert note.startswith("pa9.noise of the term config reaches the pa9 lab's PARAMS, but its")
    assert labs.config_notes(labs.LABS["missile"], cfg, groups=True) == []


def load_config_text(text: str):
    import tomllib

    from uio_teach.instructor.config import FigureConfig

    return FigureConfig.from_dict(tomllib.loads(text))


# variants per group ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def variants(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("variants")
    assert cli.main(["labs", "--out", str(out), "--groups", "3", "--seed", "5", "-q"]) == 0
    return out


@pytest.mark.slow
def test_groups_give_distinct_notebooks_per_lab_named_by_group(variants):
    for lab in labs.LABS:
        seen = []
        for g in ("g01", "g02", "g03"):
            student = nbformat.read(variants / lab / "student" / f"{lab}_{g}.ipynb", 4)
            solution = nbformat.read(variants / lab / "solution" / f"{lab}_{g}.ipynb", 4)
            assert student.metadata.uio_teach["lab"] == lab
            assert student.metadata.uio_teach["group"] == g
            assert params_of(student) == params_of(solution)
            seen.append(params_of(student))
        assert len({json.dumps(p, sort_keys=True) for p in seen}) == 3


@pytest.mark.slow
def test_every_variant_is_a_fair_exercise(variants):
    for lab in labs.LABS.values():
        for g in ("g01", "g02", "g03"):
            nb = nbformat.read(variants / lab.id / "student" / f"{lab.id}_{g}.ipynb", 4)
            params = lab.params.from_params(params_of(nb))
            assert not params.problems()
    for variant in labs.draw_variants(labs.LABS["pa9"], 30, seed=1):
        poles = np.array(variant.poles, dtype=float)
        assert len(set(poles)) == 3 and np.all(poles <= -1) and np.all(poles >= -6)
        assert abs(variant.sine_amplitude) >= 0.5 and max(map(abs, variant.switch_values)) >= 0.5
    for variant in labs.draw_variants(labs.LABS["case_study"], 30, seed=1):
        assert abs(variant.pole) < 1 and abs(variant.pole - 0.5) >= 0.2


@pytest.mark.slow
def test_the_same_seed_gives_byte_identical_files(variants, tmp_path):
    assert cli.main(["labs", "--out", str(tmp_path), "--groups", "3", "--seed", "5", "-q"]) == 0
    files = sorted(p.relative_to(variants) for p in variants.rglob("*") if p.is_file())
    again = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    assert files == again and len(files) == 3 * 3 * 2 + 2  # and the key, the manifest
    for name in files:
        assert (variants / name).read_bytes() == (tmp_path / name).read_bytes(), name


@pytest.mark.slow
def test_another_seed_gives_other_numbers(variants, tmp_path):
    assert cli.main(["labs", "--out", str(tmp_path), "--groups", "3", "--seed", "6", "-q"]) == 0
    a = nbformat.read(variants / "pa9" / "student" / "pa9_g01.ipynb", 4)
    b = nbformat.read(tmp_path / "pa9" / "student" / "pa9_g01.ipynb", 4)
    assert params_of(a) != params_of(b)


@pytest.mark.slow
def test_the_answer_key_has_one_row_per_lab_and_group_with_the_right_answers(variants):
    with (variants / "answer_key.csv").open(newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert [(r["lab"], r["group"]) for r in rows] == [
        (lab, g) for lab in sorted(labs.LABS) for g in ("g01", "g02", "g03")
    ]
    for row in rows:
        nb = nbformat.read(
            variants / row["lab"] / "solution" / f"{row['lab']}_{row['group']}.ipynb", 4
        )
        assert json.loads(row["params"]) == params_of(nb)
        params = json.loads(row["params"])
        plant = ut.experiments.plant_from_params(row["lab"], params)
        assert "plant" in params  # every group has a plant of its own
        if row["lab"] == "pa9":
            F = np.array(json.loads(row["pa9.F"]))
            assert np.allclose(
                np.sort(np.linalg.eigvals(F).real), sorted(params["poles"]), atol=1e-6
            )
            K1 = np.array(json.loads(row["pa9.K1"]))
            H = np.array(json.loads(row["pa9.H"]))
            T = np.array(json.loads(row["pa9.T"]))
            K2 = np.array(json.loads(row["pa9.K2"]))
            assert checks.pa9_design(
                H, T, K1, F, K2, plant=plant, poles=params["poles"], tol=1e-8
            ).passed
            assert np.allclose(
                K1, ct.place((T @ plant.A).T, plant.C.T, params["poles"]).T, atol=1e-8
            )
        elif row["lab"] == "case_study":
            L = np.array(json.loads(row["case_study.L_pole"]))
            assert checks.case_study_pole(L, params["pole"], plant).passed
            M = np.array(json.loads(row["case_study.M"]))
            assert checks.case_study_projection(M, plant).passed
        else:
            M = np.array(json.loads(row["missile.M"]))
            L = np.array(json.loads(row["missile.L"]))
            F = (np.eye(4) - M @ plant.C) @ plant.A - L @ plant.C
            assert checks.missile_pmo(M, L, F, poles=params["pmo_poles"], plant=plant).passed


def test_groups_need_a_lab_of_the_course_and_sane_numbers(tmp_path, capsys):
    other = tmp_path / "lab_other.md"
    other.write_text((BOOK / "lab_pa9.md").read_text())
    code = cli.main(
        [
            "labs",
            "--out",
            str(tmp_path / "o"),
            "--groups",
            "2",
            "--source",
            str(other),
            "--book",
            str(BOOK),
        ]
    )
    assert code == 2 and "--groups needs a lab of the course" in capsys.readouterr().err
    assert cli.main(["labs", "--out", str(tmp_path / "o"), "--groups", "0"]) == 2
    assert cli.main(["labs", "--out", str(tmp_path / "o"), "--groups", "2", "--seed", "-1"]) == 2
    assert cli.main(["labs", "--out", str(tmp_path / "o"), "--seed", "3"]) == 2
    assert not (tmp_path / "o").exists()


# a group's numbers depend on the seed, its lab and the group only ------------------------------

EXTRA_LAB = """
from uio_teach.worked import ExplorerOptions, LabEntry, WorkedExample
from uio_teach.worked.pa9 import PA9, PA9Params
from uio_teach.examples import pa9

EXAMPLES = (
    WorkedExample(
        name="aaa_probe_lab",
        title="A lab registered before every other",
        plant=pa9,
        experiment=PA9,
        family="uio",
        order=-1,
        explorer=ExplorerOptions(
            period=2.5, pole_limits=(-10, 1), frequency_limits=(0, 10),
            period_limits=(0.25, 5), static_values=(-1.0,),
        ),
        lab=LabEntry("lab_aaa_probe.md", PA9Params, ()),
    ),
)
"""


def every_groups_numbers(seed: int) -> dict:
    return {
        lab_id: [v.to_params() for v in labs.draw_variants(lab, 3, seed=seed)]
        for lab_id, lab in labs.LABS.items()
        if lab_id != "aaa_probe_lab"
    }


def test_registering_a_lab_before_the_others_changes_no_groups_numbers(tmp_path, monkeypatch):
    """The draw is keyed by the lab's id, not its place: an answer key stays right."""
    import importlib
    import sys

    from uio_teach.worked import discover

    before = every_groups_numbers(seed=2027)
    package = tmp_path / "probe_labs"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "probe.py").write_text(EXTRA_LAB)
    monkeypatch.syspath_prepend(str(tmp_path))
    importlib.invalidate_caches()
    discover("probe_labs")
    try:
        assert list(labs.LABS)[0] == "aaa_probe_lab"  # first: every other lab moved one place
        assert every_groups_numbers(seed=2027) == before
    finally:
        discover("probe_labs", remove=True)
        for name in [m for m in sys.modules if m.split(".")[0] == "probe_labs"]:
            del sys.modules[name]
    assert "aaa_probe_lab" not in labs.LABS


def test_a_lab_draws_from_a_stream_of_its_own():
    """Two labs with the same parameter class draw different groups under one seed."""
    from uio_teach.instructor.lab_registry import Lab

    pa9 = labs.LABS["pa9"]
    twin = Lab("pa9_twin", pa9.source, pa9.params, pa9.check_ids)
    assert [v.to_params() for v in labs.draw_variants(twin, 2, seed=1)] != [
        v.to_params() for v in labs.draw_variants(pa9, 2, seed=1)
    ]


def test_a_draw_that_cannot_vary_says_what_collided():
    """Not "poles or plant" whatever it was: the message names what every draw shared."""
    from uio_teach.instructor.lab_registry import Lab

    class Still(PA9Params):
        @classmethod
        def vary(cls, rng, base):
            return {"noise": 0.1}  # the poles and the plant stay the course's

    still = Lab("still", "lab_pa9.md", Still, ())
    with pytest.raises(labs.LabUsageError, match=r"cannot draw 1 distinct variants") as err:
        labs.draw_variants(still, 1, seed=1)
    message = str(err.value)
    assert "draws shared their poles with the book" in message, message
    assert "draws shared their plant with the book" in message, message
    assert "params" not in message.split("(", 1)[1], message  # the noise differed
