"""lmi_gain: scaling, strict margin, unmovable boundary modes, infeasible versus failed."""

import warnings

import numpy as np
import pytest

import uio_teach as ut
from uio_teach.lmi import STRICT_MARGIN, LMIError, LMIInfeasibleError, LMISolverError

A0 = np.array([[0.5, 1.0, 0.0], [0.0, 1.2, 1.0], [0.3, 0.0, 0.4]])
C0 = np.array([[1.0, 0.0, 0.0]])
S = np.diag([1.0, 300.0, 1 / 300.0])


def test_badly_scaled_detectable_pair_is_solved():
    A, C = S @ A0 @ np.linalg.inv(S), C0 @ np.linalg.inv(S)
    # placement stabilizes it, so the LMI must be feasible
    L_place = ut.placement.place_observer_poles(A, C, [0.1, 0.2, 0.3])
    assert np.max(np.abs(np.linalg.eigvals(A - L_place @ C))) < 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no raw cvxpy warning either
        L, P = ut.lmi_gain(A, C, dt=True)
    F = A - L @ C
    assert np.max(np.abs(np.linalg.eigvals(F))) < 1 - STRICT_MARGIN
    # the returned certificate certifies the returned gain (scaling undone consistently)
    assert np.min(np.linalg.eigvalsh(P)) > 0
    assert np.max(np.linalg.eigvalsh(F.T @ P @ F - P)) < 0


@pytest.mark.parametrize("decades", [2, 4, 6])
def test_scaled_pairs_give_the_same_certified_stability(decades):
    s = np.logspace(0, decades, 3)
    A, C = np.diag(s) @ A0 @ np.diag(1 / s), C0 @ np.diag(1 / s)
    L, P = ut.lmi_gain(A, C, dt=True)
    assert np.max(np.abs(np.linalg.eigvals(A - L @ C))) < 1 - STRICT_MARGIN


def test_unmovable_mode_on_the_unit_circle_is_infeasible_and_named():
    with pytest.raises(LMIInfeasibleError, match=r"mode\(s\) 1 cannot be moved") as info:
        ut.lmi_gain(np.diag([1.0, 0.3]), [[0.0, 1.0]], dt=True)
    assert info.value.status == "infeasible"


def test_unmovable_mode_on_the_imaginary_axis_is_infeasible_and_named():
    A = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    with pytest.raises(LMIInfeasibleError, match=r"-1j, 1j|0 - 1j, 0 \+ 1j|cannot be moved"):
        ut.lmi_gain(A, [[0.0, 0.0, 1.0]])


def test_certified_gain_is_strictly_stable():
    # a marginal plant mode that the output does see: the gain must move it strictly inside
    L, _ = ut.lmi_gain(np.diag([1.0, 0.3]), [[1.0, 1.0]], dt=True)
    F = np.diag([1.0, 0.3]) - L @ [[1.0, 1.0]]
    assert np.max(np.abs(np.linalg.eigvals(F))) < 1 - STRICT_MARGIN
    obs = ut.design_pmo(ut.examples.dt_case_study(), method="lmi")
    assert obs.is_stable


def test_failed_solve_is_told_apart_from_infeasible():
    assert issubclass(LMIInfeasibleError, LMIError) and issubclass(LMISolverError, LMIError)
    assert not issubclass(LMISolverError, LMIInfeasibleError)
    # OSQP cannot solve semidefinite programs: refused by name before any solve
    with pytest.raises(ValueError, match="solver must be an installed cvxpy solver"):
        ut.lmi_gain([[0.5]], [[1.0]], dt=True, solver="OSQP")


def test_solver_name_is_case_insensitive():
    L, _ = ut.lmi_gain([[1.5]], [[1.0]], dt=True, solver="scs")
    assert abs(1.5 - L[0, 0]) < 1


@pytest.mark.parametrize("dt", [None, 0, False])
def test_continuous_time_spellings(dt):
    L, _ = ut.lmi_gain([[1.0]], [[1.0]], dt=dt)
    assert 1.0 - L[0, 0] < 0


@pytest.mark.parametrize("dt", [True, 1, 0.1])
def test_discrete_time_spellings(dt):
    L, _ = ut.lmi_gain([[1.5]], [[1.0]], dt=dt)
    assert abs(1.5 - L[0, 0]) < 1
