"""Shared CLI helpers: the console and turning teachfit errors into clear messages."""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, ParamSpec, TypeVar

import typer
from rich.console import Console

from teachfit.core.errors import TeachfitError

console = Console()
err_console = Console(stderr=True)

#: ``--robot NAME``: every command that runs a robot takes it (names from the robot registry)
RobotOpt = Annotated[
    str,
    typer.Option("--robot", help="robot to run on (teachfit robot list; simulated: floating)"),
]

#: ``--host ADDRESS``: a real robot's address (``--robot franka``)
HostOpt = Annotated[
    str | None, typer.Option("--host", help="address of a real robot (--robot franka)")
]


#: ``--realtime/--no-realtime``: a real robot's control loop needs a real-time kernel; the
#: protocol simulator (127.0.0.1) runs without one
RealtimeOpt = Annotated[
    bool, typer.Option(help="real robot: require a real-time kernel (off for the simulator)")
]


def robot_options(host: str | None, realtime: bool = True) -> dict[str, object]:
    """The ``make_robot`` options the CLI's ``--host``/``--no-realtime`` give (none for
    simulated robots)."""
    return {} if host is None else {"host": host, "realtime": realtime}


P = ParamSpec("P")
R = TypeVar("R")


def guarded(func: Callable[P, R]) -> Callable[P, R]:
    """Report a :class:`TeachfitError` as one red line and exit with status 2 (no traceback)."""

    @functools.wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return func(*args, **kwargs)
        except TeachfitError as exc:
            err_console.print("[bold red]error:[/] ", end="")
            # the message is plain text: no markup, no ":emoji:" codes, no highlighting
            err_console.print(str(exc), markup=False, emoji=False, highlight=False)
            raise typer.Exit(2) from exc

    return wrapper


def append_markdown(path: Path, text: str) -> Path:
    """Append ``text`` to the markdown file ``path`` (created with its folder if missing): every
    ``--markdown FILE`` appends, so one file can collect several benchmark runs."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("a", encoding="utf-8") as fh:
        fh.write(("\n" if path.stat().st_size else "") + text.rstrip("\n") + "\n")
    return path
