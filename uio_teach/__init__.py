"""uio_teach: unknown input observers for linear systems, for teaching.

The companion package of the course *Unknown Input Observers*. It holds the
algorithms; the book tells the story.

Examples
--------
>>> import uio_teach as ut
>>> plant = ut.examples.pa9()
>>> ut.check_existence(plant).ok
True
>>> ut.design_uio(plant, poles=[-1, -2, -3]).poles().real.round(6).tolist()
[-3.0, -2.0, -1.0]
"""

import importlib

from . import data_driven, examples, linalg, signals
from .data_driven import (
    DataConditionError,
    DataConditioningWarning,
    DataReport,
    check_data,
    design_uio_from_data,
)
from .detection import (
    Detection,
    Fault,
    Threshold,
    actuator_fault,
    detect,
    detection_time,
    false_alarm_rate,
    observer_residual,
    process_fault,
    residual_rms,
    residual_threshold,
    sensor_fault,
    simulate_fault,
)
from .errors import InputError, UIOTeachError, UIOTeachWarning
from .existence import Condition, ExistenceReport, UIOExistenceError, check_existence
from .isolation import BankMember, Isolation, UIOBank, design_uio_bank
from .lmi import LMIError, LMIInfeasibleError, LMIResult, LMISolverError, lmi_gain
from .nullspace import (
    FaultModel,
    NullspaceFilter,
    NullspaceFilterError,
    decoupling_gap,
    design_nullspace_filter,
    fault_model,
)
from .observers import (
    PMO,
    UIO,
    DelayedUIO,
    DelayedUIOExistenceError,
    DelayVerdict,
    GInverseObserver,
    LuenbergerObserver,
    Observer,
    ObserverRealization,
    ReducedUIO,
    UnstableObserverWarning,
    delay_verdict,
    design_delayed_uio,
    design_ginverse,
    design_luenberger,
    design_pmo,
    design_reduced_uio,
    design_uio,
)
from .plant import Plant
from .reconstruction import InputEstimate, catch_time, reconstruct_input
from .simulation import SimulationInputs, SimulationOverflowError, UIOResponse, simulate
from .verify import PlacementAccuracyError, PlacementAccuracyWarning

__version__ = "0.1.0"

# Loaded on first use, not by `import uio_teach`, so that a script (or `uio-teach figures`)
# that needs only the algorithms does not pay for them: the lab checks (`ut.checks`, which
# build the worked experiments and their figures), the plotting layer and the explorers
# (matplotlib figures; ipywidgets for the live explorers), the worked experiments and the
# registry of the worked examples.
_LAZY = ("checks", "experiments", "explorers", "plotting", "worked")


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return importlib.import_module(f".{name}", __name__)


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY])


__all__ = [
    "InputError",
    "UIOTeachError",
    "UIOTeachWarning",
    "Plant",
    "examples",
    "experiments",
    "worked",
    "linalg",
    "signals",
    "plotting",
    "checks",
    "check_existence",
    "Condition",
    "ExistenceReport",
    "UIOExistenceError",
    "lmi_gain",
    "LMIResult",
    "LMIInfeasibleError",
    "LMIError",
    "LMISolverError",
    "PlacementAccuracyError",
    "PlacementAccuracyWarning",
    "SimulationOverflowError",
    "design_uio",
    "design_pmo",
    "design_ginverse",
    "design_luenberger",
    "data_driven",
    "design_uio_from_data",
    "check_data",
    "DataReport",
    "DataConditionError",
    "DataConditioningWarning",
    "design_reduced_uio",
    "design_delayed_uio",
    "delay_verdict",
    "Observer",
    "ObserverRealization",
    "UIO",
    "PMO",
    "GInverseObserver",
    "LuenbergerObserver",
    "ReducedUIO",
    "DelayedUIO",
    "DelayVerdict",
    "DelayedUIOExistenceError",
    "UnstableObserverWarning",
    "simulate",
    "UIOResponse",
    "SimulationInputs",
    "reconstruct_input",
    "InputEstimate",
    "catch_time",
    "Fault",
    "actuator_fault",
    "sensor_fault",
    "process_fault",
    "simulate_fault",
    "observer_residual",
    "residual_rms",
    "Threshold",
    "residual_threshold",
    "Detection",
    "detect",
    "false_alarm_rate",
    "detection_time",
    "design_uio_bank",
    "UIOBank",
    "BankMember",
    "Isolation",
    "fault_model",
    "FaultModel",
    "design_nullspace_filter",
    "NullspaceFilter",
    "NullspaceFilterError",
    "decoupling_gap",
    "explorers",
]
