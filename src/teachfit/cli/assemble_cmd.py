"""``teachfit assemble`` and ``teachfit bench assembly``: the three seeds joined."""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from teachfit.cli.common import RobotOpt, console, guarded
from teachfit.cli.progress import progress_bar
from teachfit.cli.recording import LogOpt, RrdOpt, check_recording_targets, write_recordings
from teachfit.cli.run_end import end_run, exit_if_faulted, report_faults
from teachfit.cli.tables import print_table
from teachfit.core.errors import TeachfitError
from teachfit.execution.batch import Finished, keeping, run_batch_keeping

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
    robot: RobotOpt = "floating",
    log: LogOpt = None,
    rrd: RrdOpt = None,
) -> None:
    """Assemble over trials: taught hole -> approach -> skill -> learned search recovery.

    Exit status 1 when the robot stopped a trial (each reason is printed); a run cut short
    (Ctrl-C) prints and logs the trials that finished; see the README."""
    from teachfit.metrics.stats import summarize
    from teachfit.robot.registry import ROBOTS

    video = render
    err = parse_quantity(hole_error)
    yaw = parse_quantity(yaw_error, "deg", "--yaw-error")
    if robot not in ROBOTS:
        raise TeachfitError(f"unknown robot {robot!r}; robots: {', '.join(sorted(ROBOTS))}")
    if demo is not None and task not in ("l-groove", "tenon"):
        from teachfit.cli.plan_cmd import _load_demo

        _load_demo(str(demo))  # a bad file is named first
        raise TeachfitError(f"--demo {demo}: only l-groove and tenon plan from a demonstration")
    task_name = task
    if task not in ("l-groove", "tenon"):
        from teachfit.cli.geometry_progress import geometry_progress
        from teachfit.tasks.registry import load_task

        # a bad task (file) before any output; its name is what a model learned on it records
        # (a task file of a built-in kind is that kind): matched as search run matches it
        with geometry_progress(f"loading task {task}"):
            task_name = load_task(task).name
    check_recording_targets(log, rrd)
    if task in ("l-groove", "tenon"):
        ang = parse_quantity(angle_error, "deg", "--angle-error")
        rec = (log, rrd, {"task": task, "demo": demo, "hole_error": hole_error,
               "angle_error": angle_error, "trials": trials, "seed": seed})  # fmt: skip
        _assemble_plan(task, demo, err, ang, trials, seed, plot, video, rec)
        return
    from teachfit.execution.assembly import assembly_jobs, run_assembly_job
    from teachfit.models.search_model import SearchModel
    from teachfit.skills.library import get_skill
    from teachfit.skills.params import read_params_toml

    if trials < 1:
        raise TeachfitError(f"--trials must be >= 1, got {trials}")
    model = SearchModel.load(search, task=task_name) if search is not None else None
    if model is not None and skill != "peg-in-hole":
        raise TeachfitError(f"the learned search recovers the peg-in-hole skill, not {skill!r}")
    method = "joined" if model is not None else "skill"
    learned: dict[str, float] = {}
    if params is not None:
        from teachfit.execution.assembly import method_skill

        sk = method_skill(method, model, skill, controller)
        learned = read_params_toml(params, sk.params, sk.users())
    else:
        get_skill(skill, controller)  # a bad --skill fails before any trial
    jobs = assembly_jobs(
        task, [method], [err], trials, model, seed=seed, yaw_error=yaw, skill=skill,
        controller=controller, learned=tuple(sorted(learned.items())), robot=robot,
        keep_log=any(v is not None for v in (plot, video, log, rrd)),
    )  # fmt: skip
    what = "skill with learned-search recovery" if model else f"{skill} alone (no --search)"
    console.print(f"{task}: {what}; taught hole off by {err * 1e3:g} mm; {trials} trial(s)")
    with progress_bar() as bar:
        job = bar.add_task("assembling", total=len(jobs))
        finished = run_batch_keeping(run_assembly_job, jobs, workers, lambda: bar.advance(job))
    out = finished.items
    if not out:
        console.print("no trial finished")
        return end_run(finished, what="trial")
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
    faulted = report_faults(((t.index, *t.reason.partition(": ")[::2]) for t in out), "trial")
    if log is not None or rrd is not None:
        info = ("assemble", task, robot, seed, f"{method} {skill} {controller}")
        opts = {
            "task": task, "search": search, "skill": skill, "hole_error": hole_error,
            "yaw_error": yaw_error, "trials": trials, "params": params,
            "controller": controller, "seed": seed, "robot": robot,
        }  # fmt: skip
        write_recordings(log, rrd, [t.result for t in out], info, opts)
    if (plot is None and video is None) or not finished.complete:
        return end_run(finished, faulted, "trial")
    pick = next((t for t in out if "search" in t.nodes and t.success), out[0])
    assert pick.result is not None
    if plot is not None:
        from teachfit.viz.assembly_figures import plot_phases

        console.print(f"phases of trial {pick.index} -> {plot_phases(pick.result, plot)}")
    if video is not None:
        from teachfit.tasks.registry import get_task
        from teachfit.viz.video import render_motion

        log = pick.result.log
        with console.status("rendering"):
            path = render_motion(get_task(task), log.t, log.pos, log.quat, video, robot=robot)
        console.print(f"video of trial {pick.index} -> {path}")
    exit_if_faulted(faulted)


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
) -> None:
    """Each seed alone vs joined: same trials, same taught-hole errors, Wilson intervals."""
    from teachfit.bench.assembly import bench_inputs, bench_plan_task, bench_task, losses
    from teachfit.execution.assembly import METHODS

    errs = [parse_quantity(e) for e in errors.split(",") if e.strip()]
    names = [t.strip() for t in tasks.split(",") if t.strip()]
    model, learned = bench_inputs(names, search, params, seed)
    chosen = tuple(m.strip() for m in methods.split(",") if m.strip())
    if not set(chosen) <= set(METHODS) or not (chosen or learned):
        raise TeachfitError(f"--methods: choose from {', '.join(METHODS)} (got {methods!r})")
    for name in names:
        if name in ("l-groove", "tenon"):
            with progress_bar() as bar:
                job = bar.add_task(f"{name}: plan, then trials", total=2 * trials)
                rows, meas = bench_plan_task(name, trials, seed, lambda j=job: bar.advance(j))
            for m, pts in rows.items():
                console.print(
                    f"{name} {m}: capture error 0.5-{pts[0][0] * 1e3:g} mm, 0.5-2 deg: truly "
                    f"inserted {pts[0][1]} (end time); measured success {meas[m]}/{trials}"
                )
            for line in losses(rows):
                console.print(f"  [yellow]joined does not beat[/] {line}")
            continue
        with progress_bar() as bar:
            job = bar.add_task(f"{name}: demonstrations, then trials")
            rows = bench_task(
                name, errs, trials, seed, workers, lambda j=job: bar.advance(j),
                model=model, learned=learned, methods=chosen,
            )  # fmt: skip
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
        if plot is not None:
            from teachfit.viz.assembly_figures import plot_success_by_error

            path = plot.with_name(f"{plot.stem}-{name}{plot.suffix}")
            title = f"{name}: success against the taught-hole error, {trials} trials, seed {seed}"
            console.print(f"figure -> {plot_success_by_error(rows, path, title)}")


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
    rec: tuple[Path | None, Path | None, dict[str, object]] = (None, None, {}),
) -> None:
    """demonstration -> plan -> path executed in contact -> seating skill, over trials;
    ``rec``: the run log and Rerun targets and the options they record."""
    import numpy as np

    from teachfit.execution.plan_contact import (
        PAPER_ROBOT,
        PlanTrial,
        plan_path,
        run_plan_trials,
        timed_path,
        trial_cell,
    )
    from teachfit.metrics.stats import summarize

    if trials < 1:
        raise TeachfitError(f"--trials must be >= 1, got {trials}")
    lo_t, lo_r = min(0.0005, err), min(np.radians(0.5), ang)
    ranges = {"translation": (lo_t, err), "rotation": (lo_r, ang)}
    d = None
    if demo is not None:
        from teachfit.cli.plan_cmd import _load_demo

        d = _load_demo(str(demo))
        if getattr(d, "task", part) != part:
            raise TeachfitError(f"{demo}: a demonstration of {d.task!r}, not {part!r}")
    with console.status("planning"):
        plan = plan_path(part, d, seed)  # type: ignore[arg-type]
    if not plan.success:
        raise TeachfitError(f"no plan for {part}: {plan.message}")
    path = timed_path(part, plan)
    console.print(
        f"{part}: plan in {plan.time_s:.2f} s with {plan.used_key_poses}/{plan.candidates} key "
        f"poses ({'demo ' + str(demo) if demo else 'synthetic demo'}), {path.duration:.1f} s "
        f"path; capture error {lo_t * 1e3:g}-{err * 1e3:g} mm, "
        f"{np.degrees(lo_r):g}-{np.degrees(ang):g} deg"
    )
    finished: Finished[PlanTrial] = Finished(total=trials)
    with keeping(finished), progress_bar() as bar:
        job = bar.add_task("executing in contact", total=trials)

        def done(trial: PlanTrial) -> None:
            finished.add(trial)
            bar.advance(job)

        run_plan_trials(part, path, trials, seed, on_trial=done, **ranges)
    out = finished.items
    if not out:
        console.print("no trial finished")
        return end_run(finished, what="trial")
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
    faulted = report_faults(rows, "trial")
    if rec[0] is not None or rec[1] is not None:
        info = ("assemble", part, "floating", seed, "plan in contact + seating")
        write_recordings(rec[0], rec[1], [t.result for t in out], info, rec[2])
    if not finished.complete:
        return end_run(finished, faulted, "trial")
    pick = out[0]
    if plot is not None:
        from teachfit.viz.assembly_figures import plot_phases

        console.print(f"phases of trial 0 -> {plot_phases(pick.result, plot)}")
    if video is not None:
        from teachfit.viz.video import render_motion

        log = pick.result.log
        cell = trial_cell(part, seed, 0, **ranges)
        with console.status("rendering"):
            path_mp4 = render_motion(cell, log.t, log.pos, log.quat, video)
        console.print(f"video of trial 0 -> {path_mp4}")
    exit_if_faulted(faulted)
