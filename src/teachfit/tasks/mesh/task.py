"""``mesh``: a task built from a user's held and fixed part meshes (a TOML task file).

The task is one of Johannsmeier et al.'s kind (:class:`~teachfit.tasks.geometry.skill.SkillTask`):
the skill protocol's four starts above the hole and the taught hole pose, and for Ehlers et al.'s
search the ``"table1"`` starts (uniform in a disc of ``table1_radius`` halfway between the teacher's
start and the hole) and the blind teacher's starts ``demo_offset`` from the hole. Frames as
in :mod:`teachfit.tasks.base` (placement in :mod:`teachfit.tasks.mesh.cell`); the task's
``name`` is its file's path, so every command and worker process that gets the name loads the
same task (:func:`teachfit.tasks.registry.get_task`).
"""

from __future__ import annotations

import dataclasses
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from scipy.spatial import ConvexHull

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.core.teaching import TeacherHints
from teachfit.tasks.geometry.skill import SkillTask
from teachfit.tasks.mesh.cell import MeshCell, build_cell
from teachfit.tasks.mesh.spec import read_spec
from teachfit.tasks.params import doc_field
from teachfit.tasks.protocols.skill import SkillProtocol, SkillProtocolParams, in_frame
from teachfit.tasks.scene.builder import SceneBuilder, add_geom, add_mesh_geom, fixture_body
from teachfit.tasks.scene.mjcf import ContactParams, SceneXml

#: mass of the held part (kg), spread over its convex pieces by volume
HELD_MASS = 0.05
#: half extents (m) of the solid table under the fixed part
TABLE_HALF = (0.5, 0.5, 0.01)


@dataclass(frozen=True)
class MeshParams(SkillProtocolParams):
    """Protocol and success parameters of a :class:`MeshTask` (m, rad); the geometry is in
    the meshes."""

    task_name: ClassVar[str] = "mesh"

    success_depth: float = doc_field("insertion past the hole entry that counts (m)", 0.005, 0)
    demo_offset: float = doc_field(
        "distance of the blind teacher's start from the hole (m)", 0.004, above=0
    )
    table1_radius: float = doc_field(
        "radius of the disc of the table1 search starts (m)", 0.002, at_least=0
    )


class MeshScene(SceneBuilder):
    """The fixed part's and the held part's convex pieces as MuJoCo mesh geoms, on a solid
    table: a box :data:`TABLE_HALF` (m) whose top is world z = 0, where the fixed part stands,
    so a part through a through hole stops on it (the floor plane, which collides with nothing,
    only shows it)."""

    task: MeshTask

    @property
    def held_part_length(self) -> float:
        return self.task.cell.held_length

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        body = fixture_body(scene)
        for i, verts in enumerate(self.task.cell.fixture_pieces()):
            add_mesh_geom(body, scene, f"fixed_piece_{i}", verts, contact)
        hx, hy, hz = TABLE_HALF
        add_geom(body, "table", contact, "grid", type="box", size=[hx, hy, hz], pos=[0, 0, -hz])

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        pieces = self.task.cell.held_pieces_tcp()
        vols = np.array([ConvexHull(v).volume for v in pieces])
        for i, verts in enumerate(pieces):
            mass = HELD_MASS * vols[i] / vols.sum()
            name = f"held_piece_{i}"
            add_mesh_geom(body, scene, name, verts, contact, "tool", mass=f"{mass:.6g}")


class MeshProtocol(SkillProtocol):
    """Johannsmeier et al.'s ``"skill"`` starts and Ehlers et al.'s ``"table1"`` disc of starts."""

    task: MeshTask
    names = ("skill", "table1")

    def paper_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None
    ) -> list[Pose]:
        """``"skill"``: as :class:`SkillProtocol`. ``"table1"``: ``n`` starts on the surface
        uniform in a disc of ``table1_radius`` centred halfway between ``demo_start``
        (default: ``demo_offset`` along the hole's +x) and the hole, yaw within
        ``+-start_yaw`` of the hole's where rz is searched."""
        if protocol == "skill":
            return self.spread_starts(n, rng, None)
        task, p = self.task, self.task.params
        hole = task.hole2world
        if demo_start is None:
            demo_xy = np.array([p.demo_offset, 0.0])
        else:
            demo_xy = hole.inverse().compose(demo_start).pos[:2]
        centre = demo_xy / 2
        r = p.table1_radius * np.sqrt(rng.uniform(0.0, 1.0, n))
        a = rng.uniform(0.0, 2 * np.pi, n)
        yaw = rng.uniform(-p.start_yaw, p.start_yaw, n) if task.has_rz else np.zeros(n)
        return [
            in_frame(hole, centre + ri * np.array([np.cos(ai), np.sin(ai)]), 0.0, float(y))
            for ri, ai, y in zip(r, a, yaw, strict=True)
        ]


class MeshTask(SkillTask):
    """A peg-in-hole cell made of a user's two meshes; search in x, y (and rz)."""

    name = "mesh"
    description = "a user's held part into a user's fixed part, from STL/OBJ/PLY meshes"
    search_dims: ClassVar[tuple[str, ...]] = ("x", "y")
    params_type = MeshParams
    scene_type = MeshScene
    protocol_type = MeshProtocol
    params: MeshParams
    protocol: MeshProtocol

    def __init__(self, cell: MeshCell, params: MeshParams | None, name: str) -> None:
        self.cell = cell
        self.name = name  # type: ignore[misc]  # the file's path: loadable by every process
        self.search_dims = cell.spec.search_dims  # type: ignore[misc]  # the file's dims, per cell
        if cell.rz_period_deg > 0:
            self.rz_period = float(np.radians(cell.rz_period_deg))
        super().__init__(params)
        self._check_protocol()

    def _check_protocol(self) -> None:
        p, reach = self.params, self.detection_radius
        far = max(p.demo_offset, p.demo_offset / 2 + p.table1_radius, p.start_offset)
        if far > reach:
            raise TaskError(
                f"{self.cell.spec.path}: the starts reach {1e3 * far:.2f} mm from the hole, but "
                f"the held part stays over the top surface only within {1e3 * reach:.2f} mm "
                "(another opening or the edge is nearer); lower [protocol] demo_offset, "
                "table1_radius or start_offset"
            )

    @property
    def surface_z(self) -> float:
        return float(self.cell.hole2world.pos[2])

    @property
    def hole2world(self) -> Pose:
        return self.cell.hole2world

    @property
    def hole_depth(self) -> float:
        return self.cell.fit.hole_depth

    @property
    def stop_depth(self) -> float:
        """Depth below the entry (m) where the aligned part stops: the hole's bottom, the
        table under a through hole, or a shoulder of the held part."""
        return self.cell.fit.stop_depth

    @property
    def capture_radius(self) -> float:
        """Twice the clearance per side plus 0.1 mm of soft-contact give."""
        return 2 * self.cell.fit.clearance + 1e-4

    @property
    def detection_radius(self) -> float:
        return self.cell.fit.detection_radius

    @property
    def clearance(self) -> float:
        """The fit's clearance per side (m)."""
        return self.cell.fit.clearance

    @property
    def part_half_width(self) -> float:
        """The held part's half width along the task x (m): its largest ``|x|`` (TCP frame)
        over the length that enters the hole."""
        return self._body_extent(0)

    @property
    def part_half_depth(self) -> float:
        """The held part's half width across the task x (m): its largest ``|y|`` (TCP frame)
        over the length that enters the hole."""
        return self._body_extent(1)

    def _body_extent(self, axis: int) -> float:
        """The held part's largest ``|coordinate|`` along TCP ``axis`` (m) over the length
        that enters the hole."""
        verts = self.cell.held.vertices
        body = verts[verts[:, 2] <= verts[:, 2].min() + self.hole_depth]
        return float(np.abs(body[:, axis]).max())

    @property
    def tip_chamfer(self) -> float:
        """How much narrower along x (m) the held part's tip face is than its body (0: a sharp
        edge)."""
        verts = self.cell.held.vertices
        tip = verts[verts[:, 2] <= verts[:, 2].min() + 1e-6]
        return max(0.0, self.part_half_width - float(np.abs(tip[:, 0]).max()))

    @property
    def rz_tolerance(self) -> float:
        return self.cell.fit.rz_tolerance

    def teacher_hints(self) -> TeacherHints:
        """The blind teacher's search scaled to this cell (m, rad).

        The teacher's defaults suit the built-in cells (a 1-2 mm chamfered entry, a 5 mm
        belief, a 15 mm half-width sweep). A user's part may enter only within a few tenths
        of a millimetre and a degree or two of yaw, so its raster rows are one capture radius
        apart (a pass always crosses the entry), its slow wander stays below that, its belief
        and sweep scale with the start's distance from the hole (and stay over the top
        surface, inside the detection radius), and its yaw belief and wiggle stay inside the
        yaw tolerance.
        """
        p, pitch = self.params, self.capture_radius
        sigma = p.demo_offset / 8
        # a stiffer arm than the default 600 N/m, and the friction lag of the sliding part
        # (friction times the push plus its weight, over the stiffness) added to the sweep's
        # half-width: within the lag of a turn the part sticks instead of sliding
        stiffness, push = 2000.0, 6.0
        lag = p.friction * (push + HELD_MASS * 9.81) / stiffness
        room = self.detection_radius - p.demo_offset - 2 * pitch
        hints = TeacherHints(
            belief_sigma=sigma,
            spiral_pitch=pitch,
            sweep_halfwidth=max(pitch, min(4 * sigma + lag, room)),
            wander_amplitude=pitch / 4,
            arm_stiffness=stiffness,
            push_force=push,
            speed=0.008,
        )
        if self.has_rz:
            tol = self.rz_tolerance
            hints = dataclasses.replace(hints, rz_belief_sigma=tol / 6, rz_wiggle=tol / 3)
        return hints


def task_name_of(path: str | Path) -> str:
    """The task name of the file ``path``: relative to the working folder if inside it."""
    rel = os.path.relpath(Path(path).resolve())
    return rel if not rel.startswith("..") else str(Path(path).resolve())


#: cells built in this process, by (resolved task file, modification time)
_CELLS: dict[tuple[str, float], MeshCell] = {}


def _key(path: Path) -> tuple[str, float]:
    try:
        return str(path.resolve()), path.stat().st_mtime
    except OSError as exc:
        raise TaskError(f"cannot read task file {path}: {exc.strerror or exc}") from exc


def remember_cell(path: str | Path, cell: MeshCell) -> None:
    """Keep ``cell``, just built from the file ``path``, for :func:`load_mesh_task`."""
    _CELLS[_key(Path(path))] = cell


def _params_of(cell: MeshCell, overrides: dict[str, Any]) -> MeshParams:
    spec, s = cell.spec, cell.spec.scale
    values: dict[str, Any] = {"success_depth": cell.success_depth, "friction": spec.friction}
    for key, value in spec.protocol.items():
        if key.endswith("_deg"):
            values[key.removesuffix("_deg")] = float(np.radians(value))
        else:
            values[key] = value * s
    fields = {f.name for f in dataclasses.fields(MeshParams)}
    unknown = sorted(set(overrides) - fields)
    if unknown:
        raise TaskError(f"unknown mesh task parameter(s) {unknown}; known: {sorted(fields)}")
    values.update({k: float(v) for k, v in overrides.items()})
    return MeshParams(**values)


def load_mesh_task(path: str | Path, **overrides: float) -> MeshTask:
    """The :class:`MeshTask` of the task file ``path`` with parameter overrides (SI units).

    Cells are cached per process by the file's path and modification time.
    """
    p = Path(path)
    key = _key(p)
    if key not in _CELLS:  # an edited file has a new key and is re-read
        _CELLS[key] = build_cell(read_spec(p))
    cell = _CELLS[key]
    return MeshTask(cell, _params_of(cell, overrides), task_name_of(p))
