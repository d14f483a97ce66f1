"""Progress of long geometry work (reading, checking and decomposing part meshes).

The geometry code calls :func:`report` with what it is doing and how far it got; whoever shows
progress (the CLI's progress bar) installs a reporter with :func:`reporting` around the work.
Without a reporter nothing is shown. The reporter is a context variable, so threads and other
callers are unaffected.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar

#: ``reporter(what, done, total)``: ``done`` of ``total`` steps of the work ``what`` are done
Reporter = Callable[[str, int, int], None]

_REPORTER: ContextVar[Reporter | None] = ContextVar("teachfit_mesh_progress", default=None)


@contextmanager
def reporting(reporter: Reporter) -> Iterator[None]:
    """Send the progress of the geometry work inside the ``with`` block to ``reporter``."""
    token = _REPORTER.set(reporter)
    try:
        yield
    finally:
        _REPORTER.reset(token)


def report(what: str, done: int, total: int) -> None:
    """Tell the installed reporter (if any) that ``done`` of ``total`` steps of ``what`` are
    done."""
    reporter = _REPORTER.get()
    if reporter is not None:
        reporter(what, done, total)
