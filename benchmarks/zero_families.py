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


# families with exact truth -------------------------------------------------------------------
# Every number below is a small dyadic rational, and every mixing of coordinates an integer
# matrix of determinant 1 applied in rational arithmetic: the doubles stored are the plant
# built, and its zeros are exactly the eigenvalues of the block J, with J's Jordan structure.

EXACT_KINDS = ("jordan", "boundary", "unimodular", "tall", "rank edge", "time units")
"""The families of the exact-truth table."""


class ExactCase(NamedTuple):
    """A plant stored exactly, its zeros (``None`` when only their side is known), the truth."""

    plant: ut.Plant
    zeros: np.ndarray | None
    truth: str  # "exists", "no" or "boundary"
    label: str


def _fr(M):
    from fractions import Fraction

    return [[Fraction(x) for x in row] for row in np.atleast_2d(np.asarray(M, float))]


def _mul(X, Y):
    from fractions import Fraction

    return (
        [
            [sum((X[i][k] * Y[k][j] for k in range(len(Y))), Fraction(0)) for j in range(len(Y[0]))]
            for i in range(len(X))
        ]
        if X and Y and Y[0]
        else [[] for _ in X]
    )


def _to_float(X) -> np.ndarray:
    out = np.array([[float(x) for x in row] for row in X], float) if X else np.zeros((0, 0))
    # exact: every rational is a double
    assert all(float(x) == x for row in X for x in row), "not exactly representable"
    return out


def _unimodular(n: int, rng: np.random.Generator, steps: int):
    """An integer matrix of determinant 1 and its integer inverse (products of shears)."""
    from fractions import Fraction

    P = [[Fraction(int(i == j)) for j in range(n)] for i in range(n)]
    Pi = [row[:] for row in P]
    for _ in range(steps):
        i, j = (int(v) for v in rng.choice(n, 2, replace=False))
        k = int(rng.choice([-2, -1, 1, 2]))
        # P <- (I + k e_i e_j^T) P ; Pi <- Pi (I - k e_i e_j^T)
        P[i] = [a + k * b for a, b in zip(P[i], P[j], strict=True)]
        for row in Pi:
            row[j] = row[j] - k * row[i]
    return P, Pi


def _exact_plant(J, rng, *, q, p, dt, mix_steps, time_exp=0):
    """The plant of ``zero_families.plant_with_zeros``' form, stored exactly."""
    k = J.shape[0]
    n = k + q
    A = np.zeros((n, n))
    A[:k, :k] = J
    A[:k, k:] = rng.integers(-4, 5, (k, q)) / 4
    A[k:, :k] = rng.integers(-4, 5, (q, k)) / 4
    A[k:, k:] = rng.integers(-4, 5, (q, q)) / 4 - (0 if dt else 2 * np.eye(q))
    E = np.zeros((n, q))
    E[k:] = np.eye(q)
    C = np.zeros((p, n))
    C[:, k:] = rng.integers(-2, 3, (p, q)) + 2 * np.eye(p, q)
    if np.linalg.matrix_rank(C[:, k:]) < q:
        C[:q, k:] += 4 * np.eye(q)
    if mix_steps:
        P, Pi = _unimodular(n, rng, mix_steps)
        A = _to_float(_mul(_mul(P, _fr(A)), Pi))
        E = _to_float(_mul(P, _fr(E)))
        C = _to_float(_mul(_fr(C), Pi))
    f = 2.0**time_exp
    return ut.Plant(A * f, C, E=E * f, dt=dt)


def _truth_of(zeros: np.ndarray, discrete: bool) -> str:
    # the zeros are dyadic rationals or exact multiples of i: their side is exact
    return _truth(zeros, discrete)


def _zero_block(rng, discrete: bool, boundary: bool, kmax: int = 6):
    """A block J of Jordan blocks with dyadic eigenvalues (or exactly on the boundary)."""
    blocks, zeros = [], []
    size = 0
    while size < 2 or (size < kmax and rng.random() < 0.5):
        k = int(rng.integers(1, kmax - size + 1))
        if boundary and not blocks:
            if discrete:
                z = float(rng.choice([1.0, -1.0]))
            else:
                z = 0.0
            if rng.random() < 0.3 and kmax - size >= 2:
                # a pair exactly on the boundary: +-i (discrete) or +-2i (continuous)
                w = 1.0 if discrete else 2.0
                blocks.append(np.array([[0.0, w], [-w, 0.0]]))
                zeros += [1j * w, -1j * w]
                size += 2
                continue
        else:
            pool = [-0.5, 0.25, 0.5, -0.75, 1.5] if discrete else [-1.0, -0.5, -2.0, 0.5, 1.0]
            z = float(rng.choice(pool))
        blocks.append(_jordan(z, k))
        zeros += [z] * k
        size += k
    J = np.zeros((size, size))
    at = 0
    for b in blocks:
        J[at : at + b.shape[0], at : at + b.shape[0]] = b
        at += b.shape[0]
    return J, np.array(zeros, complex)


def build_exact(kind: str, seed: int) -> ExactCase:
    """The ``seed``-th plant of an exact-truth family (deterministic)."""
    rng = np.random.default_rng([100 + EXACT_KINDS.index(kind), seed])
    discrete = bool(seed % 2)
    dt = 1.0 if discrete else None
    q = 1 + int(seed % 5 == 4)
    if kind == "rank edge":
        # C E = 2^-e exactly (or 0): n = 2, one zero, computed exactly from the data
        from fractions import Fraction

        e = [48, 49, 50, 51, 52, None][seed % 6]
        eps = 0.0 if e is None else 2.0**-e
        a, b, c, d = (rng.integers(-4, 5, 4) / 4).tolist()
        if not discrete:
            a, d = a - 2, d - 2
        A = np.array([[a, b], [c, d]])
        E = np.array([[1.0], [-1.0 + eps]])
        plant = ut.Plant(A, [[1.0, 1.0]], E=E, dt=dt)
        if e is None:
            return ExactCase(plant, np.zeros(0, complex), "no", "rank edge C E = 0")
        F = Fraction
        e2 = F(-1.0 + eps)
        z = -((F(c) - F(d)) + (F(b) - F(a)) * e2) / (1 + e2)
        zeros = np.array([complex(float(z))])
        if discrete:
            truth = "no" if abs(z) > 1 else ("boundary" if abs(z) == 1 else "exists")
        else:
            truth = "no" if z > 0 else ("boundary" if z == 0 else "exists")
        return ExactCase(plant, zeros, truth, f"rank edge C E = 2^-{e}")
    boundary = kind == "boundary"
    J, zeros = _zero_block(rng, discrete, boundary, kmax=6)
    p = q + (1 + int(seed % 3 == 0) if kind == "tall" else 0)
    steps = {"unimodular": 6 + seed % 10, "boundary": seed % 8, "tall": seed % 6}.get(kind, 0)
    if kind == "jordan":
        steps = 2 * (seed % 4)
    time_exp = 0
    if kind == "time units" and not discrete:
        time_exp = int([-27, -13, 0, 13, 27][seed % 5])
        zeros = zeros * 2.0**time_exp
    plant = _exact_plant(J, rng, q=q, p=p, dt=dt, mix_steps=steps, time_exp=time_exp)
    label = f"{kind} {'discrete' if discrete else 'continuous'} n={plant.n} p={p} q={q}"
    return ExactCase(plant, np.sort_complex(zeros), _truth_of(zeros, discrete), label)


def said(report: ut.ExistenceReport) -> str:
    """The report's verdict as "exists", "no" or "undecided"."""
    if report.ok:
        return "exists"
    if any(c.holds is False for c in report.conditions if c.required):
        return "no"
    return "undecided"


def confidently_wrong(verdict: str, truth: str) -> bool:
    """A decided verdict the exact truth contradicts (a zero on the boundary makes "no" true)."""
    if verdict == "exists":
        return truth != "exists"
    if verdict == "no":
        return truth == "exists"
    return False


def ab08nd_verdict(plant: ut.Plant):
    """AB08ND's zeros (ctrlsys) and the verdict their signs give, or (None, None)."""
    try:
        import ctrlsys
    except ImportError:  # pragma: no cover
        return None, None

    def f(M):
        return np.array(M, dtype=float, order="F", copy=True)

    n, q, p = plant.n, plant.q, plant.p
    out = ctrlsys.ab08nd("S", n, q, p, f(plant.A), f(plant.E), f(plant.C), f(np.zeros((p, q))))
    nz = int(out[0])
    # the finite zeros: generalized eigenvalues of the returned pencil (Af, Bf)
    zeros = np.zeros(0, complex)
    try:
        Af, Bf = np.asarray(out[8])[:nz, :nz], np.asarray(out[9])[:nz, :nz]
        import scipy.linalg as sla

        zeros = sla.eigvals(Af, Bf) if nz else zeros
    except Exception:  # pragma: no cover - layout of the wrapper's outputs
        zeros = np.full(nz, np.nan + 0j)
    if plant.is_discrete:
        ok = bool(np.all(np.abs(zeros) < 1))
    else:
        ok = bool(np.all(zeros.real < 0))
    rank_ok = np.linalg.matrix_rank(plant.C @ plant.E) == np.linalg.matrix_rank(plant.E)
    return zeros, ("exists" if ok and rank_ok else "no")
