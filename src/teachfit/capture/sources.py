"""Synchronised frame sources: recorded videos (checked against each other) and live cameras.

A source yields ``(t, images)`` per frame: the time stamp (s) and one grey (H, W) uint8 image
per camera, in rig order.
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Iterator, Sequence
from pathlib import Path

import cv2
import numpy as np

from teachfit.capture.rig import Rig
from teachfit.core.errors import CaptureError

__all__ = ["CameraSet", "VideoSet"]


def _check_size(img: np.ndarray, rig: Rig, i: int, label: str) -> None:
    cam = rig.cameras[i]
    if img.shape[:2] != (cam.height, cam.width):
        raise CaptureError(
            f"{label}: frames are {img.shape[1]}x{img.shape[0]} px but rig camera "
            f"{cam.name!r} is calibrated for {cam.width}x{cam.height}"
        )


def _fingerprint(path: Path, head: int = 1 << 20) -> str:
    """Size and hash of the first MiB: equal for the same video under two names."""
    with path.open("rb") as fh:
        digest = hashlib.sha1(fh.read(head), usedforsecurity=False).hexdigest()
    return f"{path.stat().st_size}:{digest}"


class VideoSet:
    """Videos of the rig's cameras (one per camera, same order), read in lock step.

    Raises
    ------
    CaptureError
        A video that cannot be opened or decoded, a count that differs from the rig's, frame
        sizes that differ from the calibration, different frame rates or frame counts, or
        time stamps that drift apart by more than half a frame.
    """

    def __init__(self, paths: Sequence[str | Path], rig: Rig, *, threads: int = 0) -> None:
        self.paths = [Path(p) for p in paths]
        self.rig = rig
        if len(self.paths) != len(rig):
            raise CaptureError(
                f"{len(self.paths)} video(s) given but the rig has {len(rig)} cameras"
            )
        for p in self.paths:
            if not p.is_file():
                raise CaptureError(f"video {p}: no such file")
        seen: dict[str, Path] = {}
        for p in self.paths:
            key = _fingerprint(p)
            if key in seen:
                raise CaptureError(
                    f"videos {seen[key]} and {p} are the same file: each camera needs its own"
                )
            seen[key] = p
        self.caps = []
        for p in self.paths:
            cap = cv2.VideoCapture(str(p), cv2.CAP_FFMPEG, [cv2.CAP_PROP_N_THREADS, threads])
            if not cap.isOpened():
                raise CaptureError(
                    f"video {p}: cannot be opened (not a video, or unsupported codec)"
                )
            self.caps.append(cap)
        self.fps = [float(c.get(cv2.CAP_PROP_FPS)) for c in self.caps]
        counts = [int(c.get(cv2.CAP_PROP_FRAME_COUNT)) for c in self.caps]
        if any(not f > 0 for f in self.fps):
            raise CaptureError(f"video {self.paths[self.fps.index(min(self.fps))]}: no frame rate")
        if max(self.fps) - min(self.fps) > 1e-3 * max(self.fps):
            raise CaptureError(f"frame rates differ between cameras: {self._list(self.fps)}")
        if len(set(counts)) > 1:
            raise CaptureError(f"frame counts differ between cameras: {self._list(counts)}")
        self.n_frames = counts[0]

    def _list(self, values: Sequence[object]) -> str:
        return ", ".join(f"{p}: {v}" for p, v in zip(self.paths, values, strict=True))

    def close(self) -> None:
        """Release the decoders."""
        for c in self.caps:
            c.release()

    def __iter__(self) -> Iterator[tuple[float, list[np.ndarray]]]:
        period = 1.0 / self.fps[0]
        k = 0
        try:
            while True:
                oks = [c.grab() for c in self.caps]
                if not any(oks):
                    break
                if not all(oks):
                    ended = [p.name for p, ok in zip(self.paths, oks, strict=True) if not ok]
                    raise CaptureError(
                        f"videos end at different frames: {', '.join(ended)} ended at frame {k}"
                    )
                stamps = [c.get(cv2.CAP_PROP_POS_MSEC) / 1e3 for c in self.caps]
                if max(stamps) - min(stamps) > 0.5 * period:
                    raise CaptureError(
                        f"time stamps of frame {k} differ by more than half a frame: "
                        f"{self._list([f'{s:.3f} s' for s in stamps])}"
                    )
                images = []
                for i, (c, p) in enumerate(zip(self.caps, self.paths, strict=True)):
                    ok, img = c.retrieve()
                    if not ok or img is None:
                        raise CaptureError(f"video {p}: frame {k} cannot be decoded")
                    grey = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
                    _check_size(grey, self.rig, i, f"video {p}")
                    images.append(grey)
                yield k * period, images
                k += 1
        finally:
            self.close()
        if k == 0:
            raise CaptureError(f"video {self.paths[0]}: no frame could be decoded")


class CameraSet:
    """Live cameras (OpenCV device indices, rig order); stops after ``max_frames`` frames or
    ``max_seconds``, or on Ctrl-C. Time stamps are the host's monotonic clock."""

    def __init__(
        self, indices: Sequence[int], rig: Rig, *, max_frames: int = 300, max_seconds: float = 60.0
    ) -> None:
        if len(indices) != len(rig):
            raise CaptureError(f"{len(indices)} camera(s) given but the rig has {len(rig)}")
        self.rig, self.max_frames, self.max_seconds = rig, max_frames, max_seconds
        self.caps = []
        for i, idx in enumerate(indices):
            cap = cv2.VideoCapture(int(idx))
            if not cap.isOpened():
                self.close()
                raise CaptureError(f"camera {idx} cannot be opened")
            cam = rig.cameras[i]
            cap.set(cv2.CAP_PROP_FRAME_WIDTH, cam.width)
            cap.set(cv2.CAP_PROP_FRAME_HEIGHT, cam.height)
            self.caps.append(cap)
        self.n_frames = max_frames

    def close(self) -> None:
        """Release the cameras."""
        for c in self.caps:
            c.release()

    def __iter__(self) -> Iterator[tuple[float, list[np.ndarray]]]:
        t0 = time.monotonic()
        try:
            for _ in range(self.max_frames):
                t = time.monotonic() - t0
                if t > self.max_seconds or not all(c.grab() for c in self.caps):
                    break
                images = []
                for i, c in enumerate(self.caps):
                    ok, img = c.retrieve()
                    if not ok:
                        raise CaptureError(f"camera {i}: frame cannot be read")
                    grey = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
                    _check_size(grey, self.rig, i, f"camera {i}")
                    images.append(grey)
                yield t, images
        except KeyboardInterrupt:
            return
        finally:
            self.close()
