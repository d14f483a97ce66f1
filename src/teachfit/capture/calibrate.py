"""ChArUco calibration of a camera rig: each camera's intrinsics, then each camera's pose
relative to camera 0 (the rig frame).

Calibration folder layout: one sub-folder per camera (sorted names become the rig's camera
order, the first is the rig frame), images named alike across cameras when they were taken
at the same instant (the same board pose)::

    calib_frames/cam0/000.png  calib_frames/cam1/000.png  ...

Intrinsics: ``cv2.calibrateCamera`` on the ChArUco corners of every usable image
(``CharucoDetector.detectBoard`` then ``CharucoBoard.matchImagePoints``; OpenCV 5 has no
``calibrateCameraCharuco``). Extrinsics: ``cv2.stereoCalibrate`` with fixed intrinsics on the
corners camera 0 and camera c both saw in the same shots; ``(R, T)`` maps camera-0 to camera-c
coordinates, so ``cam_c2rig = inv([R | T])``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from teachfit.capture.geometry import invert
from teachfit.capture.markers import aruco_dictionary
from teachfit.capture.rig import Camera, Rig
from teachfit.core.errors import CaptureError

__all__ = ["CalibrationReport", "CharucoSpec", "calibrate_folder", "calibrate_rig", "load_views"]

MIN_CORNERS = 6
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")


@dataclass(frozen=True)
class CharucoSpec:
    """A ChArUco board: ``squares`` (columns, rows), square and marker edges (m), dictionary."""

    squares: tuple[int, int] = (5, 5)
    square: float = 0.04
    marker: float = 0.03
    dictionary: str = "DICT_4X4_50"

    def __post_init__(self) -> None:
        if min(self.squares) < 2:
            raise CaptureError(f"a ChArUco board needs at least 2x2 squares, got {self.squares}")
        if not 0 < self.marker < self.square:
            raise CaptureError("the marker edge must be > 0 and smaller than the square edge")

    def board(self) -> cv2.aruco.CharucoBoard:
        """The OpenCV board object."""
        return cv2.aruco.CharucoBoard(
            tuple(self.squares), self.square, self.marker, aruco_dictionary(self.dictionary)
        )


@dataclass(frozen=True)
class CalibrationReport:
    """RMS reprojection errors (px): per camera's intrinsics and per camera pair with camera 0,
    and the number of images used for each."""

    intrinsic_rms: dict[str, float]
    intrinsic_views: dict[str, int]
    stereo_rms: dict[str, float]
    stereo_views: dict[str, int]


def load_views(folder: str | Path) -> dict[str, dict[str, np.ndarray]]:
    """Grey images of a calibration folder: camera name -> image stem -> (H, W) uint8."""
    folder = Path(folder)
    if not folder.is_dir():
        raise CaptureError(f"calibration folder {folder} does not exist")
    views: dict[str, dict[str, np.ndarray]] = {}
    for sub in sorted(p for p in folder.iterdir() if p.is_dir()):
        imgs = {}
        for f in sorted(sub.iterdir()):
            if f.suffix.lower() in IMAGE_SUFFIXES:
                img = cv2.imread(str(f), cv2.IMREAD_GRAYSCALE)
                if img is None:
                    raise CaptureError(f"calibration image {f} cannot be read")
                imgs[f.stem] = img
        if imgs:
            views[sub.name] = imgs
    if not views:
        raise CaptureError(f"{folder} holds no camera sub-folder with images")
    return views


def _corners(detector: cv2.aruco.CharucoDetector, board, img: np.ndarray):
    ch_corners, ch_ids, _, _ = detector.detectBoard(img)
    if ch_ids is None or len(ch_ids) < MIN_CORNERS:
        return None
    obj, pts = board.matchImagePoints(ch_corners, ch_ids)
    return ch_ids.reshape(-1), obj.reshape(-1, 3), pts.reshape(-1, 2)


def calibrate_rig(
    views: Mapping[str, Mapping[str, np.ndarray]], spec: CharucoSpec, *, fix_k3: bool = True
) -> tuple[Rig, CalibrationReport]:
    """Calibrate every camera of ``views`` (camera name -> shot name -> grey image).

    ``fix_k3`` keeps the sixth-order radial term at 0 (``CALIB_FIX_K3``), which a handful of
    shots cannot determine.

    Raises
    ------
    CaptureError
        A camera with fewer than 3 usable images, mixed image sizes within a camera, or a
        camera that shares fewer than 2 usable shots with camera 0.
    """
    board = spec.board()
    detector = cv2.aruco.CharucoDetector(board)
    found: dict[str, dict[str, tuple]] = {}
    intr: dict[str, _Intrinsics] = {}
    rms_i: dict[str, float] = {}
    for cam, imgs in views.items():
        found[cam], intr[cam], rms_i[cam] = _intrinsics(cam, imgs, detector, board, spec, fix_k3)
    names = list(views)
    ref = names[0]
    cams = [Camera(ref, intr[ref][2][0], intr[ref][2][1], intr[ref][0], intr[ref][1], np.eye(4))]
    rms_s: dict[str, float] = {}
    n_s: dict[str, int] = {}
    for cam in names[1:]:
        camera, rms_s[cam], n_s[cam] = _extrinsics(cam, ref, found, intr)
        cams.append(camera)
    report = CalibrationReport(rms_i, {c: len(found[c]) for c in names}, rms_s, n_s)
    return Rig(tuple(cams)), report


_Intrinsics = tuple[np.ndarray, np.ndarray, tuple[int, int]]
"""A camera's K (3, 3) px, distortion coefficients and image size (width, height) px."""


def _intrinsics(
    cam: str,
    imgs: Mapping[str, np.ndarray],
    detector: cv2.aruco.CharucoDetector,
    board: cv2.aruco.CharucoBoard,
    spec: CharucoSpec,
    fix_k3: bool,
) -> tuple[dict[str, tuple], _Intrinsics, float]:
    """Camera ``cam``'s board corners per shot of ``imgs``, its intrinsics and their RMS
    reprojection error (px); CaptureError for mixed sizes or fewer than 3 usable images."""
    sizes = {img.shape[:2] for img in imgs.values()}
    if len(sizes) != 1:
        raise CaptureError(f"camera {cam}: images of different sizes {sorted(sizes)}")
    h, w = sizes.pop()
    found = {k: c for k, img in imgs.items() if (c := _corners(detector, board, img))}
    if len(found) < 3:
        raise CaptureError(
            f"camera {cam}: the board ({spec.squares[0]}x{spec.squares[1]}, "
            f"{spec.dictionary}) was found in {len(found)} of {len(imgs)} images; "
            "need at least 3"
        )
    obj = [c[1].astype(np.float32) for c in found.values()]
    pts = [c[2].astype(np.float32) for c in found.values()]
    flags = cv2.CALIB_FIX_K3 if fix_k3 else 0
    rms, K, dist, _, _ = cv2.calibrateCamera(obj, pts, (w, h), None, None, flags=flags)
    return found, (K, dist.reshape(-1), (w, h)), float(rms)


def _extrinsics(
    cam: str, ref: str, found: Mapping[str, Mapping[str, tuple]], intr: Mapping[str, _Intrinsics]
) -> tuple[Camera, float, int]:
    """Camera ``cam`` placed in the frame of camera ``ref`` by stereo calibration on the corners
    both saw in the same shots, the RMS error (px) and the number of shots used; CaptureError
    for fewer than 2 shared usable shots."""
    obj, p0, pc = [], [], []
    for shot in sorted(set(found[ref]) & set(found[cam])):
        ids0, o0, q0 = found[ref][shot]
        idsc, _, qc = found[cam][shot]
        common, i0, ic = np.intersect1d(ids0, idsc, return_indices=True)
        if len(common) >= MIN_CORNERS:
            obj.append(o0[i0].astype(np.float32))
            p0.append(q0[i0].astype(np.float32))
            pc.append(qc[ic].astype(np.float32))
    if len(obj) < 2:
        raise CaptureError(f"camera {cam} shares {len(obj)} usable shot(s) with {ref}; need 2")
    (K0, d0, size0), (Kc, dc, _) = intr[ref], intr[cam]
    rms, *_, R, T, _, _ = cv2.stereoCalibrate(
        obj, p0, pc, K0, d0, Kc, dc, size0, flags=cv2.CALIB_FIX_INTRINSIC
    )
    ref2cam = np.eye(4)
    ref2cam[:3, :3], ref2cam[:3, 3] = R, np.asarray(T).reshape(3)
    U, _, Vt = np.linalg.svd(ref2cam[:3, :3])
    ref2cam[:3, :3] = U @ Vt
    w, h = intr[cam][2]
    return Camera(cam, w, h, Kc, dc, invert(ref2cam)), float(rms), len(obj)


def calibrate_folder(
    folder: str | Path, spec: CharucoSpec, *, fix_k3: bool = True
) -> tuple[Rig, CalibrationReport]:
    """:func:`calibrate_rig` on a calibration folder (see the module docstring)."""
    return calibrate_rig(load_views(folder), spec, fix_k3=fix_k3)
