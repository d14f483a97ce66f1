"""Shared CLI helpers: the console and turning teachfit errors into clear messages."""

from __future__ import annotations

import functools
import math
import os
import signal
import typing
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, ParamSpec, TypeVar

import typer
from rich.console import Console

from teachfit.cli.options import Within
from teachfit.core.errors import OutputError, TeachfitError

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


def seed_option(help: str = "random seed") -> Any:
    """A ``--seed`` option: an integer >= 0 (numpy's generators take no negative seed)."""
    return typer.Option(min=0, help=f"{help} (an integer >= 0)")


#: ``--seed N``: every command with randomness takes it (0 and up)
SeedOpt = Annotated[int, seed_option()]


def count_option(
    help: str, *, low: int = 1, high: int | None = None, flag: str | None = None
) -> Any:
    """An integer option (a count, a size, a rate) in ``[low, high]``; typer refuses others
    with exit status 2 before the command runs."""
    decls = () if flag is None else (flag,)
    return typer.Option(*decls, min=low, max=high, help=help)


#: ``--fps``, ``--width``, ``--height`` of a rendered video (pixels; H.264 needs even sizes up
#: to 8K)
FpsOpt = Annotated[int, count_option("frames per second", high=240)]
WidthOpt = Annotated[int, count_option("video width (pixels)", low=16, high=7680)]
HeightOpt = Annotated[int, count_option("video height (pixels)", low=16, high=4320)]


#: ``--confirm``: ask the person at a real robot before each reset
ConfirmOpt = Annotated[
    bool,
    typer.Option(help="real robot: ask on the terminal before each reset (Enter moves, q stops)"),
]


#: ``--reflex-force N``: the firmware's collision reflex threshold a real robot's driver sets
ReflexForceOpt = Annotated[
    float | None,
    typer.Option(
        "--reflex-force",
        help="real robot: the collision reflex's force threshold (N per axis; default 75, "
        "1.25 x the driver's 60 N force limit)",
    ),
]


def check_reflex_force(host: str | None, reflex_force: float | None) -> None:
    """Refuse ``--reflex-force`` without ``--host`` or that is not a finite force > 0."""
    if reflex_force is None:
        return
    if host is None:
        raise TeachfitError("--reflex-force sets a real robot's collision reflex: give --host")
    if not (math.isfinite(reflex_force) and reflex_force > 0):
        raise TeachfitError(
            f"--reflex-force {reflex_force:g}: give the collision reflex's force threshold in "
            "N, a number > 0 (default 75)"
        )


def robot_options(
    host: str | None,
    realtime: bool = True,
    confirm: bool = False,
    reflex_force: float | None = None,
) -> dict[str, Any]:
    """The ``make_robot`` options the CLI's ``--host``/``--no-realtime``/``--confirm``/
    ``--reflex-force`` give (none for simulated robots; ``--confirm`` or ``--reflex-force``
    without ``--host`` is refused, as a reflex force that is not a number > 0)."""
    if confirm and host is None:
        raise TeachfitError("--confirm asks before a real robot's resets: give --host with it")
    check_reflex_force(host, reflex_force)
    if host is None:
        return {}
    opts: dict[str, Any] = {"host": host, "realtime": realtime}
    if reflex_force is not None:
        opts["reflex_force"] = reflex_force
    return opts | ({"confirm": True} if confirm else {})


#: options that name a file or folder a command writes: :func:`guarded` checks them before the
#: command runs (a new command's output option named otherwise is added here)
OUTPUT_OPTIONS = frozenset(
    {"out", "plot", "render", "markdown", "save", "strip", "keyposes", "toml", "traces",
     "best_plot", "benchmarks", "workdir", "log", "rrd", "columns_out", "trace"}
)  # fmt: skip


def check_output(path: object, option: str = "out") -> None:
    """Refuse an output path whose folder cannot be made before any work is done: the nearest
    existing folder above it must be a writable folder (a missing folder is created when the
    file is written, :mod:`teachfit.core.atomic`)."""
    if not isinstance(path, Path):
        return
    above = next((p for p in path.absolute().parents if p.exists()), None)
    if above is None:
        return
    flag = "--" + option.replace("_", "-")
    if not above.is_dir():
        raise OutputError(f"{flag} {path}: {above} is a file, not a folder")
    if not os.access(above, os.W_OK | os.X_OK):
        raise OutputError(f"{flag} {path}: folder {above} is not writable")


def check_finite(value: object, option: str) -> None:
    """Refuse ``nan``/``inf`` given to a number option (typer parses them as floats)."""
    values = value if isinstance(value, list | tuple) else [value]
    for v in values:
        if isinstance(v, float) and not math.isfinite(v):
            flag = "--" + option.replace("_", "-")
            raise TeachfitError(f"{flag} {v}: give a finite number")


def exit_on_sigterm() -> None:
    """Make SIGTERM (``kill``, ``timeout``, a scheduler) end the process like Ctrl-C does:
    ``SystemExit(143)`` unwinds the stack, so half-written outputs' temporary files are removed
    (:mod:`teachfit.core.atomic`) instead of being left behind by the default handler."""

    def terminate(signum: int, frame: object) -> None:
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, terminate)


def ranges(func: Callable[..., object]) -> dict[str, Within]:
    """The :class:`~teachfit.cli.options.Within` ranges of a command's options, by name."""
    hints = typing.get_type_hints(func, include_extras=True)
    return {
        name: meta
        for name, hint in hints.items()
        for meta in getattr(hint, "__metadata__", ())
        if isinstance(meta, Within)
    }


P = ParamSpec("P")
R = TypeVar("R")


def guarded(func: Callable[P, R]) -> Callable[P, R]:
    """Report a :class:`TeachfitError` as one red line and exit with status 2 (no traceback)."""

    @functools.wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            for name, within in ranges(func).items():
                within.check("--" + name.replace("_", "-"), kwargs.get(name))
            for name, value in kwargs.items():
                check_finite(value, name)
            for name in OUTPUT_OPTIONS.intersection(kwargs):
                check_output(kwargs[name], name)
            return func(*args, **kwargs)
        except TeachfitError as exc:
            err_console.print("[bold red]error:[/] ", end="")
            # the message is plain text: no markup, no ":emoji:" codes, no highlighting; one
            # line however narrow the terminal (soft_wrap: rich does not break it)
            err_console.print(str(exc), markup=False, emoji=False, highlight=False, soft_wrap=True)
            raise typer.Exit(2) from exc

    return wrapper


def append_markdown(path: Path, text: str) -> Path:
    """Append ``text`` to the markdown file ``path`` (created with its folder if missing): every
    ``--markdown FILE`` appends, so one file can collect several benchmark runs. A command's
    first append to ``path`` in one run (process) starts with its provenance header (command
    line, version, commit, UTC date, machine: :mod:`teachfit.cli.provenance`), so the newest
    run's block is the text after the file's last header."""
    from teachfit.cli import provenance
    from teachfit.core.atomic import atomic_append_text

    if provenance.first_in_run(path):
        text = provenance.header(provenance.current()) + "\n\n" + text.lstrip("\n")
    sep = "\n" if path.is_file() and path.stat().st_size else ""
    return atomic_append_text(path, sep + text.rstrip("\n") + "\n", "markdown file")
