"""The quickstart job behind ``make demo`` / ``teachfit quickstart``.

Records demonstrations with the simulated blind teacher, then compares three executions through
the impedance controller: replaying the demonstration, the learned TSHIX search (exploration
distribution + GMR feed-forward from that one demonstration, Ehlers et al. 2019) and a
random-walk search of the same path length (Abu-Dakka et al.'s baseline). Half of the start
poses are new starts of the paper's Table I protocol (a 3 cm circle halfway between the
demonstration's start and the hole); for the other half the hole is moved
:data:`HOLE_SHIFT` to the side of where the demonstration found it. Reports successes and time
to insertion, and draws the demonstrations, one TSHIX plan and the executed paths.
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
from teachfit.core.geometry import Pose
from teachfit.demonstrations.dataset import Demonstration, write_dataset
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

#: how far the hole is moved sideways (m, across the demonstration's search direction) for the
#: second half of the starts: the replay's sweep then passes beside it
HOLE_SHIFT = 0.015
_METHODS = ("replay", "tshix", "random-walk")


@dataclass(frozen=True)
class QuickstartResult:
    """Success summaries per phase (``"new starts"``, ``"hole moved"``) and method."""

    summaries: dict[tuple[str, str], SuccessSummary]
    outcomes: dict[str, list[ExecutionResult]]
    files: dict[str, Path]


def shifted_starts(starts: list[Pose], demo: Demonstration, shift: float) -> list[Pose]:
    """The starts as seen from a hole moved by ``shift`` (m) across the demonstration's search
    direction (its start -> end in x-y): the same relative geometry as moving the fixture, with
    the fixture left where it is (each start moves by ``-shift`` instead)."""
    d = demo.pos[-1, :2] - demo.pos[0, :2]
    across = np.array([-d[1], d[0], 0.0]) / max(float(np.linalg.norm(d)), 1e-9)
    return [Pose(s.pos - shift * across, s.quat) for s in starts]


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
    if n_starts < 2:
        raise TeachfitError(f"--starts must be >= 2 (half run with the hole moved), not {n_starts}")
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
    starts = task.protocol.protocol_starts("table1", n_starts, rng, demo.start_pose)
    phases = {
        "new starts": starts[:n_new],
        f"hole moved {HOLE_SHIFT * 1e3:.0f} mm": shifted_starts(starts[n_new:], demo, HOLE_SHIFT),
    }
    robot = make_robot(robot_name, task, seed=seed)
    model = SearchModel.fit([demo], task.name)
    model_file = model.save(out / "search.model")
    console.print(
        f"2. learned the exploration distribution and dynamics from {demo.name} -> {model_file}"
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
                traj = plan_search(model, "tshix", 300, episode_rng(seed, i))
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
            ("replay", "replay of the demonstration"),
            ("tshix", f"TSHIX, N = 300, seed {seed}"),
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
        "replay": "replay of the demo",
        "tshix": "TSHIX search, 300 points",
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
    new, moved = phases
    line = {
        p: ", ".join(f"{k} {summaries[p, k].successes}/{summaries[p, k].trials}" for k in _METHODS)
        for p in phases
    }
    console.print(
        f"[bold]What this showed:[/] from new starts: {line[new]}; with the {moved}: "
        f"{line[moved]}. The replay repeats the one demonstrated path, so it can insert only "
        "where the hole lies on that path; TSHIX plans a new path over the area the "
        "demonstration searched each time, and the random walk searches blind. The search "
        "paper's Table I with 30 starts (Ehlers et al. 2019): teachfit bench search --table 1."
    )
    return QuickstartResult(summaries, outcomes, {**files})
