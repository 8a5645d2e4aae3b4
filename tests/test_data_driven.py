"""UIOs from data: the data conditions, the equivalence with the model-based design, noise."""

import warnings

import numpy as np
import pytest
from tolerance import roundoff

import uio_teach as ut
from uio_teach.data_driven import (
    DataConditionError,
    DataConditioningWarning,
    check_data,
    data_matrices,
    design_uio_from_data,
    record_experiment,
    sampled_plant,
)

# the existence conditions that decide (the model-based report's required ones)
DECIDING = ("rank condition", "invariant zeros stable", "detectable (TA, C)")


def random_plant(rng):
    """A random discrete plant: stable A (the experiment stays bounded), q up to p + 1."""
    n = int(rng.integers(2, 6))
    p = int(rng.integers(1, n + 1))
    q = int(rng.integers(1, min(p + 1, n - 1) + 1)) if n > 2 else 1
    m = int(rng.integers(0, 3))
    A = rng.standard_normal((n, n))
    A *= 0.9 / max(abs(np.linalg.eigvals(A)))
    return ut.Plant(
        A,
        rng.standard_normal((p, n)),
        B=rng.standard_normal((n, m)),
        E=rng.standard_normal((n, q)),
        dt=1,
    )


def richness(plant, rec):
    """Condition number of the row-scaled [U_p; X_p; D_p]: how much the data amplify round-off."""
    mats = data_matrices(rec.u, rec.y, rec.x)
    S = np.vstack([mats.U_p, mats.X_p, rec.d[:, :-1]])
    S = S / np.sqrt(np.mean(S**2, axis=1, keepdims=True))
    s = np.linalg.svd(S, compute_uv=False)
    return float(s[0] / s[-1])


def same_values(a, b, tol):
    """The same multiset of (complex) values, each within tol (a repeated value may split)."""
    a, b = list(np.asarray(a, complex)), list(np.asarray(b, complex))
    if len(a) != len(b):
        return False
    for z in a:
        i = int(np.argmin(np.abs(np.array(b) - z)))
        if abs(b[i] - z) > tol:
            return False
        b.pop(i)
    return True


def failed_names(report):
    return sorted(c.name for c in report.failed if c.name in DECIDING)


def equivalence_cases(count=32, seed=2027):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        plant = random_plant(rng)
        N = plant.m + plant.n + plant.q + 8
        yield plant, record_experiment(plant, N, seed=rng)


CASES = list(equivalence_cases())


def test_the_data_reach_the_model_based_verdict_on_random_plants():
    kinds = {"exists": 0, "rank condition": 0, "invariant zeros stable": 0}
    for plant, rec in CASES:
        model = ut.check_existence(plant)
        data = check_data(rec.u, rec.y, rec.x, dt=1, unknown_inputs=plant.q)
        assert data.existence is not None, str(data)
        assert data.ok == model.ok, f"{plant}\n{model}\n{data}"
        assert failed_names(data) == failed_names(model)
        if model.ok:
            kinds["exists"] += 1
        else:
            names = failed_names(model)
            kinds["rank condition" if "rank condition" in names else "invariant zeros stable"] += 1
        # the fixed modes (the invariant zeros) seen in the data are the plant's
        gain = richness(plant, rec)
        tol = roundoff(1, terms=rec.x.size, gain=gain) ** 0.5
        assert same_values(data.existence.invariant_zeros, model.invariant_zeros, tol)
    # both directions of the equivalence, each on several plants
    assert min(kinds.values()) >= 5, kinds


def test_refused_from_the_data_for_the_model_based_reason():
    refused = 0
    for plant, rec in CASES:
        model = ut.check_existence(plant)
        if model.ok:
            continue
        with pytest.raises(DataConditionError) as info:
            design_uio_from_data(rec.u, rec.y, rec.x, dt=1, poles=None, unknown_inputs=plant.q)
        for name in failed_names(model):
            assert name in str(info.value)
        assert isinstance(info.value, ValueError)
        refused += 1
    assert refused >= 10


def check_designs(cases, rng):
    """On each plant where a UIO exists: placed poles, the model-based matrices for the same
    gain, and the defining property (the error does not depend on d)."""
    designed = 0
    for plant, rec in cases:
        model = ut.check_existence(plant)
        if not model.ok:
            continue
        poles = rng.uniform(-0.6, 0.6, model.movable)
        obs = design_uio_from_data(rec.u, rec.y, rec.x, dt=1, poles=poles)
        gain = richness(plant, rec) * max(1.0, float(np.linalg.norm(obs.K, 2)))
        tol = roundoff(1, terms=rec.x.size, gain=gain) ** 0.5
        # the movable poles exactly those asked for, plus the fixed invariant zeros
        assert same_values(obs.poles(), np.concatenate([poles, model.fixed_modes]), tol)
        # for the same gain K1, the model-based observer, matrix by matrix
        same = ut.design_uio(plant, K1=obs.K1)
        size = max(float(np.abs(getattr(same, k)).max()) for k in ("F", "H", "T", "K"))
        atol = roundoff(max(size, 1.0), terms=rec.x.size, gain=gain)
        for name in ("H", "T", "F", "K"):
            assert np.allclose(getattr(obs, name), getattr(same, name), rtol=0, atol=atol), name
        assert np.allclose(obs.realization().B_u, same.realization().B_u, rtol=0, atol=atol)
        # the defining property, on the true plant
        t = np.arange(25)
        x0 = rng.standard_normal(plant.n)
        u = rng.standard_normal((plant.m, t.size)) if plant.m else None
        d = 5 * rng.standard_normal((plant.q, t.size))
        quiet = ut.simulate(plant, obs, t, u=u, initial_state=x0)
        loud = ut.simulate(plant, obs, t, u=u, initial_state=x0, d=d)
        size = float(np.abs(loud.states).max())
        bound = roundoff(size, terms=rec.x.size, steps=t.size, gain=gain)
        assert np.allclose(quiet.error, loud.error, rtol=0, atol=bound)
        assert np.abs(quiet.states - loud.states).max() > 0.1  # the unknown input did act
        designed += 1
    return designed


def test_designs_from_data_are_the_model_based_ones():
    assert check_designs(CASES[:16], np.random.default_rng(7)) >= 4


@pytest.mark.slow
def test_designs_from_data_are_the_model_based_ones_on_many_plants():
    cases = list(equivalence_cases(count=120, seed=31))
    assert check_designs(cases, np.random.default_rng(8)) >= 30


def test_minimum_norm_design_is_the_papers_estimator():
    """poles=None: Turan & Ferrari-Trecate's x[k+1] = X_f W [u; y; x; u+; y+] with Tini = Tf = 1."""
    rng = np.random.default_rng(11)
    plant = ut.Plant(
        np.diag([0.5, 0.3, -0.2]) + 0.1 * rng.standard_normal((3, 3)),
        rng.standard_normal((2, 3)),
        B=rng.standard_normal((3, 1)),
        E=rng.standard_normal((3, 1)),
        dt=0.01,
    )
    rec = record_experiment(plant, 20, seed=rng)
    obs = design_uio_from_data(rec.u, rec.y, rec.x, dt=0.01)
    # the paper's W, written out from its definition (U_f included, as in its code)
    u, y, x = rec.u, rec.y, rec.x
    Phi = np.vstack([u[:, :-1], y[:, :-1], x[:, :-1], u[:, 1:], y[:, 1:]])
    W = np.linalg.pinv(Phi)
    Xf = x[:, 1:]
    m, p, n = 1, 2, 3
    W2 = W[:, m + p : m + p + n]
    tol = roundoff(float(np.abs(Xf).max()), terms=x.size, gain=np.linalg.cond(Phi[: m + p + n]))
    assert np.allclose(obs.F, Xf @ W2, rtol=0, atol=tol**0.5)
    assert np.allclose(obs.K1, Xf @ W[:, m : m + p], rtol=0, atol=tol**0.5)
    # and it estimates the state whatever d is (the error obeys e+ = F e)
    assert obs.is_stable


def test_minimum_norm_can_be_unstable_where_a_uio_exists():
    # a sensor in small units: the minimum-norm solution weighs the state more than the
    # output, and F is nearly T A, unstable here (the choice depends on the units of y)
    plant = ut.Plant(np.diag([3.0, 0.5]), 1e-3 * np.eye(2), E=[[0.0], [1.0]], dt=1)
    assert ut.check_existence(plant).ok
    rec = record_experiment(plant, 10, seed=0)
    with pytest.warns(ut.UnstableObserverWarning, match="poles="):
        obs = design_uio_from_data(rec.u, rec.y, rec.x, dt=1)
    assert not obs.is_stable
    placed = design_uio_from_data(rec.u, rec.y, rec.x, dt=1, poles=[0.1, 0.2])
    assert np.allclose(np.sort(placed.poles().real), [0.1, 0.2])


# data conditions ---------------------------------------------------------------------------------


def simple_plant(q=1, m=1):
    rng = np.random.default_rng(5)
    return ut.Plant(
        np.array([[0.5, 0.2, 0.0], [0.0, 0.4, 0.1], [0.1, 0.0, 0.3]]),
        [[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]],
        B=rng.standard_normal((3, m)),
        E=rng.standard_normal((3, q)),
        dt=1,
    )


def test_too_short_names_the_samples_to_record():
    plant = simple_plant()
    rec = record_experiment(plant, plant.m + plant.n + plant.q, seed=1)
    with pytest.raises(DataConditionError, match="enough samples") as info:
        design_uio_from_data(rec.u, rec.y, rec.x, dt=1, poles=[0.1, 0.2, 0.3], unknown_inputs=1)
    assert "record at least 7 samples" in str(info.value)
    # without q the data alone show that no transition is left
    report = check_data(rec.u, rec.y, rec.x, dt=1)
    assert report["enough samples"].holds is False
    rec = record_experiment(plant, 7, seed=1)
    assert check_data(rec.u, rec.y, rec.x, dt=1, unknown_inputs=1).ok


def test_not_exciting_says_which_signal():
    plant = simple_plant()
    rec = record_experiment(plant, 30, seed=1, u=np.zeros((1, 30)))
    with pytest.raises(DataConditionError, match="input and state exciting.*known input"):
        design_uio_from_data(rec.u, rec.y, rec.x, dt=1, poles=[0.1, 0.2, 0.3])
    quiet = ut.Plant(np.diag([0.5, 0.4, 0.3]), np.eye(3), E=[[1.0], [0.0], [0.0]], dt=1)
    rec = record_experiment(quiet, 30, seed=1, initial_state=[0, 0, 0])
    report = check_data(rec.u, rec.y, rec.x, dt=1)
    assert (
        "the state stayed in a subspace of dimension 1" in report["input and state exciting"].reason
    )


def test_a_hidden_direction_is_refused_and_would_not_be_decoupled():
    plant = simple_plant(q=2)
    rng = np.random.default_rng(2)
    d1 = rng.standard_normal(30)
    rec = record_experiment(plant, 30, seed=3, d=np.vstack([d1, d1]))  # channels together
    with pytest.raises(DataConditionError, match="unknown input shows every direction") as info:
        design_uio_from_data(rec.u, rec.y, rec.x, dt=1, unknown_inputs=2, poles=[0.1])
    assert "moved in 1 direction(s)" in str(info.value)
    # without the number of unknown inputs the data look like one: the design decouples only
    # the direction seen, and the hidden one reaches the error
    movable = check_data(rec.u, rec.y, rec.x, dt=1).existence.movable
    obs = design_uio_from_data(rec.u, rec.y, rec.x, dt=1, poles=np.linspace(0.1, 0.3, movable))
    t = np.arange(20)
    seen = ut.simulate(plant, obs, t, d=np.vstack([np.ones(20), np.ones(20)]))
    hidden = ut.simulate(plant, obs, t, d=np.vstack([np.ones(20), -np.ones(20)]))
    assert np.abs(seen.error).max() < 1e-8
    assert np.abs(hidden.error).max() > 0.1


def test_outputs_not_a_function_of_the_state_are_refused():
    plant = simple_plant()
    rec = record_experiment(plant, 30, seed=1)
    y = rec.y + np.vstack([rec.d, np.zeros_like(rec.d)])  # d reaches y directly
    with pytest.raises(DataConditionError, match="outputs a function of the state"):
        design_uio_from_data(rec.u, y, rec.x, dt=1, poles=[0.1, 0.2, 0.3])


# the course's plants ------------------------------------------------------------------------------


def test_quadruple_tank_sampled_at_p_minus_and_p_plus():
    good = sampled_plant(ut.examples.quadruple_tank("P-"), 5.0)
    bad = sampled_plant(ut.examples.quadruple_tank("P+"), 5.0)
    for plant in (good, bad):
        rec = record_experiment(plant, 40, seed=4)
        data = check_data(rec.u, rec.y, rec.x, dt=5.0, unknown_inputs=2)
        model = ut.check_existence(plant)
        assert data.ok == model.ok
        assert failed_names(data) == failed_names(model)
    assert ut.check_existence(good).ok and not ut.check_existence(bad).ok
    rec = record_experiment(bad, 40, seed=4)
    with pytest.raises(DataConditionError, match="invariant zero.*outside the open unit disk"):
        design_uio_from_data(rec.u, rec.y, rec.x, dt=5.0, poles=[0.5, 0.6], unknown_inputs=2)


def test_verdicts_do_not_depend_on_units():
    plant = sampled_plant(ut.examples.quadruple_tank("P-"), 5.0)
    rec = record_experiment(plant, 40, seed=4)
    base = check_data(rec.u, rec.y, rec.x, dt=5.0, unknown_inputs=2)
    for scale in (1e-6, 1e6):
        other = check_data(rec.u, scale * rec.y, rec.x / scale, dt=5.0, unknown_inputs=2)
        assert [c.holds for c in other.conditions] == [c.holds for c in base.conditions]


# noise -------------------------------------------------------------------------------------------


def test_noise_moves_the_design_in_proportion():
    plant = simple_plant()
    model = ut.design_uio(plant, poles=[0.1, 0.2, 0.3])
    gaps = []
    for noise in (1e-7, 1e-5, 1e-3):
        rec = record_experiment(plant, 200, seed=9, noise=noise)
        obs = design_uio_from_data(
            rec.u, rec.y, rec.x, dt=1, poles=[0.1, 0.2, 0.3], unknown_inputs=1, rtol=noise
        )
        gaps.append(float(np.abs(obs.F - model.F).max()))
    # graceful: the observer moves by an amount of the order of the noise, not more
    assert gaps[0] < gaps[1] < gaps[2]
    assert gaps[2] < 1e3 * 1e-3 and gaps[0] < 1e3 * 1e-7


def test_ill_conditioned_data_warn():
    plant = simple_plant()
    rec = record_experiment(plant, 40, seed=9, noise=0.01)
    with pytest.warns(DataConditioningWarning, match="ill-conditioned"):
        design_uio_from_data(
            rec.u, rec.y, rec.x, dt=1, poles=[0.1, 0.2, 0.3], unknown_inputs=1, rtol=0.01
        )
    rec = record_experiment(plant, 40, seed=9)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataConditioningWarning)
        design_uio_from_data(rec.u, rec.y, rec.x, dt=1, poles=[0.1, 0.2, 0.3], unknown_inputs=1)


# bad input ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"y": np.ones((2, 9))}, "y has 9 samples"),
        ({"x": np.full((3, 10), np.nan)}, "x has a non-finite value"),
        ({"dt": None}, "discrete-time"),
        ({"dt": 0}, "discrete-time"),
        ({"unknown_inputs": 5}, "unknown_inputs must be"),
        ({"poles": [0.1, 0.2], "K1": np.zeros((3, 2))}, "at most one of poles"),
        ({"u": np.ones((1, 10, 1))}, "one row per channel"),
        ({"rtol": -1.0}, "rtol must be >= 0"),
    ],
)
def test_bad_input_gets_a_clear_error(kwargs, match):
    plant = simple_plant()
    rec = record_experiment(plant, 10, seed=0)
    args = {"u": rec.u, "y": rec.y, "x": rec.x, "dt": 1}
    args.update(kwargs)
    u, y, x = args.pop("u"), args.pop("y"), args.pop("x")
    with pytest.raises(ValueError, match=match):
        design_uio_from_data(u, y, x, **args)


def test_the_report_reads_as_a_table():
    plant = simple_plant()
    rec = record_experiment(plant, 12, seed=0)
    report = check_data(rec.u, rec.y, rec.x, dt=1, unknown_inputs=1)
    text = str(report)
    assert text.startswith("Data conditions") and "=> a UIO can be designed" in text
    assert "<table>" in report._repr_html_()
    with pytest.raises(KeyError, match="no condition named"):
        report["nonsense"]


def test_several_experiments_count_together():
    # A = 0.5 I, no known input: one experiment keeps the state in span{x(0), E}
    case = ut.examples.dt_case_study()
    plant = ut.Plant(case.A, case.C, E=case.E, dt=1)
    one = record_experiment(plant, 30, seed=1)
    assert check_data(one.u, one.y, one.x, dt=1).failed[0].name == "input and state exciting"
    runs = [record_experiment(plant, 10, seed=k) for k in range(3)]
    report = check_data(None, [r.y for r in runs], [r.x for r in runs], dt=1, unknown_inputs=1)
    assert report.ok and report.samples == 30
    # no transition across two experiments: the blocks are the experiments' side by side
    mats = data_matrices(None, [r.y for r in runs], [r.x for r in runs])
    assert mats.transitions == 27
    assert np.array_equal(mats.X_f[:, 9], runs[1].x[:, 1])
    obs = design_uio_from_data(
        None, [r.y for r in runs], [r.x for r in runs], dt=1, poles=[0.1, 0.2], unknown_inputs=1
    )
    model = ut.check_existence(plant)
    assert same_values(obs.poles(), np.concatenate([[0.1, 0.2], model.fixed_modes]), 1e-8)
    with pytest.raises(ValueError, match="lists of 3 2-D arrays"):
        check_data(None, runs[0].y, [r.x for r in runs], dt=1)


def test_minimum_norm_with_noise_stays_near_the_exact_one():
    plant = simple_plant()
    exact = record_experiment(plant, 200, seed=4)
    noisy = record_experiment(plant, 200, seed=4, noise=1e-6)
    ref = design_uio_from_data(exact.u, exact.y, exact.x, dt=1)
    obs = design_uio_from_data(noisy.u, noisy.y, noisy.x, dt=1, unknown_inputs=1, rtol=1e-6)
    assert np.abs(obs.F - ref.F).max() < 1e-3
    assert np.abs(obs.H - ref.H).max() < 1e-3
