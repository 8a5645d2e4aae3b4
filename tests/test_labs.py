"""`uio-teach labs`: student and solution notebooks from one MyST lab chapter.

The student notebook runs from top to bottom, and each check cell says what is still
missing (with a group's numbers here; with the course's, it is the notebook the built book
offers, which ``test_book_install.py`` runs); the solution notebook runs and every check
passes. Both are valid nbformat 4 notebooks with empty outputs and no MyST syntax left that
Jupyter would show raw.
"""

from __future__ import annotations

import ast
import functools
import json
import re
import textwrap
from pathlib import Path

import jupytext
import nbclient
import nbformat
import pytest
from lab_outputs import assert_checks_say_what_is_missing, assert_every_check_passes, tags
from term_changes import changed_values, leaves, nested, reached

from uio_teach.instructor import cli, labs
from uio_teach.instructor.config import FigureConfig, load_config

BOOK = Path(__file__).resolve().parents[1] / "book"
LABS = labs.find_labs(BOOK)
CELL_TIMEOUT = 300

pytestmark = pytest.mark.skipif(not LABS, reason="no lab chapter (book/*lab*.md) yet")


def execute(nb, folder: Path):
    client = nbclient.NotebookClient(
        nb,
        timeout=CELL_TIMEOUT,
        kernel_name="python3",
        resources={"metadata": {"path": str(folder)}},
    )
    client.execute()  # raises CellExecutionError on the first failing cell
    return nb


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("labs")
    results = labs.write_labs(out, book_dir=BOOK)
    return {"out": out, "results": results}


def read(path: Path):
    return nbformat.read(path, as_version=4)


@pytest.fixture(scope="module", params=[p.name for p in LABS])
def lab(request, written) -> dict:
    result = next(r for r in written["results"] if r.source.name == request.param)
    return {
        "source": result.source,
        "myst": jupytext.read(result.source),
        "student": read(result.student),
        "solution": read(result.solution),
        "result": result,
    }


# structure --------------------------------------------------------------------------------------


def test_every_lab_gets_a_student_and_a_solution_notebook(written):
    out = written["out"]
    assert {r.source for r in written["results"]} == set(LABS)
    for path in LABS:
        for version in labs.VERSIONS:
            assert (out / version / f"{path.stem}.ipynb").is_file()


@pytest.mark.parametrize("version", labs.VERSIONS)
def test_notebooks_are_valid_nbformat_4_with_empty_outputs(lab, version):
    nb = lab[version]
    nbformat.validate(nb)
    assert nb.nbformat == 4
    assert nb.metadata.kernelspec.name == "python3"
    meta = nb.metadata.uio_teach
    assert meta["source"] == lab["source"].name and meta["version"] == version
    assert meta["lab"] == labs.lab_of(lab["source"]).id
    for cell in nb.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None
    assert len({cell.id for cell in nb.cells}) == len(nb.cells)


def solution_cells(myst) -> list[str]:
    """Sources of the code cells that are solutions (inside a block, or tagged)."""
    out, inside = [], False
    for cell in myst.cells:
        if cell.cell_type == "markdown":
            for line in cell.source.splitlines():
                if "{solution-start}" in line:
                    inside = True
                elif "{solution-end}" in line:
                    inside = False
        elif inside or "solution" in tags(cell):
            out.append(cell.source)
    return out


def test_the_student_version_has_no_solution(lab):
    student = lab["student"]
    code = "\n".join(c.source for c in student.cells if c.cell_type == "code")
    solutions = solution_cells(lab["myst"])
    assert solutions, "the lab chapter has no solution cells"
    for source in solutions:
        assert source.strip() not in code
    assert not any("solution" in tags(c) or "instructor" in tags(c) for c in student.cells)
    text = "\n".join(c.source for c in student.cells)
    assert "Solution of Exercise" not in text and "Instructor notes" not in text


def test_each_solution_becomes_todo_cells_with_its_exercise_label(lab):
    myst_text = lab["source"].read_text(encoding="utf-8")
    blocks = re.findall(r"\{solution-start\}\s*(\S+)", myst_text)
    todo = [c for c in lab["student"].cells if "todo" in tags(c)]
    assert len(todo) == lab["result"].todo_cells
    labels = []
    for cell in todo:
        first = cell.source.splitlines()[0]
        assert first.startswith(("# TODO: Exercise ", "**Your answer to Exercise ")), first
        label = re.search(r"\((ex-[\w-]+)\)", first).group(1)
        if label not in labels:
            labels.append(label)
    assert labels == blocks


def test_a_solution_explained_in_words_gets_a_your_answer_cell(lab):
    """The solution's prose is a model answer: the student gets an empty answer cell instead."""
    cells = lab["solution"].cells
    explained = set()
    for i, cell in enumerate(cells):
        if cell.cell_type == "markdown" and "solution" in tags(cell):
            if not cell.source.startswith("**Solution of Exercise"):
                head = next(
                    c.source
                    for c in reversed(cells[:i])
                    if c.source.startswith("**Solution of Exercise")
                )
                explained.add(re.search(r"Exercise ([\d.]+)", head).group(1))
    answers = {
        re.search(r"Exercise ([\d.]+)", c.source).group(1)
        for c in lab["student"].cells
        if c.cell_type == "markdown" and c.source.startswith("**Your answer to Exercise")
    }
    assert explained and explained <= answers


def test_the_check_cells_are_kept_in_both_versions(lab):
    solutions = solution_cells(lab["myst"])
    source_checks = [
        c.source
        for c in lab["myst"].cells
        if c.cell_type == "code"
        and re.search(r"\bchecks\.\w+\(", c.source)
        and c.source not in solutions
    ]
    assert source_checks, "the lab has no check cells"
    solution = [c for c in lab["solution"].cells if "check" in tags(c)]
    # only the cells a student runs carry the tag: not the instructor's demonstrations
    assert not any("instructor" in tags(c) for c in solution)
    demos = [
        c.source
        for c in lab["solution"].cells
        if "instructor" in tags(c) and re.search(r"\bchecks\.\w+\(", c.source)
    ]
    assert [c.source for c in solution] == [s for s in source_checks if s not in demos]
    assert [c.source for c in lab["student"].cells if "check" in tags(c)] == [
        c.source for c in solution
    ]


def test_the_solution_version_is_complete(lab):
    source_code = [c.source for c in lab["myst"].cells if c.cell_type == "code"]
    solution_code = [c.source for c in lab["solution"].cells if c.cell_type == "code"]
    assert solution_code == source_code
    for source in solution_cells(lab["myst"]):
        cell = next(c for c in lab["solution"].cells if c.source == source)
        assert "solution" in tags(cell)


@pytest.mark.parametrize("version", labs.VERSIONS)
def test_no_raw_myst_is_left_in_the_markdown(lab, version):
    for cell in lab[version].cells:
        if cell.cell_type != "markdown":
            continue
        assert not re.search(r"^(```|:::)\{", cell.source, re.M), cell.source[:200]
        assert not re.search(r"\{[\w:.-]+\}`", cell.source), cell.source[:200]
        assert not re.search(r"^\([\w:.-]+\)=\s*$", cell.source, re.M), cell.source[:200]
    text = "\n".join(c.source for c in lab[version].cells)
    assert re.search(r"\*\*Exercise \d+(\.\d+)?\*\*", text)


# execution --------------------------------------------------------------------------------------


@pytest.mark.book
@pytest.mark.kernel
def test_the_solution_version_runs_and_every_check_passes(lab, tmp_path):
    """(Its student version, with the same numbers, is the notebook the book offers:
    ``test_book_install.py`` runs it, and its checks say what is missing.)"""
    assert_every_check_passes(execute(lab["solution"], tmp_path))


# the conversion, on a small made-up lab ---------------------------------------------------------

SMALL_LAB = textwrap.dedent(
    """\
    ---
    jupytext:
      text_representation:
        extension: .md
        format_name: myst
    kernelspec:
      display_name: Python 3
      language: python
      name: python3
    ---

    (sec-small)=
    # A small lab

    See {cite:p}`smith` and {ref}`sec-small-two`; equation {eq}`eq-small-one`:

    $$
    y = 2x
    $$ (eq-small-one)

    ```python
    # not a heading: inside a fenced code block
    ```

    ```{code-cell} ipython3
    import math
    ```

    ```{exercise}
    :label: ex-small-1
    Compute `y` for $x = 21$.
    ```

    ```{solution-start} ex-small-1
    :class: dropdown
    ```

    ```{code-cell} ipython3
    x = 21
    y = 2 * x
    helper = math.pi
    ```

    Because $y = 2x$.

    ```{solution-end}
    ```

    ```{code-cell} ipython3
    assert y == 42
    ```

    (sec-small-two)=
    ## Part two

    :::{exercise}
    :label: ex-small-2
    Why?
    :::

    ```{solution-start} ex-small-2
    ```
    Because.
    ```{solution-end}
    ```

    ```{code-cell} ipython3
    :tags: [solution]

    z = y + 1
    ```

    ```{code-cell} ipython3
    print(z)
    ```

    (sec-small-instructor)=
    ## Notes for the marker

    ```{code-cell} ipython3
    print("only for instructors", y)
    ```

    ## After the notes

    ```{note}
    Kept for everyone.
    ```
    """
)

SMALL_BIB = "@article{smith,\n  author = {Smith, Ann and Jones, Bo},\n  year = {2001},\n}\n"


@pytest.fixture()
def small_lab(tmp_path) -> Path:
    book = tmp_path / "book"
    book.mkdir()
    (tmp_path / "references.bib").write_text(SMALL_BIB)
    path = book / "lab_small.md"
    path.write_text(SMALL_LAB)
    return path


@pytest.mark.kernel
def test_small_lab_student_version(small_lab, tmp_path):
    nb = labs.make_notebook(small_lab, "student")
    nbformat.validate(nb)
    sources = [c.source for c in nb.cells]
    text = "\n".join(sources)
    todo = [c.source for c in nb.cells if "todo" in tags(c)]
    assert todo[0].splitlines() == [
        "# TODO: Exercise 1 (ex-small-1). Write your code here.",
        "# The cells below use these names; replace None by your answer:",
        "y = None",
    ]  # x and helper are not used later: no placeholder for them
    # the solution of exercise 1 explains in words too: an answer cell after the code cell
    assert todo[1].startswith("**Your answer to Exercise 1 (ex-small-1)**")
    assert todo[2].startswith("**Your answer to Exercise 2 (ex-small-2)**")  # prose only
    assert todo[3].splitlines()[0] == "# TODO: Exercise 2 (ex-small-2). Write your code here."
    assert "z = None" in todo[3]
    assert "Because" not in text and "only for instructors" not in text
    assert "Notes for the marker" not in text
    assert "After the notes" in text and "> **Note.** Kept for everyone." in text
    assert "(Smith and Jones, 2001)" in text
    assert 'See (Smith and Jones, 2001) and section "Part two"; equation (1):' in text
    assert "$$\ny = 2x \\tag{1}$$" in text
    assert "# not a heading" in text  # fenced code is left alone
    assert "> **Exercise 1**" in text and "> **Exercise 2**" in text
    # it runs up to the end: the check cell fails on the placeholder, as a student would see
    with pytest.raises(nbclient.exceptions.CellExecutionError, match="assert y == 42"):
        execute(nb, tmp_path)


@pytest.mark.kernel
def test_small_lab_solution_version(small_lab, tmp_path):
    nb = labs.make_notebook(small_lab, "solution")
    text = "\n".join(c.source for c in nb.cells)
    assert "Because $y = 2x$." in text and "Notes for the marker" in text
    marker = [c for c in nb.cells if "instructor" in tags(c)]
    assert any("only for instructors" in c.source for c in marker)
    assert not any("After the notes" in c.source for c in marker)
    assert [c.source for c in nb.cells if "solution" in tags(c) and c.cell_type == "code"] == [
        "x = 21\ny = 2 * x\nhelper = math.pi",
        "z = y + 1",
    ]
    execute(nb, tmp_path)


def test_an_unclosed_solution_block_is_an_error(tmp_path):
    path = tmp_path / "lab_broken.md"
    path.write_text("# Lab\n\n```{solution-start} ex-1\n```\n\nforever\n")
    with pytest.raises(labs.LabError, match="lab_broken.md: solution block 'ex-1' is never closed"):
        labs.make_notebook(path, "student")


# the command ------------------------------------------------------------------------------------


def test_labs_command_writes_both_versions_with_a_summary(tmp_path, capsys):
    code = cli.main(["labs", "--out", str(tmp_path)])
    out = capsys.readouterr().out.strip().splitlines()
    assert code == 0
    assert len(out) == len(LABS) + 1
    assert out[-1].startswith(f"{len(LABS)} lab")
    assert f"written to {tmp_path}" in out[-1]
    for path in LABS:
        for version in labs.VERSIONS:
            nbformat.validate(read(tmp_path / version / f"{path.stem}.ipynb"))


def test_labs_command_fails_clearly_on_a_missing_source(tmp_path, capsys):
    code = cli.main(["labs", "--out", str(tmp_path), "--source", "no_such_lab.md"])
    err = capsys.readouterr().err
    assert code == 2
    assert err == "uio-teach labs: error: no_such_lab.md: no such file\n"
    code = cli.main(["labs", "--out", str(tmp_path), "--book", str(tmp_path)])
    assert code == 2 and "no lab chapter" in capsys.readouterr().err
    code = cli.main(["labs", "--out", str(tmp_path), "--book", str(tmp_path / "nonexist")])
    assert code == 2 and "nonexist: no such folder" in capsys.readouterr().err


# nothing of the solution in the student notebook ------------------------------------------------


def solution_only_lines(solution) -> list[str]:
    """Lines of the solution cells that no other cell of the solution notebook has."""
    shared = set()
    for cell in solution.cells:
        if "solution" not in tags(cell):
            shared.update(line.strip() for line in cell.source.splitlines())
    out = []
    for cell in solution.cells:
        if cell.cell_type == "code" and "solution" in tags(cell):
            for line in cell.source.splitlines():
                line = line.strip()
                if len(line) >= 12 and line not in shared and line not in out:
                    out.append(line)
    return out


def test_no_line_of_solution_code_is_in_the_student_notebook(lab):
    """Not in its code, and not in its markdown either (a summary that repeats the solution)."""
    text = "\n".join(c.source for c in lab["student"].cells)
    lines = solution_only_lines(lab["solution"])
    assert len(lines) >= 10, (
        f"the solution cells (tagged `solution`) of {lab['source']} hold {len(lines)} lines of "
        "code of their own, fewer than 10: a lab chapter's exercises are solved in code cells "
        "tagged `solution` between `solution-start` and `solution-end` (see CONTRIBUTING.md)"
    )
    leaked = [line for line in lines if line in text]
    assert not leaked, leaked


def test_no_model_answer_is_in_the_student_notebook(lab):
    """The prose of the solutions (the model answers) is only in the solution notebook."""
    text = "\n".join(c.source for c in lab["student"].cells)
    prose = [
        c.source
        for c in lab["solution"].cells
        if c.cell_type == "markdown"
        and "solution" in tags(c)
        and not c.source.startswith("**Solution of")
    ]
    assert prose
    for answer in prose:
        for sentence in re.split(r"(?<=[.:])\s+", answer):
            if len(sentence) > 40:
                assert sentence not in text, sentence


# a variant of every lab runs too ------------------------------------------------------------------


@pytest.fixture(scope="module")
def variant_dir(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("variants")
    labs.write_labs(out, groups=2, seed=11)
    return out


@pytest.mark.book
@pytest.mark.parametrize("lab_id", list(labs.LABS))
@pytest.mark.kernel
def test_a_variant_solves_with_every_check_passing_and_its_student_form_runs(
    lab_id, variant_dir, tmp_path
):
    solution = execute(read(variant_dir / lab_id / "solution" / f"{lab_id}_g02.ipynb"), tmp_path)
    assert_every_check_passes(solution)
    # no cell may fail: TODO cells define placeholders
    student = execute(read(variant_dir / lab_id / "student" / f"{lab_id}_g02.ipynb"), tmp_path)
    assert_checks_say_what_is_missing(student)


def test_a_source_that_is_not_a_lab_is_a_usage_error(tmp_path, capsys):
    garbled = tmp_path / "lab_notes.md"
    garbled.write_text("# Notes\n\n```{exercise\nno closing\n")
    code = cli.main(["labs", "--out", str(tmp_path / "out"), "--source", str(garbled)])
    err = capsys.readouterr().err
    assert code == 2 and "lab_notes.md: not a lab chapter" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("version", labs.VERSIONS)
def test_cross_references_are_short_plain_text(lab, version):
    text = "\n".join(c.source for c in lab[version].cells if c.cell_type == "markdown")
    assert re.search(r"\b(?:eq\.|equations?) \(\d+\.\d+\)", text)
    assert re.search(r"\bchapter \d+\b", text)
    assert not re.search(r"\) of chapter \d", text)
    assert not re.search(r"chapter \d+, \*", text)
    # the word is said once: not "eq. eq. (4.2)", not "equations (4.1), eq. (4.2)"
    listed = r"(?:\([^()]*\)(?:,\s*|\s+and\s+))*"
    doubled = re.search(rf"\b(?:[Ee]q\.|[Ee]qs\.|[Ee]quations?)\s+{listed}eq\. \(", text)
    assert not doubled, doubled and doubled.group(0)


# every key of the term config reaches the labs (or the help says why not) ----------------------

# a value for each key that differs from the default, valid on its own, derived from the schema
TERM_CHANGES = {key: value for key, (value, _) in changed_values().items() if value is not None}


def test_every_config_key_has_a_change_the_config_and_the_labs_accept():
    """Each key of the schema is tried (no list of keys here): none is left out unseen."""
    stuck = {key: why for key, (value, why) in changed_values().items() if value is None}
    assert not stuck, f"no changed value could be made for these config keys: {stuck}"


def params_of(nb) -> dict:
    (cell,) = [c for c in nb.cells if "parameters" in tags(c)]
    return ast.literal_eval(cell.source.split("=", 1)[1])


def reads(code: str, path: tuple) -> bool:
    """Whether ``code`` reads ``PARAMS[path[0]][path[1]]...`` (or a whole sub-dict of it)."""
    for k in range(len(path), 0, -1):
        chain = "PARAMS" + "".join(f'["{p}"]' for p in path[:k])
        if re.search(re.escape(chain) + (r"(?!\[)" if k < len(path) else ""), code):
            return True
    return False


def unread(lab_id: str, key: str) -> bool:
    return any(lab_id in e.labs and key in e.keys for e in labs.UNREAD_CONFIG_KEYS)


@pytest.fixture(scope="module")
def term_labs(tmp_path_factory) -> dict:
    """The labs written with a term config that changes every key of TERM_CHANGES."""
    folder = tmp_path_factory.mktemp("term")
    changes = {
        k: v for k, v in TERM_CHANGES.items() if reached(FigureConfig.from_dict(nested({k: v})))
    }
    config = load_config(write_toml(folder / "term.toml", nested(changes)))
    results = labs.write_labs(folder / "labs", book_dir=BOOK, config=config)
    return {"config": config, "results": {labs.lab_of(r.source).id: r for r in results}}


def write_toml(path: Path, data: dict) -> Path:
    lines = [f"{k} = {json.dumps(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for table, values in data.items():
        if isinstance(values, dict):
            for k, v in leaves(values, (table,)):
                lines.append(f"{'.'.join(k[:-1])}.{k[-1]} = {json.dumps(v)}")
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("lab_id", list(labs.LABS))
def test_the_written_notebooks_hold_the_terms_numbers(term_labs, lab_id):
    result = term_labs["results"][lab_id]
    expected = labs.LABS[lab_id].params.from_config(term_labs["config"]).to_params()
    for path in (result.student, result.solution):
        assert params_of(nbformat.read(path, as_version=4)) == expected


@functools.cache
def solution_code(lab_id: str) -> str:
    """The code cells of the lab's solution notebook (quotes made double, for :func:`reads`)."""
    solution = labs.make_notebook(BOOK / labs.LABS[lab_id].source, "solution")
    code = "\n".join(c.source for c in solution.cells if c.cell_type == "code")
    return code.replace("'", '"')


def wiring_problems(key: str, value) -> list[str]:
    """Why ``key`` = ``value`` of a term config would not reach what the students run (empty: it
    does): a key no lab reads must be named by ``labs``; one that reaches a lab's PARAMS must be
    read by its code, or named in UNREAD_CONFIG_KEYS."""
    config = FigureConfig.from_dict(nested({key: value}))
    reaches = reached(config)
    if not reaches:  # a key no lab declares: `labs` says so, by name
        notes = labs.unused_config_keys(config)
        said = [n for n in notes if n.startswith(f"{key} of the term config is used by no lab")]
        return [] if said else [f"{key} reaches no lab and `uio-teach labs` does not say so"]
    out = []
    for lab_id, changed in reaches.items():
        is_read = any(reads(solution_code(lab_id), p) for p in changed)
        if is_read == unread(lab_id, key):
            out.append(
                f"{key} reaches the PARAMS of the {lab_id} lab "
                + (
                    "and its notebook reads it, but UNREAD_CONFIG_KEYS says it does not"
                    if is_read
                    else f"but no code cell of {labs.LABS[lab_id].source} reads "
                    + " or ".join("PARAMS" + "".join(f"[{p!r}]" for p in path) for path in changed)
                    + ": wire it into the chapter's code (or name it in UNREAD_CONFIG_KEYS "
                    "with the reason)"
                )
            )
    return out


@pytest.mark.parametrize("key", list(TERM_CHANGES))
def test_every_config_key_reaches_a_lab_that_reads_it_or_is_said(key, capsys):
    assert wiring_problems(key, TERM_CHANGES[key]) == []
    assert cli.main(["labs", "--help"]) == 0
    help_text = " ".join(capsys.readouterr().out.split())
    for entry in labs.UNREAD_CONFIG_KEYS:
        assert " ".join(entry.text().split()) in help_text


def test_a_lab_field_added_without_wiring_fails_by_name():
    """One more line in PA9's experiment, ``lab=True``, that the lab chapter never reads."""
    import dataclasses

    from uio_teach.experiments import param
    from uio_teach.lab_params import lab_params_of
    from uio_teach.worked import discover, pa9

    @dataclasses.dataclass(frozen=True)
    class WithBias(pa9.PA9Experiment):
        bias: float = param(0.25, "float", "a constant added to d", key="sine.bias")

    @lab_params_of(WithBias(name="pa9", timepts=pa9.PA9_LAB.timepts))
    class BiasParams(pa9.PA9Params):
        pass

    own = pa9.EXAMPLES
    entry = own[0]
    lab = dataclasses.replace(entry.lab, params=BiasParams)
    experiment = WithBias(name="pa9", timepts=pa9.PA9.timepts)
    pa9.EXAMPLES = (dataclasses.replace(entry, experiment=experiment, lab=lab),)
    discover()
    try:
        problems = wiring_problems("pa9.sine.bias", 0.5)
    finally:
        pa9.EXAMPLES = own
        discover()
    assert problems == [
        "pa9.sine.bias reaches the PARAMS of the pa9 lab but no code cell of lab_pa9.md reads "
        "PARAMS['sine']['bias']: wire it into the chapter's code (or name it in "
        "UNREAD_CONFIG_KEYS with the reason)"
    ]


@pytest.mark.book
@pytest.mark.parametrize("lab_id", list(labs.LABS))
@pytest.mark.kernel
def test_a_term_configs_solution_runs_with_every_check_passing(term_labs, lab_id, tmp_path):
    """The term's numbers (TERM_CHANGES) run through the lab: its checks pass with them."""
    nb = nbformat.read(term_labs["results"][lab_id].solution, as_version=4)
    assert_every_check_passes(execute(nb, tmp_path))
