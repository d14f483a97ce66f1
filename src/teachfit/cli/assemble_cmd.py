"""``teachfit assemble`` and ``teachfit bench assembly``: the three methods joined."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, cast

import typer
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import (
    ConfirmOpt,
    HostOpt,
    RealtimeOpt,
    ReflexForceOpt,
    RobotOpt,
    append_markdown,
    console,
    guarded,
    robot_options,
)
from teachfit.cli.progress import progress_bar
from teachfit.cli.recording import LogOpt, RrdOpt, check_recording_targets, write_recordings
from teachfit.cli.run_end import end_run, exit_if_faulted, report_faults
from teachfit.cli.tables import print_table
from teachfit.core.errors import TeachfitError
from teachfit.execution.batch import run_batch_keeping

if TYPE_CHECKING:
    from teachfit.bench.assembly import Rows
    from teachfit.demonstrations.dataset import Demonstration
    from teachfit.execution.assembly import AssemblyTrial
    from teachfit.execution.plan_contact import PlanTrial
    from teachfit.metrics.stats import SuccessSummary

_UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6, "deg": 0.017453292519943295, "rad": 1.0}


def parse_quantity(text: str, default_unit: str = "mm", what: str = "--hole-error") -> float:
    """``"3mm"``, ``"0.5 cm"``, ``"2"`` (``default_unit``) -> SI (m, rad)."""
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:e-?[0-9]+)?)\s*([a-z]*)\s*", text.lower())
    if m is None or (m.group(2) or default_unit) not in _UNITS:
        raise TeachfitError(f"{what}: cannot read {text!r}; write e.g. 3mm, 0.5cm, 2deg")
    return float(m.group(1)) * _UNITS[m.group(2) or default_unit]


def register(app: typer.Typer, bench_app: typer.Typer) -> None:
    """Add ``assemble`` to ``app`` and ``assembly`` to ``bench_app``."""
    app.command("assemble")(assemble)
    bench_app.command("assembly")(bench_assembly)


@guarded
# Long (> 60 lines) only by its options' declarations: the body checks, runs the trials, prints
def assemble(
    task: Annotated[
        str, typer.Option(help="task: peg2d, socket3d, puzzle, key, peg; l-groove, tenon")
    ] = "peg2d",
    search: Annotated[
        Path | None, typer.Option(help="search model (teachfit learn search)")
    ] = None,
    skill: Annotated[
        str, typer.Option(help="skill: built-in name or skill .toml (the search recovers it)")
    ] = "peg-in-hole",
    demo: Annotated[
        str | None,
        typer.Option(help="demonstration FILE.h5:INDEX for l-groove/tenon (default: synthetic)"),
    ] = None,
    hole_error: Annotated[str, typer.Option(help="taught-hole error, e.g. 3mm")] = "3mm",
    yaw_error: Annotated[str, typer.Option(help="taught yaw error bound, e.g. 2deg")] = "0deg",
    angle_error: Annotated[
        str, typer.Option(help="l-groove/tenon: capture rotation error bound")
    ] = "2deg",
    trials: Annotated[int, typer.Option(help="trials to run")] = 30,
    params: Annotated[
        Path | None, typer.Option(help="skill parameters (TOML, e.g. from learn skill)")
    ] = None,
    controller: Annotated[str, typer.Option(help="controller: adaptive or impedance")] = "adaptive",
    seed: Annotated[int, typer.Option(help="random seed of the trials")] = 0,
    workers: Annotated[int, typer.Option(help="worker processes (0: in this process)")] = 0,
    plot: Annotated[Path | None, typer.Option(help="figure: phases of one trial over time")] = None,
    render: Annotated[
        Path | None, typer.Option("--render", help="video (mp4) of that trial")
    ] = None,
    fps: o.Fps = 30,
    width: o.Width = 640,
    height: o.Height = 480,
    robot: RobotOpt = "floating",
    host: HostOpt = None,
    realtime: RealtimeOpt = True,
    confirm: ConfirmOpt = False,
    reflex_force: ReflexForceOpt = None,
    log: LogOpt = None,
    rrd: RrdOpt = None,
) -> None:
    """Assemble over trials: taught hole -> approach -> skill -> learned search recovery.

    Exit status 1 when the robot stopped a trial (each reason is printed); a run cut short
    (Ctrl-C) prints and logs the trials that finished; see the README."""
    from teachfit.execution.assembly import close_robots, run_assembly_job
    from teachfit.execution.assembly_run import PLANNED_PARTS, assembly_setup, shown_trial

    err, yaw, task_name = _checked(task, demo, hole_error, yaw_error, robot)
    check_recording_targets(log, rrd)
    frames = (fps, width, height)
    if task in PLANNED_PARTS:
        ang = parse_quantity(angle_error, "deg", "--angle-error")
        rec = (log, rrd, {"task": task, "demo": demo, "hole_error": hole_error,
               "angle_error": angle_error, "trials": trials, "seed": seed})  # fmt: skip
        _assemble_plan(task, demo, err, ang, trials, seed, plot, render, rec, frames)
        return
    arm = tuple(robot_options(host, realtime, confirm, reflex_force).items())
    if arm and workers:
        raise TeachfitError("--workers: a real robot runs its trials one at a time: leave it out")
    model, method, jobs = assembly_setup(
        (task, task_name), search, skill, params, controller, err, trials, seed=seed,
        yaw_error=yaw, robot=robot, keep_log=any(v is not None for v in (plot, render, log, rrd)),
        robot_options=arm,
    )  # fmt: skip
    what = "skill with learned-search recovery" if model else f"{skill} alone (no --search)"
    console.print(f"{task}: {what}; taught hole off by {err * 1e3:g} mm; {trials} trial(s)")
    with progress_bar() as bar:
        job = bar.add_task("assembling", total=len(jobs))
        try:
            finished = run_batch_keeping(run_assembly_job, jobs, workers, lambda: bar.advance(job))
        finally:
            close_robots()  # a real arm's connection; simulated ones are rebuilt when needed
    out = finished.items
    if not out:
        console.print("no trial finished")
        return end_run(finished, what="trial")
    faulted = _report_trials(out)
    if log is not None or rrd is not None:
        info = ("assemble", task, robot, seed, f"{method} {skill} {controller}")
        opts = {
            "task": task, "search": search, "skill": skill, "hole_error": hole_error,
            "yaw_error": yaw_error, "trials": trials, "params": params,
            "controller": controller, "seed": seed, "robot": robot,
        }  # fmt: skip
        write_recordings(log, rrd, [t.result for t in out], info, opts)
    if (plot is None and render is None) or not finished.complete:
        return end_run(finished, faulted, "trial")
    _trial_figures(shown_trial(out), task, plot, render, robot, frames)
    exit_if_faulted(faulted)


def _checked(
    task: str, demo: str | None, hole_error: str, yaw_error: str, robot: str
) -> tuple[float, float, str]:
    """``assemble``'s options checked before any output: the taught-hole and yaw errors (m,
    rad) and the task's name (a task file of a built-in kind is that kind)."""
    from teachfit.execution.assembly_run import PLANNED_PARTS
    from teachfit.robot.registry import ROBOTS

    err = parse_quantity(hole_error)
    yaw = parse_quantity(yaw_error, "deg", "--yaw-error")
    if robot not in ROBOTS:
        raise TeachfitError(f"unknown robot {robot!r}; robots: {', '.join(sorted(ROBOTS))}")
    if demo is not None and task not in PLANNED_PARTS:
        from teachfit.cli.plan_cmd import _load_demo

        _load_demo(str(demo))  # a bad file is named first
        raise TeachfitError(f"--demo {demo}: only l-groove and tenon plan from a demonstration")
    if task in PLANNED_PARTS:
        return err, yaw, task
    from teachfit.cli.geometry_progress import geometry_progress
    from teachfit.tasks.registry import load_task

    # a bad task (file) before any output; its name is what a model learned on it records
    # (a task file of a built-in kind is that kind): matched as search run matches it
    with geometry_progress(f"loading task {task}"):
        return err, yaw, load_task(task).name


def _report_trials(out: list[AssemblyTrial]) -> bool:
    """The table of the finished trials, their success and the reason of each the robot
    stopped; whether the robot faulted in any."""
    from teachfit.metrics.stats import summarize

    _print_trials(
        "taught offset (mm)",
        [
            (t, f"({t.offset[0] * 1e3:+.2f}, {t.offset[1] * 1e3:+.2f})", t.reason, t.nodes)
            for t in out
        ],
    )
    s = summarize([t.success for t in out], [t.time for t in out])
    searched = sum("search" in t.nodes for t in out)
    console.print(f"success {s}; the search ran in {searched}/{len(out)} trial(s)")
    return report_faults(((t.index, *t.reason.partition(": ")[::2]) for t in out), "trial")


def _trial_figures(
    pick: AssemblyTrial,
    task: str,
    plot: Path | None,
    video: Path | None,
    robot: str,
    frames: tuple[int, int, int],
) -> None:
    """``--plot`` (phases over time) and ``--render`` (a video, ``frames``: its fps, width and
    height) of trial ``pick``."""
    assert pick.result is not None
    if plot is not None:
        from teachfit.viz.assembly_figures import plot_phases

        console.print(f"phases of trial {pick.index} -> {plot_phases(pick.result, plot)}")
    if video is not None:
        from teachfit.tasks.registry import get_task
        from teachfit.viz.video import render_motion

        log = pick.result.log
        with console.status("rendering"):
            path = render_motion(
                get_task(task),
                log.t,
                log.pos,
                log.quat,
                video,
                robot=robot,
                fps=frames[0],
                width=frames[1],
                height=frames[2],
            )
        console.print(f"video of trial {pick.index} -> {path}")


# long (> 60 lines) only by the declarations of its options: the runs are in execution/
@guarded
def bench_assembly(
    tasks: Annotated[str, typer.Option(help="tasks, comma-separated")] = "peg2d,socket3d",
    errors: Annotated[
        str, typer.Option(help="taught-hole errors (mm), comma-separated")
    ] = "0,1,2,3,4,5",
    trials: Annotated[int, typer.Option(help="trials per method and error")] = 10,
    seed: Annotated[int, typer.Option(help="random seed of the demonstrations and trials")] = 0,
    workers: Annotated[
        int | None, typer.Option(help="worker processes (default: all cores)")
    ] = None,
    plot: Annotated[
        Path | None, typer.Option(help="figure: success against error (one per task)")
    ] = None,
    search: Annotated[
        Path | None, typer.Option(help="search model (default: learned from the teacher)")
    ] = None,
    params: Annotated[
        Path | None,
        typer.Option(
            help="skill parameters of the joined skill (TOML from learn skill): adds joined-learned"
        ),
    ] = None,
    methods: Annotated[
        str,
        typer.Option(
            help="methods, comma-separated: skill, search, open-loop, joined (none: only --params)"
        ),
    ] = "skill,search,open-loop,joined",
    markdown: o.Markdown = None,
    robot: Annotated[
        str, typer.Option(help="robot to run on, simulated: floating or fr3 (trials and demos)")
    ] = "floating",
) -> None:
    """Each seed alone vs joined: same trials, same taught-hole errors, Wilson intervals."""
    from teachfit.bench.assembly import bench_inputs, bench_task
    from teachfit.bench.search import use_robot
    from teachfit.execution.assembly import METHODS
    from teachfit.robot.registry import ROBOTS

    simulated = sorted(n for n, e in ROBOTS.items() if e.simulated)
    if robot not in simulated:
        raise TeachfitError(f"--robot: choose {' or '.join(simulated)} (got {robot!r})")
    use_robot(robot)
    on = "" if robot == "floating" else f" on {robot}"
    errs = [parse_quantity(e) for e in errors.split(",") if e.strip()]
    names = [t.strip() for t in tasks.split(",") if t.strip()]
    model, learned = bench_inputs(names, search, params, seed)
    chosen = tuple(m.strip() for m in methods.split(",") if m.strip())
    if not set(chosen) <= set(METHODS) or not (chosen or learned):
        raise TeachfitError(f"--methods: choose from {', '.join(METHODS)} (got {methods!r})")
    md: list[str] = []
    for name in names:
        if name in ("l-groove", "tenon"):
            md += _bench_planned(name, trials, seed, on)
            continue
        with progress_bar() as bar:
            job = bar.add_task(f"{name}: demonstrations, then trials")
            rows = bench_task(
                name, errs, trials, seed, workers, partial(bar.advance, job),
                model=model, learned=learned, methods=chosen,
            )  # fmt: skip
        _print_bench(name, rows, errs, bool(learned))
        md += ["", *_bench_markdown(name + on, rows, errs, trials)]
        if plot is not None:
            from teachfit.viz.assembly_figures import plot_success_by_error

            path = plot.with_name(f"{plot.stem}-{name}{plot.suffix}")
            title = f"{name}: success against the taught-hole error, {trials} trials, seed {seed}"
            console.print(f"figure -> {plot_success_by_error(rows, path, title)}")
    if markdown is not None and md:
        text = "\n".join(md).strip("\n")
        console.print(f"markdown appended to {append_markdown(markdown, text)}")


def _bench_markdown(name: str, rows: Rows, errs: list[float], trials: int) -> list[str]:
    """``bench assembly``'s table of a peg-type task in markdown: each cell successes/trials
    [Wilson 95 %] and the median time to insertion (s from the start)."""

    def cell(s: SuccessSummary) -> str:
        t = "" if math.isnan(s.median_time) else f" {s.median_time:.2f}"
        return f"{s.successes}/{s.trials} [{100 * s.low:.0f},{100 * s.high:.0f}]{t}"

    out = [f"| {name} ({trials} trials), e (mm) | " + " | ".join(rows) + " |"]
    out.append("| --- " * (len(rows) + 1) + "|")
    for i, e in enumerate(errs):
        out.append(f"| {e * 1e3:g} | " + " | ".join(cell(rows[m][i][1]) for m in rows) + " |")
    return out


def _bench_planned(name: str, trials: int, seed: int, on: str = "") -> list[str]:
    """``bench assembly`` on a planned part: open loop vs joined, one line each (returned
    as markdown list items too)."""
    from teachfit.bench.assembly import bench_plan_task, losses

    with progress_bar() as bar:
        job = bar.add_task(f"{name}: plan, then trials", total=2 * trials)
        rows, meas = bench_plan_task(name, trials, seed, partial(bar.advance, job))
    lines = [
        f"{name}{on} {m}: capture error 0.5-{pts[0][0] * 1e3:g} mm, 0.5-2 deg: truly "
        f"inserted {pts[0][1]} (end time); measured success {meas[m]}/{trials}"
        for m, pts in rows.items()
    ]
    for line in lines:
        console.print(line)
    for line in losses(rows):
        console.print(f"  [yellow]joined does not beat[/] {line}")
    return [f"- {line}" for line in lines]


def _print_bench(name: str, rows: Rows, errs: list[float], learned: bool) -> None:
    """``bench assembly``'s table of a peg-type task and where the joined skill loses."""
    from teachfit.bench.assembly import losses

    table = Table(title=f"{name}: success [Wilson 95 %], median time", title_justify="left")
    table.add_column("error (mm)", justify="right")
    for method in rows:
        table.add_column(method)
    for i, e in enumerate(errs):
        table.add_row(f"{e * 1e3:g}", *(str(rows[m][i][1]) for m in rows))
    console.print(table)
    for line in losses(rows) if "joined" in rows else ():
        console.print(f"  [yellow]joined does not beat[/] {line}")
    for line in losses(rows, "joined-learned") if learned else ():
        console.print(f"  [yellow]joined-learned does not beat[/] {line}")


def _print_trials(error_col: str, rows: list[tuple[Any, str, str, Sequence[str]]]) -> None:
    """The per-trial table of both kinds of run: (trial, its error, failure reason, nodes)."""
    table = Table(title="trials", title_justify="left")
    for col in ("#", error_col, "outcome", "time (s)", "truth", "primitives"):
        table.add_column(col)
    for tr, error, reason, nodes in rows:
        outcome = "[green]success[/]" if tr.success else f"[red]{reason}[/]"
        table.add_row(
            str(tr.index), error, outcome, f"{tr.time:.2f}", str(tr.ground_truth), " > ".join(nodes)
        )
    print_table(table)


def _assemble_plan(
    part: str,
    demo: str | None,
    err: float,
    ang: float,
    trials: int,
    seed: int,
    plot: Path | None,
    video: Path | None,
    rec: tuple[Path | None, Path | None, Mapping[str, object]],
    frames: tuple[int, int, int],
) -> None:
    """demonstration -> plan -> path executed in contact -> seating skill, over trials;
    ``rec``: the run log and Rerun targets and the options they record; ``frames``: the
    video's fps, width and height."""
    import numpy as np

    from teachfit.execution.assembly_run import capture_ranges, planned_path
    from teachfit.execution.assembly_run import run_plan_trials_keeping as run_trials

    if trials < 1:
        raise TeachfitError(f"--trials must be >= 1, got {trials}")
    ranges = capture_ranges(err, ang)
    d = None
    if demo is not None:
        from teachfit.cli.plan_cmd import _load_demo

        d = cast("Demonstration", _load_demo(str(demo)))
        if getattr(d, "task", part) != part:
            raise TeachfitError(f"{demo}: a demonstration of {d.task!r}, not {part!r}")
    with console.status("planning"):
        plan, path = planned_path(part, d, seed)
    (lo_t, _), (lo_r, _) = ranges["translation"], ranges["rotation"]
    console.print(
        f"{part}: plan in {plan.time_s:.2f} s with {plan.used_key_poses}/{plan.candidates} key "
        f"poses ({'demo ' + str(demo) if demo else 'synthetic demo'}), {path.duration:.1f} s "
        f"path; capture error {lo_t * 1e3:g}-{err * 1e3:g} mm, "
        f"{np.degrees(lo_r):g}-{np.degrees(ang):g} deg"
    )
    with progress_bar() as bar:
        job = bar.add_task("executing in contact", total=trials)
        finished = run_trials(part, path, trials, seed, lambda: bar.advance(job), **ranges)
    out = finished.items
    if not out:
        console.print("no trial finished")
        return end_run(finished, what="trial")
    faulted = _report_plan_trials(part, out)
    if rec[0] is not None or rec[1] is not None:
        info = ("assemble", part, "floating", seed, "plan in contact + seating")
        write_recordings(rec[0], rec[1], [t.result for t in out], info, rec[2])
    if not finished.complete:
        return end_run(finished, faulted, "trial")
    _plan_figures(out[0], plot, video, part, seed, ranges, frames)
    exit_if_faulted(faulted)


def _report_plan_trials(part: str, out: list[PlanTrial]) -> bool:
    """The table of a planned part's finished trials, their success beside the paper's robot
    and the reason of each the robot stopped; whether the robot faulted in any."""
    import numpy as np

    from teachfit.execution.plan_contact import PAPER_ROBOT
    from teachfit.metrics.stats import summarize

    _print_trials(
        "error (mm, deg)",
        [
            (
                t,
                f"{t.error_m * 1e3:.2f}, {np.degrees(t.error_rad):.2f}",
                t.result.reason,
                [v.node for v in t.result.visits],
            )
            for t in out
        ],
    )
    s = summarize([t.success for t in out], [t.time for t in out])
    truth = sum(bool(t.ground_truth) for t in out)
    ok, n = PAPER_ROBOT[part]
    console.print(
        f"success {s}; ground truth {truth}/{len(out)}; the paper's robot, open loop: {ok}/{n}"
    )
    rows = ((t.index, t.result.outcome.value, t.result.reason) for t in out)
    return report_faults(rows, "trial")


def _plan_figures(
    pick: PlanTrial,
    plot: Path | None,
    video: Path | None,
    part: str,
    seed: int,
    ranges: dict[str, tuple[float, float]],
    frames: tuple[int, int, int],
) -> None:
    """``--plot`` (phases over time) and ``--render`` (a video in its cell; ``frames``: its
    fps, width and height) of trial 0."""
    if plot is not None:
        from teachfit.viz.assembly_figures import plot_phases

        console.print(f"phases of trial 0 -> {plot_phases(pick.result, plot)}")
    if video is not None:
        from teachfit.execution.plan_contact import trial_cell
        from teachfit.viz.video import render_motion

        log = pick.result.log
        cell = trial_cell(part, seed, 0, **ranges)
        with console.status("rendering"):
            path_mp4 = render_motion(
                cell,
                log.t,
                log.pos,
                log.quat,
                video,
                fps=frames[0],
                width=frames[1],
                height=frames[2],
            )
        console.print(f"video of trial 0 -> {path_mp4}")
