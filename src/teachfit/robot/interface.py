"""The robot interface everything above the robot layer talks to.

A robot reports :class:`~teachfit.core.state.RobotState` and accepts
:class:`~teachfit.core.state.ImpedanceCommand`: a desired pose and twist, a feed-forward
wrench, and the Cartesian stiffness and damping to track them with. This is what
torque-controlled arms expose (KUKA FRI Cartesian impedance, Franka's ``cartesian_impedance``
example). The robot runs its control loop itself, at its own rate; which control law that loop
runs is *data* (:data:`~teachfit.core.control.ControllerSpec`, fixed-gain or adaptive
impedance) handed over at :meth:`Robot.reset`. The simulated floating tool implements this
protocol with MuJoCo; a 7-DOF arm or a real driver implements the same one and registers
itself in :mod:`teachfit.robot.registry`. Nothing above this layer touches MuJoCo.

A command expires: ``expires_after`` seconds after it was sent the set-point stops moving with
the commanded twist. Faults are typed (:class:`~teachfit.core.errors.RobotFault` and its
subclasses :class:`~teachfit.core.errors.ReflexFault`,
:class:`~teachfit.core.errors.LimitViolation`, :class:`~teachfit.core.errors.ConnectionLost`,
:class:`~teachfit.core.errors.SimulationDiverged`); after one, the robot accepts no command until
the next :meth:`Robot.reset`.

Frames and units: positions in metres, quaternions ``w, x, y, z``, twists ``[v; w]`` in m/s and
rad/s, wrenches ``[f; tau]`` in N and N·m, all in the world frame at the tool centre point (TCP).
The measured wrench is the one the *environment exerts on the tool*.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np

from teachfit.core.control import ControllerSpec
from teachfit.core.errors import ControlError
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.core.teaching import TeacherHints

if TYPE_CHECKING:
    from teachfit.tasks.base import Task


@runtime_checkable
class Robot(Protocol):
    """A robot that tracks Cartesian impedance commands at its own control rate."""

    name: str
    #: how the robot measures the external wrench: "wrist-ft" or "joint-torques"
    wrench_source: str

    @property
    def control_period(self) -> float:
        """Seconds per control tick (1 ms for the simulated robots and the Franka)."""
        ...

    @property
    def time(self) -> float:
        """Seconds since the last reset."""
        ...

    def reset(self, pose: Pose, controller: ControllerSpec | None = None) -> RobotState:
        """Place (simulation) or move (real robot) the TCP to ``pose`` at rest, zero the wrench
        reading, and run ``controller`` from now on (``None``: keep the current law; a fresh
        robot runs fixed-gain impedance). Clears a latched fault."""
        ...

    def state(self) -> RobotState:
        """The latest measured state."""
        ...

    def command(self, cmd: ImpedanceCommand) -> None:
        """Set the impedance set-point tracked from now on (until it expires)."""
        ...

    def step(self, n: int = 1) -> RobotState:
        """Let ``n`` control ticks pass (simulation: integrate; real robot: wait) and report.

        Raises a :class:`~teachfit.core.errors.RobotFault` when the robot faulted meanwhile.
        """
        ...

    def finish_execution(self) -> None:
        """The execution commanding the robot has ended: stop acting on its last command now.

        A simulated robot's time runs only in :meth:`step`: nothing to do. A real arm's control
        loop runs on while the caller judges and logs the execution, so the skill's press would
        go on (the Franka lets the part go and holds it at rest in the hole)."""
        ...

    def close(self) -> None:
        """Release the robot (stop the control loop, free the connection or the simulator)."""
        ...

    def teacher_hints(self, task: Task) -> TeacherHints:
        """How a person guiding this robot demonstrates ``task``: overrides of the blind
        teacher's style fields (:class:`~teachfit.core.teaching.TeacherHints`), applied by
        ``execution.teacher.style_for`` on fields left at their defaults. The one per-robot
        table; :data:`NO_TEACHER_HINTS` for a robot that needs none (the floating tool)."""
        ...


@runtime_checkable
class NoiseSeeded(Protocol):
    """A simulated robot whose sensor noise comes from its own seeded stream.

    A batch that runs many trials on one robot restarts that stream per trial (from the
    trial's own seed), so that a trial's noise depends on the trial alone, not on the trials
    that ran before it in the same process. A real arm's noise is its sensors' own: it does
    not implement this.
    """

    def seed_noise(self, seed: int) -> None:
        """Restart the sensor noise's stream from ``seed`` (integer >= 0); the readings from
        the next :meth:`Robot.reset` on draw from it."""
        ...


def restart_noise(robot: object, seed: int) -> None:
    """Restart ``robot``'s sensor noise from ``seed`` if it is :class:`NoiseSeeded` (a
    simulated robot); a real arm is left as it is. Batches call it before each trial."""
    if isinstance(robot, NoiseSeeded):
        robot.seed_noise(seed)


def reseed(rng: np.random.Generator, seed: int) -> None:
    """Restart ``rng`` in place (every holder of the generator sees it) on the noise stream of
    ``seed``: the child ``(1,)`` of its :class:`numpy.random.SeedSequence`, apart from the draws
    of ``default_rng(seed)`` that a trial makes from the same seed."""
    child = np.random.SeedSequence(seed, spawn_key=(1,))
    rng.bit_generator.state = np.random.PCG64(child).state


def law_fault(law: object, t: float) -> ControlError | None:
    """A :class:`ControlError` if the control law's last wrench is not finite, else ``None``.

    A simulator asks before it reports a diverged state: when the law (an adaptive law whose
    gains blew up, a NaN in a command) produced the NaN, the law is the cause, not the physics.
    """
    w = getattr(law, "last_wrench", None)
    if w is None or np.all(np.isfinite(w)):
        return None
    return ControlError(
        f"the {type(law).__name__} control law produced a non-finite wrench {np.asarray(w)} "
        f"at t={t:.3f} s (its command or gains are invalid); the simulation is invalid after it"
    )
