"""A robot log of either kind read into a :class:`~teachfit.demonstrations.rawlog.RawLog`.

A ROS bag (ROS 1 ``.bag``, a ROS 2 folder, ``.db3`` or ``.mcap``) is read by its topics and
times itself by its header stamps; anything else is a CSV log read with a column map (TOML).
The options of one kind given for the other are refused, naming the option (``demo import``'s
flags) and the fix.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from teachfit.core.errors import TeachfitError
from teachfit.demonstrations.column_map import ColumnMap
from teachfit.demonstrations.csv_import import read_csv_log
from teachfit.demonstrations.frames import FrameTransform
from teachfit.demonstrations.rawlog import RawLog
from teachfit.demonstrations.rosbag_import import is_bag, read_bag


@dataclass(frozen=True)
class LogSource:
    """How to read a robot log.

    Parameters
    ----------
    columns : Path
        CSV column map (TOML); not used for a bag.
    rate : float or None
        Hz, for a CSV log without a time column (a bag's stamps give the time).
    pose_topic, wrench_topic : str or None
        Bag topics of the pose and of the wrench (the pose topic is required for a bag).
    wrench_sign : int
        Bag: +1 the wrench the environment exerts on the tool, -1 the wrench the robot applies.
    child_frame : str or None
        Bag: child frame of a tf topic.
    """

    columns: Path
    rate: float | None = None
    pose_topic: str | None = None
    wrench_topic: str | None = None
    wrench_sign: int = 1
    child_frame: str | None = None


def read_robot_log(
    log: Path, source: LogSource, transform: FrameTransform | None = None
) -> tuple[RawLog, FrameTransform | None]:
    """Read ``log`` (a bag or a CSV log) as ``source`` says; returns the raw log and the frame
    transform to apply: ``transform`` if given, else a CSV column map's own (a bag has none)."""
    if is_bag(log):
        if source.pose_topic is None:
            raise TeachfitError(f"{log} is a bag: give --pose-topic (and --wrench-topic)")
        if source.rate is not None:
            raise TeachfitError(f"{log} is a bag: its header stamps give the time, drop --rate")
        raw = read_bag(
            log,
            source.pose_topic,
            source.wrench_topic,
            wrench_sign=source.wrench_sign,
            child_frame=source.child_frame,
        )
        return raw, transform
    bag_only = {
        "--pose-topic": source.pose_topic,
        "--wrench-topic": source.wrench_topic,
        "--child-frame": source.child_frame,
        "--wrench-sign": None if source.wrench_sign == 1 else 1,
    }
    given = [option for option, value in bag_only.items() if value is not None]
    if given:
        raise TeachfitError(
            f"{given[0]} is for ROS bags; {log} is read as CSV with the map {source.columns}"
            + (" (set wrench_sign there)" if given[0] == "--wrench-sign" else "")
        )
    the_map = ColumnMap.from_toml(source.columns, rate_hz=source.rate)
    return read_csv_log(log, the_map), transform or the_map.transform
