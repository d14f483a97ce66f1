"""Small builders for MuJoCo MJCF scenes made of convex pieces, and the contact model.

MuJoCo collides every mesh as its convex hull, so a part with a hole is assembled from many
convex pieces. The builders here return vertex arrays of such pieces; :class:`SceneXml` collects
assets, bodies and geoms into an MJCF document (``xml.etree`` keeps the output valid XML);
:class:`ContactParams` and :func:`contact_attrs` give every geom the same contact model.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ContactParams:
    """Contact model shared by the fixture and the held part.

    ``solref``/``solimp`` make contacts stiff enough for sub-millimetre clearances at a 1 ms
    step (MuJoCo needs ``solref[0] >= 2 * timestep``). ``friction`` is the sliding coefficient.

    The contact is *progressive*, as machined surfaces are (asperities first): its impedance
    rises from 0.1 at first touch to 0.99 over 0.1 mm. With full impedance from the first
    micrometre (``solimp = (0.95, 0.99, 0.0005)``, the former default) a part pressed with 6 N
    and slid *hops*: friction at each landing stops the contact points within one tick, tips
    the part and throws it up again, and the wrist signal is a train of impacts (std 1.6 N,
    white at 100 Hz). It is not the cone type, ``impratio``, the solver or the mesh pieces.
    The 0.1 mm ramp keeps the tasks' blocking behaviour (a part 1 mm off rests on the rim,
    sinking < 0.2 mm); a wider ramp (0.5 mm) lets a rotated key squeeze into its slot. The FR3
    (a heavier, joint-friction-loaded arm) uses a softer ramp of its own
    (:class:`teachfit.robot.fr3.FR3Params`).
    """

    friction: float = 0.3
    solref: tuple[float, float] = (0.002, 1.0)
    solimp: tuple[float, float, float] = (0.1, 0.99, 0.0001)
    margin: float = 0.0


def fmt(values: np.ndarray | list[float] | tuple[float, ...] | float) -> str:
    """Format numbers for an MJCF attribute with enough digits for sub-millimetre geometry."""
    arr = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
    return " ".join(f"{v:.9g}" for v in arr)


def ring_sector(
    r_inner: float,
    r_outer: float,
    z_bottom: float,
    z_top: float,
    n_sectors: int,
    chamfer: float = 0.0,
    chamfer_depth: float | None = None,
) -> np.ndarray:
    """Vertices of one convex sector of a ring (annulus) centred on the z-axis, sector at angle 0.

    The inner boundary is a chord placed so that its *closest* point is at ``r_inner``: the
    polygonal hole circumscribes the circle of radius ``r_inner`` and never makes the hole
    narrower than asked. An optional conical chamfer widens the hole at the top: from radius
    ``r_inner`` at ``z_top - chamfer_depth`` to ``r_inner + chamfer`` at ``z_top``.

    Parameters
    ----------
    r_inner, r_outer : float
        Inner (hole) radius and outer radius, m. The outer chord lies *inside* ``r_outer``.
    z_bottom, z_top : float
        Bottom and top of the ring, m.
    n_sectors : int
        Number of sectors in the full ring (each spans ``2 pi / n_sectors``).
    chamfer, chamfer_depth : float
        Radial width and depth of the top chamfer, m (depth defaults to the width: 45 degrees).

    Returns
    -------
    vertices : ndarray, shape (n, 3)
        Vertices of the sector; their convex hull is the piece.
    """
    half = np.pi / n_sectors
    scale = 1.0 / np.cos(half)  # chord endpoints so that the chord's midpoint sits at r_inner
    depth = chamfer if chamfer_depth is None else chamfer_depth
    verts = []
    for ang in (-half, half):
        c, s = np.cos(ang), np.sin(ang)
        pts = [
            (r_inner * scale, z_bottom),
            (r_inner * scale, z_top - depth if chamfer > 0 else z_top),
            ((r_inner + chamfer) * scale, z_top),
            (r_outer, z_top),
            (r_outer, z_bottom),
        ]
        for r, z in pts:
            verts.append((r * c, r * s, z))
    return np.unique(np.round(np.asarray(verts), 12), axis=0)


def chamfered_cylinder(
    radius: float, length: float, chamfer: float, n_sides: int = 32
) -> np.ndarray:
    """Vertices of a convex cylinder along +z from ``z=0`` to ``z=length``, chamfered at ``z=0``.

    The vertices lie *on* the circle of ``radius``, so the polygonal peg is never wider than
    asked (its flats are ``radius * (1 - cos(pi / n_sides))`` inside it). The chamfer shrinks
    the tip to ``radius - chamfer`` over a height of ``chamfer`` (45 degrees).
    """
    ang = np.linspace(0.0, 2 * np.pi, n_sides, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    tip_r = radius - chamfer
    layers = (
        [(tip_r, 0.0), (radius, chamfer), (radius, length)]
        if chamfer > 0
        else [
            (radius, 0.0),
            (radius, length),
        ]
    )
    verts = [np.column_stack([ring * r, np.full(n_sides, z)]) for r, z in layers]
    return np.concatenate(verts, axis=0)


@dataclass
class SceneXml:
    """An MJCF document under construction (model name, options, assets, world body)."""

    model: str
    timestep: float = 0.001

    def __post_init__(self) -> None:
        self.root = ET.Element("mujoco", model=self.model)
        ET.SubElement(self.root, "compiler", angle="radian", autolimits="true")
        self.option = ET.SubElement(
            self.root,
            "option",
            timestep=fmt(self.timestep),
            integrator="implicitfast",
            cone="elliptic",
            impratio="1",
        )
        self.visual = ET.SubElement(self.root, "visual")
        ET.SubElement(self.visual, "global", offwidth="1920", offheight="1080")
        ET.SubElement(self.visual, "quality", shadowsize="2048")
        self.asset = ET.SubElement(self.root, "asset")
        ET.SubElement(
            self.asset,
            "texture",
            name="grid",
            type="2d",
            builtin="checker",
            rgb1=".85 .87 .9",
            rgb2=".75 .78 .82",
            width="256",
            height="256",
        )
        ET.SubElement(
            self.asset,
            "material",
            name="grid",
            texture="grid",
            texrepeat="8 8",
            reflectance=".05",
        )
        ET.SubElement(self.asset, "material", name="metal", rgba=".62 .64 .68 1", specular=".6")
        ET.SubElement(self.asset, "material", name="tool", rgba=".85 .45 .15 1", specular=".4")
        ET.SubElement(self.asset, "material", name="dark", rgba=".25 .27 .3 1")
        self.default = ET.SubElement(self.root, "default")
        self.worldbody = ET.SubElement(self.root, "worldbody")
        self.sensor = ET.SubElement(self.root, "sensor")

    def add_mesh(self, name: str, vertices: np.ndarray) -> None:
        """Add a mesh asset given by vertices; MuJoCo builds (and collides) its convex hull."""
        ET.SubElement(self.asset, "mesh", name=name, vertex=fmt(vertices))

    def to_string(self) -> str:
        ET.indent(self.root)
        return ET.tostring(self.root, encoding="unicode")


def contact_attrs(contact: ContactParams) -> dict[str, str]:
    """MJCF geom attributes of a contact model: friction (sliding, torsional, rolling), solref,
    solimp, margin, and ``condim=4`` (torsional friction, so a pressed part cannot spin freely)."""
    return {
        "friction": fmt([contact.friction, 0.005, 0.0001]),
        "solref": fmt(contact.solref),
        "solimp": fmt(contact.solimp),
        "margin": fmt(contact.margin),
        "condim": "4",
    }
