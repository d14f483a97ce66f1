"""The quickstart job behind ``make demo`` / ``teachfit quickstart``.

Records demonstrations with the simulated blind teacher (each from its own side of the hole),
then compares three executions through the impedance controller: replaying the first
demonstration, the learned TSHIX search (exploration distribution + GMR feed-forward from all the
demonstrations, Ehlers et al. 2019) and a random-walk search of the same path length (Abu-Dakka
et al.'s baseline). A search runs in the frame of its start (a demonstration's first pose is its
origin), so what matters is where the hole lies *seen from the start*:

- ``"new starts"``: starts of the paper's Table I protocol (a 3 cm circle halfway between the
  first demonstration's start and the hole): the hole lies about where the replayed
  demonstration went;
- ``"hole moved"``: Table I starts halfway between another demonstration's start and the hole:
  seen from the start, the hole has moved to where that demonstration found it, by half the
  distance between the two demonstrations' starts (up to ``demo_offset``, 30 mm on peg2d).
  The replay sweeps its own band and passes beside it; the learned distribution covers every
  demonstrated band.

Reports successes and time to insertion, and draws the demonstrations, one TSHIX plan and the
executed paths.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.progress import Progress
from rich.table import Table

from teachfit.core.atomic import ensure_folder
from teachfit.core.errors import TeachfitError
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

_METHODS = ("replay", "tshix", "random-walk")


@dataclass(frozen=True)
class QuickstartResult:
    """Success summaries per phase (``"new starts"``, ``"hole moved"``) and method."""

    summaries: dict[tuple[str, str], SuccessSummary]
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
    n_points: int = 300,
) -> QuickstartResult:
    """Record ``n_demos``, learn from all of them, run ``n_starts`` starts (half of them with
    the hole moved) with each method and report; files and figures go to ``out``."""
    console = console or Console()
    if n_starts < 2:
        raise TeachfitError(f"--starts must be >= 2 (half run with the hole moved), not {n_starts}")
    if n_demos < 2:
        raise TeachfitError(
            "--count must be >= 2 (the hole-moved starts come from the other demonstrations' "
            f"sides), not {n_demos}"
        )
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
    n_new = (n_starts + 1) // 2
    others = [demos[1 + j % (len(demos) - 1)].start_pose for j in range(n_starts - n_new)]
    shifts = [float(np.linalg.norm(o.pos - demo.start_pose.pos)) / 2 for o in others]
    moved = f"hole moved {min(shifts) * 1e3:.0f}-{max(shifts) * 1e3:.0f} mm"
    phases = {
        "new starts": task.protocol.protocol_starts("table1", n_new, rng, demo.start_pose),
        moved: [task.protocol.protocol_starts("table1", 1, rng, o)[0] for o in others],
    }
    robot = make_robot(robot_name, task, seed=seed)
    model = SearchModel.fit(demos, task.name)
    model_file = model.save(out / "search.model")
    console.print(
        f"2. learned the exploration distribution and dynamics from all {len(demos)} "
        f"demonstrations -> {model_file}"
    )
    outcomes: dict[str, list[ExecutionResult]] = {k: [] for k in _METHODS}
    by_phase: dict[tuple[str, str], list[ExecutionResult]] = {}
    paths: dict[str, list] = {k: [] for k in outcomes}
    fig_plan = out / "tshix_plan.png"
    i = 0
    with Progress(console=console, transient=True) as bar:
        job = bar.add_task("executing", total=3 * n_starts)
        for phase, phase_starts in phases.items():
            for start in phase_starts:
                traj = plan_search(model, "tshix", n_points, episode_rng(seed, i))
                if i == 0:
                    fig = search_figures.tshix_stages(traj, model.exploration, seed=seed)
                    search_figures.save(fig, fig_plan)
                steps = max(1, int(traj.path_length() / 0.003))  # random-walk moves average 3 mm
                walk = plan_search(model, "random-walk", steps, np.random.default_rng(seed + i))
                for key in _METHODS:
                    if key == "replay":
                        result = run_trajectory(robot, task, replay_trajectory(demo, start), start)
                    else:
                        tr = traj if key == "tshix" else walk
                        result = run_search(robot, task, model, start, tr).result
                    outcomes[key].append(result)
                    by_phase.setdefault((phase, key), []).append(result)
                    paths[key].append((result.log.pos, result.success))
                    bar.advance(job)
                i += 1
    where = f"{n_new} new starts + {n_starts - n_new} with the hole moved"
    figs = {
        key: plot_executions(
            paths[key], out / f"{key.replace('-', '_')}.png", task, title=f"{label}, {where}"
        )
        for key, label in (
            ("replay", f"replay of {demo.name}"),
            ("tshix", f"TSHIX, N = {n_points}, seed {seed}"),
            ("random-walk", f"random walk, seed {seed}"),
        )
    }
    summaries = {
        k: summarize([o.success for o in v], [o.time_to_success for o in v])
        for k, v in by_phase.items()
    }
    table = Table(title=f"3. executions on {task.name} (Table I starts)")
    for col in ("where", "execution", "successes", "rate [95 % CI]", "median time"):
        table.add_column(col, justify="right")
    labels = {
        "replay": "replay of the first demo",
        "tshix": f"TSHIX search, {n_points} points",
        "random-walk": "random walk, same length",
    }
    for (phase, key), summary in summaries.items():
        t_med = "n/a" if np.isnan(summary.median_time) else f"{summary.median_time:.2f} s"
        table.add_row(
            phase if key == "replay" else "",
            labels[key],
            f"{summary.successes}/{summary.trials}",
            f"{100 * summary.rate:.0f} % [{100 * summary.low:.0f}, {100 * summary.high:.0f}]",
            t_med,
        )
    console.print(table)
    files = {
        "demonstrations": demo_file,
        "demo figure": fig_demos,
        "model": model_file,
        "TSHIX plan figure": fig_plan,
        "replay figure": figs["replay"],
        "search figure": figs["tshix"],
        "random-walk figure": figs["random-walk"],
    }
    for label, path in files.items():
        console.print(f"   {label}: {path}")
    line = {
        p: ", ".join(f"{k} {summaries[p, k].successes}/{summaries[p, k].trials}" for k in _METHODS)
        for p in phases
    }
    console.print(
        f"[bold]What this showed:[/] from new starts: {line['new starts']}; with the "
        f"{moved}: {line[moved]}. A search runs in the frame of its start. The replay "
        "repeats the first demonstration's sweep, so it inserts only where the hole lies on "
        "that sweep; with the hole moved to where another demonstration found it, the sweep "
        "passes beside it. TSHIX plans a new path each time over the area all the "
        "demonstrations searched, and the random walk searches blind. The search paper's "
        "Table I with 30 starts (Ehlers et al. 2019): teachfit bench search --table 1."
    )
    return QuickstartResult(summaries, outcomes, {**files})
