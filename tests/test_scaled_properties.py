"""Property tests on badly scaled plants: right to the stated tolerance, or refused clearly.

The plants are similarity-scaled, ``A = S A0 S^-1``, ``C = C0 S^-1``, ``E = S E0``, with the
diagonal of ``S`` spread over 2 to 6 decades: mathematically the same system as
``(A0, C0, E0)``, numerically a much harder one. No result may be silently wrong.
"""

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.optimize import linear_sum_assignment

import uio_teach as ut
from uio_teach.verify import (
    IDENTITY_RTOL,
    WARN_RTOL,
    DecouplingWarning,
    PlacementAccuracyError,
    PlacementAccuracyWarning,
)

SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True
)


def matched_error(requested, obtained):
    requested = np.asarray(requested, complex)
    cost = np.abs(requested[:, None] - np.asarray(obtained)[None, :])
    r, c = linear_sum_assignment(cost)
    return float(np.max(cost[r, c] / np.maximum(1.0, np.abs(requested[r]))))


@st.composite
def scaled(draw, n_min=2, n_max=20, p=1, q=0):
    n = draw(st.integers(n_min, n_max))
    decades = draw(st.floats(2.0, 6.0))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    A0 = rng.standard_normal((n, n))
    C0 = rng.standard_normal((p, n))
    E0 = rng.standard_normal((n, q))
    s = 10.0 ** rng.uniform(0.0, decades, n)
    s *= 10.0**decades / s.max() if s.max() > s.min() else 1.0
    poles = -np.sort(rng.uniform(0.5, 3.0, n))
    return A0, C0, E0, s, poles


def _run(call):
    """Call; return (result, our warnings) or (None, exception) for a clear refusal."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = call()
        except (PlacementAccuracyError, ut.UIOExistenceError) as exc:
            assert str(exc)  # a message in plain words
            return None, exc
    raw = [
        w
        for w in caught
        if not issubclass(
            w.category, (PlacementAccuracyWarning, ut.UnstableObserverWarning, DecouplingWarning)
        )
    ]
    assert not raw, [str(w.message) for w in raw]  # never a raw numpy/scipy warning
    return result, [w for w in caught if w.category is PlacementAccuracyWarning]


@SETTINGS
@given(scaled())
def test_single_output_placement_is_right_or_refused(case):
    A0, C0, _, s, poles = case
    A, C = s[:, None] * A0 / s[None, :], C0 / s[None, :]
    obs, info = _run(lambda: ut.design_luenberger(ut.Plant(A, C), poles=poles))
    if obs is None:
        return
    err = matched_error(poles, np.linalg.eigvals(obs.F))
    assert err <= WARN_RTOL  # silent or warned, never badly wrong


@pytest.mark.slow
@SETTINGS
@given(scaled(n_min=3, n_max=8, p=2, q=1))
def test_uio_on_scaled_plants_decouples_or_refuses(case):
    A0, C0, E0, s, poles = case
    A, C, E = s[:, None] * A0 / s[None, :], C0 / s[None, :], s[:, None] * E0
    # make the invariant zero stable so that a UIO exists in exact arithmetic
    zeros = ut.linalg.invariant_zeros(A0, E0, C0)
    shift = max(0.0, float(np.max(zeros.real, initial=-1.0))) + 1.0
    A = A - shift * np.eye(len(s))
    plant = ut.Plant(A, C, E=E)
    report = ut.check_existence(plant)
    if not report.ok:
        return  # the verdict is a refusal in plain words
    movable = report.movable
    obs, info = _run(lambda: ut.design_uio(plant, poles=poles[:movable]))
    if obs is None:
        return
    # decoupling to the stated tolerance, relative to the factors
    scale = np.linalg.norm(obs.T, 2) * np.linalg.norm(E, 2)
    assert np.linalg.norm(obs.T @ E, 2) <= IDENTITY_RTOL * max(scale, 1.0)
    requested = np.concatenate([poles[:movable], report.fixed_modes])
    assert matched_error(requested, np.linalg.eigvals(obs.F)) <= WARN_RTOL


@SETTINGS
@given(scaled(n_min=2, n_max=8, p=1, q=1))
def test_invariant_zeros_survive_similarity_scaling(case):
    A0, C0, E0, s, _ = case
    A, C, E = s[:, None] * A0 / s[None, :], C0 / s[None, :], s[:, None] * E0
    z0 = ut.linalg.invariant_zeros(A0, E0, C0)
    z = ut.linalg.invariant_zeros(A, E, C)
    assert z.size == z0.size
    if z.size:
        # the zeros of a single-input single-output system: to 1e-6 relative to ||A0||
        tol = 1e-6 * max(1.0, np.linalg.norm(A0, 2)) * max(1.0, float(np.max(np.abs(z0))))
        assert matched_error(z0, z) * max(1.0, float(np.max(np.abs(z0)))) <= tol


@pytest.mark.slow
@SETTINGS
@given(scaled(n_min=2, n_max=6, p=1, q=0))
def test_lmi_on_scaled_pairs_is_certified_or_refused(case):
    A0, C0, _, s, _ = case
    A0 = A0 / (0.9 * max(1.0, np.max(np.abs(np.linalg.eigvals(A0)))))  # mostly stable, some not
    A, C = s[:, None] * A0 / s[None, :], C0 / s[None, :]
    try:
        L, P = ut.lmi_gain(A, C, dt=True)
    except ut.lmi.LMIError as exc:
        assert exc.status and str(exc)
        return
    assert np.max(np.abs(np.linalg.eigvals(A - L @ C))) < 1 - ut.lmi.STRICT_MARGIN
