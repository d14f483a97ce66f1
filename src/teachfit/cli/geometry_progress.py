"""Progress bars for long geometry work (mesh tasks: reading, checking, decomposing parts)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from rich.progress import TaskID

from teachfit.cli.common import console
from teachfit.cli.progress import progress_bar
from teachfit.tasks.mesh.progress import reporting


@contextmanager
def geometry_progress(what: str) -> Iterator[None]:
    """Show ``what`` with a spinner-like bar, and a bar for each step of geometry work that
    the mesh code reports inside the ``with`` block (transient: gone once done; nothing when
    the output is not a terminal)."""
    if not console.is_terminal:
        yield
        return
    with progress_bar() as bar:
        bar.add_task(what, total=None)
        steps: dict[str, TaskID] = {}

        def show(step: str, done: int, total: int) -> None:
            if step not in steps:
                steps[step] = bar.add_task(step, total=total)
            bar.update(steps[step], completed=done, total=total)

        with reporting(show):
            yield
