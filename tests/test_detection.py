"""Fault detection and isolation with UIOs: the defining properties, measured.

* a fault entering through E leaves the UIO's error and residual unchanged, one that does not
  shows in the residual (r = C e + R2 f);
* a threshold set from fault-free noise gives the designed false-alarm rate on fresh data;
* a larger fault is detected sooner;
* a bank member is blind to its own fault (the same residual whatever that fault's signal) and
  sees the others; members with as many measurements as decoupled inputs read no data at all.
"""

from __future__ import annotations

import numpy as np
import pytest
from tolerance import (
    assert_rounding_close,
    assert_same_run,
    assert_zero,
    eigenvector_condition,
    roundoff,
    size_of,
)

import uio_teach as ut
from uio_teach.detection import faulty_plant

T = np.linspace(0, 10, 1001)
U = ut.signals.stack(ut.signals.step(1.0), ut.signals.sinusoid(0.5, 1.0))
D = ut.signals.sinusoid(1.0, 2.0)
SIGMA = 0.01


@pytest.fixture(scope="module")
def pa9():
    return ut.examples.pa9()


@pytest.fixture(scope="module")
def uio(pa9):
    return ut.design_uio(pa9, poles=[-1, -2, -3])


@pytest.fixture(scope="module")
def three_sensors(pa9):
    return ut.Plant(pa9.A, np.eye(3), B=pa9.B, E=pa9.E, name="PA9, three sensors")


def healthy_residuals(plant, obs, seeds):
    return np.stack(
        [
            ut.simulate_fault(plant, obs, T, u=U, d=D, noise=SIGMA, seed=int(s)).residual
            for s in seeds
        ]
    )


# faults ------------------------------------------------------------------------------------


def test_fault_directions(pa9):
    f = ut.signals.step(1.0, 2.0)
    a = ut.actuator_fault(pa9, 1, f)
    s = ut.sensor_fault(pa9, 0, f)
    p = ut.process_fault(pa9, pa9.E, f, name="through E")
    np.testing.assert_array_equal(a.state_direction, pa9.B[:, 1])
    np.testing.assert_array_equal(a.output_direction, 0)
    np.testing.assert_array_equal(s.output_direction, [1, 0])
    np.testing.assert_array_equal(s.state_direction, 0)
    np.testing.assert_array_equal(p.state_direction, pa9.E[:, 0])
    assert (a.name, s.name, p.name) == ("actuator 2", "sensor 1", "through E")
    fp = faulty_plant(pa9, s)
    assert (fp.q, fp.nv) == (pa9.q + 1, pa9.nv + 1)


@pytest.mark.parametrize(
    "call, word",
    [
        (lambda p: ut.actuator_fault(p, 2, ut.signals.step()), "index"),
        (lambda p: ut.actuator_fault(p, -1, ut.signals.step()), "index"),
        (lambda p: ut.actuator_fault(p, 1.0, ut.signals.step()), "index"),
        (lambda p: ut.sensor_fault(p, 2, ut.signals.step()), "index"),
        (lambda p: ut.sensor_fault(p, 0, 3.0), "signal"),
        (lambda p: ut.sensor_fault("PA9", 0, ut.signals.step()), "plant"),
        (lambda p: ut.process_fault(p, [1, 0], ut.signals.step()), "direction"),
        (lambda p: ut.process_fault(p, [1, np.nan, 0], ut.signals.step()), "direction"),
    ],
)
def test_fault_bad_inputs(pa9, call, word):
    with pytest.raises(ValueError, match=word):
        call(pa9)


def test_fault_of_another_plant_refused(pa9):
    other = ut.examples.missile_autopilot()
    fault = ut.sensor_fault(other, 0, ut.signals.step())
    with pytest.raises(ValueError, match="fault was built for a plant"):
        ut.simulate_fault(pa9, ut.design_uio(pa9, poles=[-1, -2, -3]), T, fault)


# detection: which faults show ----------------------------------------------------------------


@pytest.mark.parametrize("size", [0.5, -2.0])
def test_fault_through_E_is_invisible(pa9, uio, size):
    """The defining property: error and residual do not change, whatever the fault signal."""
    base = ut.simulate_fault(pa9, uio, T, u=U, d=D, initial_state=[1, 0, -1])
    for signal in (ut.signals.step(size, 3.0), ut.signals.sinusoid(size, 5.0)):
        fault = ut.process_fault(pa9, pa9.E, signal)
        resp = ut.simulate_fault(pa9, uio, T, fault, u=U, d=D, initial_state=[1, 0, -1])
        assert_same_run(resp.error, base.error, resp, base)
        assert_same_run(resp.residual, base.residual, resp, base)
        assert np.abs(resp.states - base.states).max() > 0.1  # the fault does act


@pytest.mark.parametrize("kind, index", [("actuator", 0), ("actuator", 1), ("sensor", 0)])
def test_fault_outside_E_shows_in_residual(pa9, uio, kind, index):
    make = ut.actuator_fault if kind == "actuator" else ut.sensor_fault
    fault = make(pa9, index, ut.signals.step(0.5, 5.0))
    resp = ut.simulate_fault(pa9, uio, T, fault, u=U, d=D)
    before, after = resp.residual[:, T < 5], resp.residual[:, T > 5.5]
    assert_same_run(before, 0, resp)  # zero (e(0) = 0 here) up to rounding
    assert np.abs(after).max() > 1e-2


def test_residual_is_C_e_plus_sensor_fault(pa9, uio):
    fault = ut.sensor_fault(pa9, 1, ut.signals.step(0.3, 4.0))
    resp = ut.simulate_fault(pa9, uio, T, fault, u=U, d=D)
    f = fault.signal(T)
    assert_same_run(resp.residual, pa9.C @ resp.error + np.outer(fault.output_direction, f), resp)


def test_residual_of_p_equals_q_observer_reads_no_data():
    """Missile: p = q, C H = I and r' = -C K1 r: an actuator fault changes nothing."""
    mis = ut.examples.missile_autopilot()
    obs = ut.design_uio(mis, poles=[-100, -120])
    assert_zero(
        mis.C @ obs.H - np.eye(2), mis.C, obs.H, terms=4, gain=np.linalg.cond(mis.C @ mis.E)
    )
    t = np.linspace(0, 0.5, 2001)
    fault = ut.actuator_fault(mis, 0, ut.signals.step(0.1, 0.2))
    kw = dict(d=ut.examples.missile_inputs(), initial_state=ut.examples.MISSILE_PUBLISHED.x0)
    resp = ut.simulate_fault(mis, obs, t, fault, **kw)
    assert_same_run(resp.residual, 0, resp)  # zero to the rounding of the run
    assert np.abs(resp.error).max() > 1  # the estimate is wrong, and the residual cannot tell


def test_observer_residual_matches_joint_simulation(pa9, uio):
    fault = ut.actuator_fault(pa9, 1, ut.signals.step(0.5, 5.0))
    resp = ut.simulate_fault(pa9, uio, T, fault, u=U, d=D, initial_state=[1, 0, 0])
    r = ut.observer_residual(uio, T, resp.inputs.u, resp.outputs)
    # the observer reads y as linear between samples: agreement to the interpolation error
    np.testing.assert_allclose(r, resp.residual, atol=1e-4)
    finer = np.linspace(0, 10, 4001)
    resp2 = ut.simulate_fault(pa9, uio, finer, fault, u=U, d=D, initial_state=[1, 0, 0])
    r2 = ut.observer_residual(uio, finer, resp2.inputs.u, resp2.outputs)
    assert np.abs(r2 - resp2.residual).max() < np.abs(r - resp.residual).max() / 4


def test_observer_residual_discrete_is_exact():
    case = ut.examples.dt_case_study()
    pmo = ut.design_pmo(case, method="lmi")
    k = np.arange(40)
    resp = ut.simulate(case, pmo, k, d=np.sin(k), v=np.cos(k), initial_state=[1, 2, 3])
    r = ut.observer_residual(pmo, k, resp.inputs.u, resp.outputs)
    assert_same_run(r, resp.residual, resp)


@pytest.mark.parametrize(
    "kwargs, word",
    [
        (dict(observer="uio"), "observer"),
        (dict(u=np.zeros((3, 1001))), "u has shape"),
        (dict(y=np.zeros((2, 10))), "y has shape"),
        (dict(observer_state=[1, 2]), "observer_state"),
    ],
)
def test_observer_residual_bad_inputs(uio, kwargs, word):
    args = dict(observer=uio, timepts=T, u=np.zeros((2, 1001)), y=np.zeros((2, 1001)))
    extra = {k: kwargs.pop(k) for k in list(kwargs) if k == "observer_state"}
    args.update(kwargs)
    with pytest.raises(ValueError, match=word):
        ut.observer_residual(args["observer"], args["timepts"], args["u"], args["y"], **extra)


def test_observer_residual_runs_on_the_simulation_engine_also_on_a_non_uniform_grid(uio):
    # one engine: the residual of the observer alone equals the joint simulation's
    plant = uio.plant
    t = np.r_[0, np.linspace(0.01, 3, 300) ** 1.1]
    resp = ut.simulate(plant, uio, t, d=ut.signals.sinusoid(1.0, 2.0), initial_state=[1, 0, 0])
    r = ut.observer_residual(uio, t, resp.inputs.u, resp.outputs)
    assert float(np.abs(r - resp.residual).max()) < 1e-3 * float(np.abs(resp.residual).max())


# residual evaluation and thresholds ------------------------------------------------------------


def test_residual_rms_of_constant_and_window():
    r = np.vstack([3 * np.ones(T.size), 4 * np.ones(T.size)])
    np.testing.assert_allclose(ut.residual_rms(T, r, 0.5), 5.0)
    step = np.where(T >= 5, 1.0, 0.0)[None]
    J = ut.residual_rms(T, step, 1.0)
    assert J[T < 4.99].max() == 0
    np.testing.assert_allclose(J[T >= 6.01], 1.0)
    assert 0 < J[np.searchsorted(T, 5.5)] < 1
    runs = ut.residual_rms(T, np.stack([r, 2 * r]), 0.5)
    np.testing.assert_allclose(runs[1], 2 * runs[0])


@pytest.mark.parametrize(
    "call, word",
    [
        (lambda: ut.residual_rms(T, np.ones((2, T.size)), 0), "window"),
        (lambda: ut.residual_rms(T, np.ones((2, T.size)), np.inf), "window"),
        (lambda: ut.residual_rms(T, np.ones((2, 5)), 1.0), "residual must have shape"),
        (lambda: ut.residual_rms(T, np.full((2, T.size), np.nan), 1.0), "non-finite"),
        (
            lambda: ut.residual_threshold(
                T, np.ones((2, T.size)), false_alarm_rate=1.5, window=0.5
            ),
            "false_alarm_rate",
        ),
        (
            lambda: ut.residual_threshold(T, np.ones((2, T.size)), false_alarm_rate=0, window=0.5),
            "false_alarm_rate",
        ),
        (
            lambda: ut.residual_threshold(
                T, np.ones((2, T.size)), false_alarm_rate=0.1, window=0.5, per="hour"
            ),
            "per",
        ),
        (
            lambda: ut.residual_threshold(
                T, np.ones((2, T.size)), false_alarm_rate=0.1, window=0.5, start=20.0
            ),
            "start",
        ),
        (lambda: ut.detect(T, np.ones((2, T.size)), 0.5), "threshold"),
        (lambda: ut.false_alarm_rate(T, np.ones((2, T.size)), 0.5), "threshold"),
    ],
)
def test_evaluation_bad_inputs(call, word):
    with pytest.raises(ValueError, match=word):
        call()


@pytest.fixture(scope="module")
def monte_carlo(pa9, uio):
    design = healthy_residuals(pa9, uio, range(200))
    fresh = healthy_residuals(pa9, uio, range(1000, 1200))
    return design, fresh


@pytest.mark.parametrize("rate", [0.01, 0.05])
def test_false_alarm_rate_per_sample_near_design(monte_carlo, rate):
    design, fresh = monte_carlo
    thr = ut.residual_threshold(T, design, false_alarm_rate=rate, window=0.5)
    assert ut.false_alarm_rate(T, design, thr) == pytest.approx(rate, abs=1e-3)
    measured = ut.false_alarm_rate(T, fresh, thr)
    assert measured == pytest.approx(rate, rel=0.5)
    # a per-sample rate lets many more runs raise an alarm somewhere
    assert ut.false_alarm_rate(T, fresh, thr, per="run") > 5 * rate


def test_false_alarm_rate_per_run_near_design(monte_carlo):
    design, fresh = monte_carlo
    thr = ut.residual_threshold(T, design, false_alarm_rate=0.1, window=0.5, per="run")
    measured = ut.false_alarm_rate(T, fresh, thr)
    # 200 fresh runs: binomial standard deviation sqrt(0.1 * 0.9 / 200) = 0.021
    assert abs(measured - 0.1) < 0.07
    per_sample = ut.residual_threshold(T, design, false_alarm_rate=0.1, window=0.5)
    assert thr.value > per_sample.value


def test_threshold_grows_with_noise_and_shrinks_with_window(pa9, uio):
    small = healthy_residuals(pa9, uio, range(30))
    thr = ut.residual_threshold(T, small, false_alarm_rate=0.05, window=0.5)
    thr2 = ut.residual_threshold(T, 2 * small, false_alarm_rate=0.05, window=0.5)
    # doubling is exact in binary; the threshold's sums over the samples round at most eps each
    assert thr2.value == pytest.approx(2 * thr.value, rel=roundoff(1.0, terms=small.size))
    long = ut.residual_threshold(T, small, false_alarm_rate=0.05, window=2.0)
    assert long.value < thr.value


@pytest.mark.parametrize(
    "kwargs, word",
    [
        (dict(value=-1.0), "value"),
        (dict(value=np.nan), "value"),
        (dict(window=0.0), "window"),
        (dict(design_rate=1.0), "design_rate"),
        (dict(start=np.inf), "start"),
        (dict(per="day"), "per"),
    ],
)
def test_threshold_refuses_bad_fields(kwargs, word):
    fields = dict(value=0.5, window=0.2, design_rate=0.01, start=0.2, samples=1)
    fields.update(kwargs)
    with pytest.raises(ValueError, match=word):
        ut.Threshold(**fields)


def test_detect_alarm_only_after_start():
    thr = ut.Threshold(value=0.5, window=0.2, design_rate=0.01, start=3.0, samples=1)
    r = np.ones((1, T.size))
    det = ut.detect(T, r, thr)
    assert det.fired and det.first_alarm == pytest.approx(3.0)
    assert not det.alarm[T < 3].any() and det.alarm[T >= 3].all()
    quiet = ut.detect(T, 0 * r, thr)
    assert not quiet.fired and quiet.first_alarm is None and quiet.alarm_times.size == 0


def test_detection_time_decreases_with_fault_size(pa9, uio, monte_carlo):
    design, _ = monte_carlo
    thr = ut.residual_threshold(T, design, false_alarm_rate=0.05, window=0.5, per="run")
    medians = []
    for size in (0.02, 0.05, 0.2, 1.0):
        fault = ut.actuator_fault(pa9, 1, ut.signals.step(size, 5.0))
        times = [
            ut.detection_time(
                T,
                ut.simulate_fault(pa9, uio, T, fault, u=U, d=D, noise=SIGMA, seed=500 + k).residual,
                thr,
                5.0,
            )
            for k in range(20)
        ]
        medians.append(np.median(times))
    assert np.all(np.isfinite(medians))
    assert np.all(np.diff(medians) < 0), medians
    # below the noise: never detected
    tiny = ut.actuator_fault(pa9, 1, ut.signals.step(1e-5, 5.0))
    resp = ut.simulate_fault(pa9, uio, T, tiny, u=U, d=D, noise=SIGMA, seed=3)
    assert ut.detection_time(T, resp.residual, ut.Threshold(1.0, 0.5, 0.01, 0.5, 1), 5.0) == np.inf


def test_detection_time_bad_fault_time():
    thr = ut.Threshold(value=0.5, window=0.2, design_rate=0.01, start=0.2, samples=1)
    with pytest.raises(ValueError, match="fault_time"):
        ut.detection_time(T, np.ones((1, T.size)), thr, fault_time=11.0)


# the bank ------------------------------------------------------------------------------------


def test_pa9_bank_members_honest(pa9):
    act = ut.design_uio_bank(pa9, "actuator", poles=[-2, -3, -4])
    assert not act.members[0].exists
    assert [c.name for c in act.members[0].report.failed] == ["rank condition"]
    assert act.members[1].exists and act.members[1].residual_size == 0
    sen = ut.design_uio_bank(pa9, "sensor", poles=[-2, -3, -4])
    assert all(m.exists and m.residual_size == 0 and not m.usable for m in sen.members)
    assert "does not exist: rank condition" in repr(act)


def test_blind_member_reads_no_data(pa9):
    """residual_size 0: r' = -C K1 r, so two runs with different faults give the same residual."""
    member = ut.design_uio_bank(pa9, "actuator", poles=[-2, -3, -4]).members[1]
    obs = member.observer
    CK1 = member.plant.C @ obs.K1
    rng = np.random.default_rng(0)
    u = rng.standard_normal((1, T.size))
    y1, y2 = rng.standard_normal((2, T.size)), rng.standard_normal((2, T.size))
    w0 = rng.standard_normal(3)
    r1 = ut.observer_residual(obs, T, u, y1, observer_state=w0)
    r2 = ut.observer_residual(obs, T, 0 * u, y2, observer_state=w0)
    # two runs of the residual recursion, equal to its rounding: terms as large as y, u, w0
    size = size_of(r1, r2, y1, y2, u, w0) * max(1.0, size_of(obs.K1, CK1))
    tol = dict(size=size, terms=9, steps=T.size, gain=eigenvector_condition(CK1))
    assert_rounding_close(r1, r2, **tol)
    from scipy.linalg import expm

    tol["steps"] += np.linalg.norm(CK1, 1) * T[100]  # the reference's scaling and squaring
    assert_rounding_close(r1[:, 100], expm(-CK1 * T[100]) @ r1[:, 0], **tol)


@pytest.fixture(scope="module")
def banks(three_sensors):
    act = ut.design_uio_bank(three_sensors, "actuator", poles=[-2, -3, -4])
    sen = ut.design_uio_bank(three_sensors, "sensor", poles=[-2, -3, -4])
    return act, sen


def test_three_sensor_bank_exists(banks):
    for bank in banks:
        assert all(m.usable and m.residual_size == 1 for m in bank.members)
        for m in bank.members:
            assert m.observer.is_stable


@pytest.mark.parametrize("kind", ["actuator", "sensor"])
def test_member_is_blind_to_its_fault_and_sees_the_others(three_sensors, banks, kind):
    bank = banks[0] if kind == "actuator" else banks[1]
    make = ut.actuator_fault if kind == "actuator" else ut.sensor_fault
    monitor = ut.design_uio(three_sensors, poles=[-1, -2, -3])
    for i in range(len(bank.members)):
        runs = []
        for signal in (ut.signals.step(0.5, 4.0), ut.signals.sinusoid(2.0, 3.0)):
            resp = ut.simulate_fault(three_sensors, monitor, T, make(three_sensors, i, signal), u=U)
            runs.append(bank.residuals(resp))
        healthy = bank.residuals(ut.simulate_fault(three_sensors, monitor, T, u=U))
        # member i: the same residual whatever fault i does (here: no residual at all), up to
        # reading y as linear between samples (h = 0.01 s: about 1e-5)
        np.testing.assert_allclose(runs[0][i], runs[1][i], atol=1e-4)
        np.testing.assert_allclose(runs[0][i], healthy[i], atol=1e-4)
        for j in range(len(bank.members)):
            if j != i:
                assert np.abs(runs[0][j] - healthy[j]).max() > 1e-2, (i, j)


def test_isolation_names_the_fault(three_sensors, banks):
    act, sen = banks
    monitor = ut.design_uio(three_sensors, poles=[-1, -2, -3])
    kw = dict(u=U, d=D, noise=SIGMA)
    healthy = [ut.simulate_fault(three_sensors, monitor, T, seed=k, **kw) for k in range(40)]
    th_act = act.thresholds(healthy, false_alarm_rate=0.05, window=0.5)
    th_sen = sen.thresholds(healthy, false_alarm_rate=0.05, window=0.5)
    for i in range(2):
        fault = ut.actuator_fault(three_sensors, i, ut.signals.step(0.3, 5.0))
        resp = ut.simulate_fault(three_sensors, monitor, T, fault, seed=900 + i, **kw)
        assert act.isolate(resp, th_act).suspect == f"actuator {i + 1}"
    for j in range(3):
        fault = ut.sensor_fault(three_sensors, j, ut.signals.step(0.3, 5.0))
        resp = ut.simulate_fault(three_sensors, monitor, T, fault, seed=950 + j, **kw)
        assert sen.isolate(resp, th_sen).suspect == f"sensor {j + 1}"
    quiet = ut.simulate_fault(three_sensors, monitor, T, seed=999, **kw)
    assert act.isolate(quiet, th_act).suspect == "no fault"


def test_isolation_verdicts():
    faults = ("a", "b", "c")
    assert ut.Isolation(faults, (False, False, False), (None,) * 3).suspect == "no fault"
    assert ut.Isolation(faults, (True, True, True), (1.0,) * 3).suspect == "not isolated"
    assert ut.Isolation(faults, (False, True, False), (None, 1, None)).suspect == "not isolated"
    # a member that does not exist: its fault cannot be named
    assert ut.Isolation(faults, (None, True, False), (None, 1, None)).suspect == "not isolated"


@pytest.mark.parametrize(
    "call, word",
    [
        (lambda p: ut.design_uio_bank("PA9", "actuator", poles=[-1, -2, -3]), "plant"),
        (lambda p: ut.design_uio_bank(p, "valve", poles=[-1, -2, -3]), "kind"),
        (lambda p: ut.design_uio_bank(p, "sensor", poles=[-1]), "poles"),
        (lambda p: ut.design_uio_bank(p, "sensor", poles="fast"), "poles"),
        (
            lambda p: ut.design_uio_bank(
                ut.Plant(p.A, p.C, B=p.B[:, :1], E=p.E), "actuator", poles=[-1, -2, -3]
            ),
            "^an actuator bank needs at least 2 actuators",
        ),
        (
            lambda p: ut.design_uio_bank(ut.Plant(p.A, p.C[:1], B=p.B), "sensor", poles=[-1, -2]),
            "^a sensor bank needs at least 2 sensors",
        ),
    ],
)
def test_bank_bad_inputs(three_sensors, call, word):
    with pytest.raises(ValueError, match=word):
        call(three_sensors)


def test_bank_residuals_and_thresholds_bad_inputs(banks, pa9):
    act, _ = banks
    with pytest.raises(ValueError, match="response"):
        act.residuals(np.zeros((3, 10)))
    other = ut.simulate(pa9, ut.design_uio(pa9, poles=[-1, -2, -3]), T)
    with pytest.raises(ValueError, match="bank monitors"):
        act.residuals(other)
    with pytest.raises(ValueError, match="healthy"):
        act.thresholds([], false_alarm_rate=0.05, window=0.5)
    with pytest.raises(ValueError, match="thresholds"):
        act.isolate(other, [None])
