"""Every numerical tolerance of the package, in one place, each with its reason.

The algorithms read these names at call time (``tolerances.NAME``), so the one definition here is
the one in use; ``tests/test_tolerances.py`` pins each from both sides (a value a hundred times
looser or tighter fails a named test). The relative tolerances (``*_RTOL``, the margins) are
relative to the size of the data they judge: a verdict of the algorithms does not change when
time, states, inputs or outputs are measured in other units. ``CHECK_ZERO_ATOL`` alone is
absolute: the lab checks judge the course's own plants, whose numbers are of order 1.

Examples
--------
>>> from uio_teach import tolerances
>>> tolerances.IDENTITY_RTOL
1e-08
>>> sorted(tolerances.ALL)[:3]
['AMPLIFICATION_LIMIT', 'CHECK_EXACT_RTOL', 'CHECK_RTOL']
"""

from __future__ import annotations

import numpy as np

EPS = float(np.finfo(float).eps)
"""The relative rounding of every stored number (double precision, ``2.2e-16``)."""

# ranks ------------------------------------------------------------------------------------------

RANK_MARGIN = 1e4
"""A kept singular value below ``RANK_MARGIN`` times its rank threshold makes the verdict marginal:
round-off of data known to a few digits less than double precision could remove it."""

DROP_MARGIN = 10.0
"""A singular value taken as 0 above ``1 / DROP_MARGIN`` of its threshold makes a rank-deficient
verdict marginal (round-off of a product over ``n`` terms sits far below the threshold)."""

RANK_RTOL = 100.0
"""The rank condition's thresholds are ``RANK_RTOL * eps`` (times ``n`` for the product ``C E``)
of the balanced data: the rounding of a product of ``n`` terms, with a hundredfold room."""

STAIRCASE_RTOL = 1e3
"""A singular value of an observability-staircase step counts as 0 below
``STAIRCASE_RTOL * max(shape) * eps`` of the data: each step multiplies by ``A`` once more, and
the rounding of the compressions adds up over up to ``n`` steps."""

# zeros and stability ----------------------------------------------------------------------------

ZERO_RTOL = 10.0
"""The computed invariant zeros are those of a plant within ``ZERO_RTOL * (n + p) * eps``
(relative, in balanced units) of the data, their backward error (the orthogonal staircase
is backward stable with a constant of that order). A zero is decided when no plant that close
has a zero on the stability boundary."""

STABILITY_MARGIN = 1e-9
"""A value counts as stable (``is_stable``) when it lies inside the region by at least this
fraction of its own size (``Re z < -STABILITY_MARGIN |z|``, ``|z| < 1 - STABILITY_MARGIN``), a
margin relative to the value, so it is the same in any unit of time. Also the margin of a gain
the LMI certifies."""

REAL_RTOL = 1e-10
"""An imaginary part below this fraction of a value's size is round-off of a real
value (``sort_poles``: a real pole computed as ``-2 + 1e-15j``), and two requested poles within
this fraction of their size are one pole requested twice (``check_poles``)."""

MODES_RTOL = 1e-5
"""The fixed modes (unobservable modes of the designs' pair) agree with the invariant zeros when
matched one to one within this fraction of their size (two computations, each with its own
round-off; a double zero moves by ``sqrt(eps)``)."""

SPAN_RTOL = 1e-8
"""The eigenvectors of distinct fixed modes span their subspace when the smallest singular value
of the stacked vectors is above this fraction of the largest (below: the modes are repeated or
nearly so, and the subspace is not spanned by eigenvectors)."""

CLOSE_NOTE_RTOL = 1e-3
"""A decided zero closer to the stability boundary than this fraction of its size gets a note in
the report with its distance and how far round-off can move it."""

FIXED_POLE_RTOL = 1e-6
"""A requested pole within this fraction of a fixed mode is that mode (listed with the fixed
modes, or refused as indistinguishable from it)."""

# designs ----------------------------------------------------------------------------------------

POLE_RTOL = 1e-6
"""Obtained poles within this fraction of the requested ones are accepted without a word."""

ROUNDOFF_ROOM = 10.0
"""Obtained poles off by up to this many times their first-order round-off (``n eps ||F||``
times the eigenvalue's condition number, or the distance ``n eps ||F||`` of a matrix having the
requested value as eigenvalue) are accepted without a word: the estimates leave out constants
of order 1 (``check_poles``)."""

WARN_RTOL = 1e-3
"""Obtained poles off by more than round-off explains are accepted with a warning up to this
fraction, refused beyond."""

IDENTITY_RTOL = 1e-8
"""A decoupling identity (``T E = 0``, ``H C E = E``, ``L D = 0``) must hold to this fraction of
its terms, entry by entry."""

LEAK_RTOL = 1e-6
"""A design is returned without a word when the unknown input's gain to the estimation error is
certainly (round-off of the check included) below this fraction of its gain to the state."""

LEAK_REFUSE = 1e-3
"""A design whose bound on that leak exceeds this fraction is refused."""

AMPLIFICATION_LIMIT = 1e6
"""Above this, ``||E|| ||C|| / sigma_min(C E)`` (the size of ``H``) or ``||K|| ||C|| / ||A||``
(the size of the gain) says that a UIO amplifies round-off notably, and is named as the cause
of a leak."""

GAIN_EXACT_RTOL = 1e-9
"""An explicit gain with ``L D`` below this fraction of its largest entry meets ``L D = 0``; it
is taken as it is (the rounding of a gain computed in double precision)."""

GAIN_ROUNDED_RTOL = 1e-3
"""An explicit gain with ``L D`` within this fraction of its largest entry is a rounded copy of
a gain with ``L D = 0`` (printed to a few decimals): it is projected, with a warning; beyond,
refused."""

DECAY_RTOL = 1e-6
"""An LMI gain meets a requested decay rate when every pole is within this fraction of it
(the solver meets its constraints to about ``1e-8``)."""

CONJUGATE_RTOL = 1e-9
"""For requested poles, an imaginary part below this fraction of the poles' size (at least 1) is
round-off of a real pole, and two poles within it of each other's conjugate are one conjugate
pair, typed or computed to round-off; they are made exactly real or conjugate."""

# answers' checks --------------------------------------------------------------------------------

CHECK_ZERO_ATOL = 1e-12
"""An answer's quantity that must vanish (an initial error, a regenerated noise's difference, a
matrix's imaginary parts, relative to its entries) counts as zero below this: the rounding of
numbers of order 1, far below what any typed or rounded number leaves."""

CHECK_EXACT_RTOL = 1e-9
"""An answer recomputed in double precision agrees with the reference to this fraction of the
reference's size (at least 1), entry by entry: a matrix copied or computed from the data passes,
one typed with the digits printed in a document (``0.33`` for ``1/3``) does not."""

CHECK_RUN_RTOL = 1e-8
"""Two computations of one result along different sequences of operations (a student's run
and the check's replay, a run and its replay without the unknown inputs, a gain and the
observer built from it) agree to this fraction of its size (at least 1): the rounding of a
simulation adds up over its steps, to well above ``CHECK_EXACT_RTOL`` of a single product."""

CHECK_RTOL = 1e-6
"""A design, solved or recomputed by the student (poles placed, an LMI solved, a gain
rebuilt), meets what it must to this fraction (at least 1): a solver meets its constraints
to about ``1e-8`` and a double pole moves by ``sqrt(eps)``; a typo or a wrong formula is
farther off."""

# what is shown as zero ---------------------------------------------------------------------------

ROUNDING_RTOL = 1e-9
"""A computed value (a pole, a run's error or residual) below this fraction of its scale is
shown and called zero to rounding (``format_poles``, a panel's "zero to rounding"): eigenvalues
and long recursions carry more rounding than a single product, far less than any design
leaves."""

DISPLAY_ZERO_RTOL = 1e-12
"""An entry (or an imaginary part) of a printed matrix or number below this fraction of the
largest entry shown with it prints as 0: the rounding of a product of data of order 1."""

# time grids -------------------------------------------------------------------------------------

TIME_GRID_RTOL = 1e-9
"""Time points are evenly spaced when every step is within this fraction of the mean step (plus
the rounding of the times themselves)."""

ALL = {
    name: value
    for name, value in dict(globals()).items()
    if name.isupper() and name not in ("EPS", "ALL") and isinstance(value, float)
}
"""Every tolerance by name (``EPS`` is a constant of the arithmetic, not a choice)."""
