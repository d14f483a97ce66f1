"""``teachfit demo ...``: record, import and show demonstrations."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from teachfit.cli.common import RobotOpt, console, guarded
from teachfit.core.errors import TeachfitError
from teachfit.demonstrations.csv_import import ColumnMap, import_csv
from teachfit.demonstrations.dataset import (
    append_dataset,
    dataset_summary,
    read_dataset,
    write_dataset,
)
from teachfit.execution.teacher import PATTERNS, BlindTeacher, TeacherStyle
from teachfit.tasks.registry import load_task

app = typer.Typer(help="Record, import and inspect demonstrations.", no_args_is_help=True)


@app.command("record")
@guarded
def record(
    task: Annotated[str, typer.Option(help="built-in task name or task .toml")] = "peg2d",
    n: Annotated[int, typer.Option("-n", help="demonstrations to keep")] = 3,
    seed: Annotated[int, typer.Option(help="random seed")] = 0,
    out: Annotated[Path, typer.Option(help="HDF5 file to write")] = Path("demos.h5"),
    pattern: Annotated[str, typer.Option(help=f"search pattern: {', '.join(PATTERNS)}")] = "sweep",
    append: Annotated[bool, typer.Option(help="append to an existing file")] = False,
    overwrite: Annotated[bool, typer.Option(help="replace an existing file")] = False,
    robot: RobotOpt = "floating",
) -> None:
    """Record demonstrations with the simulated blind teacher."""
    the_task = load_task(task)
    teacher = BlindTeacher(the_task, TeacherStyle(pattern=pattern), seed=seed, robot=robot)
    demos, discarded = teacher.record(n, progress=True)
    if append:
        append_dataset(out, demos)
    else:
        write_dataset(out, demos, overwrite=overwrite)
    console.print(
        f"recorded {len(demos)} demonstration(s) of [bold]{the_task.name}[/] -> {out}"
        + (f" (discarded {len(discarded)}: {'; '.join(discarded)})" if discarded else "")
    )


@app.command("import")
@guarded
def import_(
    csv_file: Annotated[Path, typer.Argument(help="robot log (CSV)")],
    task: Annotated[str, typer.Option(help="task the log demonstrates")] = "peg2d",
    columns: Annotated[Path, typer.Option(help="column mapping TOML")] = Path("columns.toml"),
    out: Annotated[Path, typer.Option(help="HDF5 file to write or append to")] = Path("demos.h5"),
    name: Annotated[str | None, typer.Option(help="demonstration name")] = None,
) -> None:
    """Import a real robot log (CSV) as a demonstration, appending to ``--out``."""
    load_task(task)
    demo = import_csv(csv_file, ColumnMap.from_toml(columns), task=task, name=name)
    append_dataset(out, [demo])
    console.print(
        f"imported {demo.n_samples} samples ({demo.duration:.2f} s at {demo.rate_hz:.1f} Hz) "
        f"from {csv_file} -> {out}"
    )


@app.command("show")
@guarded
def show(
    dataset: Annotated[Path, typer.Argument(help="HDF5 demonstration file")],
    plot: Annotated[Path | None, typer.Option(help="write a figure (PNG/PDF) here")] = None,
) -> None:
    """List the demonstrations in a file; optionally plot paths and wrenches."""
    rows = dataset_summary(dataset)
    table = Table(title=str(dataset))
    for col in ("index", "name", "task", "source", "samples", "duration", "rate"):
        table.add_column(col, justify="right" if col not in ("name", "task", "source") else "left")
    for r in rows:
        table.add_row(
            str(r["index"]),
            r["name"],
            r["task"],
            r["source"],
            str(r["samples"]),
            f"{r['duration']:.2f} s",
            f"{r['rate']:.0f} Hz",
        )
    console.print(table)
    if plot is not None:
        from teachfit.viz.figures import plot_demonstrations

        demos = read_dataset(dataset)
        tasks = {d.task for d in demos}
        try:
            task = load_task(tasks.pop()) if len(tasks) == 1 else None
        except TeachfitError:
            task = None
        plot_demonstrations(demos, plot, task)
        console.print(f"figure -> {plot}")
