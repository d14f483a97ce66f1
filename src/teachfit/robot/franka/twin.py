"""``teachfit robot twin``: the task's FR3 cell behind libfranka's protocol on 127.0.0.1.

A digital twin of a Franka for the real-arm code path (``--robot franka``): a libfranka client
(pylibfranka, the teachfit driver) connects to it as to a robot, and the physics behind it is
the task's cell with the part held in the hand, as ``--robot fr3`` has it
(:mod:`teachfit.robot.franka.twin_cell`), so a skill in contact meets the fixture. The firmware
behaviour a client can tell (the external-wrench estimate and its sign, collision reflexes with
``setCollisionBehavior``'s thresholds, joint and torque-rate limits, the communication
constraint, ``automaticErrorRecovery``) is :mod:`teachfit.robot.franka.twin_firmware`.

What of the firmware it does *not* do: the acceleration-phase collision thresholds (the nominal
ones are used), Cartesian position/velocity limits, self-collision avoidance, the joint and
Cartesian impedance controllers (``setJointImpedance`` / ``setCartesianImpedance`` are
acknowledged, the motion generators run franky-sim's stiff joint servo), the brakes, guiding
mode, the power and ``tau_J`` range limits and the gripper (it does not move). The load set by
``setLoad`` is honoured as the firmware does: franky-sim adds it to its gravity model of the arm
and the Franka Hand (and reports it in the state's ``m_load``); the teachfit driver sends the
held part (:mod:`teachfit.robot.franka.load`), so the part no longer hangs on the law's
stiffness.

A scripted hand (a person guiding the arm, as a force profile: :mod:`teachfit.robot.franka.hand`)
comes over a second loopback port, 1339 (:mod:`teachfit.robot.franka.hand_channel`); the twin
applies it inside the physics, so the wrench estimate sees it as a person's push.

Loopback only, as the franky-sim launcher (:mod:`teachfit.robot.franka.sim`): every socket of
the process is confined to 127.0.0.1. ``python -m teachfit.robot.franka.twin --task NAME`` is
the process :class:`TwinProcess` starts for the tests (its own process group, a READY line,
stopped by its PID and group); ``teachfit robot twin`` runs :func:`serve` in the foreground.
"""

from __future__ import annotations

import argparse
import contextlib
import ipaddress
import os
import signal
import socket
import sys
from collections.abc import Callable
from pathlib import Path

from teachfit.core.errors import TeachfitError
from teachfit.robot.franka.sim import HOST, PORT_TAKEN, ROBOT_PORT, SimServer, port_free
from teachfit.robot.franka.twin_cell import TwinParams
from teachfit.tasks.base import Task

READY = "TEACHFIT-FRANKA-TWIN-READY"


def check_host(host: str) -> str:
    """``host`` if it is a loopback address; :class:`TeachfitError` otherwise."""
    try:
        loopback = ipaddress.ip_address(socket.gethostbyname(host)).is_loopback
    except (OSError, ValueError):
        loopback = False
    if not loopback:
        raise TeachfitError(f"--host {host}: the twin listens on loopback only (use --host {HOST})")
    return host


def serve(
    task: Task,
    host: str = HOST,
    params: TwinParams | None = None,
    realtime: bool = True,
    ready: Callable[[str], None] = print,
    trace: Path | None = None,
) -> None:
    """Serve ``task``'s cell on ``host`` (loopback) until Ctrl-C (``KeyboardInterrupt``) or
    ``SystemExit``; calls ``ready(address)`` once it listens; ``trace``: a CSV of the part's
    contact ticks (:mod:`~teachfit.robot.franka.twin_trace`). :class:`TeachfitError` for a
    non-loopback host or a port already taken."""
    from teachfit.robot.franka.hand_channel import HandChannel
    from teachfit.robot.franka.sim import confine_to_loopback
    from teachfit.robot.franka.twin_cell import TwinSimulator
    from teachfit.robot.franka.twin_firmware import TwinSimulationServer
    from teachfit.robot.franka.twin_trace import ContactTrace

    check_host(host)
    if not port_free(host, ROBOT_PORT):
        why = PORT_TAKEN.replace(HOST, host).replace("the simulator again", "the twin again")
        raise TeachfitError(why)
    confine_to_loopback()
    sim = TwinSimulator(task, params)
    with contextlib.ExitStack() as stack:
        if trace is not None:
            sim.trace = stack.enter_context(ContactTrace(trace))
        stack.enter_context(HandChannel(host, sim.hand.take))
        stack.enter_context(sim)
        server = stack.enter_context(TwinSimulationServer(sim, host, realtime))
        ready(host)
        server.run_forever()


def main(argv: list[str] | None = None) -> None:
    """The twin as a process: ``--task NAME [--host ADDRESS] [--seed N] [--no-realtime]
    [--start DX DY DZ]``
    (the TCP's start from the hole's contact pose, m); READY once it listens; SIGTERM/SIGINT
    end it. Bad input: one line on stderr, exit status 2."""
    from teachfit.tasks import get_task

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--task", required=True)
    parser.add_argument("--host", default=HOST)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-realtime", action="store_true")
    parser.add_argument("--start", type=float, nargs=3, default=TwinParams.start)
    parser.add_argument("--parent", type=int, default=None, help="end with this process")
    parser.add_argument("--trace", type=Path, default=None, help="CSV of the contact ticks")
    args = parser.parse_args(argv)
    if args.parent is not None:  # SIGTERM (a clean stop) if the starter dies without stopping us
        from teachfit.core.process import die_with_parent

        die_with_parent(args.parent, signal.SIGTERM)
    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    try:
        serve(
            get_task(args.task),
            args.host,
            params=TwinParams(start=tuple(args.start), seed=args.seed),
            realtime=not args.no_realtime,
            ready=lambda host: print(f"{READY} {host}", flush=True),
            trace=args.trace,
        )
    except TeachfitError as exc:
        print(f"error: teachfit.robot.franka.twin: {exc}", file=sys.stderr, flush=True)
        raise SystemExit(2) from None
    except KeyboardInterrupt:
        pass


class TwinProcess(SimServer):
    """The twin as a child process on 127.0.0.1 (its own process group; :class:`SimServer`'s
    start, READY line and stop by PID and group)."""

    ready = READY
    what = "the Franka twin"

    def __init__(
        self,
        task: str = "peg",
        realtime: bool = False,
        start: tuple[float, float, float] = TwinParams.start,
        host: str = HOST,
        startup_timeout: float = 120.0,
        seed: int = 0,
    ) -> None:
        super().__init__(startup_timeout=startup_timeout)
        self.task, self.realtime, self.start_offset = task, realtime, start
        self.seed = seed  # the sensors' noise and offsets
        self.host = check_host(host)

    def command(self) -> list[str]:
        cmd = [sys.executable, "-m", "teachfit.robot.franka.twin", "--task", self.task]
        cmd += ["--host", self.host, "--seed", str(self.seed)]
        cmd += ["--start", *(repr(float(v)) for v in self.start_offset)]
        cmd += ["--parent", str(os.getpid())]  # ends with this process
        return cmd + ([] if self.realtime else ["--no-realtime"])


if __name__ == "__main__":
    main()
