"""Benchmark: observer design at size, against scipy/python-control's placement in one process.

Run with ``python benchmarks/bench_design.py``. Each row designs the decoupling UIO of a random
plant (``n`` states, ``p`` outputs, two unknown inputs) with :func:`uio_teach.design_uio`, which
checks existence in balanced units, places the movable poles and verifies the observer, and times
the bare placement step the way python-control does it (``control.place`` on the same pair
``(T A, C)``, scipy's YT method with its default 30 sweeps). Both are measured as process CPU time
in this process, median of a few repeats, so the ratio holds on a busy machine; the absolute
seconds do not. The poles are the pair's own eigenvalues mirrored into the left half-plane and
shifted by 0.5 (a well-posed placement); the accuracy column is the largest relative distance
between requested and obtained poles of the designed observer, the leak column the unknown input's
gain to the estimation error over its gain to the state that the design's own check reports (from
the returned matrices). BLAS keeps its default threads: the designs limit them to one around their
small-matrix loops themselves, as a user's call would.
"""

from __future__ import annotations

import argparse
import time
import warnings

import control as ct
import numpy as np

import uio_teach as ut

SIZES = ((40, 6), (60, 8), (80, 10))


def _plant(n: int, p: int, seed: int = 1) -> ut.Plant:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    return ut.Plant(A, rng.standard_normal((p, n)), E=rng.standard_normal((n, 2)))


def _cpu(call, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.process_time()
        call()
        times.append(time.process_time() - start)
    return float(np.median(times))


def _row(n: int, p: int, repeats: int, reference: bool) -> str:
    plant = _plant(n, p)
    dec = ut.existence.decoupling(plant)
    lam = np.linalg.eigvals(dec.A1)
    poles = -np.abs(lam.real) - 0.5 + 1j * lam.imag
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        obs = ut.design_uio(plant, poles=poles)
        leak = obs.leak.bound
        ours = _cpu(lambda: ut.design_uio(plant, poles=poles), repeats)
        got = np.sort_complex(obs.poles())
        want = np.sort_complex(poles)
        acc = float(np.max(np.abs(got - want) / np.maximum(1.0, np.abs(want))))
        if reference:
            theirs = _cpu(lambda: ct.place(dec.A1.T, plant.C.T, poles), 1)
            ratio = f"{theirs / ours:9.1f}x"
            ref = f"{theirs:10.2f}"
        else:
            ratio, ref = "        -", "         -"
    return f"| {n:3d} | {p:2d} | {ours:8.2f} | {ref} | {ratio} | {acc:8.1e} | {leak:8.1e} |"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument(
        "--no-reference", action="store_true", help="skip control.place (slow at n = 40)"
    )
    args = parser.parse_args(argv)
    print("| n   | p  | design_uio [s CPU] | control.place [s CPU] | ratio | pole error | leak |")
    print("|-----|----|----------|------------|-----------|----------|----------|")
    for n, p in SIZES:
        print(_row(n, p, args.repeats, not args.no_reference), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
