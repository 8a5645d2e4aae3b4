"""The command line under its former name; it lives in :mod:`uio_teach.instructor.cli`.

Examples
--------
>>> from uio_teach.cli import main
>>> main(["figures", "--list"])  # doctest: +ELLIPSIS
pa9_sine ...
0
"""

from .instructor.cli import build_parser, main

__all__ = ["main", "build_parser"]
