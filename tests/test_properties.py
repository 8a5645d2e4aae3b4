"""Property tests on random plants that satisfy the existence conditions."""

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from tolerance import assert_zero

import uio_teach as ut

SETTINGS = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True
)


@st.composite
def plants(draw, discrete=False, with_D=False):
    n = draw(st.integers(2, 5))
    p = draw(st.integers(1, n))
    q = draw(st.integers(1, p))
    r = draw(st.integers(0, p - q)) if with_D else 0
    assume(q + r <= p)
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    C = rng.standard_normal((p, n))
    E = rng.standard_normal((n, q))
    D = rng.standard_normal((p, r))
    B = rng.standard_normal((n, 1))
    Ez = np.hstack([E, np.zeros((n, r))])
    Dz = np.hstack([np.zeros((p, q)), D])
    zeros = ut.linalg.invariant_zeros(A, Ez, C, Dz)
    # shift A so that every invariant zero is stable (the zeros of A - aI are zeros - a)
    if discrete:
        A = A / (
            1.2 * max(1.0, np.max(np.abs(zeros), initial=0.0), np.max(np.abs(np.linalg.eigvals(A))))
        )
    elif zeros.size:
        A = A - (max(0.0, np.max(zeros.real)) + 1.0) * np.eye(n)
    return ut.Plant(A, C, B=B, E=E, D=D if r else None, dt=1 if discrete else None)


def _pick_poles(k, discrete):
    if discrete:
        return np.linspace(-0.6, 0.6, k) if k > 1 else np.array([0.2])
    return -1.0 - 0.7 * np.arange(k)


def _close_sets(a, b, rtol):
    a, b = list(np.asarray(a, complex)), list(np.asarray(b, complex))
    if len(a) != len(b):
        return False
    for x in a:
        d = [abs(x - y) for y in b]
        i = int(np.argmin(d))
        if d[i] > rtol * max(1.0, abs(x)):
            return False
        b.pop(i)
    return True


@pytest.mark.parametrize("discrete", [False, True])
@pytest.mark.parametrize("with_D", [False, True])
def test_random_designs(discrete, with_D):
    @SETTINGS
    @given(plants(discrete=discrete, with_D=with_D))
    def check(plant):
        report = ut.check_existence(plant)
        assert report["rank condition"].holds
        assume(report.ok)
        # the fixed modes are the invariant zeros
        assert _close_sets(report.fixed_modes, report.invariant_zeros, 1e-5)
        poles = _pick_poles(report.movable, discrete)
        # a pole requested on a fixed mode is refused (tested in test_units): move off them
        while report.movable and any(
            np.min(np.abs(report.fixed_modes - p), initial=np.inf) <= 1e-3 for p in poles
        ):
            poles = poles * 1.07 + 0.01
        design = ut.design_pmo if plant.nv else ut.design_uio
        if report.movable:
            obs = design(plant, poles=poles)
        else:  # nothing to place: the observer has only its fixed modes
            obs = design(plant, **{"L" if plant.nv else "K1": np.zeros((plant.n, plant.p))})
        real = obs.realization()
        n = plant.n
        H = real.D_y
        # decoupling identities: zero to the rounding of n-term products of gains solved from
        # C E (and D): their condition numbers are the gain
        CE = plant.C @ plant.E
        cond = np.linalg.cond(np.hstack([CE, plant.D]) if plant.nv else CE)
        eye = np.eye(n)
        TE = (eye - H @ plant.C) @ plant.E
        assert_zero(TE, eye + np.abs(H) @ np.abs(plant.C), plant.E, terms=n, gain=cond)
        if plant.nv:
            assert_zero(H @ plant.D, H, plant.D, terms=n, gain=cond)
            assert_zero(obs.L @ plant.D, obs.L, plant.D, terms=n, gain=cond)
        # eq. (7) of Practical Assignment 9: A - K1 C - H C A - F = 0 and B - T B - H C B = 0
        F = obs.error_matrix
        T = np.eye(n) - H @ plant.C
        K1 = real.B_y - F @ H
        tol = 1e-8 * max(1.0, np.abs(F).max(), np.abs(K1).max())
        np.testing.assert_allclose(real.A, F)
        np.testing.assert_allclose(plant.A - K1 @ plant.C - H @ plant.C @ plant.A - F, 0, atol=tol)
        np.testing.assert_allclose(real.B_u, T @ plant.B, atol=tol)
        # poles: requested + fixed
        assert _close_sets(obs.poles(), np.concatenate([poles, report.fixed_modes]), 1e-5)

    check()


def test_luenberger_places_all_poles_of_an_observable_pair():
    @SETTINGS
    @given(st.integers(0, 2**32 - 1), st.integers(2, 5))
    def check(seed, n):
        rng = np.random.default_rng(seed)
        plant = ut.Plant(rng.standard_normal((n, n)), rng.standard_normal((2, n)))
        poles = -1.0 - np.arange(n)
        obs = ut.design_luenberger(plant, poles=poles)
        assert _close_sets(obs.poles(), poles, 1e-6)

    check()
