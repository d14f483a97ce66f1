"""MuJoCo scenes for synthetic capture: parts, marker carriers, textured markers, cameras.

A marker is drawn as a thin box mesh whose top face carries the marker image (with its white
quiet zone) through explicit texture coordinates; the top face lies in the marker's z = 0
plane, so the marker frame of the scene is exactly the ``marker2part`` of the marker file.
Cameras are placed by look-at and converted between conventions: OpenCV's camera frame
(x right, y down, z forward) is MuJoCo's (x right, y up, looking along -z) turned by pi about x.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import cv2
import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from teachfit.core.geometry import rotation_to_wxyz

__all__ = ["Carrier", "Quad", "camera_K", "look_at", "scene_xml"]

CV2MJ = np.diag([1.0, -1.0, -1.0])
"""Rotation from an OpenCV camera frame to the MuJoCo camera frame (pi about x)."""


@dataclass(frozen=True)
class Carrier:
    """A box (visual only) rigidly fixed to a part: centre (3,) and half sizes (3,) in m, in
    the part frame, with an RGBA colour."""

    center: tuple[float, float, float]
    half: tuple[float, float, float]
    rgba: tuple[float, float, float, float] = (0.92, 0.92, 0.9, 1.0)


@dataclass(frozen=True, eq=False)
class Quad:
    """A textured rectangle: ``size`` (width, height) in m (a marker's quiet zone included),
    pose ``quad2part`` (4, 4), and a grey or RGB uint8 ``image`` mapped onto it (image up =
    quad +y, image right = quad +x)."""

    name: str
    size: tuple[float, float]
    quad2part: np.ndarray
    image: np.ndarray


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray | None = None) -> np.ndarray:
    """(4, 4) ``cam2world`` of an OpenCV camera at ``eye`` (m) whose optical axis passes
    through ``target``; image rows run "down" with respect to ``up`` (default world z)."""
    up = np.array([0.0, 0.0, 1.0]) if up is None else np.asarray(up, dtype=float)
    z = np.asarray(target, dtype=float) - np.asarray(eye, dtype=float)
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = eye
    return T


def camera_K(width: int, height: int, fovy_deg: float) -> np.ndarray:
    """(3, 3) intrinsics of a MuJoCo camera: ``f = (H / 2) / tan(fovy / 2)`` in px for both
    axes; principal point at the image centre in OpenCV's pixel-centre convention, i.e.
    ``((W - 1) / 2, (H - 1) / 2)`` (OpenGL puts the centre at W / 2 in pixel-edge units)."""
    f = (height / 2.0) / np.tan(np.radians(fovy_deg) / 2.0)
    return np.array([[f, 0.0, (width - 1) / 2.0], [0.0, f, (height - 1) / 2.0], [0.0, 0.0, 1.0]])


def _floats(values: np.ndarray | Sequence[float]) -> str:
    return " ".join(f"{v:.9g}" for v in np.asarray(values, dtype=float).reshape(-1))


def _pose_attrs(T: np.ndarray) -> str:
    q = rotation_to_wxyz(Rotation.from_matrix(T[:3, :3]), canonical=False)
    return f'pos="{_floats(T[:3, 3])}" quat="{_floats(q)}"'


def _quad_mesh(name: str, size: tuple[float, float], depth: float = 4e-4) -> str:
    a, b = size[0] / 2.0, size[1] / 2.0
    top = [[-a, -b, 0], [a, -b, 0], [a, b, 0], [-a, b, 0]]
    verts = np.array(top + [[x, y, -depth] for x, y, _ in top])
    # top face: u along +x, v along -y (texture rows run down the image); the bottom copies it
    uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]] * 2, dtype=float)
    faces = [0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6, 0, 4, 5, 0, 5, 1, 1, 5, 6, 1, 6, 2]
    faces += [2, 6, 7, 2, 7, 3, 3, 7, 4, 3, 4, 0]
    return (
        f'<mesh name="{name}" vertex="{_floats(verts)}" texcoord="{_floats(uv)}" '
        f'face="{" ".join(map(str, faces))}"/>'
    )


def _trimesh_mesh(name: str, mesh: trimesh.Trimesh) -> str:
    return (
        f'<mesh name="{name}" vertex="{_floats(mesh.vertices)}" '
        f'face="{" ".join(map(str, np.asarray(mesh.faces).reshape(-1)))}"/>'
    )


def scene_xml(
    parts: Mapping[str, tuple[trimesh.Trimesh | None, tuple[float, float, float, float]]],
    carriers: Mapping[str, Sequence[Carrier]],
    quads: Mapping[str, Sequence[Quad]],
    cameras: Sequence[tuple[str, np.ndarray, float]],
    *,
    offscreen: tuple[int, int] = (1920, 1080),
) -> tuple[str, dict[str, bytes]]:
    """MJCF text and its in-memory assets (PNG textures) for a capture scene.

    Parameters
    ----------
    parts : name -> (mesh in the part frame (m) or None, RGBA)
        Each part is a mocap body named after it; set its pose with ``data.mocap_pos/quat``.
    carriers, quads : name -> boxes / textured quads fixed to that part
    cameras : sequence of (name, cam2world (4, 4) in OpenCV convention, fovy in degrees)
    offscreen : (width, height) of the largest image that will be rendered (px)
    """
    assets: dict[str, bytes] = {}
    asset_xml, body_xml = [], []
    for part, (mesh, rgba) in parts.items():
        geoms = []
        if mesh is not None:
            asset_xml.append(_trimesh_mesh(f"{part}_mesh", mesh))
            geoms.append(
                f'<geom type="mesh" mesh="{part}_mesh" rgba="{_floats(rgba)}" '
                'contype="0" conaffinity="0"/>'
            )
        geoms += [
            _carrier_geom(f"{part}_carrier{j}", b) for j, b in enumerate(carriers.get(part, ()))
        ]
        for quad in quads.get(part, ()):
            geoms.append(_add_quad(quad, asset_xml, assets))
        body_xml.append(f'<body name="{part}" mocap="true">' + "".join(geoms) + "</body>")
    cam_xml = [_camera(name, cam2world, fovy) for name, cam2world, fovy in cameras]
    return _SCENE.format(
        w=offscreen[0],
        h=offscreen[1],
        assets="".join(asset_xml),
        cameras="".join(cam_xml),
        bodies="".join(body_xml),
    ), assets


def _carrier_geom(name: str, box: Carrier) -> str:
    return (
        f'<geom name="{name}" type="box" pos="{_floats(box.center)}" '
        f'size="{_floats(box.half)}" rgba="{_floats(box.rgba)}" '
        'contype="0" conaffinity="0"/>'
    )


def _add_quad(quad: Quad, asset_xml: list[str], assets: dict[str, bytes]) -> str:
    """Add ``quad``'s PNG texture to ``assets`` and its texture, material and mesh to
    ``asset_xml``; return its geom."""
    img = quad.image if quad.image.ndim == 3 else cv2.cvtColor(quad.image, cv2.COLOR_GRAY2BGR)
    ok, png = cv2.imencode(".png", img)
    assets[f"{quad.name}.png"] = png.tobytes()
    asset_xml += [
        f'<texture name="{quad.name}_tex" type="2d" file="{quad.name}.png"/>',
        f'<material name="{quad.name}_mat" texture="{quad.name}_tex" specular="0" '
        'shininess="0" reflectance="0"/>',
        _quad_mesh(f"{quad.name}_mesh", quad.size),
    ]
    return (
        f'<geom type="mesh" mesh="{quad.name}_mesh" material="{quad.name}_mat" '
        f'{_pose_attrs(quad.quad2part)} contype="0" conaffinity="0"/>'
    )


def _camera(name: str, cam2world: np.ndarray, fovy: float) -> str:
    """A MuJoCo camera of an OpenCV ``cam2world`` (4, 4) with a vertical field ``fovy`` (deg)."""
    T = np.array(cam2world, dtype=float)
    T[:3, :3] = T[:3, :3] @ CV2MJ
    return f'<camera name="{name}" fovy="{fovy:.9g}" {_pose_attrs(T)}/>'


_SCENE = """<mujoco model="capture">
  <compiler inertiafromgeom="false"/>
  <visual>
    <global offwidth="{w}" offheight="{h}"/>
    <quality shadowsize="0" offsamples="4"/>
    <headlight ambient="0.35 0.35 0.35" diffuse="0.25 0.25 0.25" specular="0 0 0"/>
  </visual>
  <asset>{assets}</asset>
  <worldbody>
    <light name="key" pos="0.3 -0.4 1.2" dir="-0.25 0.33 -1" diffuse="0.55 0.55 0.55"
           specular="0 0 0" castshadow="false"/>
    <geom type="plane" size="1 1 0.01" pos="0 0 -0.03" rgba="0.45 0.47 0.5 1"
          contype="0" conaffinity="0"/>
    {cameras}
    {bodies}
  </worldbody>
</mujoco>"""
"""The capture scene's MJCF: offscreen size ``w`` x ``h`` px, then the assets, cameras and
part bodies as XML text."""
