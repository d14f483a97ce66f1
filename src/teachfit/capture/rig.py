"""The camera rig: pinhole intrinsics, lens distortion and each camera's pose in a rig frame.

Rig file (TOML, ``format = "teachfit-rig"``, ``version = 1``)::

    format = "teachfit-rig"
    version = 1
    [[camera]]
    name = "cam0"
    width = 1920                  # px
    height = 1080                 # px
    K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]   # px, OpenCV pixel-centre convention
    dist = [k1, k2, p1, p2, k3]   # OpenCV's distortion model (4, 5, 8, 12 or 14 values)
    cam2rig = [[...], [...], [...], [0, 0, 0, 1]]   # m; p_rig = cam2rig @ p_cam

Camera frames follow OpenCV: x right, y down, z along the optical axis.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teachfit.capture.geometry import checked_transform, invert, toml_matrix
from teachfit.capture.tomlfile import read_versioned_toml, write_versioned_toml
from teachfit.core.errors import CaptureError

__all__ = ["Camera", "Rig", "read_rig", "write_rig"]

FORMAT = "teachfit-rig"
VERSION = 1
_DIST_SIZES = (4, 5, 8, 12, 14)


@dataclass(frozen=True, eq=False)
class Camera:
    """One calibrated camera.

    Attributes
    ----------
    name : str
        Label (unique within a rig).
    width, height : int
        Image size in px.
    K : np.ndarray
        (3, 3) intrinsic matrix ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]`` in px.
    dist : np.ndarray
        (k,) OpenCV distortion coefficients, k in (4, 5, 8, 12, 14).
    cam2rig : np.ndarray
        (4, 4) pose of the camera in the rig frame (m).

    Raises
    ------
    CaptureError
        Non-positive size or focal length, a principal point outside the image, a
        distortion vector of the wrong length, or a ``cam2rig`` that is not a rigid transform.
    """

    name: str
    width: int
    height: int
    K: np.ndarray
    dist: np.ndarray
    cam2rig: np.ndarray

    def __post_init__(self) -> None:
        what = f"camera {self.name!r}"
        if not isinstance(self.name, str) or not self.name:
            raise CaptureError(f"camera name must be a non-empty string, got {self.name!r}")
        if int(self.width) <= 0 or int(self.height) <= 0:
            raise CaptureError(f"{what}: image size must be > 0, got {self.width}x{self.height}")
        K = np.array(self.K, dtype=float)
        if K.shape != (3, 3) or not np.all(np.isfinite(K)):
            raise CaptureError(f"{what}: K must be a finite 3x3 matrix, got shape {K.shape}")
        if K[0, 0] <= 0 or K[1, 1] <= 0 or not np.allclose(K[2], [0, 0, 1]):
            raise CaptureError(f"{what}: K needs fx, fy > 0 and last row [0, 0, 1]")
        if not (0 <= K[0, 2] <= self.width and 0 <= K[1, 2] <= self.height):
            raise CaptureError(f"{what}: principal point ({K[0, 2]}, {K[1, 2]}) outside image")
        dist = np.array(self.dist, dtype=float).reshape(-1)
        if dist.size not in _DIST_SIZES or not np.all(np.isfinite(dist)):
            raise CaptureError(f"{what}: dist needs {_DIST_SIZES} finite values, got {dist.size}")
        cam2rig = checked_transform(self.cam2rig, f"{what} cam2rig")
        for arr in (K, dist):
            arr.setflags(write=False)
        object.__setattr__(self, "width", int(self.width))
        object.__setattr__(self, "height", int(self.height))
        object.__setattr__(self, "K", K)
        object.__setattr__(self, "dist", dist)
        object.__setattr__(self, "cam2rig", cam2rig)

    @property
    def rig2cam(self) -> np.ndarray:
        """(4, 4) inverse of ``cam2rig``."""
        return invert(self.cam2rig)


@dataclass(frozen=True)
class Rig:
    """A set of cameras sharing one rig frame (names unique, at least one camera)."""

    cameras: tuple[Camera, ...]

    def __post_init__(self) -> None:
        cams = tuple(self.cameras)
        if not cams:
            raise CaptureError("a rig needs at least one camera")
        names = [c.name for c in cams]
        if len(set(names)) != len(names):
            raise CaptureError(f"camera names must be unique, got {names}")
        object.__setattr__(self, "cameras", cams)

    def __len__(self) -> int:
        return len(self.cameras)

    def subset(self, indices: Sequence[int]) -> Rig:
        """The rig restricted to cameras ``indices`` (in that order)."""
        try:
            return Rig(tuple(self.cameras[i] for i in indices))
        except IndexError as exc:
            raise CaptureError(f"camera index out of range 0..{len(self) - 1}: {indices}") from exc


def read_rig(path: str | Path) -> Rig:
    """Read and validate a rig TOML file; every problem is a :class:`CaptureError` naming it."""
    doc = read_versioned_toml(path, "rig", FORMAT, VERSION)
    cams = []
    for i, entry in enumerate(doc.get("camera", [])):
        missing = {"name", "width", "height", "K", "dist", "cam2rig"} - set(entry)
        if missing:
            raise CaptureError(f"rig file {path}: camera {i} lacks {', '.join(sorted(missing))}")
        try:
            cams.append(Camera(**{k: entry[k] for k in Camera.__dataclass_fields__}))
        except CaptureError as exc:
            raise CaptureError(f"rig file {path}: {exc}") from exc
    try:
        return Rig(tuple(cams))
    except CaptureError as exc:
        raise CaptureError(f"rig file {path}: {exc}") from exc


def write_rig(rig: Rig, path: str | Path) -> Path:
    """Write ``rig`` as TOML (by hand: the standard library's tomllib only reads)."""
    lines = [""]
    for cam in rig.cameras:
        lines += [
            "[[camera]]",
            f'name = "{cam.name}"',
            f"width = {cam.width}",
            f"height = {cam.height}",
            f"K = {toml_matrix(cam.K)}",
            f"dist = {toml_matrix(cam.dist)}",
            f"cam2rig = {toml_matrix(cam.cam2rig)}",
            "",
        ]
    return write_versioned_toml(path, FORMAT, VERSION, lines)
