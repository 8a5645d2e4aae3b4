"""Existence conditions: each failing condition gives the right, readable error."""

import control as ct
import numpy as np
import pytest
from tolerance import roundoff

import uio_teach as ut
from uio_teach.linalg import invariant_zeros


def unstable_zero_plant(zero=1.0, dt=None):
    """d -> y has the transfer function (s - zero) / (s^2 + 3 s + 2)."""
    return ut.Plant([[0, 1], [-2, -3]], [[-zero, 1]], E=[[0], [1]], dt=dt)


def test_rank_condition_failure():
    plant = ut.Plant([[0, 1], [-2, -3]], [[0, 1]], E=[[1], [0]])  # CE = 0
    report = ut.check_existence(plant)
    assert not report.ok
    cond = report["rank condition"]
    assert cond.holds is False
    assert "rank(CE) = 0 but rank(E) = 1" in cond.reason
    assert report["detectable (TA, C)"].holds is None  # not evaluated
    with pytest.raises(ut.UIOExistenceError, match="rank condition") as info:
        ut.design_uio(plant, poles=[-1, -2])
    assert isinstance(info.value, ValueError)
    assert info.value.report is not None and not info.value.report.ok


def test_rank_condition_with_measurement_disturbance():
    # D parallel to C E: the two unknown inputs cannot be told apart
    plant = ut.Plant(np.diag([0.5, 0.2]), [[1, 0], [0, 1]], E=[[1], [0]], D=[[1], [0]], dt=1)
    report = ut.check_existence(plant)
    assert "rank([CE D]) = 1 but rank(E) + rank(D) = 1 + 1" in report["rank condition"].reason
    with pytest.raises(ut.UIOExistenceError):
        ut.design_pmo(plant, method="lmi")


def test_unstable_invariant_zero_is_named():
    plant = unstable_zero_plant(1.0)
    report = ut.check_existence(plant)
    np.testing.assert_allclose(report.invariant_zeros, [1.0])
    assert not report.ok
    assert report["rank condition"].holds
    assert not report["invariant zeros stable"].holds
    assert "{1}" in report["invariant zeros stable"].reason
    assert not report["detectable (TA, C)"].holds
    with pytest.raises(
        ut.UIOExistenceError, match=r"invariant zero\(s\) \{1\} outside the open left"
    ):
        ut.design_uio(plant, poles=[-5])


def test_same_zero_stable_in_discrete_time():
    """A zero at 0.5 is unstable for a continuous plant but stable for a discrete one."""
    assert not ut.check_existence(unstable_zero_plant(0.5)).ok
    report = ut.check_existence(unstable_zero_plant(0.5, dt=1))
    assert report.ok
    np.testing.assert_allclose(report.fixed_modes, [0.5])
    with pytest.raises(ut.UIOExistenceError, match=r"\{1.5\} outside the open unit disk"):
        ut.design_uio(unstable_zero_plant(1.5, dt=1), poles=[0.1])


@pytest.mark.parametrize(
    "plant_fn", [ut.examples.pa9, ut.examples.dt_case_study, ut.examples.missile_autopilot]
)
def test_fixed_modes_are_the_invariant_zeros_on_the_examples(plant_fn):
    report = ut.check_existence(plant_fn())
    assert report.ok
    z, f = report.invariant_zeros, report.fixed_modes
    assert len(z) == len(f)
    np.testing.assert_allclose(np.sort_complex(np.round(z, 8)), np.sort_complex(np.round(f, 8)))


@pytest.mark.parametrize(
    "plant_fn", [ut.examples.pa9, ut.examples.dt_case_study, ut.examples.missile_autopilot]
)
def test_fixed_modes_are_observer_poles_whatever_the_placement(plant_fn):
    plant = plant_fn()
    report = ut.check_existence(plant)
    k = report.movable
    stable = 0.3 if plant.is_discrete else -50.0
    for poles in ([stable] * 0 + list(np.linspace(stable, stable * 1.5, k)),):
        obs = ut.design_pmo(plant, poles=poles) if plant.nv else ut.design_uio(plant, poles=poles)
        got = obs.poles()
        for zf in report.fixed_modes:
            assert np.min(np.abs(got - zf)) < 1e-6 * max(1, abs(zf))
        for pp in poles:
            assert np.min(np.abs(got - pp)) < 1e-6 * max(1, abs(pp))


def test_report_display():
    report = ut.check_existence(ut.examples.dt_case_study())
    text = str(report)
    assert "rank condition" in text and "=> a UIO exists" in text
    assert "(info)" in text
    html = report._repr_html_()
    assert html.count("<tr>") == len(report.conditions) + 1
    with pytest.raises(KeyError, match="no condition named"):
        report["nope"]


def test_invariant_zeros_match_python_control_on_square_systems():
    rng = np.random.default_rng(0)
    for _ in range(30):
        n, m = rng.integers(2, 6), rng.integers(1, 3)
        A, B = rng.standard_normal((n, n)), rng.standard_normal((n, m))
        C, D = rng.standard_normal((m, n)), np.zeros((m, m))
        ours = invariant_zeros(A, B, C, D)
        theirs = ct.ss(A, B, C, D).zeros()
        theirs = theirs[np.abs(theirs) < 1e8]  # python-control may return huge values for
        # zeros at infinity (ill-conditioned pencil); those are not finite zeros
        assert len(ours) == len(theirs)
        for z in theirs:
            assert np.min(np.abs(ours - z)) < 1e-6 * max(1, abs(z))


def test_invariant_zeros_of_non_square_systems_drop_the_rosenbrock_rank():
    """Tall systems: two outputs seeing a common zero. The zero found must drop the rank."""
    rng = np.random.default_rng(1)
    for _ in range(20):
        n = 4
        # build a system with a known zero at s0 in both outputs: C (s0 I - A)^-1 B = 0
        A = rng.standard_normal((n, n))
        B = rng.standard_normal((n, 1))
        s0 = -0.7
        X = np.linalg.solve(s0 * np.eye(n) - A, B)  # (s0 I - A)^-1 B
        C = rng.standard_normal((2, n))
        C -= (C @ X) @ X.T / (X.T @ X)  # make C X = 0 for both rows
        z = invariant_zeros(A, B, C)
        assert np.min(np.abs(z - s0)) < 1e-7
        for zz in z:
            R = np.block([[zz * np.eye(n) - A, -B], [C, np.zeros((2, 1))]])
            sv = np.linalg.svd(R, compute_uv=False)
            # rank n + 1 - 1: R(s0) is singular (to the rounding of building C), and R moves
            # by |z - s0| from s0 to the computed zero
            assert sv[-1] <= abs(zz - s0) + roundoff(sv[0], terms=n + 2)


def test_no_zeros_for_generic_tall_system():
    rng = np.random.default_rng(2)
    A, B, C = rng.standard_normal((4, 4)), rng.standard_normal((4, 1)), rng.standard_normal((3, 4))
    assert invariant_zeros(A, B, C).size == 0
