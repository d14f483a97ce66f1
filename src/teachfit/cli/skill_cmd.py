"""``teachfit skill show|run``: the skill graph, and executions of a skill on a task."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

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
from teachfit.cli.recording import LogOpt, RrdOpt, check_recording_targets, write_recordings
from teachfit.cli.run_end import end_run, report_faults
from teachfit.cli.tables import print_table
from teachfit.core.atomic import atomic_write_text

if TYPE_CHECKING:
    from teachfit.execution.engine import ExecutionResult
    from teachfit.execution.recording import Episode
    from teachfit.execution.setups import DrawnSetups
    from teachfit.execution.skill_trial import SkillSetup, SkillTrial
    from teachfit.tasks.base import Task

skill_app = typer.Typer(
    help="Manipulation skills (Johannsmeier et al. 2019): show a skill's graph, run it on a task.",
    no_args_is_help=True,
)

_SKILL = typer.Argument(help="built-in skill name or a skill .toml")
_CONTROLLER = typer.Option(help="controller: adaptive (learns its meta-parameters) or impedance")


def _num(v: float) -> str:
    return f"{v:.4g}"


@skill_app.command("show")
@guarded
def show(
    skill: Annotated[str, _SKILL] = "peg-in-hole",
    plot: Annotated[Path | None, o.plot("the skill graph")] = None,
    controller: Annotated[str, _CONTROLLER] = "adaptive",
    toml: Annotated[Path | None, typer.Option(help="write the skill as TOML here")] = None,
) -> None:
    """Print a skill's primitives, transitions, conditions and parameters."""
    from teachfit.skills.library import get_skill
    from teachfit.skills.loader import skill_to_toml

    sk = get_skill(skill, controller)
    console.print(f"[bold]{sk.name}[/]: {sk.doc}\ntask frame: {sk.frame}")
    nodes = Table(title="primitives (nodes)", title_justify="left")
    for col in ("node", "primitive", "error exit"):
        nodes.add_column(col)
    for node in sk.nodes + ((sk.recovery,) if sk.recovery else ()):
        tag = " (recovery)" if node is sk.recovery else " (start)" if node.name == sk.start else ""
        nodes.add_row(
            node.name + tag, node.primitive.describe(), node.error.describe() if node.error else "-"
        )
    print_table(nodes)
    trs = Table(title="transitions", title_justify="left")
    for col in ("from", "to", "when"):
        trs.add_column(col)
    for tr in sk.transitions:
        trs.add_row(tr.source, tr.target, tr.condition.describe())
    print_table(trs)
    console.print(f"pre: {sk.pre.describe() if sk.pre else 'always'}")
    console.print(f"success: {sk.success.describe()}\nerror: {sk.error.describe()}")
    ctx = Table(title="context parameters (set by the task)", title_justify="left")
    for col in ("name", "value", "unit", "meaning"):
        ctx.add_column(col)
    for name, p in sk.params.context.items():
        ctx.add_row(name, _num(p.value), p.unit, p.doc)
    print_table(ctx)
    lrn = Table(title="learned parameters", title_justify="left")
    for col in ("name", "default", "low", "high", "unit", "meaning"):
        lrn.add_column(col)
    for name, lp in sk.params.learned.items():
        scale = " (log)" if lp.domain.log else ""
        dom = lp.domain
        lrn.add_row(name, _num(lp.default), _num(dom.low), _num(dom.high) + scale, lp.unit, lp.doc)
    print_table(lrn)
    if toml is not None:
        atomic_write_text(toml, skill_to_toml(sk), "skill file")
        console.print(f"skill -> {toml}")
    if plot is not None:
        from teachfit.viz.skill_figures import plot_skill_graph

        console.print(f"graph -> {plot_skill_graph(sk, plot)}")


# long (> 60 lines) only by the declarations of its options: the body checks, runs, prints
@skill_app.command("run")
@guarded
def run(
    ctx: typer.Context,
    skill: Annotated[str, _SKILL] = "peg-in-hole",
    task: Annotated[str, o.task()] = "peg2d",
    params: Annotated[
        Path | None, typer.Option(help="skill parameters (TOML) written by 'teachfit learn skill'")
    ] = None,
    controller: Annotated[str, _CONTROLLER] = "adaptive",
    seed: Annotated[int, o.seed("the hole estimate, the starts and the sensor noise")] = 0,
    starts: Annotated[int, o.starts("per set-up (one execution each)")] = 4,
    setups: Annotated[
        int | None, o.setups("held out: drawn from a stream 'learn skill' never uses")
    ] = None,
    render: o.Render = None,
    render_start: Annotated[int, typer.Option(help="which execution --render draws")] = 0,
    plot: Annotated[Path | None, o.plot("force and pose over time of each execution")] = None,
    fps: o.Fps = 25,
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
    """Run a skill on a task from several start poses: one trial of the skill-learning paper
    (Johannsmeier et al. 2019), its successes and cost.

    Exit status: 0, or 1 when the robot stopped an execution (each reason is printed); a run
    cut short (lost connection, Ctrl-C) prints and logs what finished; see the README."""
    from teachfit.core.errors import SkillError
    from teachfit.execution.setups import draw_setups
    from teachfit.execution.skill_runs import run_starts, start_episodes
    from teachfit.execution.skill_trial import SkillTrial
    from teachfit.skills.library import get_skill
    from teachfit.tasks.registry import load_task

    if starts < 1:
        raise SkillError(f"--starts must be >= 1, got {starts}")
    n_runs = starts * (setups or 1)
    if render is not None and not 0 <= render_start < n_runs:
        raise SkillError(f"--render-start must be within [0, {n_runs - 1}]")
    check_recording_targets(log, rrd)
    the_task = load_task(task)
    sk = get_skill(skill, controller)
    drawn = draw_setups(the_task, seed, starts, controller, sk, setups or 1, setups is not None)
    setup = drawn.setup
    learned = _learned(params, setup)
    trial = SkillTrial(
        setup,
        controller,
        robot=robot,
        seed=seed,
        **robot_options(host, realtime, confirm, reflex_force),
    )
    try:
        console.print(f"{setup.skill.name} on {the_task.name} ({controller} controller); "
                      + describe_setups(drawn))  # fmt: skip
        with console.status(f"running {n_runs} execution(s)"):
            finished = run_starts(trial, learned, n_runs)
        faulted = _report(trial, finished.items)
        if setups is not None:
            console.print(held_out_summary(drawn, trial, finished.items))
        info = ("skill", the_task, robot, seed, f"{skill} {controller}")
        _record(log, rrd, start_episodes(setup, finished.items), info, ctx.params)
        if finished.complete:
            figures = (plot, render, render_start, (fps, width, height))
            _figures(trial, finished.items, figures, f"{controller} controller, seed {seed}")
        end_run(finished, faulted)
    finally:
        trial.robot.close()


def describe_setups(drawn: DrawnSetups) -> str:
    """How far the taught hole of the set-up(s) is off the true one."""
    n = len(drawn.setup.starts) // drawn.setups
    errs = drawn.taught_errors()
    if drawn.setups == 1:
        est = errs[0]
        return (
            f"hole estimate off by ({est.pos[0] * 1e3:+.2f}, {est.pos[1] * 1e3:+.2f}) mm, "
            f"yaw {est.rz:+.3f} rad"
        )
    off = [float(np.hypot(*e.pos[:2])) * 1e3 for e in errs]
    return (
        f"{drawn.setups} held-out set-ups, {n} start(s) each; taught hole off by "
        f"{min(off):.2f}-{max(off):.2f} mm (median {np.median(off):.2f} mm)"
    )


def held_out_summary(drawn: DrawnSetups, trial: SkillTrial, traces: list[ExecutionResult]) -> str:
    """Held-out success: set-ups where every start inserted, and executions, with 95 % Wilson
    intervals."""
    from teachfit.metrics.stats import wilson_interval

    oks = [trial.metric.evaluate(tr)[0] for tr in traces]
    per = drawn.per_setup(oks)

    def rate(k: int, n: int) -> str:
        lo, hi = wilson_interval(k, n)
        return f"{k}/{n} = {100 * k / max(n, 1):.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]"

    return (
        f"held-out set-ups with every start inserted: {rate(sum(per), len(per))}; "
        f"executions: {rate(sum(oks), len(oks))}"
    )


def _learned(params: Path | None, setup: SkillSetup) -> dict[str, float] | None:
    """The learned values of ``--params`` (``None``: defaults); notes the names it leaves out."""
    if params is None:
        return None
    import tomllib

    from teachfit.skills.params import read_params_toml

    learned = read_params_toml(params, setup.skill.params, setup.skill.users())
    given = tomllib.loads(params.read_text(encoding="utf-8")).get("params", {})
    if not (isinstance(given, dict) and given):
        given = tomllib.loads(params.read_text(encoding="utf-8"))
    missing = sorted(set(setup.skill.params.learned) - set(given))
    if missing:
        console.print(
            f"[yellow]note:[/] {params} does not set {', '.join(missing)}: their defaults are used"
        )
    return learned


def _report(trial: SkillTrial, traces: list[ExecutionResult]) -> bool:
    """Print the table of the finished executions, the trial's figures and the reason of
    every execution the robot stopped; whether the robot faulted in any."""
    if not traces:
        console.print("no execution finished")
        return False
    scored = [trial.metric.evaluate(tr) for tr in traces]
    table = Table(title="executions", title_justify="left")
    for col in ("#", "outcome", "detected", "cost (s)", "contact (s)", "end (s)", "nodes"):
        table.add_column(col)
    for i, (tr, (ok, cost)) in enumerate(zip(traces, scored, strict=True)):
        path = " > ".join(v.node for v in tr.visits)
        table.add_row(
            str(i),
            "[green]success[/]" if ok else f"[red]{tr.outcome.value}[/]",
            str(tr.detected),
            f"{cost:.3f}",
            f"{tr.t_first_contact:.2f}",
            f"{tr.t_end:.2f}",
            path,
        )
    print_table(table)
    steps = sum(tr.steps for tr in traces)
    wall = sum(tr.wall_s for tr in traces)
    n_ok = sum(ok for ok, _ in scored)
    console.print(
        f"trial: {n_ok}/{len(traces)} succeeded, cost {np.mean([c for _, c in scored]):.3f} s; "
        f"{wall / len(traces):.3f} s wall per execution, {steps / max(wall, 1e-9):,.0f} sim "
        "steps/s"
    )
    return report_faults((i, tr.outcome.value, tr.reason) for i, tr in enumerate(traces))


def _record(
    log: Path | None,
    rrd: Path | None,
    episodes: list[Episode],
    info: tuple[str, Task, str, int, str],
    options: dict[str, Any],
) -> None:
    """Write ``--log``/``--rrd`` of the finished executions (none finished: nothing written,
    an older file at the path is kept)."""
    if episodes:
        write_recordings(log, rrd, episodes, info, options)
    elif log is not None or rrd is not None:
        console.print("no run log written")


def _figures(trial: SkillTrial, traces: list[ExecutionResult], figures: tuple, title: str) -> None:
    """``--plot`` (force and pose over time; joint torques on the FR3) and ``--render``."""
    plot, render, render_start, (fps, width, height) = figures
    setup = trial.setup
    robot = trial.robot
    title = f"{setup.skill.name} on {setup.task.name}, {title}"
    if plot is not None:
        from teachfit.viz.skill_figures import plot_traces

        console.print(f"traces -> {plot_traces(traces, plot, title)}")
        if hasattr(robot, "recent_torque_traces"):  # the FR3: joint torques over time
            from teachfit.viz.torque_figures import plot_joint_torques

            torques = robot.recent_torque_traces(len(traces))
            image = plot.with_name(f"{plot.stem}-torques{plot.suffix}")
            console.print(f"joint torques -> {plot_joint_torques(torques, image)}")
    if render is not None:
        from teachfit.viz.video import render_motion

        log = traces[render_start].log
        with console.status("rendering"):
            path = render_motion(
                setup.task, log.t, log.pos, log.quat, render, fps=fps, width=width,
                height=height, robot=robot.name,
            )  # fmt: skip
        console.print(f"video -> {path}")
