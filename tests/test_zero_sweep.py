"""Plants with invariant zeros placed exactly, in random coordinates: verdicts and designs judged.

Each plant is built in coordinates where its zeros are known exactly,
``A = [[Z, A12], [E2 G, A22]]``, ``E = [0; E2]``, ``C = [0, C2]`` (the zeros are the
eigenvalues of ``Z``: a change of unknown input ``d -> d + G xi`` makes the Rosenbrock matrix
block triangular), and then written in random coordinates (orthogonal, or of condition
``1e3``-``1e6``) with outputs and unknown inputs in random units. Families: a fast zero
(``1e3``-``1e6`` times the poles) on either side of the stability boundary, a slow one, a lightly
damped pair, none.

Judged:

* the existence verdict against the zeros placed: right, or "cannot be decided at this
  precision"; never a confident wrong verdict;
* every returned design on its own matrices, in exact rational arithmetic: the residuals of the
  observer's defining identities (``theta A - F theta - K C``, ``theta E`` and
  ``I - Dy C - Co theta``, with ``theta = I - Dy C`` for the UIO and the PMO) are formed in
  exact rational (dyadic integer) arithmetic from the returned floating-point matrices, and the
  unknown input's gain to the estimation error follows from them. A design returned without a
  warning leaks less than ``LEAK_RTOL`` of the state's response, a warned one less than
  ``LEAK_REFUSE``.

A quick sample runs in the suite; ``python tests/test_zero_sweep.py --cases 2000`` runs the
sweep and prints the table by family.
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np
import pytest

import uio_teach as ut
from uio_teach.verify import LEAK_REFUSE, LEAK_RTOL, DecouplingWarning, PlacementAccuracyError

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import zero_families  # noqa: E402

FAMILIES = (
    "fast unstable",
    "fast stable",
    "slow unstable",
    "slow stable",
    "lightly damped unstable",
    "lightly damped stable",
    "no zero",
)
COORDINATES = ("orthogonal", "cond 1e3", "cond 1e6")


def _zeros(family: str, rng: np.random.Generator) -> list[complex]:
    if family.startswith("fast"):
        z = 10.0 ** rng.uniform(3, 6)
        return [z if family.endswith("unstable") else -z]
    if family.startswith("slow"):
        z = rng.uniform(0.1, 3.0)
        return [z if family.endswith("unstable") else -z]
    if family.startswith("lightly"):
        w, zeta = rng.uniform(0.5, 5.0), rng.uniform(0.01, 0.05)
        re = zeta * w if family.endswith("unstable") else -zeta * w
        return [complex(re, w), complex(re, -w)]
    return []


def _orthogonal(n: int, rng: np.random.Generator) -> np.ndarray:
    Q, R = np.linalg.qr(rng.standard_normal((n, n)))
    return Q * np.sign(np.diag(R))


def build(family: str, coordinates: str, seed: int) -> tuple[ut.Plant, np.ndarray]:
    """A plant with the family's zeros placed exactly, and those zeros."""
    rng = np.random.default_rng(seed)
    zeros = _zeros(family, rng)
    k = len(zeros)
    q = int(rng.integers(1, 3))
    m = int(rng.integers(max(q, 2), 6))  # states outside the zero dynamics
    n = k + m
    # outputs: square (p = q = m) or more outputs than unknown inputs (generically no more zeros)
    p = q if (m == q and rng.random() < 0.5) else int(rng.integers(q + 1, m + 2))
    Z = np.zeros((k, k))
    if k == 1:
        Z[0, 0] = zeros[0].real
    elif k == 2:
        re, im = zeros[0].real, zeros[0].imag
        Z[:] = [[re, im], [-im, re]]
    A = np.zeros((n, n))
    A[:k, :k] = Z
    A[:k, k:] = rng.standard_normal((k, m))
    A[k:, k:] = rng.standard_normal((m, m))
    A[k : k + q, :k] = rng.standard_normal((q, k))  # E2 G: d enters the zero dynamics' coupling
    E = np.zeros((n, q))
    E[k : k + q] = np.eye(q)
    C = np.zeros((p, n))
    C[:, k:] = rng.standard_normal((p, m))
    if rng.random() < 0.5 and q:
        # poles near -1 by a feedback through the unknown input's channel (only rows k..k+q
        # change, so the zeros stay exactly where they are): the "fast zero, slow poles"
        import scipy.signal as ssig

        try:
            target = -(0.5 + rng.random(n))
            G = ssig.place_poles(A, E, target).gain_matrix
            A[k : k + q] -= G
        except (ValueError, np.linalg.LinAlgError):
            pass
    if coordinates == "orthogonal":
        S = _orthogonal(n, rng)
    else:
        c = 1e3 if coordinates == "cond 1e3" else 1e6
        S = _orthogonal(n, rng) @ np.diag(np.logspace(0, np.log10(c), n)) @ _orthogonal(n, rng)
    Si = np.linalg.inv(S)
    A, E, C = Si @ A @ S, Si @ E, C @ S
    C = (10.0 ** rng.uniform(-2, 2, p))[:, None] * C
    E = E * (10.0 ** rng.uniform(-2, 2, q))[None, :]
    B = rng.standard_normal((n, 1))
    return ut.Plant(A, C, B=B, E=E), np.array(zeros, complex)


# exact judgement: the rational-arithmetic judge of the benchmark's families, which evaluates at
# DC and at every mode's own rate and skips only points on an eigenvalue to round-off
exact_leak = zero_families.exact_leak


def why(call) -> str:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            call()
    except Exception as exc:  # noqa: BLE001 - only for the printed table
        return str(exc)[:240]
    return ""


# one case -----------------------------------------------------------------------------------
def _design(call):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            obs = call()
        except (PlacementAccuracyError, ut.UIOExistenceError, ValueError) as exc:
            return None, "refused: " + type(exc).__name__, False
    warned = any(issubclass(w.category, DecouplingWarning) for w in caught)
    return obs, "returned", warned


def _poles(report: ut.ExistenceReport) -> np.ndarray:
    k = report.movable
    poles = -np.linspace(1.0, 3.0, k) if k > 1 else -np.ones(k)
    for z in report.fixed_modes:  # keep the requested poles off the fixed modes
        poles = np.where(np.abs(poles - z) < 0.05 * max(1.0, abs(z)), poles - 0.1, poles)
    return poles


@ut.linalg.one_blas_thread()
def run_case(
    family: str, coordinates: str, seed: int, lmi: bool = False, verbose: bool = False
) -> dict:
    """Verdict and designs of one plant, judged; a dict of outcomes."""
    plant, zeros = build(family, coordinates, seed)
    truth = bool(np.all(zeros.real < 0))
    report = ut.check_existence(plant)
    if report.ok == truth:
        verdict = "right"
    elif not report.decided and not any(c.holds is False for c in report.conditions if c.required):
        verdict = "undecided"
    else:
        verdict = "WRONG"
    out = {"verdict": verdict, "designs": [], "leaks": []}
    if not report.ok:
        return out
    calls = {
        "uio": lambda: ut.design_uio(plant, poles=_poles(report)),
        "pmo": lambda: ut.design_pmo(plant, poles=_poles(report)),
    }
    if ut.linalg.rank(plant.C) == plant.p:
        calls["ginverse"] = lambda: ut.design_ginverse(plant)
    if lmi:
        calls["pmo lmi"] = lambda: ut.design_pmo(plant, method="lmi")
    for name, call in calls.items():
        obs, status, warned = _design(call)
        if obs is None and verbose:
            print(family, coordinates, seed, name, status, why(call))
        out["designs"].append((name, status if obs is None else ("warned" if warned else "silent")))
        if obs is not None:
            leak = exact_leak(plant, obs)
            limit = LEAK_REFUSE if warned else LEAK_RTOL
            out["leaks"].append((name, leak, leak <= limit))
    return out


def sweep(
    cases: int, lmi_every: int = 50, verbose: bool = False, part: tuple[int, int] = (0, 1)
) -> tuple[dict, list]:
    """Run ``cases`` plants (every ``part[1]``-th from ``part[0]``: one of several processes)."""
    table: dict = defaultdict(Counter)
    bad = []
    i = 0
    while i < cases:
        for family in FAMILIES:
            for coordinates in COORDINATES:
                if i >= cases:
                    break
                if i % part[1] != part[0]:
                    i += 1
                    continue
                res = run_case(family, coordinates, i, lmi=(i % lmi_every == 0), verbose=verbose)
                row = table[family]
                row["cases"] += 1
                row[res["verdict"]] += 1
                for _, status in res["designs"]:
                    row[
                        "designs " + ("returned" if status in ("silent", "warned") else "refused")
                    ] += 1
                    if status == "warned":
                        row["warned"] += 1
                for name, leak, ok in res["leaks"]:
                    row["max leak"] = max(row["max leak"], leak)
                    if not ok:
                        row["LEAKING"] += 1
                        bad.append((family, coordinates, i, name, leak))
                if res["verdict"] == "WRONG":
                    bad.append((family, coordinates, i, "verdict", None))
                if verbose:
                    print("CASE", json.dumps([family, coordinates, i, res]), flush=True)
                i += 1
    return table, bad


# tests ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("family", FAMILIES)
def test_quick_sample_no_wrong_verdict_no_leaking_design(family):
    for coordinates in COORDINATES:
        for seed in range(2):
            res = run_case(family, coordinates, seed=1000 + seed)
            assert res["verdict"] != "WRONG", (family, coordinates, seed)
            for name, leak, ok in res["leaks"]:
                assert ok, (family, coordinates, seed, name, leak)


def test_exact_leak_sees_a_design_that_does_not_decouple():
    # the judge itself: an observer built with the wrong H leaks, and the judge says so
    plant, _ = build("slow stable", "orthogonal", seed=3)
    obs = ut.design_uio(plant, poles=_poles(ut.check_existence(plant)))
    assert exact_leak(plant, obs) <= LEAK_RTOL
    wrong = ut.design_luenberger(ut.Plant(plant.A, plant.C), poles=-np.arange(1.0, plant.n + 1))
    assert exact_leak(plant, wrong) > 1e-3


@pytest.mark.slow
def test_sweep_of_fifty_plants_per_family():
    table, bad = sweep(7 * 3 * 50 // 3)
    assert not bad, bad[:5]


def _print(table: dict) -> None:
    cols = ("cases", "right", "undecided", "WRONG", "designs returned", "warned")
    cols += ("designs refused", "LEAKING")
    print("| family | " + " | ".join(cols) + " | max exact leak |")
    print("|---" * (len(cols) + 2) + "|")
    total: Counter = Counter()
    for family in FAMILIES:
        row = table[family]
        total.update({c: row[c] for c in cols})
        vals = " | ".join(str(row[c]) for c in cols)
        print(f"| {family} | {vals} | {row['max leak']:.1e} |")
    print("| all | " + " | ".join(str(total[c]) for c in cols) + " | |")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=210)
    parser.add_argument("--verbose", action="store_true", help="print why designs were refused")
    parser.add_argument("--part", type=int, nargs=2, default=(0, 1), metavar=("I", "OF"))
    parser.add_argument("--merge", nargs="*", help="JSON tables of parts to add up and print")
    args = parser.parse_args()
    if args.merge:
        table = defaultdict(Counter)
        for path in args.merge:
            with open(path, encoding="utf-8") as fh:
                for family, row in json.load(fh).items():
                    for key, value in row.items():
                        if key == "max leak":
                            table[family][key] = max(table[family][key], value)
                        else:
                            table[family][key] += value
        _print(table)
        raise SystemExit(0)
    table, bad = sweep(args.cases, verbose=args.verbose, part=tuple(args.part))
    print("JSON", json.dumps({k: dict(v) for k, v in table.items()}))
    _print(table)
    for b in bad:
        print("BAD", b)
