"""Time the explorers over a sweep of every control, against rebuilding; memory over re-runs.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_widgets.py [--steps 12] [--busy 1] [--write]

For each explorer every control is swept over its whole range (each slider from its
minimum to its maximum in ``--steps`` steps, each menu through its options, the LMI
bound in LMI mode), one change at a time, as a student sets it; a change is timed from
setting the control's ``value`` until its handler returns (design, both simulations,
the in-place update including any axis rescale, the redraw and the PNG the widget
shows). The baseline is **rebuilding**: a new explorer, built and drawn from scratch.
Memory: the resident size after re-running an explorer cell 20 times (each run builds
a new explorer; the previous one is closed).

While the explorers are timed, ``--busy`` other processes (one by default) each keep a core
busy with a spin loop, as another program on a student's laptop does. Goals on a 2-core
machine: median at most 50 ms, 95th percentile at most a third of the rebuild, memory growth
under 30 MiB over 20 re-runs. ``--write`` puts the table
in ``benchmarks/WIDGETS.md``.
"""

from __future__ import annotations

import argparse
import gc
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

import uio_teach as ut  # noqa: E402
from uio_teach.explorers import widgets  # noqa: E402


def _own(static: bool = False) -> widgets.Explorer:
    plant = ut.Plant([[0, 1], [-0.08, 0.6]], [[-0.5, 1]], E=[[0], [1]], dt=1)
    return widgets.explorer(plant, "uio", static=static, drag=False)


EXPLORERS: dict[str, Callable[[], widgets.Explorer]] = {
    "PA9": lambda: widgets.pa9_explorer(static=False, drag=False),
    "case study": lambda: widgets.case_study_explorer(static=False, drag=False),
    "missile": lambda: widgets.missile_explorer(static=False, drag=False),
    "quadruple tank": lambda: widgets.tank_explorer(static=False),
    "own plant": _own,
}


def _rss_mib() -> float:
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * 4096 / 2**20


def sweep(ex: widgets.Explorer, steps: int) -> dict[str, tuple[list[float], list[float]]]:
    """Set every control over its range: wall and CPU times (ms) of each kind of change.

    ``"controls"``: the observer's and the experiment's controls; ``"LMI bound"``: the case
    study's LMI decay rate (each value one LMI solve); ``"plant"``: the sliders of a physical
    parameter (a valve), each of which remakes the plant, its existence check and the figure.
    """
    times: list[float] = []
    cpu: list[float] = []
    plant_names = [pc.name for pc in ex.scenario.plant_controls]

    def timed_set(control, value) -> None:
        c0, t0 = time.process_time(), time.perf_counter()
        control.value = value
        times.append(1e3 * (time.perf_counter() - t0))
        cpu.append(1e3 * (time.process_time() - c0))

    def sweep_controls(names) -> tuple[list[float], list[float]]:
        for name in names:
            control = ex.controls[name]
            start = control.value
            if hasattr(control, "options"):
                values = [o[1] if isinstance(o, tuple) else o for o in control.options]
            else:
                values = list(np.linspace(control.min, control.max, steps))
            for v in [*values, start]:
                timed_set(control, v)
        out = (list(times), list(cpu))
        del times[:], cpu[:]
        return out

    skip = {"pattern", "mode", "decay", *plant_names}
    out = {"controls": sweep_controls([n for n in list(ex.controls) if n not in skip])}
    out["plant"] = sweep_controls(plant_names)
    if "mode" in ex.controls:
        ex.controls["mode"].value = "lmi"
        d = ex.controls["decay"]
        for v in [*np.linspace(d.min, d.max, steps), d.value]:
            timed_set(d, v)
        ex.controls["mode"].value = "poles"
    out["LMI bound"] = (list(times), list(cpu))
    return out


def rebuild(make: Callable[[], widgets.Explorer], count: int = 5, lmi: bool = False) -> list[float]:
    out = []
    for _ in range(count):
        t0 = time.perf_counter()
        ex = make()
        if lmi:  # the explorer anew, showing the LMI design (one solve, as a bound change)
            ex.set(mode="lmi", decay=0.85)
        out.append(1e3 * (time.perf_counter() - t0))
    return out


def memory(make: Callable[[], widgets.Explorer], runs: int = 20) -> tuple[float, float]:
    make()
    gc.collect()
    before = _rss_mib()
    for _ in range(runs):
        make()
    gc.collect()
    return before, _rss_mib()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=12)
    parser.add_argument("--write", action="store_true")
    parser.add_argument(
        "--busy",
        type=int,
        default=1,
        help="other processes kept busy (a spin loop each) while the explorers are timed",
    )
    args = parser.parse_args()
    spinners = [
        subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(args.busy)
    ]
    try:
        rows = _measure(args.steps)
    finally:
        for spinner in spinners:
            spinner.kill()
            spinner.wait()
    _report(rows, args.busy, args.write)


def _measure(steps: int) -> list[str]:
    rows = []
    for name, make in EXPLORERS.items():
        ex = make()
        kinds = sweep(ex, steps)
        m0, m1 = memory(make)
        for kind, (t, c) in kinds.items():
            if not t:
                continue
            lmi = kind == "LMI bound"
            label = {"controls": name, "plant": f"{name}, plant sliders"}.get(
                kind, f"{name}, {kind}"
            )
            med = statistics.median(t)
            p95 = float(np.percentile(t, 95))
            reb = statistics.median(rebuild(make, 3 if lmi else 5, lmi=lmi))
            rows.append(
                f"| {label} | {len(t)} | {med:.0f} | {p95:.0f} | {reb:.0f} | "
                f"{p95 / reb:.2f} | {statistics.median(c):.0f} | {np.percentile(c, 95):.0f} | "
                f"{m1 - m0:+.1f} |"
            )
            print(rows[-1], file=sys.stderr, flush=True)  # progress; the table is printed last
    return rows


def _report(rows: list[str], busy: int, write: bool) -> None:
    table = "\n".join(
        [
            "| explorer | changes | median (ms) | p95 (ms) | rebuild (ms) | p95 / rebuild "
            "| CPU median (ms) | CPU p95 (ms) | memory, 20 re-runs (MiB) |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
            *rows,
        ]
    )
    with open("/proc/loadavg") as f:
        load = f.read().split()[0]
    info = (
        f"{platform.python_version()}, {platform.machine()}, {os.cpu_count()} cores "
        f"(load average {load} at the end), Agg backend, no kernel, {busy} other "
        f"process{'es' if busy != 1 else ''} kept busy"
    )
    print(f"Python {info}.")
    print(table)
    if write:
        text = (
            "# Explorer latency\n\n"
            "`benchmarks/bench_widgets.py --write`: every control of each explorer swept over "
            "its whole range, one change at a time (design, both simulations, in-place update "
            "with any axis rescale, redraw, PNG), against rebuilding the explorer from scratch; "
            "wall-clock time, and the CPU time of the process (which other programs on a "
            "shared machine do not inflate); memory growth over 20 re-runs of the explorer's "
            f"cell. Python {info}.\n\n"
            "Goals: median at most 50 ms, p95 at most a third of the rebuild, memory growth "
            "under 30 MiB. The LMI bound of the case study is timed on its own row: each new "
            "bound is one LMI solve (cvxpy), and its rebuild is an explorer built anew in LMI "
            "mode. So are the sliders of a physical parameter (the quadruple tank's valves): "
            "each remakes the plant, its existence check and the whole figure, a rebuild of "
            "all but the controls.\n\n" + table + "\n"
        )
        Path(__file__).with_name("WIDGETS.md").write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
