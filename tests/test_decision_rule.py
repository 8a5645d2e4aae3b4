"""One decision rule: verdicts in any unit, every zero counted, no leak certified that is not.

A zero is on a side of the stability boundary when no plant within the backward error of the
data has it on the other side; the report says "cannot be decided" only then, with the bound
and the distance. The cases are classes of plants whose zeros are known exactly
(``benchmarks/zero_families.py``), the quadruple tank near its valve line, and the named
instances that were once answered wrong.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from tolerance import roundoff

import uio_teach as ut
from uio_teach.verify import LEAK_REFUSE, LEAK_RTOL, DecouplingError, DecouplingWarning

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from zero_families import (  # noqa: E402
    FAMILIES,
    build,
    exact_leak,
    judge,
    plant_with_zeros,
    poles_for,
    slicot_zero_count,
)

ALPHAS = (1e-6, 1e-3, 1.0, 3600.0, 1e6)


def verdict(report: ut.ExistenceReport) -> str:
    if report.ok:
        return "exists"
    if any(c.holds is False for c in report.conditions if c.required):
        return "no"
    return "undecided"


def time_scaled(plant: ut.Plant, alpha: float) -> ut.Plant:
    """The same plant with time measured in units ``alpha`` times longer (rates times alpha)."""
    return ut.Plant(plant.A * alpha, plant.C, B=plant.B * alpha, E=plant.E * alpha, D=plant.D)


def unit_scaled(plant: ut.Plant, rng: np.random.Generator) -> ut.Plant:
    """The same plant with states, unknown inputs and outputs in other units (powers of 10)."""
    t = 10.0 ** rng.integers(-3, 4, plant.n)
    wd = 10.0 ** rng.integers(-3, 4, plant.q)
    wy = 10.0 ** rng.integers(-3, 4, plant.p)
    return ut.Plant(
        plant.A / t[:, None] * t[None, :],
        wy[:, None] * plant.C * t[None, :],
        E=plant.E / t[:, None] * wd[None, :],
        dt=plant.dt,
    )


def clusters_match(a: np.ndarray, b: np.ndarray, radius: np.ndarray) -> bool:
    """Each value of ``a`` within twice the round-off radius (or 1e-6 relative) of one of ``b``."""
    a, b = np.asarray(a, complex), np.asarray(b, complex)
    if a.size != b.size:
        return False
    reach = 2 * np.asarray(radius, float) + 1e-6 * np.abs(b)
    return all(np.any(np.abs(x - b) <= reach) for x in a)


def matched(a: np.ndarray, b: np.ndarray, rtol: float) -> bool:
    a, b = np.sort_complex(np.asarray(a, complex)), np.sort_complex(np.asarray(b, complex))
    if a.size != b.size:
        return False
    scale = max(float(np.max(np.abs(b), initial=0.0)), np.finfo(float).tiny)
    return bool(np.all(np.abs(a - b) <= rtol * np.maximum(np.abs(b), rtol * scale)))


# the quadruple tank near gamma1 + gamma2 = 1 -----------------------------------------------------
def tank_zeros(g1: float, g2: float) -> np.ndarray:
    """The tank's zeros, from (1 + s T3)(1 + s T4) = (1 - g1)(1 - g2) / (g1 g2), stably."""
    T = ut.examples.tank_time_constants("P-", gamma1=g1, gamma2=g2)
    T3, T4 = T[2], T[3]
    one_minus_k = (g1 + g2 - 1.0) / (g1 * g2)  # 1 - k, without cancellation
    b, c = T3 + T4, T3 * T4
    root = np.sqrt(b * b - 4 * c * one_minus_k)
    return np.array([-(b + root) / (2 * c), -2 * one_minus_k / (b + root)])


@pytest.mark.parametrize("offset", [1e-8, 1e-6, 1e-3, -1e-3, -1e-6, -1e-8])
def test_tank_near_its_valve_line_has_one_verdict_in_every_unit_of_time(offset):
    g1 = 0.5
    g2 = 0.5 + offset
    tank = ut.examples.quadruple_tank(gamma1=g1, gamma2=g2)
    exact = tank_zeros(g1, g2)
    expected = "exists" if offset > 0 else "no"
    for alpha in ALPHAS:
        report = ut.check_existence(time_scaled(tank, alpha))
        assert verdict(report) == expected, (alpha, str(report))
        assert report.decided
        # the slow zero, found to many digits, scaled with the unit of time
        assert matched(report.invariant_zeros, exact * alpha, 1e-6), (alpha, report.invariant_zeros)
        assert report.movable == 2


def test_tank_on_its_valve_line_is_never_said_to_have_a_uio():
    tank = ut.examples.quadruple_tank(gamma1=0.7, gamma2=0.3)  # the sum is 1 to round-off
    verdicts = {verdict(ut.check_existence(time_scaled(tank, a))) for a in ALPHAS}
    assert "exists" not in verdicts
    report = ut.check_existence(tank)
    if not report.decided:
        reason = report["invariant zeros stable"].reason
        # the bound and the distance are said
        assert "backward error" in reason and "from the imaginary axis" in reason


def test_tank_verdict_does_not_change_with_the_units_of_states_inputs_and_outputs():
    rng = np.random.default_rng(7)
    for offset in (1e-7, -1e-7):
        tank = ut.examples.quadruple_tank(gamma1=0.5, gamma2=0.5 + offset)
        base = verdict(ut.check_existence(tank))
        for _ in range(4):
            assert verdict(ut.check_existence(unit_scaled(tank, rng))) == base


# constructed families: classes, not instances ---------------------------------------------------
@pytest.mark.parametrize("family", FAMILIES)
def test_constructed_family_never_wrong_and_every_zero_counted(family):
    for seed in range(4):
        case = build(family, seed)
        out = judge(case)
        assert out.verdict != "wrong", (case.label, str(out.report))
        assert out.count_right, (case.label, out.report.invariant_zeros, case.zeros)
        assert out.silent_leaks == 0, case.label
        if out.report.ok and family in ("slow", "repeated", "defective", "discrete"):
            # the report's movable count is what both designs place: neither refuses
            assert out.designs == 2, case.label
        tall_unstable = case.plant.p > case.plant.q and case.truth == "no"
        if case.truth != "boundary" and not tall_unstable:
            # decided whenever the exact zeros are clear of the boundary (they all are here)
            assert out.verdict == "right", (case.label, str(out.report))
        elif tall_unstable and out.verdict == "undecided":
            # more outputs than unknown inputs: a plant within round-off has no zero at all,
            # so an unstable zero alone does not decide "no"; the reason says so
            assert "holds only by the structure" in out.report["invariant zeros stable"].reason


@pytest.mark.parametrize("family", ["fast", "slow", "repeated", "defective"])
def test_constructed_family_has_one_verdict_in_every_unit(family):
    rng = np.random.default_rng(11)
    for seed in range(3):
        case = build(family, seed)
        base = ut.check_existence(case.plant)
        for alpha in (1e-6, 1e6):
            other = ut.check_existence(time_scaled(case.plant, alpha))
            assert verdict(other) == verdict(base), (case.label, alpha)
            # a defective cluster scatters within its radius, in any unit
            assert clusters_match(
                other.invariant_zeros, base.invariant_zeros * alpha, base.zero_radius * alpha
            )
            assert other.movable == base.movable
        other = ut.check_existence(unit_scaled(case.plant, rng))
        assert verdict(other) == verdict(base), case.label
        assert other.movable == base.movable


@pytest.mark.slow
@pytest.mark.parametrize("family", FAMILIES)
def test_constructed_family_sweep(family):
    for seed in range(4, 40):
        case = build(family, seed)
        out = judge(case)
        assert out.verdict != "wrong", (case.label, str(out.report))
        assert out.count_right and out.silent_leaks == 0, case.label


@pytest.mark.parametrize("family", ["slow", "repeated", "defective", "boundary", "discrete"])
def test_zero_count_agrees_with_slicot(family):
    pytest.importorskip("ctrlsys")
    for seed in range(0, 12, 2):  # plain and orthogonal coordinates, square and tall
        case = build(family, seed)
        assert (
            slicot_zero_count(case.plant)
            == case.zeros.size
            == (ut.check_existence(case.plant).invariant_zeros.size)
        ), case.label


# a zero beyond what double precision resolves is never dropped -----------------------------------
@pytest.mark.parametrize("ce", [-1e-12, 1e-12, -1e-10, 1e-10])
@pytest.mark.parametrize("dt", [None, 1.0])
def test_a_small_ce_keeps_its_fast_zero_and_the_refusal_names_it(ce, dt):
    A = np.array([[-1.0, 0.5, 0.0], [1.1, -2.0, 1.0], [0.3, 0.0, -3.0]])
    A = A if dt is None else 0.3 * A
    E = np.array([[1.0], [0.0], [0.0]])
    C = np.array([[ce, 1.0, 0.0]])
    plant = ut.Plant(A, C, E=E, dt=dt)
    report = ut.check_existence(plant)
    fast = -(C @ A @ E)[0, 0] / ce  # about -CAE / CE
    unstable = (fast > 0) if dt is None else True  # |fast| > 1 in discrete time
    assert report.invariant_zeros.size == 2
    if unstable:
        assert verdict(report) != "exists", str(report)
        with pytest.raises(ut.UIOExistenceError) as info:
            ut.design_uio(plant, poles=[-1.0] if dt is None else [0.5])
        message = str(info.value)
        assert "invariant zero" in message and "amplifies round-off" not in message
    if report.decided:
        assert np.min(np.abs(report.invariant_zeros - fast)) <= 1e-3 * abs(fast)


def test_a_zero_beyond_double_precision_makes_the_verdict_undecided_or_no():
    # C E = 1e-17: no double-precision computation tells where the zero is, or whether it is
    A = np.array([[-1.0, 0.5, 0.0], [1.1, -2.0, 1.0], [0.3, 0.0, -3.0]])
    for ce in (1e-17, -1e-17):
        plant = ut.Plant(A, [[ce, 1.0, 0.0]], E=[[1.0], [0.0], [0.0]])
        assert verdict(ut.check_existence(plant)) != "exists"


# repeated and defective zeros: counted by their multiplicity ------------------------------------
@pytest.mark.parametrize(
    ("z", "k", "dt"), [(0.98, 3, 1.0), (0.5, 2, 1.0), (-0.5, 3, None), (-0.02, 4, None)]
)
def test_a_defective_zero_is_counted_once_per_multiplicity_and_decided(z, k, dt):
    J = z * np.eye(k) + np.diag(np.ones(k - 1), 1)
    plant = plant_with_zeros(J, np.random.default_rng(k), dt=dt, orthogonal=True)
    report = ut.check_existence(plant)
    assert report.ok and report.decided, str(report)
    assert report.invariant_zeros.size == k
    assert report.movable == plant.n - k
    assert f"(x{k})" in report["invariant zeros stable"].reason
    # the centre of the cluster is well conditioned
    assert abs(np.mean(report.invariant_zeros) - z) <= 1e-8
    poles = poles_for(report)
    obs = ut.design_uio(plant, poles=poles)
    assert obs.poles().size == plant.n
    with pytest.raises(ValueError, match=f"{plant.n - k} pole"):
        ut.design_uio(plant, poles=np.append(poles, poles[0] * 1.5))


# the chapter's example ----------------------------------------------------------------------------
def test_the_chapters_ce_example_is_decided_and_refused_for_its_real_cause():
    A = np.array([[-1.0, 0.0], [1.0, -2.0]])
    weak = ut.Plant(A, [[1.0, 1.0]], E=[[1.0], [-1.0 + 1e-8]])
    report = ut.check_existence(weak)
    assert report.ok and report.decided
    assert abs(report.invariant_zeros[0] + 2e8) <= 1e-3 * 2e8
    assert "round-off" not in report["invariant zeros stable"].reason
    with pytest.raises(DecouplingError, match="C E small next to E makes H large"):
        ut.design_uio(weak, poles=[-1.0])


# the leak of every returned design, at every frequency -----------------------------------------
@pytest.mark.parametrize("slow", [1e-6, 1e-8, 1e-10])
@pytest.mark.parametrize("dt", [None, 1.0])
def test_a_slow_fixed_mode_does_not_hide_a_leak_at_dc(slow, dt):
    z = -slow if dt is None else 1.0 - slow
    rng = np.random.default_rng(3)
    for p in (1, 2):
        plant = plant_with_zeros(np.array([[z]]), rng, p=p, dt=dt, orthogonal=True)
        report = ut.check_existence(plant)
        assert report.ok, str(report)
        for design in (ut.design_uio, ut.design_pmo):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                try:
                    obs = design(plant, poles=poles_for(report))
                except DecouplingError:
                    continue  # refused: nothing certified
            warned = any(issubclass(w.category, DecouplingWarning) for w in caught)
            exact = exact_leak(plant, obs)
            assert exact <= (LEAK_REFUSE if warned else LEAK_RTOL)
            # what the design certifies covers what its matrices do, DC included
            assert exact <= obs.leak.bound + roundoff(1.0, terms=plant.n)


def test_a_leak_above_the_refusal_threshold_is_refused_not_warned():
    from uio_teach.verify import check_decoupling

    # x1 is measured (xhat1 = y) and drives x2: the gain K = [0; 1] decouples exactly
    A = np.array([[-1.0, 0.0], [1.0, -2.0]])
    E = np.array([[1.0], [0.0]])
    C = np.array([[1.0, 0.0]])
    Dy = np.array([[1.0], [0.0]])
    K = np.array([[0.0], [1.0]])
    assert check_decoupling(A, E, C, A, K, np.eye(2), Dy).bound <= LEAK_RTOL
    for off in (3e-3, 1e-2):  # a leak of a few thousandths: above the threshold, refused
        with pytest.raises(DecouplingError, match="refused"):
            check_decoupling(A, E, C, A, K * (1 + off), np.eye(2), Dy)
    with pytest.warns(DecouplingWarning):  # below it: warned
        check_decoupling(A, E, C, A, K * (1 + 1e-5), np.eye(2), Dy)


# deadbeat: verified by F^k = 0 -----------------------------------------------------------------
@pytest.mark.parametrize("seed", range(4))
def test_a_deadbeat_design_is_built_and_nilpotent(seed):
    rng = np.random.default_rng(seed)
    n, p = 4 + seed % 2, 2
    plant = ut.Plant(
        0.5 * rng.standard_normal((n, n)),
        rng.standard_normal((p, n)),
        E=rng.standard_normal((n, 1)),
        dt=1.0,
    )
    report = ut.check_existence(plant)
    assert report.ok and report.movable > p
    for design in (ut.design_uio, ut.design_pmo):
        obs = design(plant, poles=np.zeros(report.movable))
        F = obs.F if hasattr(obs, "F") else obs.realization().A
        Fk = np.linalg.matrix_power(F, n)
        size = float(np.linalg.norm(F, 2)) ** n
        assert np.linalg.norm(Fk, 2) <= roundoff(max(size, 1.0), terms=n, steps=n)
