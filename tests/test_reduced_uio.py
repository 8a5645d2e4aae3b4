"""The reduced-order UIO: n - rank C states, the same existence and fixed modes as the full one."""

import numpy as np
import pytest
import scipy.linalg as sla
from tolerance import (
    assert_rounding_close,
    assert_same_run,
    eigenvalue_roundoff,
    matched_distance,
    size_of,
)

import uio_teach as ut
from uio_teach.observers.reduced import reduced_pair


def test_pa9_order_poles_and_matrices():
    plant = ut.examples.pa9()
    obs = ut.design_reduced_uio(plant, poles=[-4])
    assert obs.order == plant.n - np.linalg.matrix_rank(plant.C) == 1
    assert_rounding_close(obs.poles(), [-4.0], size=4.0, terms=plant.n)
    real = obs.realization()
    assert real.A.shape == (1, 1) and real.C.shape == (3, 1) and real.D_y.shape == (3, 2)
    # the observer state estimates theta x with theta E = 0; the estimate is exact for w = theta x
    assert_rounding_close(obs.theta @ plant.E, 0, size=size_of(obs.theta, plant.E), terms=3)
    x = np.array([0.3, -1.2, 2.0])
    xhat = real.C @ (obs.theta @ x) + real.D_y @ (plant.C @ x)
    assert_rounding_close(xhat, x, size=size_of(real.C, real.D_y, obs.theta) * 4, terms=9)


def test_the_error_does_not_depend_on_the_unknown_input():
    plant = ut.examples.pa9()
    obs = ut.design_reduced_uio(plant, poles=[-2])
    t = np.linspace(0, 8, 801)
    x0 = [1.0, -0.5, 2.0]
    quiet = ut.simulate(plant, obs, t, initial_state=x0, u=[np.sin, np.cos])
    loud = ut.simulate(
        plant, obs, t, initial_state=x0, u=[np.sin, np.cos], d=ut.signals.sinusoid(20.0, 3.0)
    )
    assert np.abs(loud.states - quiet.states).max() > 1.0  # the input does move the state
    assert_same_run(loud.error, quiet.error, quiet, loud, what="error with and without d")
    # and the error is P exp(F t) theta x0 (the observer starts at w = 0)
    expected = obs.P @ sla.expm(obs.F * t[-1]) @ obs.theta @ np.asarray(x0)
    assert_rounding_close(
        quiet.error[:, -1], expected, size=size_of(quiet.states), terms=9, steps=t.size
    )


def test_missile_has_no_free_pole_and_the_full_uio_s_fixed_modes():
    missile = ut.examples.missile_autopilot()
    report = ut.check_existence(missile)
    obs = ut.design_reduced_uio(missile, poles=[])
    assert obs.order == 2 == report.fixed_modes.size
    assert matched_distance(obs.poles(), report.fixed_modes) <= 100 * eigenvalue_roundoff(obs.F)
    with pytest.raises(ValueError, match=r"0 pole\(s\) can be placed, got 2.*invariant zeros"):
        ut.design_reduced_uio(missile, poles=[-150, -160])


def test_measurement_disturbance_is_kept_out():
    plant = ut.examples.dt_case_study()
    obs = ut.design_reduced_uio(plant, poles=[])  # order 2: both poles fixed (0.5, 0.5)
    N = ut.linalg.left_null(plant.D)
    assert obs.order == plant.n - np.linalg.matrix_rank(N @ plant.C)
    for X in (obs.K, obs.Q):
        assert_rounding_close(X @ plant.D, 0, size=size_of(X) * size_of(plant.D), terms=plant.p)
    t = np.arange(40)
    rng = np.random.default_rng(3)
    a = ut.simulate(plant, obs, t, initial_state=[1, 1, 1])
    b = ut.simulate(
        plant, obs, t, initial_state=[1, 1, 1], d=rng.normal(size=40) * 50, v=rng.normal(size=40)
    )
    assert_same_run(a.error, b.error, a, b, what="error with and without d and v")


def _random_plant(seed, discrete, stable_zeros, rank_ok):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 6))
    p = int(rng.integers(2, n))
    q = p if seed % 2 else int(rng.integers(1, p))  # square plants have n - p zeros
    A = rng.standard_normal((n, n))
    C = rng.standard_normal((p, n))
    if rank_ok:
        E = rng.standard_normal((n, q))
    else:  # C E = 0: the input shows in the outputs one step late only
        null = sla.null_space(C)
        E = null @ rng.standard_normal((null.shape[1], q))
    zeros = ut.linalg.invariant_zeros(A, E, C, np.zeros((p, q)))
    if discrete:
        rad = np.max(np.abs(zeros), initial=0.0)
        rad = rad if rad > 1e-2 else np.max(np.abs(np.linalg.eigvals(A)))
        A = A * ((0.5 if stable_zeros else 1.6) / rad)
    elif zeros.size:
        A = A - (np.max(zeros.real) + (1.0 if stable_zeros else -0.7)) * np.eye(n)
    return ut.Plant(A, C, B=rng.standard_normal((n, 1)), E=E, dt=1 if discrete else None)


@pytest.mark.parametrize("discrete", [False, True])
def test_reduced_exists_exactly_when_the_full_order_uio_does(discrete):
    """Both directions, on random plants: a stable reduced design where the full one exists;
    where it does not, the reduced construction itself fails the same way (P E cannot be 0 when
    the rank condition fails; the unstable zero is a mode of the reduced pair no gain moves)."""
    seen = {True: 0, False: 0}
    for seed in range(60):
        plant = _random_plant(seed, discrete, stable_zeros=seed % 3 != 0, rank_ok=seed % 4 != 1)
        report = ut.check_existence(plant)
        if not report.decided:
            continue
        seen[report.ok] += 1
        rp = reduced_pair(plant)
        if report["rank condition"].holds:
            # the reduced pair's fixed modes are the full UIO's: the invariant zeros
            fixed = rp.split.unobservable_modes
            assert fixed.size == report.invariant_zeros.size
            assert matched_distance(fixed, report.invariant_zeros) <= 1e-6 * max(
                1.0, np.abs(report.invariant_zeros).max(initial=0.0)
            )
        else:
            # no Gamma solves Gamma C E = V2^T E: P E stays far from zero
            PE = rp.P @ plant.E
            assert np.abs(PE).max() > 1e-6 * size_of(rp.V2, plant.E)
        if report.ok:
            k = rp.split.Ao.shape[0]
            poles = (np.linspace(0.13, 0.41, k) * (1 if discrete else -17)) if k else []
            obs = ut.design_reduced_uio(plant, poles=poles)
            assert obs.order == plant.n - np.linalg.matrix_rank(plant.C)
            assert obs.is_stable
            want = np.concatenate([np.asarray(poles, complex), report.fixed_modes])
            assert matched_distance(obs.poles(), want) <= 1e-6 * max(1.0, np.abs(want).max())
        else:
            with pytest.raises(ut.UIOExistenceError, match="reduced-order"):
                ut.design_reduced_uio(plant, poles=[])
    assert seen[True] >= 5 and seen[False] >= 5, seen


def test_bad_input_gets_package_errors():
    plant = ut.examples.pa9()
    with pytest.raises(ValueError, match=r"1 pole\(s\) can be placed, got 2"):
        ut.design_reduced_uio(plant, poles=[-1, -2])
    with pytest.raises(ValueError, match="poles"):
        ut.design_reduced_uio(plant, poles=[np.nan])
    with pytest.raises(ValueError, match="Plant"):
        ut.design_reduced_uio("pa9", poles=[-1])
    no_rank = ut.Plant(np.diag([-1.0, -2.0]), [[1.0, 0.0]], E=[0.0, 1.0])
    with pytest.raises(ut.UIOExistenceError, match="rank condition"):
        ut.design_reduced_uio(no_rank, poles=[])
    obs = ut.design_reduced_uio(plant, poles=[-3])
    with pytest.raises(AttributeError, match="read-only"):
        obs.F = np.zeros((1, 1))


def test_residual_and_python_control_view():
    plant = ut.examples.pa9()
    obs = ut.design_reduced_uio(plant, poles=[-3])
    sys = obs.as_statespace()
    assert (sys.nstates, sys.ninputs, sys.noutputs) == (1, 4, 3)
    t = np.linspace(0, 5, 501)
    resp = ut.simulate(plant, obs, t, d=ut.signals.step(1.0), initial_state=[1, 0, 0])
    r = ut.observer_residual(obs, t, resp.inputs.u, resp.outputs)
    assert_rounding_close(r, resp.residual, size=size_of(resp.outputs), terms=9, steps=t.size)
    # the residual of a reduced-order UIO is zero: y is used as it is (x = R y + V2 eta)
    assert_rounding_close(resp.residual, 0, size=size_of(resp.outputs), terms=9, steps=t.size)


def test_the_explorer_and_the_checks_accept_it():
    from uio_teach.explorers import make_scenario
    from uio_teach.explorers.frames import compute_frame

    # the explorer: one movable pole on PA9, none on the missile (both are its zeros)
    sc = make_scenario(ut.examples.pa9(), "reduced")
    assert sc.movable == 1 and len(sc.defaults.poles) == 1
    frame = compute_frame(sc)
    assert isinstance(frame.observer, ut.ReducedUIO) and frame.observer.order == 1
    assert frame.response is not None and not frame.observer_message
    missile = make_scenario(ut.examples.missile_autopilot(), "reduced")
    assert missile.movable == 0 and compute_frame(missile).observer.order == 2
    # a lab check of a simulation: the error ignores d and decays
    plant = ut.examples.pa9()
    obs = ut.design_reduced_uio(plant, poles=[-3])
    t = np.linspace(0, 10, 1001)
    resp = ut.simulate(plant, obs, t, d=ut.signals.sinusoid(1.0, 2.0), initial_state=[1, 1, 1])
    result = ut.checks.pa9_simulation(resp)
    assert any("does not depend on d" in m for ok, m in result.items if ok), result


@pytest.mark.parametrize("discrete", [False, True])
def test_an_exact_rank_failure_is_refused_by_both(discrete):
    """C E = 0 exactly (the input enters states that no output reads): the rank condition fails
    as a decided verdict, and the reduced-order design refuses for that reason, as the full one
    does."""
    rng = np.random.default_rng(11)
    n, p = 4, 2
    A = rng.standard_normal((n, n)) * (0.3 if discrete else 1.0)
    C = np.hstack([rng.standard_normal((p, n - 1)), np.zeros((p, 1))])
    E = np.zeros((n, 1))
    E[-1, 0] = 1.0
    plant = ut.Plant(A, C, E=E, dt=1 if discrete else None)
    report = ut.check_existence(plant)
    assert report.decided and not report.ok
    assert report["rank condition"].holds is False
    with pytest.raises(ut.UIOExistenceError, match="reduced-order"):
        ut.design_reduced_uio(plant, poles=[])
    with pytest.raises(ut.UIOExistenceError):
        ut.design_uio(plant, poles=np.full(n, 0.2 if discrete else -2.0))
