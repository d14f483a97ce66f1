"""Test helpers: small generated robot logs shaped like public Franka Panda logs (20 Hz, base
frame ``panda_link0``, tool pointing down), written into ``tmp_path`` by the tests."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore

RATE = 20.0
FIELDS = ("x", "y", "z", "qx", "qy", "qz", "qw", "fx", "fy", "fz", "tx", "ty", "tz")


def tool_down_quat(yaw: np.ndarray) -> np.ndarray:
    """(T, 4) w-x-y-z: the tool z-axis pointing down (180 deg about x), then ``yaw`` about z."""
    half = np.asarray(yaw) / 2.0
    zeros = np.zeros_like(half)
    return np.stack([zeros, np.cos(half), np.sin(half), zeros], axis=1)


def _phase(
    seconds: float,
    rng: np.random.Generator,
    start: np.ndarray,
    end: np.ndarray,
    contact: bool,
    yaw: tuple[float, float],
) -> dict[str, np.ndarray]:
    n = int(round(seconds * RATE))
    s = np.linspace(0.0, 1.0, n, endpoint=False)[:, None]
    pos = start + (end - start) * s
    wrench = rng.normal(0.0, 0.2, size=(n, 6)) * [1, 1, 1, 0.01, 0.01, 0.01]
    if contact:  # a spiral search pressed onto the surface: +z force on the tool
        turns = 3.0 * 2.0 * np.pi * s[:, 0]
        radius = 0.012 * s[:, 0]
        pos = pos + np.column_stack([radius * np.cos(turns), radius * np.sin(turns), 0 * turns])
        wrench[:, 2] += 8.0 + rng.normal(0.0, 0.5, n)
        wrench[:, :2] += rng.normal(0.0, 0.8, (n, 2))
    quat = tool_down_quat(np.linspace(yaw[0], yaw[1], n, endpoint=False))
    return {"pos": pos, "quat": quat, "wrench": wrench}


def panda_log(kind: str = "search", seed: int = 0) -> dict[str, np.ndarray]:
    """Samples of a generated log: ``t`` (s), ``pos`` m, ``quat`` w-x-y-z, ``wrench`` (the
    environment on the tool), all in the base frame.

    ``"search"``: one 25 s demonstration (5 s approach, 20 s spiral search in contact, yaw
    sweeping 278 deg). ``"tasks"``: 285 s, three tasks 150 mm apart, each a 45 s transfer then
    a 50 s search in contact.
    """
    rng = np.random.default_rng(seed)
    top, surface = 0.30, 0.25
    if kind == "search":
        hole = np.array([0.45, -0.10, surface])
        above = hole + [0.0, 0.0, top - surface]
        phases = [
            _phase(5.0, rng, above, hole, False, (0.0, np.radians(30))),
            _phase(20.0, rng, hole, hole, True, (np.radians(30), np.radians(278))),
        ]
    else:
        holes = [np.array([x, y, surface]) for x, y in ((0.30, 0.0), (0.45, 0.15), (0.60, -0.05))]
        phases, here = [], np.array([0.45, 0.0, top])
        for hole in holes:
            phases.append(_phase(45.0, rng, here, hole, False, (0.0, 0.0)))
            phases.append(_phase(50.0, rng, hole, hole, True, (0.0, np.radians(20))))
            here = hole + [0.0, 0.0, top - surface]
    out = {k: np.concatenate([p[k] for p in phases]) for k in ("pos", "quat", "wrench")}
    out["t"] = np.arange(out["pos"].shape[0]) / RATE
    return out


def tilted_between_tasks(log: dict[str, np.ndarray], degrees: float = 60.0) -> dict:
    """A ``"tasks"`` log whose tool tilts about the base x-axis during the transfers: 0 deg at
    the first task, ``degrees`` / 2 at the second, ``degrees`` at the third (as a real Franka
    log re-grasps between tasks), and wobbles by up to 2 deg within each search."""
    from scipy.spatial.transform import Rotation

    t = log["t"]
    ramp = np.interp(t, [95.0, 140.0, 190.0, 235.0], [0.0, 0.5, 0.5, 1.0]) * degrees
    angle = np.radians(ramp + 2.0 * np.sin(2.0 * np.pi * t / 7.0))
    quat = log["quat"]
    rot = Rotation.from_rotvec(np.outer(angle, [1.0, 0.0, 0.0]))
    tool = Rotation.from_quat(quat[:, [1, 2, 3, 0]])
    xyzw = (rot * tool).as_quat()
    return {**log, "quat": xyzw[:, [3, 0, 1, 2]]}


def write_log(
    path: Path,
    log: dict[str, np.ndarray],
    *,
    time_column: str | None = "t_ms",
    time_factor: float = 1e3,
    epoch: float = 1718023402.0,
    quat_order: str = "x,y,z,w",
    robot_wrench: bool = False,
) -> Path:
    """Write ``log`` as CSV: optional time column (``t * time_factor`` from ``epoch``), then
    ``x..z``, the quaternion in ``quat_order`` named q0..q3, and ``fx..tz`` (negated when
    ``robot_wrench``)."""
    quat = log["quat"] if quat_order == "w,x,y,z" else log["quat"][:, [1, 2, 3, 0]]
    wrench = -log["wrench"] if robot_wrench else log["wrench"]
    cols = [log["pos"], quat, wrench]
    header = ["x", "y", "z", "q0", "q1", "q2", "q3", "fx", "fy", "fz", "tx", "ty", "tz"]
    fmt = ["%.6f"] * 7 + ["%.3f"] * 3 + ["%.4f"] * 3
    if time_column is not None:
        cols.insert(0, ((epoch + log["t"]) * time_factor)[:, None])
        header.insert(0, time_column)
        fmt.insert(0, "%.3f")
    np.savetxt(path, np.hstack(cols), fmt=fmt, delimiter=",", header=",".join(header), comments="")
    return path


def write_map(path: Path, *, time: str | None = "t_ms", **options: object) -> Path:
    """A column map for :func:`write_log` files; ``options`` become top-level keys."""
    lines = []
    defaults = {"time_scale": 1e-3, "frame": "panda_link0", "quat_order": "x,y,z,w"}
    for key, value in {**defaults, **options}.items():
        if value is not None:
            lines.append(
                f"{key} = {value!r}" if not isinstance(value, str) else f'{key} = "{value}"'
            )
    lines.append("[columns]")
    if time is not None:
        lines.append(f'time = "{time}"')
    lines += ['x = "x"', 'y = "y"', 'z = "z"', 'quat = ["q0", "q1", "q2", "q3"]']
    lines += [f'{k} = "{k}"' for k in ("fx", "fy", "fz", "tx", "ty", "tz")]
    path.write_text("\n".join(lines) + "\n")
    return path


EPOCH_NS = 1_718_023_402_000_000_000
POSE = "geometry_msgs/msg/PoseStamped"
WRENCH = "geometry_msgs/msg/WrenchStamped"
TF = "tf2_msgs/msg/TFMessage"
TRANSFORM = "geometry_msgs/msg/TransformStamped"


def _header(ts, ns: int, frame: str, ros1: bool):
    stamp = ts.types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
    header = ts.types["std_msgs/msg/Header"]
    return (
        header(seq=0, stamp=stamp, frame_id=frame) if ros1 else header(stamp=stamp, frame_id=frame)
    )


def _pose_msg(ts, kind: str, ns: int, pos, quat, ros1: bool, frame: str = "panda_link0"):
    """A PoseStamped, a TransformStamped (to panda_hand_tcp) or a TFMessage (to panda_hand_tcp
    and, 1 m away, camera) for one pose."""
    t = ts.types
    w, x, y, z = quat
    if kind == POSE:
        pose = t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=pos[0], y=pos[1], z=pos[2]),
            orientation=t["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w),
        )
        return t[POSE](header=_header(ts, ns, frame, ros1), pose=pose)
    transforms = []
    for child, offset in (("panda_hand_tcp", 0.0), ("camera", 1.0)):
        transform = t["geometry_msgs/msg/Transform"](
            translation=t["geometry_msgs/msg/Vector3"](x=pos[0] + offset, y=pos[1], z=pos[2]),
            rotation=t["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w),
        )
        transforms.append(
            t["geometry_msgs/msg/TransformStamped"](
                header=_header(ts, ns, frame, ros1), child_frame_id=child, transform=transform
            )
        )
    return transforms[0] if kind == TRANSFORM else t[TF](transforms=transforms)


def _wrench_msg(ts, ns: int, wrench, ros1: bool, frame: str):
    t = ts.types
    vec = t["geometry_msgs/msg/Vector3"]
    body = t["geometry_msgs/msg/Wrench"](force=vec(*wrench[:3]), torque=vec(*wrench[3:]))
    return t[WRENCH](header=_header(ts, ns, frame, ros1), wrench=body)


def write_bag(
    path: Path,
    storage: str = "ros1",
    pose_kind: str = POSE,
    wrench_frame: str = "panda_link0",
    wrench_sign: float = 1.0,
) -> dict[str, np.ndarray]:
    """A 25 s search at 20 Hz: poses at the log's stamps, wrenches at 50 Hz offset by 3 ms.

    Returns the generated log (``t`` s, ``pos``, ``quat``, ``wrench`` at the pose stamps).
    """
    log = panda_log("search")
    ros1 = storage == "ros1"
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    w_t = np.arange(0.003, log["t"][-1] + 0.1, 0.02)
    w_values = np.column_stack([np.interp(w_t, log["t"], log["wrench"][:, k]) for k in range(6)])
    if ros1:
        writer = Writer1(path)
    else:
        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        writer = Writer2(path, version=9, storage_plugin=plugin)
    serialize = ts.serialize_ros1 if ros1 else ts.serialize_cdr
    with writer:
        pose_conn = writer.add_connection("/tcp_pose", pose_kind, typestore=ts)
        wrench_conn = writer.add_connection("/ft_sensor", WRENCH, typestore=ts)
        events = [(int(round(t * 1e9)), 0, i) for i, t in enumerate(log["t"])]
        events += [(int(round(t * 1e9)), 1, i) for i, t in enumerate(w_t)]
        for ns, kind, i in sorted(events):
            stamp = EPOCH_NS + ns
            if kind == 0:
                msg = _pose_msg(ts, pose_kind, stamp, log["pos"][i], log["quat"][i], ros1)
                writer.write(pose_conn, stamp + 1_000_000, serialize(msg, pose_kind))
            else:
                msg = _wrench_msg(ts, stamp, wrench_sign * w_values[i], ros1, wrench_frame)
                writer.write(wrench_conn, stamp + 1_000_000, serialize(msg, WRENCH))
    return log
