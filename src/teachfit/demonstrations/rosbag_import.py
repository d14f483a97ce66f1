"""Read a demonstration from a ROS 1 bag, a ROS 2 bag (folder, ``.db3`` or ``.mcap``) with rosbags.

rosbags reads both ROS generations without a ROS installation. The pose topic may carry
``geometry_msgs/PoseStamped``, ``geometry_msgs/TransformStamped`` or ``tf2_msgs/TFMessage``
(then ``child_frame`` picks the transform, required when several child frames are published);
the optional wrench topic ``geometry_msgs/WrenchStamped``.

Time stamps are the message headers' (the bag's receive times only when every header stamp is
zero, with a note). The pose stamps are the time base; the wrench is interpolated linearly onto
them, and pose samples outside the wrench's time span are dropped (with a note). A wrench whose
``frame_id`` differs from the pose's is taken to be in the tool's axes (a wrist sensor) and
rotated into the pose frame with the tool orientation at each sample (with a note).
"""

from __future__ import annotations

import sqlite3
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from teachfit.core.errors import DatasetError
from teachfit.core.geometry import wxyz_to_rotation
from teachfit.demonstrations.dataset import MIN_SAMPLES
from teachfit.demonstrations.rawlog import RawLog

POSE_TYPES = (
    "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/TransformStamped",
    "tf2_msgs/msg/TFMessage",
)
WRENCH_TYPE = "geometry_msgs/msg/WrenchStamped"
BAG_SUFFIXES = (".bag", ".mcap", ".db3")


def is_bag(path: Path) -> bool:
    """Whether ``path`` looks like a bag (a ROS 1 ``.bag``, a ROS 2 folder or storage file)."""
    return path.suffix in BAG_SUFFIXES or path.is_dir()


@dataclass(frozen=True)
class _Stream:
    """Samples of one topic: header stamps (ns), bag stamps (ns), values (N, K), frame ids."""

    stamps: np.ndarray
    bag_stamps: np.ndarray
    values: np.ndarray
    frames: tuple[str, ...]


def _bag_errors() -> tuple[type[BaseException], ...]:
    """What rosbags and its storage libraries raise on a damaged or truncated bag (a corrupt
    header, record length, index, database page or message body)."""
    from rosbags.rosbag1 import ReaderError as Reader1Error
    from rosbags.rosbag2 import ReaderError as Reader2Error

    errors: list[type[BaseException]] = [Reader1Error, Reader2Error, OSError, ValueError]
    errors += [LookupError, AssertionError, ArithmeticError, MemoryError, EOFError]
    errors += [struct.error, sqlite3.Error]
    try:
        import apsw  # the SQLite binding rosbags may use for ROS 2 .db3 files
    except ImportError:
        pass
    else:
        errors.append(apsw.Error)
    return tuple(errors)


def _ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def _pose_rows(msg: Any, msgtype: str, child: str | None) -> list[tuple[int, str, list[float]]]:
    """(stamp ns, frame id, [x, y, z, qw, qx, qy, qz]) for each pose in one message."""
    if msgtype == "geometry_msgs/msg/PoseStamped":
        p, q = msg.pose.position, msg.pose.orientation
        return [(_ns(msg.header.stamp), msg.header.frame_id, [p.x, p.y, p.z, q.w, q.x, q.y, q.z])]
    items = msg.transforms if msgtype == "tf2_msgs/msg/TFMessage" else [msg]
    rows = []
    for tf in items:
        if child is None or tf.child_frame_id == child:
            p, q = tf.transform.translation, tf.transform.rotation
            frame = f"{tf.header.frame_id}>{tf.child_frame_id}"
            rows.append((_ns(tf.header.stamp), frame, [p.x, p.y, p.z, q.w, q.x, q.y, q.z]))
    return rows


def _read_topic(
    reader: Any, topic: str, kinds: tuple[str, ...], where: str, child: str | None
) -> _Stream:
    conns = [c for c in reader.connections if c.topic == topic]
    if not conns:
        listed = ", ".join(f"{c.topic} ({c.msgtype})" for c in reader.connections) or "none"
        raise DatasetError(f"no topic {topic!r} in the bag (topics: {listed})", path=where)
    msgtype = conns[0].msgtype
    if child is not None and msgtype == "geometry_msgs/msg/PoseStamped":
        raise DatasetError(
            f"topic {topic!r} carries {msgtype}, which has no child frame: drop --child-frame "
            "(it picks a transform on a tf or TransformStamped topic)",
            path=where,
        )
    if msgtype not in kinds:
        raise DatasetError(
            f"topic {topic!r} carries {msgtype}, expected one of {', '.join(kinds)}", path=where
        )
    stamps, bag, values, frames = [], [], [], []
    for conn, bag_ns, raw in reader.messages(connections=conns):
        msg = reader.deserialize(raw, conn.msgtype)
        if msgtype == WRENCH_TYPE:
            f, m = msg.wrench.force, msg.wrench.torque
            rows = [(_ns(msg.header.stamp), msg.header.frame_id, [f.x, f.y, f.z, m.x, m.y, m.z])]
        else:
            rows = _pose_rows(msg, msgtype, child)
        for stamp, frame, value in rows:
            stamps.append(stamp)
            bag.append(bag_ns)
            frames.append(frame)
            values.append(value)
    if msgtype != WRENCH_TYPE and msgtype != "geometry_msgs/msg/PoseStamped":
        children = sorted({f.split(">")[1] for f in frames})
        if child is None and len(children) > 1:
            raise DatasetError(
                f"topic {topic!r} has transforms to several child frames {children}: "
                "pick one with --child-frame",
                path=where,
            )
        frames = [f.split(">")[0] for f in frames]
    if not values:
        extra = f" with child frame {child!r}" if child else ""
        raise DatasetError(f"topic {topic!r} has no messages{extra}", path=where)
    return _Stream(
        np.array(stamps, dtype=np.int64),
        np.array(bag, dtype=np.int64),
        np.array(values, dtype=float),
        tuple(frames),
    )


def _timed(stream: _Stream, topic: str, where: str, notes: list[str]) -> tuple[np.ndarray, ...]:
    """Sorted stamps (ns), values and original message indices; duplicates dropped."""
    stamps = stream.stamps
    if not stamps.any():
        notes.append(f"every header stamp on {topic} is zero: used the bag's receive times")
        stamps = stream.bag_stamps
    order = np.argsort(stamps, kind="stable")
    stamps, values = stamps[order], stream.values[order]
    keep = np.concatenate([[True], np.diff(stamps) > 0])
    if not keep.all():
        notes.append(f"dropped {np.count_nonzero(~keep)} {topic} messages with repeated stamps")
    if np.any(order[1:] < order[:-1]):
        notes.append(f"{topic} messages were not in stamp order: sorted them by header stamp")
    return stamps[keep], values[keep], order[keep] + 1


def read_bag(
    path: str | Path,
    pose_topic: str,
    wrench_topic: str | None = None,
    *,
    wrench_sign: int = 1,
    child_frame: str | None = None,
) -> RawLog:
    """Read the pose (and wrench) topics of a bag into a :class:`RawLog`.

    Parameters
    ----------
    path : str or Path
        ROS 1 ``.bag`` file, ROS 2 bag folder, or a ROS 2 ``.db3`` / ``.mcap`` file.
    pose_topic, wrench_topic : str
        Topic names; without ``wrench_topic`` the demonstration has no wrench.
    wrench_sign : int
        +1: the topic holds the wrench the environment exerts on the tool; -1: the robot's.
    child_frame : str, optional
        For transform topics: the child frame (the tool) whose pose to read.

    Raises
    ------
    DatasetError
        Naming the bag for an unreadable bag, a missing topic, a wrong message type, too few
        messages or no overlap between the pose and wrench stamps.
    """
    path = _checked_path(path, wrench_sign)
    where = str(path)
    notes: list[str] = []
    poses, wrenches, generation = _read_streams(path, pose_topic, wrench_topic, child_frame)
    stamps, values, rows = _timed(poses, pose_topic, where, notes)
    meta: dict[str, Any] = {"source_file": path.name, "source_format": generation}
    meta.update(pose_topic=pose_topic, time_offset_s=float(stamps[0]) * 1e-9)
    topics = (pose_topic, wrench_topic)
    stamps, values, rows, wrench = _with_wrench(
        (stamps, values, rows, poses.frames[0]), wrenches, topics, wrench_sign, where, notes, meta
    )
    if stamps.size < MIN_SAMPLES:
        raise DatasetError(f"{stamps.size} pose messages, need at least {MIN_SAMPLES}", path=where)
    return RawLog(
        path=where,
        t=(stamps - stamps[0]).astype(float) * 1e-9,
        pos=values[:, :3],
        quat=_unit_quats(values[:, 3:], rows, pose_topic, where),
        wrench=wrench,
        frame=poses.frames[0] or "world",
        rows=rows,
        notes=tuple(notes),
        meta=meta,
        fix_in=None,
        quat_order="w,x,y,z",
        time_step_units=None,
    )


def _checked_path(path: str | Path, wrench_sign: int) -> Path:
    """``path`` as a Path; a wrench sign other than +1 or -1, or a bag that does not exist, is
    a :class:`DatasetError`."""
    path = Path(path)
    if wrench_sign not in (1, -1):
        raise DatasetError(f"--wrench-sign must be +1 or -1, got {wrench_sign}", path=str(path))
    if not path.exists():
        raise DatasetError("no such file or folder", path=str(path))
    return path


def _unit_quats(quat: np.ndarray, rows: np.ndarray, topic: str, where: str) -> np.ndarray:
    """The orientations (w, x, y, z) normalised; one off norm 1 by more than 1e-3 is a
    :class:`DatasetError` naming its message (``rows``)."""
    norms = np.linalg.norm(quat, axis=1)
    bad = np.flatnonzero(np.abs(norms - 1.0) > 1e-3)
    if bad.size:
        raise DatasetError(
            f"{topic} message {rows[bad[0]]}: orientation norm {norms[bad[0]]:.6g}, not 1",
            path=where,
        )
    return quat / norms[:, None]


def _read_streams(
    path: Path, pose_topic: str, wrench_topic: str | None, child_frame: str | None
) -> tuple[_Stream, _Stream | None, str]:
    """The pose stream (all in one frame), the wrench stream (None without ``wrench_topic``) and
    the bag's ROS generation (``"ros1"`` or ``"ros2"``); a bag rosbags cannot read, or poses in
    several frames, are a :class:`DatasetError`."""
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.typesys import Stores, get_typestore

    where = str(path)
    damaged: tuple[type[BaseException], ...] = (AnyReaderError, *_bag_errors())
    try:
        with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
            poses = _read_topic(reader, pose_topic, POSE_TYPES, where, child_frame)
            wrenches = None
            if wrench_topic is not None:
                wrenches = _read_topic(reader, wrench_topic, (WRENCH_TYPE,), where, None)
            generation = "ros2" if reader.is2 else "ros1"
    except damaged as exc:
        text = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise DatasetError(
            f"cannot read as a ROS bag ({text}): a bag cut short or damaged while recording can "
            "often be repaired with 'rosbag reindex' (ROS 1) or 'ros2 bag reindex' (ROS 2)",
            path=where,
        ) from exc
    frames = sorted(set(poses.frames))
    if len(frames) != 1:
        raise DatasetError(f"{pose_topic} poses are in several frames {frames}", path=where)
    return poses, wrenches, generation


def _with_wrench(
    poses: tuple[np.ndarray, np.ndarray, np.ndarray, str],
    wrenches: _Stream | None,
    topics: tuple[str, str | None],
    wrench_sign: int,
    where: str,
    notes: list[str],
    meta: dict[str, Any],
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """The pose samples (stamps ns, values, message indices) inside the wrench's time span and
    the wrench (N, N*m; times ``wrench_sign``) interpolated onto them, in the poses' frame; the
    poses as they are and no wrench without ``wrenches``. Notes the wrench topic, sign and frame
    in ``meta``."""
    stamps, values, rows, frame = poses
    if wrenches is None:
        return stamps, values, rows, None
    pose_topic, wrench_topic = topics[0], str(topics[1])  # a topic when there are wrenches
    w_stamps, w_values, _ = _timed(wrenches, wrench_topic, where, notes)
    inside = (stamps >= w_stamps[0]) & (stamps <= w_stamps[-1])
    if np.count_nonzero(inside) < MIN_SAMPLES:
        raise DatasetError(
            f"{pose_topic} and {wrench_topic} stamps do not overlap (poses "
            f"{stamps[0] * 1e-9:.3f}..{stamps[-1] * 1e-9:.3f} s, wrenches "
            f"{w_stamps[0] * 1e-9:.3f}..{w_stamps[-1] * 1e-9:.3f} s)",
            path=where,
        )
    if not inside.all():
        notes.append(
            f"dropped {np.count_nonzero(~inside)} {pose_topic} samples outside the time span "
            f"of {wrench_topic}"
        )
    stamps, values, rows = stamps[inside], values[inside], rows[inside]
    dt = (w_stamps - stamps[0]).astype(float)
    at = (stamps - stamps[0]).astype(float)
    wrench = np.column_stack([np.interp(at, dt, w_values[:, k]) for k in range(6)])
    wrench *= wrench_sign
    w_frame = wrenches.frames[0]
    if w_frame and w_frame != frame:
        rot = wxyz_to_rotation(values[:, 3:])
        wrench = np.hstack([rot.apply(wrench[:, :3]), rot.apply(wrench[:, 3:])])
        notes.append(
            f"{wrench_topic} is in {w_frame!r}: rotated it into {frame!r} with the tool "
            "orientation (assumes the sensor axes are the tool's)"
        )
    meta.update(wrench_topic=wrench_topic, wrench_sign=wrench_sign, wrench_frame=w_frame)
    return stamps, values, rows, wrench
