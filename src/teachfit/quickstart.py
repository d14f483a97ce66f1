"""The quickstart job behind ``make demo`` / ``teachfit quickstart``.

Records demonstrations with the simulated blind teacher, then from new start poses (seed A's
Table I protocol: a 3 cm circle halfway between the demonstration's start and the hole)
compares three executions through the impedance controller: replaying the demonstration, the
learned TSHIX search (exploration distribution + GMR feed-forward from that one demonstration)
and a random-walk search of the same path length (Abu-Dakka et al.'s baseline). Reports
successes and time to insertion, and draws the demonstrations, one TSHIX plan (samples ->
itinerary -> smoothed trajectory) and the executed paths.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.progress import Progress
from rich.table import Table

from teachfit.core.atomic import ensure_folder
from teachfit.demonstrations.dataset import write_dataset
from teachfit.execution.batch import episode_rng
from teachfit.execution.engine import ExecutionResult
from teachfit.execution.follow import run_trajectory
from teachfit.execution.replay import replay_trajectory
from teachfit.execution.search import plan_search, run_search
from teachfit.execution.teacher import BlindTeacher
from teachfit.metrics.stats import SuccessSummary, summarize
from teachfit.models.search_model import SearchModel
from teachfit.robot.registry import ROBOTS, make_robot
from teachfit.tasks.registry import get_task
from teachfit.viz import search_figures
from teachfit.viz.figures import plot_demonstrations, plot_executions


@dataclass(frozen=True)
class QuickstartResult:
    replay: SuccessSummary
    search: SuccessSummary
    random_walk: SuccessSummary
    outcomes: dict[str, list[ExecutionResult]]
    files: dict[str, Path]


def run_quickstart(
    out: Path,
    task_name: str = "peg2d",
    n_demos: int = 3,
    n_starts: int = 10,
    seed: int = 0,
    console: Console | None = None,
    robot_name: str = "floating",
) -> QuickstartResult:
    console = console or Console()
    task = get_task(task_name)
    if robot_name not in ROBOTS:
        make_robot(robot_name, task)  # the registry's error, before any output
    ensure_folder(out)
    console.rule(f"[bold]teachfit quickstart[/]: {task.name} - {task.description}")
    teacher = BlindTeacher(task, seed=seed, robot=robot_name)
    demos, discarded = teacher.record(n_demos, progress=True)
    demo_file = write_dataset(out / "demos.h5", demos, overwrite=True)
    fig_demos = plot_demonstrations(demos, out / "demos.png", task)
    console.print(
        f"1. recorded {len(demos)} blind-teacher demonstrations "
        f"({', '.join(f'{d.duration:.1f} s' for d in demos)}; discarded {len(discarded)})"
    )
    demo = demos[0]
    rng = np.random.default_rng(seed + 1)
    demo_start = demo.start_pose
    starts = task.protocol.protocol_starts("table1", n_starts, rng, demo_start)
    robot = make_robot(robot_name, task, seed=seed)
    model = SearchModel.fit([demo], task.name)
    model_file = model.save(out / "search.model")
    console.print(
        f"2. learned the exploration distribution and dynamics from {demo.name} -> {model_file}"
    )
    outcomes: dict[str, list[ExecutionResult]] = {"replay": [], "tshix": [], "random-walk": []}
    paths: dict[str, list] = {k: [] for k in outcomes}
    fig_plan = out / "tshix_plan.png"
    with Progress(console=console, transient=True) as bar:
        job = bar.add_task("executing from new starts", total=3 * len(starts))
        for i, start in enumerate(starts):
            outcome = run_trajectory(robot, task, replay_trajectory(demo, start), start)
            outcomes["replay"].append(outcome)
            paths["replay"].append((outcome.log.pos, outcome.success))
            bar.advance(job)
            traj = plan_search(model, "tshix", 300, episode_rng(seed, i))
            if i == 0:
                search_figures.save(search_figures.tshix_stages(traj, model.exploration), fig_plan)
            steps = max(1, int(traj.path_length() / 0.003))  # random-walk moves average 3 mm
            walk = plan_search(model, "random-walk", steps, np.random.default_rng(seed + i))
            for key, tr in (("tshix", traj), ("random-walk", walk)):
                run = run_search(robot, task, model, start, tr)
                outcomes[key].append(run.result)
                paths[key].append((run.result.log.pos, run.result.success))
                bar.advance(job)
    fig_replay = plot_executions(paths["replay"], out / "replay.png", task, title="demo replay")
    fig_search = plot_executions(paths["tshix"], out / "tshix.png", task, title="TSHIX search")
    fig_walk = plot_executions(
        paths["random-walk"], out / "random_walk.png", task, title="random-walk search"
    )
    summaries = {
        k: summarize([o.success for o in v], [o.time_to_success for o in v])
        for k, v in outcomes.items()
    }
    table = Table(title=f"3. execution from {len(starts)} new starts (Table I protocol)")
    for col in ("execution", "starts", "successes", "rate [95 % CI]", "median time"):
        table.add_column(col, justify="right")
    labels = {
        "replay": "replay of the demo",
        "tshix": "TSHIX search, 300 points",
        "random-walk": "random walk, same length",
    }
    for key, summary in summaries.items():
        t_med = "n/a" if np.isnan(summary.median_time) else f"{summary.median_time:.2f} s"
        table.add_row(
            labels[key],
            str(summary.trials),
            str(summary.successes),
            f"{100 * summary.rate:.0f} % [{100 * summary.low:.0f}, {100 * summary.high:.0f}]",
            t_med,
        )
    console.print(table)
    files = {
        "demonstrations": demo_file,
        "demo figure": fig_demos,
        "model": model_file,
        "TSHIX plan figure": fig_plan,
        "replay figure": fig_replay,
        "search figure": fig_search,
        "random-walk figure": fig_walk,
    }
    for label, path in files.items():
        console.print(f"   {label}: {path}")
    rep, srch, walk_s = summaries["replay"], summaries["tshix"], summaries["random-walk"]
    console.print(
        f"[bold]What this showed:[/] from {len(starts)} new starts, the TSHIX search learned "
        f"from one blind demonstration inserted the peg {srch.successes} times, replaying that "
        f"demonstration {rep.successes} times and a blind random walk of the same length "
        f"{walk_s.successes} times. Seed A's Table I with 30 starts: teachfit bench search."
    )
    return QuickstartResult(rep, srch, walk_s, outcomes, files)
