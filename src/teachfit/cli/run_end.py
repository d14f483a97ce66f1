"""How a command that runs executions on a robot ends: the faults it reports, its exit status.

``search run``, ``skill run`` and ``assemble`` share one rule for their exit status:

* 0: the run completed and no execution was stopped by the robot;
* 1: an execution was stopped by the robot (``robot-fault``: a reflex, a limit, a lost
  connection; or ``diverged``: a broken simulation), or a robot fault cut the run short;
* 2: bad input, refused before the run (as every command), or another teachfit error that
  cut the run short;
* 130: Ctrl-C; 143: SIGTERM.

The reason of every execution the robot or its controller stopped is printed below the table,
one line each (:func:`report_faults`). A run cut short (:class:`~teachfit.execution.batch.
Finished`) still prints the table of what finished and writes every finished execution to its
``--log``; then :func:`end_run` prints one line saying why it stopped and exits.
"""

from __future__ import annotations

import signal
from collections.abc import Iterable
from typing import Any

import typer
from rich.markup import escape

from teachfit.cli.common import console, err_console
from teachfit.core.errors import RobotFault, TeachfitError
from teachfit.core.outcome import Outcome
from teachfit.execution.batch import Finished

#: exit status of a run in which the robot stopped an execution (see the module docstring)
EXIT_FAULT = 1
#: exit status of bad input or another teachfit error
EXIT_ERROR = 2
#: exit status after Ctrl-C
EXIT_INTERRUPTED = 130
#: outcomes whose reason is printed below the table
STOPPED = (Outcome.FAULT.value, Outcome.DIVERGED.value, Outcome.CONTROL_ERROR.value)
#: outcomes that make the exit status 1
FAULTED = (Outcome.FAULT.value, Outcome.DIVERGED.value)
#: reason lines printed at most (the rest counted; every reason is in ``--log``)
MAX_LINES = 10


def report_faults(rows: Iterable[tuple[int, str, str]], what: str = "execution") -> bool:
    """Print ``WHAT I OUTCOME: REASON`` for each ``(index, outcome value, reason)`` the robot
    or its controller stopped (at most :data:`MAX_LINES`); whether any was a robot fault."""
    stopped = [row for row in rows if row[1] in STOPPED]
    for i, outcome, reason in stopped[:MAX_LINES]:
        line = f"[red]{what} {i} {outcome}:[/] {escape(reason)}"
        console.print(line, highlight=False, soft_wrap=True)  # one line at any width
    if len(stopped) > MAX_LINES:
        console.print(f"... and {len(stopped) - MAX_LINES} more (every reason is in --log)")
    return any(row[1] in FAULTED for row in stopped)


def exit_if_faulted(faulted: bool) -> None:
    """Exit with status 1 (:data:`EXIT_FAULT`) when the robot stopped an execution of a run
    that completed (``faulted``, from :func:`report_faults`)."""
    if faulted:
        raise typer.Exit(EXIT_FAULT)


def _stop_line(finished: Finished[object], what: str) -> tuple[str, int]:
    """The line saying why the run stopped, and the exit status."""
    exc = finished.stop
    done = len(finished.items)
    of = f" of {finished.total}" if finished.total else ""
    head = f"stopped after {done}{of} {what}(s)"
    if isinstance(exc, KeyboardInterrupt):
        return f"{head}: interrupted (Ctrl-C)", EXIT_INTERRUPTED
    if isinstance(exc, SystemExit):  # SIGTERM in teachfit's CLI: 128 + the signal's number
        code = exc.code if isinstance(exc.code, int) else 1
        try:
            why = f"terminated by {signal.Signals(code - 128).name}"
        except ValueError:
            why = f"ended with status {code}"
        return f"{head}: {why}", code
    status = EXIT_FAULT if isinstance(exc, RobotFault) else EXIT_ERROR
    return f"{head}: {exc}", status


def end_run(finished: Finished[Any], faulted: bool = False, what: str = "execution") -> None:
    """End the command as the module docstring says, after its table and its ``--log``.

    Returns when the run completed and ``faulted`` is false (status 0); raises
    ``typer.Exit`` with the status otherwise, after one line on stderr when the run was cut
    short; re-raises an exception that is neither a teachfit error nor an interruption (a bug
    shows its traceback, after the finished executions were recorded)."""
    exc = finished.stop
    if exc is None:
        return exit_if_faulted(faulted)
    if not isinstance(exc, TeachfitError | KeyboardInterrupt | SystemExit):
        raise exc
    line, status = _stop_line(finished, what)
    err_console.print("[bold red]error:[/] ", end="")
    err_console.print(line, markup=False, emoji=False, highlight=False, soft_wrap=True)
    raise typer.Exit(status) from None
