"""The README's performance table is the one ``benchmarks/report.py`` wrote from the benchmarks'
own output: nothing typed by hand (the benchmarks are not re-run here)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SPEC = importlib.util.spec_from_file_location("report", ROOT / "benchmarks" / "report.py")
report = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(report)


def test_the_readme_table_is_the_one_in_results():
    readme = report.readme_table(report.README.read_text(encoding="utf-8"))
    results = report.readme_table(report.RESULTS.read_text(encoding="utf-8"))
    assert readme == results
    assert readme.splitlines()[:2] == report.HEADER
    assert len(readme.splitlines()) > 2, "the table has no row: run `make bench`"


def test_results_are_written_from_the_kept_outputs():
    """Rendering the kept outputs again gives RESULTS.md as committed, and the README's table."""
    assert report.RESULTS.read_text(encoding="utf-8") == report.results_text()
    assert report.readme_table(report.README.read_text(encoding="utf-8")) == report.summary()


def test_every_row_comes_from_a_kept_output():
    kept = {p.stem for p in report.OUTPUT.glob("*.txt")}
    assert {"import", "figures"} <= kept
    for name in kept & set(report.BENCHMARKS):
        text = (report.OUTPUT / f"{name}.txt").read_text(encoding="utf-8")
        assert text.startswith("command: benchmarks/bench_"), name
        assert "load average" in text.splitlines()[1], name


SIMULATE = """\
| case | `simulate` (ms) | `forced_response` (ms) | speed-up | max rel. difference | x |
| --- | ---: | ---: | ---: | ---: | ---: |
| PA9 + UIO, 20 s | 1.51 | 83.4 | 55x | 7.3e-14 | 7.70 |

| case | `simulate` | `forced_response` |
| --- | ---: | ---: |
| PA9 + UIO, 20 s | 3.9e-07 | 3.9e-07 |
"""


def test_a_reader_takes_its_numbers_from_the_script_output():
    rows = report.read_simulate(SIMULATE)
    assert rows == [
        ["simulate PA9 + UIO, 20 s", "1.5 ms", "`control.forced_response` 83.4 ms", "55x faster"]
    ]
    with pytest.raises(report.ReportError, match="no table"):
        report.read_simulate("simulate: 1.5 ms")


def test_the_table_is_replaced_between_the_markers_only():
    text = f"before\n{report.BEGIN}\n| old |\n{report.END}\nafter\n"
    new = report.with_table(text, "| new |")
    assert new == f"before\n{report.BEGIN}\n| new |\n{report.END}\nafter\n"
    assert report.readme_table(new) == "| new |"


PDF = """\
cores: 2
make pdf after make book: 250.4 s (printing 231.0 s)
printed: 17 PDFs, 760 pages, 3.29 pages/s
one PDF at a time (--jobs 1): 402.7 s
"""


def test_the_pdf_reader_takes_time_pages_and_the_one_at_a_time_reference():
    (row,) = report.read_pdf(PDF)
    assert row[0].endswith("17 tagged PDFs, 760 pages")
    assert row[1:] == [
        "250 s (printing 231 s, 3.3 pages/s)",
        "printing one PDF at a time 403 s",
        "1.7x faster on 2 cores",
    ]
    with pytest.raises(report.ReportError, match="make pdf after make book"):
        report.read_pdf("printed: 17 PDFs")
