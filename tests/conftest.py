"""Shared set-up of the tests, and markers that say what each test needs.

Figures are drawn off screen (matplotlib's Agg backend), once for every test module.

Each test is marked by what it needs, read from the test modules themselves (their module, the
fixtures a test uses, and what its code and its fixtures' code call), so that a new test is
marked without anyone remembering to:

``kernel``
    starts a Jupyter kernel (executes a notebook: the chapters, the lab notebooks, grading);
``book``
    builds or executes the book;
``browser``
    drives headless Chromium over built pages (marked in the test modules);
``wheel``
    builds the package's wheel and runs it outside the checkout;
``subprocess``
    starts a Python process (the command line, a fresh interpreter); also ``slow``;
``doctest``
    runs the examples in the package's docstrings; the long ones are also ``slow``;
``slow``
    any other test that takes long (listed in ``SLOW``).

``make check`` runs what needs none of kernel, browser, book, wheel or slow; ``make test`` runs
everything.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

# What a whole test module needs.
MODULE_MARKS = {
    "test_chapters": {"kernel", "book"},
    "test_grade": {"kernel"},
    "test_book": {"book"},
}
# What a fixture or a test of a test module needs (a fixture's marks go to every test using it).
FIXTURE_MARKS = {
    ("test_packaging", "installed"): {"wheel", "slow"},
}
# The tests (or fixtures) that take over 10 s each on a busy 2-core machine: every course figure
# drawn, every lab written, exhaustive sweeps of the explorers' controls, all static frames of an
# explorer pre-computed, hypothesis searches over scaled plants. They are `slow`, run by
# `make test`; the quick loop keeps the cheaper tests of the same code.
SLOW = {
    "test_cli": {"two_runs", "test_vector_formats_are_deterministic_too"},
    "test_explorers": {
        "test_every_setting_gives_a_picture_or_a_message",
        "test_fast_draw_matches_a_full_draw",
    },
    "test_widgets": {
        "test_every_control_value_gives_a_picture_or_a_message",
        "test_mimebundle_has_the_widget_and_the_static_frames",
        "pa9_static",
        "test_static_missile_page_is_light",
        "test_static_ids_are_unique_and_frames_differ",
        "test_missile_filter_slider_redraws_the_reconstruction",
        "test_drag_uses_an_ipympl_canvas_and_redraws_after_a_resize",
        "test_rerunning_a_cell_frees_the_previous_explorer",
        "test_case_study_pole_and_lmi_mode",
    },
    "test_scaled_properties": {"test_uio_on_scaled_plants_decouples_or_refuses"},
    "test_lab_variants": {
        "variants",
        "test_another_seed_gives_other_numbers",
        "test_the_same_seed_gives_byte_identical_files",
    },
    "test_instructor_output": {
        "test_a_good_run_over_last_term_leaves_only_this_terms_files",
        "test_the_same_run_gives_the_same_manifest",
    },
}
# Names whose use in a test, its fixtures or the module's helpers they call says what it needs.
CALL_MARKS = {
    "nbclient": {"kernel"},
    "NotebookClient": {"kernel"},
    "subprocess": {"subprocess", "slow"},
}
# Package modules whose docstring examples take long (over 5 s on a busy 2-core machine:
# explorers built, lab notebooks written, figures drawn).
SLOW_DOCTESTS = {
    "uio_teach.explorers._drag",
    "uio_teach.explorers._figure",
    "uio_teach.explorers.widgets",
    "uio_teach.explorers.static",
    "uio_teach.instructor.labs",
    "uio_teach.instructor.figures",
}


@functools.cache
def reached_names(path: Path) -> dict[str, set[str]]:
    """Each top-level function of a test module -> the names its code uses (and its arguments).

    The names a function reaches through the module's other functions are included, so a test
    that calls a helper, or uses a fixture, that runs ``nbclient`` is found to need a kernel.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"))
    direct: dict[str, set[str]] = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            names = {a.arg for a in node.args.args}
            for sub in ast.walk(node):
                if isinstance(sub, ast.Name):
                    names.add(sub.id)
                elif isinstance(sub, ast.Attribute):
                    names.add(sub.attr)
            direct[node.name] = names
    reach = {name: set(names) for name, names in direct.items()}
    changed = True
    while changed:
        changed = False
        for name, names in reach.items():
            extra = set().union(*(reach[n] for n in names & reach.keys() if n != name)) - names
            if extra:
                names |= extra
                changed = True
    return reach


def marks_for(item: pytest.Item) -> set[str]:
    """The markers ``item`` needs, from its module, its fixtures and what its code calls."""
    module = Path(str(item.fspath))
    stem = module.stem
    marks = set(MODULE_MARKS.get(stem, ()))
    function = getattr(item, "originalname", item.name)
    for fixture in getattr(item, "fixturenames", ()):
        marks |= FIXTURE_MARKS.get((stem, fixture), set())
    if SLOW.get(stem, set()) & {function, *getattr(item, "fixturenames", ())}:
        marks.add("slow")
    reached = reached_names(module).get(function, set())
    for name, needs in CALL_MARKS.items():
        if name in reached:
            marks |= needs
    if stem == "test_api_docs" and function == "test_docstring_examples_run":
        marks.add("doctest")
        if item.callspec.params.get("modname") in SLOW_DOCTESTS:
            marks.add("slow")
    return marks


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        present = {mark.name for mark in item.iter_markers()}
        for name in sorted(marks_for(item) - present):
            item.add_marker(getattr(pytest.mark, name))
