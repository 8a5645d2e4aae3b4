"""Explorers: move the observer poles and the disturbance, see the observer respond.

The explorers put an unknown input observer next to a plain Luenberger observer with the
same poles, for one plant, and let a student move the poles and the disturbance:

* :mod:`~uio_teach.explorers.model` -- what is explored (:class:`Scenario`) and the values
  of the controls (:class:`Settings`, :class:`Channel`, :func:`disturbance_signals`);
* :mod:`~uio_teach.explorers.scenarios` -- the worked examples' scenarios
  (:func:`scenario_of`, from the registry :data:`uio_teach.worked.WORKED`) and
  :func:`make_scenario` for any plant;
* :mod:`~uio_teach.explorers.frames` -- :func:`compute_frame`: design, simulate and
  prepare one picture (:class:`Frame`), never raising for a value a student can set;
* :mod:`~uio_teach.explorers.modes` -- the error's modes: which the start excites
  (:func:`excited_modes`), which the controls move, how fast they shrink the error;
* :mod:`~uio_teach.explorers.messages` -- the words, all derived from one
  :class:`ErrorVerdict` on the simulated error;
* :class:`ExplorerFigure` and :func:`render` -- the figure, updated in place;
* :mod:`~uio_teach.explorers.widgets` -- the live explorers (ipywidgets, loaded on first
  use): :func:`~uio_teach.explorers.widgets.pa9_explorer` and the others;
* :mod:`~uio_teach.explorers.static` -- pre-computed frames with a slider for the static
  book.

The Luenberger observer's poles follow :func:`uio_teach.luenberger.luenberger_poles`.

Examples
--------
>>> from uio_teach.explorers import compute_frame, scenario_of
>>> scenario = scenario_of("pa9")
>>> frame = compute_frame(scenario, scenario.defaults.replace(poles=(-2.0, -3.0, -4.0)))
>>> frame.poles.real.round(6).tolist()
[-4.0, -3.0, -2.0]
>>> frame.messages
()
"""

from ..luenberger import luenberger_poles
from ._figure import ExplorerFigure, render
from .frames import Frame, compute_frame
from .messages import ErrorVerdict, error_grows
from .model import (
    DISTURBANCES,
    FAMILIES,
    STARTS,
    Channel,
    PlantControl,
    Scenario,
    Settings,
    default_poles,
    default_timepts,
    disturbance_signals,
    expand_poles,
)
from .modes import excited_modes
from .scenarios import make_scenario, scenario_of

__all__ = [
    "DISTURBANCES",
    "FAMILIES",
    "STARTS",
    "Channel",
    "PlantControl",
    "Settings",
    "Scenario",
    "Frame",
    "ExplorerFigure",
    "make_scenario",
    "scenario_of",
    "expand_poles",
    "disturbance_signals",
    "luenberger_poles",
    "compute_frame",
    "excited_modes",
    "error_grows",
    "ErrorVerdict",
    "default_poles",
    "default_timepts",
    "render",
]
