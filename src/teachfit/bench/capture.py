"""``teachfit bench capture``: accuracy of the captured ``L2G`` against ground truth with 1, 2
and 3 cameras, and tracking speed per 1080p stream on one core.

Accuracy: a synthetic capture (:mod:`teachfit.capture.synth`, H.264 videos) is tracked with
cameras ``[0]``, ``[0, 1]``, ``[0, 1, 2]``; per valid frame the position error is
``|p_est - p_true|`` of L's origin in G (mm) and the rotation error the angle of
``R_true^T R_est`` (deg). Speed: one 1080p video decoded and tracked with OpenCV limited to one
thread (decoding, detection, edge refinement, fusion), in frames per second of wall time.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from teachfit.capture.geometry import rotation_angle_deg
from teachfit.capture.markers import MarkerSet, read_markers
from teachfit.capture.rig import Rig, read_rig
from teachfit.capture.sources import VideoSet
from teachfit.capture.synth import SynthConfig, write_synth_capture
from teachfit.capture.track import Track, TrackConfig, Tracker, track_frames
from teachfit.core.geometry import wxyz_to_rotation
from teachfit.demonstrations.dataset import Demonstration, read_demo

__all__ = [
    "TARGET_DEG",
    "TARGET_FPS",
    "TARGET_MM",
    "AccuracyRow",
    "CaptureBench",
    "pose_errors",
    "run_capture_bench",
    "to_markdown",
]

TARGET_MM, TARGET_DEG, TARGET_FPS = 1.0, 1.0, 30.0


@dataclass(frozen=True)
class AccuracyRow:
    """Errors of one camera subset: median and 95th percentile (mm, deg) over valid frames."""

    cameras: int
    filtered: bool
    frames: int
    valid: int
    med_mm: float
    p95_mm: float
    med_deg: float
    p95_deg: float


@dataclass(frozen=True)
class CaptureBench:
    """Results: accuracy rows, speed (fps per stream and ms per stage) and the set-up."""

    rows: tuple[AccuracyRow, ...]
    fps: float
    ms_decode: float
    ms_track: float
    stream: str
    setup: str


def pose_errors(track: Track, truth: Demonstration) -> tuple[np.ndarray, np.ndarray]:
    """Position (mm) and rotation (deg) errors of ``track``'s valid frames against ``truth``
    (matched by frame index; both must have the same number of frames)."""
    if truth.n_samples != track.n_frames:
        raise ValueError(f"truth has {truth.n_samples} samples, track {track.n_frames} frames")
    ok = track.valid
    R_true = wxyz_to_rotation(np.asarray(truth.quat)[ok]).as_matrix()
    est = track.L2G[ok]
    mm = 1e3 * np.linalg.norm(est[:, :3, 3] - np.asarray(truth.pos)[ok], axis=1)
    deg = rotation_angle_deg(np.transpose(R_true, (0, 2, 1)) @ est[:, :3, :3])
    return mm, deg


def _row(n: int, filtered: bool, track: Track, truth: Demonstration) -> AccuracyRow:
    mm, deg = pose_errors(track, truth)
    stats = [
        float(np.percentile(x, q)) if x.size else float("nan") for x in (mm, deg) for q in (50, 95)
    ]
    return AccuracyRow(n, filtered, track.n_frames, int(track.valid.sum()), *stats)


def run_capture_bench(
    workdir: str | Path,
    cfg: SynthConfig,
    *,
    seed: int = 0,
    track_cfg: TrackConfig | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> CaptureBench:
    """Render a synthetic capture into ``workdir``, then measure accuracy and speed."""
    paths = write_synth_capture(
        workdir,
        seed=seed,
        cfg=cfg,
        progress=None if progress is None else lambda d, n: progress("render", d, n),
    )
    rig, markers = read_rig(paths["rig"]), read_markers(paths["markers"])
    truth = read_demo(paths["truth"])
    videos = [paths[f"video{i}"] for i in range(len(rig))]
    track_cfg = track_cfg or TrackConfig()
    rows = _accuracy_rows(rig, markers, videos, truth, track_cfg, progress)
    # speed: the first 1080p stream (else the largest), one OpenCV thread, decoding included
    sizes = [(c.width * c.height, i) for i, c in enumerate(rig.cameras)]
    hd = [i for i, c in enumerate(rig.cameras) if (c.width, c.height) == (1920, 1080)]
    idx = hd[0] if hd else max(sizes)[1]
    n, t_dec, t_trk = _time_one_stream(rig.subset([idx]), markers, videos[idx], track_cfg)
    cam = rig.cameras[idx]
    setup = (
        f"{len(rig)} cameras ({', '.join(f'{c.width}x{c.height}' for c in rig.cameras)}), "
        f"{cfg.distance} m, noise {cfg.noise} grey levels, blur {cfg.blur} px, lighting "
        f"{cfg.lighting}, H.264 crf {cfg.crf}, {truth.n_samples} frames, seed {seed}"
    )
    return CaptureBench(
        rows=tuple(rows),
        fps=n / (t_dec + t_trk),
        ms_decode=1e3 * t_dec / n,
        ms_track=1e3 * t_trk / n,
        stream=f"{cam.name} {cam.width}x{cam.height}",
        setup=setup,
    )


def _accuracy_rows(
    rig: Rig,
    markers: MarkerSet,
    videos: list[Path],
    truth: Demonstration,
    track_cfg: TrackConfig,
    progress: Callable[[str, int, int], None] | None,
) -> list[AccuracyRow]:
    """Track ``videos`` with the first 1, 2, ... cameras of ``rig`` and score each against
    ``truth``; with a temporal filter, all cameras once more without it (the filter's share)."""
    rows = []
    runs = [(n, track_cfg) for n in range(1, len(rig) + 1)]
    if track_cfg.filter is not None:  # the temporal filter's share: all cameras without it
        runs.append((len(rig), replace(track_cfg, filter=None)))
    for n, tcfg in runs:
        sub = rig.subset(range(n))
        label = f"{n} cam" + ("" if tcfg.filter is not None else ", no filter")

        def tick(d: int, lb: str = label) -> None:
            if progress is not None:
                progress(lb, d, truth.n_samples)

        track = track_frames(VideoSet(videos[:n], sub), sub, markers, tcfg, progress=tick)
        rows.append(_row(n, tcfg.filter is not None, track, truth))
    return rows


def _time_one_stream(
    sub: Rig, markers: MarkerSet, video: Path, track_cfg: TrackConfig
) -> tuple[int, float, float]:
    """Decode and track ``video`` (one camera, ``sub``) with one OpenCV thread: the number of
    frames and the wall time (s) spent decoding and tracking them."""
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        tracker = Tracker(sub, markers, track_cfg)
        t_dec = t_trk = 0.0
        n = 0
        frames = iter(VideoSet([video], sub, threads=1))
        while True:
            t0 = time.perf_counter()
            item = next(frames, None)
            t1 = time.perf_counter()
            if item is None:
                break
            tracker.step(*item)
            t_dec += t1 - t0
            t_trk += time.perf_counter() - t1
            n += 1
    finally:
        cv2.setNumThreads(threads)
    return n, t_dec, t_trk


def to_markdown(b: CaptureBench, command: str = "teachfit bench capture") -> str:
    """The results as a BENCHMARKS.md section."""
    lines = [
        "## Capture from video (`teachfit bench capture`)",
        "",
        f"`{command}` - {b.setup}.",
        "",
        "| cameras | filter | valid frames | median mm | p95 mm | median deg | p95 deg |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in b.rows:
        lines.append(
            f"| {r.cameras} | {'yes' if r.filtered else 'no'} | {r.valid}/{r.frames} | "
            f"{r.med_mm:.3f} | {r.p95_mm:.3f} | "
            f"{r.med_deg:.3f} | {r.p95_deg:.3f} |"
        )
    lines += [
        "",
        f"Speed, {b.stream}, one core: {b.fps:.1f} fps (decode {b.ms_decode:.1f} ms + track "
        f"{b.ms_track:.1f} ms per frame); target {TARGET_FPS:.0f} fps, ratio "
        f"{b.fps / TARGET_FPS:.2f}. Accuracy target with 3 cameras: median <= {TARGET_MM} mm "
        f"and <= {TARGET_DEG} deg.",
    ]
    return "\n".join(lines) + "\n"
