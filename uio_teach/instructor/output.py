"""Writing the term's figure files so that the same figure always gives the same bytes.

:func:`save_figure` leaves out the time stamps and software names that
matplotlib would write into PNG, PDF and SVG files; :func:`save_description`
writes what a figure shows, in words, beside it. The folders they go into, the
manifest and the lock are :mod:`uio_teach.folders`, shared with the grader.

Examples
--------
>>> from uio_teach.instructor.output import FORMATS
>>> FORMATS
('png', 'pdf', 'svg')
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputError
from ..figure_text import description, description_text

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "FORMATS",
    "save_figure",
    "save_description",
]

FORMATS = ("png", "pdf", "svg")
"""The image formats :func:`save_figure` writes."""

_SVG_HASHSALT = "uio-teach"


def save_figure(fig: Figure, path: str | os.PathLike[str], fmt: str, dpi: int = 150) -> Path:
    """Save a figure so that the same figure always gives the same bytes.

    PNG files get no ``Software`` entry, PDF files no ``CreationDate``, SVG
    files no ``Date``, and SVG element ids come from a fixed salt instead of
    a random one.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or path-like
        The file to write.
    fmt : {"png", "pdf", "svg"}
        The format.
    dpi : int
        Resolution (raster images and raster parts of vector files).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from matplotlib.figure import Figure
    >>> from uio_teach.instructor.output import save_figure
    >>> fig = Figure(figsize=(2, 2))
    >>> _ = fig.subplots().plot([0, 1], [1, 0])
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     a = save_figure(fig, pathlib.Path(tmp) / "a.svg", "svg").read_bytes()
    ...     b = save_figure(fig, pathlib.Path(tmp) / "b.svg", "svg").read_bytes()
    >>> a == b
    True
    """
    import matplotlib  # deferred on purpose: the lab notebooks and the grader do not draw

    if fmt not in FORMATS:
        raise InputError(f"fmt must be one of {', '.join(FORMATS)}, got {fmt!r}")
    metadata = {
        "png": {"Software": None},
        "pdf": {"CreationDate": None, "ModDate": None},
        "svg": {"Date": None},
    }[fmt]
    said = description(fig)
    if said is not None:  # the text alternative travels inside the file too
        metadata[{"png": "Description", "pdf": "Subject", "svg": "Description"}[fmt]] = said.alt
    with matplotlib.rc_context({"svg.hashsalt": _SVG_HASHSALT}):
        fig.savefig(path, format=fmt, dpi=dpi, metadata=metadata)
    return Path(path)


def save_description(fig: Figure, path: str | os.PathLike[str]) -> Path | None:
    """Write what a figure shows, in words, beside its picture: ``<stem>.txt``.

    The text alternative (what is plotted and what the reader should see), then the long
    description, as :func:`uio_teach.figure_text.description_text` gives them: for the alt
    text of a handout, a slide or a learning platform.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or path-like
        The picture's file; the text goes to the same name with ``.txt``.

    Returns
    -------
    pathlib.Path or None
        The text file, or ``None`` for a figure without a description.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from matplotlib.figure import Figure
    >>> from uio_teach.figure_text import describe
    >>> from uio_teach.instructor.output import save_description
    >>> fig = describe(Figure(), "An error that decays to zero.")
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     save_description(fig, pathlib.Path(tmp) / "a.png").read_text()
    'An error that decays to zero.\\n'
    """
    text = description_text(fig)
    if not text:
        return None
    target = Path(path).with_suffix(".txt")
    target.write_text(text, encoding="utf-8")
    return target
