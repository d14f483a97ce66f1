"""``teachfit bench search``: Ehlers et al.'s tables in simulation, ours beside the paper's."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from teachfit.cli import options as o
from teachfit.cli.common import RobotOpt, console, guarded
from teachfit.cli.progress import progress_bar
from teachfit.cli.tables import emit_table
from teachfit.core.atomic import atomic_write_text
from teachfit.core.errors import TeachfitError

if TYPE_CHECKING:
    from teachfit.bench.search import Row
    from teachfit.bench.search_variants import VariantResult

TABLES = ("1", "2", "ablation", "3", "all")
_COLS = ("method", "ours [95 % CI]", "paper [95 % CI]", "median time", "plan", "length", "E")


def _rate(s: int, n: int, lo: float, hi: float) -> str:
    return f"{s}/{n} = {100 * s / n:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]"


def _cells(row: Row) -> list[str]:
    from teachfit.metrics.stats import wilson_interval

    ours = row.ours
    paper = row.paper
    p = "n/a" if paper is None else _rate(*paper, *wilson_interval(*paper))
    t = "n/a" if ours.median_time != ours.median_time else f"{ours.median_time:.1f} s"
    plan = f"{row.plan_ms:.0f} ms"
    if row.paper_cpu_s is not None:
        plan += f" (paper {row.paper_cpu_s:.1f} s)"
    return [
        row.method,
        _rate(ours.successes, ours.trials, ours.low, ours.high),
        p,
        t,
        plan,
        f"{row.length:.2f} m",
        f"{row.ergodic:.4f}",
    ]


def _emit(title: str, rows: Sequence[Row], markdown: Path | None) -> None:
    emit_table(title, _COLS, [_cells(r) for r in rows], markdown)


@guarded
def bench_search(
    table: Annotated[str, typer.Option(help="paper table: 1, 2, ablation, 3 or all")] = "1",
    seed: Annotated[int, o.seed("the starts and the TSHIX samples")] = 0,
    starts: Annotated[
        int | None, o.starts("per table (default: the paper's, 30 for I, 15 for III)")
    ] = None,
    points: Annotated[
        int | None,
        typer.Option(min=1, help="TSHIX points (default: the paper's, 300 for I, 600 for III)"),
    ] = None,
    trajectories: Annotated[int, typer.Option(help="Table II trajectories per N")] = 20,
    workers: o.Workers = None,
    markdown: o.Markdown = None,
    robot: RobotOpt = "floating",
    task: Annotated[
        str | None, o.task("run Table I's protocol on this one (name or .toml) instead")
    ] = None,
    demo: Annotated[
        str | None,
        typer.Option(help="demonstrations of --task, FILE.h5 (default: the teacher records one)"),
    ] = None,
    variants: Annotated[
        int,
        typer.Option(
            min=0,
            help="also run this many seeded task variants per task: Table I's protocol on "
            "peg2d variants (--table 1), Table III's on socket3d ones (--table 3), both (all); "
            "0: none",
        ),
    ] = 0,
    plot: Annotated[
        Path, o.plot("with --variants, success against each variant parameter (one per task)")
    ] = Path("search_variants.png"),
    methods: Annotated[
        str | None,
        typer.Option(
            help="methods, comma-separated: the rows of --table 1 or 3 to run (default: all; "
            "Table I: tshix, tshix-iid, ergodic; Table III: random-walk, spiral, tshix-1demo, "
            "tshix-2demo, tshix-2demo-diag, tshix-2demo-auto, ergodic-3d-2demo; with --variants: "
            "tshix, ergodic, where tshix alone, the goal's method, halves the executions)"
        ),
    ] = None,
    passes: Annotated[
        int,
        typer.Option(
            min=1,
            help="TSHIX passes: with --variants, a tour that ends without the hole goes on "
            "through fresh samples (1: Ehlers et al.'s single tour)",
        ),
    ] = 1,
) -> None:
    """The search paper's experiments (Ehlers et al. 2019) in simulation, beside its numbers.

    Success rates carry a Wilson 95 % interval; 'plan' is the median trajectory-planning wall
    time, 'length' the mean planned path length (x, y), 'E' the mean ergodic metric.
    """
    from teachfit.bench import search as bs

    todo, rows_of, ergodic = _check(table, task, demo, methods, variants)
    if passes > 1 and not variants:
        raise TeachfitError("--passes is for --variants: the paper's tables run one tour")
    bs.use_robot(robot)
    if variants:
        names = {"1": ["peg2d"], "3": ["socket3d"], "all": ["peg2d", "socket3d"]}[table]
        run = VariantRun(starts or 20, points, workers, ergodic, passes)
        for name in names:
            _variants(name, variants, seed, run, markdown, plot)
    elif task is not None:
        _task_table(task, demo, seed, starts or 10, points or 300, workers, markdown)
    else:
        _paper_tables(todo, seed, starts, points, trajectories, workers, markdown, rows_of)


def _check(
    table: str, task: str | None, demo: str | None, methods: str | None, variants: int
) -> tuple[tuple[str, ...], list[str] | None, bool]:
    """The tables to run, the methods chosen (None: all) and whether the ergodic rows run;
    refuses a combination of options that does not fit before anything is recorded."""
    from teachfit.bench import search as bs

    if table not in TABLES:
        raise TeachfitError(f"unknown table {table!r}; available: {list(TABLES)}")
    if demo is not None and task is None:
        raise TeachfitError(f"--demo {demo} is for --task TASK (the paper's tables record theirs)")
    todo = TABLES[:-1] if table == "all" else (table,)
    rows_of = None if methods is None else [m.strip() for m in methods.split(",") if m.strip()]
    if variants and rows_of is not None and rows_of not in (["tshix"], ["tshix", "ergodic"]):
        raise TeachfitError("with --variants, --methods is tshix or tshix,ergodic")
    ergodic = rows_of is None or "ergodic" in rows_of
    if rows_of is not None and not variants and (table not in ("1", "3") or task is not None):
        raise TeachfitError("--methods chooses rows of --table 1 or --table 3 (one table)")
    if rows_of is not None and not variants:  # a bad name fails before anything is recorded
        bs.chosen_methods(
            rows_of, *((bs.TABLE1_METHODS, "I") if table == "1" else (bs.TABLE3_METHODS, "III"))
        )
    if variants and (table not in ("1", "3", "all") or task is not None):
        raise TeachfitError("--variants runs --table 1, 3 or all, and takes no --task")
    return todo, rows_of, ergodic


def _paper_tables(
    todo: Sequence[str],
    seed: int,
    starts: int | None,
    points: int | None,
    trajectories: int,
    workers: int | None,
    markdown: Path | None,
    rows_of: list[str] | None,
) -> None:
    """The paper's tables in ``todo``, each printed (and appended to ``markdown``)."""
    from teachfit.bench import search as bs

    with progress_bar() as bar:
        if "1" in todo:
            n = starts or 30
            k = len(bs.chosen_methods(rows_of, bs.TABLE1_METHODS, "I"))
            job = bar.add_task("Table I: TSHIX (QMC, i.i.d.) and ergodic", total=k * n)
            rows = bs.table1(
                seed, n, points or 300, workers=workers, progress=lambda: bar.advance(job),
                methods=rows_of,
            )  # fmt: skip
            title = f"Table I (peg2d, 0.5 mm clearance, 1 demo, {n} starts, seed {seed})"
            _emit(title, rows, markdown)
        if "2" in todo or "ablation" in todo:
            sizes = (100, 200, 300, 400, 500) if "2" in todo else ()
            abl = (100, 200, 400) if "ablation" in todo else ()
            job = bar.add_task("Table II / ablation", total=(len(sizes) + len(abl)) * trajectories)
            rows2, rows_a = bs.table2(
                seed, sizes, trajectories, abl, workers=workers, progress=lambda: bar.advance(job)
            )
            if rows2:
                title = f"Table II (peg2d, one start, {trajectories} TSHIX runs per N, seed {seed})"
                _emit(title, rows2, markdown)
            if rows_a:
                title = f"Feed-forward ablation (same start, no feed-forward, seed {seed})"
                _emit(title, rows_a, markdown)
        if "3" in todo:
            n, n_points = starts or 15, points or 600
            k = len(bs.chosen_methods(rows_of, bs.TABLE3_METHODS, "III"))
            job = bar.add_task("Table III: socket3d", total=k * n)
            rows = bs.table3(
                seed, n, n_points, workers=workers, progress=lambda: bar.advance(job),
                methods=rows_of,
            )  # fmt: skip
            title = f"Table III (socket3d x-y-rz, {n} starts, {n_points} points, seed {seed})"
            _emit(title, rows, markdown)


def _task_table(
    task: str,
    demo: str | Path | None,
    seed: int,
    starts: int,
    points: int,
    workers: int | None,
    markdown: Path | None,
) -> None:
    from teachfit.bench.search_task import task_demos, task_table
    from teachfit.demonstrations.dataset import read_dataset
    from teachfit.tasks.registry import load_task

    load_task(task)  # a bad task file fails first, before any demonstration is read
    if demo is None:
        with console.status(f"the blind teacher demonstrates {task}"):
            demos = task_demos(task, seed)
    else:
        demos = read_dataset(demo)
    with progress_bar() as bar:
        job = bar.add_task(f"Table I protocol on {task}", total=2 * starts)
        rows = task_table(task, demos, seed, starts, points, workers, lambda: bar.advance(job))
    title = f"Table I protocol ({task}, {len(demos)} demo(s), {starts} starts, seed {seed})"
    _emit(title, rows, markdown)


def _variant_cells(r: VariantResult) -> list[str]:
    """A variant's row: its axis values, demonstrations kept/tried, TSHIX, ergodic."""
    cells = [f"{v:g}" for _, v in r.variant.values] + [f"{r.kept}/{r.tried}"]
    by = {row.method: row.ours for row in r.rows}
    for m in ("tshix", "ergodic"):
        s = by.get(m)
        why = r.why[:60] or "not run"
        cells.append(why if s is None else _rate(s.successes, s.trials, s.low, s.high))
    return cells


@dataclass(frozen=True)
class VariantRun:
    """How each variant runs: ``starts``, TSHIX ``points`` (None: the protocol's),
    ``workers``, whether the ``ergodic`` row runs, TSHIX ``passes`` per start."""

    starts: int
    points: int | None
    workers: int | None
    ergodic: bool
    passes: int


def _variants(
    task: str, n: int, seed: int, run: VariantRun, markdown: Path | None, figure: Path
) -> None:
    from matplotlib.figure import Figure

    from teachfit.bench import search_variants as sv
    from teachfit.viz.output import save_figure
    from teachfit.viz.variant_figures import success_by_parameter

    if figure.suffix.lower().lstrip(".") not in Figure().canvas.get_supported_filetypes():
        raise TeachfitError(f"cannot write figure {figure}: unknown image format; use .png")
    protocol, default_points, demos = sv.PROTOCOLS[task]
    tours = "" if run.passes == 1 else f" x {run.passes} passes"
    title = (
        f"{task} variants ({protocol} protocol, {demos} teacher demo(s), {run.starts} starts, "
        f"{run.points or default_points} points{tours}, seed {seed})"
    )
    out = figure.with_name(f"{figure.stem}_{task}{figure.suffix}")
    done: list[VariantResult] = []

    def finished(r: VariantResult) -> None:  # printed and saved as each variant ends
        done.append(r)
        cells = _variant_cells(r)[-3:] if r.rows else [f"{r.kept}/{r.tried}", r.why]
        console.print(f"{task} {r.variant.label}: demos {', '.join(cells)}")
        atomic_write_text(out.with_suffix(".json"), sv.results_json(done), "results")
        save_figure(success_by_parameter(sv.figure_data(done), title, sv.GOALS[task]), out)

    with progress_bar() as bar:
        what = "TSHIX and ergodic" if run.ergodic else "TSHIX"
        job = bar.add_task(f"{task} variants: {what}", total=(1 + run.ergodic) * n * run.starts)
        results = sv.run_variants(
            task,
            n,
            seed,
            run.starts,
            run.points,
            run.workers,
            lambda: bar.advance(job),
            run.ergodic,
            finished,
            run.passes,
        )
    cols = (*(k for k, _ in results[0].variant.values), "demos kept/tried", "TSHIX", "ergodic")
    lines = [_variant_cells(r) for r in results]
    emit_table(title, cols, lines, markdown)
    misses = sv.goal_misses(results)
    goal = sv.GOALS[task]
    console.print(
        f"goal TSHIX >= {100 * goal:.0f} % on every variant: "
        + ("met" if not misses else f"missed on {', '.join(r.variant.label for r in misses)}")
    )
    console.print(f"figure -> {out}, results -> {out.with_suffix('.json')}")
