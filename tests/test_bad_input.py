"""Catalogue of bad arguments: each is refused with the right exception and names the argument.

Every case is ``(call, exception type, pattern)``; the pattern must name the argument (or the
matrix) that is wrong, so that a student knows what to fix.
"""

import warnings

import numpy as np
import pytest

import uio_teach as ut
from uio_teach.lmi import LMIInfeasibleError
from uio_teach.placement import place_observer_poles
from uio_teach.verify import PlacementAccuracyError

PA9 = ut.examples.pa9()
CASE = ut.examples.dt_case_study()
MISSILE = ut.examples.missile_autopilot()
UIO = ut.design_uio(PA9, poles=[-1, -2, -3])
T = np.linspace(0.0, 1.0, 11)
A2 = [[0.0, 1.0], [-2.0, -3.0]]
C2 = [[1.0, 0.0]]


def _sim(**kwargs):
    args = {"plant": PA9, "observer": UIO, "timepts": T}
    args.update(kwargs)
    return ut.simulate(args.pop("plant"), args.pop("observer"), args.pop("timepts"), **args)


def _reconstruct(**kwargs):
    run = _sim(d=ut.signals.step(1.0))
    return ut.reconstruct_input(PA9, run, **kwargs)


CPLX = np.array([[0.0, 1.0], [-2.0, -3.0 + 1e-3j]])

CATALOGUE = [
    # --- Plant: matrices ------------------------------------------------------------------
    ("plant-A-complex", lambda: ut.Plant(CPLX, C2), ValueError, r"^A must .*complex"),
    ("plant-A-complex-list", lambda: ut.Plant([[1j]], [[1.0]]), ValueError, r"^A must .*complex"),
    ("plant-C-complex", lambda: ut.Plant(A2, np.array([[1 + 1j, 0]])), ValueError, r"^C must"),
    ("plant-B-complex", lambda: ut.Plant(A2, C2, B=np.array([1j, 0])), ValueError, r"^B must"),
    ("plant-E-complex", lambda: ut.Plant(A2, C2, E=np.array([0, 1j])), ValueError, r"^E must"),
    ("plant-D-complex", lambda: ut.Plant(A2, C2, D=np.array([1j])), ValueError, r"^D must"),
    ("plant-A-text", lambda: ut.Plant("abc", C2), ValueError, r"^A must"),
    ("plant-A-text-entry", lambda: ut.Plant([[1, "2"], [0, 1]], C2), ValueError, r"^A must"),
    ("plant-A-string-number", lambda: ut.Plant([["1"]], [[1]]), ValueError, r"^A must"),
    ("plant-A-nan", lambda: ut.Plant([[np.nan]], [[1]]), ValueError, r"^A has a non-finite"),
    ("plant-A-inf", lambda: ut.Plant([[np.inf]], [[1]]), ValueError, r"^A has a non-finite"),
    ("plant-A-not-square", lambda: ut.Plant(np.ones((2, 3)), C2), ValueError, r"^A has shape"),
    ("plant-A-3d", lambda: ut.Plant(np.ones((2, 2, 2)), C2), ValueError, r"^A must be a 2-D"),
    ("plant-A-ragged", lambda: ut.Plant([[1, 2], [3]], C2), ValueError, r"^A must"),
    ("plant-C-shape", lambda: ut.Plant(A2, [[1.0, 0.0, 0.0]]), ValueError, r"^C has shape"),
    ("plant-E-shape", lambda: ut.Plant(A2, C2, E=[0, 1, 0]), ValueError, r"^E has shape"),
    ("plant-D-shape", lambda: ut.Plant(A2, C2, D=np.ones((2, 1))), ValueError, r"^D has shape"),
    ("plant-dt-text", lambda: ut.Plant(A2, C2, dt="abc"), ValueError, r"^dt must"),
    ("plant-dt-negative", lambda: ut.Plant(A2, C2, dt=-1), ValueError, r"^dt must"),
    ("plant-dt-nan", lambda: ut.Plant(A2, C2, dt=np.nan), ValueError, r"^dt must"),
    # --- designs: gains and options ------------------------------------------------------
    ("uio-K1-complex", lambda: ut.design_uio(PA9, K1=np.ones((3, 2)) * 1j), ValueError, r"^K1"),
    ("uio-K1-shape", lambda: ut.design_uio(PA9, K1=np.ones((2, 2))), ValueError, r"^K1 has shape"),
    ("uio-K1-nan", lambda: ut.design_uio(PA9, K1=np.full((3, 2), np.nan)), ValueError, r"^K1"),
    ("uio-poles-text", lambda: ut.design_uio(PA9, poles="abc"), ValueError, r"^poles"),
    ("uio-poles-nan", lambda: ut.design_uio(PA9, poles=[np.nan, -1, -2]), ValueError, r"^poles"),
    ("uio-poles-count", lambda: ut.design_uio(PA9, poles=[-1, -2]), ValueError, r"^poles"),
    (
        "uio-poles-unpaired",
        lambda: ut.design_uio(PA9, poles=[-1 + 1j, -2, -3]),
        ValueError,
        r"^poles",
    ),
    ("uio-plant-type", lambda: ut.design_uio("plant", poles=[-1]), ValueError, r"^plant"),
    ("pmo-L-complex", lambda: ut.design_pmo(PA9, L=np.ones((3, 2)) * 1j), ValueError, r"^L must"),
    ("pmo-L-shape", lambda: ut.design_pmo(PA9, L=np.ones((3, 3))), ValueError, r"^L has shape"),
    (
        "pmo-Mv-complex",
        lambda: ut.design_pmo(MISSILE, [-80, -120], Mv=np.ones((4, 2)) * 1j),
        ValueError,
        r"^Mv",
    ),
    (
        "pmo-Mv-shape",
        lambda: ut.design_pmo(MISSILE, [-80, -120], Mv=np.ones((2, 2))),
        ValueError,
        r"^Mv has shape",
    ),
    ("pmo-method", lambda: ut.design_pmo(PA9, [-1, -2, -3], method="nope"), ValueError, r"^method"),
    ("pmo-decay-text", lambda: ut.design_pmo(CASE, method="lmi", decay="a"), ValueError, r"^decay"),
    (
        "ginv-Kv-complex",
        lambda: ut.design_ginverse(MISSILE, Kv=np.ones((4, 2)) * 1j),
        ValueError,
        r"^Kv",
    ),
    (
        "ginv-Kv-shape",
        lambda: ut.design_ginverse(MISSILE, Kv=np.ones((2, 2))),
        ValueError,
        r"^Kv has shape",
    ),
    (
        "ginv-Kv-positional",
        lambda: ut.design_ginverse(MISSILE, np.zeros((4, 2))),
        TypeError,
        r"positional",
    ),
    (
        "luen-L-complex",
        lambda: ut.design_luenberger(PA9, L=np.ones((3, 2)) * 1j),
        ValueError,
        r"^L must",
    ),
    ("luen-L-text", lambda: ut.design_luenberger(PA9, L="L"), ValueError, r"^L must"),
    (
        "luen-poles-huge",
        lambda: ut.design_luenberger(
            ut.Plant(np.diag([1.0, 2, 3]), [[1, 1, 1]]), poles=[-1e300, -2, -3]
        ),
        PlacementAccuracyError,
        r"requested \{-1e\+300",
    ),
    ("place-A-complex", lambda: place_observer_poles(CPLX, C2, [-1, -2]), ValueError, r"^A must"),
    (
        "place-C-shape",
        lambda: place_observer_poles(A2, [[1.0]], [-1, -2]),
        ValueError,
        r"^C has shape",
    ),
    # --- lmi_gain ------------------------------------------------------------------------
    (
        "lmi-A1-complex",
        lambda: ut.lmi_gain(np.array([[0.5j]]), [[1.0]], dt=True),
        ValueError,
        r"^A1 must",
    ),
    (
        "lmi-A1-not-square",
        lambda: ut.lmi_gain(np.ones((2, 3)), [[1.0, 0, 0]]),
        ValueError,
        r"^A1 has shape",
    ),
    (
        "lmi-C-complex",
        lambda: ut.lmi_gain([[0.5]], np.array([[1j]]), dt=True),
        ValueError,
        r"^C must",
    ),
    (
        "lmi-D-complex",
        lambda: ut.lmi_gain([[0.5]], [[1.0]], D=np.array([[1j]]), dt=True),
        ValueError,
        r"^D must",
    ),
    ("lmi-dt-text", lambda: ut.lmi_gain([[0.5]], [[1.0]], dt="abc"), ValueError, r"^dt must"),
    ("lmi-dt-negative", lambda: ut.lmi_gain([[0.5]], [[1.0]], dt=-1), ValueError, r"^dt must"),
    ("lmi-dt-list", lambda: ut.lmi_gain([[0.5]], [[1.0]], dt=[1]), ValueError, r"^dt must"),
    (
        "lmi-solver-unknown",
        lambda: ut.lmi_gain([[0.5]], [[1.0]], dt=True, solver="NOPE"),
        ValueError,
        r"^solver must .*CLARABEL",
    ),
    (
        "lmi-solver-type",
        lambda: ut.lmi_gain([[0.5]], [[1.0]], dt=True, solver=3),
        ValueError,
        r"^solver must",
    ),
    (
        "lmi-decay-text",
        lambda: ut.lmi_gain([[0.5]], [[1.0]], dt=True, decay="a"),
        ValueError,
        r"^decay must be a real",
    ),
    (
        "lmi-decay-bool",
        lambda: ut.lmi_gain([[0.5]], [[1.0]], dt=True, decay=True),
        ValueError,
        r"^decay must be a real",
    ),
    (
        "lmi-decay-range-dt",
        lambda: ut.lmi_gain([[0.5]], [[1.0]], dt=True, decay=1.5),
        ValueError,
        r"^decay must satisfy",
    ),
    (
        "lmi-decay-negative-ct",
        lambda: ut.lmi_gain([[-1.0]], [[1.0]], decay=-1),
        ValueError,
        r"^decay must satisfy",
    ),
    (
        "lmi-decay-nan",
        lambda: ut.lmi_gain([[-1.0]], [[1.0]], decay=np.nan),
        ValueError,
        r"^decay must satisfy",
    ),
    (
        "lmi-boundary-mode",
        lambda: ut.lmi_gain(np.diag([1.0, 0.3]), [[0, 1.0]], dt=True),
        LMIInfeasibleError,
        r"mode\(s\) 1 cannot be moved",
    ),
    # --- simulate ------------------------------------------------------------------------
    ("sim-seed-negative", lambda: _sim(noise=0.1, seed=-1), ValueError, r"^seed must"),
    ("sim-seed-float", lambda: _sim(noise=0.1, seed=1.5), ValueError, r"^seed must"),
    ("sim-seed-text", lambda: _sim(noise=0.1, seed="x"), ValueError, r"^seed must"),
    ("sim-seed-bool", lambda: _sim(noise=0.1, seed=True), ValueError, r"^seed must"),
    ("sim-seed-without-noise", lambda: _sim(seed=-3), ValueError, r"^seed must"),
    ("sim-noise-text", lambda: _sim(noise="0.1"), ValueError, r"^noise must"),
    ("sim-noise-negative", lambda: _sim(noise=-0.1), ValueError, r"^noise"),
    ("sim-noise-nan", lambda: _sim(noise=np.nan), ValueError, r"^noise"),
    ("sim-noise-complex", lambda: _sim(noise=0.1j), ValueError, r"^noise must be real"),
    ("sim-noise-shape", lambda: _sim(noise=[0.1, 0.1, 0.1]), ValueError, r"^noise must be one"),
    ("sim-timepts-text", lambda: _sim(timepts="abc"), ValueError, r"^timepts must"),
    (
        "sim-timepts-2d",
        lambda: _sim(timepts=np.ones((2, 3))),
        ValueError,
        r"^timepts must be a 1-D",
    ),
    (
        "sim-timepts-nan",
        lambda: _sim(timepts=[0, np.nan, 1]),
        ValueError,
        r"^timepts must be finite",
    ),
    (
        "sim-timepts-decreasing",
        lambda: _sim(timepts=[0, 2, 1]),
        ValueError,
        r"^timepts must be strictly",
    ),
    ("sim-timepts-complex", lambda: _sim(timepts=T + 0j), ValueError, r"^timepts must"),
    ("sim-timepts-short", lambda: _sim(timepts=[0.0]), ValueError, r"^timepts must hold"),
    (
        "sim-timepts-dt-grid",
        lambda: _sim(plant=CASE, observer=ut.design_pmo(CASE, method="lmi"), timepts=[0, 1, 3]),
        ValueError,
        r"^timepts must lie",
    ),
    ("sim-d-complex", lambda: _sim(d=np.ones(11) * 1j), ValueError, r"^d must be real"),
    ("sim-d-text", lambda: _sim(d="step"), ValueError, r"^d must"),
    ("sim-d-shape", lambda: _sim(d=np.ones(5)), ValueError, r"^d must have shape"),
    ("sim-d-nan", lambda: _sim(d=np.full(11, np.nan)), ValueError, r"^d has a non-finite"),
    (
        "sim-u-complex-callable",
        lambda: _sim(u=lambda t: np.vstack([t, t]) * 1j),
        ValueError,
        r"^u\(t\) must be real",
    ),
    ("sim-u-bad-callable", lambda: _sim(u=lambda t: 1.0), ValueError, r"^u\(t\) must return"),
    ("sim-v-without-D", lambda: _sim(v=np.ones(11)), ValueError, r"^v was given"),
    (
        "sim-initial-state-text",
        lambda: _sim(initial_state="abc"),
        ValueError,
        r"^initial_state must",
    ),
    (
        "sim-initial-state-complex",
        lambda: _sim(initial_state=[1j, 0, 0]),
        ValueError,
        r"^initial_state must be real",
    ),
    (
        "sim-initial-state-length",
        lambda: _sim(initial_state=[1, 0]),
        ValueError,
        r"^initial_state must have length",
    ),
    (
        "sim-observer-state-nan",
        lambda: _sim(observer_state=[np.nan, 0, 0]),
        ValueError,
        r"^observer_state must be finite",
    ),
    ("sim-observer-type", lambda: _sim(observer="uio"), ValueError, r"^observer must"),
    ("sim-plant-type", lambda: _sim(plant="plant"), ValueError, r"^plant must"),
    # --- catch_time ----------------------------------------------------------------------
    ("catch-all-text", lambda: ut.catch_time("a", "b", "c"), ValueError, r"^time must"),
    ("catch-actual-text", lambda: ut.catch_time(T, "b", np.ones(11)), ValueError, r"^actual must"),
    (
        "catch-estimate-text",
        lambda: ut.catch_time(T, np.ones(11), "c"),
        ValueError,
        r"^estimate must",
    ),
    (
        "catch-estimate-all-nan",
        lambda: ut.catch_time(T, np.ones(11), np.full(11, np.nan)),
        ValueError,
        r"^estimate has no finite",
    ),
    (
        "catch-estimate-inf",
        lambda: ut.catch_time(T, np.ones(11), np.full(11, np.inf)),
        ValueError,
        r"^estimate has an infinite",
    ),
    (
        "catch-actual-nan",
        lambda: ut.catch_time(T, np.full(11, np.nan), np.ones(11)),
        ValueError,
        r"^actual has a non-finite",
    ),
    (
        "catch-actual-complex",
        lambda: ut.catch_time(T, np.ones(11) * 1j, np.ones(11)),
        ValueError,
        r"^actual must",
    ),
    (
        "catch-time-decreasing",
        lambda: ut.catch_time(T[::-1], np.ones(11), np.ones(11)),
        ValueError,
        r"^time must be strictly",
    ),
    (
        "catch-time-nan",
        lambda: ut.catch_time(np.full(11, np.nan), np.ones(11), np.ones(11)),
        ValueError,
        r"^time must be finite",
    ),
    (
        "catch-tol-text",
        lambda: ut.catch_time(T, np.ones(11), np.ones(11), tol="2%"),
        ValueError,
        r"^tol must",
    ),
    (
        "catch-tol-negative",
        lambda: ut.catch_time(T, np.ones(11), np.ones(11), tol=-1),
        ValueError,
        r"^tol must",
    ),
    # --- reconstruct_input ---------------------------------------------------------------
    ("rec-method", lambda: _reconstruct(method="nope"), ValueError, r"^method must"),
    ("rec-tau-text", lambda: _reconstruct(method="filtered", tau="0.1"), ValueError, r"^tau must"),
    (
        "rec-tau-negative",
        lambda: _reconstruct(method="filtered", tau=-0.1),
        ValueError,
        r"^tau must",
    ),
    ("rec-tau-bool", lambda: _reconstruct(method="filtered", tau=True), ValueError, r"^tau must"),
    ("rec-plant-type", lambda: ut.reconstruct_input("plant", None), ValueError, r"^plant must"),
    ("rec-response-type", lambda: ut.reconstruct_input(PA9, "run"), ValueError, r"^response must"),
    # --- signals -------------------------------------------------------------------------
    ("sig-sinusoid-text", lambda: ut.signals.sinusoid("1", 2.0), ValueError, r"^amplitude must"),
    ("sig-sinusoid-complex", lambda: ut.signals.sinusoid(1j, 2.0), ValueError, r"^amplitude must"),
    ("sig-step-time-nan", lambda: ut.signals.step(1.0, np.nan), ValueError, r"^time must"),
    ("sig-step-bool", lambda: ut.signals.step(True), ValueError, r"^amplitude must"),
    (
        "sig-pwc-times-text",
        lambda: ut.signals.piecewise_constant("ab", [1.0, 2.0]),
        ValueError,
        r"^times must",
    ),
    (
        "sig-pwc-values-complex",
        lambda: ut.signals.piecewise_constant([0, 1], [1j, 2.0]),
        ValueError,
        r"^values must",
    ),
    (
        "sig-pwc-times-order",
        lambda: ut.signals.piecewise_constant([1, 0], [1.0, 2.0]),
        ValueError,
        r"^times must be strictly",
    ),
    # --- existence -----------------------------------------------------------------------
    ("exist-plant-type", lambda: ut.check_existence("plant"), ValueError, r"^plant must"),
]


def test_catalogue_is_large_and_named_uniquely():
    names = [case[0] for case in CATALOGUE]
    assert len(names) >= 60
    assert len(set(names)) == len(names)


@pytest.mark.parametrize(
    ("call", "exc", "pattern"), [c[1:] for c in CATALOGUE], ids=[c[0] for c in CATALOGUE]
)
def test_bad_argument_is_refused_and_named(call, exc, pattern):
    with warnings.catch_warnings():
        # no raw numpy/scipy warning may escape on the way to the error
        warnings.simplefilter("error", RuntimeWarning)
        warnings.filterwarnings("error", message=".*ComplexWarning.*")
        with pytest.raises(exc, match=pattern) as caught:
            call()
    # one except clause catches every refusal of the package; a call Python itself refuses
    # (a keyword-only argument given by position) stays Python's TypeError
    if exc is not TypeError:
        assert isinstance(caught.value, ut.UIOTeachError), type(caught.value).__mro__
