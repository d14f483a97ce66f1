"""teachfit: teach robots tight-fit assembly from a few demonstrations and a few trials.

Data flows through the sub-packages in this order::

    demonstrations -> models -> trajectories / skills / plans -> execution -> metrics

with ``tasks`` (the simulated assembly cells), ``robot`` (the robot interface and its MuJoCo
implementation), ``control`` (impedance control laws) and ``viz`` (figures, video) beside them.
"""

from teachfit.core.errors import (
    ControlError,
    DatasetError,
    ModelError,
    PlanningError,
    RenderError,
    SimulationDiverged,
    TaskError,
    TeachfitError,
)

__version__ = "0.1.0"

__all__ = [
    "ControlError",
    "DatasetError",
    "ModelError",
    "PlanningError",
    "RenderError",
    "SimulationDiverged",
    "TaskError",
    "TeachfitError",
    "__version__",
]
