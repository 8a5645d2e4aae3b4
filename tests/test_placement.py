"""Pole placement is verified: the poles asked for, to the stated tolerance, or a clear refusal."""

import warnings

import control
import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment
from tolerance import assert_zero, roundoff

import uio_teach as ut
from uio_teach.placement import place_observer_poles
from uio_teach.verify import (
    POLE_RTOL,
    WARN_RTOL,
    PlacementAccuracyError,
    PlacementAccuracyWarning,
    check_identity,
    check_poles,
)


def matched_error(requested, obtained):
    requested = np.asarray(requested, complex)
    cost = np.abs(requested[:, None] - np.asarray(obtained)[None, :])
    r, c = linear_sum_assignment(cost)
    return float(np.max(cost[r, c] / np.maximum(1.0, np.abs(requested[r]))))


def place_or_refuse(A, C, poles):
    """Place; return the relative pole error, or None when refused clearly."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            L = place_observer_poles(A, C, poles)
        except PlacementAccuracyError as exc:
            assert "requested" in str(exc) or "failed numerically" in str(exc)
            return None
    # only our own warning may reach the user, never scipy's or numpy's
    assert all(w.category is PlacementAccuracyWarning for w in caught), [
        str(w.message) for w in caught
    ]
    err = matched_error(poles, np.linalg.eigvals(A - L @ C))
    assert err <= WARN_RTOL, err  # never silently (or even with a warning) badly wrong
    if not caught:
        # silent: right to the stated tolerance (round-off, or conditioning up to WARN_RTOL)
        assert err <= WARN_RTOL
    return err


def test_single_output_many_states_close_poles_right_or_refused():
    rng = np.random.default_rng(12)
    outcomes = {"right": 0, "refused": 0}
    for _ in range(20):
        A = rng.standard_normal((12, 12))
        C = rng.standard_normal((1, 12))
        err = place_or_refuse(A, C, -1 - 0.1 * np.arange(12))
        outcomes["refused" if err is None else "right"] += 1
    assert sum(outcomes.values()) == 20


def test_twenty_states_one_output_never_raw_python_control_error():
    rng = np.random.default_rng(20)
    A = rng.standard_normal((20, 20))
    C = rng.standard_normal((1, 20))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            place_observer_poles(A, C, -1 - 0.1 * np.arange(20))
        except PlacementAccuracyError as exc:
            assert "not reachable" not in str(exc).split("(")[0]
            assert "poles" in str(exc)


def test_absurd_pole_is_refused_not_returned_as_zero():
    # the absurd pole is named; -2 and -3 are at the round-off of ||F|| = 4e301, which
    # explains any error there
    with pytest.raises(PlacementAccuracyError, match=r"requested \{-1e\+300\}"):
        place_observer_poles(np.diag([1.0, 2.0, 3.0]), [[1.0, 1.0, 1.0]], [-1e300, -2, -3])


@pytest.mark.parametrize("decades", [2, 3, 4, 5, 6])
def test_similarity_scaled_plant_gets_requested_poles_or_refusal(decades):
    rng = np.random.default_rng(decades)
    A0 = rng.standard_normal((5, 5))
    C0 = rng.standard_normal((1, 5))
    s = np.logspace(0, decades, 5)
    A, C = np.diag(s) @ A0 @ np.diag(1 / s), C0 @ np.diag(1 / s)
    place_or_refuse(A, C, [-1.0, -2.0, -3.0, -4.0, -5.0])


def test_balancing_recovers_the_unscaled_accuracy():
    A0 = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, -2.0, -3.0]])
    C0 = np.array([[1.0, 0.0, 0.0]])
    s = np.array([1.0, 1e4, 1e-4])
    A, C = np.diag(s) @ A0 @ np.diag(1 / s), C0 @ np.diag(1 / s)
    err = place_or_refuse(A, C, [-1.0, -2.0, -3.0])
    assert err is not None and err <= POLE_RTOL


def test_check_poles_three_tiers():
    F = np.diag([-1.0, -2.0])
    np.testing.assert_allclose(check_poles(F, [-2.0, -1.0]).real, [-2.0, -1.0])
    with pytest.warns(PlacementAccuracyWarning, match=r"requested \{-1.0001\}.*obtained \{-1\}"):
        check_poles(F, [-1.0001, -2.0])
    with pytest.raises(PlacementAccuracyError, match=r"condition numbers"):
        check_poles(F, [-1.1, -2.0])
    with pytest.raises(PlacementAccuracyError, match="not finite"):
        check_poles(np.array([[np.inf]]), [-1.0])


def test_repeated_poles_are_accepted_within_their_conditioning():
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 2.0, 3.0]])
    C = np.array([[1.0, 0.0, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        L = place_observer_poles(A, C, [-2.0, -2.0, -2.0])
    # a triple pole moves by ~eps^(1/3) under round-off: right to that, not to 1e-6
    assert matched_error([-2, -2, -2], np.linalg.eigvals(A - L @ C)) < 1e-4


def test_check_identity_names_the_identity():
    assert check_identity("T E = 0", np.zeros((3, 1)), 1.0) == 0.0
    with pytest.raises(PlacementAccuracyError, match=r"T E = 0 holds only to 1e-06"):
        check_identity("T E = 0", np.full((1, 1), 1e-6), 1.0)


def test_every_design_meets_its_decoupling_identities():
    pa9 = ut.examples.pa9()
    uio = ut.design_uio(pa9, poles=[-1, -2, -3])
    # zero to the rounding of 3-term products of gains solved with C E (D)
    gain = np.linalg.cond(pa9.C @ pa9.E)
    assert_zero(uio.T @ pa9.E, uio.T, pa9.E, terms=3, gain=gain)
    assert_zero(
        uio.H @ pa9.C @ pa9.E - pa9.E, 1 + np.abs(uio.H) @ np.abs(pa9.C), pa9.E, terms=3, gain=gain
    )
    case = ut.examples.dt_case_study()
    pmo = ut.design_pmo(case, method="lmi")
    assert_zero(pmo.L @ case.D, pmo.L, case.D, terms=3, gain=np.linalg.cond(case.D))
    assert_zero(pmo.M @ case.D, pmo.M, case.D, terms=3, gain=np.linalg.cond(case.D))
    g = ut.design_ginverse(ut.examples.missile_autopilot())
    P, K, pl = g.projection, g.Kg, g.plant
    gain = np.linalg.cond(pl.C) * np.linalg.cond(pl.C @ pl.E)  # P from pinv(C), K from CE
    assert_zero(
        (P - P @ K @ pl.C) @ pl.E,
        1 + np.abs(P) @ np.abs(K) @ np.abs(pl.C),
        pl.E,
        terms=4,
        gain=gain,
    )


# repeated poles on a matrix that is not cyclic ----------------------------------------------

TWO_EQUAL_MODES = (np.diag([-1.0, -2.0, -2.0]), np.array([[1.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))


@pytest.mark.filterwarnings("error::uio_teach.verify.PlacementAccuracyWarning")
@pytest.mark.parametrize("poles", [[-4, -4, -4], [-4, -4, -5], [-1, -1, -1]])
def test_repeated_poles_beyond_the_outputs_on_two_equal_modes(poles):
    A, C = TWO_EQUAL_MODES
    L = place_observer_poles(A, C, poles)  # verified inside: no error, no warning (an error)
    F = A - L @ C
    m = max(poles.count(p) for p in poles)
    # a pole repeated m times moves by about (eps ||F||)^(1/m) under round-off
    bound = 100 * (np.finfo(float).eps * np.linalg.norm(F, 2)) ** (1 / m) * max(map(abs, poles))
    got = np.sort_complex(np.linalg.eigvals(F))
    assert np.abs(got - np.sort_complex(np.array(poles, complex))).max() <= bound


@pytest.mark.filterwarnings("error::uio_teach.verify.PlacementAccuracyWarning")
def test_deadbeat_on_two_equal_modes_in_discrete_time():
    A, C = TWO_EQUAL_MODES
    Ad = np.diag(np.exp(np.diag(A) * 0.1))
    L = place_observer_poles(Ad, C, [0, 0, 0])
    F = Ad - L @ C
    # F = F0 + dF with F0^3 = 0 and dF the rounding of L C (3 terms): F^3 is at most
    # 3 ||F||^2 ||dF|| (three products)
    dF = np.linalg.norm(Ad, 2) + np.linalg.norm(L, 2) * np.linalg.norm(C, 2)
    bound = roundoff(np.linalg.norm(F, 2) ** 2 * dF, terms=3, steps=3)
    assert np.linalg.norm(np.linalg.matrix_power(F, 3), 2) <= bound


def test_a_failed_placement_says_why(monkeypatch):
    def broken(*args, **kwargs):
        raise ValueError("the controllability matrix is singular")

    monkeypatch.setattr(control, "acker", broken)
    A, C = TWO_EQUAL_MODES
    with pytest.raises(PlacementAccuracyError) as info:
        place_observer_poles(A, C, [-1, -1, -1])
    text = str(info.value)
    assert "()" not in text
    assert "single output w C: the controllability matrix is singular" in text


def jordan_block(pole: float, m: int, delta: float) -> np.ndarray:
    """An m x m Jordan block of ``pole`` with ``delta`` in the corner: poles move by delta^(1/m)."""
    J = pole * np.eye(m) + np.diag(np.ones(m - 1), 1)
    J[-1, 0] = delta
    return J


@pytest.mark.filterwarnings("error::uio_teach.verify.PlacementAccuracyWarning")
def test_a_triple_pole_off_by_round_off_is_accepted():
    # the poles sit 7e-5 from -2, as a triple pole computed from a gain with round-off
    # (a perturbation of F of a few hundred eps ||F||) lands
    J = jordan_block(-2.0, 3, 3e-13)
    assert np.abs(np.linalg.eigvals(J) + 2).max() > 5e-5
    check_poles(J, [-2, -2, -2])


def test_a_triple_pole_off_by_more_than_round_off_is_refused():
    J = jordan_block(-2.0, 3, 1e-6)  # poles 1e-2 away: a real error, not round-off
    with pytest.raises(PlacementAccuracyError, match="requested"):
        check_poles(J, [-2, -2, -2])
