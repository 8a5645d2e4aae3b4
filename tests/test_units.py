"""The same plant in other units gets the same verdict and a right observer, or a clear refusal.

Every rank, zero and observability decision is made on the balanced plant
(uio_teach.balancing), so diagonal changes of state, output and input units and
well-conditioned similarities change no verdict; every design is verified on the data as
given before it is returned. The named cases below are the ones that once went wrong; the
property tests draw plants whose invariant zeros are known by construction.
"""

import warnings

import numpy as np
import pytest
from tolerance import (
    assert_rounding_close,
    assert_same_run,
    eigenvector_condition,
    roundoff,
    size_of,
)

import uio_teach as ut
from uio_teach.balancing import balanced_plant, plant_scaling
from uio_teach.lmi import LMIUndecidedError
from uio_teach.verify import PlacementAccuracyError, check_fixed_modes

# helpers -------------------------------------------------------------------------------------


def in_units(plant, s=None, o=None, w=None, name=None):
    """The plant with states x = diag(s) x_new, outputs y_new = diag(o) y, d = diag(w) d_new."""
    n, p, q = plant.n, plant.p, plant.q
    s = np.ones(n) if s is None else np.asarray(s, float)
    o = np.ones(p) if o is None else np.asarray(o, float)
    w = np.ones(q) if w is None else np.asarray(w, float)
    return ut.Plant(
        plant.A * s[None, :] / s[:, None],
        o[:, None] * plant.C * s[None, :],
        B=plant.B / s[:, None],
        E=plant.E / s[:, None] * w[None, :],
        D=o[:, None] * plant.D,
        dt=plant.dt,
        name=name,
    )


def verdict(report):
    return tuple(c.holds for c in report.conditions), report.movable


def same_values(a, b, rtol=1e-5):
    a, b = np.sort_complex(np.asarray(a, complex)), np.sort_complex(np.asarray(b, complex))
    if a.size != b.size:
        return False
    if not a.size:
        return True
    cost = np.abs(a[:, None] - b[None, :])
    return bool(np.all(cost.min(axis=1) <= rtol * np.maximum(1.0, np.abs(a))))


def d_leak(obs, s):
    """How much d reaches the error, in the units of the well-scaled plant (relative)."""
    # UIO/PMO: e' = F e + T E d; back in the base units (x_base = diag(s) x)
    pl = obs.plant
    TE = (np.eye(pl.n) - obs.M @ pl.C) @ pl.E if isinstance(obs, ut.PMO) else obs.T @ pl.E
    TE_base = s[:, None] * TE
    E_base = s[:, None] * pl.E
    return float(np.linalg.norm(TE_base) / max(np.linalg.norm(E_base), 1e-300))


# the named cases -------------------------------------------------------------------------------

MISSILE_UNITS = np.logspace(-4, 4, 4)


def test_missile_in_other_state_units_keeps_its_fixed_zeros():
    pl = ut.examples.missile_autopilot()
    other = in_units(pl, s=MISSILE_UNITS)
    a, b = ut.check_existence(pl), ut.check_existence(other)
    assert verdict(a) == verdict(b) and b.movable == 2
    assert same_values(b.fixed_modes, b.invariant_zeros)
    assert same_values(b.invariant_zeros, [-105.6 - 142.1j, -105.6 + 142.1j], rtol=1e-3)
    # four poles cannot be placed: the message names the two fixed zeros
    with pytest.raises(ValueError, match=r"2 pole\(s\) can be placed, got 4"):
        ut.design_uio(other, poles=[-100, -120, -140, -160])
    obs = ut.design_uio(other, poles=[-100, -120])
    assert same_values(obs.poles(), [-100, -120, *b.invariant_zeros], rtol=1e-6)
    # T E = 0 to the rounding of n-term products with the gains solved from C E
    pl = obs.plant
    assert d_leak(obs, MISSILE_UNITS) <= roundoff(1.0, terms=pl.n, gain=np.linalg.cond(pl.C @ pl.E))


def test_missile_error_does_not_depend_on_d_in_other_units():
    pl = in_units(ut.examples.missile_autopilot(), s=MISSILE_UNITS)
    obs = ut.design_uio(pl, poles=[-100, -120])
    t = np.linspace(0, 0.2, 2001)
    quiet = ut.simulate(pl, obs, t, initial_state=np.ones(4))
    loud = ut.simulate(pl, obs, t, initial_state=np.ones(4), d=[np.sin, np.cos])
    units = MISSILE_UNITS[:, None]
    # in the plant's own units, equal to the rounding of the run: the condition of the units
    # scaling is the gain rounding can meet on the way
    assert_rounding_close(
        quiet.error * units,
        loud.error * units,
        size=size_of(loud.states * units, loud.estimates * units),
        terms=16,
        steps=t.size,
        gain=eigenvector_condition(obs.error_matrix) * MISSILE_UNITS.max() / MISSILE_UNITS.min(),
    )


def test_a_pole_requested_on_an_invariant_zero_is_refused():
    pl = ut.examples.missile_autopilot()
    z = ut.check_existence(pl).invariant_zeros
    with pytest.raises(ValueError, match="requested on the fixed mode"):
        ut.design_uio(pl, poles=list(z))


def test_tiny_product_in_badly_scaled_units_passes_the_rank_condition():
    A = np.array([[-1.0, 1, 0], [0, -2, 1], [1, 0, -3]])
    S = np.array([1e6, 1, 1e-6])
    plant = ut.Plant(A * S / S[:, None], [[1e6, 0, 0]], E=[[1e-10], [0], [1e6]])
    unscaled = ut.Plant(A, [[1.0, 0, 0]], E=[[1e-4], [0], [1.0]])
    a, b = ut.check_existence(unscaled), ut.check_existence(plant)
    assert a.ok and b.ok and verdict(a) == verdict(b)
    assert "rank(CE) = 1" in b["rank condition"].reason
    assert not b["rank condition"].marginal
    assert same_values(a.invariant_zeros, b.invariant_zeros)


def test_output_units_invent_no_zero():
    pl = ut.examples.pa9()
    other = in_units(pl, o=[1e-6, 1e6])
    a, b = ut.check_existence(pl), ut.check_existence(other)
    assert verdict(a) == verdict(b) and b.ok and b.invariant_zeros.size == 0


@pytest.mark.parametrize("factor", [1e155, 1e200])
def test_overflow_range_data_is_scaled_first(factor):
    pa9 = ut.examples.pa9()
    big_ce = ut.Plant(pa9.A, pa9.C * factor, E=pa9.E * factor)
    big_a = ut.Plant(pa9.A * factor, pa9.C, E=pa9.E)
    base = verdict(ut.check_existence(pa9))
    for plant in (big_ce, big_a):
        report = ut.check_existence(plant)  # no numpy.linalg.LinAlgError
        assert verdict(report) == base
        assert "rank(CE) = 1" in report["rank condition"].reason


def test_rank_deficient_verdicts_agree_with_the_zero_list():
    # the movable count and the fixed modes always agree with the invariant zeros
    rng = np.random.default_rng(3)
    for _ in range(20):
        pl, zeros, _ = known_zero_plant(rng, discrete=False)
        report = ut.check_existence(pl)
        if report["rank condition"].holds:
            assert report.movable + len(report.fixed_modes) == pl.n
            assert same_values(report.fixed_modes, report.invariant_zeros, rtol=1e-4)


def test_deadbeat_uio_of_any_multiplicity():
    rng = np.random.default_rng(1)
    A = 0.5 * rng.standard_normal((5, 5))
    plant = ut.Plant(A, rng.standard_normal((2, 5)), E=rng.standard_normal((5, 1)), dt=True)
    report = ut.check_existence(plant)
    assert report.movable == 5
    obs = ut.design_uio(plant, poles=[0] * 5)
    F = obs.F
    # F = F0 + dF with F0^5 = 0, dF the rounding of T A - K1 C (5 terms): ||F^5|| is at most
    # 5 ||F||^4 ||dF||, and the trace (the poles' sum, 0) is within 5 ||dF||
    size = np.linalg.norm(obs.T @ plant.A) + np.linalg.norm(obs.K1) * np.linalg.norm(plant.C)
    power = np.linalg.norm(np.linalg.matrix_power(F, 5))
    assert power <= roundoff(max(1.0, np.linalg.norm(F)) ** 4 * size, terms=5, steps=5)
    assert abs(np.trace(F)) <= roundoff(size, terms=5, steps=5)
    assert d_leak(obs, np.ones(5)) <= roundoff(1.0, terms=5, gain=np.linalg.cond(plant.C @ plant.E))


def test_repeated_complex_pair_beyond_the_output_count():
    rng = np.random.default_rng(1)
    for _ in range(2):
        rng.standard_normal((5, 5))
    plant = ut.Plant(
        rng.standard_normal((5, 5)), rng.standard_normal((2, 5)), E=rng.standard_normal((5, 1))
    )
    assert ut.check_existence(plant).movable == 5
    want = [-1 + 1j, -1 - 1j, -1 + 1j, -1 - 1j, -3]
    obs = ut.design_uio(plant, poles=want)
    w = obs.poles()
    assert abs(np.sum(w) - np.sum(want)) < 1e-7
    assert same_values(w, want, rtol=1e-4)


def test_near_conjugate_pair_is_treated_the_same_by_validator_and_design():
    obs = ut.design_uio(ut.examples.pa9(), poles=[-1 + 2j, -1 - 2j + 1e-12j, -3])
    assert same_values(obs.poles(), [-1 + 2j, -1 - 2j, -3], rtol=1e-8)
    assert np.isrealobj(obs.K1)


def test_an_error_matrix_without_the_fixed_modes_is_refused():
    with pytest.raises(PlacementAccuracyError, match="not error poles"):
        check_fixed_modes([-100, -120, -140, -160], [-105.6 + 142.1j, -105.6 - 142.1j])
    check_fixed_modes([-1, -105.6 + 142.1j, -105.6 - 142.1j], [-105.6 + 142.1j, -105.6 - 142.1j])


def test_lmi_on_a_similarity_of_condition_1e5():
    pl = ut.examples.dt_case_study()
    rng = np.random.default_rng(0)
    U, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    V, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    S = U @ np.diag([1.0, 10**2.5, 1e5]) @ V
    Si = np.linalg.inv(S)
    other = ut.Plant(Si @ pl.A @ S, pl.C @ S, E=Si @ pl.E, D=pl.D, dt=pl.dt)
    assert verdict(ut.check_existence(other)) == verdict(ut.check_existence(pl))
    pmo = ut.design_pmo(other, method="lmi")
    assert np.max(np.abs(pmo.poles())) < 1
    assert same_values(ut.check_existence(other).fixed_modes, [0.5, 0.5], rtol=1e-6)


def test_an_inaccurate_solver_status_is_not_a_proof(monkeypatch):
    import cvxpy as cp

    def inaccurate(self, *args, **kwargs):
        self._status = "infeasible_inaccurate"  # what Clarabel said on a feasible problem
        return None

    monkeypatch.setattr(cp.Problem, "solve", inaccurate)
    monkeypatch.setattr(cp.Problem, "status", property(lambda self: self._status))
    # feasible: the placed gain cross-checks and is returned with its certificate
    res = ut.lmi_gain([[1.2, 0.0], [0.0, 0.5]], [[1.0, 0.0]], dt=True)
    F = np.array([[1.2, 0.0], [0.0, 0.5]]) - res.L @ np.array([[1.0, 0.0]])
    assert np.max(np.abs(np.linalg.eigvals(F))) < 1
    assert np.all(np.linalg.eigvalsh(F.T @ res.P @ F - res.P) < 0)
    # nothing decides (no placed gain either): "could not decide", never "infeasible"
    monkeypatch.setattr(ut.lmi, "placed_solution", lambda *args, **kwargs: None)
    with pytest.raises(LMIUndecidedError, match="could not decide"):
        ut.lmi_gain([[1.2, 0.0], [0.0, 0.5]], [[1.0, 0.0]], dt=True)


def test_lmi_infeasibility_is_still_proven_when_it_is_true():
    with pytest.raises(ut.LMIInfeasibleError):
        ut.lmi_gain([[1.2, 0.0], [0.0, 0.5]], [[0.0, 1.0]], dt=True)  # 1.2 unobservable


def test_design_of_size_40_with_6_outputs():
    rng = np.random.default_rng(1)
    n, p = 40, 6
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    plant = ut.Plant(A, rng.standard_normal((p, n)), E=rng.standard_normal((n, 2)))
    dec = ut.existence.decoupling(plant)
    lam = np.linalg.eigvals(dec.A1)
    poles = -np.abs(lam.real) - 0.5 + 1j * lam.imag
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ut.PlacementAccuracyWarning)
        obs = ut.design_uio(plant, poles=poles)
    assert same_values(obs.poles(), poles, rtol=1e-3)
    # T E = 0 to the rounding of n-term products with gains solved from C E
    assert d_leak(obs, np.ones(n)) <= roundoff(1.0, terms=n, gain=np.linalg.cond(plant.C @ plant.E))


def test_residual_with_a_measurement_disturbance_is_Ce_plus_Dv():
    plant = ut.examples.dt_case_study()
    pmo = ut.design_pmo(plant, method="lmi")
    k = np.arange(40)
    resp = ut.simulate(plant, pmo, k, d=np.ones(40), v=np.sin(k), initial_state=[1, 1, 1])
    expected = plant.C @ resp.error + plant.D @ resp.inputs.v
    assert_same_run(resp.residual, expected, resp)
    assert np.abs(resp.residual).max() > 0.5  # Dv is not small: C e alone would be wrong


# property tests: random units and similarities on plants with known zeros ---------------------


def known_zero_plant(rng, discrete):
    """A plant whose invariant zeros are known: C E = I on x1 and zeros eig(Z) on x2.

    In canonical coordinates x = [x1 (q); z (k); w (rest)]: C = [[I, 0, 0], [0, 0, c]],
    E = [I; 0; 0], A22 = [[Z, X], [0, W]] so the z-part is unobservable once x1 is
    decoupled: the invariant zeros are eig(Z). An orthogonal similarity hides the structure.
    """
    q = int(rng.integers(1, 3))
    k = int(rng.integers(0, 3))
    r = int(rng.integers(1, 3))
    n = q + k + r
    if discrete:
        zeros = rng.uniform(-0.9, 0.9, k)
        if k and rng.random() < 0.2:
            zeros[0] = 1.3  # an unstable zero: no UIO
    else:
        zeros = -rng.uniform(0.2, 3.0, k)
        if k and rng.random() < 0.2:
            zeros[0] = 0.7
    A = rng.standard_normal((n, n))
    A[q : q + k, q : q + k] = np.diag(zeros) + np.triu(rng.standard_normal((k, k)), 1)
    A[q + k :, q : q + k] = 0.0  # W does not see z
    if discrete:
        A = A / max(1.0, np.max(np.abs(np.linalg.eigvals(A))) * 1.2)
        A[q : q + k, q : q + k] = np.diag(zeros) + np.triu(0.3 * rng.standard_normal((k, k)), 1)
    C = np.zeros((q + 1, n))
    C[:q, :q] = np.eye(q)
    C[q, q + k :] = rng.standard_normal(r)
    E = np.zeros((n, q))
    E[:q, :q] = np.eye(q)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    plant = ut.Plant(Q.T @ A @ Q, C @ Q, E=Q.T @ E, dt=True if discrete else None)
    return plant, np.sort_complex(zeros.astype(complex)), n


def random_units(rng, plant):
    s = 10.0 ** rng.uniform(-6, 6, plant.n)
    o = 10.0 ** rng.uniform(-6, 6, plant.p)
    w = 10.0 ** rng.uniform(-3, 3, plant.q)
    return s, in_units(plant, s=s, o=o, w=w)


def _stable_poles(rng, k, discrete):
    return rng.uniform(-0.6, 0.6, k) if discrete else -rng.uniform(1.0, 4.0, k)


COUNTS = {"tried": 0, "right": 0, "refused": 0, "wrong": 0}


def _near_a_bound(report):
    """A decision of the report within a factor of 4 of its bound (rank margin, zero disk)."""
    rank = report["rank condition"]
    if rank.undecided or (rank.margin is not None and rank.margin < 10):
        return True
    zs = report.zero_set
    if zs is None or not zs.zeros.size:
        return False
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = zs.distance / zs.radius
    return bool(np.any((ratio > 0.25) & (ratio < 4)))


def run_case(seed, discrete, design):
    """One case: verdicts in random units equal the base verdicts; a design is right or refused.

    Returns "right", "refused" or "wrong" (a verdict that changed, or a returned observer
    whose error depends on d).
    """
    rng = np.random.default_rng(seed)
    base, zeros, n = known_zero_plant(rng, discrete)
    ref = ut.check_existence(base)
    if not same_values(ref.invariant_zeros, zeros, rtol=1e-6):
        return "wrong"
    s, other = random_units(rng, base)
    report = ut.check_existence(other)
    if verdict(report) != verdict(ref):
        # round-off of other units may move a plant between decided and undecided only where
        # a decision sits at its bound; a decided verdict never turns into the other
        decided = [r for r in (ref, report) if r.decided]
        if len(decided) == 2 or not any(_near_a_bound(r) for r in (ref, report)):
            return "wrong"
    if not same_values(report.invariant_zeros, zeros, 1e-6):
        return "wrong"
    if not report.ok:
        return "right"  # refused by the existence check, as the base plant is
    poles = _stable_poles(rng, report.movable, discrete)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if design == "uio":
                obs = ut.design_uio(other, poles=poles)
            elif design == "pmo":
                obs = ut.design_pmo(other, poles=poles)
            else:
                obs = ut.design_pmo(other, method="lmi")
    except (PlacementAccuracyError, ut.LMIError):
        return "refused"
    if d_leak(obs, s) > 1e-7:
        return "wrong"
    try:
        check_fixed_modes(obs.poles(), report.fixed_modes)  # the zeros stay error poles
    except PlacementAccuracyError:
        return "wrong"
    if design != "lmi" and not same_values(obs.poles(), [*poles, *report.fixed_modes], 1e-3):
        return "wrong"
    if not obs.is_stable:
        return "wrong"
    return "right"


@pytest.mark.parametrize("design", ["uio", "pmo", "lmi"])
@pytest.mark.parametrize("discrete", [False, True])
def test_random_units_change_no_verdict_and_no_observer_leaks_d(design, discrete):
    cases = 12 if design == "lmi" else 25
    outcome = [
        run_case(1000 * (design == "pmo") + 2000 * discrete + i, discrete, design)
        for i in range(cases)
    ]
    assert outcome.count("wrong") == 0, outcome
    assert outcome.count("refused") <= cases // 5, outcome


def test_scaling_is_unique_up_to_units():
    # the balanced copies of a plant and of the same plant in other units agree
    rng = np.random.default_rng(7)
    base, _, _ = known_zero_plant(rng, discrete=False)
    _, other = random_units(rng, base)
    a, _ = balanced_plant(base, time=True)
    b, _ = balanced_plant(other, time=True)
    for X, Y in ((a.A, b.A), (a.C @ a.E, b.C @ b.E)):
        ratio = np.abs(X) / np.maximum(np.abs(Y), 1e-300)
        big = np.abs(X) > 1e-8 * np.abs(X).max()
        assert np.all((ratio[big] > 0.2) & (ratio[big] < 5)), ratio[big]
    assert plant_scaling(base).t.shape == (base.n,)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_detection_verdicts_do_not_depend_on_units(seed):
    rng = np.random.default_rng(seed)
    base = ut.examples.pa9()
    s = 10.0 ** rng.uniform(-6, 6, base.n)
    o = 10.0 ** rng.uniform(-6, 6, base.p)
    t = np.linspace(0, 10, 1001)
    d = ut.signals.sinusoid(2.0, 1.5)
    fired = []
    for plant, out in ((base, np.ones(base.p)), (in_units(base, s=s, o=o), o)):
        uio = ut.design_uio(plant, poles=[-2, -3, -4])
        noise = 0.01 * out
        quiet = np.stack(
            [
                ut.simulate(plant, uio, t, d=d, noise=noise, seed=k).residual / out[:, None]
                for k in range(4)
            ]
        )
        # a threshold well above every fault-free run (a per-run rate near 0)
        level = max(float(ut.residual_rms(t, r, 0.5)[t >= 0.5].max()) for r in quiet)
        thr = ut.Threshold(
            value=3 * level, window=0.5, design_rate=0.01, start=0.5, samples=4, per="run"
        )
        hidden = ut.process_fault(plant, plant.E[:, 0], ut.signals.step(5.0, 4.0))
        shown = ut.actuator_fault(plant, 1, ut.signals.step(1.0, 4.0))
        row = []
        for fault in (hidden, shown):
            resp = ut.simulate_fault(plant, uio, t, fault, d=d, noise=noise, seed=9)
            r = resp.residual / out[:, None]  # each output in its own units, normalized
            row.append(ut.detect(t, r, thr).fired)
        fired.append(row)
    # the fault through E stays hidden, the actuator fault shows, in both units (the two
    # observers differ: H = E (CE)^+ is another generalized inverse in other output units)
    assert fired[0] == fired[1] == [False, True]
