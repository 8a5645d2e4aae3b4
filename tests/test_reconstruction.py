"""reconstruct_input() (missile paper, eq. (17)) and catch_time() (how Table II is read).

References are closed forms or plain loops written here; no stored simulation outputs.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from tolerance import assert_rounding_close, assert_same_run, eigenvector_condition, size_of

import uio_teach as ut
from uio_teach import examples, signals

X0 = np.asarray(examples.MISSILE_PUBLISHED.x0)


def _missile_run(family: str, *, samples: int = 20001, span: float = 0.2, **kwargs):
    plant = examples.missile_autopilot()
    obs = ut.design_ginverse(plant) if family == "g-inverse" else ut.design_pmo(plant, [-80, -120])
    t = np.linspace(0.0, span, samples)
    run = ut.simulate(plant, obs, t, d=examples.missile_inputs(), initial_state=X0, **kwargs)
    return plant, run


# the missile example ---------------------------------------------------------------------------


@pytest.mark.parametrize("family", ["g-inverse", "PMO"])
def test_missile_inputs_are_recovered(family):
    plant, run = _missile_run(family)
    est = ut.reconstruct_input(plant, run)
    assert est.method == "derivative" and est.tau is None
    np.testing.assert_array_equal(est.actual, run.inputs.d)
    late = run.time >= 0.1
    scale = np.abs(est.actual).max(axis=1)  # 10 and about 50
    # v1 and v2 converge: after 0.1 s the error is a small fraction of each signal
    assert np.all(np.abs(est.error[:, late]).max(axis=1) < 1e-3 * scale)
    # while at the start (observer not converged) it is not small at all
    assert np.all(np.abs(est.error[:, :50]).max(axis=1) > 0.1 * scale)
    # caught about when the paper says (Table II: 0.04 / 0.02 s g-inverse, 0.08 / 0.07 s PMO)
    caught = ut.catch_time(est.time, est.actual, est.estimates)
    assert np.all(caught > 0.0) and np.all(caught < 0.08)


def test_filtered_derivative_beats_the_raw_derivative_under_noise():
    plant, noisy = _missile_run("g-inverse", noise=0.01, seed=2014)
    late = noisy.time >= 0.1
    raw = ut.reconstruct_input(plant, noisy)
    filtered = ut.reconstruct_input(plant, noisy, method="filtered", tau=3e-3)
    rms_raw = np.sqrt(np.mean(raw.error[:, late] ** 2, axis=1))
    rms_filtered = np.sqrt(np.mean(filtered.error[:, late] ** 2, axis=1))
    assert np.all(rms_filtered < rms_raw)
    assert np.all(rms_filtered < 0.1 * rms_raw)  # by far: the raw derivative amplifies noise
    # the same seed reproduces the same reconstruction
    _, again = _missile_run("g-inverse", noise=0.01, seed=2014)
    np.testing.assert_array_equal(ut.reconstruct_input(plant, again).estimates, raw.estimates)


def test_filtered_derivative_trades_lag_for_noise():
    """Without noise the filter only costs accuracy, and more so for a larger tau."""
    plant, run = _missile_run("g-inverse")
    late = run.time >= 0.1
    errors = []
    for tau in (1e-4, 1e-3, 1e-2):
        est = ut.reconstruct_input(plant, run, method="filtered", tau=tau)
        assert est.method == "filtered" and est.tau == tau
        errors.append(np.abs(est.error[:, late]).max())
    assert errors[0] < errors[1] < errors[2]
    assert errors[0] < 1.0  # v2 has amplitude ~50 and 100 rad/s: tau = 1e-4 s barely lags


def test_table_ii_shape_for_the_g_inverse_observer():
    """Table II: x1, x2 exact from t = 0 (they are measured); x3, x4 caught within ~0.06 s."""
    plant, run = _missile_run("g-inverse")
    caught = ut.catch_time(run.time, run.states, run.estimates, tol=0.02)
    assert caught[0] == 0.0 and caught[1] == 0.0
    assert 0.03 < caught[2] <= 0.06
    assert 0.03 < caught[3] <= 0.065
    # exact from t = 0 indeed, not only within 2 %
    assert_same_run(run.error[:2], 0, run)


# exactness of the filters ----------------------------------------------------------------------


class _Response:
    """The fields of a response that reconstruct_input reads, for closed-form checks."""

    def __init__(self, time, estimates, u, d=None):
        self.time = np.asarray(time, float)
        self.estimates = np.asarray(estimates, float)

        class Inputs:
            pass

        self.inputs = Inputs()
        self.inputs.u = np.asarray(u, float)
        self.inputs.d = None if d is None else np.asarray(d, float)


INTEGRATOR = ut.Plant([[0.0]], [[1.0]], E=[[1.0]], name="integrator")  # x' = d, so dhat = xhat'


def test_filtered_derivative_is_exact_on_the_grid_for_a_ramp():
    t = np.linspace(0.0, 2.0, 11)  # a coarse grid: a ramp is linear between samples
    tau = 0.3
    est = ut.reconstruct_input(
        INTEGRATOR, _Response(t, 3.0 * t[None], np.zeros((0, t.size))), method="filtered", tau=tau
    )
    # s / (tau s + 1) applied to 3 t (from rest): 3 (1 - exp(-t / tau)), to the rounding of the
    # filter's two-term recursion over the samples
    assert_rounding_close(est.estimates[0], 3.0 * (1 - np.exp(-t / tau)), terms=2, steps=t.size)
    assert est.actual is None and est.error is None


def test_filtered_derivative_of_a_sine_converges_like_h_squared():
    tau = 0.2
    errs = []
    for samples in (201, 401):
        t = np.linspace(0.0, 4.0, samples)
        est = ut.reconstruct_input(
            INTEGRATOR,
            _Response(t, np.sin(t)[None], np.zeros((0, t.size))),
            method="filtered",
            tau=tau,
        )
        # tau y' = cos t - y, y(0) = 0
        exact = (np.cos(t) + tau * np.sin(t) - np.exp(-t / tau)) / (1 + tau**2)
        errs.append(np.abs(est.estimates[0] - exact).max())
    assert errs[0] < 1e-3
    assert 3.5 < errs[0] / errs[1] < 4.5  # second order


def test_filtered_reconstruction_on_a_non_uniform_grid():
    tau = 0.3
    t = np.sort(np.concatenate([[0.0, 2.0], np.random.default_rng(4).uniform(0, 2, 30)]))
    est = ut.reconstruct_input(
        INTEGRATOR, _Response(t, 3.0 * t[None], np.zeros((0, t.size))), method="filtered", tau=tau
    )
    assert_rounding_close(est.estimates[0], 3.0 * (1 - np.exp(-t / tau)), terms=2, steps=t.size)


def test_derivative_method_is_second_order_numpy_gradient():
    plant = examples.pa9()
    t = np.linspace(0.0, 1.0, 51)
    xhat = np.vstack([np.sin(t), t**2, np.exp(-t)])
    u = np.vstack([np.cos(t), np.ones_like(t)])
    est = ut.reconstruct_input(plant, _Response(t, xhat, u))
    dx = np.gradient(xhat, t, axis=1, edge_order=2)
    Ep = np.linalg.pinv(plant.E)
    expected = Ep @ (dx - plant.A @ xhat - plant.B @ u)
    # the same formula: n-term products of E^+ with terms as large as A xhat, B u and dx
    size = size_of(Ep) * size_of(dx, plant.A @ xhat, plant.B @ u)
    assert_rounding_close(est.estimates, expected, size=size, terms=plant.n + plant.m)


# discrete time ----------------------------------------------------------------------------------


def test_discrete_one_step_reconstruction():
    plant = examples.dt_case_study()
    obs = ut.design_pmo(plant, method="lmi")
    k = np.arange(80.0)
    d = np.sin(0.3 * k) + 0.5
    run = ut.simulate(plant, obs, k, d=d, v=np.cos(k), initial_state=[1.0, -1.0, 2.0])
    est = ut.reconstruct_input(plant, run)
    assert np.isnan(est.estimates[0, -1])
    # dhat[k] = E^+ (xhat[k+1] - A xhat[k]), computed here by a loop
    Ep = np.linalg.pinv(plant.E)
    loop = [Ep @ (run.estimates[:, j + 1] - plant.A @ run.estimates[:, j]) for j in range(79)]
    size = size_of(Ep) * (1 + size_of(plant.A)) * size_of(run.estimates)
    assert_rounding_close(est.estimates[:, :-1], np.column_stack(loop), size=size, terms=3)
    # the error poles are {0, 0.5, 0.5}: d is recovered once the error has died out (0.5^60),
    # to the rounding of the run read through E^+ (x[k+1] - A x[k])
    size = size_of(Ep) * (1 + size_of(plant.A)) * size_of(run.states, run.estimates)
    gain = eigenvector_condition(obs.error_matrix)
    assert_rounding_close(est.error[:, 60:-1], 0, size=size, terms=9, steps=k.size, gain=gain)
    # filtered: y[k] = a y[k-1] + (1 - a) dhat[k] from rest, a = exp(-dt / tau)
    tau = 2.0
    filt = ut.reconstruct_input(plant, run, method="filtered", tau=tau)
    a, y, ref = np.exp(-1.0 / tau), 0.0, []
    for value in est.estimates[0, :-1]:
        y = a * y + (1 - a) * value
        ref.append(y)
    assert_rounding_close(filt.estimates[0, :-1], ref, terms=2, steps=k.size)
    assert np.isnan(filt.estimates[0, -1])
    # catch_time skips the NaN sample (counted, it would say 79)
    assert ut.catch_time(k, est.actual[0], est.estimates[0], tol=1e-6) < 79


def test_discrete_filter_with_unspecified_period_counts_steps():
    case = examples.dt_case_study()
    steps = ut.Plant(case.A, case.C, E=case.E, D=case.D, dt=True)
    obs = ut.design_pmo(steps, method="lmi")
    k = 0.5 * np.arange(30.0)  # any uniform spacing; the filter still counts one per step
    run = ut.simulate(steps, obs, k, d=np.ones(30), initial_state=[1.0, 0.0, 0.0])
    est = ut.reconstruct_input(steps, run, method="filtered", tau=4.0)
    raw = ut.reconstruct_input(steps, run)
    a, y = np.exp(-1.0 / 4.0), 0.0
    for j in range(29):
        y = a * y + (1 - a) * raw.estimates[0, j]
    assert_rounding_close(est.estimates[0, 28], y, size=size_of(raw.estimates), terms=2, steps=29)
    fig = est.plot()
    assert fig.axes[-1].get_xlabel() == "step k"
    plt.close(fig)


# the result object -------------------------------------------------------------------------------


def test_input_estimate_fields_and_plot():
    plant, run = _missile_run("g-inverse", samples=2001)
    est = ut.reconstruct_input(plant, run, method="filtered", tau=1e-3)
    assert est.estimates.shape == est.actual.shape == est.error.shape == (2, 2001)
    np.testing.assert_array_equal(est.error, est.estimates - est.actual)
    np.testing.assert_array_equal(est.time, run.time)
    assert est.dt is None
    text = repr(est)
    assert "filtered" in text and "tau=0.001" in text and "q=2" in text
    fig = est.plot()
    assert len(fig.axes) == 2
    assert sorted(ax.get_ylabel() for ax in fig.axes) == [
        "$d_{1}$ (model units)",
        "$d_{2}$ (model units)",
    ]
    assert fig.axes[-1].get_xlabel() == "time (s)"
    line_true, line_est = fig.axes[0].get_lines()
    np.testing.assert_array_equal(line_est.get_ydata(), est.estimates[0])
    np.testing.assert_array_equal(line_true.get_ydata(), est.actual[0])
    fig2, axes = plt.subplots(2, 1)
    assert est.plot(axes=axes) is fig2
    plt.close("all")


# clear errors ------------------------------------------------------------------------------------


def test_e_without_full_column_rank_is_refused():
    plant = ut.Plant(
        [[0, 1], [-2, -3]], [[1, 0], [0, 1]], E=[[1, 2], [1, 2]], name="E rank 1"
    )  # the two unknown inputs act along the same direction
    obs = ut.design_luenberger(plant, poles=[-4, -5])
    run = ut.simulate(plant, obs, np.linspace(0, 1, 11))
    with pytest.raises(ValueError, match=r"E has rank 1 < q = 2.*only E d can be recovered"):
        ut.reconstruct_input(plant, run)


def test_a_plant_without_unknown_input_is_refused():
    plant = ut.Plant([[0, 1], [-2, -3]], [[1, 0]], B=[[0], [1]])
    obs = ut.design_luenberger(plant, poles=[-4, -5])
    run = ut.simulate(plant, obs, np.linspace(0, 1, 11))
    with pytest.raises(ValueError, match="no unknown input"):
        ut.reconstruct_input(plant, run)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"method": "filtered"}, r"tau must be a positive time constant.*got None"),
        ({"method": "filtered", "tau": 0.0}, r"tau must be a positive"),
        ({"method": "filtered", "tau": -1.0}, r"tau must be a positive"),
        ({"method": "filtered", "tau": np.inf}, r"tau must be a positive"),
        ({"method": "filtered", "tau": "fast"}, r"tau must be a positive"),
        ({"tau": 0.1}, r"tau is the filter time constant: give it only with method='filtered'"),
        ({"method": "spline"}, r"method must be 'derivative' or 'filtered', got 'spline'"),
    ],
)
def test_bad_method_or_tau(kwargs, pattern):
    plant = examples.pa9()
    run = ut.simulate(plant, ut.design_uio(plant, poles=[-1, -2, -3]), np.linspace(0, 1, 11))
    with pytest.raises(ValueError, match=pattern):
        ut.reconstruct_input(plant, run, **kwargs)


def test_response_must_fit_the_plant():
    pa9 = examples.pa9()
    run = ut.simulate(pa9, ut.design_uio(pa9, poles=[-1, -2, -3]), np.linspace(0, 1, 11))
    with pytest.raises(ValueError, match=r"response.estimates has shape \(3, 11\), expected \(4"):
        ut.reconstruct_input(examples.missile_autopilot(), run)
    with pytest.raises(ValueError, match="response must be the result of uio_teach.simulate"):
        ut.reconstruct_input(pa9, np.zeros((3, 11)))
    with pytest.raises(ValueError, match="plant must be a uio_teach.Plant"):
        ut.reconstruct_input("pa9", run)


# catch_time -------------------------------------------------------------------------------------


def test_catch_time_reads_the_last_exit_from_the_band():
    t = np.linspace(0.0, 1.0, 1001)
    actual = np.ones_like(t)
    estimate = 1.0 - np.exp(-10.0 * t)  # error exp(-10 t): inside 2 % after ln(50) / 10
    caught = ut.catch_time(t, actual, estimate)
    assert isinstance(caught, float)
    assert caught == pytest.approx(np.log(50.0) / 10.0, abs=1e-3)
    assert caught < np.log(50.0) / 10.0  # the last sample outside the band
    # a late excursion counts: the estimate must *stay* in the band
    bumped = estimate.copy()
    bumped[800] += 0.5
    assert ut.catch_time(t, actual, bumped) == pytest.approx(0.8)
    # trailing NaN samples (undefined end of a discrete reconstruction) are not judged
    tail = estimate.copy()
    tail[-1] = np.nan
    assert ut.catch_time(t, actual, tail) == caught
    # any other NaN is never "caught": it counts as outside the band
    holes = estimate.copy()
    holes[[0, 999]] = np.nan
    assert ut.catch_time(t, actual, holes) == pytest.approx(0.999)
    # never outside: 0.0 (even when time does not start at 0)
    assert ut.catch_time(t + 5.0, actual, actual + 0.01) == 0.0
    # the band scales with max|actual| and tol
    assert ut.catch_time(t, 10 * actual, 10 * estimate) == caught
    assert ut.catch_time(t, actual, estimate, tol=0.1) == pytest.approx(
        np.log(10.0) / 10.0, abs=1e-3
    )


def test_catch_time_per_channel():
    t = np.linspace(0.0, 1.0, 101)
    actual = np.vstack([np.ones_like(t), np.sin(10 * t)])
    estimate = actual + np.vstack([np.exp(-10 * t), np.zeros_like(t)])
    caught = ut.catch_time(t, actual, estimate)
    assert isinstance(caught, np.ndarray) and caught.shape == (2,)
    assert caught[1] == 0.0 and caught[0] == pytest.approx(0.39)
    np.testing.assert_array_equal(
        caught, [ut.catch_time(t, a, e) for a, e in zip(actual, estimate, strict=True)]
    )


@pytest.mark.parametrize(
    ("args", "kwargs", "pattern"),
    [
        ((np.arange(5.0), np.zeros(4), np.zeros(4)), {}, r"one sample per time point \(5\), got 4"),
        ((np.arange(5.0), np.zeros(5), np.zeros(4)), {}, r"same shape, got \(5,\) and \(4,\)"),
        ((np.zeros((2, 5)), np.zeros(5), np.zeros(5)), {}, r"time must be a 1-D"),
        ((np.arange(5.0), np.zeros((1, 1, 5)), np.zeros((1, 1, 5))), {}, r"1-D or 2-D"),
        ((np.arange(5.0), np.zeros(5), np.zeros(5)), {"tol": -0.1}, r"tol must be >= 0"),
        ((np.arange(5.0), np.zeros(5), np.zeros(5)), {"tol": "2%"}, r"tol must be a real number"),
    ],
)
def test_catch_time_validates(args, kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        ut.catch_time(*args, **kwargs)


def test_pa9_lab_sinusoid_is_reconstructed():
    """The lab of PA9: a sinusoidal disturbance, recovered once the error has decayed."""
    plant = examples.pa9()
    obs = ut.design_uio(plant, poles=[-1, -2, -3])
    t = np.linspace(0.0, 20.0, 8001)
    run = ut.simulate(plant, obs, t, d=signals.sinusoid(1.0, 2.0), initial_state=[1.0, 0.0, 1.0])
    est = ut.reconstruct_input(plant, run)
    assert np.abs(est.error[:, t > 10]).max() < 1e-4
    assert ut.catch_time(t, est.actual, est.estimates) < 6.0


def test_nan_estimate_is_never_caught():
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ValueError, match="^estimate has no finite sample"):
        ut.catch_time(t, np.ones(11), np.full(11, np.nan))
    # one channel all NaN, the other fine: that channel never caught anything
    actual = np.ones((2, 11))
    estimate = np.vstack([np.full(11, np.nan), np.ones(11)])
    np.testing.assert_array_equal(ut.catch_time(t, actual, estimate), [1.0, 0.0])
    # a NaN in the middle of a settled estimate counts as outside the band
    mid = np.ones(11)
    mid[5] = np.nan
    assert ut.catch_time(t, np.ones(11), mid) == pytest.approx(0.5)


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (("a", "b", "c"), "time"),
        ((np.arange(3.0), "b", "c"), "actual"),
        ((np.arange(3.0), np.ones(3), "c"), "estimate"),
    ],
)
def test_catch_time_names_the_argument_that_is_not_numeric(args, name):
    with pytest.raises(ValueError, match=rf"^{name} must"):
        ut.catch_time(*args)
