"""``teachfit robot check`` and ``teachfit bench robot --robot franka``: library functions.

:func:`check_robot` connects, reads the state, reports the driver's limits and measures the
loop timing while holding the current pose. :func:`bench_loop` runs the torque loop for a
while (10 s by default) and prints the per-tick compute time (read -> torques ready) and the
missed deadlines. Neither moves the arm: the loop holds the pose it finds.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from teachfit.core.control import ControllerSpec
from teachfit.robot.franka.connect import CONNECT_TIMEOUT
from teachfit.robot.franka.driver import FrankaParams, FrankaRobot
from teachfit.robot.franka.safety import FrankaLimits


@dataclass(frozen=True)
class LoopTiming:
    """Timing of ``ticks`` control ticks.

    ``compute_p50``/``compute_p99``/``compute_max`` per-tick compute time (s), ``overruns``
    ticks whose compute took longer than the period, ``missed_packets`` robot states the loop
    did not read (gaps between consecutive states over 1.5 periods, counted in periods),
    ``period`` (s), ``wall_rate`` ticks per wall-clock second (0: not measured; a real robot
    runs at 1000, a simulator may run slower than real time), ``thread`` the control thread's
    scheduling class (:meth:`~teachfit.robot.franka.priority.ThreadClass.describe`).
    """

    ticks: int
    compute_p50: float
    compute_p99: float
    compute_max: float
    overruns: int
    missed_packets: int
    period: float
    wall_rate: float = 0.0
    thread: str = ""

    def lines(self) -> list[str]:
        """Human-readable figures."""
        hz = 1 / self.period
        out = [
            f"ticks: {self.ticks} ({self.ticks * self.period:.1f} s at {hz:.0f} Hz)",
            f"tick compute time: p50 {self.compute_p50 * 1e6:.0f} µs, p99 "
            f"{self.compute_p99 * 1e6:.0f} µs, max {self.compute_max * 1e6:.0f} µs",
            f"missed deadlines: {self.overruns} ticks over {self.period * 1e3:.0f} ms, "
            f"{self.missed_packets} robot states never read",
        ]
        if self.wall_rate:
            out.append(f"wall-clock rate: {self.wall_rate:.0f} ticks/s")
        if self.thread:
            out.append(f"control thread: {self.thread}")
        return out


@dataclass(frozen=True)
class RobotCheck:
    """What ``teachfit robot check`` prints: connection, state, limits, loop timing."""

    host: str
    robot_mode: str
    q: tuple[float, ...]
    tcp_pos: tuple[float, float, float]
    limits: tuple[tuple[str, str], ...]
    timing: LoopTiming

    def lines(self) -> list[str]:
        out = [f"robot at {self.host}: mode {self.robot_mode}"]
        out.append("joints (rad): " + ", ".join(f"{v:+.3f}" for v in self.q))
        out.append("TCP (m, world): " + ", ".join(f"{v:+.4f}" for v in self.tcp_pos))
        out += [f"{name}: {value}" for name, value in self.limits]
        return out + self.timing.lines()


def loop_timing(robot: FrankaRobot, ticks: int) -> LoopTiming:
    """Timing of the last ``ticks`` ticks the driver ran (at most its ring buffer)."""
    comp, gaps = robot.timing_since(robot.ticks - ticks)
    n = len(comp)
    period = robot.control_period
    missed = np.round(gaps / period) - 1
    return LoopTiming(
        ticks=int(n),
        compute_p50=float(np.percentile(comp, 50)) if n else 0.0,
        compute_p99=float(np.percentile(comp, 99)) if n else 0.0,
        compute_max=float(comp.max()) if n else 0.0,
        overruns=int(np.sum(comp > period)),
        missed_packets=int(np.sum(missed[gaps > 1.5 * period])),
        period=period,
        thread=robot.thread_class.describe(),
    )


def bench_loop(
    host: str,
    seconds: float = 10.0,
    params: FrankaParams | None = None,
    realtime: bool = True,
    out: Callable[[str], None] | None = print,
    controller: ControllerSpec | None = None,
) -> LoopTiming:
    """Run the torque loop holding the current pose for ``seconds`` s with ``controller``'s law
    (the fixed-gain one by default) and report its timing."""
    with FrankaRobot(host, params=params, realtime=realtime, controller=controller) as robot:
        robot.step(100)  # let the loop start up
        ticks = int(round(seconds / robot.control_period))
        start = time.perf_counter()
        robot.step(ticks)
        wall = time.perf_counter() - start
        timing = dataclasses.replace(loop_timing(robot, ticks), wall_rate=ticks / wall)
    if out is not None:
        for line in timing.lines():
            out(line)
    return timing


def check_robot(
    host: str,
    limits: FrankaLimits | None = None,
    seconds: float = 1.0,
    realtime: bool = True,
    connect_timeout: float = CONNECT_TIMEOUT,
) -> RobotCheck:
    """Connect to the Franka at ``host`` (:class:`~teachfit.core.errors.ConnectionLost` when it
    does not answer within ``connect_timeout`` s), read its state, and time ``seconds`` s of
    the loop."""
    params = FrankaParams(limits=limits or FrankaLimits(), connect_timeout=connect_timeout)
    with FrankaRobot(host, params=params, realtime=realtime) as robot:
        mode = robot.robot_mode
        ticks = int(round(seconds / robot.control_period))
        state = robot.step(ticks)
        timing = loop_timing(robot, ticks)
        q = tuple(float(v) for v in robot.joint_positions)
    return RobotCheck(
        host=host,
        robot_mode=mode,
        q=q,
        tcp_pos=(float(state.pos[0]), float(state.pos[1]), float(state.pos[2])),
        limits=tuple(params.limits.rows()),
        timing=timing,
    )
