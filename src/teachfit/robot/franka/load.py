"""The held part as the firmware's load: libfranka's ``setLoad`` (mass, centre of mass, inertia).

A Franka compensates gravity with its model of the arm, the Franka Hand and the *load* set with
``setLoad`` (an external load on the flange). Without it the held part's weight is left to the
torque loop's stiffness: on the peg twin the 33 g part (0.32 N) hung the TCP 0.16 mm low at
2000 N/m and 1.06 mm at 300 N/m. :func:`part_load` reads the part's mass and inertia from the
task's held part (the MJCF the cells are built from: MuJoCo's mass properties of its geoms);
:meth:`PartLoad.in_flange` turns them into ``setLoad``'s arguments for where the part sits on
the flange.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from teachfit.core.errors import TeachfitError
from teachfit.tasks.scene.mjcf import ContactParams, SceneXml

_BODY = "held_part"


@dataclass(frozen=True)
class PartLoad:
    """A held part's mass properties in its own frame (= the TCP frame: the part's tip, +z
    towards the flange): ``mass`` (kg), ``com`` (3,) (m), ``inertia`` (3, 3) (kg·m², about
    the centre of mass, in the TCP frame's axes)."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray

    def __post_init__(self) -> None:
        if not self.mass >= 0 or np.shape(self.com) != (3,) or np.shape(self.inertia) != (3, 3):
            raise TeachfitError(
                f"held part's load: mass {self.mass} kg must be >= 0, com (3,) m and "
                "inertia (3, 3) kg·m²"
            )

    def in_flange(self, f_t_tcp: np.ndarray) -> tuple[float, list[float], list[float]]:
        """``setLoad``'s arguments for the part at ``f_t_tcp`` (4, 4; the TCP in the flange
        frame F, ``F_T_EE @ EE_T_TCP``): mass (kg), ``F_x_Cload`` (3,) (m, flange frame) and
        ``I_load`` (9,) (kg·m², about the centre of mass in flange axes, column-major)."""
        rot, pos = f_t_tcp[:3, :3], f_t_tcp[:3, 3]
        com = rot @ np.asarray(self.com, dtype=float) + pos
        inertia = rot @ np.asarray(self.inertia, dtype=float) @ rot.T
        return float(self.mass), com.tolist(), inertia.reshape(-1, order="F").tolist()


def part_load(task: Any) -> PartLoad:
    """The mass properties of ``task``'s held part (its ``scene.add_held_part``), in the TCP
    frame, as MuJoCo computes them from the part's geoms."""
    scene = SceneXml(model=f"teachfit-load-{task.name}")
    body = ET.SubElement(scene.worldbody, "body", name=_BODY)
    task.scene.add_held_part(body, scene, task.scene.contact or ContactParams())
    model = mujoco.MjModel.from_xml_string(scene.to_string())
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, _BODY)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, model.body_iquat[b])
    axes = rot.reshape(3, 3)  # the principal axes in the body (= TCP) frame
    inertia = axes @ np.diag(model.body_inertia[b]) @ axes.T
    return PartLoad(float(model.body_mass[b]), model.body_ipos[b].copy(), inertia)
