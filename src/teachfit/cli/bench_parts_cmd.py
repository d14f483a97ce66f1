"""``teachfit bench parts``: the parts suite, every method on every part and robot."""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from teachfit.cli import options as o
from teachfit.cli.common import check_output, console, guarded
from teachfit.cli.progress import progress_bar
from teachfit.cli.tables import emit_table
from teachfit.core.errors import TeachfitError

if TYPE_CHECKING:
    from teachfit.bench.parts import PartRow

_COLS = ("part", "robot", "method", "success [Wilson 95 %]", "median time", "commonest failure")


def _cells(r: PartRow) -> list[str]:
    from teachfit.bench.parts import rate_cell

    t = r.summary.median_time
    why = r.commonest_failure().replace("|", "/")
    why = why if len(why) <= 80 else why[:79] + "…"
    time = "n/a" if t != t else f"{t:.1f} s"
    return [r.part, r.robot, r.method, rate_cell(r.summary), time, why]


def _split(text: str) -> list[str]:
    return [t.strip() for t in text.split(",") if t.strip()]


@guarded
def bench_parts(
    parts: Annotated[
        str, typer.Option(help="parts of the suite, comma-separated (default: all)")
    ] = "",
    robots: Annotated[str, typer.Option(help="robots, comma-separated")] = "floating,fr3",
    methods: Annotated[
        str, typer.Option(help="methods, comma-separated: skill, skill-learned, search, assemble")
    ] = "skill,skill-learned,search,assemble",
    setups: Annotated[int, o.setups("held out, one start each (skill, skill-learned)")] = 20,
    trials: Annotated[int, typer.Option(min=1, help="trials of the learning (skill-learned)")] = 30,
    starts: Annotated[int, o.starts("of the search, and assemble's trials")] = 20,
    train_setups: Annotated[
        int, typer.Option(min=1, help="training set-ups per learning trial")
    ] = 8,
    clearance: o.SuiteClearance = 0.2,
    seed: Annotated[int, o.seed("set-ups, starts, demonstrations and trials")] = 0,
    workers: o.Workers = None,
    markdown: o.Markdown = None,
    plot: Annotated[
        Path | None, o.plot("success per part x method x robot (Wilson 95 % intervals)")
    ] = None,
) -> None:
    """The parts suite (teachfit tasks suite): the skill with default and learned parameters
    on held-out set-ups, the learned search, and assemble with the taught hole 3 mm off, on
    each part and robot; success with Wilson 95 % intervals in one table (goal: >= 90 %)."""
    from teachfit.bench import parts as bp
    from teachfit.robot.registry import ROBOTS
    from teachfit.tasks.mesh.suite import PARTS, write_suite

    chosen = bp.check_choice(_split(parts) or list(PARTS), list(PARTS), "parts")
    robot_list = bp.check_choice(_split(robots), sorted(ROBOTS), "robots")
    method_list = bp.check_choice(_split(methods), bp.METHODS, "methods")
    sizes = bp.Sizes(setups, trials, starts, train_setups, workers=workers)
    for path, flag in ((markdown, "markdown"), (plot, "plot")):
        check_output(path, flag)
    if plot is not None:
        _check_figure(plot)
    title = (
        f"parts suite ({setups} held-out set-ups, {trials} learning trials on {train_setups} "
        f"set-ups, {starts} search starts / assemble trials, {clearance:g} mm clearance, "
        f"seed {seed})"
    )
    with tempfile.TemporaryDirectory(prefix="teachfit-parts-") as folder:
        tasks = dict(zip(chosen, write_suite(folder, chosen, clearance), strict=True))
        rows = _run(tasks, robot_list, sizes, seed, method_list)
    _report(rows, title, markdown, plot)


def _check_figure(plot: Path) -> None:
    from matplotlib.figure import Figure

    if plot.suffix.lower().lstrip(".") not in Figure().canvas.get_supported_filetypes():
        raise TeachfitError(f"--plot {plot}: unknown image format; use .png")


def _run(
    tasks: dict[str, Path], robots: list[str], sizes: object, seed: int, methods: list[str]
) -> list[PartRow]:
    """Every part x robot with a progress bar; each part-robot's rows printed as they end."""
    from teachfit.bench import parts as bp

    assert isinstance(sizes, bp.Sizes)
    total = len(tasks) * len(robots) * sizes.units(methods)

    def done(rows: list[PartRow]) -> None:
        for r in rows:
            console.print(" ".join(_cells(r)))

    with progress_bar() as bar:
        job = bar.add_task("parts suite", total=total)
        return bp.run_parts(
            tasks, robots, sizes, seed, methods, lambda: bar.advance(job), on_rows=done
        )


def _report(rows: Sequence[PartRow], title: str, markdown: Path | None, plot: Path | None) -> None:
    """The table, the goal's misses, the markdown (one line per part and robot, then each
    miss with its commonest failure) and the figure."""
    from teachfit.bench.parts import GOAL, goal_misses, pivot
    from teachfit.cli.common import append_markdown

    emit_table(title, _COLS, [_cells(r) for r in rows], None)
    misses = goal_misses(rows)
    miss = ", ".join(f"{r.part}/{r.robot}/{r.method}" for r in misses)
    goal = f"goal >= {100 * GOAL:.0f} % on every row: " + (f"missed on {miss}" if miss else "met")
    console.print(goal)
    if markdown is not None:
        cols, lines = pivot(rows)
        text = [f"**{title}**", "", "| " + " | ".join(cols) + " |", "|" + " --- |" * len(cols)]
        text += ["| " + " | ".join(c) + " |" for c in lines]
        text += ["", f"{goal}."] + [
            f"- {' / '.join(_cells(r)[:4])}: {_cells(r)[5]}" for r in misses
        ]
        append_markdown(markdown, "\n".join(text))
        console.print(f"markdown appended to {markdown}")
    if plot is not None:
        from teachfit.viz.parts_figures import save_parts_figure

        cells = [(r.part, r.method, r.robot, r.summary) for r in rows]
        console.print(f"figure -> {save_parts_figure(cells, plot, title)}")
