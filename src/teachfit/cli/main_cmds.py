"""Top-level commands: tasks, render, quickstart, bench sim."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from teachfit.cli.common import RobotOpt, console, guarded
from teachfit.tasks.registry import TASKS, load_task


@guarded
def tasks(
    xml: Annotated[str | None, typer.Option(help="print the MJCF scene of this task")] = None,
) -> None:
    """List the built-in tasks with their parameters."""
    if xml is not None:
        from teachfit.robot.floating import build_scene

        console.print(build_scene(load_task(xml)), markup=False, highlight=False)
        return
    for name, cls in TASKS.items():
        task = cls()
        table = Table(title=f"{name}: {cls.description}", title_justify="left")
        table.add_column("parameter")
        table.add_column("default", justify="right")
        table.add_column("meaning")
        for pname, value, doc in task.param_table():
            table.add_row(pname, f"{value:g}" if isinstance(value, float) else str(value), doc)
        console.print(table)
        console.print(f"  search dims: {', '.join(cls.search_dims)}\n")


@guarded
def render(
    task: Annotated[str, typer.Option(help="task name or .toml")] = "peg2d",
    demo: Annotated[str, typer.Option(help="demonstration, e.g. demos.h5:0")] = "demos.h5:0",
    out: Annotated[Path, typer.Option(help="mp4 to write")] = Path("demo.mp4"),
    fps: Annotated[int, typer.Option(help="frames per second")] = 25,
    width: int = 640,
    height: int = 480,
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
    demos: Annotated[int, typer.Option(help="demonstrations to record")] = 3,
    starts: Annotated[int, typer.Option(help="new start poses")] = 10,
    seed: int = 0,
    robot: RobotOpt = "floating",
) -> None:
    """The main job on the default task: demonstrations -> execution -> success table."""
    from teachfit.quickstart import run_quickstart

    run_quickstart(out, task, demos, starts, seed, console, robot_name=robot)


@guarded
def bench_sim(
    task: Annotated[str, typer.Option(help="task name")] = "peg2d",
    steps: Annotated[int, typer.Option(help="steps per measurement")] = 5000,
    repeats: int = 3,
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
    arm = hasattr(s, "compute_p99_us")
    table.add_row("real-time factor", f"{s.real_time_factor:.1f}x", ">= 5" if arm else ">= 10")
    if arm:
        table.add_row("law per tick p50", f"{s.compute_p50_us:.1f} µs", "")
        table.add_row("law per tick p99", f"{s.compute_p99_us:.1f} µs", "<= 100 µs")
    console.print(table)


def register(app: typer.Typer, bench_app: typer.Typer) -> None:
    app.command("tasks")(tasks)
    app.command("render")(render)
    app.command("quickstart")(quickstart)
    bench_app.command("sim")(bench_sim)
