"""The progress bar every long-running command shows (transient: gone once done)."""

from __future__ import annotations

from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from teachfit.cli.common import console

__all__ = ["progress_bar"]


def progress_bar() -> Progress:
    """A description, a bar, ``done/total`` and the elapsed time, on the shared console."""
    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        transient=True,
    )
