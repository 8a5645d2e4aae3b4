"""Every chapter of the book runs from top to bottom.

Each MyST Markdown notebook in ``book/`` (a ``.md`` file whose front matter has a ``kernelspec``)
is executed by the test run's one book build (``book_build`` in ``conftest.py``, every chapter
afresh). One test per chapter, named after the chapter file, so a failing cell points at its
chapter.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml
from myst_nb.core.read import read_myst_markdown_notebook

BOOK = Path(__file__).resolve().parents[1] / "book"
HTML = BOOK.parent / "_build" / "html"


def _front_matter(text: str) -> dict:
    if not text.startswith("---"):
        return {}
    end = text.find("\n---", 3)
    if end < 0:
        return {}
    data = yaml.safe_load(text[3:end])
    return data if isinstance(data, dict) else {}


def chapter_notebooks(book: Path = BOOK) -> list[Path]:
    """The ``.md`` files of ``book`` that are notebooks (they declare a kernelspec)."""
    return sorted(
        path
        for path in book.rglob("*.md")
        if ".ipynb_checkpoints" not in path.parts
        and "kernelspec" in _front_matter(path.read_text(encoding="utf-8"))
    )


CHAPTERS = chapter_notebooks()


def test_the_book_has_chapters() -> None:
    assert CHAPTERS, f"no MyST notebook (front matter with a kernelspec) found in {BOOK}"


@pytest.mark.book
@pytest.mark.kernel
@pytest.mark.parametrize(
    "chapter", CHAPTERS, ids=[str(path.relative_to(BOOK)) for path in CHAPTERS]
)
def test_chapter_runs(chapter: Path, book_build) -> None:
    """The chapter ran from top to bottom in the test run's one book build (every cell executed
    afresh, a failing cell's traceback saved by myst-nb in ``reports/<page>.err.log``)."""
    docname = chapter.relative_to(BOOK.parent).with_suffix("").as_posix()
    report = HTML / "reports" / f"{docname}.err.log"
    if report.is_file():
        pytest.fail(
            f"{chapter.relative_to(BOOK)}: a cell failed\n{report.read_text(encoding='utf-8')}",
            pytrace=False,
        )
    page = HTML / f"{docname}.html"
    assert page.is_file(), f"{chapter.relative_to(BOOK)} was not built:\n{book_build.log}"


# --- the reader sees the computation, not the test ----------------------------------------------

MAX_VISIBLE_ASSERTS = 10
HIDDEN_TAGS = {"remove-cell", "remove-input", "hide-input", "hide-cell"}


def visible_assert_lines(chapter: Path) -> list[str]:
    """Lines with ``assert`` in the code cells of ``chapter`` that the rendered page shows."""
    notebook = read_myst_markdown_notebook(chapter.read_text(encoding="utf-8"), path=chapter)
    found = []
    for cell in notebook.cells:
        if cell.cell_type != "code" or HIDDEN_TAGS & set(cell.metadata.get("tags", [])):
            continue
        found += [line.strip() for line in cell.source.splitlines() if "assert" in line]
    return found


def test_few_visible_asserts() -> None:
    counts = {path.name: visible_assert_lines(path) for path in CHAPTERS}
    total = sum(len(lines) for lines in counts.values())
    detail = {name: len(lines) for name, lines in counts.items() if lines}
    assert total <= MAX_VISIBLE_ASSERTS, (
        f"{total} visible assert lines (at most {MAX_VISIBLE_ASSERTS}): {detail}; move checks"
        " that do not teach into a hidden cell (tags: [remove-cell]) or into the tests"
    )


def test_hidden_checks_still_run() -> None:
    """Hidden cells must be removed from the page, not from execution (no skip-execution)."""
    for chapter in CHAPTERS:
        notebook = read_myst_markdown_notebook(chapter.read_text(encoding="utf-8"), path=chapter)
        skipped = [
            cell.source.splitlines()[0]
            for cell in notebook.cells
            if cell.cell_type == "code"
            and "skip-execution" in cell.metadata.get("tags", [])
            and "assert" in cell.source
        ]
        assert not skipped, f"{chapter.name}: checks that never run: {skipped}"


# At 1280 px a code cell of the text column is 652 px wide inside its padding, and 630 px inside
# an exercise or a solution dropdown; the code font (14 px monospace, 8.43 px a character in
# Chromium with DejaVu Sans Mono) fits 77 and 74 characters. A longer line of a cell the reader
# sees scrolls sideways, its end hidden. tests/test_book.py measures the built pages in a browser;
# this is the same rule on the sources, without a build, at the narrower width.
MAX_CODE_LINE = 74


def wide_code_lines(chapter: Path, limit: int = MAX_CODE_LINE) -> list[str]:
    """Lines longer than ``limit`` in the code cells of ``chapter`` that the page shows."""
    notebook = read_myst_markdown_notebook(chapter.read_text(encoding="utf-8"), path=chapter)
    found = []
    for number, cell in enumerate(notebook.cells, start=1):
        if cell.cell_type != "code" or HIDDEN_TAGS & set(cell.metadata.get("tags", [])):
            continue
        found += [
            f"{chapter.name}, cell {number}: {len(line)} characters: {line.strip()[:60]}"
            for line in cell.source.splitlines()
            if len(line) > limit
        ]
    return found


def test_wide_code_lines_are_found(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    long = "x = " + "1 + " * 30 + "1"
    page.write_text(
        "---\nkernelspec:\n  name: python3\n  display_name: Python 3\n---\n# Page\n\n"
        f"```{{code-cell}} ipython3\n{long}\n```\n\n"
        f"```{{code-cell}} ipython3\n:tags: [remove-input]\n{long}\n```\n",
        encoding="utf-8",
    )
    assert len(long) > MAX_CODE_LINE
    assert len(wide_code_lines(page)) == 1  # the hidden cell does not count


def test_visible_code_fits_the_column() -> None:
    wide = [line for chapter in CHAPTERS for line in wide_code_lines(chapter)]
    assert not wide, (
        f"{len(wide)} visible code lines longer than {MAX_CODE_LINE} characters (they scroll "
        "sideways at 1280 px); wrap them:\n" + "\n".join(wide)
    )


# --- every chapter opens with its goals and closes with a summary and exercises -----------------


def course_chapters(root: Path = BOOK.parent) -> list[Path]:
    """The chapters of the part "The course" of ``_toc.yml``, in reading order, but the lab."""
    toc = yaml.safe_load((root / "_toc.yml").read_text(encoding="utf-8"))
    part = next(part for part in toc["parts"] if part.get("caption") == "The course")
    files = [root / f"{entry['file']}.md" for entry in part["chapters"]]
    return [path for path in files if not path.name.startswith("lab_")]


COURSE_CHAPTERS = course_chapters()


def test_course_chapters_are_found() -> None:
    names = [path.stem for path in COURSE_CHAPTERS]
    assert names[:2] == ["introduction", "toolbox"] and "fault_detection" in names, names
    assert all(path.is_file() for path in COURSE_CHAPTERS)


@pytest.mark.parametrize("chapter", COURSE_CHAPTERS, ids=[path.name for path in COURSE_CHAPTERS])
def test_chapter_structure(chapter: Path) -> None:
    text = chapter.read_text(encoding="utf-8")
    opening = text.find("```{admonition} In this chapter")
    assert opening >= 0, f"{chapter.name}: no 'In this chapter' box under the title"
    box = text[opening : text.find("```", opening + 3)]
    for phrase in ("You will be able to", "It assumes"):
        assert phrase in box, f"{chapter.name}: the opening box does not say {phrase!r}"
    summary, exercises = text.find("\n## Summary\n"), text.find("\n## Exercises\n")
    assert 0 < summary < exercises, f"{chapter.name}: no '## Summary' followed by '## Exercises'"
    assert "```{exercise}" in text[exercises:], f"{chapter.name}: no exercise"
    starts = re.findall(r"```\{solution-start\}[^\n]*\n(:class: [^\n]*)?", text[exercises:])
    assert starts, f"{chapter.name}: no solution"
    unfolded = [opts for opts in starts if "dropdown" not in opts]
    assert not unfolded, f"{chapter.name}: every solution must be folded (:class: dropdown)"


def test_no_hard_coded_chapter_or_equation_numbers() -> None:
    """Numbers follow the table of contents only through {numref}, {eq}, {ref} and {doc} roles."""
    pattern = re.compile(r"\b[Cc]hapters? \d|(?<![\w`])\(\d+\.\d+\)")
    found = []
    for page in sorted(BOOK.glob("*.md")):
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            if pattern.search(line):
                found.append(f"{page.name}:{number}: {line.strip()}")
    assert not found, "hard-coded chapter or equation numbers:\n" + "\n".join(found)


# --- each chapter as a notebook (the book's _ext/chapter_notebooks.py) --------------------------


@pytest.mark.subprocess  # jupytext asks pandoc for its version
def test_chapter_converts_to_a_notebook_without_outputs(tmp_path: Path, monkeypatch) -> None:
    import importlib.util

    import nbformat

    # the book's extensions import each other from their folder, as Sphinx loads them
    monkeypatch.syspath_prepend(str(BOOK.parent / "_ext"))
    spec = importlib.util.spec_from_file_location(
        "chapter_notebooks", BOOK.parent / "_ext" / "chapter_notebooks.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    chapter = BOOK / "case_study.md"
    target = tmp_path / "case_study.ipynb"
    module.write_notebook(chapter, target)
    notebook = nbformat.read(target, as_version=4)
    nbformat.validate(notebook)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    source = read_myst_markdown_notebook(chapter.read_text(encoding="utf-8"), path=chapter)
    assert len(code) == sum(cell.cell_type == "code" for cell in source.cells)
    assert all(not cell.outputs and cell.execution_count is None for cell in code)
    # the checks hidden in the book are kept, and still marked as such
    assert any("remove-cell" in cell.metadata.get("tags", []) for cell in code)
    assert notebook.metadata["kernelspec"]["name"] == "python3"
    assert "jupytext" not in notebook.metadata


# --- the prose states the worked experiments' numbers -------------------------------------------
# The chapters read each experiment from `uio_teach.experiments`; where their text states one of
# its numbers, the sentence is rebuilt here from the experiment, so that changing the experiment
# fails this test instead of leaving the text false.


def _num(value: float) -> str:
    return f"{float(value):g}"


def _prose_claims() -> list[tuple[str, str]]:
    from uio_teach.worked.case_study import CASE_STUDY
    from uio_teach.worked.missile import MISSILE
    from uio_teach.worked.pa9 import PA9

    x0_pa9 = PA9.initial_state
    poles_pa9 = ", ".join(_num(p) for p in PA9.poles)
    sine = "" if PA9.sine_amplitude == 1 else f"{_num(PA9.sine_amplitude)} "
    sin_pa9 = f"{sine}\\sin {_num(PA9.sine_frequency)}t"
    jumps = [_num(t) for t in PA9.switch_times[1:]]
    jumps_text = f"$t = {jumps[0]}$, " + ", ".join(f"${t}$" for t in jumps[1:-1])
    jumps_text = jumps_text.rstrip(", ") + f" and ${jumps[-1]}$ s"
    x0_case = ", ".join(_num(x) for x in CASE_STUDY.initial_state)
    (a1, r1, w1, k1), (a2, r2, w2, k2) = MISSILE.v_parameters
    x0_missile = MISSILE.initial_state
    poles_missile = sorted(MISSILE.poles)  # the pole for x1 is the faster one
    return [
        # introduction: the PA9 experiment's poles, start and sinusoid
        ("introduction.md", f"error poles $\\{{{poles_pa9}\\}}$, those of the PA9 experiment"),
        ("introduction.md", f"the sinusoid $d(t) = {sine}\\sin({_num(PA9.sine_frequency)}t)$"),
        ("introduction.md", f"$\\omega = {_num(PA9.sine_frequency)}$ rad/s"),
        (
            "introduction.md",
            "the PA9 experiment's $x(0) = [" + ",\\ ".join(_num(x) for x in x0_pa9) + "]^\\top$",
        ),
        ("introduction.md", f"twice the experiment's {_num(PA9.duration)} s"),
        # PA9
        ("pa9.md", "start the plant at $x_0 = [" + ", ".join(_num(x) for x in x0_pa9) + "]^\\top$"),
        ("pa9.md", f"the run lasts {_num(PA9.duration)} s, on {PA9.timepts.size} time points"),
        ("pa9.md", f"**(i) Sinusoidal disturbance** $d(t) = {sin_pa9}$"),
        ("pa9.md", f"**(ii) Piecewise-constant disturbance**, jumping at {jumps_text}"),
        ("pa9.md", f"gains that place $\\{{{poles_pa9}\\}}$"),
        ("toolbox.md", f"the gain $K_1$ places the poles $\\{{{poles_pa9}\\}}$"),
        # case study
        (
            "case_study.md",
            f"$d[k] = {_num(CASE_STUDY.d_amplitude)} \\sin({_num(CASE_STUDY.d_frequency)} k)$",
        ),
        (
            "case_study.md",
            f"drawn uniformly in $[-{_num(CASE_STUDY.v_amplitude)}, "
            f"{_num(CASE_STUDY.v_amplitude)}]$, every {CASE_STUDY.v_hold} steps",
        ),
        ("case_study.md", f"$x[0] = [{x0_case}]^\\top$"),
        ("case_study.md", f"the steps $k = 0, 1, \\dots, {int(CASE_STUDY.duration)}$"),
        # missile
        (
            "missile.md",
            "x_0 = \\begin{bmatrix} "
            + " \\\\ ".join(_num(x) for x in x0_missile)
            + " \\end{bmatrix}",
        ),
        (
            "missile.md",
            f"v_1(t) = {_num(a1)}\\, \\mathrm{{e}}^{{-{_num(r1)}t}} \\{k1}({_num(w1)} t), \\qquad "
            f"v_2(t) = {_num(a2)}\\, \\mathrm{{e}}^{{-{_num(r2)}t}} \\{k2}({_num(w2)} t)",
        ),
        (
            "missile.md",
            f"A grid of {MISSILE.timepts.size:,} points over {_num(MISSILE.duration)} s".replace(
                ",", " "
            ),
        ),
        (
            "missile.md",
            f"pole ${_num(poles_missile[0])}$ for $x_1$ and ${_num(poles_missile[1])}$ for $x_2$",
        ),
        ("missile.md", f"the error ${_num(x0_missile[0])}\\,\\mathrm{{e}}^{{-l_1 t}}$"),
        # fault detection: the PA9 experiment again
        ("fault_detection.md", f"the experiment's poles $\\{{{poles_pa9}\\}}$"),
        ("fault_detection.md", f"over the same {_num(PA9.duration)} s"),
        ("fault_detection.md", f"the disturbance $d(t) = {sin_pa9}$"),
    ]


def test_prose_states_the_experiments_numbers() -> None:
    """Every number the text gives for an experiment is the experiment's."""
    from uio_teach.worked.pa9 import PA9

    # the known input of PA9 has no parameters: the text describes it as u = [1, 0.5 sin t]
    assert str(PA9.inputs) == "[1 step(t - 0); 0.5 sin(1 t)]"
    missing = []
    texts: dict[str, str] = {}
    for name, phrase in _prose_claims():
        if name not in texts:
            texts[name] = " ".join((BOOK / name).read_text(encoding="utf-8").split())
        if " ".join(phrase.split()) not in texts[name]:
            missing.append(f"{name}: {phrase!r}")
    assert not missing, "text that no longer states the experiment's value:\n" + "\n".join(missing)
    for name in ("pa9.md", "fault_detection.md"):
        assert "$u = [1,\\ 0.5 \\sin t]^\\top$" in texts[name], name


# --- one notation ---------------------------------------------------------------------------------

# The observer's own state is z in every chapter (the missile paper's q is named only as the
# paper's); r is the residual alone (the number of measurement disturbances is n_v, `plant.nv`).
_OTHER_OBSERVER_STATE = re.compile(r"\\dot q\b|\bq\(0\)|\bq\[0\]|\bq_\{?\d|plant\.r\b")
NOTATION_CHAPTERS = [path for path in CHAPTERS if not path.name.startswith("lab_")]


@pytest.mark.parametrize(
    "chapter", NOTATION_CHAPTERS, ids=[path.name for path in NOTATION_CHAPTERS]
)
def test_one_notation_for_the_observer_state_and_the_residual(chapter: Path) -> None:
    lines = chapter.read_text(encoding="utf-8").splitlines()
    found = [
        f"line {k}: {line.strip()[:80]}"
        for k, line in enumerate(lines, 1)
        if _OTHER_OBSERVER_STATE.search(line)
    ]
    assert not found, f"{chapter.name}: the observer state is z, r the residual:\n" + "\n".join(
        found
    )


def test_the_notation_table_names_z_d_nv_and_the_residual() -> None:
    text = (BOOK / "introduction.md").read_text(encoding="utf-8")
    table = text[text.index("(sec-introduction-notation)=") :]
    rows = {
        line.split("|")[1].strip(): line for line in table.splitlines() if line.startswith("| $")
    }
    assert "$z$" in rows and "observer" in rows["$z$"]
    assert "$d$" in rows and "$u_2$" in rows["$d$"] and "$v_1, v_2$" in rows["$d$"]
    assert "$n_v$" in rows["$v$"] and "$r = y - C\\hat x$" in rows
