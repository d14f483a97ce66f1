"""Square fiducial markers (ArUco) attached to the parts, and the marker file that lists them.

Marker frame (OpenCV's ``SOLVEPNP_IPPE_SQUARE`` convention): origin at the centre of the black
square, x to the right and y up in the printed image, z out of the printed side. Corners are
ordered top-left, top-right, bottom-right, bottom-left, i.e. ``(-s/2, s/2, 0)``,
``(s/2, s/2, 0)``, ``(s/2, -s/2, 0)``, ``(-s/2, -s/2, 0)`` for edge length ``s``.

Marker file (TOML, ``format = "teachfit-markers"``, ``version = 1``)::

    format = "teachfit-markers"
    version = 1
    dictionary = "DICT_4X4_50"
    reference = "G"               # part whose frame the demonstration is expressed in
    moving = "L"                  # part whose pose is recorded
    [[marker]]
    id = 0
    part = "L"
    size = 0.024                  # m, edge of the black square
    marker2part = [[...], [...], [...], [0, 0, 0, 1]]   # m; p_part = marker2part @ p_marker
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from teachfit.capture.geometry import checked_transform, toml_matrix
from teachfit.capture.tomlfile import read_versioned_toml, write_versioned_toml
from teachfit.core.errors import CaptureError

__all__ = [
    "DICTIONARIES",
    "Marker",
    "MarkerSet",
    "aruco_dictionary",
    "marker_image",
    "read_markers",
    "square_points",
    "write_markers",
]

FORMAT = "teachfit-markers"
VERSION = 1
DICTIONARIES: tuple[str, ...] = tuple(
    sorted(n for n in dir(cv2.aruco) if n.startswith("DICT_") and n.upper() == n)
)


def aruco_dictionary(name: str) -> cv2.aruco.Dictionary:
    """OpenCV's predefined dictionary ``name`` (e.g. ``"DICT_4X4_50"``), or CaptureError."""
    if name not in DICTIONARIES:
        raise CaptureError(f"unknown ArUco dictionary {name!r}; known: {', '.join(DICTIONARIES)}")
    return cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, name))


def square_points(size: float) -> np.ndarray:
    """(4, 3) corners of a square marker of edge ``size`` (m) in its own frame, IPPE order."""
    h = size / 2.0
    return np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])


@dataclass(frozen=True, eq=False)
class Marker:
    """One marker: its id, the part it is fixed to, its edge (m) and ``marker2part`` (4, 4)."""

    id: int
    part: str
    size: float
    marker2part: np.ndarray

    def __post_init__(self) -> None:
        if isinstance(self.id, bool) or int(self.id) != self.id or self.id < 0:
            raise CaptureError(f"marker id must be an integer >= 0, got {self.id!r}")
        if not isinstance(self.part, str) or not self.part:
            raise CaptureError(f"marker {self.id}: part must be a non-empty string")
        if not np.isfinite(self.size) or self.size <= 0:
            raise CaptureError(f"marker {self.id}: size must be > 0 m, got {self.size!r}")
        T = checked_transform(self.marker2part, f"marker {self.id} marker2part")
        object.__setattr__(self, "id", int(self.id))
        object.__setattr__(self, "size", float(self.size))
        object.__setattr__(self, "marker2part", T)

    @property
    def corners_in_part(self) -> np.ndarray:
        """(4, 3) corners in the part frame (m), IPPE order."""
        pts = square_points(self.size)
        return pts @ self.marker2part[:3, :3].T + self.marker2part[:3, 3]


@dataclass(frozen=True)
class MarkerSet:
    """The markers of a capture: a dictionary, unique ids, two parts (reference and moving).

    Raises
    ------
    CaptureError
        Unknown dictionary, duplicate ids, ids beyond the dictionary, markers on parts other
        than ``reference``/``moving``, or a part without any marker.
    """

    dictionary: str
    markers: tuple[Marker, ...]
    reference: str = "G"
    moving: str = "L"

    def __post_init__(self) -> None:
        dic = aruco_dictionary(self.dictionary)
        markers = tuple(self.markers)
        ids = [m.id for m in markers]
        dup = sorted({i for i in ids if ids.count(i) > 1})
        if dup:
            raise CaptureError(f"duplicate marker id(s) {dup}")
        n_codes = int(dic.bytesList.shape[0])
        if any(i >= n_codes for i in ids):
            raise CaptureError(f"{self.dictionary} has ids 0..{n_codes - 1}; got {max(ids)}")
        if self.reference == self.moving:
            raise CaptureError("reference and moving part must differ")
        for m in markers:
            if m.part not in (self.reference, self.moving):
                raise CaptureError(
                    f"marker {m.id} is on part {m.part!r}, expected {self.reference!r} "
                    f"or {self.moving!r}"
                )
        for part in (self.reference, self.moving):
            if not any(m.part == part for m in markers):
                raise CaptureError(f"part {part!r} has no marker")
        object.__setattr__(self, "markers", markers)

    def by_id(self) -> dict[int, Marker]:
        """Markers keyed by id."""
        return {m.id: m for m in self.markers}

    def ids_of(self, part: str) -> list[int]:
        """Ids of the markers on ``part``."""
        return [m.id for m in self.markers if m.part == part]


def read_markers(path: str | Path) -> MarkerSet:
    """Read and validate a marker TOML file; problems raise :class:`CaptureError`."""
    doc = read_versioned_toml(path, "marker", FORMAT, VERSION)
    try:
        markers = []
        for i, entry in enumerate(doc.get("marker", [])):
            missing = {"id", "part", "size", "marker2part"} - set(entry)
            if missing:
                raise CaptureError(f"marker entry {i} lacks {', '.join(sorted(missing))}")
            markers.append(Marker(**{k: entry[k] for k in Marker.__dataclass_fields__}))
        return MarkerSet(
            dictionary=str(doc.get("dictionary", "")),
            markers=tuple(markers),
            reference=str(doc.get("reference", "G")),
            moving=str(doc.get("moving", "L")),
        )
    except CaptureError as exc:
        raise CaptureError(f"marker file {path}: {exc}") from exc


def write_markers(markers: MarkerSet, path: str | Path) -> Path:
    """Write a marker set as TOML (by hand: tomllib only reads)."""
    lines = [
        f'dictionary = "{markers.dictionary}"',
        f'reference = "{markers.reference}"',
        f'moving = "{markers.moving}"',
        "",
    ]
    for m in markers.markers:
        lines += [
            "[[marker]]",
            f"id = {m.id}",
            f'part = "{m.part}"',
            f"size = {m.size!r}",
            f"marker2part = {toml_matrix(m.marker2part)}",
            "",
        ]
    return write_versioned_toml(path, FORMAT, VERSION, lines)


def marker_image(dictionary: str, marker_id: int, px: int, margin: float = 0.25) -> np.ndarray:
    """Printable marker: (P, P) uint8 grey image, the black square of ``px`` pixels centred in a
    white quiet zone of ``margin * px`` on every side (``P = px + 2 * round(margin * px)``)."""
    img = cv2.aruco.generateImageMarker(aruco_dictionary(dictionary), int(marker_id), int(px))
    pad = int(round(margin * px))
    return cv2.copyMakeBorder(img, pad, pad, pad, pad, cv2.BORDER_CONSTANT, value=255)
