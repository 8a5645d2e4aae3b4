"""Former home of :mod:`uio_teach.checks.common`; kept so that old imports keep working."""

from .common import CheckResult, clear_collected, collected, never_raises

_never_raises = never_raises

__all__ = ["CheckResult", "collected", "clear_collected", "never_raises"]
