"""Watching the grasp between trials: a part lost from the fingers stops the run.

A real arm that runs trials on its own can drop the part (a jam that pulls it out of the
fingers, a reset that catches it): every following trial would then "search" with empty
fingers and the learner would be charged for it. :class:`GraspWatch` reads the Franka Hand over
libfranka's gripper protocol (``pylibfranka.Gripper``: ``width`` in m and ``is_grasped``) at
each reset. The first reading is the reference: the part held when the run began. A later
reading that is no longer grasped, or whose width moved by more than ``tolerance`` from the
reference (the fingers closed on nothing, or on the part at another place), raises
:class:`PartLost`, which stops the run with its finished trials kept.

A hand that holds nothing at the first reading (e.g. a protocol simulator without a part)
cannot tell a lost part from one never held: the watch then turns itself off and says so in
:attr:`GraspWatch.note`.
"""

from __future__ import annotations

from typing import Any

from teachfit.core.errors import NeedsAPerson


class PartLost(NeedsAPerson):
    """The gripper no longer holds the part as it did when the run began."""


class GraspWatch:
    """The hand's grasp, read at each reset (see the module docstring).

    Parameters
    ----------
    gripper : a connected ``pylibfranka.Gripper`` (anything with ``read_once()`` returning
        ``width`` (m) and ``is_grasped``).
    tolerance : float
        Width change (m) from the reference that counts as a lost part.
    """

    def __init__(self, gripper: Any, tolerance: float = 0.002) -> None:
        #: the connected hand (one connection per hand: commands go through it too)
        self.gripper = gripper
        self.tolerance = tolerance
        self.reference: float | None = None
        self.active = True
        self.note = ""

    def check(self) -> None:
        """Read the hand; the first reading becomes the reference; raise :class:`PartLost`
        when the part is gone."""
        if not self.active:
            return
        state = self.gripper.read_once()
        width, held = float(state.width), bool(state.is_grasped)
        if self.reference is None:
            if not held:
                self.active = False
                self.note = (
                    f"the gripper holds nothing at the start (width {width * 1e3:.1f} mm, not "
                    "grasped): a lost part cannot be told from none, the grasp is not watched"
                )
                return
            self.reference = width
            return
        if not held or abs(width - self.reference) > self.tolerance:
            was = self.reference * 1e3
            raise PartLost(
                f"the part is no longer in the gripper (width {width * 1e3:.1f} mm, was "
                f"{was:.1f} mm, {'grasped' if held else 'not grasped'}): put it back in the "
                "fingers, then continue with --resume"
            )


#: libfranka's gripper port (fixed by the protocol)
GRIPPER_PORT = 1338


def connect_gripper(pf: Any, host: str, timeout: float = 1.0) -> tuple[GraspWatch | None, str]:
    """A :class:`GraspWatch` on the hand at ``host``, or ``None`` and why not: no hand answers
    on the gripper port, or its connect does not finish within ``timeout`` s (a hand serves
    one client: another program holding it makes libfranka's connect wait for ever; the
    waiting thread is then left behind, a daemon)."""
    import socket
    import threading

    try:
        socket.create_connection((host, GRIPPER_PORT), timeout=timeout).close()
    except OSError as exc:
        return (
            None,
            f"no gripper answers at {host}:{GRIPPER_PORT} ({exc}): the grasp is not watched",
        )
    got: list[Any] = []

    def connect() -> None:
        try:
            got.append(pf.Gripper(host))
        except (RuntimeError, pf.NetworkException) as exc:
            got.append(exc)

    worker = threading.Thread(target=connect, name="gripper-connect", daemon=True)
    worker.start()
    worker.join(timeout)
    if not got or isinstance(got[0], Exception):
        why = (
            f"({got[0]})" if got else f"(no answer within {timeout:g} s: another client holds it?)"
        )
        return None, f"the gripper at {host} did not connect {why}: the grasp is not watched"
    return GraspWatch(got[0]), ""
