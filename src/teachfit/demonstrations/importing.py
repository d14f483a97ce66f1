"""From a :class:`~teachfit.demonstrations.rawlog.RawLog` to checked demonstrations.

Order of work: a fixed frame transform is applied to the whole log; the whole-log checks run
(``rate``, ``orientation``, ``wrench_sign``); the log is cut into pieces (or kept whole); each
piece is re-anchored at its first pose if asked, re-timed to start at t = 0 and checked
(``duration``, ``extent``, ``speed``). A failed check not accepted is a
:class:`~teachfit.core.errors.DatasetError` naming the file and the fix.

Each demonstration's ``meta`` records where it came from: ``source_file``, ``source_format``,
``source_frame``, ``source2frame`` (pose of the log frame in the stored frame, ``[x, y, z, qw,
qx, qy, qz]``), ``time_offset_s`` (first time stamp, s), ``source_rows`` (first and last CSV
row or bag message) and, for a piece of a segmented log, ``segment``, ``segment_start_s`` and
``segmented_by``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.dataset import Demonstration
from teachfit.demonstrations.frames import FrameTransform
from teachfit.demonstrations.plausibility import (
    Limits,
    check_demo_shape,
    check_orientation,
    check_rate,
    check_wrench_sign,
    enforce,
)
from teachfit.demonstrations.rawlog import RawLog
from teachfit.demonstrations.segment import Segmenter


@dataclass(frozen=True)
class ImportOptions:
    """How a log becomes demonstrations.

    Parameters
    ----------
    transform : FrameTransform or None
        Frame transform applied on import; None keeps the log's frame.
    limits : Limits
        Plausibility limits.
    accept : frozenset of str
        Checks whose failure is accepted (noted, not an error); ``"all"`` accepts every one.
    segmenter : Segmenter or None
        Cut the log into several demonstrations; None keeps it whole.
    """

    transform: FrameTransform | None = None
    limits: Limits = field(default_factory=Limits)
    accept: frozenset[str] = frozenset()
    segmenter: Segmenter | None = None


@dataclass(frozen=True)
class Piece:
    """Summary of one imported demonstration, for a table (s, mm, N)."""

    name: str
    start_s: float
    duration_s: float
    samples: int
    extent_mm: tuple[float, float]
    peak_force_n: float | None


@dataclass(frozen=True)
class ImportResult:
    """The demonstrations, their summaries and what was noticed on the way."""

    demos: tuple[Demonstration, ...]
    pieces: tuple[Piece, ...]
    notes: tuple[str, ...]


def _fixed_transform(log: RawLog, transform: FrameTransform | None) -> tuple[RawLog, list[float]]:
    """Apply a fixed (not first-pose) transform to the whole log."""
    identity = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    if transform is None or transform.first_pose:
        return log, identity
    pos, quat, wrench, pose = transform.apply(log.pos, log.quat, log.wrench)
    return replace(log, pos=pos, quat=quat, wrench=wrench, frame=transform.to), pose


def build_demos(log: RawLog, *, task: str, name: str, options: ImportOptions) -> ImportResult:
    """Checked demonstrations (``source="imported"``) from ``log``.

    Raises
    ------
    DatasetError
        Naming the log for a failed plausibility check that was not accepted, or a segmentation
        that found nothing.
    """
    source_frame = log.frame
    log, source2frame = _fixed_transform(log, options.transform)
    notes = list(log.notes)
    limits = options.limits
    whole = [check_rate(log, limits), check_orientation(log, limits)]
    whole.append(check_wrench_sign(log, limits))
    notes += enforce([f for f in whole if f is not None], options.accept, log.path)
    ranges = [(0, log.n_samples)]
    seg = options.segmenter
    if seg is not None:
        ranges = seg.split(log)
        if not ranges:
            what = {
                "contact": f"no contact phase above {seg.force_on_n:g} N",
                "window": "no window",
                "marker": "no marker run"
                + (f" of {seg.marker_value!r}" if seg.marker_value else ""),
            }[seg.mode]
            raise DatasetError(
                f"{what} lasting at least {seg.min_duration_s:g} s: nothing to import "
                "(lower the threshold or --min-duration)",
                path=log.path,
            )
    demos, pieces = [], []
    for k, (a, b) in enumerate(ranges):
        piece = log.sliced(a, b)
        label = name if seg is None else f"{name}-{k:02d}"
        context = (
            ""
            if seg is None
            else f"demonstration {label} ({log.row_word} {piece.rows[0]}-{piece.rows[-1]}): "
        )
        pos, quat, wrench = piece.pos, piece.quat, piece.wrench
        frame, pose = piece.frame, source2frame
        if options.transform is not None and options.transform.first_pose:
            pos, quat, wrench, origin = options.transform.apply(pos, quat, wrench)
            frame = options.transform.target(piece.frame)
            pose = [*(np.array(source2frame[:3]) + origin[:3]).tolist(), *source2frame[3:]]
        t = piece.t - piece.t[0]
        notes += enforce(check_demo_shape(t, pos, log, limits), options.accept, log.path, context)
        meta = dict(log.meta)
        meta.update(
            source_frame=source_frame,
            source2frame=[float(v) for v in pose],
            source_rows=[int(piece.rows[0]), int(piece.rows[-1])],
            time_offset_s=float(log.meta.get("time_offset_s", 0.0)) + float(piece.t[0]),
        )
        if seg is not None:
            meta.update(segment=k, segment_start_s=float(piece.t[0]), segmented_by=seg.mode)
        try:
            demo = Demonstration(
                t=t,
                pos=pos,
                quat=quat,
                wrench=wrench,
                task=task,
                source="imported",
                frame=frame,
                name=label,
                meta=meta,
            )
        except DatasetError as exc:  # not expected after the reader's checks
            raise DatasetError(f"{context}{exc}", path=log.path) from exc
        demos.append(demo)
        force = None if wrench is None else float(np.linalg.norm(wrench[:, :3], axis=1).max())
        ex, ey = (float(v) for v in np.ptp(pos[:, :2], axis=0) * 1e3)
        pieces.append(
            Piece(label, float(piece.t[0]), demo.duration, demo.n_samples, (ex, ey), force)
        )
    if demos[0].frame != "world":
        notes.append(
            f"poses are stored in frame {demos[0].frame!r}, not the simulation world: learning "
            "uses them relative to the first pose, but a start pose read from them (search run "
            "--demo) is not a world pose; to store world poses give the log-to-world transform "
            "([transform] in the map, or --transform world:x,y,z,qw,qx,qy,qz)"
        )
    return ImportResult(tuple(demos), tuple(pieces), tuple(notes))
