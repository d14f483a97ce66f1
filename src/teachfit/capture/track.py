"""From synchronised frames to the relative pose sequence ``L2G`` (the paper's G_T_L).

Per frame: detect markers in every camera, fuse each part's markers over cameras
(:func:`~teachfit.capture.fuse.fuse_part`), form ``L2G = inv(G2rig) @ L2rig`` with its
covariance, filter it in time (:class:`~teachfit.capture.temporal.PoseFilter`) and judge it.
A frame is valid when both parts were found, the predicted 1-sigma error of ``L2G`` is within
``max_std_mm`` / ``max_std_deg``, the RMS reprojection error within ``max_rms_px`` and the
filter accepted it. Invalid frames are marked with a reason and never filled in.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.capture.detect import DetectorConfig, detect_markers, make_detector
from teachfit.capture.fuse import FusionConfig, fuse_part, relative_pose
from teachfit.capture.markers import MarkerSet
from teachfit.capture.rig import Rig
from teachfit.capture.temporal import FilterConfig, PoseFilter
from teachfit.core.errors import CaptureError
from teachfit.core.geometry import rotation_to_wxyz
from teachfit.demonstrations.dataset import Demonstration, MetaValue

__all__ = ["STATUS", "Track", "TrackConfig", "Tracker", "track_frames"]

STATUS: tuple[str, ...] = ("ok", "no-reference", "no-moving", "low-quality", "gated")
"""Per-frame status codes (index into this tuple)."""


@dataclass(frozen=True)
class TrackConfig:
    """Settings of the tracker; the thresholds are 1-sigma predictions (mm, deg) and px."""

    detector: DetectorConfig = field(default_factory=DetectorConfig)
    fusion: FusionConfig = field(default_factory=FusionConfig)
    filter: FilterConfig | None = field(default_factory=FilterConfig)
    max_std_mm: float = 2.0
    max_std_deg: float = 2.0
    max_rms_px: float = 2.0

    def __post_init__(self) -> None:
        if min(self.max_std_mm, self.max_std_deg, self.max_rms_px) <= 0:
            raise CaptureError("quality thresholds must be > 0")


@dataclass(frozen=True, eq=False)
class Track:
    """A tracked sequence of T frames.

    Attributes
    ----------
    t : (T,) s
    L2G : (T, 4, 4) pose of the moving part in the reference part's frame (m); NaN where
        ``valid`` is False
    valid : (T,) bool
    status : (T,) int8, index into :data:`STATUS`
    std_mm, std_deg : (T,) predicted 1-sigma error of ``L2G`` (position of L's origin, rotation)
    rms_px : (T,) RMS reprojection error of the inlier corners, both parts
    n_markers : (T, 2) inlier markers of (reference, moving)
    n_cameras : (T,) cameras that saw an inlier marker
    """

    t: np.ndarray
    L2G: np.ndarray
    valid: np.ndarray
    status: np.ndarray
    std_mm: np.ndarray
    std_deg: np.ndarray
    rms_px: np.ndarray
    n_markers: np.ndarray
    n_cameras: np.ndarray

    @property
    def n_frames(self) -> int:
        """Number of frames T."""
        return int(self.t.shape[0])

    def to_demonstration(self, task: str, name: str = "", **meta: MetaValue) -> Demonstration:
        """The valid frames as a demonstration (``frame="G"``, ``child_frame="L"``,
        ``source="captured"``); ``meta`` records the frame counts, the dropped frames' indices
        and each kept sample's predicted error (mm)."""
        keep = np.flatnonzero(self.valid)
        if keep.size < 2:
            raise CaptureError(
                f"only {keep.size} of {self.n_frames} frames have a trustworthy pose; need 2 "
                f"(statuses: {self.summary()})"
            )
        T = self.L2G[keep]
        quat = rotation_to_wxyz(Rotation.from_matrix(T[:, :3, :3]))  # w >= 0
        info: dict[str, MetaValue] = {
            "frames_total": self.n_frames,
            "frames_valid": int(keep.size),
            "dropped_frames": [float(i) for i in np.flatnonzero(~self.valid)],
            "std_mm": [round(float(v), 4) for v in self.std_mm[keep]],
            "std_deg": [round(float(v), 4) for v in self.std_deg[keep]],
            **meta,
        }
        return Demonstration(
            t=self.t[keep],
            pos=T[:, :3, 3],
            quat=quat,
            wrench=None,
            task=task,
            source="captured",
            frame="G",
            child_frame="L",
            name=name,
            meta=info,
        )

    def summary(self) -> str:
        """Counts of frames per status, e.g. ``"ok 150, no-moving 4"``."""
        counts = np.bincount(self.status.astype(int), minlength=len(STATUS))
        return ", ".join(f"{s} {c}" for s, c in zip(STATUS, counts, strict=True) if c)


class Tracker:
    """Per-frame tracking state: detector, previous part poses, temporal filter."""

    def __init__(self, rig: Rig, markers: MarkerSet, cfg: TrackConfig | None = None) -> None:
        self.rig, self.markers, self.cfg = rig, markers, cfg or TrackConfig()
        self.detector = make_detector(markers.dictionary, self.cfg.detector)
        by_id = markers.by_id()
        self.parts = {
            p: {i: by_id[i] for i in markers.ids_of(p)} for p in (markers.reference, markers.moving)
        }
        self.known = set(by_id)
        self.filter = None if self.cfg.filter is None else PoseFilter(self.cfg.filter)
        self.prior: dict[str, np.ndarray | None] = {p: None for p in self.parts}
        self.seen = {p: 0 for p in self.parts}

    def detect(self, images: Iterable[np.ndarray]) -> list:
        """Detections of known markers in every camera's image."""
        out = []
        edges = self.cfg.detector.edges
        for cam, img in enumerate(images):
            c = self.rig.cameras[cam]
            intr = (c.K, c.dist) if edges else None
            out += detect_markers(self.detector, img, cam, self.known, intr)
        return out

    def step(self, t: float, images: Iterable[np.ndarray]) -> dict:
        """Process one synchronised frame; returns the fields of one :class:`Track` row."""
        dets = self.detect(images)
        poses = {}
        for part, mk in self.parts.items():
            pd = [d for d in dets if d.marker_id in mk]
            self.seen[part] += bool(pd)
            pose = fuse_part(pd, self.rig, mk, self.cfg.fusion, self.prior[part])
            poses[part] = pose
            self.prior[part] = None if pose is None else pose.part2rig
        row: dict[str, Any] = {
            "L2G": np.full((4, 4), np.nan),
            "std_mm": np.nan,
            "std_deg": np.nan,
            "rms_px": np.nan,
            "n_cameras": 0,
            "valid": False,
        }
        ref, mov = poses[self.markers.reference], poses[self.markers.moving]
        row["n_markers"] = [0 if p is None else len(p.markers) for p in (ref, mov)]
        if ref is None or mov is None:
            row["status"] = 1 if ref is None else 2
            return row
        L2G, cov = relative_pose(ref, mov)
        n = sum(len(p.markers) for p in (ref, mov))
        row.update(
            std_mm=1e3 * float(np.sqrt(np.trace(cov[3:, 3:]))),
            std_deg=float(np.degrees(np.sqrt(np.trace(cov[:3, :3])))),
            rms_px=float(
                np.sqrt((ref.rms_px**2 * len(ref.markers) + mov.rms_px**2 * len(mov.markers)) / n)
            ),
            n_cameras=len(set(ref.cameras) | set(mov.cameras)),
        )
        c = self.cfg
        if (
            row["std_mm"] > c.max_std_mm
            or row["std_deg"] > c.max_std_deg
            or row["rms_px"] > c.max_rms_px
        ):
            row["status"] = 3
            return row
        filtered = (
            L2G
            if self.filter is None
            else self.filter.update(t, L2G, 1e-3 * row["std_mm"], float(np.radians(row["std_deg"])))
        )
        if filtered is None:
            row["status"] = 4
            return row
        row.update(L2G=filtered, valid=True, status=0)
        return row


def track_frames(
    frames: Iterable[tuple[float, list[np.ndarray]]],
    rig: Rig,
    markers: MarkerSet,
    cfg: TrackConfig | None = None,
    progress: Callable[[int], None] | None = None,
) -> Track:
    """Track every frame of a synchronised source (see :mod:`.sources`).

    Raises
    ------
    CaptureError
        No frame, or a part whose markers were never detected in any frame of any camera.
    """
    tracker = Tracker(rig, markers, cfg)
    rows, times = [], []
    for k, (t, images) in enumerate(frames):
        if len(images) != len(rig):
            raise CaptureError(f"frame {k} has {len(images)} images, the rig {len(rig)} cameras")
        rows.append(tracker.step(t, images))
        times.append(t)
        if progress is not None:
            progress(k + 1)
    if not rows:
        raise CaptureError("no frame to track")
    for part, count in tracker.seen.items():
        if count == 0:
            raise CaptureError(
                f"no marker of part {part!r} (ids {markers.ids_of(part)}, {markers.dictionary}) "
                f"was detected in any of the {len(rows)} frames of any camera; check the marker "
                "file's dictionary and ids, the lighting and the focus"
            )
    stack = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    return Track(
        t=np.asarray(times, dtype=float),
        L2G=stack["L2G"],
        valid=stack["valid"].astype(bool),
        status=stack["status"].astype(np.int8),
        std_mm=stack["std_mm"].astype(float),
        std_deg=stack["std_deg"].astype(float),
        rms_px=stack["rms_px"].astype(float),
        n_markers=stack["n_markers"].astype(int),
        n_cameras=stack["n_cameras"].astype(int),
    )
