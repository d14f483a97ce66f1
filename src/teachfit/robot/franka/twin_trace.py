"""The twin's contact trace: the simulator's own contact force beside the firmware's estimate.

A client sees the cell only through libfranka's filtered estimate ``O_F_ext_hat_K``. To tell a
real contact force from the estimate's lag, its filters or its model errors, ``teachfit robot
twin --trace FILE`` writes one CSV row per 1 kHz tick in which the held part (or the hand
holding it) touches anything:

=========================  =====================================================================
column                     meaning (world axes; the robot's base is only translated)
=========================  =====================================================================
``t``                      simulation time (s)
``fx, fy, fz``             the summed contact force the part exerts on the cell (N), libfranka's
                           sign (pressing down reads negative z), from ``mj_contactForce``
``est_fx, est_fy, est_fz`` the force of ``O_F_ext_hat_K`` served at that tick (N), at the EE
``x, y, z``                the part's tip (the TCP, m)
``vx, vy, vz``             the tip's velocity (m/s)
``contacts``               how many contacts the part and hand have
``deepest``                the lowest contact point's height (m): the hole's bottom shows here
=========================  =====================================================================

Rows go to a temporary file beside ``FILE``, which becomes ``FILE`` when the twin stops (Ctrl-C
or SIGTERM; :func:`teachfit.core.atomic.atomic_path`); a trace holds only the contact ticks (a
peg skill's execution: about 800 rows, 0.1 MB).
"""

from __future__ import annotations

import contextlib
import csv
from pathlib import Path
from typing import IO, Any

import mujoco
import numpy as np

from teachfit.core.atomic import atomic_path

COLUMNS = (
    "t",
    "fx",
    "fy",
    "fz",
    "est_fx",
    "est_fy",
    "est_fz",
    "x",
    "y",
    "z",
    "vx",
    "vy",
    "vz",
    "contacts",
    "deepest",
)


def subtree_geoms(model: mujoco.MjModel, root: int) -> frozenset[int]:
    """The geoms of body ``root`` and of every body below it (the hand and the part it holds)."""
    below = {root}
    for body in range(root + 1, model.nbody):  # MuJoCo numbers a parent before its children
        if int(model.body_parentid[body]) in below:
            below.add(body)
    return frozenset(g for g in range(model.ngeom) if int(model.geom_bodyid[g]) in below)


def part_contact_force(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: frozenset[int]
) -> tuple[np.ndarray, int, float]:
    """The force (3,) (N, world) that ``geoms`` exert on everything else they touch, the number
    of such contacts and the lowest contact's height (m; ``nan`` without contact).

    ``mj_contactForce`` gives each contact's force in its frame (normal first), as the force
    of ``geom1`` on ``geom2``; a part that is ``geom2`` exerts its opposite."""
    total, force6 = np.zeros(3), np.zeros(6)
    count, deepest = 0, np.inf
    for i in range(data.ncon):
        con = data.contact[i]
        first, second = con.geom1 in geoms, con.geom2 in geoms
        if first == second:
            continue
        mujoco.mj_contactForce(model, data, i, force6)
        on_second = con.frame.reshape(3, 3).T @ force6[:3]
        total += on_second if first else -on_second
        count += 1
        deepest = min(deepest, float(con.pos[2]))
    return total, count, deepest if count else float("nan")


class ContactTrace:
    """Writes the contact ticks of a :class:`~teachfit.robot.franka.twin_cell.TwinSimulator`
    to ``path`` (CSV, :data:`COLUMNS`); a context manager that closes the file."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._commit = contextlib.ExitStack()
        tmp = self._commit.enter_context(atomic_path(self.path, "contact trace"))
        self._file: IO[str] = open(tmp, "x", newline="", encoding="utf-8")  # noqa: SIM115
        self._rows = csv.writer(self._file)
        self._rows.writerow(COLUMNS)
        self._geoms: frozenset[int] | None = None
        self._vel = np.zeros(6)

    def record(self, sim: Any) -> None:
        """One row for the tick ``sim`` has just stepped, if the part touches anything."""
        model, data = sim.model, sim.data
        if self._geoms is None:
            self._geoms = subtree_geoms(model, sim.hand_body)
        force, count, deepest = part_contact_force(model, data, self._geoms)
        if not count:
            return
        est = sim.external_wrench(np.eye(4))
        site = sim.tcp_site
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_SITE, site, self._vel, 0)
        row = [data.time, *force, *est[:3], *data.site_xpos[site], *self._vel[3:], count, deepest]
        self._rows.writerow([f"{v:.6g}" for v in row])

    def close(self) -> None:
        """Close the file and put it at ``path`` (also when the twin stops on an interrupt)."""
        if not self._file.closed:
            self._file.close()
            self._commit.close()

    def __enter__(self) -> ContactTrace:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
