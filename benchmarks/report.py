"""Run the benchmarks and write their results: ``benchmarks/RESULTS.md`` and the README's table.

Run from the repository root with the project's environment (``make bench``)::

    .venv/bin/python benchmarks/report.py              # every benchmark, then both files
    .venv/bin/python benchmarks/report.py --only import figures
    .venv/bin/python benchmarks/report.py --render     # rewrite both files, run nothing

Each benchmark script runs in its own process; what it prints is kept, with the date and the
machine's load average before and after, in ``benchmarks/output/<name>.txt``. Both files are
then written from those outputs alone: ``RESULTS.md`` (the summary table, then each script's own
report) and the performance table of ``README.md``, between its marker comments. The numbers are
never typed by hand, and ``tests/test_benchmarks.py`` checks that the README's table is
the one written here.

A script that is not listed in ``BENCHMARKS`` (a new ``bench_*.py``) runs too; its output is
reported in ``RESULTS.md`` and adds no row to the summary until a reader is written for it.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
OUTPUT = HERE / "output"
RESULTS = HERE / "RESULTS.md"
README = ROOT / "README.md"
BEGIN = "<!-- benchmarks/report.py writes this table: do not edit -->"
END = "<!-- end of the table written by benchmarks/report.py -->"
HEADER = ["| what | `uio_teach` | reference | ratio |", "| --- | ---: | ---: | ---: |"]


class ReportError(RuntimeError):
    """A benchmark failed, or printed something its reader does not understand."""


# readers: a benchmark's output -> rows of the summary table ------------------------------------


def _table_rows(text: str, first_header_cell: str) -> list[list[str]]:
    """The body rows of the first Markdown table in ``text`` whose header starts with a cell."""
    rows, inside = [], False
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.lstrip().startswith("|"):
            if inside:
                break
            continue
        if not inside:
            inside = cells[0] == first_header_cell
            continue
        if set(cells[0]) <= set("-: "):
            continue
        rows.append(cells)
    return rows


def _number(cell: str) -> float:
    match = re.search(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", cell)
    if not match:
        raise ReportError(f"no number in table cell {cell!r}")
    return float(match.group())


def _json_line(text: str) -> dict:
    for line in reversed(text.strip().splitlines()):
        if line.startswith("{"):
            return json.loads(line)
    raise ReportError("no JSON result line in the output")


def read_simulate(text: str) -> list[list[str]]:
    rows = []
    for cells in _table_rows(text, "case"):
        case, sim, fr, speedup = cells[0], _number(cells[1]), _number(cells[2]), cells[3]
        rows.append(
            [
                f"simulate {case}",
                f"{sim:.1f} ms",
                f"`control.forced_response` {fr:.1f} ms",
                f"{speedup} faster",
            ]
        )
    if not rows:
        raise ReportError("no table with a 'case' column")
    return rows


def read_widgets(text: str) -> list[list[str]]:
    rows, memory = [], []
    for cells in _table_rows(text, "explorer"):
        label, changes, median, p95, rebuild, ratio, cpu_median, cpu_p95 = cells[:8]
        rows.append(
            [
                f"explorer {label}: every control over its range, "
                f"median / p95 of {changes} changes",
                f"{median} / {p95} ms (CPU {cpu_median} / {cpu_p95} ms)",
                f"rebuilding {rebuild} ms",
                f"p95 {ratio} of a rebuild",
            ]
        )
        if "," not in label:  # one memory figure per explorer, on its main row
            memory.append((label, cells[8]))
    if not rows:
        raise ReportError("no table with an 'explorer' column")
    names = " / ".join(label for label, _ in memory)
    values = " / ".join(f"{value} MiB" for _, value in memory)
    rows.append(
        [f"explorer cell re-run 20 times, memory growth ({names})", values, "goal < 30 MiB", ""]
    )
    return rows


def read_book(text: str) -> list[list[str]]:
    clean = re.search(r"clean build with execution: median\s+([\d.]+) s", text)
    cached = re.search(r"cached rebuild, prose edit: median\s+([\d.]+) s", text)
    if not (clean and cached):
        raise ReportError("no 'clean build' and 'cached rebuild' lines")
    return [
        [
            "build the whole book from clean, executing every chapter",
            f"{float(clean[1]):.0f} s",
            "goal 90 s",
            "",
        ],
        [
            "rebuild after a prose-only edit (cached execution)",
            f"{float(cached[1]):.1f} s",
            "goal 15 s",
            "",
        ],
    ]


def read_figures(text: str) -> list[list[str]]:
    whole = re.search(r"median of \d+: uio-teach figures \((\w+)\) ([\d.]+) s", text)
    if not whole:
        raise ReportError("no 'median of N: uio-teach figures' line")
    return [
        [
            f"regenerate all course figures (`uio-teach figures`, {whole[1]}, whole process)",
            f"{float(whole[2]):.1f} s",
            "goal 30 s",
            "",
        ]
    ]


def read_import(text: str) -> list[list[str]]:
    result = _json_line(text)
    ratio = result["uio_teach"] / result["control"]
    return [
        [
            "`import uio_teach` in a new interpreter",
            f"{result['uio_teach']:.1f} s",
            f"`import control` {result['control']:.1f} s",
            f"{ratio:.1f}x",
        ]
    ]


def read_decisions(text: str) -> list[list[str]]:
    r = _json_line(text)
    return [
        [
            f"existence verdicts on {r['plants']} constructed plants with exactly known zeros "
            "(right / undecided / wrong; zeros counted right; designs returned / silent leaks)",
            f"{r['right']} / {r['undecided']} / {r['wrong']}; {r['count right']}; "
            f"{r['designs']} / {r['silent_leaks']}",
            f"SLICOT AB08ND agrees on {r['slicot agrees']} zero counts",
            "",
        ]
    ]


def read_large(text: str) -> list[list[str]]:
    """One row per size, the square plant (p = q = 2): on the tall one (p = 3) AB08ND takes
    under a millisecond at n = 100 (the table in RESULTS.md), too little to be a reference."""
    rows = []
    for r in json.loads(_json_line_list(text)):
        if int(r["p"]) != 2:
            continue
        ab = r["ab08nd"]
        found = (
            "all zeros found" if r["found"] == r["zeros"] == r["ab08nd_count"] else "zeros MISSED"
        )
        rows.append(
            [
                f"`check_existence` / `design_uio`, n = {r['n']}, {r['zeros']} zeros ({found})",
                f"{r['check']:.2f} s / {r['design']:.2f} s CPU",
                f"SLICOT AB08ND {ab:.3f} s",
                f"{r['check'] / ab:.0f}x / {r['design'] / ab:.0f}x slower (goal 20x)",
            ]
        )
    if not rows:
        raise ReportError("no square plant (p = 2) in the JSON line")
    return rows


def _json_line_list(text: str) -> str:
    for line in reversed(text.strip().splitlines()):
        if line.startswith("["):
            return line
    raise ReportError("no JSON result list in the output")


def read_pdf(text: str) -> list[list[str]]:
    total = re.search(r"make pdf after make book: ([\d.]+) s \(printing ([\d.]+) s\)", text)
    printed = re.search(r"printed: (\d+) PDFs, (\d+) pages, ([\d.]+) pages/s", text)
    one = re.search(r"one PDF at a time \(--jobs 1\): ([\d.]+) s", text)
    cores = re.search(r"cores: (\d+)", text)
    if not (total and printed and one and cores):
        raise ReportError("no 'make pdf after make book', 'printed' and 'one PDF at a time' lines")
    printing = float(total[2])
    return [
        [
            f"`make pdf` after `make book`: every page and the whole book printed, "
            f"{printed[1]} tagged PDFs, {printed[2]} pages",
            f"{float(total[1]):.0f} s (printing {printing:.0f} s, {float(printed[3]):.1f} pages/s)",
            f"printing one PDF at a time {float(one[1]):.0f} s",
            f"{float(one[1]) / printing:.1f}x faster on {cores[1]} cores",
        ]
    ]


def read_suite(text: str) -> list[list[str]]:
    results = [json.loads(line) for line in text.splitlines() if line.startswith("{")]
    if not results:
        raise ReportError("no JSON result line in the output")
    rows = []
    for r in results:
        rows += _suite_rows(r)
    return rows


def _suite_rows(r: dict) -> list[list[str]]:
    label = f" ({r['label']})" if r.get("label") else ""
    rows = []
    for run in r["runs"]:
        what = {
            "check": "`make check`: ruff, then the quick tests (no kernel, browser, book, process)",
            "test": "`make test`: ruff, then every test but the slow set",
        }[run["target"]]
        load = " -> ".join(f"{x:.1f}" for x in run["load"])
        rows.append(
            [
                f"{what}, {run['tests']} tests{label}",
                f"{run['wall']:.0f} s (CPU {run['cpu']:.0f} s, load {load} on {r['cores']} cores)",
                f"goal {run['goal']:.0f} s",
                "",
            ]
        )
    if "api_bytes" in r:
        rows.append(
            [
                (
                    f"the largest API page (`{r['api_page']}`){label}"
                    if "api_page" in r  # the reference in several pages
                    else f"the API page (`book/api.html`){label}"
                ),
                f"{r['api_bytes'] / 1000:.0f} kB",
                "goal 400 kB",
                "",
            ]
        )
    return rows


# name -> (script and arguments, reader); the summary lists them in this order
BENCHMARKS: dict[str, tuple[list[str], Callable[[str], list[list[str]]]]] = {
    "simulate": (["bench_simulate.py"], read_simulate),
    "widgets": (["bench_widgets.py"], read_widgets),
    "book": (["bench_book.py", "--runs", "1"], read_book),
    "pdf": (["bench_pdf.py"], read_pdf),
    "figures": (["bench_figures.py"], read_figures),
    "import": (["bench_import.py"], read_import),
    "decisions": (["bench_decisions.py"], read_decisions),
    "large": (["bench_large.py"], read_large),
    "suite": (["bench_suite.py", "--target", "check", "--target", "test"], read_suite),
}


def _all_scripts() -> dict[str, list[str]]:
    scripts = {name: command for name, (command, _) in BENCHMARKS.items()}
    for path in sorted(HERE.glob("bench_*.py")):
        name = path.stem.removeprefix("bench_")
        scripts.setdefault(name, [path.name])
    return scripts


# running ----------------------------------------------------------------------------------------


def _load() -> str:
    try:
        return Path("/proc/loadavg").read_text().split()[0]
    except OSError:
        return "unknown"


def run(name: str, command: list[str]) -> Path:
    """Run one benchmark script; keep what it printed, with the date and the load around it."""
    before = _load()
    started = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    proc = subprocess.run(
        [sys.executable, str(HERE / command[0]), *command[1:]],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    if proc.returncode:
        raise ReportError(f"{command[0]} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    OUTPUT.mkdir(exist_ok=True)
    path = OUTPUT / f"{name}.txt"
    head = (
        f"command: {' '.join(['benchmarks/' + command[0], *command[1:]])}\n"
        f"measured: {started}, {platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}, load average {before} before, {_load()} after\n"
    )
    path.write_text(head + "\n" + proc.stdout, encoding="utf-8")
    return path


# rendering --------------------------------------------------------------------------------------


def _split(text: str) -> tuple[str, str]:
    head, _, body = text.partition("\n\n")
    return head, body


def summary() -> str:
    """The summary table, from the kept outputs (a benchmark never run adds no row)."""
    lines = list(HEADER)
    for name, (_, reader) in BENCHMARKS.items():
        path = OUTPUT / f"{name}.txt"
        if not path.exists():
            continue
        try:
            rows = reader(_split(path.read_text(encoding="utf-8"))[1])
        except ReportError as err:
            raise ReportError(f"{path.relative_to(ROOT)}: {err}") from None
        lines += [f"| {' | '.join(row)} |" for row in rows]
    return "\n".join(lines)


def results_text() -> str:
    """The whole of ``benchmarks/RESULTS.md``."""
    parts = [
        "# Benchmark results",
        "",
        "Written by `benchmarks/report.py` (`make bench`) from what each benchmark script "
        "printed (kept in `benchmarks/output/`); do not edit by hand. Timings are wall-clock "
        "medians on a shared 2-core virtual machine: the load average around each run is given "
        "with it, and a busy machine makes every number larger (ratios measured in one process "
        "suffer least).",
        "",
        BEGIN,
        summary(),
        END,
        "",
    ]
    scripts = _all_scripts()
    for name in scripts:
        path = OUTPUT / f"{name}.txt"
        if not path.exists():
            continue
        head, body = _split(path.read_text(encoding="utf-8"))
        parts += [f"## {name}", "", *[f"- {line}" for line in head.splitlines()], ""]
        parts += ["```text", body.rstrip("\n"), "```", ""]
    return "\n".join(parts)


def readme_table(text: str) -> str:
    """The table between the marker comments of ``text`` (README.md or RESULTS.md)."""
    if BEGIN not in text or END not in text:
        raise ReportError("the marker comments of the benchmark table are missing")
    return text.split(BEGIN, 1)[1].split(END, 1)[0].strip("\n")


def with_table(text: str, table: str) -> str:
    """``text`` with the table between its marker comments replaced by ``table``."""
    before, rest = text.split(BEGIN, 1)
    _, after = rest.split(END, 1)
    return f"{before}{BEGIN}\n{table}\n{END}{after}"


def render() -> None:
    RESULTS.write_text(results_text(), encoding="utf-8")
    README.write_text(with_table(README.read_text(encoding="utf-8"), summary()), encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", metavar="NAME", help="run only these benchmarks")
    parser.add_argument("--render", action="store_true", help="run nothing, rewrite both files")
    args = parser.parse_args(argv)
    scripts = _all_scripts()
    if args.only:
        unknown = sorted(set(args.only) - set(scripts))
        if unknown:
            parser.error(f"unknown benchmark(s) {unknown}; known: {sorted(scripts)}")
        scripts = {name: scripts[name] for name in args.only}
    failed = []
    if not args.render:
        for name, command in scripts.items():
            print(f"running {command[0]} ...", flush=True)
            try:
                run(name, command)
            except ReportError as err:  # the others still run; their results are still written
                print(err, file=sys.stderr)
                failed.append(command[0])
    render()
    print(f"wrote {RESULTS.relative_to(ROOT)} and the table of {README.name}")
    if failed:
        print(f"failed, results kept from an earlier run: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
