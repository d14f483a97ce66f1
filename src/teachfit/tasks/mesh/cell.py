"""A cell built from a mesh task file: placed meshes, convex pieces, hole fit and fidelity.

Placement. The fixed part is turned so that its hole frame's z (opposite the insertion axis)
is world z and stands on the table (its lowest point at world z = 0), the hole entry centre
on the world z axis: ``hole2world`` is ``(0, 0, z_entry)``, unturned, as for the built-in
tasks. The table (world z = 0) is solid: a part stops on it under a through hole. The held
part hangs in the tool (TCP) frame by its grasp: the TCP at the tip, the part's axis +z.
Lengths in metres; the file's lengths are scaled by its units.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.tasks.mesh.decompose import CACHE_DIR, CoacdSettings, Decomposition, decompose
from teachfit.tasks.mesh.fidelity import Fidelity, decomposition_fidelity, require_fidelity
from teachfit.tasks.mesh.holes import best_opening
from teachfit.tasks.mesh.loading import load_parts
from teachfit.tasks.mesh.progress import report
from teachfit.tasks.mesh.sections import HoleFit, check_entry, fit_of, reach_of
from teachfit.tasks.mesh.spec import MeshTaskSpec

#: share of the stop depth a task file without ``success_depth`` takes as its success depth
DEFAULT_SUCCESS_SHARE = 0.6


@dataclass(frozen=True, eq=False)
class MeshCell:
    """Everything a :class:`~teachfit.tasks.mesh.task.MeshTask` derives from its file.

    ``held`` is in the TCP frame, ``fixed`` in the world (m); ``part2tcp`` and
    ``fixed2world`` (4, 4) place the meshes' own frames; ``held_pieces``/``fixed_pieces`` are
    the convex decompositions in the meshes' own frames.
    """

    spec: MeshTaskSpec
    held: trimesh.Trimesh
    fixed: trimesh.Trimesh
    part2tcp: np.ndarray
    fixed2world: np.ndarray
    hole2world: Pose
    success_depth: float
    fit: HoleFit
    held_pieces: Decomposition
    fixed_pieces: Decomposition
    fidelity: Fidelity

    @property
    def held_length(self) -> float:
        """Height of the held part above the TCP (m)."""
        return float(self.held.vertices[:, 2].max())

    def fixture_pieces(self) -> list[np.ndarray]:
        """The fixed part's convex pieces' vertices in the world (m)."""
        return self.fixed_pieces.moved(self.fixed2world)

    @property
    def rz_period_deg(self) -> float:
        """The held part's yaw symmetry in the hole (deg; 0: any yaw fits): the file's
        ``rz_period_deg`` if it sets one, else the one inferred from the cross-sections
        (:func:`~teachfit.tasks.mesh.sections.rz_period_of`)."""
        if self.spec.rz_period_deg is not None:
            return float(self.spec.rz_period_deg)
        return float(np.degrees(self.fit.rz_period))

    def held_pieces_tcp(self) -> list[np.ndarray]:
        """The held part's convex pieces' vertices in the TCP frame (m)."""
        return self.held_pieces.moved(self.part2tcp)


def unit(v: np.ndarray, what: str, where: str) -> np.ndarray:
    """``v`` normalised; a zero vector is an error naming ``what``."""
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        raise TaskError(f"{where}: {what} must not be zero")
    return np.asarray(v, dtype=float) / n


def hole_frame(
    pos: np.ndarray, axis: np.ndarray, x_hint: np.ndarray | None, where: str
) -> np.ndarray:
    """(4, 4) hole frame in the fixed mesh's frame: origin ``pos`` (m), z opposite the
    insertion ``axis``, x along ``x_hint`` (default the mesh's x, else its y) made normal to z."""
    z = -unit(axis, "insertion_axis", where)
    x = np.array([1.0, 0.0, 0.0]) if x_hint is None else unit(x_hint, "hole_x_axis", where)
    x = x - z * float(x @ z)
    if np.linalg.norm(x) < 1e-6:
        if x_hint is not None:
            raise TaskError(f"{where}: hole_x_axis must not be parallel to insertion_axis")
        x = np.array([0.0, 1.0, 0.0]) - z * z[1]
    x = x / np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = pos
    return T


def grasp_of(spec: MeshTaskSpec, held: trimesh.Trimesh) -> np.ndarray:
    """(4, 4) pose of the held mesh's frame in the TCP frame: the file's grasp (scaled), or
    by default the TCP at the centre of the mesh's lowest face, axes unturned."""
    T = np.eye(4)
    if spec.grasp_pos is None:
        lo, hi = held.bounds
        T[:3, 3] = [-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]]
        return T
    T[:3, :3] = Rotation.from_euler("xyz", spec.grasp_rpy_deg, degrees=True).as_matrix()
    T[:3, 3] = np.asarray(spec.grasp_pos) * spec.scale
    return T


def _moved(mesh: trimesh.Trimesh, T: np.ndarray) -> trimesh.Trimesh:
    out = mesh.copy()
    out.apply_transform(T)
    return out


def _hole(
    spec: MeshTaskSpec, fixed: trimesh.Trimesh, held: trimesh.Trimesh
) -> tuple[np.ndarray, trimesh.Trimesh, float, tuple[float, float]]:
    """The hole frame in the fixed mesh (given or inferred), the fixed mesh in that frame, the
    success depth and the hole and stop depths (m). The success depth defaults to
    :data:`DEFAULT_SUCCESS_SHARE` of where the aligned part stops (the hole's bottom, the table
    under a through hole, or a shoulder of the part), at most of the held part's length."""
    where = str(spec.path)
    axis = np.asarray(spec.insertion_axis)
    x_hint = None if spec.hole_x_axis is None else np.asarray(spec.hole_x_axis)
    if spec.hole_pos is None:
        opening = best_opening(fixed, held, unit(axis, "insertion_axis", where))
        pos = opening.pos
        x_hint = opening.x_axis if x_hint is None else x_hint
    else:
        pos = np.asarray(spec.hole_pos) * spec.scale
    hole2fixed = hole_frame(pos, axis, x_hint, where)
    fixed_h = _moved(fixed, np.linalg.inv(hole2fixed))
    check_entry(fixed_h, where)
    reach = reach_of(fixed_h, held)
    if spec.success_depth is None:
        depth = DEFAULT_SUCCESS_SHARE * min(reach[1], held.vertices[:, 2].max())
    else:
        depth = spec.success_depth * spec.scale
    if depth <= 0:
        raise TaskError(f"{where}: success_depth must be > 0")
    return hole2fixed, fixed_h, float(depth), reach


def build_cell(
    spec: MeshTaskSpec, parts: tuple[trimesh.Trimesh, trimesh.Trimesh] | None = None
) -> MeshCell:
    """Load, check, place and decompose the parts of ``spec``; see the module docstring.

    ``parts``: the held and fixed meshes as :func:`load_parts` gave them for ``spec``
    (default: loaded here).
    """
    where = str(spec.path)
    stage = f"building the cell of {spec.path.name}"
    report(stage, 0, 4)
    if parts is None:
        parts = load_parts(spec.held_mesh, spec.fixed_mesh, spec.units, spec.path)
    held_raw, fixed_raw = parts
    report(stage, 1, 4)
    part2tcp = grasp_of(spec, held_raw)
    held = _moved(held_raw, part2tcp)
    if held.vertices[:, 2].min() < -1e-6:
        raise TaskError(f"{where}: the grasp puts part of the held mesh below the TCP (tip)")
    hole2fixed, fixed_h, depth, reach = _hole(spec, fixed_raw, held)
    fit = fit_of(fixed_h, held, depth, where, reach)
    z_entry = -float(fixed_h.vertices[:, 2].min())
    hole2world = Pose(np.array([0.0, 0.0, z_entry]))
    fixed2world = hole2world.matrix @ np.linalg.inv(hole2fixed)
    settings = _settings(spec)
    cache = spec.path.parent / CACHE_DIR
    report(stage, 2, 4)
    held_pieces = decompose(held_raw, settings, cache, Path(spec.held_mesh).stem)
    fixed_pieces = decompose(fixed_raw, settings, cache, Path(spec.fixed_mesh).stem)
    report(stage, 3, 4)
    in_hole = [v - [0.0, 0.0, z_entry] for v in fixed_pieces.moved(fixed2world)]
    fid = decomposition_fidelity(
        fixed_h, in_hole, held_pieces.moved(part2tcp), depth, fit.clearance
    )
    require_fidelity(fid, where)
    report(stage, 4, 4)
    return MeshCell(
        spec=spec,
        held=held,
        fixed=_moved(fixed_raw, fixed2world),
        part2tcp=part2tcp,
        fixed2world=fixed2world,
        hole2world=hole2world,
        success_depth=float(depth),
        fit=fit,
        held_pieces=held_pieces,
        fixed_pieces=fixed_pieces,
        fidelity=fid,
    )


def _settings(spec: MeshTaskSpec) -> CoacdSettings:
    d = dict(spec.decomposition)
    ints = ("max_pieces", "resolution", "mcts_iterations", "seed")
    kw = {k: int(v) if k in ints else v if k == "method" else float(v) for k, v in d.items()}
    return CoacdSettings(**kw)  # type: ignore[arg-type]
