"""Marker detection (OpenCV ``ArucoDetector``) and single-marker pose with IPPE_SQUARE.

OpenCV 5 removed ``estimatePoseSingleMarkers``; a marker's pose comes from ``solvePnPGeneric``
with ``SOLVEPNP_IPPE_SQUARE``, which returns both poses consistent with a planar square
(the second is the mirror of the first about the plane of sight, nearly as good when the
marker is small or seen frontally). Both are kept as hypotheses; :mod:`.fuse` decides between
them with the other markers and cameras, or with the previous frame.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass

import cv2
import numpy as np

from teachfit.capture.geometry import transform
from teachfit.capture.markers import aruco_dictionary, square_points
from teachfit.core.errors import CaptureError

__all__ = [
    "DetectorConfig",
    "Detection",
    "detect_markers",
    "make_detector",
    "refine_edges",
    "square_poses",
]


@dataclass(frozen=True)
class DetectorConfig:
    """Detector settings.

    Attributes
    ----------
    fast : bool
        Use OpenCV's ArUco3 pipeline: candidates are searched on an image scaled so that the
        smallest accepted marker has ``min_side_px`` canonical pixels, and corners are then
        refined on the full image (several times faster at 1080p).
    min_marker_ratio : float
        Smallest marker perimeter accepted, as a fraction of the image's larger side
        (ArUco3's ``minMarkerLengthRatioOriginalImg``).
    min_side_px : int
        ArUco3's ``minSideLengthCanonicalImg``.
    refine : str
        OpenCV's corner refinement: ``"subpix"``, ``"contour"`` or ``"none"``.
    edges : bool
        Re-locate the corners as intersections of lines fitted to the square's four edges
        (:func:`refine_edges`); removes the inward bias of corner refinement on blurred images.
    """

    fast: bool = True
    min_marker_ratio: float = 0.015
    min_side_px: int = 20
    refine: str = "subpix"
    edges: bool = True

    def __post_init__(self) -> None:
        if self.refine not in ("subpix", "contour", "none"):
            raise CaptureError(f"refine must be subpix, contour or none, got {self.refine!r}")
        if not 0 < self.min_marker_ratio < 1 or self.min_side_px < 8:
            raise CaptureError("min_marker_ratio must be in (0, 1) and min_side_px >= 8")


@dataclass(frozen=True, eq=False)
class Detection:
    """One marker seen by one camera: ``corners`` (4, 2) px in IPPE order (float64)."""

    camera: int
    marker_id: int
    corners: np.ndarray


def make_detector(dictionary: str, cfg: DetectorConfig | None = None) -> cv2.aruco.ArucoDetector:
    """An ``ArucoDetector`` for ``dictionary`` set up by ``cfg``."""
    cfg = cfg or DetectorConfig()
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = {
        "subpix": cv2.aruco.CORNER_REFINE_SUBPIX,
        "contour": cv2.aruco.CORNER_REFINE_CONTOUR,
        "none": cv2.aruco.CORNER_REFINE_NONE,
    }[cfg.refine]
    params.cornerRefinementWinSize = 4
    params.cornerRefinementMinAccuracy = 0.01
    params.cornerRefinementMaxIterations = 50
    if cfg.fast:
        params.useAruco3Detection = True
        params.minMarkerLengthRatioOriginalImg = cfg.min_marker_ratio
        params.minSideLengthCanonicalImg = cfg.min_side_px
    else:
        params.minMarkerPerimeterRate = cfg.min_marker_ratio
    return cv2.aruco.ArucoDetector(aruco_dictionary(dictionary), params)


def detect_markers(
    detector: cv2.aruco.ArucoDetector,
    image: np.ndarray,
    camera: int,
    known: Collection[int],
    intrinsics: tuple[np.ndarray, np.ndarray] | None = None,
) -> list[Detection]:
    """Markers of ids in ``known`` found in ``image`` ((H, W) grey or (H, W, 3) RGB uint8).

    An id seen twice in one image is ambiguous (a stray print, a reflection) and dropped. With
    ``intrinsics = (K, dist)`` the corners are refined by :func:`refine_edges`.
    """
    grey = image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    corners, ids, _ = detector.detectMarkers(grey)
    if ids is None:
        return []
    id_list = ids.reshape(-1).tolist()
    out = []
    for c, i in zip(corners, id_list, strict=True):
        if i in known and id_list.count(i) == 1:
            pts = np.asarray(c, dtype=float).reshape(4, 2)
            if intrinsics is not None:
                pts = refine_edges(grey, pts, *intrinsics)
            out.append(Detection(camera, int(i), pts))
    return out


def square_poses(
    corners: np.ndarray, size: float, K: np.ndarray, dist: np.ndarray
) -> list[tuple[np.ndarray, float]]:
    """The two IPPE_SQUARE poses of a square marker, best first.

    Parameters
    ----------
    corners : (4, 2) px, IPPE order
    size : m, edge of the black square
    K, dist : camera intrinsics (3, 3) and distortion (k,)

    Returns
    -------
    list of (marker2cam (4, 4), RMS reprojection error in px)
    """
    n, rvecs, tvecs, errs = cv2.solvePnPGeneric(
        square_points(size), corners.reshape(4, 1, 2), K, dist, flags=cv2.SOLVEPNP_IPPE_SQUARE
    )
    out = []
    for k in range(n):
        # OpenCV's rvec/tvec stop here: the transform is built by scipy (capture.geometry)
        T = transform(np.asarray(rvecs[k]).reshape(3), np.asarray(tvecs[k]).reshape(3))
        if T[2, 3] > 0:  # in front of the camera
            out.append((T, float(np.asarray(errs).reshape(-1)[k])))
    return sorted(out, key=lambda p: p[1])


def refine_edges(
    grey: np.ndarray, corners: np.ndarray, K: np.ndarray, dist: np.ndarray, samples: int = 16
) -> np.ndarray:
    """Corners (4, 2) px re-located as intersections of the square's fitted edge lines.

    Corner detectors (``cornerSubPix``) place an L-shaped corner of a blurred dark square
    slightly inside it (0.1-0.2 px at 1080p), which biases a marker's distance by ~0.5 %.
    Edges have no such bias: across a symmetric blur a step edge still crosses the mean of its
    two grey levels at its true position. Along each edge, ``samples`` intensity profiles
    normal to it (0.25 px steps, inside the black border and the white quiet zone) give
    sub-pixel crossing points; lines fitted to them in the undistorted image intersect in the
    corners, which are distorted back. OpenCV offers no edge-based refinement that handles lens
    distortion, hence this function. Falls back to the input corners when an edge has too
    little contrast or too few points.
    """
    c = np.asarray(corners, dtype=float)
    side = float(np.min(np.linalg.norm(np.roll(c, -1, axis=0) - c, axis=1)))
    half = float(np.clip(0.45 * side / 6.0, 1.0, 4.0))  # stay within one cell of the border
    offs = np.arange(-half, half + 1e-9, 0.25)
    centre = c.mean(axis=0)
    s = np.linspace(0.15, 0.85, samples)
    lines = []
    for k in range(4):
        a, b = c[k], c[(k + 1) % 4]
        d = (b - a) / np.linalg.norm(b - a)
        n = np.array([d[1], -d[0]])
        if np.dot(n, (a + b) / 2 - centre) < 0:
            n = -n  # outward normal: dark (inside) to bright (outside)
        base = a + s[:, None] * (b - a)
        xy = (base[:, None, :] + offs[None, :, None] * n).astype(np.float32)
        prof = cv2.remap(grey, xy[..., 0], xy[..., 1], cv2.INTER_LINEAR).astype(float)
        lo, hi = prof[:, :3].mean(axis=1), prof[:, -3:].mean(axis=1)
        ok = hi - lo > 20.0
        above = prof >= ((lo + hi) / 2)[:, None]
        j = np.argmax(above, axis=1)
        ok &= (j > 0) & above[np.arange(len(j)), j]
        if ok.sum() < 4:
            return c
        j, lo, hi, prof, base = j[ok], lo[ok], hi[ok], prof[ok], base[ok]
        r = np.arange(len(j))
        y0, y1 = prof[r, j - 1], prof[r, j]
        frac = ((lo + hi) / 2 - y0) / np.maximum(y1 - y0, 1e-9)
        pts = base + (offs[j - 1] + 0.25 * frac)[:, None] * n
        und = cv2.undistortPoints(pts.reshape(-1, 1, 2), K, dist, P=K).reshape(-1, 2)
        vx, vy, x0, y0_ = cv2.fitLine(und.astype(np.float32), cv2.DIST_L2, 0, 0.01, 0.01).ravel()
        lines.append(np.cross([x0, y0_, 1.0], [x0 + vx, y0_ + vy, 1.0]))
    out = np.empty((4, 2))
    for k in range(4):
        p = np.cross(lines[k - 1], lines[k])  # corner k joins edge k-1 and edge k
        if abs(p[2]) < 1e-12:
            return c
        out[k] = p[:2] / p[2]
    norm = np.column_stack([out, np.ones(4)]) @ np.linalg.inv(K).T
    img, _ = cv2.projectPoints(norm.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, dist)
    img = img.reshape(4, 2)
    return img if np.abs(img - c).max() < 3.0 else c
