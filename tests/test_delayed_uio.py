"""The delayed UIO: existence per delay (rank increments, detectability), design, simulate."""

import numpy as np
import pytest
import scipy.linalg as sla
from tolerance import assert_rounding_close, matched_distance, size_of

import uio_teach as ut
from uio_teach.observers.delayed import stacked_matrices
from uio_teach.simulation import linear_response

A3 = [[0.5, 1.0, 0.0], [0.0, 0.3, 1.0], [0.0, 0.0, 0.2]]


def _late_plant(dt=1):
    """C E = 0 but C A E has full column rank: the input shows one sample late."""
    return ut.Plant(A3, [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], E=[0.0, 1.0, 0.0], dt=dt)


def test_ce_zero_cae_full_rank_needs_delay_one():
    plant = _late_plant()
    assert np.allclose(plant.C @ plant.E, 0) and np.linalg.matrix_rank(plant.C @ plant.A @ plant.E)
    report = ut.check_existence(plant)
    assert not report.ok and not report["rank condition"].holds
    verdict = report.delayed
    assert verdict.exists and verdict.delay == 1 and verdict.increments[:2] == (0, 1)
    with pytest.raises(ut.DelayedUIOExistenceError, match="smallest delay that works is 1"):
        ut.design_delayed_uio(plant, [0.1, 0.2, 0.3], delay=0)
    with pytest.raises(ut.UIOExistenceError, match="rank condition"):
        ut.design_uio(plant, poles=[0.1, 0.2, 0.3])  # delay=0: the plain UIO, unchanged
    obs = ut.design_uio(plant, poles=[0.1, 0.2, 0.3], delay=1)
    assert isinstance(obs, ut.DelayedUIO) and obs.delay == 1
    assert_rounding_close(np.sort(obs.poles().real), [0.1, 0.2, 0.3], size=1.0, terms=9)
    assert ut.design_delayed_uio(plant, [0.1, 0.2, 0.3]).delay == 1  # the smallest by default


def test_error_is_the_same_whatever_the_unknown_input():
    plant = _late_plant()
    obs = ut.design_uio(plant, poles=[0.1, -0.2, 0.3], delay=1)
    t = np.arange(40)
    x0 = [1.0, 2.0, -3.0]
    quiet = ut.simulate(plant, obs, t, initial_state=x0)
    rng = np.random.default_rng(7)
    loud = ut.simulate(plant, obs, t, initial_state=x0, d=100 * rng.normal(size=40))
    assert np.abs(loud.states - quiet.states).max() > 10
    # the last `delay` columns have no estimate yet; the others agree to rounding
    assert np.all(np.isnan(quiet.estimates[:, -1])) and not np.any(np.isnan(quiet.error[:, :-1]))
    size = size_of(loud.states, loud.estimates[:, :-1])
    assert_rounding_close(loud.error[:, :-1], quiet.error[:, :-1], size=size, terms=9, steps=40)
    # e[k] = Ad^k e[0], with xhat[0] = 0
    e = np.asarray(x0)
    for _ in range(1, 10):
        e = obs.Ad @ e
    assert_rounding_close(loud.error[:, 9], e, size=size, terms=9, steps=40)


def test_the_causal_realization_runs_the_same_recursion():
    plant = ut.Plant(A3, [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], B=[1.0, 0.0, 1.0], E=[0, 1, 0], dt=1)
    obs = ut.design_uio(plant, poles=[0.2, 0.3, 0.4], delay=1)
    t = np.arange(30)
    rng = np.random.default_rng(1)
    resp = ut.simulate(
        plant, obs, t, initial_state=[1, 0, 2], u=rng.normal(size=30), d=rng.normal(size=30)
    )
    real = obs.realization()
    w = linear_response(
        real.A,
        np.hstack([real.B_u, real.B_y]),
        t,
        np.vstack([resp.inputs.u, resp.outputs]),
        np.zeros(real.A.shape[0]),
        discrete=True,
    )
    causal = real.C @ w + real.D_y @ resp.outputs  # the estimate of x[k - 1] at time k
    ec = resp.states[:, :-1] - causal[:, 1:]  # aligned with x[0..N-2]
    # from the time its registers hold real samples (k >= 2, j >= 1) it obeys e[j+1] = Ad e[j]
    size = size_of(resp.states, causal)
    assert_rounding_close(ec[:, 2:], obs.Ad @ ec[:, 1:-1], size=size * 10, terms=30, steps=30)
    # and both estimates converge to the state
    assert_rounding_close(ec[:, -1], 0, size=size * 10, terms=30, steps=30)


def _relative_degree_plant(seed, r, stable):
    """q unknown inputs reaching y only through C A^r E (C A^k E = 0 for k < r)."""
    rng = np.random.default_rng(seed)
    n = 5
    p = q = 1 if seed % 2 else 2  # one input and one output: n - r - 1 invariant zeros
    A = rng.standard_normal((n, n))
    C = rng.standard_normal((p, n))
    Ob = np.vstack([C @ np.linalg.matrix_power(A, k) for k in range(r)]) if r else np.zeros((0, n))
    null = sla.null_space(Ob) if r else np.eye(n)
    E = null @ rng.standard_normal((null.shape[1], q))
    zeros = ut.linalg.invariant_zeros(A, E, C, np.zeros((p, q)))
    rad = np.max(np.abs(zeros), initial=0.0)
    rad = rad if rad > 1e-2 else max(np.abs(np.linalg.eigvals(A)))
    return ut.Plant(A * ((0.5 if stable else 1.7) / rad), C, E=E, dt=1)


def _solvable(plant, a):
    """Independently of the rank increments: are the rows of [E 0 ... 0] in the row space of
    M_a (so that some F solves F M_a = [E 0 ... 0])? Ranks against the data's size."""
    Th, M, _ = stacked_matrices(plant, a)
    k = np.linalg.matrix_rank(plant.E)
    target = np.zeros((k, M.shape[1]))
    target[:, :k] = np.eye(k)  # the unknown input's own coordinates
    tol = 1e-9 * max(1.0, np.linalg.norm(Th, 2))
    return np.linalg.matrix_rank(np.vstack([M, target]), tol=tol) == np.linalg.matrix_rank(
        M, tol=tol
    )


def test_delay_exists_iff_rank_increment_and_strong_detectability():
    """Both directions on random plants of relative degree 0, 1, 2: the verdict's delay is the
    smallest for which F M = [E 0] can be solved, and a design exists (stable, poles exact)
    exactly when, in addition, every invariant zero lies inside the unit disk."""
    seen = {True: 0, False: 0}
    for seed in range(48):
        r = seed % 3
        plant = _relative_degree_plant(seed, r, stable=seed % 4 != 3)
        report = ut.check_existence(plant)
        if not report.decided:
            continue
        v = ut.delay_verdict(plant)
        smallest = next((a - 1 for a in range(1, plant.n + 2) if _solvable(plant, a)), None)
        assert v.delay == smallest, (seed, v.increments)
        strong = bool(np.all(np.abs(report.invariant_zeros) < 1))
        assert v.exists == (smallest is not None and strong), (seed, v.reason)
        seen[v.exists] += 1
        if v.exists:
            k = plant.n - report.invariant_zeros.size
            poles = np.linspace(-0.31, 0.29, k)
            obs = ut.design_uio(plant, poles=poles, delay=v.delay)
            want = np.concatenate([poles, report.invariant_zeros])
            got = obs.poles()
            assert matched_distance(got, want) <= 1e-6, (got, want)
            # waiting longer than needed works too
            assert ut.design_uio(plant, poles=poles, delay=v.delay + 1).is_stable
        else:
            with pytest.raises(ut.DelayedUIOExistenceError, match="strongly detectable|no delay"):
                ut.design_delayed_uio(plant, np.zeros(plant.n))
            if smallest is not None:
                # the unstable zero is a mode of the pair no gain moves: the PBH rank drops there
                a = smallest + 1
                Th, M, _ = stacked_matrices(plant, a)
                target = np.zeros((plant.n, M.shape[1]))
                target[:, : np.linalg.matrix_rank(plant.E)] = np.linalg.svd(plant.E)[0][
                    :, : np.linalg.matrix_rank(plant.E)
                ]
                F0 = target @ np.linalg.pinv(M)
                Nm = sla.null_space(M.T).T
                z = report.invariant_zeros[np.argmax(np.abs(report.invariant_zeros))]
                pbh = np.vstack([plant.A - F0 @ Th - z * np.eye(plant.n), Nm @ Th])
                s = np.linalg.svd(pbh, compute_uv=False)
                assert s[-1] <= 1e-6 * s[0]
    assert seen[True] >= 5 and seen[False] >= 3, seen


def test_no_delay_works_when_an_input_never_shows():
    # two unknown inputs, one output: at most one combination ever shows
    plant = ut.Plant(np.diag([0.5, 0.2]), [[1.0, 1.0]], E=np.eye(2), dt=1)
    v = ut.check_existence(plant).delayed
    assert not v.exists and v.delay is None
    with pytest.raises(ut.DelayedUIOExistenceError, match=r"no delay up to L = 2 works"):
        ut.design_uio(plant, poles=[0.1, 0.2], delay=1)


def test_continuous_time_says_what_derivatives_would_cost():
    plant = _late_plant(dt=None)
    v = ut.check_existence(plant).delayed
    assert not v.exists and v.delay == 1 and "derivative" in v.reason and "noise" in v.reason
    with pytest.raises(ut.DelayedUIOExistenceError, match="discrete-time"):
        ut.design_uio(plant, poles=[-1, -2, -3], delay=1)
    assert ut.check_existence(ut.examples.pa9()).delayed is None  # the plain UIO exists


def test_delay_zero_is_the_plain_uio_unchanged():
    plant = ut.examples.dt_case_study()
    a = ut.design_uio(plant, poles=[0.2])
    b = ut.design_uio(plant, poles=[0.2], delay=0)
    assert type(a) is type(b) is ut.UIO
    np.testing.assert_array_equal(a.F, b.F)
    np.testing.assert_array_equal(a.H, b.H)
    # with a measurement disturbance, waiting one sample works too
    c = ut.design_uio(plant, poles=[0.2], delay=1)
    t = np.arange(40)
    rng = np.random.default_rng(2)
    one = ut.simulate(plant, c, t, initial_state=[1, 1, 1])
    two = ut.simulate(
        plant, c, t, initial_state=[1, 1, 1], d=rng.normal(size=40), v=rng.normal(size=40)
    )
    size = size_of(two.states, two.estimates[:, :-1])
    assert_rounding_close(one.error[:, :-1], two.error[:, :-1], size=size, terms=9, steps=40)


@pytest.mark.parametrize("delay", [-1, 1.5, True, "1"])
def test_bad_delay_is_refused(delay):
    with pytest.raises(ValueError, match="delay"):
        ut.design_uio(_late_plant(), poles=[0.1, 0.2, 0.3], delay=delay)


def test_other_bad_input():
    plant = _late_plant()
    with pytest.raises(ValueError, match="poles= with delay="):
        ut.design_uio(plant, K1=np.zeros((3, 2)), delay=1)
    with pytest.raises(ValueError, match=r"3 pole\(s\) can be placed, got 2"):
        ut.design_uio(plant, poles=[0.1, 0.2], delay=1)
    obs = ut.design_uio(plant, poles=[0.1, 0.2, 0.3], delay=1)
    with pytest.raises(ValueError, match="observer_state"):
        ut.simulate(plant, obs, np.arange(10), observer_state=np.zeros(7))


def test_observer_residual_uses_the_aligned_estimate():
    plant = ut.Plant(A3, [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], B=[1.0, 0.0, 1.0], E=[0, 1, 0], dt=1)
    obs = ut.design_uio(plant, poles=[0.2, 0.3, 0.4], delay=1)
    t = np.arange(20)
    rng = np.random.default_rng(4)
    resp = ut.simulate(plant, obs, t, u=rng.normal(size=20), d=rng.normal(size=20))
    r = ut.observer_residual(obs, t, resp.inputs.u, resp.outputs)
    assert np.all(np.isnan(r[:, -1])) and np.all(np.isnan(resp.residual[:, -1]))
    size = size_of(resp.outputs, resp.estimates[:, :-1])
    assert_rounding_close(r[:, :-1], resp.residual[:, :-1], size=size, terms=9, steps=20)
