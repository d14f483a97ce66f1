"""``search run``'s executions: the searches from a protocol's starts on one robot, what
finished kept when a fault or an interrupt ends the rest (:class:`~teachfit.execution.batch.
Finished`), and the demonstration start that anchors Table I's starts."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from teachfit.core.errors import TeachfitError
from teachfit.execution.batch import Finished, keeping

if TYPE_CHECKING:
    from teachfit.core.geometry import Pose
    from teachfit.execution.search import SearchRun
    from teachfit.models.search_model import SearchModel
    from teachfit.robot.interface import Robot
    from teachfit.tasks.base import Task


def demo_start_pose(demo: str, task: str) -> Pose:
    """The start pose of the demonstration ``demo`` (``FILE.h5:INDEX``), which must show
    ``task`` (its name)."""
    from teachfit.demonstrations.dataset import read_demo

    d = read_demo(demo)
    if d.task != task:
        raise TeachfitError(f"--demo {demo} is a {d.task!r} demonstration, not {task!r}")
    return d.start_pose


def run_protocol_keeping(
    robot: Robot,
    task: Task,
    model: SearchModel,
    method: str,
    n_points: int,
    n_starts: int,
    protocol: str,
    seed: int,
    *,
    passes: int,
    feedforward: bool,
    demo_start: Pose | None,
    progress: Callable[[], None],
) -> Finished[SearchRun]:
    """:func:`~teachfit.execution.search.run_protocol` on ``robot``, closed at the end,
    keeping the runs that finished when a fault or an interrupt ends the rest; ``progress`` is
    called after each run."""
    from teachfit.execution.search import run_protocol

    finished: Finished[SearchRun] = Finished(total=n_starts)
    with keeping(finished):
        try:

            def done(run: SearchRun) -> None:
                finished.add(run)
                progress()

            run_protocol(
                robot, task, model, method, n_points, n_starts, protocol, seed,
                passes=passes, feedforward=feedforward, demo_start=demo_start, on_done=done,
            )  # fmt: skip
        finally:
            robot.close()
    return finished
