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

from . import checks, examples, linalg, plotting, signals
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
from .existence import Condition, ExistenceReport, UIOExistenceError, check_existence
from .isolation import BankMember, Isolation, UIOBank, design_uio_bank
from .lmi import LMIError, LMIInfeasibleError, LMIResult, LMISolverError, lmi_gain
from .observers import (
    PMO,
    UIO,
    GInverseObserver,
    LuenbergerObserver,
    Observer,
    ObserverRealization,
    UnstableObserverWarning,
    design_ginverse,
    design_luenberger,
    design_pmo,
    design_uio,
)
from .plant import Plant
from .reconstruction import InputEstimate, catch_time, reconstruct_input
from .simulation import SimulationInputs, SimulationOverflowError, UIOResponse, simulate
from .verify import PlacementAccuracyError, PlacementAccuracyWarning

__version__ = "0.1.0"

# The explorers need ipywidgets and matplotlib: loaded on first use, not by `import uio_teach`.
# The worked experiments (`ut.experiments`) are found the same way if nothing imported them yet.
_LAZY = {
    "widgets": None,
    "explorer": None,
    "static_explorer": None,
    "explorers": None,
    "experiments": None,
    "pa9_explorer": "widgets",
    "case_study_explorer": "widgets",
    "missile_explorer": "widgets",
}


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    module = importlib.import_module(f".{_LAZY[name] or name}", __name__)
    return module if _LAZY[name] is None else getattr(module, name)


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY])


__all__ = [
    "Plant",
    "examples",
    "experiments",
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
    "Observer",
    "ObserverRealization",
    "UIO",
    "PMO",
    "GInverseObserver",
    "LuenbergerObserver",
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
    "widgets",
    "explorer",
    "static_explorer",
    "explorers",
    "pa9_explorer",
    "case_study_explorer",
    "missile_explorer",
]
