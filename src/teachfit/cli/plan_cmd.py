"""CLI of guided planning: ``parts show``, ``demo synth``, ``plan``, ``bench planning``.

``app`` holds all four (``app parts show``, ``app demo synth``, ``app plan``,
``app bench planning``); the main CLI can mount the pieces it needs: ``parts_app``,
:func:`demo_synth`, :func:`plan`, :func:`bench_planning_cmd`. Every command reports a
:class:`~teachfit.core.errors.TeachfitError` as one line (:func:`~teachfit.cli.common.guarded`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import append_markdown, console, guarded
from teachfit.cli.progress import progress_bar
from teachfit.cli.tables import print_table
from teachfit.core.errors import PlanningError, TeachfitError

if TYPE_CHECKING:
    from teachfit.bench.planning import PlanningBenchConfig, TaskBench
    from teachfit.demonstrations.dataset import Demonstration
    from teachfit.plans.planner import MotionPlanner, PlanResult
    from teachfit.tasks.parts import Assembly

__all__ = [
    "app",
    "bench_app",
    "bench_planning_cmd",
    "demo_app",
    "demo_synth",
    "parts_app",
    "parts_show",
    "plan",
]

app = typer.Typer(help="Motion planning guided by demonstrated key poses.", no_args_is_help=True)
parts_app = typer.Typer(help="Parametric parts of the planning tasks.", no_args_is_help=True)
demo_app = typer.Typer(help="Demonstrations of the pose sequence.", no_args_is_help=True)
bench_app = typer.Typer(help="Benchmarks.", no_args_is_help=True)
app.add_typer(parts_app, name="parts")
app.add_typer(demo_app, name="demo")
app.add_typer(bench_app, name="bench")


@parts_app.command("show")
@guarded
def parts_show(
    task: Annotated[str, typer.Argument(help="l-groove or tenon")],
    plot: Annotated[Path | None, o.plot("the parts at their start and goal poses")] = None,
    task_param: Annotated[list[str] | None, o.TASK_PARAM] = None,
    task_params: o.TaskParams = None,
) -> None:
    """Print the parts' dimensions, start and goal poses; optionally plot them."""
    asm = _assembly(task, task_param, task_params)
    table = Table(title=f"{task} dimensions")
    table.add_column("dimension")
    table.add_column("mm", justify="right")
    for key, value in asm.dimensions.items():
        table.add_row(key, f"{1e3 * value:.1f}")
    print_table(table)
    console.print(f"moving part: {len(asm.moving.faces)} triangles, fixed: {len(asm.fixed.faces)}")
    console.print(f"start L2G position (mm): {(1e3 * asm.start[:3, 3]).round(1)}")
    console.print(f"goal  L2G position (mm): {(1e3 * asm.goal[:3, 3]).round(1)}")
    if plot is not None:
        from teachfit.viz.plan_figures import parts_figure

        parts_figure(asm, plot)
        console.print(f"wrote {plot}")


@demo_app.command("synth")
@guarded
def demo_synth(
    out: Annotated[Path, typer.Option(help="HDF5 file to write")],
    task: Annotated[str, o.task("l-groove or tenon")] = "l-groove",
    seed: Annotated[int, o.seed("the tremor and contacts (demonstration i: seed + i)")] = 0,
    count: Annotated[int, typer.Option(min=1, help="number of demonstrations to write")] = 1,
    overwrite: o.Overwrite = False,
    task_param: Annotated[list[str] | None, o.TASK_PARAM] = None,
    task_params: o.TaskParams = None,
) -> None:
    """Write synthetic human demonstrations of the pose sequence to HDF5."""
    from teachfit.demonstrations.dataset import write_dataset
    from teachfit.plans.synth import synth_demo

    asm = _assembly(task, task_param, task_params)
    demos = [synth_demo(asm, seed + i) for i in range(count)]
    write_dataset(out, demos, overwrite=overwrite)
    for demo in demos:
        console.print(
            f"{demo.name}: {len(demo.t)} poses over {demo.t[-1]:.1f} s, "
            f"{demo.meta['n_colliding']} in collision"
        )
    console.print(f"wrote {out}")


def _assembly(task: str, items: list[str] | None, path: Path | None) -> Assembly:
    """The task's parts with the ``--task-params`` file and ``--task-param`` overrides."""
    from teachfit.tasks.registry import build_assembly

    return build_assembly(task, **dict(o.task_overrides(items, PlanningError, path)))


def _load_demo(spec: str) -> Demonstration:
    from teachfit.demonstrations.dataset import read_dataset, read_demo

    if ":" in Path(spec).name:
        return read_demo(spec)
    demos = read_dataset(spec)
    if not demos:
        raise TeachfitError(f"{spec} holds no demonstration")
    return demos[0]


@app.command("plan")
@guarded
def plan(
    task: Annotated[str, o.task("l-groove or tenon")] = "l-groove",
    demo: Annotated[
        str | None, typer.Option(help="demonstration FILE.h5:INDEX (FILE.h5: its first)")
    ] = None,
    no_demo: Annotated[bool, typer.Option("--no-demo", help="plan without demonstration")] = False,
    te: Annotated[
        float | None,
        typer.Option(
            min=0, help="budget per attempt (s); default 0.002 (box parts), 0.02 (meshes)"
        ),
    ] = None,
    max_checks: Annotated[
        int | None,
        typer.Option(
            min=1, help="budget per attempt in collision checks instead of --te (any machine)"
        ),
    ] = None,
    planner: Annotated[str, typer.Option(help="OMPL planner")] = "RRTConnect",
    seed: Annotated[int, o.seed("the key-pose repair and of OMPL")] = 0,
    render: o.Render = None,
    strip: Annotated[
        Path | None, typer.Option(help="write the path as a strip of poses (png)")
    ] = None,
    keyposes: Annotated[
        Path | None, typer.Option(help="write the ranked key poses figure (png)")
    ] = None,
    save: Annotated[
        Path | None, typer.Option(help="write the path (N, 7) x,y,z,qw,qx,qy,qz as .npy")
    ] = None,
    task_param: Annotated[list[str] | None, o.TASK_PARAM] = None,
    task_params: o.TaskParams = None,
) -> None:
    """Plan the moving part from its initial to its final pose."""
    from teachfit.plans.planner import MotionPlanner, PlannerConfig

    if (demo is None) == (not no_demo):
        raise PlanningError("give exactly one of --demo FILE and --no-demo")
    asm = _assembly(task, task_param, task_params)
    mp = MotionPlanner(asm, PlannerConfig(planner=planner, te=te, max_checks=max_checks))
    result = mp.plan(None if demo is None else _load_demo(demo), seed=seed)  # no_demo
    status = "[green]success[/green]" if result.success else "[red]failure[/red]"
    console.print(
        f"{status}: {result.message}; planning {result.time_s:.3f} s "
        f"(total {result.total_s:.3f} s), {result.attempts} attempt(s), "
        f"key poses used {result.used_key_poses}/{result.candidates}, "
        f"replaced {result.replaced_key_poses}, {result.collision_checks} collision checks"
    )
    if keyposes is not None and result.key_poses is not None:
        from teachfit.viz.plan_figures import keypose_figure

        keypose_figure(result.key_poses, keyposes)
        console.print(f"wrote {keyposes}")
    if not result.success:
        raise typer.Exit(code=1)
    if save is not None:
        console.print(f"wrote {result.save(save)}")
    _write_path_media(asm, mp, result, strip, render)


def _write_path_media(
    asm: Assembly, mp: MotionPlanner, result: PlanResult, strip: Path | None, render: Path | None
) -> None:
    """The planned path as a strip of poses (png) and as a video, where asked for."""
    if strip is not None:
        from teachfit.viz.plan_figures import path_strip_figure

        path_strip_figure(asm, mp.dense_poses(result.poses, 0.002), out=strip)
        console.print(f"wrote {strip}")
    if render is not None:
        from teachfit.viz.plan_video import render_path_video

        with console.status(f"rendering the path to {render}"):
            render_path_video(asm, mp.dense_poses(result.poses, 0.002), render)
        console.print(f"wrote {render}")


def _print_planning_report(results: list[TaskBench]) -> None:
    """The Table I protocol's table and notes."""
    from teachfit.bench import planning as bp

    table = Table(title="Planning with demonstrated key poses (Table I protocol)")
    for col in bp.TABLE_COLUMNS:
        table.add_column(col)
    for row in bp.report_table(results):
        table.add_row(*row)
    print_table(table)
    for line in bp.report_notes(results):
        console.print(line)


# Long (> 60 lines) only by its options' declarations: the body parses, runs the bench, prints
@bench_app.command("planning")
@guarded
def bench_planning_cmd(
    tasks: Annotated[str, typer.Option(help="tasks, comma-separated")] = "l-groove,tenon",
    runs: Annotated[
        int, typer.Option(min=1, help="planning runs per task (seeds 0, 1, ..., runs - 1)")
    ] = 50,
    te: Annotated[
        float, typer.Option(min=0, help="budget per attempt (s) with demonstration")
    ] = 0.002,
    max_checks: Annotated[
        int | None,
        typer.Option(
            min=1, help="budget per attempt in collision checks instead of --te (with demo)"
        ),
    ] = None,
    planner: Annotated[str, typer.Option(help="OMPL planner")] = "RRTConnect",
    no_demo_runs: Annotated[
        int, typer.Option(min=0, help="planning runs without demonstration, per task")
    ] = 5,
    no_demo_budget: Annotated[
        float, typer.Option(min=0, help="budget (s) without demonstration")
    ] = 30.0,
    markdown: o.Markdown = None,
    seeds: Annotated[int | None, o.old("--seeds", "--runs")] = None,
    no_demo_seeds: Annotated[int | None, o.old("--no-demo-seeds", "--no-demo-runs")] = None,
    write: o.WriteOld = False,
    benchmarks: Annotated[Path | None, o.old("--benchmarks", "--markdown")] = None,
    task_param: Annotated[list[str] | None, o.TASK_PARAM] = None,
    task_params: o.TaskParams = None,
    variants: Annotated[
        int,
        typer.Option(
            min=0,
            help="also run this many seeded task variants per task (clearance 0.5 mm to the "
            "default, sizes x0.9-1.1), --runs seeds each; 0: none",
        ),
    ] = 0,
) -> None:
    """Table I of the planning paper (Wang et al. 2019) over many seeds, with and without
    demonstration."""
    from teachfit.bench import planning as bp

    runs, no_demo_runs = o.pick(runs, seeds), o.pick(no_demo_runs, no_demo_seeds)
    if write or benchmarks is not None:
        markdown = markdown or benchmarks or Path("BENCHMARKS.md")

    cfg = bp.PlanningBenchConfig(
        tasks=tuple(t.strip() for t in tasks.split(",") if t.strip()),
        seeds=runs,
        te=te,
        max_checks=max_checks,
        planner=planner,
        no_demo_seeds=no_demo_runs,
        no_demo_budget=no_demo_budget,
        overrides=o.task_overrides(task_param, PlanningError, task_params),
    )
    cfg.check_overrides()  # bad overrides: one line before any run
    with progress_bar() as bar:
        job = bar.add_task("planning", total=cfg.n_runs)
        results = bp.run_planning_bench(
            cfg, progress=lambda label, _done: bar.update(job, advance=1, description=label)
        )
    _print_planning_report(results)
    command = cfg.command() + (f" --variants {variants}" if variants else "")
    text = bp.to_markdown(results, command=command)
    if variants:
        text += _variant_sweep(cfg, variants)
    if markdown is not None:
        path = append_markdown(markdown, text)
        console.print(f"markdown appended to {path}")


def _variant_sweep(cfg: PlanningBenchConfig, n: int) -> str:
    """Run and print the variant sweep; its markdown table."""
    from teachfit.bench import planning_variants as pv
    from teachfit.plans.planner import PlannerConfig

    planner = PlannerConfig(planner=cfg.planner, te=cfg.te, max_checks=cfg.max_checks)
    tasks = cfg.tasks
    with progress_bar() as bar:
        job = bar.add_task("variants", total=len(tasks) * n * cfg.seeds)
        results = pv.run_variants(
            tasks,
            n,
            cfg.seeds,
            planner,
            progress=lambda label, _done: bar.update(job, advance=1, description=label),
        )
    table = Table(title="Guided planning on parameter variants (same settings)")
    for col in pv.VARIANT_COLUMNS:
        table.add_column(col)
    rows = pv.variant_rows(results)
    for row in rows:
        table.add_row(*row)
    print_table(table)
    lines = [
        "",
        "| " + " | ".join(pv.VARIANT_COLUMNS) + " |",
        "|" + "---|" * len(pv.VARIANT_COLUMNS),
    ]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows]) + "\n"
