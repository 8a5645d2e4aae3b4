"""Writing the instructor's outputs: reproducible figure files and a checked output folder.

:func:`save_figure` leaves out the time stamps and software names that
matplotlib would write into PNG, PDF and SVG files, so the same figure always
gives the same bytes; :func:`prepare_output_dir` creates the folder or says, in
one line, why it cannot.

Examples
--------
>>> from uio_teach.instructor.output import FORMATS
>>> FORMATS
('png', 'pdf', 'svg')
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["FORMATS", "OutputError", "save_figure", "prepare_output_dir"]

FORMATS = ("png", "pdf", "svg")
"""The image formats :func:`save_figure` writes."""

_SVG_HASHSALT = "uio-teach"


class OutputError(OSError):
    """The output folder cannot be created or written to."""


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
    import matplotlib

    if fmt not in FORMATS:
        raise ValueError(f"fmt must be one of {', '.join(FORMATS)}, got {fmt!r}")
    metadata = {
        "png": {"Software": None},
        "pdf": {"CreationDate": None, "ModDate": None},
        "svg": {"Date": None},
    }[fmt]
    with matplotlib.rc_context({"svg.hashsalt": _SVG_HASHSALT}):
        fig.savefig(path, format=fmt, dpi=dpi, metadata=metadata)
    return Path(path)


def prepare_output_dir(out: str | os.PathLike[str]) -> Path:
    """Create the output folder if needed and make sure files can be written into it.

    Parameters
    ----------
    out : str or path-like
        The folder.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    OutputError
        The folder cannot be created, is a file, or is not writable; the
        message is one line.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.instructor.output import prepare_output_dir, OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     prepare_output_dir(pathlib.Path(tmp) / "new" / "folder").is_dir()
    True
    >>> with tempfile.NamedTemporaryFile() as f:
    ...     try:
    ...         prepare_output_dir(pathlib.Path(f.name) / "sub")
    ...     except OutputError as err:
    ...         print("cannot create" in str(err))
    True
    """
    path = Path(out)
    if path.exists() and not path.is_dir():
        raise OutputError(f"the output folder {os.fspath(path)} is a file, not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        reason = err.strerror or str(err)
        raise OutputError(f"cannot create the output folder {os.fspath(path)}: {reason}") from None
    try:
        with tempfile.NamedTemporaryFile(dir=path, prefix=".uio-teach-write-test-"):
            pass
    except OSError as err:
        reason = err.strerror or str(err)
        raise OutputError(
            f"cannot write to the output folder {os.fspath(path)}: {reason}"
        ) from None
    return path
