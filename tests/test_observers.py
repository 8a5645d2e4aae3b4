"""Observer designs: argument checks, pole counts, warnings, LMI options, python-control views."""

import warnings

import control as ct
import numpy as np
import pytest
from tolerance import assert_rounding_close, assert_zero, eigenvalue_roundoff, size_of

import uio_teach as ut
from uio_teach.verify import PlacementAccuracyError


def test_pole_count_error_says_what_can_be_placed():
    plant = ut.examples.dt_case_study()
    with pytest.raises(
        ValueError, match=r"1 pole\(s\) can be placed, got 2.*\{0.5, 0.5\} are fixed"
    ):
        ut.design_pmo(plant, poles=[0.1, 0.2])
    with pytest.raises(ValueError, match=r"2 pole\(s\) can be placed, got 4.*fixed \(invariant"):
        ut.design_uio(ut.examples.missile_autopilot(), poles=[-1, -2, -3, -4])


def test_all_poles_including_fixed_ones_are_accepted():
    plant = ut.examples.dt_case_study()
    a = ut.design_pmo(plant, poles=[0.2])
    b = ut.design_pmo(plant, poles=[0.5, 0.2, 0.5])  # the full list with the fixed modes
    np.testing.assert_allclose(a.L, b.L)


def test_moving_the_one_movable_pole_of_the_case_study():
    plant = ut.examples.dt_case_study()
    pmo = ut.design_pmo(plant, poles=[-0.3])
    np.testing.assert_allclose(pmo.poles().real, [-0.3, 0.5, 0.5], atol=1e-7)
    # L and M are projected onto D's left null space: zero to the rounding of 3-term products
    gain = np.linalg.cond(plant.D)
    assert_zero(pmo.L @ plant.D, pmo.L, plant.D, terms=3, gain=gain)
    assert_zero(pmo.M @ plant.D, pmo.M, plant.D, terms=3, gain=gain)


def test_complex_poles_need_conjugates():
    with pytest.raises(ValueError, match="no conjugate partner"):
        ut.design_uio(ut.examples.pa9(), poles=[-1 + 1j, -1 + 1j, -3])
    obs = ut.design_uio(ut.examples.pa9(), poles=[-1 + 1j, -1 - 1j, -3])
    np.testing.assert_allclose(
        np.sort_complex(obs.poles()), [-3, -1 - 1j, -1 + 1j], atol=eigenvalue_roundoff(obs.F)
    )
    assert np.isrealobj(obs.K1)


def test_repeated_poles_beyond_output_count():
    # three poles at -2 from two outputs: a cyclic design on a combination of the outputs
    obs = ut.design_uio(ut.examples.pa9(), poles=[-2, -2, -2])
    w = obs.poles()
    assert abs(np.sum(w) + 6) < 1e-8  # the trace is well conditioned
    np.testing.assert_allclose(w, -2, atol=1e-4)  # a triple eigenvalue: eps ** (1/3)
    # a multiplicity the two outputs can produce is fine
    obs = ut.design_uio(ut.examples.pa9(), poles=[-2, -2, -3])
    np.testing.assert_allclose(np.sort(obs.poles().real), [-3, -2, -2], atol=1e-6)


def test_single_output_repeated_poles_use_ackermann():
    plant = ut.Plant([[0, 1], [-2, -3]], [[1, 0]])
    obs = ut.design_luenberger(plant, poles=[-4, -4])
    np.testing.assert_allclose(obs.poles().real, [-4, -4], atol=1e-6)


def test_argument_combinations():
    plant = ut.examples.pa9()
    with pytest.raises(ValueError, match="exactly one of poles= .* or K1="):
        ut.design_uio(plant)
    with pytest.raises(ValueError, match="exactly one of poles= .* or K1="):
        ut.design_uio(plant, poles=[-1, -2, -3], K1=np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"K1 has shape \(2, 3\), expected \(3, 2\)"):
        ut.design_uio(plant, K1=np.zeros((2, 3)))
    with pytest.raises(ValueError, match="method must be"):
        ut.design_pmo(plant, poles=[-1, -2, -3], method="magic")
    with pytest.raises(ValueError, match="method='lmi' computes L itself"):
        ut.design_pmo(plant, poles=[-1, -2, -3], method="lmi")
    with pytest.raises(ValueError, match="decay= is the LMI's bound"):
        ut.design_pmo(plant, poles=[-1, -2, -3], decay=0.5)
    with pytest.raises(ValueError, match="plant must be a uio_teach.Plant"):
        ut.design_uio(np.eye(3), poles=[-1, -2, -3])


def test_gain_must_respect_the_measurement_disturbance():
    plant = ut.examples.dt_case_study()
    with pytest.raises(ValueError, match="L D must be 0"):
        ut.design_pmo(plant, L=np.ones((3, 2)))


def test_unstable_design_warns_but_is_built():
    plant = ut.examples.pa9()
    with pytest.warns(ut.UnstableObserverWarning, match=r"pole\(s\) 1 outside the open left"):
        obs = ut.design_uio(plant, poles=[1, -2, -3])
    assert not obs.is_stable
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert ut.design_uio(plant, poles=[-1, -2, -3]).is_stable


def test_lmi_infeasible_bound():
    # the fixed modes at 0.5 cannot be pushed inside radius 0.4
    with pytest.raises(ut.LMIInfeasibleError, match="infeasible.*radius 0.4 with L D = 0") as info:
        ut.design_pmo(ut.examples.dt_case_study(), method="lmi", decay=0.4)
    assert "infeasible" in info.value.status
    assert isinstance(info.value, ValueError)


def test_lmi_decay_bound_is_met():
    pmo = ut.design_pmo(ut.examples.dt_case_study(), method="lmi", decay=0.6)
    assert np.max(np.abs(pmo.poles())) <= 0.6 + 1e-6
    obs = ut.design_pmo(ut.examples.pa9(), method="lmi", decay=2.0)
    assert np.max(obs.poles().real) <= -2.0 + 1e-6


def test_lmi_continuous_unstable_system():
    A1 = np.array([[1.0, 1.0], [0.0, 2.0]])
    C = np.array([[1.0, 0.0]])
    L, P = ut.lmi_gain(A1, C)
    assert np.all(np.linalg.eigvals(A1 - L @ C).real < 0)
    # the Lyapunov certificate really certifies it
    Q = (A1 - L @ C).T @ P + P @ (A1 - L @ C)
    assert np.max(np.linalg.eigvalsh(Q)) < 0


def test_lmi_infeasible_when_unobservable_unstable():
    A1 = np.diag([1.0, -1.0])
    with pytest.raises(ut.LMIInfeasibleError):
        ut.lmi_gain(A1, [[0.0, 1.0]])


def test_lmi_argument_checks():
    with pytest.raises(ValueError, match="decay must satisfy 0 < decay <= 1"):
        ut.lmi_gain(np.eye(2), np.eye(2), dt=True, decay=1.5)
    with pytest.raises(ValueError, match=r"C has shape \(1, 3\), expected \(\?, 2\)"):
        ut.lmi_gain(np.eye(2), np.ones((1, 3)))


@pytest.mark.parametrize(
    "design",
    [
        lambda: ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3]),
        lambda: ut.design_pmo(ut.examples.dt_case_study(), method="lmi"),
        lambda: ut.design_pmo(ut.examples.missile_autopilot(), poles=[-100, -150]),
        lambda: ut.design_ginverse(ut.examples.missile_autopilot()),
        lambda: ut.design_luenberger(ut.examples.pa9(), poles=[-1, -2, -3]),
    ],
)
def test_as_statespace_reproduces_the_realization(design):
    obs = design()
    sys = obs.as_statespace()
    pl = obs.plant
    assert sys.ninputs == pl.m + pl.p and sys.noutputs == pl.n
    assert (sys.dt not in (0, None)) == pl.is_discrete
    real = obs.realization()
    np.testing.assert_array_equal(sys.A, real.A)
    np.testing.assert_array_equal(sys.C, real.C)
    assert "xhat[0]" in sys.output_labels
    assert "poles" in repr(obs)
    assert "<table" in obs._repr_html_()


def test_uio_and_pmo_are_the_same_observer():
    """With H = M and K1 = L, the decoupling observer of PA9 is the PMO of eq. (13)."""
    plant = ut.examples.pa9()
    uio = ut.design_uio(plant, poles=[-1, -2, -3])
    pmo = ut.design_pmo(plant, L=uio.K1)
    np.testing.assert_allclose(uio.H, pmo.M)
    np.testing.assert_allclose(uio.F, pmo.F)
    # K = K1 + K2 and G = A1 M + L - L C M: the same matrix summed in another order
    size = size_of(plant.A) * size_of(uio.H) + size_of(uio.K1) * (1 + size_of(plant.C @ uio.H))
    assert_rounding_close(uio.K, pmo.G, size=size, terms=plant.n**2)


def test_closed_loop_with_python_control():
    """At any plant equilibrium the UIO's DC gain from [u; y] returns the state, whatever d is."""
    plant = ut.examples.pa9()
    sys = ut.design_uio(plant, poles=[-1, -2, -3]).as_statespace()
    u0 = np.ones(plant.m)
    for d0 in (np.zeros(plant.q), np.full(plant.q, 3.0)):
        x_eq = -np.linalg.solve(plant.A, plant.B @ u0 + plant.E @ d0)
        xhat = ct.dcgain(sys) @ np.concatenate([u0, plant.C @ x_eq])
        # two solves, with A and with the observer's matrix: their conditions are the gain
        gain = np.linalg.cond(plant.A) * np.linalg.cond(sys.A)
        assert_rounding_close(xhat, x_eq, size=size_of(x_eq, xhat), terms=plant.n**2, gain=gain)


def test_ginverse_refuses_measurement_disturbance_and_redundant_outputs():
    with pytest.raises(ValueError, match="does not handle measurement disturbances"):
        ut.design_ginverse(ut.examples.dt_case_study())
    plant = ut.Plant(np.diag([-1.0, -2.0, -3.0]), [[1, 0, 0], [2, 0, 0]], E=[1, 0, 0])
    with pytest.raises(ValueError, match="C has rank 1 < p = 2"):
        ut.design_ginverse(plant)


def test_luenberger_does_not_decouple():
    assert not ut.design_luenberger(ut.examples.pa9(), poles=[-1, -2, -3]).decouples
    assert ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3]).decouples


def test_printed_rounded_gain_is_projected_with_a_warning():
    plant = ut.examples.dt_case_study()
    printed_L = ut.examples.DT_CASE_STUDY_PUBLISHED.L
    with pytest.warns(UserWarning, match="not exactly 0 .*nearest gain with L D = 0"):
        pmo = ut.design_pmo(plant, L=printed_L)
    assert_zero(pmo.L @ plant.D, pmo.L, plant.D, terms=3, gain=np.linalg.cond(plant.D))
    np.testing.assert_allclose(pmo.L, printed_L, atol=1e-4)
    np.testing.assert_allclose(pmo.poles().real, [0, 0.5, 0.5], atol=1e-4)


def test_conjugate_pairs_sort_consistently():
    plant = ut.examples.missile_autopilot()
    report = ut.check_existence(plant)
    # zeros of the pencil and eigenvalues of (I - E (CE)^-1 C) A: both to the backward error of
    # an eigenvalue problem with A's size, times the fixed modes' conditioning
    A, C, E = plant.A, plant.C, plant.E
    A1 = (np.eye(4) - E @ np.linalg.solve(C @ E, C)) @ A
    atol = eigenvalue_roundoff(A1) * np.linalg.cond(C @ E)
    np.testing.assert_allclose(report.invariant_zeros, report.fixed_modes, rtol=0, atol=atol)
    assert report.invariant_zeros[0].imag < 0


# --- the textbook matrices are read-only and consistent -------------------------------------


def _families():
    pa9, missile, case = (
        ut.examples.pa9(),
        ut.examples.missile_autopilot(),
        ut.examples.dt_case_study(),
    )
    return [
        (ut.design_uio(pa9, poles=[-1, -2, -3]), ("H", "T", "K1", "K2", "K", "F")),
        (ut.design_pmo(case, method="lmi"), ("M", "A1", "L", "F", "G", "Mv", "lmi_certificate")),
        (ut.design_ginverse(missile), ("Cg", "Kg", "Av", "Cv", "Kv", "G", "projection")),
        (ut.design_luenberger(pa9, poles=[-1, -2, -3]), ("L", "F")),
    ]


@pytest.mark.parametrize("index", range(4))
def test_observer_matrices_are_read_only_properties(index):
    obs, names = _families()[index]
    for name in (*names, "plant"):
        assert isinstance(getattr(type(obs), name, None), property), name
        with pytest.raises(AttributeError, match=rf"{name} is read-only.*design a new observer"):
            setattr(obs, name, np.zeros((1, 1)))
    for name in names:
        value = getattr(obs, name)
        if isinstance(value, np.ndarray) and value.size:
            with pytest.raises(ValueError, match="read-only"):
                value[(0,) * value.ndim] = 1.0


def test_derived_matrices_stay_consistent():
    obs = ut.design_luenberger(ut.examples.pa9(), poles=[-1, -2, -3])
    np.testing.assert_allclose(obs.F, obs.plant.A - obs.L @ obs.plant.C)
    with pytest.raises(AttributeError):
        obs.L = np.zeros_like(obs.L)
    np.testing.assert_allclose(obs.F, obs.plant.A - obs.L @ obs.plant.C)


def test_gains_are_keyword_only():
    with pytest.raises(TypeError):
        ut.design_ginverse(ut.examples.missile_autopilot(), np.zeros((4, 2)))
    with pytest.raises(TypeError):
        ut.design_uio(ut.examples.pa9(), None, np.zeros((3, 2)))
    with pytest.raises(TypeError):
        ut.design_luenberger(ut.examples.pa9(), None, np.zeros((3, 2)))
    with pytest.raises(TypeError):
        ut.lmi_gain([[0.5]], [[1.0]], None, True)


@pytest.mark.parametrize("name", ["K1", "L"])
def test_complex_gain_is_refused_not_truncated(name):
    gain = np.zeros((3, 2)) + 1e-3j
    design = ut.design_uio if name == "K1" else ut.design_pmo
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # not numpy's ComplexWarning: our error
        with pytest.raises(ValueError, match=rf"^{name} must .*complex"):
            design(ut.examples.pa9(), **{name: gain})


def test_complex_numpy_arrays_are_refused_like_complex_lists():
    A = np.array([[0.0, 1.0], [-2.0, -3.0]], dtype=complex)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for value in (A, A.tolist()):
            with pytest.raises(ValueError, match="^A must be a real numeric matrix, got complex"):
                ut.Plant(value, [[1.0, 0.0]])
        with pytest.raises(ValueError, match="^Mv must"):
            ut.design_pmo(ut.examples.missile_autopilot(), [-80, -120], Mv=np.ones((4, 2)) * 1j)
        with pytest.raises(ValueError, match="^Kv must"):
            ut.design_ginverse(ut.examples.missile_autopilot(), Kv=np.ones((4, 2)) * 1j)
        with pytest.raises(ValueError, match="^A1 must"):
            ut.lmi_gain(np.array([[0.5 + 0j]]), [[1.0]], dt=True)


def test_designs_report_requested_versus_obtained_when_placement_is_inaccurate():
    rng = np.random.default_rng(7)
    A = rng.standard_normal((14, 14))
    C = rng.standard_normal((1, 14))
    with pytest.raises(
        PlacementAccuracyError, match=r"the Luenberger observer: .*requested .*obtained"
    ):
        ut.design_luenberger(ut.Plant(A, C), poles=-1 - 0.05 * np.arange(14))
