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

from zero_families import (  # noqa: E402
    EXACT_KINDS,
    FAMILIES,
    ab08nd_verdict,
    build,
    build_exact,
    confidently_wrong,
    judge,
    said,
    slicot_zero_count,
)

import uio_teach as ut  # noqa: E402


def exact_table(seeds: int) -> dict:
    """The exact-truth families: verdicts against the truth and against AB08ND's, one table."""
    print(
        "| family | plants | exists | no | cannot be decided | confidently wrong | "
        "raw exceptions | zeros counted right (square) | AB08ND confidently wrong | "
        "check_existence ms | AB08ND ms |"
    )
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    total, why = Counter(), Counter()
    for kind in EXACT_KINDS:
        c = Counter()
        for seed in range(seeds):
            case = build_exact(kind, seed)
            c["plants"] += 1
            start = time.process_time()
            try:
                report = ut.check_existence(case.plant)
            except Exception as exc:  # counted: the table's column says how many
                c["raw"] += 1
                print(f"<!-- raw exception: {case.label}: {exc!r} -->")
                continue
            c["ours"] += time.process_time() - start
            verdict = said(report)
            c[verdict] += 1
            c["wrong"] += confidently_wrong(verdict, case.truth)
            if verdict == "undecided":
                failed = report.failed[0]
                if failed.name == "rank condition":
                    why["the rank condition within its bound"] += 1
                elif case.truth == "boundary":
                    why["a zero exactly on the boundary"] += 1
                elif "holds only by the structure" in failed.reason:
                    why["a tall plant's zero outside the region (a plant that close has none)"] += 1
                else:
                    why["a zero's proven disk reaches the boundary"] += 1
            square = case.plant.p == case.plant.q
            if square and case.zeros is not None and report["rank condition"].holds:
                c["square"] += 1
                c["count right"] += report.invariant_zeros.size == case.zeros.size
            start = time.process_time()
            _, theirs = ab08nd_verdict(case.plant)
            c["ab08nd"] += time.process_time() - start
            if theirs is not None:
                c["ab08nd wrong"] += confidently_wrong(theirs, case.truth)
        ms = 1e3 * c["ours"] / max(c["plants"] - c["raw"], 1)
        ms_ref = 1e3 * c["ab08nd"] / max(c["plants"], 1)
        print(
            f"| {kind} | {c['plants']} | {c['exists']} | {c['no']} | {c['undecided']} | "
            f"{c['wrong']} | {c['raw']} | {c['count right']} of {c['square']} | "
            f"{c['ab08nd wrong']} | {ms:.1f} | {ms_ref:.2f} |"
        )
        total.update(c)
    print()
    print("Why the undecided plants are undecided:")
    for reason, k in why.most_common():
        print(f"- {reason}: {k}")
    print()
    return {
        "exact_plants": int(total["plants"]),
        "exact_wrong": int(total["wrong"]),
        "exact_raw": int(total["raw"]),
        "exact_undecided": int(total["undecided"]),
        "exact_ab08nd_wrong": int(total["ab08nd wrong"]),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=48, help="plants per family")
    parser.add_argument(
        "--exact", type=int, default=120, help="plants per exact-truth family (second table)"
    )
    args = parser.parse_args(argv)
    exact = exact_table(args.exact)
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
    result.update(exact)
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
