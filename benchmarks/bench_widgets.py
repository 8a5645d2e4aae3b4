"""Time the explorers: from a control change to the redrawn figure, against rebuilding the figure.

Run from the repository root with the project's environment::

    .venv/bin/python benchmarks/bench_widgets.py [--changes 50]

For each explorer the same sequence of control changes (mostly pole moves, as a
student drags a slider and lets go; then amplitude, frequency, disturbance type and
noise) is timed four ways, on the Agg backend, without a kernel:

* **widget**: setting the control's ``value`` on the live explorer, until its handler
  returns: design, both simulations, in-place update, redraw and the PNG the widget shows;
* **in place**: ``compute_frame`` + ``ExplorerFigure.update`` + ``ExplorerFigure.draw``
  (the redraw that blits or redraws only the panels whose range changed);
* **in place, full draw**: the same update followed by a complete ``fig.canvas.draw()``;
* **rebuild** (the baseline): ``compute_frame``, a new figure built from scratch and
  ``fig.canvas.draw()``.

Medians (and 90th percentiles) in milliseconds. Goals on a 2-core machine: the widget under
50 ms, at least 3 times faster than the rebuild. The static frames (the whole grid of one
explorer) are timed once.
"""

from __future__ import annotations

import argparse
import platform
import statistics
import time
from collections.abc import Callable

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

from uio_teach.explorers import DISTURBANCES, ExplorerFigure, compute_frame, widgets  # noqa: E402
from uio_teach.explorers.static import static_explorer  # noqa: E402


def changes(ex: widgets.Explorer, count: int) -> list[tuple[str, object]]:
    """A reproducible sequence of control changes: 60 % pole (or bound) moves, then the rest."""
    rng = np.random.default_rng(0)
    c = ex.controls
    main = "decay" if c.get("mode") is not None and c["mode"].value == "lmi" else "pole 1"
    lo, hi = c[main].min, c[main].max
    start = c[main].value
    out: list[tuple[str, object]] = []
    n_main = int(0.6 * count)
    # a drag: small steps around the start value, within the stable part of the range
    top = min(hi, 0.95) if ex.scenario.discrete else min(hi, 0.0)
    for value in start + np.cumsum(rng.normal(0, 0.04 * (hi - lo), n_main)):
        out.append((main, float(np.clip(value, lo, top - 0.01 * (hi - lo)))))
    others = ["amplitude", "frequency", "disturbance", "noise"]
    for i in range(count - n_main):
        name = others[i % len(others)]
        if name == "disturbance":
            out.append((name, DISTURBANCES[(i // len(others) + 1) % len(DISTURBANCES)]))
        else:
            ctl = c[name]
            out.append((name, float(rng.uniform(ctl.min, ctl.max))))
    return out


def timed(fn: Callable[[], object]) -> float:
    start = time.perf_counter()
    fn()
    return (time.perf_counter() - start) * 1e3


def bench(name: str, make: Callable[[], widgets.Explorer], count: int) -> dict[str, object]:
    ex = make()
    seq = changes(ex, count)
    # widget: set each control as the slider would
    t_widget, settings = [], []
    for key, value in seq:
        t_widget.append(timed(lambda k=key, v=value: setattr(ex.controls[k], "value", v)))
        settings.append(ex.settings)
    sc = ex.scenario
    # pure, in place, with blitting / partial redraws
    ef = ExplorerFigure(sc)
    ef.update(compute_frame(sc, settings[0]))
    ef.draw()
    full0, partial0 = ef.full_draws, ef.partial_draws
    t_inplace = [timed(lambda s=s: (ef.update(compute_frame(sc, s)), ef.draw())) for s in settings]
    full, partial = ef.full_draws - full0, ef.partial_draws - partial0
    # in place, complete canvas draw each time
    t_full = [
        timed(lambda s=s: (ef.update(compute_frame(sc, s)), ef.fig.canvas.draw())) for s in settings
    ]

    # baseline: a new figure for every change
    def rebuild(s):
        fresh = ExplorerFigure(sc)
        fresh.update(compute_frame(sc, s))
        fresh.fig.canvas.draw()

    t_rebuild = [timed(lambda s=s: rebuild(s)) for s in settings]
    t_compute = [timed(lambda s=s: compute_frame(sc, s)) for s in settings]
    static_time = timed(lambda: static_explorer(sc, ex._base))
    page = static_explorer(sc, ex._base)
    return {
        "name": name,
        "widget": t_widget,
        "in place": t_inplace,
        "in place, full draw": t_full,
        "rebuild": t_rebuild,
        "compute only": t_compute,
        "draws": (len(settings) - full - partial, partial, full),
        "static": (static_time, page.count, len(page.html)),
    }


def med(values: list[float]) -> str:
    return f"{statistics.median(values):.1f}"


def p90(values: list[float]) -> str:
    return f"{np.percentile(values, 90):.1f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--changes", type=int, default=50, help="control changes per explorer")
    args = parser.parse_args()

    def lmi_case():
        ex = widgets.case_study_explorer(static=False)
        ex.controls["mode"].value = "lmi"
        return ex

    runs = [
        ("PA9 (UIO, 3 poles)", lambda: widgets.pa9_explorer(static=False)),
        ("Case study (PMO, 1 pole)", lambda: widgets.case_study_explorer(static=False)),
        ("Case study, LMI bound", lmi_case),
        ("Missile (PMO + reconstruction)", lambda: widgets.missile_explorer(static=False)),
    ]
    results = [bench(name, make, args.changes) for name, make in runs]
    cpu = platform.processor() or platform.machine()
    print(
        f"{cpu}, Python {platform.python_version()}, matplotlib {matplotlib.__version__}; "
        f"{args.changes} changes per explorer\n"
    )
    print(
        "| explorer | widget: change to new PNG | in place (blit) | in place, full draw | "
        "rebuild (baseline) | speed-up vs rebuild | compute only | blits / partial / full |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in results:
        speed = statistics.median(r["rebuild"]) / statistics.median(r["widget"])
        blits, partial, full = r["draws"]
        print(
            f"| {r['name']} | {med(r['widget'])} (p90 {p90(r['widget'])}) | "
            f"{med(r['in place'])} | {med(r['in place, full draw'])} | "
            f"{med(r['rebuild'])} (p90 {p90(r['rebuild'])}) | {speed:.1f}x | "
            f"{med(r['compute only'])} | {blits} / {partial} / {full} |"
        )
    print("\n| explorer | static frames | build time (s) | HTML size (kB) |")
    print("|---|---|---|---|")
    for r in results:
        seconds, count, size = r["static"]
        print(f"| {r['name']} | {count} | {seconds / 1e3:.2f} | {size / 1e3:.0f} |")


if __name__ == "__main__":
    main()
