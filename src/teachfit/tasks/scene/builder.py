"""What a task's scene builder provides, and the MJCF steps the builders share.

A :class:`SceneBuilder` turns a task's geometry (:class:`~teachfit.tasks.base.Task`) into MuJoCo
bodies and geoms: the fixed parts with the hole (:meth:`SceneBuilder.add_fixture`, world frame,
z up) and the held part (:meth:`SceneBuilder.add_held_part`, in the TCP frame, the part's axis
+z). The robot (:func:`teachfit.robot.floating.build_scene`) adds the tool, the wrist sensor
:attr:`SceneBuilder.held_part_length` above the TCP, lights and the floor.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from teachfit.tasks.scene.mjcf import ContactParams, SceneXml, contact_attrs, fmt

if TYPE_CHECKING:
    from teachfit.tasks.base import Task


@dataclass(frozen=True)
class SceneBuilder(ABC):
    """MuJoCo bodies of one task's cell; ``task`` gives the geometry (lengths in metres)."""

    task: Task

    @property
    def contact(self) -> ContactParams:
        """Contact model of this cell; a ``friction`` task parameter sets the coefficient."""
        friction = getattr(self.task.params, "friction", None)
        return ContactParams() if friction is None else ContactParams(friction=float(friction))

    @abstractmethod
    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        """Add the fixed parts (with the hole) to ``scene.worldbody``."""

    @abstractmethod
    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        """Add the held part's geoms to ``body`` whose frame is the TCP (part axis along +z)."""

    @property
    @abstractmethod
    def held_part_length(self) -> float:
        """Height of the held part above the TCP (m): where the wrist F/T sensor sits."""


def fixture_body(scene: SceneXml, yaw: float = 0.0) -> ET.Element:
    """The static body ``fixture`` in the world, turned by ``yaw`` (rad) about world z."""
    kw = {"euler": fmt([0.0, 0.0, yaw])} if yaw else {}
    return ET.SubElement(scene.worldbody, "body", {}, name="fixture", **kw)


def add_geom(
    parent: ET.Element,
    name: str,
    contact: ContactParams,
    material: str = "metal",
    **attrs: Any,
) -> ET.Element:
    """A geom ``name`` under ``parent`` with the contact model; ``attrs`` are MJCF attributes
    (numbers and arrays are formatted with :func:`~teachfit.tasks.scene.mjcf.fmt`)."""
    values = {k: v if isinstance(v, str) else fmt(v) for k, v in attrs.items()}
    return ET.SubElement(
        parent, "geom", {}, name=name, material=material, **values, **contact_attrs(contact)
    )


def add_mesh_geom(
    parent: ET.Element,
    scene: SceneXml,
    name: str,
    vertices: np.ndarray,
    contact: ContactParams,
    material: str = "metal",
    **attrs: Any,
) -> ET.Element:
    """A mesh asset ``name`` (convex hull of ``vertices``, m) and a geom of it under ``parent``."""
    scene.add_mesh(name, vertices)
    return add_geom(parent, name, contact, material, type="mesh", mesh=name, **attrs)


def add_ring(
    parent: ET.Element,
    scene: SceneXml,
    mesh: str,
    sector: np.ndarray,
    n_sectors: int,
    prefix: str,
    contact: ContactParams,
) -> None:
    """A ring of ``n_sectors`` copies of the convex ``sector`` (vertices at angle 0, m) turned
    about z in equal steps: geoms ``{prefix}{i}`` sharing the mesh asset ``mesh``."""
    scene.add_mesh(mesh, sector)
    for i in range(n_sectors):
        euler = [0.0, 0.0, 2 * np.pi * i / n_sectors]
        add_geom(parent, f"{prefix}{i}", contact, type="mesh", mesh=mesh, euler=euler)
