"""``--log run.h5`` and ``--rrd run.rrd``: the recordings every command that runs a robot writes."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Annotated, Any

import typer

from teachfit.cli.common import console
from teachfit.core.errors import TeachfitError
from teachfit.tasks.base import Task

#: ``--log FILE``: the run log (HDF5, read by ``teachfit demo show``)
LogOpt = Annotated[
    Path | None,
    typer.Option(help="write the run log here (HDF5: set-points, pose, wrench, node, outcome)"),
]
#: ``--rrd FILE``: the same run as a Rerun recording
RrdOpt = Annotated[
    Path | None,
    typer.Option(help="also write a Rerun recording (.rrd; needs teachfit[rerun])"),
]


def check_recording_targets(log: Path | None, rrd: Path | None) -> None:
    """Refuse bad targets (and a missing Rerun SDK) before the robot moves."""
    if log is not None:
        from teachfit.execution.recording import check_run_log_target

        check_run_log_target(log)
    if rrd is not None:
        from teachfit.viz.run_rerun import require_rerun

        if rrd.is_dir():
            raise TeachfitError(f"--rrd {rrd} is a folder: give a file name such as run.rrd")
        require_rerun()


def write_recordings(
    log: Path | None,
    rrd: Path | None,
    episodes: Iterable[Any],
    info: tuple[str, Task | str, str, int, str],
    options: Mapping[str, Any],
) -> None:
    """Write the run log and/or the Rerun recording of ``episodes``; ``info`` is
    ``(kind, task, robot, seed, method)``, ``options`` the command's parsed options."""
    if log is None and rrd is None:
        return
    from teachfit.execution.recording import RunInfo, write_run_log

    run_info = RunInfo.here(*info, options)
    items = list(episodes)
    if log is not None:
        console.print(f"run log -> {write_run_log(log, items, run_info)}")
    if rrd is not None:
        from teachfit.viz.run_rerun import write_rrd

        console.print(f"rerun recording -> {write_rrd(rrd, items, run_info)}")


def show_run_log(path: Path, plot: Path | None) -> None:
    """``teachfit demo show RUN.h5``: the run's metadata, a table of its episodes, a figure."""
    from rich.markup import escape
    from rich.table import Table

    from teachfit.execution.recording import read_run_log, run_summary

    run = read_run_log(path)
    info = run.info
    console.print(
        escape(
            f"run log of {info.kind} {info.method} on {info.task} ({info.robot}, seed "
            f"{info.seed}), written {run.created} by teachfit {run.version}\n"
            f"command: {info.command}"
        ),
        highlight=False,
    )
    table = Table(
        title=escape(str(path)), caption="duration, time to success: s; depth: mm; force: N"
    )
    for col in ("#", "outcome", "duration", "to success", "final depth", "max force", "nodes"):
        table.add_column(col, justify="left" if col in ("outcome", "nodes") else "right")
    rows = run_summary(run)
    for r in rows:
        ok = r["outcome"] == "success"
        table.add_row(
            str(r["index"]),
            f"[green]{r['outcome']}[/]" if ok else f"[red]{r['outcome']}[/]",
            f"{r['duration']:.2f}",
            f"{r['time_to_success']:.2f}" if ok else "-",
            f"{r['final_depth'] * 1e3:.2f}",
            f"{r['max_force']:.1f}",
            r["nodes"],
        )
    console.print(table)
    n_ok = sum(r["outcome"] == "success" for r in rows)  # as the table shows
    console.print(f"{n_ok}/{len(run.episodes)} episodes succeeded")
    if plot is not None:
        from teachfit.viz.run_figures import plot_run

        console.print(f"figure -> {plot_run(run, plot)}")
