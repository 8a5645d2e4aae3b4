"""The nullspace fault detection filter: Varga's Example 5.4 as printed, and its properties.

* Example 5.4 of Varga, *Solving Fault Diagnosis Problems*: ``Q`` and ``Rf`` as printed (after the
  book's normalization, ``Rf``'s first entry at infinity equal to 1);
* ``Q [[Gu, Gd], [I, 0]] = 0`` on the returned system, and ``Rf = Q [[Gf], [0]]``;
* in simulation the residual is the same whatever the known inputs and the disturbances are, and
  equals ``Rf`` applied to the faults;
* the poles are the requested ones; a fault is reported detected exactly when it reaches the
  residual; no filter exists exactly when the disturbances reach every output direction.
"""

from __future__ import annotations

import control as ct
import numpy as np
import pytest
import scipy.signal
from tolerance import assert_rounding_close, eigenvalue_roundoff, roundoff, size_of

import uio_teach as ut
from uio_teach.examples import VARGA_5_4_PUBLISHED

T = np.linspace(0, 10, 1001)
U = ut.signals.stack(ut.signals.step(1.0), ut.signals.sinusoid(0.5, 1.0))
STEP = ut.signals.step(0.5, 5.0)


def varga():
    return ut.design_nullspace_filter(
        ut.examples.varga_5_4(), [2, 3], known=[0], disturbances=[1], poles=[-3]
    )


def tf_coefficients(sys, j):
    """Numerator and monic denominator of input ``j`` of a one-output system, descending."""
    num, den = scipy.signal.ss2tf(
        np.asarray(sys.A), np.asarray(sys.B), np.asarray(sys.C), np.asarray(sys.D), input=j
    )
    return num[0] / den[0], den / den[0]


def condition(sys_or_A, points):
    """The largest ``cond(sI - A)`` over the points: what a solve at them can amplify."""
    A = np.asarray(getattr(sys_or_A, "A", sys_or_A), float)
    n = A.shape[0]
    return max(np.linalg.cond(s * np.eye(n) - A) for s in points) if n else 1.0


def default_points(model):
    """The points ``decoupling_gap`` evaluates at by default."""
    w = np.array([0.1, 0.5, 1.0, 2.0, 3.0])
    if model.is_discrete:
        return 0.9 * np.exp(1j * w)
    return (np.linalg.norm(model.A, 2) or 1.0) * (0.05 + 1j * w)


def parity_condition(model, degree):
    """Condition of the parity matrix ``[O_k, T_d,k]`` in the design's scaled time: how much the
    rounding of its nullspace vector (the basis row) can be amplified."""
    omega = 1.0 if model.is_discrete else (np.linalg.norm(model.A, 2) or 1.0)
    A, Bd = model.A / omega, model.Bd / omega
    blocks = [model.C @ np.linalg.matrix_power(A, i) for i in range(degree + 1)]
    markov = [model.Dd] + [model.C @ np.linalg.matrix_power(A, j) @ Bd for j in range(degree)]
    p, md = model.Dd.shape
    T = np.zeros((p * (degree + 1), md * (degree + 1)))
    for i in range(degree + 1):
        for j in range(i + 1):
            T[i * p : (i + 1) * p, j * md : (j + 1) * md] = markov[i - j]
    M = np.hstack([np.vstack(blocks), T])
    s = np.linalg.svd(M, compute_uv=False)[: ut.linalg.rank(M)]  # the rank the design found
    return float(s[0] / s[-1])


def assert_decoupled(filt, Q=None):
    """``Q [[Gu, Gd], [I, 0]] = 0`` to what rounding explains: the solves at the points (the
    conditions of ``sI - A`` and ``sI - Aq``) and the basis rows (the parity matrices')."""
    model = filt.model
    Q = filt.Q if Q is None else Q
    points = default_points(model)
    gain = condition(model.A, points) * condition(Q, points)
    gain *= max(parity_condition(model, k) for k in filt.degrees)
    n = model.n + filt.order
    tol = roundoff(1.0, terms=n * n, gain=gain)
    gap = ut.decoupling_gap(Q, model)
    assert gap <= tol, f"Q G is {gap:.3g} of its terms, more than rounding explains ({tol:.3g})"


def pa9_faults(plant):
    return [
        ut.actuator_fault(plant, 0, STEP),
        ut.actuator_fault(plant, 1, STEP),
        ut.sensor_fault(plant, 0, STEP),
        ut.sensor_fault(plant, 1, STEP),
        ut.process_fault(plant, plant.E, STEP, name="along E"),
    ]


# Varga's Example 5.4 ---------------------------------------------------------------------------


def test_varga_5_4_as_printed():
    filt = varga()
    # the book's normalization: Rf's first entry at infinity is 1
    printed = filt.scaled(filt.Rf.D[0, 0])
    pub = VARGA_5_4_PUBLISHED
    half_digit = 0.5 * 10.0 ** -(pub.decimals - 1)  # 4 significant digits of numbers up to 3
    for j, expected in enumerate(pub.Q_num):
        num, den = tf_coefficients(printed.Q, j)
        np.testing.assert_allclose(den, pub.den, atol=half_digit)
        np.testing.assert_allclose(num, expected, atol=half_digit * max(1, *np.abs(expected)))
    for j, expected in enumerate(pub.Rf_num):
        num, den = tf_coefficients(printed.Rf, j)
        np.testing.assert_allclose(den, pub.den, atol=half_digit)
        np.testing.assert_allclose(num, expected, atol=half_digit * max(1, *np.abs(expected)))
    # and beyond the printed digits: the same rational functions to rounding
    for j, expected in enumerate(pub.Q_num):
        num, _ = tf_coefficients(printed.Q, j)
        assert_rounding_close(num, expected, size=3.0, terms=9, what=f"Q[{j}]")
    assert filt.degrees == (1,) and filt.order == 1
    assert filt.detected == (True, True) and filt.structure.tolist() == [[True, True]]


def test_varga_5_4_poles_and_defining_identities():
    filt = varga()
    model = filt.model
    tol = eigenvalue_roundoff(filt.Q.A)
    assert np.abs(filt.poles() - VARGA_5_4_PUBLISHED.poles).max() <= tol
    assert np.abs(np.linalg.eigvals(filt.Rf.A) - VARGA_5_4_PUBLISHED.poles).max() <= tol
    points = 3.0 * (0.05 + 1j * np.array([0.1, 0.5, 1.0, 2.0, 3.0]))
    gain = condition(model.A, points) * condition(filt.Q, points)
    assert_decoupled(filt)
    # Rf = Q [Gf; 0], evaluated on the returned systems at the same points
    sys = ut.examples.varga_5_4()
    for s in points:
        Gf = np.asarray(sys(s))[:, 2:]
        Qs = np.asarray(filt.Q(s)).reshape(1, 3)
        Rfs = np.asarray(filt.Rf(s)).reshape(1, 2)
        size = np.linalg.norm(Qs) * np.linalg.norm(Gf)
        assert_rounding_close(Rfs, Qs[:, :2] @ Gf, size=size, terms=9, gain=gain)


def test_a_wrong_construction_fails_the_check():
    # [I, -Gu] cancels the known input only: the disturbance still reaches it
    sys = ut.examples.varga_5_4()
    model = varga().model
    I_minus_Gu = ct.ss(
        sys.A,
        np.hstack([np.zeros((3, 2)), -sys.B[:, :1]]),
        sys.C,
        np.hstack([np.eye(2), -sys.D[:, :1]]),
    )
    assert ut.decoupling_gap(I_minus_Gu, model) > 0.1
    # the right filter with a perturbed entry fails too
    good = varga().Q
    bad = ct.ss(good.A, good.B * (1 + 1e-6), good.C, good.D)
    assert ut.decoupling_gap(bad, model) > 1e3 * ut.decoupling_gap(good, model)


def test_the_filter_is_a_python_control_system():
    filt = varga()
    for sys in (filt.Q, filt.Rf):
        again = ct.ss(sys)
        assert isinstance(again, ct.StateSpace)
        np.testing.assert_array_equal(np.asarray(again.A), np.asarray(sys.A))
    assert filt.Q.input_labels == ["y[0]", "y[1]", "u[0]"]
    assert filt.Rf.input_labels == ["f1", "f2"]
    assert ct.tf(filt.Rf[0, 1]).poles().real.round(9).tolist() == [-3.0]


def test_varga_5_4_residual_does_not_depend_on_u_or_d():
    # the plant is unstable (poles 2 and 3): a short run, every signal through the one system
    filt = varga()
    t = np.linspace(0, 1, 201)
    runs = [
        filt.simulate(t, u=ut.signals.sinusoid(1.0, 3.0), d=ut.signals.step(2.0, 0.3)),
        filt.simulate(t, u=ut.signals.step(-1.0, 0.5), d=ut.signals.sinusoid(5.0, 7.0)),
        filt.simulate(t),
    ]
    size = size_of(*(r.states for r in runs), *(r.outputs for r in runs))
    gain = float(np.abs(np.exp(3.0 * t[-1])))  # the unstable modes grow rounding this much
    for r in runs:
        assert_rounding_close(r.residual, 0.0, size=size, terms=16, steps=t.size, gain=gain)
    assert np.abs(runs[0].outputs - runs[1].outputs).max() > 1.0  # u and d do act


# the chapter's plant (PA9) ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def pa9():
    return ut.examples.pa9()


@pytest.fixture(scope="module")
def pa9_filter(pa9):
    return ut.design_nullspace_filter(pa9, pa9_faults(pa9), poles=[-2, -3])


def test_pa9_degrees_structure_and_poles(pa9, pa9_filter):
    assert pa9_filter.degrees == (2,)
    assert pa9_filter.detected == (True, True, True, True, False)
    assert pa9_filter.undetected == ("along E",)
    tol = eigenvalue_roundoff(pa9_filter.Q.A)
    assert np.abs(np.sort(pa9_filter.poles().real) - [-3, -2]).max() <= tol
    assert np.abs(pa9_filter.poles().imag).max() <= tol


def test_pa9_residual_is_the_same_whatever_u_and_d(pa9, pa9_filter):
    x0 = [1.0, -1.0, 0.5]
    runs = [
        pa9_filter.simulate(T, u=U, d=ut.signals.sinusoid(1.0, 2.0), initial_state=x0),
        pa9_filter.simulate(T, u=U, d=ut.signals.step(3.0, 1.0), initial_state=x0),
        pa9_filter.simulate(T, d=ut.signals.sinusoid(10.0, 0.3), initial_state=x0),
        pa9_filter.simulate(T, initial_state=x0),
    ]
    size = size_of(*(r.states for r in runs))
    for r in runs[1:]:
        assert_rounding_close(
            r.residual, runs[0].residual, size=size, terms=25, steps=T.size, what="residual"
        )
    assert np.abs(runs[0].outputs - runs[1].outputs).max() > 1.0


def test_pa9_residual_is_rf_applied_to_the_fault(pa9, pa9_filter):
    fault = pa9_faults(pa9)[1]
    run = pa9_filter.simulate(T, u=U, d=ut.signals.sinusoid(1.0, 2.0), fault=fault)
    Rf = pa9_filter.Rf
    f = np.zeros((5, T.size))
    f[1] = fault.signal(T)
    expected = ut.simulation.linear_response(
        np.asarray(Rf.A), np.asarray(Rf.B), T, f, np.zeros(Rf.nstates),
        output=np.hstack([np.asarray(Rf.C), np.asarray(Rf.D)]),
    )  # fmt: skip
    size = size_of(run.states, run.outputs)
    assert_rounding_close(run.residual, expected, size=size, terms=25, steps=T.size)
    assert np.abs(run.residual[:, T > 6]).min() > 1e-3  # the fault shows


def test_undetected_fault_leaves_the_residual_unchanged(pa9, pa9_filter):
    along_e = pa9_faults(pa9)[4]
    base = pa9_filter.simulate(T, u=U, d=ut.signals.sinusoid(1.0, 2.0))
    hit = pa9_filter.simulate(T, u=U, d=ut.signals.sinusoid(1.0, 2.0), fault=along_e)
    size = size_of(base.states, hit.states)
    assert_rounding_close(hit.residual, base.residual, size=size, terms=25, steps=T.size)
    assert np.abs(hit.states - base.states).max() > 0.1


def test_noise_is_drawn_as_simulate_fault_draws_it(pa9, pa9_filter):
    uio = ut.design_uio(pa9, poles=[-1, -2, -3])
    fault = pa9_faults(pa9)[0]
    kw = dict(u=U, d=ut.signals.sinusoid(1.0, 2.0), noise=0.01, seed=7)
    ours = pa9_filter.simulate(T, fault=fault, **kw)
    theirs = ut.simulate_fault(pa9, uio, T, fault, **kw)
    np.testing.assert_array_equal(ours.noise, theirs.inputs.noise)
    assert_rounding_close(ours.outputs, theirs.outputs, size=size_of(ours.states), terms=9,
                          steps=T.size)  # fmt: skip


def test_isolating_member_is_blind_to_its_fault(pa9):
    # three sensors: a filter that treats fault i as a disturbance does not see it
    plant3 = ut.Plant(pa9.A, np.eye(3), B=pa9.B, E=pa9.E)
    faults = [ut.actuator_fault(plant3, i, STEP) for i in range(2)]
    faults += [ut.sensor_fault(plant3, j, STEP) for j in range(3)]
    for i, blind in enumerate(faults):
        member_plant = ut.Plant(
            plant3.A,
            plant3.C,
            B=plant3.B,
            E=np.column_stack([plant3.E, blind.state_direction]),
            D=blind.output_direction[:, None],
        )
        member = ut.design_nullspace_filter(member_plant, faults, poles=-3)
        assert member.detected[i] is False
        # sensor 3 and actuator 2 produce the same measurements up to a filter: blind to both
        same = {1: 4, 4: 1}.get(i)
        expected = [j != i and j != same for j in range(5)]
        assert list(member.detected) == expected
        assert_decoupled(member)


# existence, both ways, on random plants ---------------------------------------------------------


@pytest.mark.parametrize("seed", range(8))
def test_random_plants_exist_iff_disturbances_leave_an_output_direction(seed):
    rng = np.random.default_rng(seed)
    n, p = int(rng.integers(2, 6)), int(rng.integers(1, 4))
    q = int(rng.integers(1, 4))
    plant = ut.Plant(
        rng.standard_normal((n, n)) - 2 * np.eye(n),
        rng.standard_normal((p, n)),
        B=rng.standard_normal((n, 2)),
        E=rng.standard_normal((n, q)),
    )
    faults = (rng.standard_normal((n, 2)), None)
    if q >= p:  # a generic Gd then has normal rank p: nothing is left
        with pytest.raises(ut.NullspaceFilterError, match="normal rank of Gd"):
            ut.design_nullspace_filter(plant, faults, poles=-1)
        return
    filt = ut.design_nullspace_filter(plant, faults, poles=-1.5)
    assert filt.Q.noutputs == p - q
    assert filt.order == sum(filt.degrees) <= n * (p - q)
    assert_decoupled(filt)


@pytest.mark.parametrize("factor", [1e-6, 1.0, 1e6])
def test_time_unit_does_not_change_the_verdict(pa9, factor):
    # time measured in another unit: A, B, E scale by the factor, so do the poles
    plant = ut.Plant(pa9.A * factor, pa9.C, B=pa9.B * factor, E=pa9.E * factor)
    filt = ut.design_nullspace_filter(plant, pa9_faults(plant), poles=[-2 * factor, -3 * factor])
    assert filt.degrees == (2,)
    assert filt.detected == (True, True, True, True, False)
    assert_decoupled(filt)
    expected = np.array([-3.0, -2.0]) * factor
    assert np.abs(np.sort(filt.poles().real) - expected).max() <= eigenvalue_roundoff(filt.Q.A)


def test_discrete_time(pa9):
    A = np.eye(3) + 0.1 * pa9.A
    plant = ut.Plant(A, pa9.C, B=0.1 * pa9.B, E=0.1 * pa9.E, dt=0.1)
    filt = ut.design_nullspace_filter(plant, (0.1 * pa9.B, None), poles=[0.5, 0.4])
    assert filt.Q.dt == 0.1
    assert np.abs(np.sort(filt.poles().real) - [0.4, 0.5]).max() <= eigenvalue_roundoff(filt.Q.A)
    assert_decoupled(filt)
    t = np.arange(101) * 0.1
    d = np.random.default_rng(0).standard_normal((1, t.size))
    a = filt.simulate(t, u=U, d=d, initial_state=[1, 0, 0])
    b = filt.simulate(t, u=U, initial_state=[1, 0, 0])
    assert_rounding_close(a.residual, b.residual, size=size_of(a.states, b.states), terms=25,
                          steps=t.size)  # fmt: skip
    # in discrete time the filter run on the samples is the same filter: the same residual
    again = filt.residual(t, a.outputs, a.u)
    assert_rounding_close(again, a.residual, size=size_of(a.states), terms=25, steps=t.size)


# bad input: clear messages -----------------------------------------------------------------------


def test_no_filter_when_disturbances_fill_the_outputs(pa9):
    one_sensor = ut.Plant(pa9.A, pa9.C[:1], B=pa9.B, E=pa9.E)
    with pytest.raises(ut.NullspaceFilterError, match="normal rank of Gd.*is 1 = p"):
        ut.design_nullspace_filter(one_sensor, (pa9.B, None), poles=-1)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(poles=[-1, -2, -3]), "order 2.*needs 2 poles"),
        (dict(poles=[1.0, -2]), "must be stable"),
        (dict(poles=[-1 + 1j, -2]), "no conjugate partner"),
        (dict(poles=[np.nan, -1]), "finite"),
    ],
)
def test_bad_poles_are_refused(pa9, kwargs, match):
    with pytest.raises(ValueError, match=match):
        ut.design_nullspace_filter(pa9, (pa9.B, None), **kwargs)


def test_a_conjugate_pair_is_not_split_between_rows(pa9):
    plant3 = ut.Plant(pa9.A, np.eye(3), B=pa9.B, E=pa9.E)  # two rows of degree 1
    with pytest.raises(ut.NullspaceFilterError, match="split a conjugate pair"):
        ut.design_nullspace_filter(plant3, (pa9.B, None), poles=[-1 + 1j, -1 - 1j])


def test_bad_faults_and_indices_are_refused(pa9):
    other = ut.Plant(np.eye(2), np.eye(2), B=np.eye(2))
    cases = [
        (lambda: ut.design_nullspace_filter(pa9, [ut.actuator_fault(other, 0, STEP)], poles=-1),
         "built for a plant with n = 2"),
        (lambda: ut.design_nullspace_filter(pa9, (np.ones((2, 1)), None), poles=-1),
         "R1 .state fault matrix. has shape"),
        (lambda: ut.design_nullspace_filter(pa9, "sensor", poles=-1), "list of Fault objects"),
        (lambda: ut.design_nullspace_filter(pa9, (None, None), poles=-1), "state or the output"),
        (lambda: ut.design_nullspace_filter(ut.examples.varga_5_4(), [7], poles=-1),
         "out of range"),
        (lambda: ut.design_nullspace_filter(ut.examples.varga_5_4(), [2], known=[2], poles=-1),
         "listed twice"),
        (lambda: ut.design_nullspace_filter(pa9, (pa9.B, None), known=[0], poles=-1),
         "python-control system"),
        (lambda: ut.design_nullspace_filter("plant", [0], poles=-1), "got str"),
    ]  # fmt: skip
    for call, match in cases:
        with pytest.raises(ValueError, match=match):
            call()


def test_filter_is_read_only_and_scaling_checks_its_factors():
    filt = varga()
    with pytest.raises(AttributeError, match="read-only"):
        filt.Q = None
    with pytest.raises(ut.NullspaceFilterError, match="non-zero"):
        filt.scaled(0.0)


def test_a_conjugate_pair_is_placed(pa9):
    filt = ut.design_nullspace_filter(pa9, (pa9.B, None), poles=[-1 + 2j, -1 - 2j])
    got = np.sort_complex(filt.poles())
    assert np.abs(got - np.array([-1 - 2j, -1 + 2j])).max() <= eigenvalue_roundoff(filt.Q.A)
    assert_decoupled(filt)


def test_redundant_sensors_give_a_static_filter():
    # three sensors of one state (the triplex redundancy of Varga's examples): constant rows
    plant = ut.Plant([[-1.0]], [[1.0], [1.0], [1.0]], B=[[1.0]], E=[[1.0]])
    step = ut.signals.step(1.0, 1.0)
    faults = [ut.sensor_fault(plant, j, step) for j in range(3)]
    filt = ut.design_nullspace_filter(plant, faults, poles=-1)
    assert filt.degrees == (0, 0) and filt.order == 0 and filt.poles().size == 0
    assert filt.detected == (True, True, True)
    assert_decoupled(filt)
    t = np.linspace(0, 3, 301)
    run = filt.simulate(t, u=ut.signals.sinusoid(1.0, 2.0),
                        d=ut.signals.step(2.0, 0.5), fault=faults[1])  # fmt: skip
    before = run.residual[:, t < 1.0]
    assert_rounding_close(before, 0.0, size=size_of(run.outputs), terms=3)
    # after the fault: the fault's column of Rf, a constant gain
    assert_rounding_close(run.residual[:, -1], filt.Rf.D[:, 1], size=1.0, terms=3)
