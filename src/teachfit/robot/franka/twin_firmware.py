"""The twin's firmware: what a Franka's controller does that a libfranka client can tell.

:class:`FirmwareServer` is franky-sim's libfranka-protocol server
(:class:`~franky_sim.franka_robot_server.FrankaRobotServer`) with, on top:

* **the external-wrench estimate** in the state: ``tau_ext_hat_filtered``, ``O_F_ext_hat_K`` and
  ``K_F_ext_hat_K`` from the cell's joint-torque observer
  (:meth:`~teachfit.robot.franka.twin_cell.TwinSimulator.external_wrench`, libfranka's sign:
  the wrench the robot exerts on the environment);
* **collision reflexes** with the thresholds of libfranka's ``setCollisionBehavior``
  (:class:`CollisionThresholds`; the firmware's *nominal* thresholds: the twin does not tell
  acceleration phases apart): a component of ``K_F_ext_hat_K`` over its upper force threshold
  is a ``cartesian_reflex``, a joint's ``tau_ext_hat_filtered`` over its upper torque threshold
  a ``joint_reflex``; over the lower ones sets ``cartesian_contact`` / ``joint_contact``;
* **limits** checked every tick of a motion: joint position and speed (the FR3 datasheet's,
  :mod:`teachfit.robot.fr3.params`), the commanded torque's rate (1000 N·m/s:
  ``controller_torque_discontinuity``), and the communication constraint: more than
  ``max_missed`` (20) consecutive ticks of a torque motion without a command from the client
  (``communication_constraints_violation``; in real-time mode only, see
  :class:`TwinSimulationServer`). The FCI documentation ("Minimum system and network
  requirements") states that limit: 20 consecutive dropped packets stop the robot, and a
  dropped controller packet reuses the last torques (as franky-sim does); the state's
  ``control_command_success_rate`` is the share of the last 100 ticks of the motion that got
  a command.

Any of them aborts the running motion as the firmware does: the Move command is answered
``kReflexAborted``, the error is set in the state's ``errors`` and ``reflex_reason`` (libfranka's
``current_errors`` / ``last_motion_errors``), the robot mode turns ``kReflex`` and the arm holds
where it is; the client's libfranka then raises ``ControlException`` ("Motion aborted by
reflex! [...]"). A new motion is refused (``kCommandNotPossibleRejected``) until
``automaticErrorRecovery`` clears the errors.
"""

from __future__ import annotations

import logging
import select
import time
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from franky_sim.franka_robot_protocol import (
    AutomaticErrorRecoveryCommand,
    AutomaticErrorRecoveryStatus,
    MoveCommand,
    MoveStatus,
    RobotCommand,
    RobotMode,
    SetCollisionBehaviorCommand,
    UDPCommand,
)
from franky_sim.franka_robot_server import ControlMode, FrankaRobotServer
from franky_sim.franka_server import BaseCommand
from franky_sim.simulation_server import SimulationServer

from teachfit.robot.fr3.params import DQ_MAX, DTAU_MAX, Q_MAX, Q_MIN
from teachfit.robot.franka.twin_cell import TwinSimulator

#: libfranka's error flags in the order of the protocol's 41 error bytes: libfranka's
#: ``research_interface::robot::Error`` (0-36, the order libfranka's ``franka::Errors`` reads
#: them in; libfranka-rs' ``FrankaError`` numbers them alike) and the 4 flags newer firmware
#: added (37-40, pylibfranka's ``Errors``); the tests check the ones the twin raises by name
ERRORS = (
    "joint_position_limits_violation", "cartesian_position_limits_violation",
    "self_collision_avoidance_violation", "joint_velocity_violation",
    "cartesian_velocity_violation", "force_control_safety_violation", "joint_reflex",
    "cartesian_reflex", "max_goal_pose_deviation_violation", "max_path_pose_deviation_violation",
    "cartesian_velocity_profile_safety_violation",
    "joint_position_motion_generator_start_pose_invalid",
    "joint_motion_generator_position_limits_violation",
    "joint_motion_generator_velocity_limits_violation",
    "joint_motion_generator_velocity_discontinuity",
    "joint_motion_generator_acceleration_discontinuity",
    "cartesian_position_motion_generator_start_pose_invalid",
    "cartesian_motion_generator_elbow_limit_violation",
    "cartesian_motion_generator_velocity_limits_violation",
    "cartesian_motion_generator_velocity_discontinuity",
    "cartesian_motion_generator_acceleration_discontinuity",
    "cartesian_motion_generator_elbow_sign_inconsistent",
    "cartesian_motion_generator_start_elbow_invalid",
    "force_controller_desired_force_tolerance_violation", "start_elbow_sign_inconsistent",
    "communication_constraints_violation", "power_limit_violation",
    "cartesian_motion_generator_joint_position_limits_violation",
    "cartesian_motion_generator_joint_velocity_limits_violation",
    "cartesian_motion_generator_joint_velocity_discontinuity",
    "cartesian_motion_generator_joint_acceleration_discontinuity",
    "cartesian_position_motion_generator_invalid_frame", "controller_torque_discontinuity",
    "joint_p2p_insufficient_torque_for_planning", "tau_j_range_violation",
    "instability_detected", "joint_move_in_wrong_direction",
    "cartesian_spline_motion_generator_violation",
    "joint_via_motion_generator_planning_joint_limit_violation",
    "base_acceleration_initialization_timeout", "base_acceleration_invalid_reading",
)  # fmt: skip
_E = {name: i for i, name in enumerate(ERRORS)}
log = logging.getLogger(__name__)

#: the thresholds libfranka's examples set (``setDefaultBehavior``, N·m per joint; N, N·m)
DEFAULT_TORQUE_THRESHOLDS = (20.0, 20.0, 18.0, 18.0, 16.0, 14.0, 12.0)
DEFAULT_FORCE_THRESHOLDS = (20.0, 20.0, 20.0, 25.0, 25.0, 25.0)


@dataclass(frozen=True)
class CollisionThresholds:
    """``setCollisionBehavior``'s thresholds: contact (lower) and collision (upper), per joint
    (N·m) and per Cartesian component of the wrench at K, in K's axes (N, N·m)."""

    lower_torque: tuple[float, ...] = DEFAULT_TORQUE_THRESHOLDS
    upper_torque: tuple[float, ...] = DEFAULT_TORQUE_THRESHOLDS
    lower_force: tuple[float, ...] = DEFAULT_FORCE_THRESHOLDS
    upper_force: tuple[float, ...] = DEFAULT_FORCE_THRESHOLDS


class _SetCollisionBehavior(SetCollisionBehaviorCommand):
    def handle(self, server: FirmwareServer) -> None:
        server.thresholds = CollisionThresholds(
            tuple(self.lower_torque_thresholds_nominal),
            tuple(self.upper_torque_thresholds_nominal),
            tuple(self.lower_force_thresholds_nominal),
            tuple(self.upper_force_thresholds_nominal),
        )
        self.reply(0)


class _Recovery(AutomaticErrorRecoveryCommand):
    def handle(self, server: FirmwareServer) -> None:
        server.recover()
        self.reply(AutomaticErrorRecoveryStatus.kSuccess)


class _Move(MoveCommand):
    def handle(self, server: FirmwareServer) -> None:
        if server.errors.any():  # reflex mode: no motion until the errors are recovered
            self.reply(MoveStatus.kCommandNotPossibleRejected)
            return
        super().handle(server)


class FirmwareServer(FrankaRobotServer):
    """franky-sim's robot server on the twin's cell, with the firmware's estimate, reflexes and
    limits (see the module docstring).

    Parameters
    ----------
    sim : TwinSimulator
    hostname_candidates : addresses to bind (the first free one)
    max_missed : int or None
        Consecutive ticks of a torque motion without a command that violate the communication
        constraint (``None``: not checked).
    """

    def __init__(
        self, sim: TwinSimulator, hostname_candidates: Iterable[str], max_missed: int | None
    ) -> None:
        self.sim = sim
        self.max_missed = max_missed
        self.thresholds = CollisionThresholds()
        self.errors = np.zeros(len(ERRORS), dtype=bool)
        self.reflex_reason = np.zeros(len(ERRORS), dtype=bool)
        self.torque_mode = False
        #: ticks of the running motion since its last command; whether it sent one yet
        self.missed, self.commanded, self.fresh = 0, False, False
        self._tau_prev = np.zeros(7)
        self._rate_exceeded = False
        self._stepped = False
        self._received = np.ones(100, dtype=bool)  # the last 100 ticks: a command came
        self._tick = 0
        self._o_f = np.zeros(6)
        self._k_f = np.zeros(6)
        self._tau_ext = np.zeros(7)
        super().__init__(sim.robot, hostname_candidates)
        commands = self._FrankaServer__command_class_map  # franky-sim's dispatch table
        commands[RobotCommand.kMove] = _Move
        commands[RobotCommand.kSetCollisionBehavior] = _SetCollisionBehavior
        commands[RobotCommand.kAutomaticErrorRecovery] = _Recovery

    # ------------------------------------------------------------------ motions
    def start_motion(self, controller: Any, generator: Any, motion_id: int) -> None:
        super().start_motion(controller, generator, motion_id)
        self.torque_mode = self._FrankaRobotServer__control_mode == ControlMode.TORQUE
        self.missed, self.commanded, self._rate_exceeded = 0, False, False
        self._tau_prev = np.zeros(7)
        self._received[:] = True

    def stop_motion(self, send_preemption_signal: bool = True) -> None:
        super().stop_motion(send_preemption_signal)
        self.torque_mode = self.commanded = False

    def awaiting_command(self) -> bool:
        """A torque motion has commanded and no new command came this tick."""
        return self.torque_mode and self.commanded and not self.fresh

    def wait_for_command(self, timeout: float) -> None:
        """Block until the client's UDP socket has data (a command) or ``timeout`` s pass."""
        sock = self._FrankaServer__udp_socket  # franky-sim's per-client UDP socket
        if sock is not None:
            select.select([sock], [], [], timeout)

    def _pre_process_commands(self) -> None:
        super()._pre_process_commands()
        self.fresh = False

    def _handle_udp_command(self, command_data: bytes) -> None:
        if self.torque_mode:
            tau = np.asarray(UDPCommand.from_bytes(command_data).tau_J_d)
            ticks = self.missed + 1
            step = DTAU_MAX * 1e-3 * ticks + 1e-9  # libfranka's own limiter stops just under it
            if self.commanded and np.any(np.abs(tau - self._tau_prev) > step):
                self._rate_exceeded = True
            self._tau_prev = tau
            self.commanded, self.fresh, self.missed = True, True, 0
        super()._handle_udp_command(command_data)

    def tick_done(self) -> None:
        """The physics stepped: count a tick the client missed; estimate and check anew."""
        self._stepped = True
        if self.torque_mode and self.commanded:
            self._received[self._tick % len(self._received)] = self.fresh
            self._tick += 1
            self.missed = 0 if self.fresh else self.missed + 1

    def _post_process_commands(self) -> None:
        stepped, self._stepped = self._stepped, False
        if stepped:
            self._estimate()
        if stepped and self.current_motion_id and not self.errors.any():
            violated = self._violations()
            if violated:
                self._reflex(violated)
        super()._post_process_commands()

    # ------------------------------------------------------------------ the firmware's checks
    def _estimate(self) -> None:
        ee_t_k = np.asarray(self.robot.EE_T_K, dtype=float).reshape(4, 4, order="F")
        self._o_f = self.sim.external_wrench(ee_t_k)
        rot = self.sim.ee_frame()[1] @ ee_t_k[:3, :3]  # K's axes in the base frame
        self._k_f = np.concatenate([rot.T @ self._o_f[:3], rot.T @ self._o_f[3:]])
        self._tau_ext = -self.sim.external_torques()  # libfranka's sign, as O_F_ext_hat_K

    def _violations(self) -> list[str]:
        th = self.thresholds
        out = []
        if np.any(np.abs(self._k_f) > np.asarray(th.upper_force)):
            out.append("cartesian_reflex")
        if np.any(np.abs(self._tau_ext) > np.asarray(th.upper_torque)):
            out.append("joint_reflex")
        q, dq = self.sim.joints()
        if np.any(q < np.asarray(Q_MIN)) or np.any(q > np.asarray(Q_MAX)):
            out.append("joint_position_limits_violation")
        if np.any(np.abs(dq) > np.asarray(DQ_MAX)):
            out.append("joint_velocity_violation")
        if self._rate_exceeded:
            out.append("controller_torque_discontinuity")
        if self.max_missed is not None and self.missed > self.max_missed:
            out.append("communication_constraints_violation")
        return out

    def _reflex(self, violated: list[str]) -> None:
        """Abort the running motion as the firmware does (see the module docstring)."""
        for name in violated:
            self.errors[_E[name]] = self.reflex_reason[_E[name]] = True
        motion = self.current_motion_id
        log.warning(
            "twin: motion aborted by reflex %s (K_F_ext_hat_K %s N, N·m; tau_ext %s N·m)",
            violated,
            np.round(self._k_f, 1).tolist(),
            np.round(self._tau_ext, 1).tolist(),
        )
        self.stop_motion(send_preemption_signal=False)
        BaseCommand.send_response(
            self._tcp_socket, RobotCommand.kMove, motion, MoveStatus.kReflexAborted
        )
        self.reset_current_motion_id()

    def recover(self) -> None:
        """``automaticErrorRecovery``: clear the errors; the robot is idle again."""
        self.errors[:] = False
        self.reflex_reason[:] = False

    @property
    def robot_state(self) -> Any:
        th = self.thresholds
        state = super().robot_state
        return state.replace(
            O_F_ext_hat_K=tuple(self._o_f.tolist()),
            K_F_ext_hat_K=tuple(self._k_f.tolist()),
            tau_ext_hat_filtered=tuple(self._tau_ext.tolist()),
            cartesian_contact=_flags(self._k_f, th.lower_force),
            cartesian_collision=_flags(self._k_f, th.upper_force),
            joint_contact=_flags(self._tau_ext, th.lower_torque),
            joint_collision=_flags(self._tau_ext, th.upper_torque),
            errors=tuple(self.errors.tolist()),
            reflex_reason=tuple(self.reflex_reason.tolist()),
            robot_mode=RobotMode.kReflex if self.errors.any() else state.robot_mode,
            control_command_success_rate=float(self._received.mean()),
        )


def _flags(values: np.ndarray, thresholds: tuple[float, ...]) -> tuple[float, ...]:
    """1.0 where ``|values|`` is over its threshold, else 0.0 (libfranka's contact levels)."""
    return tuple(np.where(np.abs(values) > np.asarray(thresholds), 1.0, 0.0).tolist())


class TwinSimulationServer(SimulationServer):
    """franky-sim's 1 kHz loop serving the twin's one robot through :class:`FirmwareServer`.

    ``realtime``: the physics steps every millisecond of wall-clock time whatever the client
    does, and a client that misses more than ``max_missed`` ticks of a torque motion violates
    the communication constraint (as on the real robot). Otherwise (``--no-realtime``, a
    machine without a real-time kernel) a running torque motion is stepped in lock-step with
    the client: after its first command, each tick waits for the client's next command, so a
    late client slows the twin down instead of missing ticks (at most 1 kHz either way).
    While it waits, the hand still sends its state every 10 ms, as a Franka Hand does on its
    own clock: a client that reads the hand (``Gripper.read_once``, which holds the GIL in
    pylibfranka) from the thread beside its control loop would otherwise wait for a hand
    state that only the next arm tick sends, and time out.
    """

    def __init__(
        self, sim: TwinSimulator, host: str, realtime: bool = True, max_missed: int = 20
    ) -> None:
        super().__init__(sim, hostname_candidates=[host])
        self.twin: FirmwareServer | None = None
        self.realtime = realtime
        self.max_missed = max_missed

    def init(self) -> None:
        self.twin = FirmwareServer(
            self.sim, [self._hostname_candidates[0]], self.max_missed if self.realtime else None
        )
        self.twin.init()
        self.robot_servers.append(self.twin)
        self.sim.start()

    def run_once(self, realtime: bool | float = True) -> None:
        start = time.perf_counter()
        twin = self.twin
        assert twin is not None, "init() first"
        twin.process_commands()
        if not self.realtime and twin.awaiting_command():
            twin.wait_for_command(0.01)  # the client is late: wait, the physics does not move
            hand = twin.gripper_server
            if hand is not None:  # the hand keeps sending its state on its own clock
                hand.send_state()
            return
        self.sim.step()
        twin.tick_done()
        twin.send_state()
        time.sleep(max(0.0, 1e-3 - (time.perf_counter() - start)))
