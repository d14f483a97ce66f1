"""Asking a person before each reset of a real arm (``--confirm``): where they want to watch.

Autonomous trials reset the arm between executions with nobody at the controls. With
``--confirm`` every reset first says where it goes and waits for the person at the robot: Enter
moves, ``q`` stops the run (what finished is kept, as for Ctrl-C). It needs a terminal to ask on.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

from teachfit.core.errors import NeedsAPerson, TeachfitError
from teachfit.core.geometry import Pose


class ResetDeclined(NeedsAPerson):
    """The person at the robot declined a reset (``q`` at the ``--confirm`` prompt)."""


def terminal_confirm(
    read: Callable[[str], str] = input, interactive: bool | None = None
) -> Callable[[Pose], None]:
    """A confirmation that prints where the reset goes and waits for Enter (``q``: stop).

    Raises :class:`TeachfitError` at once when there is no terminal to ask on
    (``interactive`` overrides the check)."""
    if not (sys.stdin.isatty() if interactive is None else interactive):
        raise TeachfitError(
            "--confirm asks before each reset on a terminal, and stdin is not one: run the "
            "command in a terminal, or leave --confirm out"
        )

    def confirm(goal: Pose) -> None:
        x, y, z = (1e3 * goal.pos).round(1)
        answer = read(f"reset to ({x}, {y}, {z}) mm: Enter moves the arm, q stops the run > ")
        if answer.strip().lower() in ("q", "quit", "n", "no"):
            raise ResetDeclined("reset declined at the --confirm prompt: the run stops here")

    return confirm
