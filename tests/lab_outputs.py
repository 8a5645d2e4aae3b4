"""What the check cells of an executed lab notebook printed, and what they must say.

Shared by the tests that run lab notebooks: ``test_labs.py`` (the notebooks ``uio-teach labs``
writes, with a group's or a term's numbers) and ``test_book_install.py`` (the notebooks the
built book offers, run from its wheel).
"""

from __future__ import annotations

import re


def tags(cell) -> list[str]:
    return list(cell.metadata.get("tags", []))


def text_output(cell) -> str:
    """The text a cell printed or displayed, and the traceback of its error."""
    parts = []
    for out in cell.get("outputs", []):
        if out.output_type == "stream":
            parts.append(out.text)
        elif out.output_type in ("execute_result", "display_data"):
            parts.append(out.data.get("text/plain", ""))
        elif out.output_type == "error":
            parts.append("\n".join(out.traceback))
    return "\n".join(parts)


def check_cells(nb) -> list:
    """The lab's check cells (tagged ``check``); a lab has at least one."""
    cells = [cell for cell in nb.cells if "check" in tags(cell)]
    assert cells, "no check cell (tag: check)"
    return cells


def assert_every_check_passes(nb) -> None:
    for cell in check_cells(nb):
        out = text_output(cell)
        assert re.search(r"All \d+ checks passed\.", out), f"{cell.source}\n{out}"
        assert "✗" not in out, f"{cell.source}\n{out}"


def assert_checks_say_what_is_missing(nb) -> None:
    """A student notebook as written (``# TODO`` cells in place of the solutions): every check
    fails in plain words, naming what is missing, without a traceback."""
    for cell in check_cells(nb):
        out = text_output(cell)
        assert "Traceback" not in out and "Error" not in out.split("\n")[0], out
        assert "✗" in out and "checks failed" in out, out
        assert "missing" in out or "got None" in out or "got NoneType" in out, out
