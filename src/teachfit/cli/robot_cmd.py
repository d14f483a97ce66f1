"""``teachfit robot ...`` and ``teachfit bench robot``: the robots teachfit can drive."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.markup import escape
from rich.table import Table

from teachfit.cli.common import HostOpt, RobotOpt, console, guarded
from teachfit.cli.tables import print_table
from teachfit.core.errors import TeachfitError

robot_app = typer.Typer(
    help="The robots teachfit drives: list them, check one.", no_args_is_help=True
)

_REALTIME = typer.Option(help="real robot: require a real-time kernel (off for the simulator)")


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
        raise TeachfitError(f"robot {robot!r} is simulated: nothing to connect to (use franka)")
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
) -> None:
    """Connect, read the state, print the safety limits and the loop timing."""
    from teachfit.robot.franka.check import check_robot

    result = check_robot(_real(robot, host), seconds=seconds, realtime=realtime)
    for line in result.lines():
        console.print(line, markup=False, highlight=False)


@guarded
def bench_robot(
    robot: RobotOpt = "franka",
    host: HostOpt = None,
    seconds: Annotated[
        float, typer.Option(min=0, help="seconds of the 1 kHz control loop to time")
    ] = 10.0,
    realtime: Annotated[bool, _REALTIME] = True,
) -> None:
    """Tick compute time p50/p99/max and missed deadlines of the 1 kHz loop, through the
    robot's protocol."""
    from teachfit.robot.franka.check import bench_loop

    if not seconds > 0:
        raise TeachfitError(f"--seconds must be > 0, got {seconds}")
    bench_loop(_real(robot, host), seconds=seconds, realtime=realtime, out=console.print)
