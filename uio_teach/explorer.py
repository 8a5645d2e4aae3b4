"""The explorers' model, figure and scenarios under their former name.

They now live in :mod:`uio_teach.explorers` (and :func:`luenberger_poles` in
:mod:`uio_teach.luenberger`); this module keeps the old imports working.

Examples
--------
>>> from uio_teach.explorer import compute_frame, pa9_scenario
>>> compute_frame(pa9_scenario()).messages
()
"""

from collections.abc import Sequence

from ._display import format_poles as _format_poles
from .explorers import (
    DISTURBANCES,
    FAMILIES,
    Channel,
    ExplorerFigure,
    Frame,
    Scenario,
    Settings,
    case_study_scenario,
    compute_frame,
    disturbance_signals,
    expand_poles,
    make_scenario,
    missile_scenario,
    pa9_scenario,
    render,
)
from .luenberger import luenberger_poles

__all__ = [
    "DISTURBANCES",
    "FAMILIES",
    "Channel",
    "Settings",
    "Scenario",
    "Frame",
    "ExplorerFigure",
    "pa9_scenario",
    "case_study_scenario",
    "missile_scenario",
    "make_scenario",
    "expand_poles",
    "format_poles",
    "disturbance_signals",
    "luenberger_poles",
    "compute_frame",
    "render",
]


def format_poles(poles: Sequence[complex]) -> str:
    """Poles as short text with three significant digits: :func:`uio_teach._display.format_poles`.

    Parameters
    ----------
    poles : sequence of complex
        The poles.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorer import format_poles
    >>> format_poles([8.9e-16, 0.5, -1 + 2j])
    '0, 0.5, -1 + 2j'
    """
    return _format_poles(poles, 3)
