"""The existence check and the UIO design on large plants with many zeros, against AB08ND.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_large.py [--sizes 100 200 400]

Each plant has ``n`` states, ``q = 2`` unknown inputs and ``n - 2`` invariant zeros (real and
complex, stable), hidden by an orthogonal change of coordinates; a tall one has ``p = 3``
outputs. :func:`uio_teach.check_existence` (rank condition, zeros with proven disks,
detectability) and :func:`uio_teach.design_uio` are timed against SLICOT's AB08ND
(``ctrlsys``, a test-time reference: the zeros' pencil alone) on the same plant, in the same
process, with BLAS on one thread for all three (CPU time). The last line is the result as JSON.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

import uio_teach as ut


def many_zero_plant(n: int, p: int, seed: int = 0) -> tuple[ut.Plant, np.ndarray]:
    """``n`` states, two unknown inputs, the ``n - 2`` zeros returned, orthogonal coordinates."""
    rng = np.random.default_rng(seed)
    q, k = 2, n - 2
    pairs = k // 4
    re = -rng.uniform(0.2, 3.0, k - 2 * pairs)
    J = np.zeros((k, k))
    J[: re.size, : re.size] = np.diag(re)
    zeros = list(re)
    for i in range(pairs):
        a, b = -rng.uniform(0.2, 2.0), rng.uniform(0.5, 3.0)
        j = re.size + 2 * i
        J[j : j + 2, j : j + 2] = [[a, b], [-b, a]]
        zeros += [a + 1j * b, a - 1j * b]
    A = np.zeros((n, n))
    A[:k, :k] = J
    A[:k, k:] = rng.standard_normal((k, q))
    A[k:, :k] = rng.standard_normal((q, k)) / np.sqrt(k)
    A[k:, k:] = -2 * np.eye(q)
    E = np.zeros((n, q))
    E[k:] = np.eye(q)
    C = np.zeros((p, n))
    C[:, k:] = rng.standard_normal((p, q)) + 2 * np.eye(p, q)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    return ut.Plant(Q.T @ A @ Q, C @ Q, E=Q.T @ E), np.array(zeros, complex)


def ab08nd(plant: ut.Plant) -> int:
    import ctrlsys

    def f(M):
        return np.array(M, dtype=float, order="F", copy=True)

    n, q, p = plant.n, plant.q, plant.p
    return int(
        ctrlsys.ab08nd("S", n, q, p, f(plant.A), f(plant.E), f(plant.C), f(np.zeros((p, q))))[0]
    )


def timed(fun, *args, **kwargs):
    start = time.process_time()
    out = fun(*args, **kwargs)
    return time.process_time() - start, out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 200, 400])
    args = parser.parse_args(argv)
    rows = []
    print(
        "| n | p | zeros | verdict | zeros found | AB08ND's count | check_existence (s) | "
        "design_uio (s) | AB08ND (s) | check / AB08ND | design / AB08ND |"
    )
    print("| ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    with threadpool_limits(1):
        for n in args.sizes:
            for p in (2, 3):
                plant, zeros = many_zero_plant(n, p)
                # the reference is fast: the median of 5 calls, so one call's timer noise
                # does not make the ratio
                refs = [timed(ab08nd, plant) for _ in range(5)]
                t_ref, count = float(np.median([t for t, _ in refs])), refs[0][1]
                t_check, report = timed(ut.check_existence, plant)
                t_design = float("nan")
                if report.ok:
                    poles = -np.linspace(4.0, 5.0, report.movable)
                    t_design, _ = timed(ut.design_uio, plant, poles=poles)
                row = dict(
                    n=n,
                    p=p,
                    zeros=int(zeros.size),
                    verdict=report.verdict,
                    found=int(report.invariant_zeros.size),
                    ab08nd_count=count,
                    check=t_check,
                    design=t_design,
                    ab08nd=t_ref,
                )
                rows.append(row)
                print(
                    f"| {n} | {p} | {zeros.size} | {report.verdict} | {row['found']} | {count} | "
                    f"{t_check:.2f} | {t_design:.2f} | {t_ref:.3f} | "
                    f"{t_check / t_ref:.1f} | {t_design / t_ref:.1f} |",
                    flush=True,
                )
    print(json.dumps(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
