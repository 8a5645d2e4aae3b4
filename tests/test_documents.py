"""Every number printed in the three source documents, reproduced to the precision printed."""

import numpy as np
import pytest
from tolerance import (
    assert_rounding_close,
    assert_zero,
    eigenvalue_roundoff,
    roundoff,
    size_of,
)

import uio_teach as ut
from uio_teach.examples import DT_CASE_STUDY_PUBLISHED, MISSILE_PUBLISHED, PA9_PUBLISHED
from uio_teach.worked.missile import MISSILE


def printed(x, decimals):
    """Round as the document did (half away from zero is what MATLAB prints)."""
    return np.round(np.asarray(x, float), decimals) + 0.0


# --- Case study (document 000): discrete-time projection-operator UIO --------------------------


@pytest.fixture(scope="module")
def case_pmo():
    return ut.design_pmo(ut.examples.dt_case_study(), method="lmi")


def test_case_study_M_as_printed(case_pmo):
    np.testing.assert_array_equal(printed(case_pmo.M, 4), DT_CASE_STUDY_PUBLISHED.M)


def test_case_study_decoupling_identities(case_pmo):
    plant = case_pmo.plant
    # (I - MC) E = 0 and M D = 0, up to the rounding of 3-term products of M = E [CE D]^+
    M, C, E, D = case_pmo.M, plant.C, plant.E, plant.D
    gain = np.linalg.cond(np.hstack([C @ E, D]))
    assert_zero((np.eye(3) - M @ C) @ E, np.eye(3) + np.abs(M) @ np.abs(C), E, terms=3, gain=gain)
    assert_zero(M @ D, M, D, terms=3, gain=gain)


def test_case_study_lmi_gain_as_printed(case_pmo):
    np.testing.assert_array_equal(printed(case_pmo.L, 4), DT_CASE_STUDY_PUBLISHED.L)


def test_case_study_LD_is_zero_exactly(case_pmo):
    # the solver meets Y D = 0 only to ~1e-8; the returned L is projected: zero to rounding
    D = case_pmo.plant.D
    assert_zero(case_pmo.L @ D, case_pmo.L, D, terms=3, gain=np.linalg.cond(D))


def test_case_study_poles_as_printed(case_pmo):
    np.testing.assert_allclose(case_pmo.poles(), DT_CASE_STUDY_PUBLISHED.poles, atol=5e-5)
    assert case_pmo.lmi_certificate is not None
    assert np.all(np.linalg.eigvalsh(case_pmo.lmi_certificate) >= 0.01 - 1e-7)


def test_case_study_A1_already_has_the_printed_poles(case_pmo):
    A1 = case_pmo.A1
    np.testing.assert_allclose(
        np.sort(np.linalg.eigvals(A1).real), [0, 0.5, 0.5], atol=eigenvalue_roundoff(A1)
    )


def test_case_study_rank_facts():
    """The script prints rank(observ(A1, C)) = 2 and rank(M) = 1."""
    plant = ut.examples.dt_case_study()
    pmo = ut.design_pmo(plant, poles=[0.0])
    obsv = ut.linalg.observability_matrix(pmo.A1, plant.C)
    assert ut.linalg.rank(obsv) == 2
    assert ut.linalg.rank(pmo.M) == 1


@pytest.mark.parametrize("solver", ["CLARABEL", "SCS"])
def test_case_study_lmi_with_both_solvers(solver):
    plant = ut.examples.dt_case_study()
    dec_M = np.hstack([plant.E, np.zeros((3, 1))]) @ np.linalg.pinv(
        np.hstack([plant.C @ plant.E, plant.D])
    )
    A1 = (np.eye(3) - dec_M @ plant.C) @ plant.A
    L, P = ut.lmi_gain(A1, plant.C, D=plant.D, dt=plant.dt, solver=solver)
    np.testing.assert_allclose(L, DT_CASE_STUDY_PUBLISHED.L, atol=1e-4)


# --- Practical Assignment 9 (document 001) -------------------------------------------------------


@pytest.fixture(scope="module")
def pa9_printed_design():
    return ut.design_uio(ut.examples.pa9(), K1=PA9_PUBLISHED.K1)


def chopped(x, decimals=2):
    """Practical Assignment 9 prints its matrices cut (truncated toward zero), not rounded:
    H[0, 1] = 4/17 = 0.2353 is printed 0.23 and H[2, 1] = 1/17 = 0.0588 is printed 0.05."""
    f = 10.0**decimals
    return np.trunc(np.asarray(x, float) * f) / f + 0.0


def test_pa9_H_T_as_printed(pa9_printed_design):
    np.testing.assert_array_equal(chopped(pa9_printed_design.H), PA9_PUBLISHED.H)
    np.testing.assert_array_equal(chopped(pa9_printed_design.T), PA9_PUBLISHED.T)


def test_pa9_printed_H_T_are_not_rounded(pa9_printed_design):
    """Rounding would give 0.24 and 0.06: the document chops."""
    assert printed(pa9_printed_design.H, 2)[0, 1] == 0.24
    assert PA9_PUBLISHED.H[0, 1] == 0.23


def _interval(entry_fn, K1p, cell=0.01):
    """Range of a linear function of K1 when each entry of the true K1 lies in its
    chopping cell: between the printed value and the printed value + 0.01 away from 0."""
    direction = np.where(K1p >= 0, 1.0, -1.0)
    center = K1p + 0.5 * cell * direction
    value = entry_fn(center)
    spread = 0.0
    for idx in np.ndindex(K1p.shape):
        dK = np.zeros_like(K1p)
        dK[idx] = 1.0
        spread += abs(entry_fn(center + dK) - value) * 0.5 * cell
    return value - spread, value + spread


@pytest.mark.parametrize("name", ["F", "K2"])
def test_pa9_F_K2_consistent_with_printed_K1(name):
    """F = TA - K1 C and K2 = F H from the printed K1 agree with the printed F and K2.

    Both the printed K1 and the printed F, K2 are chopped to 2 decimals, so each
    printed entry must be reachable: for the true K1 somewhere in the chopping
    cells of the printed K1, the exact entry chops to the printed value. This is
    an interval check, entry by entry, of a function linear in K1.
    """
    plant = ut.examples.pa9()
    K1p = np.array(PA9_PUBLISHED.K1)
    target = np.array(getattr(PA9_PUBLISHED, name))

    def matrix(K1):
        return getattr(ut.design_uio(plant, K1=K1), name)

    for idx in np.ndindex(target.shape):
        lo, hi = _interval(lambda K1, idx=idx: matrix(K1)[idx], K1p)
        printed_cell = sorted([target[idx], target[idx] + (0.01 if target[idx] >= 0 else -0.01)])
        if target[idx] == 0:  # chopped to zero: |value| < 0.01
            printed_cell = [-0.01, 0.01]
        slack = roundoff(max(abs(lo), abs(hi), 1.0), terms=9)  # the range's own rounding
        assert lo <= printed_cell[1] + slack and hi >= printed_cell[0] - slack, (
            f"{name}{idx}: printed {target[idx]} is not reachable; exact range [{lo:.4f}, {hi:.4f}]"
        )
    # and directly, to the printed precision: within one unit of the last printed digit
    # from the chopped K1, and two where chopping K1 and F add up
    np.testing.assert_allclose(matrix(K1p), target, atol=0.02)


def test_pa9_printed_K1_places_the_printed_poles(pa9_printed_design):
    # MATLAB's place put the poles at -1, -2, -3; the 2-decimal K1 moves them by < 0.01
    np.testing.assert_allclose(pa9_printed_design.poles().real, [-3, -2, -1], atol=0.01)


def test_pa9_decoupling_identities(pa9_printed_design):
    o, pl = pa9_printed_design, pa9_printed_design.plant
    # products of 3-by-3 factors, H from a solve with C E: zero to their rounding
    gain = np.linalg.cond(pl.C @ pl.E)
    eye = np.eye(3)
    assert_zero(
        (eye - o.H @ pl.C) @ pl.E, eye + np.abs(o.H) @ np.abs(pl.C), pl.E, terms=3, gain=gain
    )
    np.testing.assert_allclose(pl.C @ pl.E @ np.linalg.pinv(pl.C @ pl.E) @ pl.C @ pl.E, pl.C @ pl.E)
    assert_zero(o.K2 - o.F @ o.H, o.F, o.H, terms=3)
    # B - TB - HCB = 0
    assert_zero(
        o.T @ pl.B + o.H @ pl.C @ pl.B - pl.B,
        eye + np.abs(o.T) + np.abs(o.H) @ np.abs(pl.C),
        pl.B,
        terms=3,
        gain=gain,
    )


def test_pa9_poles_placed_exactly_with_a_different_K1():
    """python-control/scipy place the same poles with another K1.

    Multi-output pole placement is not unique: with p = 2 outputs there is a
    family of gains giving eig(TA - K1 C) = {-1, -2, -3}. MATLAB's ``place`` and
    scipy's ``place_poles`` (Kautsky-Nichols-Van Dooren, YT variant) pick
    different members, so K1 (and F, K2) differ from the printed ones while the
    poles are the same.
    """
    o = ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3])
    tol = eigenvalue_roundoff(o.F)
    np.testing.assert_allclose(o.poles().real, [-3, -2, -1], atol=tol)
    np.testing.assert_allclose(o.poles().imag, 0, atol=tol)
    assert not np.allclose(o.K1, PA9_PUBLISHED.K1, atol=0.01)
    np.testing.assert_array_equal(chopped(o.H), PA9_PUBLISHED.H)


# --- Missile autopilot (document 002) ------------------------------------------------------------


def test_missile_conditions_hold():
    report = ut.check_existence(ut.examples.missile_autopilot())
    assert report.ok
    assert report["rank condition"].holds


def test_missile_fixed_poles_are_the_invariant_zeros():
    report = ut.check_existence(ut.examples.missile_autopilot())
    expected = np.array([-105.6 - 142.09j, -105.6 + 142.09j])

    def by_imag(z):
        return z[np.argsort(z.imag)]

    np.testing.assert_allclose(by_imag(report.invariant_zeros), expected, atol=0.005)
    np.testing.assert_allclose(by_imag(report.fixed_modes), by_imag(report.invariant_zeros))
    # closed form: (I - E (CE)^-1 C) A restricted to the actuator states is
    # [[4.8, 1], [-32378.4, -216]], so the zeros are the roots of s^2 + 211.2 s + 31341.6
    z = by_imag(report.invariant_zeros)
    # both to the backward error of their eigenvalue problems, the closed form's 2-by-2 one and
    # the Rosenbrock pencil's (A's entries reach 3e4), times the zeros' conditioning
    closed = np.array([[4.8, 1.0], [-32378.4, -216.0]])
    A = ut.examples.missile_autopilot().A
    atol = eigenvalue_roundoff(closed) * max(1.0, np.linalg.norm(A, 2) / np.linalg.norm(closed, 2))
    np.testing.assert_allclose(z, by_imag(np.roots([1, 211.2, 31341.6])), rtol=0, atol=atol)


@pytest.mark.parametrize("Mv", [None, MISSILE_PUBLISHED.Mv, np.ones((4, 2))])
def test_missile_M_is_E_CE_inverse_whatever_Mv(Mv):
    plant = ut.examples.missile_autopilot()
    pmo = ut.design_pmo(plant, poles=[-100, -120], Mv=Mv)
    # two solves with C E (cond ~1e2 in these units): equal to their rounding
    reference = plant.E @ np.linalg.inv(plant.C @ plant.E)
    gain = np.linalg.cond(plant.C @ plant.E)
    assert_rounding_close(pmo.M, reference, size=size_of(reference), terms=4, gain=gain)


def test_missile_pmo_structural_identities():
    plant = ut.examples.missile_autopilot()
    pmo = ut.design_pmo(plant, poles=[-100, -120])
    A, C, E = plant.A, plant.C, plant.E
    # (I - MC) E = 0, eq. (18), to the rounding of M = E (CE)^-1 and the products
    assert_zero(pmo.projection @ E, pmo.projection, E, terms=4, gain=np.linalg.cond(C @ E))
    np.testing.assert_allclose(pmo.A1, (np.eye(4) - pmo.M @ C) @ A)
    np.testing.assert_allclose(pmo.F, pmo.A1 - pmo.L @ C)
    G = (np.eye(4) - pmo.M @ C) @ A @ pmo.M + pmo.L - pmo.L @ C @ pmo.M  # eq. (13)
    # the same sum of 4-term products in another order; A's entries reach 3e4
    size = size_of(A) * size_of(pmo.M) + size_of(pmo.L) * (1 + size_of(C @ pmo.M))
    assert_rounding_close(pmo.G, G, size=size, terms=16, gain=np.linalg.cond(C @ E))
    poles = pmo.poles()
    real = np.abs(poles.imag) <= eigenvalue_roundoff(pmo.F)  # real up to the eigensolver's rounding
    np.testing.assert_allclose(np.sort(poles[real].real), [-120, -100])


def test_missile_ginverse_structural_identities():
    plant = ut.examples.missile_autopilot()
    g = ut.design_ginverse(plant, Kv=np.arange(8.0).reshape(4, 2))
    A, C, E = plant.A, plant.C, plant.E
    Pc = np.eye(4) - np.linalg.pinv(C) @ C
    # eq. (20): (I - Cg C) E - Kg C E = 0
    gain = np.linalg.cond(C) * np.linalg.cond(C @ E)  # Pc from pinv(C), Kg from a solve with CE
    assert_zero(Pc @ E - g.Kg @ C @ E, np.eye(4) + np.abs(g.Kg) @ np.abs(C), E, terms=4, gain=gain)
    # Pc is the orthogonal projection: symmetric and idempotent
    np.testing.assert_allclose(Pc, Pc.T)
    np.testing.assert_allclose(Pc @ Pc, Pc)
    # CE invertible => Cv = 0 and Kv has no effect
    # Cv = (I - CE (CE)^g) C A Pc: zero to the rounding of the products and of (CE)^g
    assert_zero(
        g.Cv, np.eye(2) + np.abs(C @ E) @ np.abs(np.linalg.pinv(C @ E)), C, A, terms=4, gain=gain
    )
    g0 = ut.design_ginverse(plant)
    assert_rounding_close(g.Kg, g0.Kg, terms=4, gain=gain)  # Kv does not enter Kg
    assert_rounding_close(  # G does not depend on Kv either (Cv = 0): products with A, ~3e4
        g.realization().B_y,
        g0.realization().B_y,
        size=size_of(A) * size_of(g.Kg),
        terms=16,
        gain=gain,
    )
    np.testing.assert_allclose(g.poles(), [-105.6 - 142.0924j, -105.6 + 142.0924j], atol=1e-3)
    # the measured states are read from y: C xhat = y
    D_y, C_o = g.realization().D_y, g.realization().C
    assert_zero(C @ D_y - np.eye(2), np.eye(2) + np.abs(C) @ np.abs(D_y), terms=4, gain=gain)
    assert_zero(C @ C_o, C, C_o, terms=4, gain=gain)
    del A


def test_missile_actuator_reading():
    """The read-back actuator rows: natural frequency 180 rad/s, damping 0.6."""
    A = ut.examples.missile_autopilot().A
    wn = np.sqrt(-A[3, 2])
    assert wn == pytest.approx(180)
    assert -A[3, 3] / (2 * wn) == pytest.approx(0.6)


def test_case_study_rounded_gain_is_accepted_and_projected_onto_LD_zero():
    """The printed L (4 decimals) misses L D = 0 by ~4e-5: design_pmo warns and projects it."""
    plant = ut.examples.dt_case_study()
    off = np.abs(DT_CASE_STUDY_PUBLISHED.L @ plant.D).max()
    assert 1e-5 < off < 1e-4
    with pytest.warns(UserWarning, match="L D"):
        pmo = ut.design_pmo(plant, L=DT_CASE_STUDY_PUBLISHED.L)
    assert_zero(pmo.L @ plant.D, pmo.L, plant.D, terms=3, gain=np.linalg.cond(plant.D))
    assert np.abs(pmo.L - DT_CASE_STUDY_PUBLISHED.L).max() < 4e-5
    np.testing.assert_allclose(np.sort(pmo.poles().real), [0, 0.5, 0.5], atol=1e-4)


@pytest.mark.parametrize(
    ("poles", "x34"),
    [([-60, -50], (0.084, 0.098)), ([-100, -120], (0.042, 0.060)), ([-300, -250], (0.039, 0.045))],
)
def test_missile_catch_times_of_x3_x4_depend_on_the_start_and_the_x1_pole(poles, x34):
    """Table II: from xhat(0) = 0 the x1 error leaks into x3, x4 through A1's first column, so
    their catch times follow the x1 pole; from z(0) = 0 only the fixed modes are excited."""
    plant = MISSILE.plant()
    pmo = ut.design_pmo(plant, poles=poles, Mv=MISSILE_PUBLISHED.Mv)
    A1_tol = roundoff(size_of(plant.A) * (1 + size_of(pmo.M) * size_of(plant.C)), terms=4)
    np.testing.assert_allclose(pmo.A1[2:, 0], [34.4, 154.8], atol=A1_tol)  # (I - MC) A
    t = MISSILE.timepts
    from_zero_estimate = MISSILE.simulate(pmo)  # xhat(0) = 0
    from_zero_state = MISSILE.simulate(pmo, observer_state=None)  # z(0) = 0
    catch = ut.catch_time(t, from_zero_estimate.states, from_zero_estimate.estimates, tol=0.02)
    np.testing.assert_allclose(catch[2:], x34, atol=0.0015)
    catch0 = ut.catch_time(t, from_zero_state.states, from_zero_state.estimates, tol=0.02)
    np.testing.assert_allclose(catch0[2:], [0.051, 0.058], atol=0.0015)
