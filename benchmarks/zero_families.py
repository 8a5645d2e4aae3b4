"""Constructed plants whose invariant zeros are known exactly, and an exact judge of a design.

Each plant has states ``x = [x_z; x_r]``: the unknown inputs enter ``x_r`` only (``E = [0; I]``)
and the outputs see ``x_r`` only (``C = [0, C_r]``, ``C_r`` of full column rank), so the zeros
are exactly the eigenvalues of the block ``J`` that drives ``x_z`` (a Jordan block for a
defective zero), with its multiplicities, and there are exactly as many. The poles are then
placed by feedback through the unknown input (rows of ``x_r`` only), which moves no zero. The
coordinates are the built ones ("plain") or an orthogonal change of them ("orthogonal", which
rounds the data). Used by ``benchmarks/bench_decisions.py`` and ``tests/test_decision_rule.py``.

Examples
--------
>>> from zero_families import build
>>> case = build("defective", 0)
>>> case.plant.n, len(case.zeros), case.truth
(5, 3, 'exists')
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np
import scipy.signal as ssig

import uio_teach as ut

FAMILIES = ("fast", "slow", "repeated", "defective", "boundary", "discrete", "time-scaled")
"""The families of the benchmark's table."""


class Case(NamedTuple):
    """One constructed plant: the plant, its exact zeros, the true verdict, how it was made."""

    plant: ut.Plant
    zeros: np.ndarray
    truth: str  # "exists", "no" or "boundary" (a zero exactly on the stability boundary)
    label: str


def _jordan(z: float, k: int) -> np.ndarray:
    return z * np.eye(k) + np.diag(np.ones(k - 1), 1)


def _truth(zeros: np.ndarray, discrete: bool) -> str:
    dist = np.abs(zeros) - 1.0 if discrete else zeros.real
    if np.any(dist > 0):
        return "no"
    if np.any(dist == 0):
        return "boundary"
    return "exists"


def plant_with_zeros(
    J: np.ndarray,
    rng: np.random.Generator,
    *,
    q: int = 1,
    p: int | None = None,
    dt: float | None = None,
    pole_scale: float = 1.0,
    orthogonal: bool = False,
) -> ut.Plant:
    """A plant whose invariant zeros from ``d`` to ``y`` are exactly ``eig(J)``."""
    k = J.shape[0]
    p = q if p is None else p
    r = max(q, 1)
    n = k + r
    A = np.zeros((n, n))
    A[:k, :k] = J
    A[:k, k:] = rng.standard_normal((k, r))
    A[k:, :k] = rng.standard_normal((r, k))
    A[k:, k:] = rng.standard_normal((r, r))
    E = np.zeros((n, q))
    E[k:, :] = np.eye(r)[:, :q]
    C = np.zeros((p, n))
    C[:, k:] = rng.standard_normal((p, r)) + np.eye(p, r) * 2
    if dt is None:
        poles = -pole_scale * (0.5 + rng.random(n))
    else:
        poles = 0.2 + 0.6 * rng.random(n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # feedback through the unknown input moves the poles, not the zeros (only x_r's rows)
        G = ssig.place_poles(A, E, poles).gain_matrix if q == r else np.zeros((q, n))
    A[k:, :] -= G
    if orthogonal:
        Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
        A, E, C = Q.T @ A @ Q, Q.T @ E, C @ Q
    return ut.Plant(A, C, E=E, dt=dt)


def build(family: str, seed: int) -> Case:
    """The ``seed``-th plant of ``family`` (deterministic)."""
    rng = np.random.default_rng([FAMILIES.index(family), seed])
    ortho = bool(seed % 2)
    tall = seed % 3 == 2
    p = 2 if tall else 1
    dt = None
    if family == "fast":  # a fast zero next to slow poles (placed through E: a large gain)
        z = [1e3, 1e5, 1e7, 1e9][seed % 4] * (-1 if seed % 5 < 3 else 1)
        J = np.array([[z]])
    elif family == "slow":
        z = [1e-4, 1e-6, 1e-8, 1e-10][seed % 4] * (-1 if seed % 5 < 3 else 1)
        J = np.array([[z, 0.0], [0.0, -0.5]])
    elif family == "repeated":
        # a zero of geometric multiplicity k needs k unknown inputs
        z = [-0.5, 0.25, -2.0, -0.02][seed % 4]
        k = 2 + seed % 2
        plant = plant_with_zeros(z * np.eye(k), rng, q=k, p=k + tall, orthogonal=ortho)
        zeros = np.full(k, z, complex)
        label = f"{family} {'orthogonal' if ortho else 'plain'} p={k + tall}"
        return Case(plant, zeros, _truth(zeros, False), label)
    elif family == "defective":
        z = [-0.5, -0.02, 0.25, -3.0][seed % 4]
        J = _jordan(z, 3 + (seed % 3 == 1))
    elif family == "boundary":
        J = np.array([[0.0, 0.0], [0.0, -1.0]])
    elif family == "discrete":
        dt = 1.0
        choice = seed % 6
        J = [
            _jordan(0.98, 3),
            np.array([[1.02]]),
            np.array([[0.5, 0.0], [0.0, -0.99]]),
            np.array([[1.0 - 2.0**-26]]),
            np.array([[1.0 + 2.0**-26]]),
            np.array([[1.0]]),
        ][choice]
    elif family == "time-scaled":
        inner = FAMILIES[seed % 4]
        base = build(inner, seed // 4 + 100)
        alpha = [1e-6, 1e-3, 1e3, 1e6][seed % 4]
        pl = base.plant
        plant = ut.Plant(pl.A * alpha, pl.C, E=pl.E * alpha)
        zeros = base.zeros * alpha
        return Case(plant, zeros, base.truth, f"{base.label}, time x {alpha:g}")
    else:
        raise ValueError(f"family must be one of {FAMILIES}, got {family!r}")
    plant = plant_with_zeros(J, rng, q=1, p=p, dt=dt, orthogonal=ortho)
    zeros = np.linalg.eigvals(J) if family != "defective" else np.full(J.shape[0], J[0, 0])
    zeros = np.sort_complex(zeros.astype(complex))
    label = f"{family} {'orthogonal' if ortho else 'plain'} p={p}"
    return Case(plant, zeros, _truth(zeros, dt is not None), label)


# exact judgement of a design ------------------------------------------------------------------
class Exact:
    """A matrix of doubles held exactly, as Python integers over one power of 2."""

    def __init__(self, ints: np.ndarray, shift: int) -> None:
        self.ints, self.shift = ints, shift

    @classmethod
    def of(cls, M) -> Exact:
        M = np.atleast_2d(np.asarray(M, float))
        ratios = [x.as_integer_ratio() for x in M.ravel().tolist()]
        shift = max((d.bit_length() - 1 for _, d in ratios), default=0)
        ints = np.array([a << (shift - (d.bit_length() - 1)) for a, d in ratios], dtype=object)
        return cls(ints.reshape(M.shape), shift)

    @classmethod
    def eye(cls, n: int) -> Exact:
        return cls(np.array(np.eye(n, dtype=int), dtype=object), 0)

    def _at(self, shift: int) -> np.ndarray:
        return self.ints * (1 << (shift - self.shift))

    def __matmul__(self, other: Exact) -> Exact:
        return Exact(np.dot(self.ints, other.ints), self.shift + other.shift)

    def __sub__(self, other: Exact) -> Exact:
        shift = max(self.shift, other.shift)
        return Exact(self._at(shift) - other._at(shift), shift)

    def to_float(self) -> np.ndarray:
        den = 1 << self.shift
        return np.array([int(x) / den for x in self.ints.ravel()], float).reshape(self.ints.shape)


def exact_leak(plant: ut.Plant, obs) -> float:
    """The unknown input's largest gain to the estimation error over its largest gain to the
    state, from the exact residuals of the returned matrices, at DC, at every mode's own rate
    (a tenth and ten times it too), at every resonance and on a fine grid between."""
    real = obs.realization()
    n = plant.n
    X = Exact.of
    A, E, C = X(plant.A), X(plant.E), X(plant.C)
    Dy, F, K, Co = X(real.D_y), X(real.A), X(real.B_y), X(real.C)
    M = X(obs.Kg) if isinstance(obs, ut.GInverseObserver) else Dy
    theta = Exact.eye(n) - M @ C
    R0 = ((Exact.eye(n) - Dy @ C) - Co @ theta).to_float()
    R = ((theta @ A - F @ theta) - K @ C).to_float()
    R1 = (theta @ E).to_float()
    Af, Ef, Ff, Cof = plant.A, plant.E, real.A, real.C
    lam = np.concatenate([np.linalg.eigvals(Af), np.linalg.eigvals(Ff)])
    discrete = plant.is_discrete
    rate = np.abs(1.0 - lam) if discrete else np.abs(lam)
    rate = rate[rate > 0]
    ang = np.abs(np.angle(lam)) if discrete else np.abs(lam.imag)
    ws = np.concatenate(
        [[0.0], rate, rate / 10, rate * 10, ang, np.geomspace(rate.min() / 10, rate.max() * 10, 61)]
    )
    if discrete:
        ws = np.concatenate([ws[ws <= np.pi], np.linspace(0, np.pi, 31)])
    leak = gain = 0.0
    for w in np.unique(ws):
        s = np.exp(1j * w) if discrete else 1j * w
        if np.min(np.abs(lam - s)) <= 1e3 * n * np.finfo(float).eps * max(1.0, abs(s)):
            continue  # on an undamped mode: no transfer function there
        try:
            Xs = np.linalg.solve(s * np.eye(n) - Af, Ef)
            Ys = np.linalg.solve(s * np.eye(Ff.shape[0]) - Ff, R @ Xs + R1)
        except np.linalg.LinAlgError:
            continue
        if not (np.all(np.isfinite(Xs)) and np.all(np.isfinite(Ys))):
            continue
        gain = max(gain, float(np.linalg.norm(Xs, 2)))
        leak = max(leak, float(np.linalg.norm(R0 @ Xs + Cof @ Ys, 2)))
    return leak / gain if gain else 0.0


def slicot_zero_count(plant: ut.Plant) -> int | None:
    """The number of finite invariant zeros from ``d`` to ``y`` by SLICOT's AB08ND (ctrlsys),
    or None when ctrlsys is not installed (a test-time reference only)."""
    try:
        import ctrlsys
    except ImportError:  # pragma: no cover
        return None

    def f(M):
        return np.array(M, dtype=float, order="F", copy=True)

    n, q, p = plant.n, plant.q, plant.p
    out = ctrlsys.ab08nd("S", n, q, p, f(plant.A), f(plant.E), f(plant.C), f(np.zeros((p, q))))
    return int(out[0])


class Outcome(NamedTuple):
    """How the package did on one case."""

    verdict: str  # "right", "undecided" or "wrong"
    count_right: bool  # as many zeros as the plant has (with multiplicity)
    slicot_count: int | None
    designs: int  # designs returned
    silent_leaks: int  # designs returned (silently, or with a warning) leaking beyond their word
    report: ut.ExistenceReport


def poles_for(report: ut.ExistenceReport) -> np.ndarray:
    """Movable poles for a design: inside the region, clear of the fixed modes."""
    k = report.movable
    if report.plant.is_discrete:
        poles = np.linspace(0.1, 0.3, k) if k > 1 else np.full(k, 0.2)
    else:
        scale = max(float(np.max(np.abs(np.linalg.eigvals(report.plant.A)))), 1e-300)
        poles = -scale * (np.linspace(1.0, 2.0, k) if k > 1 else np.ones(k))
    for z in report.fixed_modes:
        poles = np.where(np.abs(poles - z) < 0.05 * np.abs(poles), poles * 1.1, poles)
    return poles


def judge(case: Case) -> Outcome:
    """Verdict, zero count and the designs of one case, judged against the exact answer."""
    from uio_teach.verify import LEAK_REFUSE, LEAK_RTOL, DecouplingWarning

    report = ut.check_existence(case.plant)
    said_no = any(c.holds is False for c in report.conditions if c.required)
    if report.ok:
        verdict = "right" if case.truth == "exists" else "wrong"
    elif said_no:
        verdict = "wrong" if case.truth == "exists" else "right"
    else:
        # a zero exactly on the boundary: round-off of the data puts it on either side, and
        # "cannot be decided" is the answer the rule gives
        verdict = "right" if case.truth == "boundary" else "undecided"
    count_right = report.invariant_zeros.size == case.zeros.size
    designs = leaks = 0
    if report.ok:
        for design in (ut.design_uio, ut.design_pmo):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                try:
                    obs = design(case.plant, poles=poles_for(report))
                except (ut.UIOExistenceError, ValueError):
                    continue
            designs += 1
            warned = any(issubclass(w.category, DecouplingWarning) for w in caught)
            if exact_leak(case.plant, obs) > (LEAK_REFUSE if warned else LEAK_RTOL):
                leaks += 1
    return Outcome(verdict, count_right, slicot_zero_count(case.plant), designs, leaks, report)
