"""``import uio_teach`` leaves the heavy optional libraries to the functions that need them."""

from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = pytest.mark.subprocess  # each test starts a fresh interpreter

HEAVY = ("control", "cvxpy", "scipy.signal", "matplotlib.pyplot")

SCRIPT = """
import sys
import uio_teach as ut
plant = ut.worked.pa9.PA9.plant()
ut.existence.decoupling(plant)
print(" ".join(m for m in {heavy!r} if m in sys.modules))
"""


def loaded_after(code: str) -> set[str]:
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    return set(out.split())


def test_importing_and_an_existence_check_load_no_heavy_library():
    assert loaded_after(SCRIPT.format(heavy=HEAVY)) == set()


@pytest.mark.parametrize(
    ("call", "module"),
    [
        ("ut.examples.pa9().as_statespace()", "control"),
        ("ut.design_luenberger(ut.worked.pa9.PA9.plant(), poles=[-1, -1, -1])", "control"),
        ("ut.lmi_gain([[0.5, 1.0], [0.0, 0.9]], [[1.0, 0.0]], dt=True)", "cvxpy"),
    ],
)
def test_the_deferred_import_happens_where_it_is_used(call, module):
    code = f"import sys\nimport uio_teach as ut\n{call}\nprint({module!r} in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split()[-1] == "True"
