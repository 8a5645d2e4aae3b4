"""Checks for the labs (Practical Assignment 9, the case study, the missile): plain-words feedback.

Each function takes what a lab group produced (matrices, a simulation, a
figure), never raises on a student mistake, and returns a :class:`CheckResult`:
a list of ✓ / ✗ messages that say what is right, what is not, and how to fix it.

* :func:`pa9_design` -- ``H``, ``T``, ``K1`` (and ``F``, ``K2``): the design
  equations (8) of the assignment and the stability of ``F``.
* :func:`pa9_simulation` -- a :func:`~uio_teach.simulate` response with a
  sinusoidal disturbance: the error does not depend on ``d`` and decays.
* :func:`pa9_plot` -- a matplotlib figure: labelled axes showing the error
  ``e`` and the residual ``r``.
* :func:`pa9_piecewise` -- a response with a piecewise-constant disturbance:
  the same error as with the sinusoid; :func:`pa9_piecewise_plot` its figure.
* ``case_study_*`` -- the case-study lab (module ``uio_teach.checks.case_study``).
* ``missile_*`` -- the missile lab (module ``uio_teach.checks.missile``).
* ``uio_teach.checks.common`` -- the result and the helpers every check
  shares (reading matrices, runs and poles); ``uio_teach.checks.plots``
  reads figures (time axes and their units, titles).

Every graded quantity is checked by its defining property and against the
group's own earlier answers (any valid ``H``, any solver's ``P`` and ``Y``),
and a simulation by what the exercise fixes (observer, initial states,
inputs). A ✗ names the mistake and the idea, never a solution line or the
expected number. Every result carries a ``check_id`` such as
``"pa9.design"``.

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach import checks
>>> plant = ut.examples.pa9()
>>> H = plant.E @ np.linalg.pinv(plant.C @ plant.E)
>>> T = np.eye(3) - H @ plant.C
>>> K1 = ut.examples.PA9_PUBLISHED.K1
>>> checks.pa9_design(H, T, K1).passed
True
"""

from .case_study import (
    case_study_lmi,
    case_study_plot,
    case_study_pole,
    case_study_projection,
    case_study_residual,
    case_study_simulation,
)
from .common import CheckResult, clear_collected, collected
from .design import pa9_design
from .missile import (
    missile_catch_times,
    missile_ginverse,
    missile_noise,
    missile_plot,
    missile_pmo,
    missile_reconstruction,
)
from .plots import pa9_piecewise_plot, pa9_plot
from .responses import pa9_piecewise, pa9_simulation

__all__ = [
    "CheckResult",
    "collected",
    "clear_collected",
    "pa9_design",
    "pa9_simulation",
    "pa9_plot",
    "pa9_piecewise",
    "pa9_piecewise_plot",
    "case_study_projection",
    "case_study_lmi",
    "case_study_pole",
    "case_study_simulation",
    "case_study_residual",
    "case_study_plot",
    "missile_pmo",
    "missile_ginverse",
    "missile_reconstruction",
    "missile_catch_times",
    "missile_noise",
    "missile_plot",
]
