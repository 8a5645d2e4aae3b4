"""The lab notebooks under their former name; they live in :mod:`uio_teach.instructor.labs`.

Examples
--------
>>> from uio_teach import labs
>>> labs.VERSIONS
('student', 'solution')
"""

from .instructor.labs import (
    VERSIONS,
    BookIndex,
    LabError,
    LabResult,
    default_book_dir,
    find_labs,
    make_notebook,
    write_labs,
)

__all__ = [
    "VERSIONS",
    "BookIndex",
    "LabError",
    "LabResult",
    "default_book_dir",
    "find_labs",
    "make_notebook",
    "write_labs",
]
