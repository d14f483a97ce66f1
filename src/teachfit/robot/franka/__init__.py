"""A real Franka arm behind :class:`~teachfit.robot.interface.Robot` (pylibfranka torque control).

Modules: :mod:`.driver` (:class:`FrankaRobot`), :mod:`.tick` (the per-tick law-to-torque
computation), :mod:`.safety` (:class:`FrankaLimits`), :mod:`.frames` (base/world, EE/TCP),
:mod:`.record` (kinesthetic teaching), :mod:`.check` (``robot check`` and the loop benchmark),
:mod:`.sim` (the libfranka-protocol simulator franky-sim, confined to loopback), :mod:`.twin`
(``teachfit robot twin``: the task's cell behind libfranka's protocol, with the firmware's
wrench estimate, reflexes and limits; :mod:`.twin_cell`, :mod:`.twin_firmware`).
Needs the ``franka`` extra (``pylibfranka``; ``franky-sim`` for the simulator).
"""

from __future__ import annotations

from typing import Any

from teachfit.core.control import ControllerSpec
from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose
from teachfit.robot.franka.frames import DEFAULT_BASE2WORLD, FrankaFrames, ee2tcp_for_part
from teachfit.robot.franka.safety import FrankaLimits

__all__ = [
    "DEFAULT_BASE2WORLD",
    "FrankaFrames",
    "FrankaLimits",
    "ee2tcp_for_part",
    "franka_for_task",
]


def franka_for_task(
    task: Any,
    *,
    host: str | None = None,
    controller: ControllerSpec | None = None,
    base2world: Pose | None = None,
    ee2tcp: Pose | None = None,
    limits: FrankaLimits | None = None,
    realtime: bool = True,
    confirm: bool = False,
    reflex_force: float | None = None,
) -> Any:
    """A connected :class:`~teachfit.robot.franka.driver.FrankaRobot` for ``task``'s cell.

    ``host`` the robot's address (required), ``base2world`` where the robot base sits in the
    task world (default :data:`DEFAULT_BASE2WORLD`), ``ee2tcp`` the TCP in libfranka's EE frame
    (default: the task's held part of ``held_part_length`` with its top at EE). Resets leave
    the task's hole along its axis first (:mod:`teachfit.robot.franka.reset_path`);
    ``confirm`` asks on the terminal before each one (:mod:`teachfit.robot.franka.confirm`).
    ``reflex_force`` (N) the firmware's collision reflex threshold
    (:mod:`teachfit.robot.franka.reflex`; ``None``: 1.25 x the driver's force limit, 75 N).
    The task's held part is sent as the firmware's load (:mod:`teachfit.robot.franka.load`).
    """
    if not host:
        raise TeachfitError("robot 'franka' needs host=ADDRESS (the robot's or simulator's IP)")
    try:
        from teachfit.robot.franka.driver import FrankaParams, FrankaRobot
    except ImportError as exc:  # pragma: no cover - depends on the installed extras
        raise TeachfitError(
            f"robot 'franka' needs pylibfranka: pip install teachfit[franka] ({exc})"
        ) from exc
    frames = FrankaFrames(
        base2world=base2world or DEFAULT_BASE2WORLD,
        ee2tcp=ee2tcp or ee2tcp_for_part(task.scene.held_part_length),
    )
    from teachfit.robot.franka.reset_path import ResetCell

    hole = task.hole2world
    # the part's tip 5 mm above the surface around the hole is clear of the fixture
    clear = float(task.surface_z - hole.pos[2]) + 0.005
    cell = ResetCell(hole, clear)
    from teachfit.robot.franka.load import part_load

    params = FrankaParams(
        limits=limits or FrankaLimits(),
        frames=frames,
        reset_cell=cell,
        reflex_force=reflex_force,
        load=part_load(task),
    )
    ask = None
    if confirm:
        from teachfit.robot.franka.confirm import terminal_confirm

        ask = terminal_confirm()  # refused here without a terminal, before connecting
    return FrankaRobot(host, controller=controller, params=params, realtime=realtime, confirm=ask)
