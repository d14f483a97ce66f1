"""Bounds on a part mesh read before its triangles are: file size and triangle count.

A binary STL states its triangle count in its header (80 bytes, then a little-endian uint32
``n``, then 50 bytes per triangle: ``84 + 50 n`` bytes in all), a PLY in its header's
``element face N`` line; a text mesh (ASCII STL, OBJ) is bounded by its size
(:data:`TEXT_BYTES_PER_TRIANGLE`). A file over the bounds, or a binary STL whose size does not
match its header (truncated, or a sparse file), is refused before any triangle is read, so a
huge file costs neither time nor memory. The count read is checked again once loaded.
"""

from __future__ import annotations

import re
from pathlib import Path

from teachfit.core.errors import TaskError

#: most triangles a part mesh may have (the checks and decompositions run in seconds below it)
MAX_TRIANGLES = 400_000
#: bytes a text mesh takes per triangle at most in practice (ASCII STL: ~250; OBJ, PLY: < 100)
TEXT_BYTES_PER_TRIANGLE = 400
#: how to get under the bound
DECIMATE = (
    "decimate it (e.g. MeshLab's Quadric Edge Collapse Decimation, Blender's Decimate "
    "modifier) or re-export it with a coarser tessellation"
)
_PLY_FACES = re.compile(rb"^element\s+face\s+(\d+)\s*$", re.MULTILINE)


def too_many(n: int, path: Path, where: str) -> TaskError:
    """The error for a mesh of ``n`` triangles, over :data:`MAX_TRIANGLES`."""
    return TaskError(
        f"{where}: {path} has {n:,} triangles, more than the {MAX_TRIANGLES:,} a part mesh may "
        f"have; {DECIMATE}"
    )


def check_triangle_count(n: int, path: Path, where: str) -> None:
    """Refuse a mesh of more than :data:`MAX_TRIANGLES` triangles."""
    if n > MAX_TRIANGLES:
        raise too_many(n, path, where)


def check_mesh_file(path: Path, where: str) -> None:
    """Refuse the mesh file ``path`` before reading it: empty, larger than a text mesh of
    :data:`MAX_TRIANGLES` triangles takes, a header counting too many triangles, or a binary
    STL whose size does not match its header. ``where`` starts the messages."""
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise TaskError(f"{where}: cannot read {path} ({exc.strerror or exc})") from exc
    if size == 0:
        raise TaskError(f"{where}: {path} is empty; export the part as a mesh")
    if size > 84 + MAX_TRIANGLES * TEXT_BYTES_PER_TRIANGLE:
        raise TaskError(
            f"{where}: {path} is {size / 1e6:,.0f} MB, more than a mesh of {MAX_TRIANGLES:,} "
            f"triangles (the most a part may have) takes; {DECIMATE}"
        )
    suffix = path.suffix.lower()
    n = _stl_count(path, size, where) if suffix == ".stl" else None
    if suffix == ".ply":
        n = _ply_count(path)
    if n is not None:
        check_triangle_count(n, path, where)


def _head(path: Path, size: int) -> bytes:
    try:
        with path.open("rb") as f:
            return f.read(min(size, 65536))
    except OSError as exc:
        raise TaskError(f"cannot read {path} ({exc.strerror or exc})") from exc


def _stl_count(path: Path, size: int, where: str) -> int | None:
    """The triangle count of a binary STL (its header's), None for an ASCII STL."""
    head = _head(path, size)
    n = int.from_bytes(head[80:84], "little") if len(head) >= 84 else 0
    if len(head) >= 84 and 84 + 50 * n == size:
        return n
    start = head[:1024]
    if start.lstrip().lower().startswith(b"solid") and b"\0" not in start:
        return None  # ASCII STL: bounded by its size
    raise TaskError(
        f"{where}: {path} is not a whole binary STL (its header counts {n:,} triangles, "
        f"{84 + 50 * n:,} bytes, but the file has {size:,}): truncated or damaged; re-export "
        "the part"
    )


def _ply_count(path: Path) -> int | None:
    """The face count a PLY header states (None if the header does not state one)."""
    head = _head(path, 65536)
    end = head.find(b"end_header")
    match = _PLY_FACES.search(head[: end if end >= 0 else len(head)])
    return None if match is None else int(match.group(1))
