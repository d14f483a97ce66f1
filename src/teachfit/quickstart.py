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

from collections.abc import Callable
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
from teachfit.robot.interface import Robot
from teachfit.robot.registry import ROBOTS, make_robot
from teachfit.tasks.base import Task
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
    _check_sizes(n_demos, n_starts)
    task = get_task(task_name)
    if robot_name not in ROBOTS:
        make_robot(robot_name, task)  # the registry's error, before any output
    ensure_folder(out)
    console.rule(f"[bold]teachfit quickstart[/]: {task.name} - {task.description}")
    teacher = BlindTeacher(task, seed=seed, robot=robot_name)
    demos, discarded = teacher.record(n_demos, progress=True)
    files = {
        "demonstrations": write_dataset(out / "demos.h5", demos, overwrite=True),
        "demo figure": plot_demonstrations(demos, out / "demos.png", task),
    }
    console.print(
        f"1. recorded {len(demos)} blind-teacher demonstrations "
        f"({', '.join(f'{d.duration:.1f} s' for d in demos)}; discarded {len(discarded)})"
    )
    phases = _phases(task, demos, n_starts, seed)
    robot = make_robot(robot_name, task, seed=seed)
    model = SearchModel.fit(demos, task.name)
    files["model"] = model.save(out / "search.model")
    console.print(
        f"2. learned the exploration distribution and dynamics from all {len(demos)} "
        f"demonstrations -> {files['model']}"
    )
    runs = _Executions(task, robot, model, demos[0], n_points, seed)
    files["TSHIX plan figure"] = out / "tshix_plan.png"
    with Progress(console=console, transient=True) as bar:
        job = bar.add_task("executing", total=3 * n_starts)
        for phase, phase_starts in phases.items():
            for start in phase_starts:
                runs.run(phase, start, files["TSHIX plan figure"], lambda: bar.advance(job))
    moved = len(phases["new starts"]), n_starts - len(phases["new starts"])
    files |= runs.figures(out, f"{moved[0]} new starts + {moved[1]} with the hole moved")
    summaries = {
        k: summarize([o.success for o in v], [o.time_to_success for o in v])
        for k, v in runs.by_phase.items()
    }
    console.print(_table(task.name, summaries, n_points))
    for label, path in files.items():
        console.print(f"   {label}: {path}")
    console.print(_what_it_showed(summaries, list(phases)))
    return QuickstartResult(summaries, runs.outcomes, {**files})


def _check_sizes(n_demos: int, n_starts: int) -> None:
    if n_starts < 2:
        raise TeachfitError(f"--starts must be >= 2 (half run with the hole moved), not {n_starts}")
    if n_demos < 2:
        raise TeachfitError(
            "--count must be >= 2 (the hole-moved starts come from the other demonstrations' "
            f"sides), not {n_demos}"
        )


def _phases(task: Task, demos: list[Demonstration], n_starts: int, seed: int) -> dict[str, list]:
    """The starts by phase: Table I starts halfway between the first demonstration's start
    and the hole (``"new starts"``), and halfway between another's start and the hole (the
    hole moved, seen from the start; the phase named by how far)."""
    demo = demos[0]
    rng = np.random.default_rng(seed + 1)
    n_new = (n_starts + 1) // 2
    others = [demos[1 + j % (len(demos) - 1)].start_pose for j in range(n_starts - n_new)]
    shifts = [float(np.linalg.norm(o.pos - demo.start_pose.pos)) / 2 for o in others]
    moved = f"hole moved {min(shifts) * 1e3:.0f}-{max(shifts) * 1e3:.0f} mm"
    return {
        "new starts": task.protocol.protocol_starts("table1", n_new, rng, demo.start_pose),
        moved: [task.protocol.protocol_starts("table1", 1, rng, o)[0] for o in others],
    }


class _Executions:
    """The three methods from each start, in order (the i-th start's TSHIX seed is
    ``episode_rng(seed, i)``), with the executed paths for the figures."""

    def __init__(
        self,
        task: Task,
        robot: Robot,
        model: SearchModel,
        demo: Demonstration,
        n_points: int,
        seed: int,
    ) -> None:
        self.task, self.robot, self.model, self.demo = task, robot, model, demo
        self.n_points, self.seed, self.i = n_points, seed, 0
        self.outcomes: dict[str, list[ExecutionResult]] = {k: [] for k in _METHODS}
        self.by_phase: dict[tuple[str, str], list[ExecutionResult]] = {}
        self.paths: dict[str, list] = {k: [] for k in _METHODS}

    def run(self, phase: str, start: Pose, fig_plan: Path, advance: Callable[[], None]) -> None:
        """Replay, TSHIX and the random walk from ``start``; the first TSHIX plan is drawn."""
        task, model, seed, i = self.task, self.model, self.seed, self.i
        traj = plan_search(model, "tshix", self.n_points, episode_rng(seed, i))
        if i == 0:
            fig = search_figures.tshix_stages(traj, model.exploration, seed=seed)
            search_figures.save(fig, fig_plan)
        steps = max(1, int(traj.path_length() / 0.003))  # random-walk moves average 3 mm
        walk = plan_search(model, "random-walk", steps, np.random.default_rng(seed + i))
        for key in _METHODS:
            if key == "replay":
                plan = replay_trajectory(self.demo, start)
                result = run_trajectory(self.robot, task, plan, start)
            else:
                tr = traj if key == "tshix" else walk
                result = run_search(self.robot, task, model, start, tr).result
            self.outcomes[key].append(result)
            self.by_phase.setdefault((phase, key), []).append(result)
            self.paths[key].append((result.log.pos, result.success))
            advance()
        self.i += 1

    def figures(self, out: Path, where: str) -> dict[str, Path]:
        """The executed paths of each method, one figure each."""
        titles = {
            "replay": f"replay of {self.demo.name}",
            "tshix": f"TSHIX, N = {self.n_points}, seed {self.seed}",
            "random-walk": f"random walk, seed {self.seed}",
        }
        labels = {"replay": "replay figure", "tshix": "search figure"}
        return {
            labels.get(key, "random-walk figure"): plot_executions(
                self.paths[key], out / f"{key.replace('-', '_')}.png", self.task,
                title=f"{title}, {where}",
            )
            for key, title in titles.items()
        }  # fmt: skip


def _table(
    task_name: str, summaries: dict[tuple[str, str], SuccessSummary], n_points: int
) -> Table:
    table = Table(title=f"3. executions on {task_name} (Table I starts)")
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
    return table


def _what_it_showed(summaries: dict[tuple[str, str], SuccessSummary], phases: list[str]) -> str:
    line = {
        p: ", ".join(f"{k} {summaries[p, k].successes}/{summaries[p, k].trials}" for k in _METHODS)
        for p in phases
    }
    new, moved = phases
    return (
        f"[bold]What this showed:[/] from new starts: {line[new]}; with the "
        f"{moved}: {line[moved]}. A search runs in the frame of its start. The replay "
        "repeats the first demonstration's sweep, so it inserts only where the hole lies on "
        "that sweep; with the hole moved to where another demonstration found it, the sweep "
        "passes beside it. TSHIX plans a new path each time over the area all the "
        "demonstrations searched, and the random walk searches blind. The search paper's "
        "Table I with 30 starts (Ehlers et al. 2019): teachfit bench search --table 1."
    )
