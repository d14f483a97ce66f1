"""Every robot teachfit can drive, by name: the one place that builds a robot.

``make_robot("floating", task)`` returns a ready :class:`~teachfit.robot.interface.Robot`.
A new robot (a simulated arm, a real driver) is one module and one :func:`register` call;
every command that runs a robot takes ``--robot NAME`` from :data:`ROBOTS`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from teachfit.core.control import ControllerSpec
from teachfit.core.errors import TeachfitError
from teachfit.robot.interface import Robot
from teachfit.tasks.base import Task

Factory = Callable[..., Robot]


@dataclass(frozen=True)
class RobotEntry:
    """A registered robot: how to build it and what it is (one line for ``--help``)."""

    name: str
    factory: Factory
    description: str
    simulated: bool = True


ROBOTS: dict[str, RobotEntry] = {}


def register(entry: RobotEntry) -> None:
    """Add a robot to :data:`ROBOTS` (a second entry of the same name is an error)."""
    if entry.name in ROBOTS:
        raise TeachfitError(f"robot {entry.name!r} is registered twice")
    ROBOTS[entry.name] = entry


def make_robot(
    name: str,
    task: Task,
    *,
    controller: ControllerSpec | None = None,
    seed: int = 0,
    **options: Any,
) -> Robot:
    """The robot ``name`` for ``task``'s cell, running ``controller`` (default fixed-gain).

    ``seed`` seeds a simulated robot's sensor noise; ``options`` are the robot's own (e.g. a
    real robot's ``host``). Unknown names raise :class:`TeachfitError` listing the known ones.
    """
    try:
        entry = ROBOTS[name]
    except KeyError:
        raise TeachfitError(f"unknown robot {name!r}; known robots: {sorted(ROBOTS)}") from None
    return entry.factory(task, controller=controller, seed=seed, **options)


def _floating(
    task: Task, *, controller: ControllerSpec | None = None, seed: int = 0, **options: Any
) -> Robot:
    from teachfit.robot.floating import FloatingToolParams, FloatingToolRobot

    params = options.pop("params", None)
    if options:
        raise TeachfitError(f"robot 'floating' takes no option(s) {sorted(options)}")
    return FloatingToolRobot(
        task, controller=controller, params=params or FloatingToolParams(), seed=seed
    )


register(
    RobotEntry(
        "floating",
        _floating,
        "a free 6-DOF tool pushed by the impedance wrench, wrist F/T sensor (MuJoCo)",
    )
)


def _fr3(
    task: Task, *, controller: ControllerSpec | None = None, seed: int = 0, **options: Any
) -> Robot:
    import dataclasses

    from teachfit.robot.fr3 import FR3Params, FR3Robot

    params = options.pop("params", None) or FR3Params()
    known = {f.name for f in dataclasses.fields(FR3Params)}
    unknown = sorted(set(options) - known)
    if unknown:
        raise TeachfitError(f"robot 'fr3' takes no option(s) {unknown}; known: {sorted(known)}")
    if options:
        params = dataclasses.replace(params, **options)
    return FR3Robot(task, controller=controller, params=params, seed=seed)


def _franka(
    task: Task, *, controller: ControllerSpec | None = None, seed: int = 0, **options: Any
) -> Robot:
    from teachfit.robot.franka import franka_for_task

    del seed  # a real robot has no simulated noise to seed
    return franka_for_task(task, controller=controller, **options)


register(
    RobotEntry(
        "fr3",
        _fr3,
        "a torque-controlled 7-DOF Franka FR3: Cartesian impedance in joint torques, external "
        "wrench from joint torques (sensor='wrist-ft': a wrist F/T sensor) (MuJoCo)",
    )
)

register(
    RobotEntry(
        "franka",
        _franka,
        "a real Franka FR3/Panda over libfranka (host=ADDRESS), torque control, "
        "wrench from joint torques (pip install teachfit[franka])",
        simulated=False,
    )
)
