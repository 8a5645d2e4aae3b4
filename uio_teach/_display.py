"""Plain-text and HTML display of named matrices (used by plants, observers and reports)."""

from __future__ import annotations

import html
import textwrap
from collections.abc import Iterable

import numpy as np

from . import tolerances as tols

__all__ = [
    "format_matrix",
    "matrices_text",
    "matrices_html",
    "format_complex",
    "format_poles",
    "format_matrix_line",
    "LINE_WIDTH",
    "fit_lines",
    "call_repr",
]

LINE_WIDTH = 76
"""Printed lines fit the book's column (1280 px), at most this many characters."""


def fit_lines(text: str, width: int = LINE_WIDTH, indent: str | None = None) -> str:
    """Wrap every line of ``text`` longer than ``width`` at spaces (never inside a word).

    Continuation lines get ``indent``, by default the line's own leading
    spaces plus two.

    Examples
    --------
    >>> from uio_teach._display import fit_lines
    >>> print(fit_lines("a UIO for a plant with many outputs and inputs", 20))
    a UIO for a plant
      with many outputs
      and inputs
    """
    out = []
    for line in text.split("\n"):
        if len(line) <= width:
            out.append(line)
            continue
        lead = line[: len(line) - len(line.lstrip())]
        hang = lead + "  " if indent is None else indent
        out.extend(
            textwrap.wrap(
                line,
                width,
                subsequent_indent=hang,
                break_long_words=False,
                break_on_hyphens=False,
            )
            or [line]
        )
    return "\n".join(out)


def call_repr(name: str, fields: Iterable[tuple[str, object]], width: int = LINE_WIDTH) -> str:
    """``name(key=value, ...)`` wrapped after commas to fit ``width``.

    Examples
    --------
    >>> from uio_teach._display import call_repr
    >>> call_repr("Threshold", [("value", 0.5), ("per", "run")])
    "Threshold(value=0.5, per='run')"
    """
    parts = [f"{k}={v!r}" for k, v in fields]
    pad = " " * (len(name) + 1)
    lines, cur = [], name + "("
    for i, part in enumerate(parts):
        piece = part + ("," if i < len(parts) - 1 else ")")
        if len(cur) + len(piece) + 1 > width and cur.strip() not in (name + "(", ""):
            lines.append(cur.rstrip())
            cur = pad
        cur += piece if cur.endswith("(") or cur == pad else " " + piece
    if not parts:
        cur += ")"
    lines.append(cur)
    return "\n".join(lines)


def format_complex(z: complex, digits: int = 4) -> str:
    """Format a number, dropping a negligible imaginary part."""
    z = complex(z)
    scale = max(1.0, abs(z))
    if abs(z.imag) <= tols.DISPLAY_ZERO_RTOL * scale:
        return f"{z.real:.{digits}g}"
    sign = "+" if z.imag >= 0 else "-"
    return f"{z.real:.{digits}g} {sign} {abs(z.imag):.{digits}g}j"


def format_poles(
    poles: Iterable[complex], digits: int = 4, *, braces: bool = False, empty: str = ""
) -> str:
    """The one formatter of poles (and eigenvalues, zeros) used throughout the package.

    Round-off below ``tolerances.ROUNDING_RTOL`` of the largest modulus is shown as 0, in the
    real and in the imaginary part, so ``8.9e-16`` prints as ``0`` and a real pole carries no
    ``+ 0j``.

    Parameters
    ----------
    poles : iterable of complex
        The values.
    digits : int, optional
        Significant digits (default 4).
    braces : bool, optional
        Write the values as a set, ``{-1, -2}``.
    empty : str, optional
        What to return for no values (default ``""``; with ``braces``, ``"none"`` reads well).

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach._display import format_poles
    >>> format_poles([8.9e-16, 0.5, -1 + 2j])
    '0, 0.5, -1 + 2j'
    >>> format_poles([-1, -2], braces=True)
    '{-1, -2}'
    """
    z = np.asarray(list(poles), dtype=complex)
    if not z.size:
        return empty
    tiny = tols.ROUNDING_RTOL * max(1.0, float(np.abs(z).max()))
    z = np.where(np.abs(z.real) < tiny, 0.0, z.real) + 1j * np.where(
        np.abs(z.imag) < tiny, 0.0, z.imag
    )
    text = ", ".join(format_complex(p, digits) for p in z)
    return "{" + text + "}" if braces else text


def _clean(M: np.ndarray, ref: float = 0.0) -> np.ndarray:
    """Real part if negligible imaginary; round-off below ``DISPLAY_ZERO_RTOL`` of the largest
    entry (of this matrix, or of ``ref``, the largest entry of the matrices shown together) set
    to 0."""
    M = np.real_if_close(np.asarray(M))
    scale = max(float(np.max(np.abs(M))) if M.size else 0.0, ref)
    return np.where(np.abs(M) <= tols.DISPLAY_ZERO_RTOL * scale, 0.0, M)


def _ref(items: list[tuple[str, np.ndarray]]) -> float:
    sizes = [float(np.max(np.abs(M))) for _, M in items if np.asarray(M).size]
    return max(sizes, default=0.0)


def format_matrix(M: np.ndarray, digits: int = 4, ref: float = 0.0) -> list[str]:
    """Return the rows of ``M`` as aligned strings."""
    M = np.asarray(M)
    if M.size == 0:
        return [f"(empty {M.shape[0]}x{M.shape[1]})"]
    M = _clean(M, ref)
    cells = [[f"{v:.{digits}g}" if v != 0 else "0" for v in row] for row in M]
    width = max(len(c) for row in cells for c in row)
    return ["[" + "  ".join(c.rjust(width) for c in row) + "]" for row in cells]


def format_matrix_line(M: np.ndarray, digits: int = 3) -> str:
    """A matrix on one line, round-off (below ``DISPLAY_ZERO_RTOL`` of its largest entry) as 0.

    Examples
    --------
    >>> from uio_teach._display import format_matrix_line
    >>> format_matrix_line([[0.94118, 0.23529], [1e-17, 0]])
    '[[0.941, 0.235], [0, 0]]'
    """
    M = np.atleast_2d(np.asarray(M, dtype=float))
    scale = float(np.max(np.abs(M))) if M.size else 0.0
    M = np.where(np.abs(M) <= tols.DISPLAY_ZERO_RTOL * max(scale, 1e-300), 0.0, M)
    return "[" + ", ".join("[" + ", ".join(f"{v:.{digits}g}" for v in row) + "]" for row in M) + "]"


def matrices_text(title: str, items: Iterable[tuple[str, np.ndarray]], digits: int = 4) -> str:
    """Stack named matrices under a title, one block each."""
    lines = [title]
    items = list(items)
    ref = _ref(items)
    for name, M in items:
        rows = format_matrix(M, digits, ref)
        pad = " " * (len(name) + 3)
        for i, row in enumerate(rows):
            lines.append((f"{name} = " if i == 0 else pad) + row)
    return "\n".join(lines)


_SR_ONLY = (
    "position:absolute;width:1px;height:1px;overflow:hidden;clip:rect(0 0 0 0);"
    "white-space:nowrap;border:0;padding:0;margin:-1px"
)
"""The style of text for screen readers only (in the page's structure, not on the screen)."""


def _html_matrix(M: np.ndarray, digits: int, ref: float = 0.0, name: str = "") -> str:
    """A matrix as an HTML table between brackets; a screen reader hears its name, its size and
    each entry's row and column (header cells shown to screen readers only)."""
    M = np.asarray(M)
    if M.size == 0:
        return f"<i>empty {M.shape[0]}&times;{M.shape[1]}</i>"
    rows, cols = M.shape
    label = html.escape(f"{name}, {rows} by {cols} matrix" if name else f"{rows} by {cols} matrix")
    head = (
        f'<tr><td style="{_SR_ONLY}"></td>'
        + "".join(f'<th scope="col" style="{_SR_ONLY}">column {j + 1}</th>' for j in range(cols))
        + "</tr>"
    )
    body = "".join(
        f'<tr><th scope="row" style="{_SR_ONLY}">row {i + 1}</th>'
        + "".join(f'<td style="text-align:right;padding:0 0.4em">{v:.{digits}g}</td>' for v in row)
        + "</tr>"
        for i, row in enumerate(_clean(M, ref))
    )
    return (
        f'<table aria-label="{label}" style="display:inline-table;border-left:1px solid;'
        'border-right:1px solid;border-collapse:collapse;margin:0.2em;position:relative">'
        f"{head}{body}</table>"
    )


def matrices_html(title: str, items: Iterable[tuple[str, np.ndarray]], digits: int = 4) -> str:
    """HTML version of :func:`matrices_text` for notebooks."""
    parts = [f"<div><b>{html.escape(title)}</b><br>"]
    items = list(items)
    ref = _ref(items)
    for name, M in items:
        parts.append(
            f'<span style="display:inline-block;margin-right:1em"><i>{html.escape(name)}</i> = '
            f"{_html_matrix(M, digits, ref, name)}</span>"
        )
    parts.append("</div>")
    return "".join(parts)
