"""Convex decomposition of a part mesh for MuJoCo (``coacd``), cached on disk by content hash.

MuJoCo collides every mesh geom as its convex hull, so a concave part (a board with holes, a
socket) must be split into convex pieces. ``coacd`` (Wei et al., SIGGRAPH 2022) cuts the mesh
along planes chosen by a tree search until every piece's concavity is below ``threshold``.
A convex part (volume within 0.1 % of its hull's) is its own single piece; a rectilinear one
(every face normal to a mesh axis) is cut exactly into boxes (:mod:`.planar`), and a
rectilinear one with round bores (chamfered, countersunk) into boxes and ring sectors
(:mod:`.revolved`), unless ``method = "coacd"``, since coacd's pieces narrow sub-millimetre
clearances.

The pieces are cached in ``.teachfit-cache/`` beside the task file: an NPZ of the pieces'
vertices and faces and a JSON of the settings and timing, both named by a SHA-256 of the
mesh's coordinates, faces and settings; written atomically, loaded without pickle. The
settings are tuned so that the shipped examples decompose in a few seconds: no remeshing (the
mesh is already a checked solid, and coacd's voxel remeshing would move the walls of a
0.2 mm clearance), a short tree search, a bound on the piece count.
"""

from __future__ import annotations

import hashlib
import io
import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import trimesh

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.loading import write_atomic
from teachfit.tasks.mesh.planar import box_pieces
from teachfit.tasks.mesh.revolved import MIN_SEGMENTS, revolved_pieces

CACHE_DIR = ".teachfit-cache"
METHODS = ("auto", "coacd", "boxes", "revolved")
_FORMAT = 1


@dataclass(frozen=True)
class CoacdSettings:
    """``method``: ``"auto"`` (exact boxes for a rectilinear part, boxes and ring sectors for
    one with round bores, else coacd), ``"coacd"``, ``"boxes"`` or ``"revolved"`` (exact
    pieces only); ``widening``: most a bore's ring sectors widen it at their corners (m,
    :func:`~teachfit.tasks.mesh.revolved.sector_count`); ``coacd.run_coacd`` settings:
    concavity ``threshold`` (of the part's size, 0.01-1), at most ``max_pieces`` convex
    pieces (boxes too), sampling ``resolution``, ``mcts_iterations`` of the cutting-plane
    search, ``seed``."""

    method: str = "auto"
    threshold: float = 0.03
    max_pieces: int = 48
    resolution: int = 1000
    mcts_iterations: int = 60
    seed: int = 0
    widening: float = 2e-5

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise TaskError(f"[decomposition] method must be one of {METHODS}, got {self.method!r}")
        if not 0.01 <= self.threshold <= 1.0:
            raise TaskError(f"[decomposition] threshold must be within [0.01, 1], got {self})")
        if self.max_pieces < 1 or self.resolution < 100 or self.mcts_iterations < 10:
            raise TaskError(
                "[decomposition] needs max_pieces >= 1, resolution >= 100, mcts_iterations >= 10"
            )
        if not 1e-7 <= self.widening <= 1e-3:
            raise TaskError(
                f"[decomposition] widening must be within [1e-7, 1e-3] m, got {self.widening}"
            )


@dataclass(frozen=True)
class Decomposition:
    """Convex pieces of one mesh (its own frame, m): ``pieces`` as (vertices, faces) pairs;
    ``seconds`` the decomposition's wall time when it was computed, ``cached`` whether it
    came from the cache now, ``method`` ``"hull"``, ``"boxes"``, ``"revolved"`` or
    ``"coacd"``."""

    pieces: tuple[tuple[np.ndarray, np.ndarray], ...]
    seconds: float
    cached: bool
    method: str = "hull"

    @property
    def n_pieces(self) -> int:
        return len(self.pieces)

    def moved(self, T: np.ndarray) -> list[np.ndarray]:
        """Every piece's vertices under the (4, 4) transform ``T`` (m)."""
        return [v @ T[:3, :3].T + T[:3, 3] for v, _ in self.pieces]


#: the most triangles a part may have for coacd's decomposition (a cached one is read at any
#: size): its time grows with the mesh (a torus of 20,000 triangles 42 s, 80,000 208 s on the
#: project's busy 2-core machine), so a bigger part is refused with the hint to decimate it
COACD_MAX_TRIANGLES = 100_000


def is_convex(mesh: trimesh.Trimesh) -> bool:
    """Whether ``mesh`` fills its convex hull (volume within 0.1 %)."""
    return bool(mesh.volume >= 0.999 * mesh.convex_hull.volume)


def mesh_hash(mesh: trimesh.Trimesh, settings: CoacdSettings) -> str:
    """SHA-256 (hex) of the mesh's coordinates, faces, the settings coacd uses and the cache
    format (``widening``, for the exact pieces only, is left out: older entries stay valid)."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(mesh.vertices, dtype="<f8").tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype="<i8").tobytes())
    used = {k: v for k, v in asdict(settings).items() if k != "widening"}
    h.update(json.dumps([used, _FORMAT], sort_keys=True).encode())
    return h.hexdigest()


def _run_coacd(mesh: trimesh.Trimesh, s: CoacdSettings) -> list[tuple[np.ndarray, np.ndarray]]:
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(
        coacd.Mesh(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=int)),
        threshold=s.threshold,
        max_convex_hull=s.max_pieces,
        preprocess_mode="off",
        resolution=s.resolution,
        mcts_iterations=s.mcts_iterations,
        mcts_max_depth=2,
        mcts_nodes=10,
        merge=True,
        seed=s.seed,
    )
    out = []
    for v, f in parts:
        hull = trimesh.Trimesh(np.asarray(v, dtype=float), np.asarray(f), process=True).convex_hull
        out.append((np.asarray(hull.vertices, dtype=float), np.asarray(hull.faces, dtype=np.int64)))
    if not out:
        raise TaskError("coacd returned no convex piece")
    return out


def _save(stem: Path, pieces: list[tuple[np.ndarray, np.ndarray]], meta: dict) -> None:
    buf = io.BytesIO()
    np.savez(
        buf,
        vertices=np.concatenate([v for v, _ in pieces]),
        faces=np.concatenate([f for _, f in pieces]),
        n_vertices=np.array([len(v) for v, _ in pieces], dtype=np.int64),
        n_faces=np.array([len(f) for _, f in pieces], dtype=np.int64),
    )
    write_atomic(stem.with_suffix(".npz"), buf.getvalue())
    write_atomic(stem.with_suffix(".json"), json.dumps(meta, indent=2).encode())


def _load(stem: Path) -> tuple[list[tuple[np.ndarray, np.ndarray]], dict] | None:
    npz, js = stem.with_suffix(".npz"), stem.with_suffix(".json")
    if not (npz.is_file() and js.is_file()):
        return None
    try:
        meta = json.loads(js.read_text())
        with np.load(npz, allow_pickle=False) as z:
            v_split = np.cumsum(z["n_vertices"])[:-1]
            f_split = np.cumsum(z["n_faces"])[:-1]
            verts = np.split(z["vertices"], v_split)
            faces = np.split(z["faces"], f_split)
    except (OSError, ValueError, KeyError):
        return None  # a damaged cache entry is recomputed
    return list(zip(verts, faces, strict=True)), meta


def _exact(mesh: trimesh.Trimesh, settings: CoacdSettings, name: str) -> Decomposition | None:
    """Boxes for a rectilinear part, boxes and ring sectors for one with round bores (unless
    ``method`` names the other), else None; an error if ``method`` asks for what fails."""
    t0 = time.perf_counter()
    if settings.method in ("auto", "boxes"):
        boxes = box_pieces(mesh, settings.max_pieces)
        if boxes is not None:
            box_list = tuple((np.asarray(b.vertices), np.asarray(b.faces)) for b in boxes)
            return Decomposition(box_list, time.perf_counter() - t0, False, "boxes")
    if settings.method in ("auto", "revolved"):
        pieces = revolved_pieces(mesh, settings.widening, settings.max_pieces)
        if pieces is not None:
            return Decomposition(tuple(pieces), time.perf_counter() - t0, False, "revolved")
    if settings.method == "boxes":
        raise TaskError(
            f'{name}: method = "boxes" needs a rectilinear part (every face normal to a '
            f'mesh axis) of at most {settings.max_pieces} boxes; use "auto" or "coacd"'
        )
    if settings.method == "revolved":
        raise TaskError(
            f'{name}: method = "revolved" needs a rectilinear part whose only curved faces are '
            f"round bores along one mesh axis (at least {MIN_SEGMENTS} facets around) and at "
            f'most {settings.max_pieces} boxes besides; use "auto" or "coacd"'
        )
    return None


def decompose(
    mesh: trimesh.Trimesh, settings: CoacdSettings, cache_dir: Path | None, name: str
) -> Decomposition:
    """Convex pieces of ``mesh`` (m), from ``cache_dir`` when there, else computed and stored.

    ``name`` prefixes the cache files (e.g. ``"board"``); ``cache_dir=None`` caches nothing.
    """
    if is_convex(mesh):
        hull = mesh.convex_hull
        piece = (np.asarray(hull.vertices, dtype=float), np.asarray(hull.faces, dtype=np.int64))
        return Decomposition((piece,), 0.0, False, "hull")
    if settings.method != "coacd":
        exact = _exact(mesh, settings, name)
        if exact is not None:
            return exact
    stem = None
    if cache_dir is not None:
        stem = cache_dir / f"{name}-{mesh_hash(mesh, settings)[:20]}"
        hit = _load(stem)
        if hit is not None:
            return Decomposition(tuple(hit[0]), float(hit[1].get("seconds", 0.0)), True, "coacd")
    if len(mesh.faces) > COACD_MAX_TRIANGLES:
        raise TaskError(
            f"{name}: a convex decomposition (coacd) of {len(mesh.faces):,} triangles takes "
            f"many minutes (it grows with the mesh; 80,000 took 3.5 min): decimate the part "
            f"below {COACD_MAX_TRIANGLES:,} triangles (MeshLab's quadric edge collapse, "
            "Blender's Decimate) or re-export it with a coarser tessellation"
        )
    t0 = time.perf_counter()
    pieces = _run_coacd(mesh, settings)
    seconds = time.perf_counter() - t0
    if stem is not None:
        meta = {"settings": asdict(settings), "seconds": seconds, "n_pieces": len(pieces)}
        _save(stem, pieces, meta)
    return Decomposition(tuple(pieces), seconds, False, "coacd")
