"""`uio-teach figures` over an existing folder: checked first, written all at once, with a manifest.

A term's configuration is checked whole before anything is written (every problem on its own
line, exit 2); the figures go into a temporary folder beside the target that replaces it only
when every figure was made; a folder that is not an earlier output is never replaced.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import pytest

from uio_teach.instructor import cli, figures, output
from uio_teach.instructor.config import MAX_SAMPLES, ConfigError, FigureConfig, load_config

FAST = ["case_error", "missile_table2"]  # two quick outputs: a figure and a table


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (relative name -> bytes), hidden ones included."""
    return {
        os.fspath(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def make(out: Path, *extra: str) -> int:
    return cli.main(["figures", "--out", str(out), "-q", "--dpi", "30", "--only", *FAST, *extra])


@pytest.fixture
def last_term(tmp_path) -> Path:
    """A folder made by an earlier run, plus a figure that this term no longer makes."""
    folder = tmp_path / "figures"
    assert make(folder) == 0
    (folder / "old_figure.png").write_bytes(b"last term")
    return folder


def test_late_failures_of_old_are_config_errors_before_anything_is_written(
    tmp_path, last_term, capsys
):
    config = tmp_path / "term.toml"
    config.write_text(
        "seed = -1\n[pa9]\nsamples = 1000000000000\nnoise = -2\n"
        "[missile]\nsamples = 200000000\nduration = 0.0\n"
    )
    before = snapshot(tmp_path)
    code = cli.main(["figures", "--out", str(last_term), "--config", str(config)])
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 5, err  # every problem, one line each
    assert all(line.startswith(f"uio-teach figures: error: {config}: ") for line in lines)
    for key, words in [
        ("seed", "must be >= 0, got -1"),
        ("pa9.samples", f"must be <= {MAX_SAMPLES}"),
        ("pa9.noise", "must be >= 0"),
        ("missile.samples", f"must be <= {MAX_SAMPLES}"),
        ("missile.duration", "must be > 0"),
    ]:
        assert any(f": {key}: {words}" in line for line in lines), (key, err)
    assert snapshot(tmp_path) == before  # the old folder exactly as it was, nothing beside it


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("seed = 4294967296\n", "seed: must be <= 4.29497e+09"),
        ("[pa9]\nduration = 1e9\n", "pa9.duration: must be <= 10000"),
        ("[pa9.sine]\namplitude = 1e300\n", "pa9.sine.amplitude: must be between"),
        ("[pa9.sine]\nfrequency = 1000.0\n", "pa9.sine.frequency: 1000 rad/s is too fast"),
        ("[pa9.piecewise]\ntimes = [0, 2, 5, 12]\n", "not before the end of the run"),
        ("[pa9]\npoles = [-1, -1, -1]\n", "pa9.poles: -1 is repeated 3 times but only 2"),
        ("[pa9]\npoles = [-1, -2, -1e7]\n", "faster than"),
        ("[missile]\npmo_poles = [-100, nan]\n", "missile.pmo_poles[1]: expected a finite"),
        ("[case_study]\nsteps = 100001\n", "case_study.steps: must be <= 100000"),
        ("[case_study.u2]\nfrequency = 4.0\n", "case_study.u2.frequency: must be <= 3.14159"),
        ("[case_study.v]\nhold = 50\n", "case_study.v.hold: 50 steps is longer than the run"),
        ('style = "missing.mplstyle"\n', "style: no such file"),
    ],
)
def test_every_value_has_a_range(tmp_path, text, expected):
    config = tmp_path / "term.toml"
    config.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_config(config)
    assert len(info.value.problems) == 1, info.value.problems
    assert expected in info.value.problems[0]


def test_a_style_file_is_read_beside_the_config_file(tmp_path, monkeypatch):
    folder = tmp_path / "course"
    folder.mkdir()
    (folder / "x.mplstyle").write_text("lines.linewidth : 3\n")
    (folder / "term.toml").write_text('style = "x.mplstyle"\n')
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # the style file is not in the current folder
    cfg = load_config(Path("..") / "course" / "term.toml")
    assert Path(cfg["style"]) == (folder / "x.mplstyle").resolve()
    assert make(elsewhere / "out", "--config", str(folder / "term.toml")) == 0
    manifest = json.loads((elsewhere / "out" / output.MANIFEST).read_text())
    assert manifest["config"]["style"] == os.fspath((folder / "x.mplstyle").resolve())


def test_a_good_run_over_last_term_leaves_only_this_terms_files(tmp_path, last_term):
    config = tmp_path / "term.toml"
    config.write_text("seed = 11\n[missile]\npmo_poles = [-90, -140]\n")
    assert make(last_term, "--config", str(config)) == 0
    names = {p.name for p in last_term.iterdir()}
    assert names == {"case_error.png", "missile_table2.csv", "missile_table2.md", output.MANIFEST}
    assert sorted(os.listdir(tmp_path)) == ["figures", "term.toml"]  # no temporary left
    manifest = json.loads((last_term / output.MANIFEST).read_text())
    assert manifest["config"]["seed"] == 11
    assert manifest["config"]["missile.pmo_poles"] == [-90.0, -140.0]
    assert manifest["options"]["config_file"] == str(config)
    canonical = json.dumps(manifest["config"], sort_keys=True, separators=(",", ":"))
    assert manifest["config_sha256"] == hashlib.sha256(canonical.encode()).hexdigest()
    listed = {f["name"]: f for f in manifest["files"]}
    assert set(listed) == names - {output.MANIFEST}
    for name, entry in listed.items():
        data = (last_term / name).read_bytes()
        assert entry["sha256"] == hashlib.sha256(data).hexdigest()
        assert entry["bytes"] == len(data)
    for library in ("python", "uio-teach", "numpy", "scipy", "control", "matplotlib"):
        assert manifest["versions"][library]


@pytest.mark.parametrize("how", ["exception", "interrupt", "failed figure"])
def test_a_run_that_fails_midway_leaves_the_folder_exactly_as_it_was(
    tmp_path, last_term, monkeypatch, how
):
    before = snapshot(tmp_path)
    if how == "failed figure":

        def broken(runs):
            raise ValueError("broken on purpose")

        specs = dict(figures.FIGURES)
        specs["missile_table2"] = figures.FigureSpec("missile_table2", "broken", broken, True)
        monkeypatch.setattr(figures, "FIGURES", specs)
        assert make(last_term) == 1
    else:
        error = OSError(28, "No space left on device") if how == "exception" else KeyboardInterrupt

        def fail(*args, **kwargs):
            raise error

        monkeypatch.setattr(figures, "write_manifest", fail)
        code = make(last_term)
        assert code == (1 if how == "exception" else 130)
    assert snapshot(tmp_path) == before


def test_a_folder_that_is_not_an_earlier_output_is_left_alone(tmp_path, capsys):
    mine = tmp_path / "thesis"
    mine.mkdir()
    (mine / "chapter1.tex").write_text("my work")
    code = make(mine)
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1
    assert f"the output folder {mine} is not empty and has no {output.MANIFEST}" in err
    assert [p.name for p in mine.iterdir()] == ["chapter1.tex"]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert make(empty) == 0 and (empty / output.MANIFEST).is_file()
    forged = tmp_path / "forged"
    forged.mkdir()
    (forged / output.MANIFEST).write_text('{"generator": "someone else"}')
    assert make(forged) == 1


def test_the_same_run_gives_the_same_manifest(tmp_path):
    for name in ("a", "b"):
        assert make(tmp_path / name) == 0
    a = (tmp_path / "a" / output.MANIFEST).read_bytes()
    assert a == (tmp_path / "b" / output.MANIFEST).read_bytes()
    assert str(tmp_path).encode() not in a  # no path of the machine, no time stamp


def test_config_errors_list_every_problem_in_python_too():
    with pytest.raises(ConfigError) as info:
        FigureConfig.from_dict({"seed": -3, "pa9": {"poles": [1, -2, -3], "pole": 1}}, "t.toml")
    problems = info.value.problems
    assert len(problems) == 3 and str(info.value).count("\n") == 2
    assert problems[0].startswith("t.toml: seed: must be >= 0")
    assert "the pole 1 is unstable" in problems[1]
    assert "unknown key 'pa9.pole'" in problems[2]
