"""The existence verdicts and designs on constructed plants whose zeros are known exactly.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_decisions.py [--seeds N]

Each family of ``benchmarks/zero_families.py`` (fast, slow, repeated, defective, boundary,
discrete and time-scaled zeros; plain and orthogonal coordinates; one and two outputs) gives
``--seeds`` plants. Each verdict of :func:`uio_teach.check_existence` is judged against the exact
zeros: right, undecided ("cannot be decided at this precision" while the exact zeros are clear
of the boundary) or wrong; a zero exactly on the boundary is rightly undecided or "no". The zero
count is compared with the exact one and with SLICOT's AB08ND (``ctrlsys``, a reference only).
Every design returned (UIO and PMO) is judged by its exact leak (rational arithmetic, at DC,
each mode's own rate and a grid): a silent leak is one above what the design said (``LEAK_RTOL``
without a warning, ``LEAK_REFUSE`` with one). The time of ``check_existence`` is measured against
AB08ND's in the same process. The last line is the result as JSON, read by
``benchmarks/report.py``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from zero_families import FAMILIES, build, judge, slicot_zero_count  # noqa: E402

import uio_teach as ut  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=48, help="plants per family")
    args = parser.parse_args(argv)
    rows, total, notes = [], Counter(), []
    ours = slicot = 0.0
    for family in FAMILIES:
        c = Counter()
        for seed in range(args.seeds):
            case = build(family, seed)
            out = judge(case)
            c["plants"] += 1
            c[out.verdict] += 1
            if case.truth == "boundary" and not out.report.decided:
                c["boundary undecided"] += 1
            c["count right"] += out.count_right
            c["designs"] += out.designs
            c["silent leaks"] += out.silent_leaks
            if out.slicot_count is not None:
                agree = out.slicot_count == case.zeros.size
                c["slicot agrees"] += agree
                if not agree:
                    notes.append(
                        f"{case.label} (seed {seed}): {case.zeros.size} zero(s), "
                        f"uio_teach {out.report.invariant_zeros.size}, AB08ND "
                        f"{out.slicot_count}; ||A|| = {np.linalg.norm(case.plant.A, 2):.2g}"
                    )
            if out.verdict != "right":
                notes.append(f"{case.label} (seed {seed}): {out.verdict}")
            # time: the package's whole check against AB08ND's zeros alone, same process
            start = time.process_time()
            for _ in range(3):
                ut.check_existence(case.plant)
            ours += time.process_time() - start
            start = time.process_time()
            for _ in range(3):
                slicot_zero_count(case.plant)
            slicot += time.process_time() - start
        rows.append((family, c))
        total.update(c)
    head = (
        "| family | plants | right | undecided | wrong | zeros counted right | "
        "AB08ND agrees on the count | designs returned | silent leaks |"
    )
    print(head)
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for family, c in [*rows, ("all", total)]:
        print(
            f"| {family} | {c['plants']} | {c['right']} | {c['undecided']} | {c['wrong']} | "
            f"{c['count right']} | {c['slicot agrees']} | {c['designs']} | {c['silent leaks']} |"
        )
    print()
    print(
        f"A zero exactly on the boundary (the boundary family and some discrete plants): the "
        f"rule's answer is *cannot be decided* (or *no*); {total['boundary undecided']} of the "
        "plants counted right said *cannot be decided*, the others *no*."
    )
    print()
    print(
        f"check_existence (rank condition, zeros with radii, detectability): "
        f"{1e3 * ours / (3 * total['plants']):.1f} ms CPU per plant; AB08ND's zeros alone "
        f"{1e3 * slicot / (3 * total['plants']):.2f} ms"
    )
    print()
    print("Cases not counted right, or where AB08ND disagrees:")
    for note in notes or ["none"]:
        print(f"- {note}")
    result = {
        key: int(total[key])
        for key in ("plants", "right", "undecided", "wrong", "count right", "slicot agrees")
    }
    result.update(
        designs=int(total["designs"]),
        silent_leaks=int(total["silent leaks"]),
        ms_per_plant=1e3 * ours / (3 * total["plants"]),
        ms_ab08nd=1e3 * slicot / (3 * total["plants"]),
    )
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
