"""Every tolerance of ``uio_teach.tolerances`` pinned from both sides.

Each tolerance has a pin: a case a tenth of the way inside what it must accept and a case ten
times outside, both built from the declared value, judged by the package reading the live one.
``test_tolerance_holds`` checks both at the declared value; ``test_tolerance_is_pinned`` sets it
a hundred times looser and a hundred times tighter and checks that its pin then fails (a moved
tolerance fails a named test). A new tolerance without a pin fails
``test_every_tolerance_has_a_pin``, and a literal tolerance written anywhere else in the package
fails ``test_no_tolerance_outside_tolerances_py``.
"""

from __future__ import annotations

import ast
import copy
import sys
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import uio_teach as ut
from uio_teach import tolerances as tols
from uio_teach._display import format_matrix_line, format_poles
from uio_teach._validation import as_poles
from uio_teach.balancing import _split_from_modes, modes_agree
from uio_teach.checks.common import (
    looks_two_decimals,
    rerun_without_unknown_inputs,
    same_poles,
    up_to,
)
from uio_teach.existence import conditioning_condition, rank_condition, zero_condition
from uio_teach.linalg import checked_zeros, is_stable, observability_decomposition, rank_decision
from uio_teach.lmi import _meets_each
from uio_teach.observers.projection import decoupled_gain
from uio_teach.placement import strip_fixed
from uio_teach.simulation import _check_discrete_grid
from uio_teach.verify import (
    DecouplingWarning,
    _condition_numbers,
    check_decoupling,
    check_identity,
    check_poles,
)

DECLARED = dict(tols.ALL)
EPS = tols.EPS
PINS: dict[str, Callable[[], tuple[bool, bool]]] = {}


def pin(name: str):
    def register(fn):
        PINS[name] = fn
        return fn

    return register


def outcome(call) -> str:
    """'ok', 'warned' or 'refused' (an error of the package)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            call()
        except (ValueError, ut.UIOTeachError):
            return "refused"
    return "warned" if caught else "ok"


# ranks ------------------------------------------------------------------------------------------
@pin("RANK_MARGIN")
def _():
    thr = 2 * EPS  # the threshold of diag(1, s): max(shape) eps ||M||
    m = DECLARED["RANK_MARGIN"]
    clear = rank_decision(np.diag([1.0, 10 * m * thr]))
    close = rank_decision(np.diag([1.0, m * thr / 10]))
    return (not clear.marginal and clear.rank == 2), (close.marginal and close.rank == 2)


@pin("DROP_MARGIN")
def _():
    thr = 2 * EPS
    m = DECLARED["DROP_MARGIN"]
    clear = rank_decision(np.diag([1.0, thr / (10 * m)]))
    close = rank_decision(np.diag([1.0, thr / (m / 10)]))
    return (not clear.marginal and clear.rank == 1), (close.marginal and close.rank == 1)


@pin("RANK_RTOL")
def _():
    thr = DECLARED["RANK_RTOL"] * 2 * EPS  # n = 2, ||C|| ||E|| = 1
    A = np.diag([-1.0, -2.0])

    def holds(ce):
        E = np.array([[ce], [1.0]])
        E = E / np.linalg.norm(E)
        return rank_condition(ut.Plant(A, [[1.0, 0.0]], E=E))[0].holds

    return holds(10 * thr), not holds(thr / 10)


@pin("STAIRCASE_RTOL")
def _():
    # (A, [1, c]): the second mode is unobservable when c is round-off of the staircase
    thr = 2 * DECLARED["STAIRCASE_RTOL"] * EPS * 2  # max(shape) rtol eps max(||A||, ||C||)
    A = np.diag([-1.0, -2.0])

    def unobservable(c):
        return observability_decomposition(A, [[1.0, c]]).Au.shape[0]

    return unobservable(10 * thr) == 0, unobservable(thr / 10) == 1


# zeros and stability ----------------------------------------------------------------------------
def _near_axis(a: float) -> ut.Plant:
    """G(s) = (s + a) / ((s + 1)(s + 2)): a zero at -a."""
    return ut.Plant([[0.0, 1.0], [-2.0, -3.0]], [[a, 1.0]], E=[0.0, 1.0])


_R0 = float(checked_zeros(_near_axis(0.0).A, _near_axis(0.0).E, _near_axis(0.0).C).radius[0])
"""How far round-off moves the zero at the declared backward error (the zero at 0)."""


@pin("ZERO_RTOL")
def _():
    def decided(a):
        pl = _near_axis(a)
        return checked_zeros(pl.A, pl.E, pl.C).decided

    return decided(10 * _R0), not decided(_R0 / 10)


@pin("STABILITY_MARGIN")
def _():
    m = DECLARED["STABILITY_MARGIN"]
    inside = is_stable([-10 * m + 1j], discrete=False)[0] and is_stable([1 - 10 * m], True)[0]
    edge = not is_stable([-m / 10 + 1j], discrete=False)[0] and not is_stable([1 - m / 10], True)[0]
    return bool(inside), bool(edge)


@pin("REAL_RTOL")
def _():
    r = DECLARED["REAL_RTOL"]
    real = ut.linalg.sort_poles([-1 + r / 10 * 1j])[0].imag == 0
    kept = ut.linalg.sort_poles([-1 + 10 * r * 1j, -1 - 10 * r * 1j])[0].imag != 0
    return bool(real), bool(kept)


@pin("MODES_RTOL")
def _():
    r = DECLARED["MODES_RTOL"]
    return modes_agree([-1 - r / 10], [-1.0]), not modes_agree([-1 - 10 * r], [-1.0])


@pin("SPAN_RTOL")
def _():
    # two unobservable modes whose eigenvectors are nearly parallel (an angle of about d)
    r = DECLARED["SPAN_RTOL"]

    def spanned(d):
        A = np.array([[-1.0, 1.0], [0.0, -1.0 - d]])
        return _split_from_modes(A, np.zeros((1, 2)), np.array([-1.0, -1.0 - d])) is not None

    return spanned(10 * r * np.sqrt(2)), not spanned(r / 10 * np.sqrt(2))


@pin("CLOSE_NOTE_RTOL")
def _():
    r = DECLARED["CLOSE_NOTE_RTOL"]  # against the spectral radius 2 of the plant

    def noted(a):
        pl = _near_axis(a)
        return "the closest" in zero_condition(checked_zeros(pl.A, pl.E, pl.C)).reason

    return noted(2 * r / 10), not noted(2 * r * 10)


@pin("FIXED_POLE_RTOL")
def _():
    r = DECLARED["FIXED_POLE_RTOL"]
    fixed = np.array([-2.0 + 0j])
    same = strip_fixed(np.array([-1.0, -2.0 - 2 * r / 10]), fixed).size == 1
    other = strip_fixed(np.array([-1.0, -2.0 - 2 * r * 10]), fixed).size == 2
    return same, other


# designs ----------------------------------------------------------------------------------------
def _poles_off(e: float) -> str:
    return outcome(lambda: check_poles(np.diag([-1.0, -2.0]), [-1.0 - e, -2.0]))


@pin("POLE_RTOL")
def _():
    r = DECLARED["POLE_RTOL"]
    return _poles_off(r / 10) == "ok", _poles_off(10 * r) == "warned"


@pin("WARN_RTOL")
def _():
    r = DECLARED["WARN_RTOL"]
    return _poles_off(r / 10) == "warned", _poles_off(10 * r) == "refused"


@pin("ROUNDOFF_ROOM")
def _():
    # an eigenvalue of condition number about 1e5: its round-off n eps ||F|| kappa is 4.4e-6,
    # above POLE_RTOL, so only ROUNDOFF_ROOM accepts an error of that order
    F = np.array([[-1.0, 1e5], [0.0, -2.0]])
    w, kappa = _condition_numbers(F)
    unit = 2 * EPS * np.linalg.norm(F, 2) * kappa[np.argmin(abs(w + 1))]
    room = DECLARED["ROUNDOFF_ROOM"]

    def off(c):
        return outcome(lambda: check_poles(F, [-1.0 - c * unit, -2.0]))

    return off(room / 10) == "ok", off(10 * room) == "warned"


@pin("IDENTITY_RTOL")
def _():
    r = DECLARED["IDENTITY_RTOL"]

    def holds(x):
        return outcome(lambda: check_identity("T E = 0", np.array([[x]]), 1.0)) == "ok"

    return holds(r / 10), not holds(10 * r)


# x1 is measured (xhat1 = y) and drives x2; the gain [0; 1 + off] leaks about off times c
_A = np.array([[-1.0, 0.0], [1.0, -2.0]])
_E, _C, _DY = np.array([[1.0], [0.0]]), np.array([[1.0, 0.0]]), np.array([[1.0], [0.0]])


def _leak(off: float) -> str:
    K = np.array([[0.0], [1.0 + off]])
    return outcome(lambda: check_decoupling(_A, _E, _C, _A, K, np.eye(2), _DY))


with warnings.catch_warnings():
    warnings.simplefilter("ignore", DecouplingWarning)
    _K = np.array([[0.0], [1.0 + 1e-4]])
    _PER_OFF = check_decoupling(_A, _E, _C, _A, _K, np.eye(2), _DY).bound / 1e-4


@pin("LEAK_RTOL")
def _():
    r = DECLARED["LEAK_RTOL"] / _PER_OFF
    return _leak(r / 10) == "ok", _leak(10 * r) == "warned"


@pin("LEAK_REFUSE")
def _():
    r = DECLARED["LEAK_REFUSE"] / _PER_OFF
    return _leak(r / 10) == "warned", _leak(10 * r) == "refused"


@pin("AMPLIFICATION_LIMIT")
def _():
    limit = DECLARED["AMPLIFICATION_LIMIT"]
    A = np.diag([-1.0, -2.0])

    def holds(amp):
        E = np.array([[1.0 / amp], [1.0]])
        return conditioning_condition(ut.Plant(A, [[1.0, 0.0]], E=E / np.linalg.norm(E))).holds

    return holds(limit / 10), not holds(limit * 10)


_GAIN_PLANT = ut.Plant([[-1.0]], [[1.0], [1.0]], D=[[1.0], [0.0]])


def _gain(r: float) -> str:
    return outcome(lambda: decoupled_gain("K1", _GAIN_PLANT, [[r, 1.0]]))


@pin("GAIN_EXACT_RTOL")
def _():
    r = DECLARED["GAIN_EXACT_RTOL"]
    return _gain(r / 10) == "ok", _gain(10 * r) == "warned"


@pin("GAIN_ROUNDED_RTOL")
def _():
    r = DECLARED["GAIN_ROUNDED_RTOL"]
    return _gain(r / 10) == "warned", _gain(10 * r) == "refused"


@pin("CONJUGATE_RTOL")
def _():
    r = DECLARED["CONJUGATE_RTOL"]  # poles of size below 1: the tolerance is absolute

    def paired(e):
        return outcome(lambda: as_poles("poles", [-0.3 + 0.4j, -0.3 - 0.4j + e * 1j])) == "ok"

    return paired(r / 10), not paired(10 * r)


# answers' checks --------------------------------------------------------------------------------
@pin("CHECK_ZERO_ATOL")
def _():
    r = DECLARED["CHECK_ZERO_ATOL"]
    return up_to(r / 10, "x") == " (up to rounding)", up_to(10 * r, "x") != " (up to rounding)"


@pin("CHECK_EXACT_RTOL")
def _():
    # a matrix typed with the 2 decimals of a document, off by e from them (scale 1)
    r = DECLARED["CHECK_EXACT_RTOL"]
    exact = np.array([[1 / 3, -0.25]])

    def typed(e):
        return looks_two_decimals(np.array([[0.33 + e, -0.25]]), exact)

    return typed(r / 10), not typed(10 * r)


_RUN = ut.simulate(
    ut.Plant([[-1.0]], [[1.0]], E=[[1.0]]),
    ut.design_luenberger(ut.Plant([[-1.0]], [[1.0]], E=[[1.0]]), poles=[-3.0]),
    np.linspace(0.0, 1.0, 11),
    initial_state=[2.0],
)


@pin("CHECK_RUN_RTOL")
def _():
    # the run replayed without its (absent) unknown input is the run itself: a change e of its
    # error, relative to its largest state (2), is what the replay finds
    r = DECLARED["CHECK_RUN_RTOL"]

    def same(e):
        run = copy.copy(_RUN)
        run.error = _RUN.error.copy()
        run.error[0, -1] += e * 2.0
        return rerun_without_unknown_inputs(run)[1]

    return same(r / 10), not same(10 * r)


@pin("CHECK_RTOL")
def _():
    r = DECLARED["CHECK_RTOL"]
    return same_poles([-1 - r / 10, -2.0], [-2.0, -1.0]), not same_poles(
        [-1 - 10 * r, -2], [-2, -1]
    )


@pin("DECAY_RTOL")
def _():
    r = DECLARED["DECAY_RTOL"]
    meets = _meets_each(np.array([-1 + r / 10 + 0j]), False, 1.0)[0]
    misses = not _meets_each(np.array([-1 + 10 * r + 0j]), False, 1.0)[0]
    return bool(meets), bool(misses)


# what is shown as zero -------------------------------------------------------------------------
@pin("ROUNDING_RTOL")
def _():
    r = DECLARED["ROUNDING_RTOL"]
    return format_poles([-1 + r / 10 * 1j]) == "-1", format_poles([-1 + 10 * r * 1j]) != "-1"


@pin("DISPLAY_ZERO_RTOL")
def _():
    r = DECLARED["DISPLAY_ZERO_RTOL"]
    shown = format_matrix_line([[1.0, r / 10]]) == "[[1, 0]]"
    kept = format_matrix_line([[1.0, 10 * r]]) != "[[1, 0]]"
    return shown, kept


@pin("TIME_GRID_RTOL")
def _():
    r = DECLARED["TIME_GRID_RTOL"]
    plant = ut.Plant([[0.5]], [[1.0]], dt=1.0)

    def on_grid(e):
        return outcome(lambda: _check_discrete_grid(plant, np.arange(11) * (1 + e))) == "ok"

    return on_grid(r / 10), not on_grid(10 * r)


# the tests --------------------------------------------------------------------------------------
def test_every_tolerance_has_a_pin():
    assert set(PINS) == set(tols.ALL)


@pytest.mark.parametrize("name", sorted(tols.ALL))
def test_tolerance_holds(name):
    inside, outside = PINS[name]()
    assert inside, f"{name}: a case a tenth inside is not accepted"
    assert outside, f"{name}: a case ten times outside is not refused"


@pytest.mark.parametrize("factor", [100.0, 0.01], ids=["looser", "tighter"])
@pytest.mark.parametrize("name", sorted(tols.ALL))
def test_tolerance_is_pinned(name, factor, monkeypatch):
    monkeypatch.setattr(tols, name, DECLARED[name] * factor)
    inside, outside = PINS[name]()
    assert not (inside and outside), f"{name} x {factor:g} passes its pin: it is not pinned"


# no tolerance outside tolerances.py -------------------------------------------------------------
PACKAGE = Path(ut.__file__).resolve().parent
SMALL = 1e-3
"""A float literal below this in size, where a comparison reads it, is a tolerance."""
RANGE_GUARD = 1e-100
"""Below this a literal is a floor against division by zero or underflow (``max(x, 1e-300)``),
far below the rounding of any data: a guard of the float range, not a tolerance."""
JUDGES = {"close", "allclose", "isclose", "assert_allclose", "same_poles"}
"""Calls whose positional arguments are compared."""

ALLOWED = {
    ("explorers/_figure.py", "ExplorerFigure._find_cells", 1e-6): (
        "layout geometry: which axes boxes of a figure touch, in figure fractions (no number of "
        "the course is judged)"
    ),
    ("explorers/modes.py", "excited_modes", 1e-7): (
        "the Arnoldi stopping size of the explorers' 'excited mode' marks, a widget's highlight "
        "rather than a verdict on a design"
    ),
    ("explorers/modes.py", "match_poles", 1e-4): (
        "matches Ritz values of a short Krylov space (accurate to its own stopping size, not to "
        "round-off) to the poles, for a widget's highlight"
    ),
    ("explorers/frames.py", "_modes", 1e-6): (
        "a repeated pole's copies share a widget's 'excited' mark when they sit within the "
        "Krylov marks' accuracy of each other"
    ),
    ("lab_params.py", "direction_key", 1e-12): (
        "the sign convention of a unit vector used as a lab variant's key: its first entry "
        "above the rounding of a normalized vector of order 1 decides the sign"
    ),
    ("worked/pa9.py", "_pa9_luenberger", 1e-6): (
        "the wording of a figure's description (two runs 'lie on top of each other' at the "
        "figure's resolution), not a verdict"
    ),
}
"""Small literals in comparisons that are not tolerances of the package, each with its reason."""


def _qualname(node, parents) -> str:
    names = []
    while node in parents:
        node = parents[node]
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.append(node.name)
    return ".".join(reversed(names)) or "<module>"


def _compared(node, parents) -> str | None:
    """How the small literal ``node`` is used to judge a number, or None."""
    child, computed = node, False  # computed: an argument of a computation (a grid's end)
    while child in parents:
        up = parents[child]
        if isinstance(up, ast.Compare):
            return "a comparison"
        if isinstance(up, ast.keyword) and up.arg and "tol" in up.arg:
            return f"{up.arg}="
        if isinstance(up, ast.Call) and child in up.args:
            name = (
                up.func.attr if isinstance(up.func, ast.Attribute) else getattr(up.func, "id", "")
            )
            if name in JUDGES:
                return f"an argument of {name}()"
            computed = True
        if isinstance(up, ast.arguments):
            return "a default argument"
        if isinstance(up, (ast.Assign, ast.AnnAssign)):
            targets = up.targets if isinstance(up, ast.Assign) else [up.target]
            names = [t.id for t in targets if isinstance(t, ast.Name)]
            if isinstance(parents.get(up), (ast.Module, ast.ClassDef)) and any(
                n.lstrip("_").isupper() for n in names
            ):
                return "a module constant"
            if computed:
                return None
            scope = up
            while scope in parents and not isinstance(scope, (ast.FunctionDef, ast.Module)):
                scope = parents[scope]
            for cmp in ast.walk(scope):
                if isinstance(cmp, ast.Compare) and any(
                    isinstance(n, ast.Name) and n.id in names for n in ast.walk(cmp)
                ):
                    return f"{', '.join(names)}, compared later"
            return None
        if isinstance(up, ast.stmt):
            return None
        child = up
    return None


def literal_tolerances() -> list[tuple[str, int, str, float, str]]:
    """Every small float literal that judges a number, outside ``tolerances.py``."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel == "tolerances.py":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        parents = {c: p for p in ast.walk(tree) for c in ast.iter_child_nodes(p)}
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Constant) and type(node.value) is float):
                continue
            if not RANGE_GUARD < abs(node.value) < SMALL:
                continue
            how = _compared(node, parents)
            if how:
                found.append((rel, node.lineno, _qualname(node, parents), node.value, how))
    return found


def test_no_tolerance_outside_tolerances_py():
    stray = [
        f"uio_teach/{rel}:{line} ({where}): {value:g} in {how}"
        for rel, line, where, value, how in literal_tolerances()
        if (rel, where, value) not in ALLOWED
    ]
    assert not stray, (
        "literal tolerances outside uio_teach/tolerances.py (declare them there, with their "
        "reason and a pin, or add them to ALLOWED with the reason they are no tolerance):\n"
        + "\n".join(stray)
    )


def test_allowed_literals_are_still_there():
    seen = {(rel, where, value) for rel, _, where, value, _ in literal_tolerances()}
    assert not set(ALLOWED) - seen, f"stale entries of ALLOWED: {sorted(set(ALLOWED) - seen)}"


def test_the_scan_finds_a_literal_tolerance(tmp_path, monkeypatch):
    # the scan itself: a literal compared directly, through a local name and as a default
    pkg = tmp_path / "uio_teach"
    pkg.mkdir()
    (pkg / "mod.py").write_text(
        "LIMIT = 1e-7\n"
        "def f(x, tol=1e-6):\n"
        "    tiny = 1e-9 * abs(x)\n"
        "    grid = np.geomspace(1e-30, 1.0, 5)\n"
        "    if x < 1e-8 or x < tiny or x in grid:\n"
        "        return max(x, 1e-300)\n"
        "    return close(x, 0, 1e-5) and np.allclose(x, 0, atol=1e-4)\n"
    )
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", pkg)
    got = {(value, how) for _, _, _, value, how in literal_tolerances()}
    assert got == {
        (1e-7, "a module constant"),
        (1e-6, "a default argument"),
        (1e-9, "tiny, compared later"),
        (1e-8, "a comparison"),
        (1e-5, "an argument of close()"),
        (1e-4, "atol="),
    }
