"""``teachfit learn search`` and ``teachfit search ...``: seed A's method from the CLI."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.progress import Progress
from rich.table import Table

from teachfit.cli.common import (
    HostOpt,
    RealtimeOpt,
    RobotOpt,
    SeedOpt,
    console,
    guarded,
    robot_options,
)
from teachfit.cli.recording import LogOpt, RrdOpt, check_recording_targets, write_recordings
from teachfit.core.atomic import ensure_folder
from teachfit.core.errors import TeachfitError

search_app = typer.Typer(help="Plan and run search trajectories (seed A).", no_args_is_help=True)


@guarded
def learn_search(
    demos: Annotated[Path, typer.Argument(help="HDF5 demonstrations of one task")],
    out: Annotated[Path, typer.Option(help="model file to write (JSON)")] = Path("search.model"),
    components: Annotated[str, typer.Option(help="GMM components: a number or 'bic'")] = "1",
    covariance: Annotated[
        str,
        typer.Option(
            help="p_e covariance: 'auto' (chosen by leave-one-demonstration-out likelihood), "
            "'full' (seed A) or 'diag' (per-DOF variances)"
        ),
    ] = "auto",
    seed: SeedOpt = 0,
) -> None:
    """Learn the exploration distribution and the dynamics model from demonstrations."""
    from teachfit.demonstrations.dataset import read_dataset
    from teachfit.models.search_model import SearchModel

    if components != "bic" and not (components.isdigit() and int(components) >= 1):
        raise TeachfitError(f"--components wants a number >= 1 or 'bic', got {components!r}")
    demo_list = read_dataset(demos)
    tasks = {d.task for d in demo_list}
    if len(tasks) != 1:
        raise TeachfitError(f"{demos} mixes tasks {sorted(tasks)}; learn one task at a time")
    n_comp: int | str = components if components == "bic" else int(components)
    model = SearchModel.fit(
        demo_list,
        tasks.pop(),
        n_components=n_comp,
        seed=seed,
        covariance=covariance,  # type: ignore[arg-type]
    )
    model.save(out)
    e = model.exploration
    console.print(
        f"learned from {len(demo_list)} demonstration(s) of [bold]{model.task}[/]: "
        f"dims {', '.join(model.dims)}, {e.n_components} component(s), "
        f"mean {np.round(e.mean * 1e3, 1)} (mm/mrad), teacher speed {model.speed * 1e3:.1f} mm/s"
        + (
            f"\ncovariance: {model.covariance_choice.describe()}"
            if model.covariance_choice is not None
            else ""
        )
        + f"\nmodel -> {out}"
    )


@search_app.command("plan")
@guarded
def plan(
    model_file: Annotated[Path, typer.Argument(help="model from 'teachfit learn search'")],
    method: Annotated[
        str, typer.Option(help="tshix, ergodic, ergodic-opt, spiral or random-walk")
    ] = "tshix",
    n: Annotated[int, typer.Option("-n", min=1, help="TSHIX sample points")] = 300,
    seed: SeedOpt = 0,
    plot: Annotated[Path | None, typer.Option(help="figure to write")] = None,
) -> None:
    """Plan one search trajectory in the search frame and report its figures of merit."""
    import time

    from teachfit.execution.search import plan_search
    from teachfit.models.search_model import SearchModel
    from teachfit.trajectories.ergodic import ergodic_metric

    model = SearchModel.load(model_file)
    t0 = time.perf_counter()
    traj = plan_search(model, method, n, np.random.default_rng(seed))
    wall = time.perf_counter() - t0
    metric = ergodic_metric(traj.states, model.exploration, t=traj.t)
    xy = float(np.linalg.norm(np.diff(traj.states[:, :2], axis=0), axis=1).sum())
    rz = ""
    if "rz" in model.dims:
        turn = np.abs(np.diff(traj.states[:, model.dims.index("rz")])).sum()
        rz = f" and {np.degrees(turn):.0f} deg of rz"
    console.print(
        f"{method}: {traj.t.size} set-points, {traj.duration:.1f} s, path {xy * 1e3:.0f} mm "
        f"in x-y{rz}, ergodic metric {metric:.4f}, planned in {wall * 1e3:.0f} ms"
    )
    if plot is not None:
        from teachfit.viz import search_figures as sf

        if traj.itinerary is not None and traj.states.shape[1] == 2:
            fig = sf.tshix_stages(traj, model.exploration)
        elif traj.states.shape[1] == 3:
            fig = sf.trajectory_3d(traj)
        else:
            fig = sf.planned_vs_executed(traj.states, traj.states, (method, method))
            fig.axes[0].lines[1].remove()  # one path: draw it once
            fig.axes[0].legend()
            fig.axes[0].set_title(f"{method} search trajectory (search frame)")
            fig.tight_layout()
        sf.save(fig, plot)
        console.print(f"figure -> {plot}")


@search_app.command("run")
@guarded
def run(
    ctx: typer.Context,
    task: Annotated[str, typer.Option(help="task name or .toml")] = "peg2d",
    model_file: Annotated[Path, typer.Option("--model", help="learned model")] = Path(
        "search.model"
    ),
    method: Annotated[
        str, typer.Option(help="tshix, ergodic, ergodic-opt, spiral or random-walk")
    ] = "tshix",
    n: Annotated[int, typer.Option("-n", min=1, help="TSHIX sample points")] = 300,
    starts: Annotated[int, typer.Option(min=1, help="number of start poses")] = 30,
    protocol: Annotated[str, typer.Option(help="start protocol of the task")] = "table1",
    feedforward: Annotated[bool, typer.Option(help="superpose the GMR feed-forward")] = True,
    passes: Annotated[
        int, typer.Option(min=1, help="TSHIX passes: re-sample and continue after a failed pass")
    ] = 1,
    demo: Annotated[
        str | None, typer.Option(help="demonstration whose start anchors the protocol (f.h5:0)")
    ] = None,
    seed: SeedOpt = 0,
    plot: Annotated[Path | None, typer.Option(help="figure of the executed paths")] = None,
    robot: RobotOpt = "floating",
    host: HostOpt = None,
    realtime: RealtimeOpt = True,
    log: LogOpt = None,
    rrd: RrdOpt = None,
) -> None:
    """Execute searches from the protocol's starts and print the success table.

    Seed A's Table I starts lie in a 3 cm circle halfway between the demonstration's start and
    the hole: pass the demonstration the model was learned from with ``--demo``.
    """
    from teachfit.execution.search import run_protocol
    from teachfit.metrics.stats import summarize
    from teachfit.models.search_model import SearchModel
    from teachfit.robot.registry import make_robot
    from teachfit.tasks.registry import load_task

    check_recording_targets(log, rrd)
    the_task = load_task(task)
    model = SearchModel.load(model_file, task=the_task.name)
    demo_start = None
    if demo is not None:
        from teachfit.demonstrations.dataset import read_demo

        d = read_demo(demo)
        if d.task != the_task.name:
            raise TeachfitError(
                f"--demo {demo} is a {d.task!r} demonstration, not {the_task.name!r}"
            )
        demo_start = d.start_pose
    elif protocol == "table1":
        console.print(
            "[yellow]note:[/] Table I starts lie halfway between the demonstration's start and "
            "the hole; without --demo a nominal demonstration start is assumed"
        )
    the_robot = make_robot(robot, the_task, seed=seed, **robot_options(host, realtime))
    try:
        with Progress(console=console, transient=True) as bar:
            job = bar.add_task(f"{method} from {starts} starts", total=starts)
            runs = run_protocol(
                the_robot, the_task, model, method, n, starts, protocol, seed,
                passes=passes, feedforward=feedforward, demo_start=demo_start,
                on_done=lambda _run: bar.advance(job),
            )  # fmt: skip
    finally:
        the_robot.close()
    outcomes = [r.result for r in runs]
    paths = [(o.log.pos, o.success) for o in outcomes]
    s = summarize([o.success for o in outcomes], [o.time_to_success for o in outcomes])
    table = Table(title=f"{method} on {the_task.name} ({protocol}, seed {seed})")
    for col in ("starts", "successes", "rate [95 % CI]", "median time", "reasons"):
        table.add_column(col, justify="right")
    reasons = {}
    for o in outcomes:
        reasons[o.outcome.value] = reasons.get(o.outcome.value, 0) + 1
    t_med = "n/a" if np.isnan(s.median_time) else f"{s.median_time:.2f} s"
    table.add_row(
        str(s.trials),
        str(s.successes),
        f"{100 * s.rate:.0f} % [{100 * s.low:.0f}, {100 * s.high:.0f}]",
        t_med,
        ", ".join(f"{k} {v}" for k, v in reasons.items()),
    )
    console.print(table)
    write_recordings(log, rrd, runs, ("search", the_task, robot, seed, method), ctx.params)
    if plot is not None:
        from teachfit.viz.figures import plot_executions

        plot_executions(paths, plot, the_task, title=method)
        console.print(f"figure -> {plot}")


@search_app.command("figures")
@guarded
def figures(
    model_file: Annotated[Path, typer.Argument(help="model from 'teachfit learn search'")],
    out: Annotated[Path, typer.Option(help="folder for the figures")] = Path("search_figures"),
    n: Annotated[int, typer.Option("-n", min=1, help="TSHIX sample points")] = 300,
    seed: SeedOpt = 0,
    robot: RobotOpt = "floating",
) -> None:
    """Seed A's figures for a model: samples over p_e for N = 100...500, samples -> itinerary ->
    smoothed trajectory, feed-forward arrows, the 3D trajectory (x, y, rz tasks), and a
    planned vs. executed path from the task's first protocol start."""
    from teachfit.execution.search import plan_search, run_search
    from teachfit.models.search_model import SearchModel
    from teachfit.robot.registry import make_robot
    from teachfit.tasks.registry import get_task
    from teachfit.viz import search_figures as sf

    model = SearchModel.load(model_file)
    task = get_task(model.task)
    ensure_folder(out, f"the figure folder {out}")
    rng = np.random.default_rng(seed)
    written = [sf.save(sf.samples_over_distribution(model.exploration, rng), out / "samples.png")]
    traj = plan_search(model, "tshix", n, np.random.default_rng(seed))
    if model.exploration.dim == 2:
        written.append(sf.save(sf.tshix_stages(traj, model.exploration), out / "tshix_stages.png"))
    else:
        written.append(sf.save(sf.trajectory_3d(traj), out / "trajectory_3d.png"))
    ff = np.zeros((traj.t.size, 6))
    if model.dynamics is not None:
        ff[:, :2] = model.feedforward_along(traj.t, traj.states)[:, :2]
    written.append(sf.save(sf.feedforward_arrows(traj, ff), out / "feedforward.png"))
    protocol = (
        "table1" if task.name == "peg2d" else "table3" if task.name == "socket3d" else "teacher"
    )
    start = task.protocol.protocol_starts(protocol, 1, np.random.default_rng(seed))[0]
    run = run_search(make_robot(robot, task, seed=seed), task, model, start, traj)
    executed = run.result.log.pos[:, :2] - start.pos[:2]
    fig = sf.planned_vs_executed(traj.states[:, :2], executed)
    fig.axes[0].set_title(f"from a {protocol} start: {run.result.outcome.value}")
    written.append(sf.save(fig, out / "planned_vs_executed.png"))
    for path in written:
        console.print(f"figure -> {path}")
