"""`uio-teach figures` over an existing folder: checked first, written all at once, with a manifest.

A term's configuration is checked whole before anything is written (every problem on its own
line, exit 2); the figures go into a temporary folder beside the target that replaces it only
when every figure was made; a folder that is not an earlier output is never replaced.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import signal
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from uio_teach import folders
from uio_teach.instructor import cli, figures
from uio_teach.instructor.config import MAX_SAMPLES, ConfigError, FigureConfig, load_config

FAST = ["case_error", "missile_table2"]  # two quick outputs: a figure and a table

SLOW = pytest.mark.slow  # each a process killed and two full runs: CI runs them all


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
        ("seed = 4294967296\n", "seed: must be <= 4294967295, got 4294967296"),
        ("[pa9]\nduration = 1e9\n", "pa9.duration: must be <= 10000"),
        ("[pa9.sine]\namplitude = 1e300\n", "pa9.sine.amplitude: must be between"),
        ("[pa9.sine]\nfrequency = 1000.0\n", "pa9.sine.frequency: 1000 rad/s is too fast"),
        ("[pa9.piecewise]\ntimes = [0, 2, 5, 12]\n", "not before the end of the run"),
        ("[pa9]\npoles = [-1, -2, -3, -4]\n", "pa9.poles: expected 3 poles"),
        ("[pa9]\npoles = [-1, -2, -1e7]\n", "faster than"),
        ("[missile]\npmo_poles = [-100, nan]\n", "missile.pmo_poles[1]: expected a finite"),
        ("[case_study]\nsteps = 100001\n", "case_study.steps: must be <= 100000"),
        ("[case_study.d]\nfrequency = 4.0\n", "case_study.d.frequency: must be <= 3.14159"),
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
    manifest = json.loads((elsewhere / "out" / folders.MANIFEST).read_text())
    assert manifest["config"]["style"] == os.fspath((folder / "x.mplstyle").resolve())


@pytest.mark.slow
def test_a_good_run_over_last_term_leaves_only_this_terms_files(tmp_path, last_term):
    config = tmp_path / "term.toml"
    config.write_text("seed = 11\n[missile]\npmo_poles = [-90, -140]\n")
    assert make(last_term, "--config", str(config)) == 0
    names = {p.name for p in last_term.iterdir()}
    assert names == {
        "case_error.png",
        "case_error.txt",
        "missile_table2.csv",
        "missile_table2.md",
        folders.MANIFEST,
    }
    assert sorted(os.listdir(tmp_path)) == ["figures", "term.toml"]  # no temporary left
    manifest = json.loads((last_term / folders.MANIFEST).read_text())
    assert manifest["config"]["seed"] == 11
    assert manifest["config"]["missile.pmo_poles"] == [-90.0, -140.0]
    assert manifest["options"]["config_file"] == str(config)
    canonical = json.dumps(manifest["config"], sort_keys=True, separators=(",", ":"))
    assert manifest["config_sha256"] == hashlib.sha256(canonical.encode()).hexdigest()
    listed = {f["name"]: f for f in manifest["files"]}
    assert set(listed) == names - {folders.MANIFEST}
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
    assert f"the output folder {mine} is not empty and has no {folders.MANIFEST}" in err
    assert [p.name for p in mine.iterdir()] == ["chapter1.tex"]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert make(empty) == 0 and (empty / folders.MANIFEST).is_file()
    forged = tmp_path / "forged"
    forged.mkdir()
    (forged / folders.MANIFEST).write_text('{"generator": "someone else"}')
    assert make(forged) == 1


@pytest.mark.slow
def test_the_same_run_gives_the_same_manifest(tmp_path):
    for name in ("a", "b"):
        assert make(tmp_path / name) == 0
    a = (tmp_path / "a" / folders.MANIFEST).read_bytes()
    assert a == (tmp_path / "b" / folders.MANIFEST).read_bytes()
    assert str(tmp_path).encode() not in a  # no path of the machine, no time stamp


def test_config_errors_list_every_problem_in_python_too():
    with pytest.raises(ConfigError) as info:
        FigureConfig.from_dict({"seed": -3, "pa9": {"poles": [1, -2, -3], "pole": 1}}, "t.toml")
    problems = info.value.problems
    assert len(problems) == 3 and str(info.value).count("\n") == 2
    assert problems[0].startswith("t.toml: seed: must be >= 0")
    assert "the pole 1 is unstable" in problems[1]
    assert "unknown key 'pa9.pole'" in problems[2]


# all or nothing under SIGKILL, locks, leftovers, permissions ----------------------------------

ROOT = Path(__file__).resolve().parents[1]
PA9_LAB = ROOT / "book" / "lab_pa9.md"


def leftovers(parent: Path) -> list[str]:
    """What a run may leave beside its folder: staging folders and lock files."""
    return sorted(p.name for p in parent.iterdir() if p.name.startswith("."))


# A child process that runs the command line and kills itself (SIGKILL) at the k-th step of
# its staged output (a file written, a point of the swap): the package's steps do nothing.
_KILLER = """
import os, signal, sys
from uio_teach import folders
from uio_teach.instructor import cli
count = 0
def step():
    global count
    count += 1
    if count == int(sys.argv[1]):
        os.kill(os.getpid(), signal.SIGKILL)
folders._step = step
sys.exit(cli.main(sys.argv[2:]))
"""


def uio_teach(*argv: str, kill_at: int | None = None, **kwargs) -> subprocess.CompletedProcess:
    """``python -m uio_teach ARGV`` in a child process (killed at its step ``kill_at``)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), *sys.path]))
    if kill_at is None:
        command = [sys.executable, "-m", "uio_teach", *argv]
    else:
        command = [sys.executable, "-c", _KILLER, str(kill_at), *argv]
    return subprocess.run(
        command,
        capture_output=True,
        text=True,
        env=env,
        check=False,
        **kwargs,
    )


def labs_argv(out: Path, groups: int) -> list[str]:
    return ["labs", "--out", str(out), "--source", str(PA9_LAB), "--groups", str(groups), "-q"]


def figures_argv(out: Path, seed: int, config_dir: Path | None = None) -> list[str]:
    """A figures run whose files depend on ``seed`` (missile_table2's noise)."""
    config = (config_dir or out.parent) / f"seed{seed}.toml"
    config.write_text(f"seed = {seed}\n")
    return [
        "figures", "--out", str(out), "-q", "--dpi", "30", "--config", str(config),
        "--only", *FAST,
    ]  # fmt: skip


@pytest.fixture(scope="module")
def lab_sets(tmp_path_factory) -> dict:
    """The old set (3 groups) and the new set (2 groups) of a pa9 labs run, made in this process."""
    base = tmp_path_factory.mktemp("lab_sets")
    sets = {}
    for name, groups in (("old", 3), ("new", 2)):
        assert cli.main(labs_argv(base / name, groups)) == 0
        sets[name] = snapshot(base / name)
    return sets


# steps of `labs --source lab_pa9.md --groups 2`: 4 notebooks (1-4), the key (5), the manifest
# (6), the swap: before it (7), after it, before the old set is removed (8)
# the step inside the swap (7) in `make test`, every other step in the slow set (`make test-slow`)
@pytest.mark.parametrize("kill_at", [7, *(pytest.param(k, marks=SLOW) for k in (1, 3, 5, 6, 8))])
@pytest.mark.subprocess
def test_labs_killed_at_any_step_leave_the_old_set_or_the_new_set(tmp_path, lab_sets, kill_at):
    out = tmp_path / "labs"
    assert cli.main(labs_argv(out, 3)) == 0
    assert snapshot(out) == lab_sets["old"]
    proc = uio_teach(*labs_argv(out, 2), kill_at=kill_at)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    now = snapshot(out)
    assert now == (lab_sets["new"] if kill_at == 8 else lab_sets["old"])  # never a mix
    assert leftovers(tmp_path)  # the killed run left its staging folder or lock behind
    # the next run cleans them and writes the new set
    assert cli.main(labs_argv(out, 2)) == 0
    assert snapshot(out) == lab_sets["new"]
    assert leftovers(tmp_path) == []


def test_a_labs_rerun_with_fewer_groups_leaves_no_notebook_of_the_earlier_run(tmp_path, lab_sets):
    out = tmp_path / "labs"
    assert cli.main(labs_argv(out, 3)) == 0
    assert (out / "pa9" / "student" / "pa9_g03.ipynb").is_file()
    assert cli.main(labs_argv(out, 2)) == 0
    assert snapshot(out) == lab_sets["new"]
    assert not list(out.rglob("*_g03*"))
    manifest = json.loads((out / folders.MANIFEST).read_text())
    names = {f["name"] for f in manifest["files"]}
    assert names == set(lab_sets["new"]) - {folders.MANIFEST}
    assert "pa9/student/pa9_g01.ipynb" in names and "answer_key.csv" in names
    for entry in manifest["files"]:
        data = (out / entry["name"]).read_bytes()
        assert entry["sha256"] == hashlib.sha256(data).hexdigest()
    assert manifest["command"] == "uio-teach labs"
    assert manifest["options"]["groups"] == 2 and manifest["versions"]["uio-teach"]


def test_labs_leave_a_folder_that_is_not_ours_alone(tmp_path, capsys):
    mine = tmp_path / "handout"
    mine.mkdir()
    (mine / "syllabus.pdf").write_bytes(b"%PDF mine")
    code = cli.main(labs_argv(mine, 2))
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1
    assert "is not empty and has no manifest.json" in err
    assert snapshot(mine) == {"syllabus.pdf": b"%PDF mine"}
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize("command", ["labs", "figures"])
def test_a_second_run_into_the_same_folder_is_refused_while_the_first_holds_it(
    tmp_path, capsys, command
):
    out = tmp_path / "out"
    argv = labs_argv(out, 2) if command == "labs" else figures_argv(out, 1)
    assert cli.main(argv) == 0
    before = snapshot(tmp_path)
    with folders.FolderLock(out):  # the first run, still writing
        code = cli.main(argv)
        err = capsys.readouterr().err
        assert (tmp_path / ".out.lock").read_text().strip() == str(os.getpid())
    assert code == 1 and err.count("\n") == 1
    assert f"another uio-teach run (process {os.getpid()}) is writing {out}" in err
    assert snapshot(tmp_path) == before
    assert leftovers(tmp_path) == []  # the lock is gone with its holder


@pytest.mark.subprocess
def test_a_second_process_is_refused_while_the_lock_is_held(tmp_path):
    out = tmp_path / "out"
    with folders.FolderLock(out):
        proc = uio_teach(*figures_argv(out, 1))
    assert proc.returncode == 1
    assert proc.stderr.count("\n") == 1 and "is writing" in proc.stderr
    assert not out.exists()


@pytest.mark.subprocess
def test_the_lock_of_a_dead_process_is_taken_over(tmp_path):
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        text=True,
        capture_output=True,
        check=True,
    )
    (tmp_path / ".out.lock").write_text(dead.stdout)  # a killed run's lock, no one holds it
    assert cli.main(figures_argv(tmp_path / "out", 1)) == 0
    assert (tmp_path / "out" / folders.MANIFEST).is_file()
    assert leftovers(tmp_path) == []


def test_staging_folders_of_killed_runs_are_removed_by_the_next_run(tmp_path):
    out = tmp_path / "figs"
    assert make(out) == 0
    for name in (".figs.new-abc123", ".figs.old-def456"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "case_error.png").write_bytes(b"half written")
    (tmp_path / ".other.new-xyz").mkdir()  # another folder's: not ours to clean
    assert make(out) == 0
    assert leftovers(tmp_path) == [".other.new-xyz"]


def test_an_output_set_aside_by_a_killed_swap_is_put_back(tmp_path):
    out = tmp_path / "figs"
    assert make(out) == 0
    before = snapshot(out)
    os.replace(out, tmp_path / ".figs.old-abc")  # killed between the two renames of a swap
    with folders.StagedFolder(out) as stage:
        assert snapshot(out) == before  # back before anything else happens
        (stage.path / "x.txt").write_text("x")
    assert snapshot(out) == before and leftovers(tmp_path) == []


@pytest.mark.parametrize("mask", [0o022, 0o027])
def test_folders_get_the_users_usual_permissions(tmp_path, mask):
    old = os.umask(mask)
    try:
        assert make(tmp_path / "figs") == 0
        assert cli.main(labs_argv(tmp_path / "labs", 1)) == 0
    finally:
        os.umask(old)
    expected = 0o777 & ~mask
    for folder in (tmp_path / "figs", tmp_path / "labs", tmp_path / "labs" / "pa9" / "student"):
        assert stat.S_IMODE(folder.stat().st_mode) == expected, folder


# steps of figures_argv: case_error.png and its words case_error.txt (1, 2), missile_table2.csv
# and .md (3, 4), the manifest (5), before the swap (6), after it (7)
# the step inside the swap (6) in `make test`, every other step in the slow set (`make test-slow`)
@pytest.mark.parametrize("kill_at", [6, *(pytest.param(k, marks=SLOW) for k in (1, 2, 4, 5, 7))])
@pytest.mark.subprocess
def test_figures_killed_at_any_step_leave_the_old_set_or_the_new_set(tmp_path, kill_at):
    sets = {}
    for seed in (1, 2):
        (tmp_path / f"ref{seed}").mkdir()
        assert cli.main(figures_argv(tmp_path / f"ref{seed}" / "figs", seed, tmp_path)) == 0
        sets[seed] = snapshot(tmp_path / f"ref{seed}" / "figs")
    assert sets[1] != sets[2]
    run = tmp_path / "run"
    run.mkdir()
    out = run / "figs"
    old, new = figures_argv(out, 1, tmp_path), figures_argv(out, 2, tmp_path)
    assert cli.main(old) == 0
    proc = uio_teach(*new, kill_at=kill_at)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    assert snapshot(out) == (sets[2] if kill_at == 7 else sets[1])
    assert cli.main(new) == 0
    assert snapshot(out) == sets[2] and leftovers(run) == []


# configuration and option errors: one line each, exit 2, whatever the bytes -----------------

BAD_CONFIGS = {
    "not UTF-8": b"\xff\xfe[pa9]\nnoise = 0.1\n",
    "latin-1": "seed = 3  # caf\xe9\n".encode("latin-1"),
    "bad TOML": b"[pa9\nnoise = \n",
    "unknown key": b"[pa9]\nnoize = 0.1\n",
    "NUL bytes": b"\x00\x00\x00",
    "empty name": b"= 3\n",
}


@pytest.mark.parametrize("command", ["labs", "figures"])
@pytest.mark.parametrize("what", list(BAD_CONFIGS))
def test_a_bad_config_is_one_line_and_exit_2(tmp_path, capsys, command, what):
    config = tmp_path / "term.toml"
    config.write_bytes(BAD_CONFIGS[what])
    out = tmp_path / "out"
    code = cli.main([command, "--out", str(out), "--config", str(config)])
    captured = capsys.readouterr()
    assert code == 2
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith(f"uio-teach {command}: error: {config}")
    assert "Traceback" not in captured.err and captured.out == ""
    assert not out.exists() and leftovers(tmp_path) == []


@pytest.mark.subprocess
def test_a_non_utf8_config_is_one_line_in_a_real_process_too(tmp_path):
    config = tmp_path / "term.toml"
    config.write_bytes(BAD_CONFIGS["not UTF-8"])
    proc = uio_teach("labs", "--out", str(tmp_path / "out"), "--config", str(config))
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "not a text file in UTF-8" in proc.stderr


@pytest.mark.parametrize(
    "argv",
    [
        ["labs"],
        ["labs", "--out", "x", "--groups", "zero"],
        ["labs", "--out", "x", "--groups", "0"],
        ["labs", "--out", "x", "--seed", "3"],
        ["figures", "--out", "x", "--dpi", "5"],
        ["figures", "--out", "x", "--format", "gif"],
        ["figures", "--out", "x", "--only", "pa9_sin"],
        ["figures", "--bogus"],
        ["nonsense"],
    ],
)
def test_every_option_error_is_one_line_and_exit_2(argv, capsys):
    code = cli.main(argv)
    captured = capsys.readouterr()
    assert code == 2
    assert len(captured.err.splitlines()) == 1, captured.err
    assert captured.err.startswith("uio-teach") and ": error: " in captured.err


@pytest.mark.parametrize("argv", [["figures", "--list"], ["figures", "--print-config"], ["--help"]])
@pytest.mark.subprocess
def test_a_closed_pipe_ends_quietly(argv):
    read, write = os.pipe()
    os.close(read)  # the reader is gone before anything is written (`... | head -0`)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), *sys.path]))
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "uio_teach", *argv],
            stdout=write,
            stderr=subprocess.PIPE,
            env=env,
            check=False,
        )
    finally:
        os.close(write)
    assert proc.returncode == 0
    assert proc.stderr == b""  # no BrokenPipeError, no "Exception ignored"


# the student and the instructor edition of the book (_ext/editions.py) ---------------------------

LAB_PAGE = """\
---
jupytext:
  text_representation:
    extension: .md
    format_name: myst
    format_version: 0.13
kernelspec:
  display_name: Python 3
  language: python
  name: python3
---

# A lab

```{exercise}
:label: ex-demo-1
Compute `x`.
```

```{solution-start} ex-demo-1
:class: dropdown
```

The model answer says SECRET-PROSE.

```{code-cell} ipython3
:tags: [solution]
x = "SECRET-CODE"
```

```{solution-end}
```

```{code-cell} ipython3
y = "VISIBLE-CHECK"
```

```{code-cell} ipython3
:tags: [solution]
z = "SECRET-LOOSE-CELL"
```

(sec-demo-instructor)=
## Instructor notes

Tutors only: SECRET-NOTE.

### What the groups should find

SECRET-FINDINGS.

## Index

See {ref}`sec-demo-instructor`.
"""


def build_edition(
    tmp_path: Path, edition: str, pages: dict[str, str] | None = None, *flags: str
) -> subprocess.CompletedProcess:
    """Build ``pages`` (file name -> text; LAB_PAGE as ``index.md`` by default) with Sphinx
    (myst-nb, sphinx-exercise, the book's editions extension), warnings as errors, ``flags``
    added."""
    src = tmp_path / "src"
    src.mkdir(exist_ok=True)
    for name, text in (pages or {"index.md": LAB_PAGE}).items():
        (src / name).write_text(text)
    (src / "conf.py").write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(ROOT / '_ext')!r})\n"
        "extensions = ['myst_nb', 'sphinx_exercise', 'editions']\n"
        "nb_execution_mode = 'off'\n"
    )
    env = dict(os.environ, UIO_TEACH_EDITION=edition)
    return subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", *flags, "-E", "-q", "-b", "html", str(src),
         str(tmp_path / "html")],
        capture_output=True, text=True, env=env, check=False,
    )  # fmt: skip


@pytest.mark.parametrize("edition", ["student", "instructor"])
@pytest.mark.book
def test_the_student_edition_leaves_solutions_and_tutors_notes_out(tmp_path, edition):
    proc = build_edition(tmp_path, edition)
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "html"
    html = (out / "index.html").read_text(encoding="utf-8")
    secrets = ["SECRET-PROSE", "SECRET-CODE", "SECRET-LOOSE-CELL", "SECRET-NOTE", "SECRET-FINDINGS"]
    assert "VISIBLE-CHECK" in html and "Compute" in html
    if edition == "student":
        assert [s for s in secrets if s in html] == []
        # the tutors' section is left out whole, its heading with it; a reference to it is
        # its title in plain text (the build has no warning: it passed -W)
        assert "<h2>Instructor notes" not in html and 'id="instructor-notes"' not in html
        assert "What the groups should find" not in html
        assert re.search(r"See\s*<span>Instructor notes</span>", html)
        assert "instructor edition" not in html and "book-instructor" not in html
        assert not (out / "_sources").exists()  # no copy of the page's source
        assert "SECRET" not in (out / "searchindex.js").read_text(encoding="utf-8")
    else:
        assert [s for s in secrets if s not in html] == []
        assert "Instructor notes" in html and 'href="#sec-demo-instructor"' in html
        assert (out / "_sources").exists()


@pytest.mark.book
def test_an_unknown_edition_is_refused(tmp_path):
    proc = build_edition(tmp_path, "teachers")
    assert proc.returncode != 0
    assert (
        "UIO_TEACH_EDITION must be one of student, instructor, selfstudy, got 'teachers'"
        in proc.stderr
    )


def test_labs_and_figures_never_replace_each_others_folders(tmp_path, capsys):
    figs, notebooks = tmp_path / "figs", tmp_path / "labs"
    assert make(figs) == 0 and cli.main(labs_argv(notebooks, 1)) == 0
    before = snapshot(tmp_path)
    assert cli.main(labs_argv(figs, 1)) == 1
    assert "holds the output of `uio-teach figures`, not of `uio-teach labs`" in (
        capsys.readouterr().err
    )
    assert make(notebooks) == 1
    assert "holds the output of `uio-teach labs`, not of `uio-teach figures`" in (
        capsys.readouterr().err
    )
    assert snapshot(tmp_path) == before


STUB_BOOK = {
    "index.md": "# Book\n\n```{toctree}\ninstructors\n```\n\n"
    "See {ref}`sec-demo-grading` and {ref}`the grading <sec-demo-grading>`.\n\n"
    "## Work\n\nText.\n\n(sec-demo-tutors)=\n## Instructor notes\n\nSECRET-NOTE.\n",
    "instructors.md": "(sec-demo-instructors)=\n# For instructors\n\nSECRET-STUB.\n\n"
    "## Handing out\n\nSECRET-HANDOUT.\n\n"
    "(sec-demo-grading)=\n## Grading\n\nSECRET-GRADING.\n",
}


@pytest.mark.parametrize("edition", ["student", "instructor"])
@pytest.mark.book
def test_a_reference_into_the_instructors_page_reads_as_its_title_in_the_student_edition(
    tmp_path, edition
):
    """The instructors' page is a stub for students: its sections go with their labels, and a
    reference to one from another page is its title in plain text (no warning under -W -n); a
    tutors' section goes with the label in front of its heading."""
    proc = build_edition(tmp_path, edition, STUB_BOOK, "-n")
    assert proc.returncode == 0, proc.stderr
    index = (tmp_path / "html" / "index.html").read_text(encoding="utf-8")
    stub = (tmp_path / "html" / "instructors.html").read_text(encoding="utf-8")
    if edition == "student":
        assert "SECRET" not in stub and "SECRET" not in index
        assert re.search(r"See <span>Grading</span> and <span>the grading</span>", index)
        # the label written before the tutors' heading closes the section before it: gone too
        assert 'id="sec-demo-tutors"' not in index and "Instructor notes" not in index
    else:
        assert "SECRET-GRADING" in stub and 'href="instructors.html#sec-demo-grading"' in index
