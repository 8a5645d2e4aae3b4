"""The package's own errors and warnings: one base class each, to catch them all at once.

Every exception that ``uio_teach`` raises on purpose derives from :class:`UIOTeachError`, and
also from the built-in class that says what went wrong: bad numbers or a design that cannot
exist are ``ValueError`` s (``UIOExistenceError``, ``LMIError``, ``ConfigError``, ...), a folder
that cannot be written an ``OSError``, an overflowing simulation an ``OverflowError``. Every
warning derives from :class:`UIOTeachWarning`.

Examples
--------
>>> import uio_teach as ut
>>> issubclass(ut.LMIInfeasibleError, ut.UIOTeachError), issubclass(ut.LMIError, ValueError)
(True, True)
>>> from uio_teach.instructor.config import FigureConfig
>>> try:
...     FigureConfig.from_dict({"seed": -1})
... except ut.UIOTeachError as err:
...     print(type(err).__name__, "--", err)
ConfigError -- <dict>: seed: must be >= 0, got -1
"""

from __future__ import annotations

__all__ = ["InputError", "UIOTeachError", "UIOTeachWarning"]


class UIOTeachError(Exception):
    """The base of every error the package raises on purpose.

    Examples
    --------
    >>> from uio_teach.errors import UIOTeachError
    >>> from uio_teach.instructor.config import ConfigError
    >>> issubclass(ConfigError, UIOTeachError) and issubclass(ConfigError, ValueError)
    True
    """


class InputError(UIOTeachError, ValueError):
    """A bad argument: a wrong shape, type or value, named in the message with what is expected.

    Every public function answers an argument it cannot use with this error (or a more specific
    subclass of :class:`UIOTeachError`), never with a bare ``ValueError`` from deep inside numpy.
    It is a ``ValueError`` too, so ``except ValueError`` still catches it.

    Examples
    --------
    >>> import uio_teach as ut
    >>> try:
    ...     ut.Plant([[0.0, 1.0]], [[1.0, 0.0]])
    ... except ut.InputError as err:
    ...     print(err)
    A has shape (1, 2), expected a square (n, n) matrix
    """


class UIOTeachWarning(UserWarning):
    """The base of every warning the package gives.

    Examples
    --------
    >>> from uio_teach.errors import UIOTeachWarning
    >>> from uio_teach.grading.grade import UnsandboxedWarning
    >>> issubclass(UnsandboxedWarning, UIOTeachWarning)
    True
    """
