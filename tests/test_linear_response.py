"""The simulation engine on hard matrices: defective, nearly defective, non-normal, stiff, unstable.

``linear_response`` runs the recursion ``z[k+1] = Phi z[k] + G0 s[k] + G1 s[k+1]`` as a block
scan of powers of the balanced ``Phi``, and hands a run whose powers grow too large (a fast
unstable pole) to the recursion mode by mode in balanced real Schur coordinates. The reference here
is that recursion itself, one step at a time in a Python loop with the matrices of
``foh_matrices``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

import uio_teach.simulation as sim
from uio_teach.simulation import _PAIR_COND, _real_modes, foh_matrices, linear_response

EPS = np.finfo(float).eps

# (id, A, B): every kind of eigenstructure the fast path must handle or hand over
HARD = [
    # a Jordan block of three: defective, no eigenvector basis at all
    ("jordan", [[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, -1.0]], [[0.0], [0.0], [1.0]]),
    # a double integrator beside a lightly damped pair (the missile's structure)
    (
        "integrators and a pair",
        [[0, 1, 0, 0], [0, 0, 0, 0], [0, 0, -0.5, 40.0], [0, 0, -40.0, -0.5]],
        [[0.0], [1.0], [0.0], [1.0]],
    ),
    # a complex pair split off a double pole by 1e-6: its eigenvectors are nearly parallel
    ("nearly defective pair", [[-1.0, 1.0], [-1e-12, -1.0]], [[0.0], [1.0]]),
    # a normal pair seen through a badly scaled basis (balancing undoes the scaling)
    ("badly scaled pair", [[-2.0, 1e6], [-1e-6, -2.0]], [[1.0], [1.0]]),
    # a stiff pole next to a slow oscillation, strongly coupled
    (
        "stiff and coupled",
        [[-400.0, 300.0, 50.0], [0.0, -0.1, 5.0], [0.0, -5.0, -0.1]],
        [[1.0], [0.0], [1.0]],
    ),
]


def _loop(A, B, t, S, z0, discrete):
    """The recursion, one step at a time."""
    if discrete:
        Phi, G0, G1 = A, B, np.zeros_like(B)
    else:
        Phi, G0, G1 = foh_matrices(A, B, t[1] - t[0])
    z = np.empty((A.shape[0], t.size))
    z[:, 0] = z0
    for k in range(t.size - 1):
        z[:, k + 1] = Phi @ z[:, k] + G0 @ S[:, k] + G1 @ S[:, k + 1]
    return z, Phi


def _tolerance(ref, Phi):
    """Each step rounds at the level of eps * (|Phi| |z| + |forcing|), carried by the balancing's
    condition number (or, mode by mode, at most _PAIR_COND per complex pair); N steps add up.
    The bound is that sum, times 100."""
    cond = max(_PAIR_COND, np.linalg.cond(sla.matrix_balance(Phi, permute=False)[0]))
    return 100 * ref.shape[1] * cond * EPS * np.abs(ref).max()


# 401 samples: three levels of blocks, the last ones partly filled; 4099 (a prime): four
@pytest.mark.parametrize("samples", [401, 4099])
@pytest.mark.parametrize("discrete", [False, True], ids=["continuous", "discrete"])
@pytest.mark.parametrize(("name", "A", "B"), HARD, ids=[h[0] for h in HARD])
def test_hard_matrices_follow_the_one_step_recursion(name, A, B, discrete, samples):
    A, B = np.asarray(A, float), np.asarray(B, float)
    n = A.shape[0]
    t = np.linspace(0.0, 2.0 * (samples - 1) / 400, samples)
    if discrete:
        # a stable discrete map with the same eigenstructure: I + h A scaled into the unit disc
        A = np.eye(n) + 0.01 * A / max(1.0, np.abs(np.linalg.eigvals(A)).max() / 50)
    S = np.vstack([np.sin(3 * t) + (t > 0.5)])
    z0 = np.arange(1.0, n + 1)
    z = linear_response(A, B, t, S, z0, discrete=discrete)
    ref, Phi = _loop(A, B, t, S, z0, discrete)
    tol = _tolerance(ref, Phi)
    assert np.abs(z - ref).max() <= tol, (name, np.abs(z - ref).max() / np.abs(ref).max())


def test_an_unstable_pole_within_range_runs_in_the_scan(monkeypatch):
    """An unstable observer pole whose powers stay in range: the block scan, to rounding."""
    called = []
    monkeypatch.setattr(sim, "_recursion_modes", lambda *a, **k: called.append(1))
    A = np.array([[0.5, 1.0, 0.0], [0.0, -3.0, 2.0], [0.0, 0.0, -400.0]])
    B = np.array([[0.0], [1.0], [1.0]])
    t = np.linspace(0.0, 30.0, 3001)
    S = np.vstack([np.sin(t)])
    z0 = np.array([1.0, -1.0, 0.5])
    z = linear_response(A, B, t, S, z0)
    ref, Phi = _loop(A, B, t, S, z0, False)
    assert not called
    assert np.abs(z - ref).max() <= _tolerance(ref, Phi)


def test_a_fast_unstable_pole_left_unexcited_stays_zero():
    """Powers of Phi beyond the float range: the run goes mode by mode, and a mode that nothing
    excites stays exactly zero (the scan would multiply 0 by a huge power)."""
    A = np.diag([-1.0, 50.0])
    B = np.array([[1.0], [0.0]])
    t = np.linspace(0.0, 20.0, 2001)  # exp(50 * 20) overflows
    S = np.vstack([np.sin(t)])
    z0 = np.array([1.0, 0.0])
    z = linear_response(A, B, t, S, z0)
    ref, Phi = _loop(A, B, t, S, z0, False)
    assert np.all(z[1] == 0.0)
    assert np.abs(z - ref).max() <= _tolerance(ref, Phi)


def test_a_nearly_defective_pair_takes_the_triangular_form():
    """An ill-conditioned pair is refused as a complex mode and still simulated correctly."""
    A = np.array([[-1.0, 1.0], [-1e-12, -1.0]])
    Phi, _, _ = foh_matrices(A, np.zeros((2, 1)), 0.01)
    T, _ = sla.schur(Phi, output="real")
    assert T[1, 0] != 0  # a 2 x 2 block: the pair is complex
    assert _real_modes(T) is None  # ... and too close to defective to diagonalize
    well = np.array([[-1.0, 1.0], [-1.0, -1.0]])
    T, _ = sla.schur(foh_matrices(well, np.zeros((2, 1)), 0.01)[0], output="real")
    assert _real_modes(T) is not None


def test_the_first_state_is_the_initial_state_exactly():
    A = np.array([[0.0, 1.0], [-1e4, -1.0]])
    t = np.linspace(0.0, 1.0, 101)
    z0 = np.array([0.1, 1e-17])
    z = linear_response(A, np.zeros((2, 0)), t, np.zeros((0, t.size)), z0)
    assert z[:, 0].tolist() == z0.tolist()


@pytest.mark.parametrize("discrete", [False, True], ids=["continuous", "discrete"])
def test_a_system_changed_in_place_is_not_taken_for_the_one_before(discrete):
    """The one-step matrices are kept per system and step: a matrix edited in place, or another
    step, is a new system."""
    A = np.array([[-1.0, 2.0], [0.0, -3.0]]) if not discrete else np.array([[0.9, 0.1], [0, 0.5]])
    B = np.array([[0.0], [1.0]])
    z0 = np.array([1.0, -1.0])
    for t in (np.linspace(0.0, 2.0, 201), np.linspace(0.0, 2.0, 401), np.linspace(0.0, 2.0, 401)):
        S = np.vstack([np.cos(t)])
        z = linear_response(A, B, t, S, z0, discrete=discrete)
        ref, Phi = _loop(A, B, t, S, z0, discrete)
        assert np.abs(z - ref).max() <= _tolerance(ref, Phi)
        A[0, 1] *= -0.5  # edited in place after each run
