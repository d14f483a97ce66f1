"""``teachfit learn search`` and ``teachfit search ...``: Ehlers et al.'s method from the CLI."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
import typer
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import (
    ConfirmOpt,
    HostOpt,
    RealtimeOpt,
    ReflexForceOpt,
    RobotOpt,
    console,
    guarded,
    robot_options,
)
from teachfit.cli.progress import progress_bar
from teachfit.cli.recording import LogOpt, RrdOpt, check_recording_targets, write_recordings
from teachfit.cli.run_end import end_run, report_faults
from teachfit.cli.tables import print_table
from teachfit.core.atomic import ensure_folder
from teachfit.core.errors import TeachfitError

if TYPE_CHECKING:
    from teachfit.execution.search import SearchRun
    from teachfit.tasks.base import Task

search_app = typer.Typer(
    help="Plan and run search trajectories learned from blind demonstrations (Ehlers et al. 2019).",
    no_args_is_help=True,
)
_METHOD = typer.Option(help="tshix, ergodic, ergodic-opt, spiral or random-walk")


@guarded
def learn_search(
    demos: Annotated[
        str, typer.Argument(help="demonstrations of one task: FILE.h5 (all) or FILE.h5:0,2")
    ],
    out: Annotated[Path, typer.Option(help="search model file to write (JSON)")] = Path(
        "search.model"
    ),
    components: Annotated[str, typer.Option(help="GMM components: a number or 'bic'")] = "1",
    covariance: Annotated[
        str,
        typer.Option(
            help="covariance of the exploration density: 'auto' (chosen by "
            "leave-one-demonstration-out likelihood), 'full' (the paper) or 'diag'"
        ),
    ] = "auto",
    seed: Annotated[int, o.seed("the mixture fit")] = 0,
    mirror: Annotated[
        str,
        typer.Option(
            help="DOFs, comma-separated (e.g. rz), whose sign the search treats as unknown: "
            "the exploration density plus its mirror image (demonstrations from one side); "
            "'auto': rz where it is searched; 'none': no mirror"
        ),
    ] = "auto",
) -> None:
    """Learn the exploration distribution and the dynamics model from demonstrations."""
    from teachfit.demonstrations.dataset import read_demos
    from teachfit.models.search_model import SearchModel, auto_mirror

    if components != "bic" and not (components.isdigit() and int(components) >= 1):
        raise TeachfitError(f"--components wants a number >= 1 or 'bic', got {components!r}")
    demo_list = read_demos(demos)
    tasks = {d.task for d in demo_list}
    if len(tasks) != 1:
        raise TeachfitError(f"{demos} mixes tasks {sorted(tasks)}; learn one task at a time")
    n_comp: int | Literal["bic"] = "bic" if components == "bic" else int(components)
    chosen = _mirror_dims(mirror)
    model = SearchModel.fit(
        demo_list,
        tasks.pop(),
        n_components=n_comp,
        seed=seed,
        covariance=covariance,  # type: ignore[arg-type]
        mirror=chosen,
    )
    even = auto_mirror(model.dims) if chosen == "auto" else chosen
    model.save(out)
    e = model.exploration
    mean = ", ".join(
        f"{d} {1e3 * v:.1f} {'mrad' if d.startswith('r') else 'mm'}"
        for d, v in zip(model.dims, e.mean, strict=True)
    )
    console.print(
        f"learned from {len(demo_list)} demonstration(s) of [bold]{model.task}[/]: "
        f"{e.n_components} component(s), mean {mean} from the first pose, teacher speed "
        f"{model.speed * 1e3:.1f} mm/s"
        + (
            f"\ncovariance: {model.covariance_choice.describe()}"
            if model.covariance_choice is not None
            else ""
        )
        + (f"\nmade even in {', '.join(even)} (its mirror image added)" if even else "")
        + f"\nmodel -> {out}"
    )


def _mirror_dims(text: str) -> tuple[str, ...] | Literal["auto"]:
    """``--mirror``'s value: ``auto``, ``none`` or comma-separated DOF names."""
    word = text.strip()
    if word == "auto":
        return "auto"
    return () if word == "none" else tuple(d.strip() for d in word.split(",") if d.strip())


@search_app.command("plan")
@guarded
def plan(
    model_arg: o.ModelArgOld = None,
    model_file: o.Model = Path("search.model"),
    method: Annotated[str, _METHOD] = "tshix",
    points: o.Points = 300,
    seed: Annotated[int, o.seed("the TSHIX samples")] = 0,
    plot: Annotated[Path | None, o.plot("the planned trajectory")] = None,
    n: o.PointsOld = None,
) -> None:
    """Plan one search trajectory in the search frame and report its figures of merit."""
    import time

    model_file, points = o.pick(model_file, model_arg), o.pick(points, n)
    from teachfit.execution.search import plan_search
    from teachfit.models.search_model import SearchModel
    from teachfit.trajectories.ergodic import ergodic_metric

    model = SearchModel.load(model_file)
    t0 = time.perf_counter()
    traj = plan_search(model, method, points, np.random.default_rng(seed))
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
            fig = sf.tshix_stages(traj, model.exploration, seed=seed)
        elif traj.states.shape[1] == 3:
            fig = sf.trajectory_3d(traj)
        else:
            fig = sf.planned_vs_executed(traj.states, traj.states, (method, method))
            fig.axes[0].lines[1].remove()  # one path: draw it once
            fig.axes[0].legend()
            fig.axes[0].set_title(f"{method} search trajectory, seed {seed} (search frame)")
            fig.tight_layout()
        sf.save(fig, plot)
        console.print(f"figure -> {plot}")


@search_app.command("run")
@guarded
# Long (> 60 lines) only by its options' declarations: the body checks, runs the searches, prints
def run(
    ctx: typer.Context,
    task: Annotated[str, o.task()] = "peg2d",
    model_file: o.Model = Path("search.model"),
    method: Annotated[str, _METHOD] = "tshix",
    points: o.Points = 300,
    starts: Annotated[int, o.starts("drawn by --protocol")] = 30,
    protocol: Annotated[str, typer.Option(help="start protocol of the task")] = "table1",
    feedforward: Annotated[bool, typer.Option(help="superpose the GMR feed-forward")] = True,
    passes: Annotated[
        int, typer.Option(min=1, help="TSHIX passes: re-sample and continue after a failed pass")
    ] = 1,
    demo: Annotated[
        str | None,
        typer.Option(help="demonstration FILE.h5:INDEX whose start anchors the protocol"),
    ] = None,
    seed: Annotated[int, o.seed("the starts and the TSHIX samples")] = 0,
    plot: Annotated[Path | None, o.plot("the executed paths over the hole")] = None,
    robot: RobotOpt = "floating",
    host: HostOpt = None,
    realtime: RealtimeOpt = True,
    confirm: ConfirmOpt = False,
    reflex_force: ReflexForceOpt = None,
    log: LogOpt = None,
    rrd: RrdOpt = None,
    n: o.PointsOld = None,
) -> None:
    """Execute searches from the protocol's starts and print the success table.

    Table I's starts (Ehlers et al. 2019) lie in a 3 cm circle halfway between the
    demonstration's start and the hole: pass the demonstration the model was learned from
    with --demo.

    Exit status: 0, or 1 when the robot stopped an execution (each reason is printed); a run
    cut short (lost connection, Ctrl-C) prints and logs what finished; see the README.
    """
    points = o.pick(points, n)
    from teachfit.execution.batch import Finished, keep_each
    from teachfit.execution.search import demo_start_pose, run_protocol
    from teachfit.models.search_model import SearchModel
    from teachfit.robot.registry import make_robot
    from teachfit.tasks.registry import load_task

    check_recording_targets(log, rrd)
    the_task = load_task(task)
    model = SearchModel.load(model_file, task=the_task.name)
    demo_start = None if demo is None else demo_start_pose(demo, the_task.name)
    if demo is None and protocol == "table1":
        console.print(
            "[yellow]note:[/] Table I starts lie halfway between the demonstration's start and "
            "the hole; without --demo a nominal demonstration start is assumed"
        )
    the_robot = make_robot(
        robot, the_task, seed=seed, **robot_options(host, realtime, confirm, reflex_force)
    )
    try:
        with progress_bar() as bar:
            job = bar.add_task(f"{method} from {starts} starts", total=starts)
            finished: Finished[SearchRun] = keep_each(
                starts,
                lambda done: run_protocol(
                    the_robot, the_task, model, method, points, starts, protocol, seed,
                    passes=passes, feedforward=feedforward, demo_start=demo_start, on_done=done,
                ),
                lambda: bar.advance(job),
            )  # fmt: skip
    finally:
        the_robot.close()
    runs = finished.items
    n_pts = f", N = {points}" if method == "tshix" else ""
    title = f"{method}{n_pts} on {the_task.name} ({protocol} starts, seed {seed})"
    faulted = _print_runs(runs, title)
    if runs:
        write_recordings(log, rrd, runs, ("search", the_task, robot, seed, method), ctx.params)
    elif log is not None or rrd is not None:
        console.print("no run log written")
    if plot is not None and runs and finished.complete:
        _plot_runs(runs, plot, the_task, f"{method}{n_pts}, seed {seed}, {protocol} starts")
    end_run(finished, faulted)


def _plot_runs(runs: list[SearchRun], plot: Path, task: Task, title: str) -> None:
    """``--plot``: the executed paths over the hole, successes marked."""
    from teachfit.viz.figures import plot_executions

    paths = [(r.result.log.pos, r.result.success) for r in runs]
    plot_executions(paths, plot, task, title=title)
    console.print(f"figure -> {plot}")


def _print_runs(runs: list[SearchRun], title: str) -> bool:
    """The success table of the finished searches and the reason of each the robot stopped;
    whether the robot faulted in any."""
    from teachfit.metrics.stats import summarize

    if not runs:
        console.print("no execution finished")
        return False
    outcomes = [r.result for r in runs]
    s = summarize([o.success for o in outcomes], [o.time_to_success for o in outcomes])
    table = Table(title=title)
    for col in ("starts", "successes", "rate [95 % CI]", "median time", "reasons"):
        table.add_column(col, justify="right")
    reasons: dict[str, int] = {}
    for res in outcomes:
        reasons[res.outcome.value] = reasons.get(res.outcome.value, 0) + 1
    t_med = "n/a" if np.isnan(s.median_time) else f"{s.median_time:.2f} s"
    table.add_row(
        str(s.trials),
        str(s.successes),
        f"{100 * s.rate:.0f} % [{100 * s.low:.0f}, {100 * s.high:.0f}]",
        t_med,
        ", ".join(f"{k} {v}" for k, v in reasons.items()),
    )
    print_table(table)
    return report_faults((i, o.outcome.value, o.reason) for i, o in enumerate(outcomes))


@search_app.command("figures")
@guarded
def figures(
    model_arg: o.ModelArgOld = None,
    model_file: o.Model = Path("search.model"),
    out: Annotated[Path, typer.Option(help="folder for the figures")] = Path("search_figures"),
    points: o.Points = 300,
    seed: Annotated[int, o.seed("the samples and the start")] = 0,
    robot: RobotOpt = "floating",
    n: o.PointsOld = None,
) -> None:
    """The search paper's figures for a model (Ehlers et al. 2019): samples over the
    exploration density for N = 100...500, samples -> itinerary -> smoothed trajectory,
    feed-forward arrows, the 3D trajectory (x, y, rz tasks), and a planned vs. executed path
    from the task's first protocol start."""
    model_file, points = o.pick(model_file, model_arg), o.pick(points, n)
    from teachfit.execution.search import plan_search, run_search
    from teachfit.models.search_model import SearchModel
    from teachfit.robot.registry import make_robot
    from teachfit.tasks.registry import get_task
    from teachfit.viz import search_figures as sf

    model = SearchModel.load(model_file)
    task = get_task(model.task)
    ensure_folder(out, f"the figure folder {out}")
    rng = np.random.default_rng(seed)
    samples = sf.samples_over_distribution(model.exploration, rng, seed=seed)
    written = [sf.save(samples, out / "samples.png")]
    traj = plan_search(model, "tshix", points, np.random.default_rng(seed))
    if model.exploration.dim == 2:
        stages = sf.tshix_stages(traj, model.exploration, seed=seed)
        written.append(sf.save(stages, out / "tshix_stages.png"))
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
    with console.status(f"running the TSHIX search from a {protocol} start"):
        run = run_search(make_robot(robot, task, seed=seed), task, model, start, traj)
    executed = run.result.log.pos[:, :2] - start.pos[:2]
    fig = sf.planned_vs_executed(traj.states[:, :2], executed)
    fig.axes[0].set_title(
        f"TSHIX, N = {points}, seed {seed}, from a {protocol} start: {run.result.outcome.value}",
        fontsize=9,
    )
    written.append(sf.save(fig, out / "planned_vs_executed.png"))
    for path in written:
        console.print(f"figure -> {path}")
