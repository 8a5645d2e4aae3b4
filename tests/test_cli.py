"""`uio-teach figures`: every figure made, byte for byte the same twice, clear errors.

Most tests call :func:`uio_teach.cli.main` in-process (fast); one runs
``python -m uio_teach figures --list`` in a subprocess to prove the entry point.
"""

from __future__ import annotations

import csv
import os
import re
import shutil
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest

import uio_teach as ut
from uio_teach.instructor import cli, figures

ALL = list(figures.FIGURES)
TABLES = [name for name, spec in figures.FIGURES.items() if spec.table]


def expected_files(names: list[str], fmt: str = "png") -> set[str]:
    out = {figures.MANIFEST}
    for name in names:
        if figures.FIGURES[name].table:
            out |= {f"{name}.csv", f"{name}.md"}
        else:
            out |= {f"{name}.{fmt}", f"{name}.txt"}  # the picture and its words
    return out


def run(argv: list[str], capsys) -> tuple[int, str, str]:
    code = cli.main(argv)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory) -> dict:
    """All figures, twice, into two folders (how long it takes: benchmarks/bench_figures.py)."""
    base = tmp_path_factory.mktemp("figures")
    out = {}
    for label in ("first", "second"):
        folder = base / label
        code = cli.main(["figures", "--out", str(folder), "-q"])
        out[label] = (code, folder)
    return out


# --list, --help, the entry point ----------------------------------------------------------------


def test_list_names_every_figure_with_a_description(capsys):
    code, out, err = run(["figures", "--list"], capsys)
    assert code == 0 and err == ""
    lines = out.strip().splitlines()
    assert len(lines) == len(ALL)
    for line, (name, spec) in zip(lines, figures.FIGURES.items(), strict=True):
        assert line.split()[0] == name
        assert spec.description in line
        assert len(spec.description) < 100  # one line
    for group in ("pa9_", "case_", "missile_"):
        assert any(name.startswith(group) for name in ALL)


@pytest.mark.subprocess
def test_python_dash_m_entry_point_lists_the_figures():
    proc = subprocess.run(
        [sys.executable, "-m", "uio_teach", "figures", "--list"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    assert [line.split()[0] for line in proc.stdout.strip().splitlines()] == ALL


@pytest.mark.subprocess
def test_console_script_is_declared():
    pyproject = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    assert pyproject["project"]["scripts"]["uio-teach"] == "uio_teach.instructor.cli:main"
    script = shutil.which("uio-teach", path=str(Path(sys.executable).parent))
    if script is None:
        pytest.skip("the package is not reinstalled yet (make venv): no uio-teach script")
    proc = subprocess.run([script, "--version"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0 and ut.__version__ in proc.stdout


@pytest.mark.parametrize("argv", [["--help"], ["figures", "--help"], ["labs", "--help"]])
def test_help_exits_0_and_reads_like_a_manual(argv, capsys):
    code, out, _ = run(argv, capsys)
    assert code == 0
    assert out.startswith("usage: uio-teach")
    assert "examples:" in out and "exit status:" in out
    if argv[0] == "figures":
        for option in ("--out", "--format", "--only", "--dpi", "--config", "--list"):
            assert option in out
        assert "png,pdf,svg" in out and "TOML" in out and "[pa9.sine]" in out
    if argv[0] == "labs":
        assert "--out" in out and "student" in out and "solution" in out


def test_usage_errors_exit_2(capsys):
    assert cli.main([]) == 2
    assert cli.main(["figures", "--format", "gif", "--out", "x"]) == 2
    for dpi in ("0", "1", "19", "1201", "100000", "-5", "1.5", "many"):
        code, _, err = run(["figures", "--dpi", dpi, "--out", "x"], capsys)
        assert code == 2 and "--dpi" in err and "Traceback" not in err, dpi
    assert not Path("x").exists()
    code, _, err = run(["figures"], capsys)
    assert code == 2 and "--out" in err
    code, _, err = run(["figures", "--out", "x", "--only", "pa9_sin"], capsys)
    assert code == 2
    assert err.strip() == (
        "uio-teach figures: error: unknown figure 'pa9_sin' (did you mean 'pa9_sine'?); "
        "`uio-teach figures --list` names them all"
    )


# making the figures ------------------------------------------------------------------------------


@pytest.mark.slow
def test_running_figures_creates_every_file(two_runs):
    code, folder = two_runs["first"]
    assert code == 0
    made = {p.name for p in folder.iterdir()}
    assert made == expected_files(ALL)
    for name in made - {figures.MANIFEST}:
        path = folder / name
        text = name.startswith(tuple(TABLES)) or name.endswith(".txt")  # a table, a figure's words
        assert path.stat().st_size > (200 if text else 5000), name
        if name.endswith(".png"):
            assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_a_second_run_is_byte_identical(two_runs):
    (_, first), (_, second) = two_runs["first"], two_runs["second"]
    names = sorted(p.name for p in first.iterdir())
    assert names == sorted(p.name for p in second.iterdir())
    for name in names:
        assert (first / name).read_bytes() == (second / name).read_bytes(), name


@pytest.mark.parametrize("fmt", ["pdf", "svg"])
@pytest.mark.slow
def test_vector_formats_are_deterministic_too(fmt, tmp_path):
    names = ["pa9_luenberger", "case_error"]
    for run_ in ("a", "b"):
        assert (
            cli.main(
                ["figures", "--out", str(tmp_path / run_), "--format", fmt, "-q"]
                + ["--only", *names]
            )
            == 0
        )
    for name in names:
        a = (tmp_path / "a" / f"{name}.{fmt}").read_bytes()
        assert a == (tmp_path / "b" / f"{name}.{fmt}").read_bytes()
        assert b"CreationDate" not in a and b"<dc:date>" not in a


def test_only_restricts_and_progress_lines_and_summary(tmp_path, capsys):
    code, out, err = run(
        ["figures", "--out", str(tmp_path), "--only", "case_error", "missile_table2"], capsys
    )
    assert code == 0 and err == ""
    assert {p.name for p in tmp_path.iterdir()} == expected_files(["case_error", *TABLES])
    lines = out.strip().splitlines()
    assert lines[0].startswith("[1/2] case_error: ") and lines[0].endswith(" s)")
    assert lines[1].startswith("[2/2] missile_table2: ")
    assert lines[2].startswith(
        f"2 of 2 figures (4 files) and {figures.MANIFEST} written to {tmp_path} in "
    )


def test_dpi_sets_the_pixel_size(tmp_path):
    from matplotlib.image import imread

    for dpi in (50, 100):
        cli.main(
            [
                "figures",
                "--out",
                str(tmp_path / str(dpi)),
                "--only",
                "case_error",
                "--dpi",
                str(dpi),
                "-q",
            ]
        )
    small = imread(tmp_path / "50" / "case_error.png").shape
    large = imread(tmp_path / "100" / "case_error.png").shape
    assert large[0] == 2 * small[0] and large[1] == 2 * small[1]


@pytest.mark.slow
def test_table_ii_holds_catch_times_computed_with_catch_time(two_runs):
    _, folder = two_runs["first"]
    with open(folder / "missile_table2.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    pub = ut.examples.MISSILE_PUBLISHED
    assert [r["signal"] for r in rows] == ["x1", "x2", "x3", "x4", "v1", "v2"]
    for r in rows:
        assert float(r["pmo_paper_s"]) == pub.catch_pmo[r["signal"]]
        assert float(r["ginverse_paper_s"]) == pub.catch_ginverse[r["signal"]]
    # recompute the g-inverse column with the public API, as the table says
    plant = ut.examples.missile_autopilot()
    cfg = figures.FigureConfig()
    t = np.linspace(0, cfg["missile.duration"], cfg["missile.samples"])
    # both observers start from q(0) = -M y(0), as the figures command documents
    q0 = -ut.design_pmo(plant, poles=cfg["missile.pmo_poles"]).M @ plant.C @ pub.x0
    resp = ut.simulate(
        plant,
        ut.design_ginverse(plant),
        t,
        d=ut.examples.missile_inputs(),
        initial_state=pub.x0,
        observer_state=q0,
    )
    est = ut.reconstruct_input(plant, resp)
    expected = list(ut.catch_time(t, resp.states, resp.estimates, tol=0.02)) + list(
        ut.catch_time(t, resp.inputs.d, est.estimates, tol=0.02)
    )
    got = [float(r["ginverse_computed_s"]) for r in rows]
    np.testing.assert_allclose(got, expected, atol=5e-5)
    assert 0 < got[2] < 0.1 and 0 < got[3] < 0.1  # x3, x4 converge within 0.1 s
    markdown = (folder / "missile_table2.md").read_text()
    assert "| signal | PMO, computed | PMO, paper |" in markdown
    assert markdown.count("\n| x") == 4 and markdown.count("\n| v") == 2


# configuration ----------------------------------------------------------------------------------


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "term.toml"
    path.write_text(text)
    return path


BAD_CONFIGS = {
    "unknown key": ("[pa9]\npole = [-1, -2, -3]\n", "unknown key 'pa9.pole' (did you mean"),
    "unknown table": ("[pa10]\npoles = [-1]\n", "unknown table [pa10] (did you mean [pa9]?)"),
    "wrong type": ('[pa9.sine]\namplitude = "big"\n', "pa9.sine.amplitude: expected a number"),
    "bool is no int": ("seed = true\n", "seed: expected an integer, got the boolean true"),
    "wrong pole count": ("[pa9]\npoles = [-1, -2]\n", "pa9.poles: expected 3 poles"),
    "unstable pole": ("[pa9]\npoles = [-1, 2, -3]\n", "pa9.poles: the pole 2 is unstable"),
    "unstable discrete pole": (
        "[case_study]\npoles = [1.2]\n",
        "case_study.poles: the pole 1.2 is unstable",
    ),
    "missing conjugate": ('[pa9]\npoles = ["-1+1j", -2, -3]\n', "no conjugate partner"),
    "bad complex": ('[pa9]\npoles = ["minus one", -2, -3]\n', "cannot read the pole"),
    "wrong length": ("[pa9]\ninitial_state = [1, 2]\n", "pa9.initial_state: expected 3"),
    "mismatched piecewise": (
        "[pa9.piecewise]\ntimes = [0, 1]\n",
        "times and values must have the same length",
    ),
    "decreasing times": (
        "[pa9.piecewise]\ntimes = [0, 2, 1, 3]\n",
        "must be strictly increasing",
    ),
    "negative noise": ("[pa9]\nnoise = -0.1\n", "pa9.noise: must be >= 0"),
    "unknown style": ('style = "ggplott"\n', "did you mean 'ggplot'"),
    "not TOML": ("[pa9\n", "not valid TOML"),
    "negative seed": ("seed = -1\n", "seed: must be >= 0, got -1"),
    "too many samples": ("[pa9]\nsamples = 1000000000000\n", "pa9.samples: must be <= 200000"),
    "pole on the imaginary axis": (
        "[pa9]\npoles = [-1, 0, -3]\n",
        "pa9.poles: the pole 0 is unstable",
    ),
    "table as value": ("pa9 = 3\n", "pa9: expected a table"),
}


@pytest.mark.parametrize("case", list(BAD_CONFIGS))
def test_a_bad_config_gives_one_line_and_exit_2(case, tmp_path, capsys):
    text, expected = BAD_CONFIGS[case]
    config = write(tmp_path, text)
    out_dir = tmp_path / "out"
    code, out, err = run(["figures", "--out", str(out_dir), "--config", str(config)], capsys)
    assert code == 2
    assert out == ""
    assert err.endswith("\n") and err.count("\n") == 1, err  # exactly one line
    assert err.startswith(f"uio-teach figures: error: {config}: ")
    assert expected in err
    assert "Traceback" not in err
    assert not out_dir.exists()  # nothing is made before the configuration is known good


@pytest.mark.slow
def test_a_triple_pole_makes_every_figure(tmp_path, capsys):
    # repeated poles are valid: the designs place them (a single-output design on w C)
    config = write(tmp_path, "[pa9]\npoles = [-1, -1, -1]\n")
    out_dir = tmp_path / "out"
    code, _, err = run(["figures", "--out", str(out_dir), "--config", str(config), "-q"], capsys)
    assert code == 0, err
    assert {p.name for p in out_dir.iterdir()} == expected_files(ALL)


def test_a_missing_config_file_is_a_config_error(tmp_path, capsys):
    code, _, err = run(["figures", "--out", str(tmp_path), "--config", "nope.toml"], capsys)
    assert code == 2 and err.strip() == "uio-teach figures: error: nope.toml: no such file"


def test_print_config_is_a_valid_commented_default_config(capsys):
    code, out, _ = run(["figures", "--print-config"], capsys)
    assert code == 0
    data = tomllib.loads(out)
    assert figures.FigureConfig.from_dict(data) == figures.FigureConfig()
    for key in figures.FigureConfig():
        assert key.rpartition(".")[2] in out
    assert all("#" in line for line in out.splitlines() if "=" in line)  # every key explained


@pytest.mark.slow
def test_a_config_changes_the_figures_it_concerns(tmp_path, two_runs):
    config = write(
        tmp_path,
        'seed = 11\n[pa9]\npoles = ["-1+1j", "-1-1j", -2]\nnoise = 0.01\n'
        "[pa9.sine]\namplitude = 3.0\nfrequency = 0.5\n",
    )
    cfg = figures.load_config(config)
    assert cfg["pa9.poles"] == (complex(-1, 1), complex(-1, -1), -2)
    assert cfg["pa9.sine.amplitude"] == 3.0 and cfg["seed"] == 11
    out = tmp_path / "out"
    names = ["pa9_sine", "missile_table2"]
    assert (
        cli.main(["figures", "--out", str(out), "--config", str(config), "-q", "--only", *names])
        == 0
    )
    default = two_runs["first"][1]
    assert (out / "pa9_sine.png").read_bytes() != (default / "pa9_sine.png").read_bytes()
    assert (out / "missile_table2.md").read_bytes() == (default / "missile_table2.md").read_bytes()


@pytest.mark.slow
def test_the_noise_is_seeded(tmp_path):
    config = write(tmp_path, "seed = 3\n[pa9]\nnoise = 0.05\n")
    for label in ("a", "b"):
        argv = ["figures", "--out", str(tmp_path / label), "--only", "pa9_sine", "-q"]
        assert cli.main([*argv, "--config", str(config)]) == 0
    assert (tmp_path / "a" / "pa9_sine.png").read_bytes() == (
        tmp_path / "b" / "pa9_sine.png"
    ).read_bytes()


# failures ---------------------------------------------------------------------------------------


def test_an_unwritable_out_fails_with_a_clear_message(tmp_path, capsys):
    a_file = tmp_path / "a-file"
    a_file.write_text("not a folder")
    code, out, err = run(["figures", "--out", str(a_file / "figs")], capsys)
    assert code == 1 and out == ""
    assert err.count("\n") == 1
    assert err.startswith(f"uio-teach figures: error: cannot create the output folder {a_file}")
    code, _, err = run(["figures", "--out", str(a_file)], capsys)
    assert code == 1 and "is a file, not a folder" in err and err.count("\n") == 1


def test_a_failing_figure_is_reported_and_nothing_is_written(tmp_path, capsys, monkeypatch):
    def broken(runs):
        raise RuntimeError("the plotter ran out of ink\nsecond line")

    specs = dict(figures.FIGURES)
    specs["pa9_sine"] = figures.FigureSpec("pa9_sine", "broken on purpose", broken)
    monkeypatch.setattr(figures, "FIGURES", MappingProxyType(specs))
    out = tmp_path / "figs"
    code, stdout, err = run(
        ["figures", "--out", str(out), "--only", "pa9_sine", "case_error"], capsys
    )
    assert code == 1
    assert not out.exists()  # the figure that worked is not left alone in a new folder
    assert os.listdir(tmp_path) == []  # and no temporary folder is left beside it
    lines = err.strip().splitlines()
    assert lines[0] == (
        "uio-teach figures: error: pa9_sine failed: RuntimeError: the plotter ran out of ink "
        "second line"
    )
    assert lines[1].startswith("uio-teach figures: error: 1 of 2 figures made, failed: pa9_sine")
    assert lines[1].endswith("nothing was written, " + str(out) + " not created")
    assert "[2/2] case_error" in stdout


def test_generate_rejects_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match="unknown figure"):
        figures.generate(tmp_path, ["nope"])
    with pytest.raises(ValueError, match="fmt"):
        figures.generate(tmp_path, fmt="gif")
    with pytest.raises(ValueError, match="dpi"):
        figures.generate(tmp_path, dpi=0)


def test_the_sample_configurations_in_the_docs_are_valid(tmp_path):
    page = (Path(__file__).parents[1] / "book" / "instructors.md").read_text()
    sample = re.search(r"```toml\n(.*?)```", page, re.DOTALL).group(1)
    cfg = figures.FigureConfig.from_dict(tomllib.loads(sample), source="instructors.md")
    assert cfg["pa9.poles"] == (complex(-1, 1), complex(-1, -1), -3)
    assert cfg["missile.pmo_poles"] == (-100, -150)
    help_text = cli.build_parser()._subparsers._group_actions[0].choices["figures"].epilog
    block = help_text.split("a configuration file (term.toml):\n")[1].split("\n\n")[0]
    cfg = figures.FigureConfig.from_dict(tomllib.loads(textwrap.dedent(block)), source="--help")
    assert cfg["seed"] == 7 and cfg["pa9.piecewise.values"] == (1.0, -2.0, 0.5)
    for line in re.findall(r"^uio-teach figures: error: term\.toml: (.*)$", page, re.M):
        assert any(expected in line for _, expected in BAD_CONFIGS.values()), line


def test_labs_without_the_instructor_extra_say_what_to_install(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "jupytext", None)  # as if it were not installed
    code, out, err = run(["labs", "--out", str(tmp_path / "labs")], capsys)
    assert code == 1 and "Traceback" not in err
    assert err.strip() == (
        "uio-teach labs: error: the lab notebooks need jupytext, which is not installed: "
        "pip install 'uio-teach[instructor]' (in a checkout, `make venv` installs it)"
    )
