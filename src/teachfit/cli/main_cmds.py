"""Top-level commands: tasks (:mod:`teachfit.cli.tasks_cmd`), render, quickstart, bench sim."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import RobotOpt, append_markdown, console, guarded
from teachfit.cli.progress import progress_bar
from teachfit.cli.tables import print_table
from teachfit.tasks.registry import load_task


@guarded
def render(
    task: Annotated[str, o.task()] = "peg2d",
    demo: Annotated[str, typer.Option(help="demonstration FILE.h5:INDEX")] = "demos.h5:0",
    render: Annotated[Path, typer.Option("--render", help="video (mp4) to write")] = Path(
        "demo.mp4"
    ),
    fps: o.Fps = 25,
    width: o.Width = 640,
    height: o.Height = 480,
    robot: RobotOpt = "floating",
    out: Annotated[Path | None, o.old("--out", "--render")] = None,
) -> None:
    """Render a recorded demonstration with MuJoCo's offscreen renderer to an mp4."""
    from teachfit.core.errors import DatasetError
    from teachfit.demonstrations.dataset import read_demo
    from teachfit.viz.video import render_motion

    render = o.pick(render, out)
    the_task = load_task(task)
    d = read_demo(demo)
    if d.task != the_task.name:
        raise DatasetError(f"demonstration is of task {d.task!r}, not {the_task.name!r}")
    with progress_bar() as bar:
        job = bar.add_task(f"rendering {d.duration:.1f} s at {fps} fps", total=None)
        path = render_motion(
            the_task, d.t, d.pos, d.quat, render, fps=fps, width=width, height=height,
            robot=robot, progress=lambda k, n: bar.update(job, completed=k, total=n),
        )  # fmt: skip
    console.print(f"video -> {path}")


@guarded
def view(
    task: Annotated[str, o.task()] = "peg2d",
    demo: Annotated[str, typer.Option(help="demonstration FILE.h5:INDEX")] = "demos.h5:0",
    speed: Annotated[float, typer.Option(help="playback speed (1: real time)")] = 1.0,
) -> None:
    """Replay a demonstration in MuJoCo's interactive viewer (needs a display; exit status 2
    and one line without one)."""
    from teachfit.core.errors import DatasetError
    from teachfit.demonstrations.dataset import read_demo
    from teachfit.robot.viewer import require_display, view_motion

    the_task = load_task(task)  # inputs first: a bad file is named even without a display
    d = read_demo(demo)
    if d.task != the_task.name:
        raise DatasetError(f"demonstration is of task {d.task!r}, not {the_task.name!r}")
    require_display()
    console.print(f"viewing {d.name or demo} ({d.duration:.1f} s); close the window to end")
    view_motion(the_task, d.t, d.pos, d.quat, speed=speed)


@guarded
def quickstart(
    out: Annotated[Path, typer.Option(help="folder for files and figures")] = Path(
        "out/quickstart"
    ),
    task: Annotated[str, o.task("a built-in name (teachfit tasks)")] = "peg2d",
    count: o.Count = 3,
    starts: Annotated[int, o.starts("new to the demonstration")] = 10,
    seed: Annotated[int, o.seed("the teacher, the starts and the searches")] = 0,
    robot: RobotOpt = "floating",
    points: o.Points = 300,
    demos: Annotated[int | None, o.old("--demos", "--count")] = None,
) -> None:
    """The main job on the default task: demonstrations -> execution -> success table."""
    from teachfit.quickstart import run_quickstart

    n_demos = o.pick(count, demos)
    run_quickstart(out, task, n_demos, starts, seed, console, robot_name=robot, n_points=points)


@guarded
def bench_sim(
    task: Annotated[str, o.task()] = "peg2d",
    steps: Annotated[int, typer.Option(min=1, help="steps per measurement")] = 5000,
    repeats: Annotated[int, typer.Option(min=1, help="measurements (the fastest counts)")] = 3,
    robot: RobotOpt = "floating",
    markdown: o.Markdown = None,
) -> None:
    """Raw mj_step steps/s vs. steps/s with the controller in the loop, in contact."""
    from teachfit.robot.speed import ArmSimSpeed, measure_sim_speed

    the_task = load_task(task)
    s = measure_sim_speed(the_task, steps, repeats, robot=robot)
    title = f"simulation speed, {robot} on {the_task.name} in contact ({s.contacts} contacts)"
    arm = isinstance(s, ArmSimSpeed)
    rows = [
        ("raw mj_step", f"{s.raw_steps_per_s:,.0f} steps/s", ""),
        ("with controller", f"{s.controlled_steps_per_s:,.0f} steps/s", ""),
        ("ratio", f"{s.ratio:.2f}", ">= 0.70"),
        ("real-time factor", f"{s.real_time_factor:.1f}x", ">= 5" if arm else ">= 10"),
    ]
    if isinstance(s, ArmSimSpeed):
        rows += [
            ("law per tick p50", f"{s.compute_p50_us:.1f} µs", ""),
            ("law per tick p99", f"{s.compute_p99_us:.1f} µs", "<= 100 µs"),
        ]
    table = Table(title=title)
    for col in ("measure", "value", "goal"):
        table.add_column(col, justify="right")
    for row in rows:
        table.add_row(*row)
    print_table(table)
    if markdown is not None:
        lines = [
            f"**{title}** (best of {repeats} x {steps} steps)",
            "",
            "| measure | value | goal |",
        ]
        lines += ["| --- | --- | --- |"] + [f"| {a} | {b} | {c} |" for a, b, c in rows]
        console.print(f"markdown appended to {append_markdown(markdown, chr(10).join(lines))}")


def register(app: typer.Typer, bench_app: typer.Typer) -> None:
    from teachfit.cli.tasks_cmd import tasks_app

    app.add_typer(tasks_app, name="tasks")
    app.command("render")(render)
    app.command("view")(view)
    app.command("quickstart")(quickstart)
    bench_app.command("sim")(bench_sim)
