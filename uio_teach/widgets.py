"""The live explorers (``ut.widgets.pa9_explorer()`` and the others).

They live in :mod:`uio_teach.explorers.widgets`; this module keeps the short
names the book and the notebooks use.

Examples
--------
>>> from uio_teach import widgets
>>> widgets.pa9_explorer(static=False).settings.poles
(-1.0, -2.0, -3.0)
"""

from .explorers.widgets import (
    Explorer,
    case_study_explorer,
    explorer,
    missile_explorer,
    pa9_explorer,
)

__all__ = ["Explorer", "pa9_explorer", "case_study_explorer", "missile_explorer", "explorer"]
