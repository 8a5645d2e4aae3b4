"""The tolerance policy of uio_teach.linalg: ranks against the factors, marginal verdicts, zeros."""

import numpy as np
import pytest
from tolerance import roundoff

import uio_teach as ut
from uio_teach.linalg import MARGIN, invariant_zeros, rank, rank_decision

ROUND_OFF_PLANT = ut.Plant(
    [[-1, 1, 0], [0, -2, 1], [0, 0, -3]], [[1, 1, 1]], E=[0.1, 0.2, -0.3]
)  # C E = 0 in exact arithmetic


def test_rank_of_a_product_is_judged_against_its_factors():
    C, E = ROUND_OFF_PLANT.C, ROUND_OFF_PLANT.E
    CE = C @ E
    assert CE[0, 0] != 0  # round-off: C E is not exactly zero in floating point
    assert rank(CE) == 1  # judged against its own size it would look full rank
    scale = np.linalg.norm(C, 2) * np.linalg.norm(E, 2)
    assert rank(CE, scale=scale) == 0


def test_a_product_within_its_rounding_cannot_be_decided():
    # 0.1 + 0.2 - 0.3 is 5.6e-17 for the doubles stored, not 0: a plant that close has
    # C E = 0, the data themselves do not; the verdict names the singular value and its bound
    report = ut.check_existence(ROUND_OFF_PLANT)
    assert not report.ok and not report.decided
    cond = report["rank condition"]
    assert cond.holds is None and cond.undecided
    assert "singular value 1 of CE is 8.57e-17" in cond.reason and "within its bound" in cond.reason
    assert report.verdict == "cannot be decided at this precision"
    with pytest.raises(ut.UIOExistenceError, match="rank condition"):
        ut.design_uio(ROUND_OFF_PLANT, poles=[-5])


def test_product_zero_in_exact_arithmetic_fails_the_rank_condition():
    exact = ut.Plant(ROUND_OFF_PLANT.A, [[1, 1, 1]], E=[1.0, 2.0, -3.0])  # C E = 0 exactly
    report = ut.check_existence(exact)
    cond = report["rank condition"]
    assert cond.holds is False and not cond.undecided
    assert "rank(CE) = 0 but rank(E) = 1" in cond.reason
    assert report.verdict == "no UIO with stable error dynamics exists"
    with pytest.raises(ut.UIOExistenceError, match="rank condition"):
        ut.design_uio(exact, poles=[-5])


def test_rank_decision_reports_a_marginal_verdict():
    d = rank_decision(np.diag([1.0, 1e-13]))
    assert d.rank == 2 and d.marginal
    assert d.margin == pytest.approx(1e-13 / d.threshold)
    clear = rank_decision(np.diag([1.0, 1e-3]))
    assert clear.rank == 2 and not clear.marginal and clear.margin > MARGIN


def test_marginal_rank_condition_says_so_in_the_report():
    # two unknown inputs whose directions differ by 1e-13: in any units, rank(E) = 2
    # only ~100 times above the threshold
    plant = ut.Plant(np.diag([-1.0, -2.0]), np.eye(2), E=[[1.0, 1.0], [1.0, 1.0 + 1e-13]])
    cond = ut.check_existence(plant)["rank condition"]
    assert cond.holds is True
    assert cond.marginal and cond.margin < MARGIN
    assert "within the numerical margin" in cond.reason and f"{cond.margin:.3g}" in cond.reason


def test_a_tiny_product_is_not_marginal_when_it_is_a_matter_of_units():
    # C E = 1e-13 only because the first state is measured in tiny units
    plant = ut.Plant(np.diag([-1.0, -2.0]), [[1.0, 0.0]], E=[1e-13, 1.0])
    cond = ut.check_existence(plant)["rank condition"]
    assert cond.holds is True and not cond.marginal


def test_clear_verdicts_carry_no_margin_note():
    report = ut.check_existence(ut.examples.pa9())
    for cond in report.conditions:
        assert "numerical margin" not in cond.reason
    assert not report["rank condition"].marginal


@pytest.mark.parametrize(
    ("B", "C", "expected"),
    [
        ([[1.0], [1.0]], np.eye(2), []),  # non-square: no zero
        ([[1.0], [1.0]], [[1.0, 1.0]], [(1e13 - 1) / 2]),  # 1/(s-1e13) + 1/(s+1)
        ([[1.0], [0.0]], [[1.0, 1.0]], [-1.0]),  # the mode -1 is input-decoupled
    ],
)
def test_large_eigenvalue_gives_no_spurious_invariant_zero(B, C, expected):
    A = np.diag([1e13, -1.0])
    z = invariant_zeros(A, B, C)
    assert z.size == len(expected)
    # accurate relative to ||A||: the backward error of the (n + 1)-square pencil's eigenvalues
    np.testing.assert_allclose(z.real, expected, rtol=0, atol=roundoff(1e13, terms=3))
    assert np.all(np.abs(z - 1e13) > 1e3) or expected  # never the pole 1e13 itself


def test_large_eigenvalue_plant_existence_report():
    plant = ut.Plant(np.diag([1e13, -1.0]), np.eye(2), E=[1.0, 1.0])
    assert ut.check_existence(plant).invariant_zeros.size == 0


def test_invariant_zeros_are_unchanged_by_similarity_scaling():
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-6.0, -11.0, -6.0]])
    B = np.array([[0.0], [0.0], [1.0]])
    C = np.array([[2.0, 3.0, 1.0]])  # zeros of s^2 + 3 s + 2: -1, -2
    S = np.diag([1.0, 1e3, 1e-3])
    z = invariant_zeros(S @ A @ np.linalg.inv(S), S @ B, C @ np.linalg.inv(S))
    np.testing.assert_allclose(np.sort(z.real), [-2.0, -1.0], atol=1e-8)


def test_observability_split_reports_its_margin():
    # the second mode is seen through 1e-11 only: observable, but close to the threshold
    split = ut.linalg.observability_decomposition(np.diag([-1.0, -2.0]), [[1.0, 1e-11]])
    assert split.Au.size == 0 and split.marginal
    # the report decides in balanced units: the second state in other units is seen clearly
    report = ut.check_existence(ut.Plant(np.diag([-1.0, -2.0]), [[1.0, 1e-11]]))
    assert report["observable (TA, C)"].holds
    assert "within the numerical margin" not in report["observable (TA, C)"].reason
    split = ut.linalg.observability_decomposition(np.diag([-1.0, -2.0]), [[1.0, 1.0]])
    assert not split.marginal


def test_a_zero_close_to_the_stability_boundary_is_decided_with_its_distance_and_radius():
    # G(s) = (s + 1e-8) / ((s + 1)(s + 2)): a zero 1e-8 from the imaginary axis, on exact data:
    # round-off moves it by about 1e-16, so it is decided, and the report says by how much
    plant = ut.Plant([[0.0, 1.0], [-2.0, -3.0]], [[1e-8, 1.0]], E=[0.0, 1.0])
    report = ut.check_existence(plant)
    cond = report["invariant zeros stable"]
    assert cond.holds is True and report.ok
    assert "1e-08 from the imaginary axis" in cond.reason and "moves it by at most" in cond.reason
    assert report["detectable (TA, C)"].holds is True
