"""Curves told apart without colour vision: simulated colour-vision deficiencies and a figure check.

A reader with deuteranopia, protanopia or tritanopia sees some pairs of colours as one.
:func:`simulate` maps sRGB colours to what such a reader sees, with the matrices of
Machado, Oliveira and Fernandes, "A physiologically-based model for simulation of color vision
deficiency", IEEE Transactions on Visualization and Computer Graphics 15(6), 2009 (severity 1.0,
applied to linear RGB). :func:`colour_distance` is the CIE 1976 colour difference
(Delta E*ab) of two colours as a reader with normal vision or a deficiency sees them.

:func:`curves_apart_by_hue_alone` lists the pairs of curves of one panel that only a hue tells
apart: the same line style and marker, and colours closer than :data:`MIN_DISTANCE` for one of
the readers. The course's figures and explorers are checked with it.

Examples
--------
>>> from uio_teach.colour_vision import colour_distance
>>> round(colour_distance("#ff7f0e", "#2ca02c", "protanopia"))  # matplotlib's C1 and C2
5
>>> colour_distance("#0072B2", "#D55E00", "deuteranopia") > 20  # the course's first two
True
"""

from __future__ import annotations

from itertools import combinations
from typing import TYPE_CHECKING, Any

import numpy as np

from .errors import InputError

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "DEFICIENCIES",
    "MIN_DISTANCE",
    "simulate",
    "colour_distance",
    "curves_apart_by_hue_alone",
]

# Machado et al. (2009), Table 1, severity 1.0: linear RGB in, linear RGB out.
_MACHADO = {
    "protanopia": np.array(
        [
            [0.152286, 1.052583, -0.204868],
            [0.114503, 0.786281, 0.099216],
            [-0.003882, -0.048116, 1.051998],
        ]
    ),
    "deuteranopia": np.array(
        [
            [0.367322, 0.860646, -0.227968],
            [0.280085, 0.672501, 0.047413],
            [-0.011820, 0.042940, 0.968881],
        ]
    ),
    "tritanopia": np.array(
        [
            [1.255528, -0.076749, -0.178779],
            [-0.078411, 0.930809, 0.147602],
            [0.004733, 0.691367, 0.303900],
        ]
    ),
}
DEFICIENCIES = ("normal", *_MACHADO)
"""The readers a figure is checked for, normal colour vision and the three dichromacies."""

MIN_DISTANCE = 20.0
"""The least colour difference (CIE76 Delta E*ab) at which two thin curves of one panel are
told apart by colour alone; below it they need another difference (line style, marker)."""


def _linear(rgb: np.ndarray) -> np.ndarray:
    return np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)


def _srgb(lin: np.ndarray) -> np.ndarray:
    lin = np.clip(lin, 0.0, 1.0)
    return np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055)


def _rgb(colour: Any) -> np.ndarray:
    from matplotlib.colors import to_rgb  # deferred: matplotlib only when colours are read

    return np.asarray(to_rgb(colour), dtype=float)


def simulate(colour: Any, deficiency: str) -> np.ndarray:
    """The sRGB colour (three floats in [0, 1]) a reader with ``deficiency`` sees for ``colour``.

    Parameters
    ----------
    colour : matplotlib colour
        A name, ``"#rrggbb"``, ``"C0"`` or an RGB(A) tuple.
    deficiency : {"normal", "protanopia", "deuteranopia", "tritanopia"}
        The reader.

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    ValueError
        An unknown deficiency.

    Examples
    --------
    >>> from uio_teach.colour_vision import simulate
    >>> simulate("#ff0000", "deuteranopia").round(2).tolist()  # red looks olive
    [0.64, 0.57, 0.0]
    """
    rgb = _rgb(colour)
    if deficiency == "normal":
        return rgb
    if deficiency not in _MACHADO:
        raise InputError(f"deficiency must be one of {', '.join(DEFICIENCIES)}, got {deficiency!r}")
    return _srgb(_MACHADO[deficiency] @ _linear(rgb))


def _lab(rgb: np.ndarray) -> np.ndarray:
    """CIE L*a*b* (D65) of an sRGB colour."""
    m = np.array(
        [[0.4124564, 0.3575761, 0.1804375], [0.2126729, 0.7151522, 0.0721750],
         [0.0193339, 0.1191920, 0.9503041]]
    )  # fmt: skip
    xyz = m @ _linear(np.asarray(rgb, dtype=float)) / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def colour_distance(first: Any, second: Any, deficiency: str = "normal") -> float:
    """The CIE76 colour difference (Delta E*ab) of two colours as ``deficiency`` sees them.

    Parameters
    ----------
    first, second : matplotlib colour
        The colours.
    deficiency : str, optional
        One of :data:`DEFICIENCIES` (default ``"normal"``).

    Returns
    -------
    float
        About 2 is just noticeable side by side; thin curves need far more (:data:`MIN_DISTANCE`).

    Examples
    --------
    >>> from uio_teach.colour_vision import colour_distance
    >>> round(colour_distance("black", "white"))
    100
    """
    a = _lab(simulate(first, deficiency))
    b = _lab(simulate(second, deficiency))
    return float(np.linalg.norm(a - b))


def _dashes(line: Any) -> tuple:
    """The drawn dash pattern of a line (solid: empty), in points, independent of its name."""
    style = line.get_linestyle()
    if style in ("-", "solid", "None", "none", " ", ""):
        return ()
    offset, pattern = line._unscaled_dash_pattern  # noqa: SLF001 (matplotlib keeps it there)
    return tuple(round(float(v), 2) for v in (pattern or ()))


def _looks(line: Any) -> tuple:
    marker = line.get_marker()
    marker = None if marker in (None, "None", "none", "", " ") else str(marker)
    return (_dashes(line), marker)


def curves_apart_by_hue_alone(fig: Figure) -> list[tuple[str, str, str, str]]:
    """The pairs of curves of one panel that only their colour tells apart, and too little.

    Two visible curves of one axes need a different line style (dash pattern) or marker, or
    colours at least :data:`MIN_DISTANCE` apart for every reader of :data:`DEFICIENCIES`
    (normal vision, protanopia, deuteranopia, tritanopia).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.

    Returns
    -------
    list of tuple of str
        ``(panel, first curve, second curve, reader)`` for each pair, the panel named by its
        title or vertical-axis label; empty when every pair is told apart.

    Examples
    --------
    >>> from uio_teach.colour_vision import curves_apart_by_hue_alone
    >>> from uio_teach.plotting import new_figure
    >>> ax = new_figure().subplots()
    >>> _ = ax.plot([0, 1], [0, 1], color="#ff7f0e", label="a")
    >>> _ = ax.plot([0, 1], [1, 0], color="#2ca02c", label="b")
    >>> curves_apart_by_hue_alone(ax.figure)[0][1:]
    ('a', 'b', 'protanopia')
    >>> ax.lines[1].set_linestyle("--")
    >>> curves_apart_by_hue_alone(ax.figure)
    []
    """
    found = []
    for k, ax in enumerate(fig.axes):
        if not ax.get_visible():
            continue
        panel = ax.get_title() or ax.get_ylabel() or f"axes {k + 1}"
        lines = [
            line
            for line in ax.get_lines()
            if line.get_visible() and np.asarray(line.get_xdata()).size > 1
        ]
        for a, b in combinations(lines, 2):
            if _looks(a) != _looks(b) or colour_distance(a.get_color(), b.get_color()) < 1:
                continue  # another style, or one series drawn several times (repeated runs)
            for reader in DEFICIENCIES:
                if colour_distance(a.get_color(), b.get_color(), reader) < MIN_DISTANCE:
                    found.append((panel, a.get_label(), b.get_label(), reader))
                    break
    return found
