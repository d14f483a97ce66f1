"""From a :class:`~teachfit.demonstrations.rawlog.RawLog` to checked demonstrations.

Order of work: a fixed frame transform is applied to the whole log; the whole-log checks run
(``rate``, ``wrench_sign``); the log is cut into pieces (or kept whole); each piece is checked
(``orientation``, ``duration``, ``extent``, ``speed``), re-anchored at its first pose if asked
and re-timed to start at t = 0. A failed check not accepted is a
:class:`~teachfit.core.errors.DatasetError` naming the file and the fix.

Each demonstration's ``meta`` records where it came from: ``source_file``, ``source_format``,
``source_frame``, ``source2frame`` (pose of the log frame in the stored frame, ``[x, y, z, qw,
qx, qy, qz]``), ``time_offset_s`` (first time stamp, s), ``source_rows`` (first and last CSV
row or bag message), ``rate_hz`` (sampling rate, Hz) and, for a piece of a segmented log,
``segment``, ``segment_start_s`` and ``segmented_by``.
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
from teachfit.demonstrations.rawlog import RawLog, sampling_rate
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
    rate_hz: float
    extent_mm: tuple[float, float]
    peak_force_n: float | None


@dataclass(frozen=True)
class ImportResult:
    """The demonstrations, their summaries and what was noticed on the way."""

    demos: tuple[Demonstration, ...]
    pieces: tuple[Piece, ...]
    notes: tuple[str, ...]


@dataclass(frozen=True)
class Labels:
    """What one demonstration is called: its task, name and the metadata of its piece."""

    task: str
    name: str
    meta: dict


def _fixed_transform(log: RawLog, transform: FrameTransform | None) -> tuple[RawLog, list[float]]:
    """Apply a fixed (not first-pose) transform to the whole log."""
    identity = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    if transform is None or transform.first_pose:
        return log, identity
    pos, quat, wrench, pose = transform.apply(log.pos, log.quat, log.wrench)
    return replace(log, pos=pos, quat=quat, wrench=wrench, frame=transform.to), pose


def _ranges(log: RawLog, seg: Segmenter | None) -> list[tuple[int, int]]:
    """Index ranges of the demonstrations: the whole log, or the pieces ``seg`` keeps."""
    if seg is None:
        return [(0, log.n_samples)]
    ranges = seg.split(log)
    if not ranges:
        what = {
            "contact": f"no contact phase above {seg.force_on_n:g} N",
            "window": "no window",
            "marker": "no marker run" + (f" of {seg.marker_value!r}" if seg.marker_value else ""),
        }[seg.mode]
        raise DatasetError(
            f"{what} lasting at least {seg.min_duration_s:g} s: nothing to import "
            "(lower the threshold or --min-duration)",
            path=log.path,
        )
    return ranges


def _piece_demo(
    piece: RawLog, source2frame: list[float], options: ImportOptions, label: Labels
) -> Demonstration:
    """The demonstration of one piece of a log (already checked), re-anchored and re-timed."""
    pos, quat, wrench = piece.pos, piece.quat, piece.wrench
    frame, pose = piece.frame, source2frame
    if options.transform is not None and options.transform.first_pose:
        pos, quat, wrench, origin = options.transform.apply(pos, quat, wrench)
        frame = options.transform.target(piece.frame)
        pose = [*(np.array(source2frame[:3]) + origin[:3]).tolist(), *source2frame[3:]]
    meta = dict(piece.meta)
    meta.update(
        source2frame=[float(v) for v in pose],
        source_rows=[int(piece.rows[0]), int(piece.rows[-1])],
        time_offset_s=float(piece.meta.get("time_offset_s", 0.0)) + float(piece.t[0]),
        rate_hz=sampling_rate(piece.t),
    )
    meta.update(label.meta)
    return Demonstration(
        t=piece.t - piece.t[0],
        pos=pos,
        quat=quat,
        wrench=wrench,
        source="imported",
        frame=frame,
        meta=meta,
        task=label.task,
        name=label.name,
    )


def build_demos(log: RawLog, *, task: str, name: str, options: ImportOptions) -> ImportResult:
    """Checked demonstrations (``source="imported"``) from ``log``.

    The whole log is checked for its rate and wrench sign; each demonstration cut from it for
    its orientation (a long log may turn the tool between demonstrations), duration, extent and
    speed. Each demonstration's ``meta["rate_hz"]`` is its sampling rate
    (:func:`~teachfit.demonstrations.rawlog.sampling_rate`).

    Raises
    ------
    DatasetError
        Naming the log for a failed plausibility check that was not accepted, or a segmentation
        that found nothing.
    """
    source = log
    log, source2frame = _fixed_transform(log, options.transform)
    notes, limits, seg = list(log.notes), options.limits, options.segmenter
    whole = [check_rate(log, limits), check_wrench_sign(log, limits)]
    notes += enforce([f for f in whole if f is not None], options.accept, log.path)
    demos, pieces = [], []
    for k, (a, b) in enumerate(_ranges(log, seg)):
        piece = log.sliced(a, b)
        label = name if seg is None else f"{name}-{k:02d}"
        context = (
            ""
            if seg is None
            else f"demonstration {label} ({log.row_word} {piece.rows[0]}-{piece.rows[-1]}): "
        )
        # the orientation of the log as read (a fixed rotation changes no tilt or step), so
        # that the fix can name the component order that fits
        found = [check_orientation(source.sliced(a, b), limits)]
        found += check_demo_shape(piece.t - piece.t[0], piece.pos, log, limits)
        notes += enforce([f for f in found if f is not None], options.accept, log.path, context)
        extra: dict[str, object] = {"source_frame": source.frame}
        if seg is not None:
            extra.update(segment=k, segment_start_s=float(piece.t[0]), segmented_by=seg.mode)
        try:
            demo = _piece_demo(piece, source2frame, options, Labels(task, label, extra))
        except DatasetError as exc:  # not expected after the reader's checks
            raise DatasetError(f"{context}{exc}", path=log.path) from exc
        demos.append(demo)
        pieces.append(_summary(demo, float(piece.t[0])))
    if demos[0].frame != "world":
        notes.append(
            f"poses are stored in frame {demos[0].frame!r}, not the simulation world: learning "
            "uses them relative to the first pose, but a start pose read from them (search run "
            "--demo) is not a world pose; to store world poses give the log-to-world transform "
            "([transform] in the map, or --transform world:x,y,z,qw,qx,qy,qz)"
        )
    return ImportResult(tuple(demos), tuple(pieces), tuple(notes))


def _summary(demo: Demonstration, start_s: float) -> Piece:
    wrench = demo.wrench
    force = None if wrench is None else float(np.linalg.norm(wrench[:, :3], axis=1).max())
    ex, ey = (float(v) for v in np.ptp(demo.pos[:, :2], axis=0) * 1e3)
    stored = demo.meta["rate_hz"]
    rate = float(stored) if isinstance(stored, int | float) else float("nan")
    return Piece(demo.name or "", start_s, demo.duration, demo.n_samples, rate, (ex, ey), force)
