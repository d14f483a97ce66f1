"""Top-level commands: tasks (:mod:`teachfit.cli.tasks_cmd`), render, quickstart, bench sim."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from teachfit.cli.common import (
    FpsOpt,
    HeightOpt,
    RobotOpt,
    SeedOpt,
    WidthOpt,
    console,
    count_option,
    guarded,
)
from teachfit.tasks.registry import load_task


@guarded
def render(
    task: Annotated[str, typer.Option(help="task name or .toml")] = "peg2d",
    demo: Annotated[str, typer.Option(help="demonstration, e.g. demos.h5:0")] = "demos.h5:0",
    out: Annotated[Path, typer.Option(help="mp4 to write")] = Path("demo.mp4"),
    fps: FpsOpt = 25,
    width: WidthOpt = 640,
    height: HeightOpt = 480,
    robot: RobotOpt = "floating",
) -> None:
    """Render a recorded demonstration with MuJoCo's offscreen renderer to an mp4."""
    from teachfit.core.errors import DatasetError
    from teachfit.demonstrations.dataset import read_demo
    from teachfit.viz.video import render_motion

    the_task = load_task(task)
    d = read_demo(demo)
    if d.task != the_task.name:
        raise DatasetError(f"demonstration is of task {d.task!r}, not {the_task.name!r}")
    with console.status(f"rendering {d.duration:.1f} s at {fps} fps"):
        path = render_motion(
            the_task, d.t, d.pos, d.quat, out, fps=fps, width=width, height=height, robot=robot
        )
    console.print(f"video -> {path}")


@guarded
def quickstart(
    out: Annotated[Path, typer.Option(help="folder for files and figures")] = Path(
        "out/quickstart"
    ),
    task: Annotated[str, typer.Option(help="built-in task")] = "peg2d",
    demos: Annotated[int, typer.Option(min=1, help="demonstrations to record")] = 3,
    starts: Annotated[int, typer.Option(min=1, help="new start poses")] = 10,
    seed: SeedOpt = 0,
    robot: RobotOpt = "floating",
) -> None:
    """The main job on the default task: demonstrations -> execution -> success table."""
    from teachfit.quickstart import run_quickstart

    run_quickstart(out, task, demos, starts, seed, console, robot_name=robot)


@guarded
def bench_sim(
    task: Annotated[str, typer.Option(help="task name")] = "peg2d",
    steps: Annotated[int, typer.Option(min=1, help="steps per measurement")] = 5000,
    repeats: Annotated[int, count_option("measurements to take the best of")] = 3,
    robot: RobotOpt = "floating",
) -> None:
    """Raw mj_step steps/s vs. steps/s with the controller in the loop, in contact."""
    from teachfit.robot.speed import measure_sim_speed

    the_task = load_task(task)
    s = measure_sim_speed(the_task, steps, repeats, robot=robot)
    table = Table(
        title=f"simulation speed, {robot} on {the_task.name} in contact ({s.contacts} contacts)"
    )
    for col in ("measure", "value", "goal"):
        table.add_column(col, justify="right")
    table.add_row("raw mj_step", f"{s.raw_steps_per_s:,.0f} steps/s", "")
    table.add_row("with controller", f"{s.controlled_steps_per_s:,.0f} steps/s", "")
    table.add_row("ratio", f"{s.ratio:.2f}", ">= 0.70")
    table.add_row("real-time factor", f"{s.real_time_factor:.1f}x", ">= 10")
    console.print(table)


def register(app: typer.Typer, bench_app: typer.Typer) -> None:
    from teachfit.cli.tasks_cmd import tasks_app

    app.add_typer(tasks_app, name="tasks")
    app.command("render")(render)
    app.command("quickstart")(quickstart)
    bench_app.command("sim")(bench_sim)
