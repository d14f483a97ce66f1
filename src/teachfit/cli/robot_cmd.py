"""``teachfit robot ...`` and ``teachfit bench robot``: the robots teachfit can drive."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.markup import escape
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import (
    HostOpt,
    RobotOpt,
    append_markdown,
    console,
    err_console,
    guarded,
)
from teachfit.cli.tables import print_table
from teachfit.core.errors import TeachfitError
from teachfit.robot.franka.connect import CONNECT_TIMEOUT

if TYPE_CHECKING:
    from teachfit.robot.franka.check import LoopTiming

robot_app = typer.Typer(
    help="The robots teachfit drives: list them, check one.", no_args_is_help=True
)

_REALTIME = typer.Option(help="real robot: require a real-time kernel (off for the simulator)")
#: ``--connect-timeout S``: how long a connect may take (a Franka answers within milliseconds)
ConnectTimeoutOpt = Annotated[
    float,
    typer.Option(min=0.1, max=600, help="seconds to wait for the robot to answer the connect"),
]


@robot_app.command("list")
@guarded
def list_robots() -> None:
    """The registered robots (names for --robot)."""
    from teachfit.robot.registry import ROBOTS

    table = Table(title="robots (--robot NAME)")
    for col in ("name", "kind", "what"):
        table.add_column(col)
    for entry in ROBOTS.values():
        kind = "simulated" if entry.simulated else "real"
        table.add_row(entry.name, kind, escape(entry.description))
    print_table(table)


def _real(robot: str, host: str | None) -> str:
    if robot != "franka":
        raise TeachfitError(
            f"robot {robot!r} is simulated: nothing to connect to (use franka; a simulated "
            f"robot's tick is timed by teachfit bench sim --robot {robot})"
        )
    if not host:
        raise TeachfitError("--host ADDRESS is needed: the Franka's (or the simulator's) address")
    return host


@robot_app.command("check")
@guarded
def check(
    robot: RobotOpt = "franka",
    host: HostOpt = None,
    seconds: Annotated[
        float, typer.Option(min=0, help="seconds of the 1 kHz control loop to time")
    ] = 1.0,
    realtime: Annotated[bool, _REALTIME] = True,
    connect_timeout: ConnectTimeoutOpt = CONNECT_TIMEOUT,
) -> None:
    """Connect, read the state, print the safety limits and the loop timing.

    A robot that does not answer within --connect-timeout s is one line, exit status 2;
    Ctrl-C ends the wait (exit status 130)."""
    from teachfit.robot.franka.check import check_robot

    address = _real(robot, host)
    with _interruptible(address):
        result = check_robot(
            address, seconds=seconds, realtime=realtime, connect_timeout=connect_timeout
        )
    for line in result.lines():
        console.print(line, markup=False, highlight=False)


@robot_app.command("twin")
@guarded
def twin(
    task: Annotated[str, o.task()] = "peg",
    host: Annotated[
        str, typer.Option(help="address of a real robot (here: the loopback address to serve on)")
    ] = "127.0.0.1",
    seed: Annotated[int, o.seed("the sensors' noise and offsets")] = 0,
    realtime: Annotated[
        bool,
        typer.Option(
            help="real robot: require a real-time kernel (here: step at 1 kHz whatever the "
            "client does, a late client violates the communication constraint; --no-realtime: "
            "in lock-step with a client without a real-time kernel)"
        ),
    ] = True,
    trace: Annotated[
        Path | None,
        typer.Option(
            help="CSV to write, one row per tick the held part touches anything: the "
            "simulator's own contact force beside the served O_F_ext_hat_K"
        ),
    ] = None,
) -> None:
    """A digital twin of a Franka: the task's FR3 cell (the part in the hand) behind
    libfranka's protocol on 127.0.0.1, with the firmware's wrench estimate, reflexes and
    limits. Runs until Ctrl-C or SIGTERM; connect with --robot franka --host 127.0.0.1."""
    from teachfit.tasks import get_task

    try:
        from teachfit.robot.franka.twin import TwinParams, check_host, serve
    except ImportError as exc:  # pragma: no cover - depends on the installed extras
        raise TeachfitError(
            f"robot twin needs franky-sim and pylibfranka: pip install teachfit[franka] ({exc})"
        ) from exc
    check_host(host)
    cell = get_task(task)
    try:
        serve(
            cell,
            host,
            TwinParams(seed=seed),
            realtime=realtime,
            ready=_twin_ready(task),
            trace=trace,
        )
    except KeyboardInterrupt:
        err_console.print("twin stopped (Ctrl-C)")
        raise typer.Exit(130) from None
    except SystemExit:  # SIGTERM (teachfit's CLI): its status, 143
        err_console.print("twin stopped (SIGTERM)")
        raise


def _twin_ready(task: str) -> Callable[[str], None]:
    import os

    def ready(host: str) -> None:
        pid = os.getpid()
        console.print(
            f"Franka twin of task {task!r} listening on {host} (libfranka's protocol), "
            f"PID {pid}; stop with Ctrl-C or kill {pid}",
            markup=False,
            highlight=False,
            soft_wrap=True,
        )

    return ready


@guarded
def bench_robot(
    robot: RobotOpt = "franka",
    host: HostOpt = None,
    seconds: Annotated[
        float, typer.Option(min=0, help="seconds of the 1 kHz control loop to time")
    ] = 10.0,
    realtime: Annotated[bool, _REALTIME] = True,
    connect_timeout: ConnectTimeoutOpt = CONNECT_TIMEOUT,
    controller: Annotated[
        str, typer.Option(help="controller that holds the pose: impedance or adaptive")
    ] = "impedance",
    markdown: o.Markdown = None,
) -> None:
    """Tick compute time p50/p99/max and missed deadlines of the 1 kHz loop, through the
    robot's protocol."""
    from teachfit.robot.franka.check import bench_loop
    from teachfit.robot.franka.driver import FrankaParams
    from teachfit.skills.controllers import controller_spec

    if not seconds > 0:
        raise TeachfitError(f"--seconds must be > 0, got {seconds}")
    spec = controller_spec(controller, {})
    address = _real(robot, host)
    params = FrankaParams(connect_timeout=connect_timeout)
    with _interruptible(address):
        timing = bench_loop(
            address, seconds=seconds, params=params, realtime=realtime, out=console.print,
            controller=spec,
        )  # fmt: skip
    if markdown is not None:
        text = _timing_markdown(timing, address, controller)
        console.print(f"markdown appended to {append_markdown(markdown, text)}")


def _timing_markdown(t: LoopTiming, address: str, controller: str) -> str:
    """``bench robot``'s figures as a one-row markdown table (times in µs, the 1-minute load
    average at the end of the run) for the loop running ``controller``."""
    import os

    us = [f"{v * 1e6:.0f} µs" for v in (t.compute_p50, t.compute_p99, t.compute_max)]
    rate = f"{t.wall_rate:.0f} ticks/s" if t.wall_rate else "-"
    row = [f"{os.getloadavg()[0]:.1f}", *us, str(t.overruns), str(t.missed_packets), rate]
    return "\n".join([
        f"**the 1 kHz loop of the robot at {address}**, {t.ticks} ticks "
        f"({t.ticks * t.period:.1f} s), through the robot's protocol, {controller} law",
        "",
        "| load | tick compute p50 | p99 | max | ticks over "
        f"{t.period * 1e3:.0f} ms | states never read | wall-clock rate |",
        "| --- | --- | --- | --- | --- | --- | --- |",
        "| " + " | ".join(row) + " |",
    ])  # fmt: skip


@contextmanager
def _interruptible(host: str) -> Iterator[None]:
    """Ctrl-C while talking to the robot at ``host``: one line and exit status 130 (SIGTERM:
    one line, 143). The driver has already held the arm and finished its motion; a connect
    is abandoned."""
    try:
        yield
    except KeyboardInterrupt:
        err_console.print(f"interrupted (Ctrl-C) while talking to the robot at {host}")
        raise typer.Exit(130) from None
    except SystemExit:  # SIGTERM (teachfit's CLI): its status, 143
        err_console.print(f"terminated while talking to the robot at {host}")
        raise
