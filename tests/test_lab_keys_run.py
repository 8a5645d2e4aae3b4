"""Every key of the term config that reaches a lab changes what its solution computes.

For each key of the schema (changed by ``term_changes``, no list of keys here) that changes a
lab's ``PARAMS``, the lab's solution notebook (as ``uio-teach labs`` writes it) is run with the
changed ``PARAMS`` and its results are compared with the run on the course's numbers: every
array its cells leave behind and every curve of its figures. A key that changes nothing there
is a number the instructor set and the students never run; it fails here by name, unless
``UNREAD_CONFIG_KEYS`` says why the notebooks do not read it (``uio-teach labs`` then says so).

The notebooks' code runs in this process (no kernel: the code cells of the solution notebook in
order, in one namespace, with matplotlib's Agg backend), once per lab and once per key: a few
minutes in all, so the module is marked ``slow`` (``make test-slow`` and CI run it). The
quick test of the same promise (the code reads the changed ``PARAMS`` entry) is in
``test_labs.py``.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json

import matplotlib
import numpy as np
import pytest
from lab_outputs import tags
from term_changes import changed_values, nested, reached

from uio_teach.instructor import labs
from uio_teach.instructor.config import FigureConfig

pytestmark = pytest.mark.slow

BOOK = labs.default_book_dir()


def _arrays(value, depth=0):
    if isinstance(value, np.ndarray) and value.dtype.kind in "fciub":
        yield value
    elif depth < 2 and isinstance(value, (list, tuple)):
        for v in value:
            yield from _arrays(v, depth + 1)
    elif depth < 1 and hasattr(value, "__dict__") and not isinstance(value, type):
        for v in vars(value).values():
            yield from _arrays(v, depth + 1)


def run_solution(lab_id: str, params: dict) -> dict[str, str]:
    """What the solution notebook computes with ``params``: a digest per variable and figure."""
    import matplotlib.pyplot as plt

    matplotlib.use("Agg")
    nb = labs.make_notebook(BOOK / labs.LABS[lab_id].source, "solution")
    ns: dict = {"display": lambda *a, **k: None}
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        source = cell.source
        if "parameters" in tags(cell):
            source = f"PARAMS = {json.dumps(params)}"
            source = source.replace("true", "True").replace("false", "False")
        with contextlib.redirect_stdout(io.StringIO()):
            exec(compile(source, f"<{lab_id} cell>", "exec"), ns)  # noqa: S102
    out = {}
    for name, value in ns.items():
        if name.startswith("_") or name == "PARAMS":
            continue
        digest = hashlib.sha256()
        for arr in _arrays(value):
            digest.update(np.round(np.asarray(arr, complex), 9).tobytes())
        out[name] = digest.hexdigest()
    for num in plt.get_fignums():
        fig = plt.figure(num)
        digest = hashlib.sha256()
        for ax in fig.axes:
            for line in ax.get_lines():
                digest.update(np.round(np.asarray(line.get_ydata(), float), 9).tobytes())
        out[f"figure {num}"] = digest.hexdigest()
    plt.close("all")
    return out


@pytest.fixture(scope="module")
def course_runs():
    return {
        lab_id: run_solution(lab_id, lab.params.from_config(FigureConfig()).to_params())
        for lab_id, lab in labs.LABS.items()
    }


def unread(lab_id: str, key: str) -> bool:
    return any(lab_id in e.labs and key in e.keys for e in labs.UNREAD_CONFIG_KEYS)


LAB_KEYS = [
    key
    for key, (value, _) in changed_values().items()
    if value is not None and reached(FigureConfig.from_dict(nested({key: value})))
]


@pytest.mark.parametrize("key", LAB_KEYS)
def test_the_solution_notebook_computes_something_else_with_the_key_changed(course_runs, key):
    value = changed_values()[key][0]
    config = FigureConfig.from_dict(nested({key: value}))
    for lab_id in reached(config):
        if unread(lab_id, key):
            continue
        params = labs.LABS[lab_id].params.from_config(config).to_params()
        changed = run_solution(lab_id, params)
        differ = [name for name in changed if changed[name] != course_runs[lab_id].get(name)]
        assert differ, (
            f"{key} = {value!r} reaches the PARAMS of the {lab_id} lab, but its solution "
            f"notebook computes the same arrays and draws the same curves as with the course's "
            f"value: the students would run a number the instructor did not set. Wire "
            f"{key} into the code of {labs.LABS[lab_id].source} (or name it in "
            "UNREAD_CONFIG_KEYS with the reason)"
        )
