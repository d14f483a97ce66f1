"""A run log as a Rerun recording (``.rrd``) for the Rerun viewer (``rerun run.rrd``).

Rerun (``rerun-sdk``, the optional extra ``teachfit[rerun]``) is the viewer made for
time-stamped robot data; this module only maps a run log onto its archetypes. Entities, one
subtree per episode, on the timeline ``time`` (s since the episode started; world frame, m)::

    run                               static text: task, robot, seed, method, command
    episodes/000/summary              static text: outcome, reason, duration, peak force
    episodes/000/path                 static line strip of the measured TCP path
    episodes/000/planned              static line strip of the planned set-points (searches)
    episodes/000/tcp                  measured TCP: a point and its frame (position, orientation)
    episodes/000/setpoint             the commanded set-point (a point)
    episodes/000/force, torque        measured wrench on the tool (N, N*m), three series each
    episodes/000/feedforward          commanded feed-forward force (N)
    episodes/000/depth                mm below the hole entry (see RunLog.depth)
    episodes/000/node                 index of the active node; episodes/000/events: its changes
"""

from __future__ import annotations

import uuid
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from teachfit.core.atomic import atomic_path
from teachfit.core.errors import TeachfitError
from teachfit.execution.recording import Episode, RunInfo, RunLog

INSTALL_HINT = "pip install 'teachfit[rerun]'"
_GREEN, _RED = (40, 160, 60), (210, 50, 40)


def require_rerun() -> None:
    """Raise a one-line :class:`TeachfitError` naming the install command when Rerun is
    missing (call it before a long run that should end in an ``.rrd``)."""
    try:
        import rerun  # noqa: F401
    except ImportError as exc:
        raise TeachfitError(f"--rrd needs the Rerun SDK: {INSTALL_HINT}") from exc


def _episode(rec: Any, rr: Any, base: str, ep: Episode, depth: np.ndarray) -> None:
    r, log = ep.result, ep.result.log
    color = _GREEN if r.success else _RED
    rec.log(
        f"{base}/summary",
        rr.TextDocument(
            f"outcome: {'success' if r.success else r.outcome.value} ({r.reason})\n"
            f"duration: {r.t_end:.3f} s, peak force {r.peak_force:.1f} N, "
            f"path {r.path_length * 1e3:.1f} mm, nodes: {' > '.join(v.node for v in r.visits)}"
        ),
        static=True,
    )
    if log.n_samples:
        rec.log(f"{base}/path", rr.LineStrips3D([log.pos], colors=[color]), static=True)
    if ep.planned is not None:
        rec.log(
            f"{base}/planned", rr.LineStrips3D([ep.planned.pos], colors=[(90, 90, 90)]), static=True
        )
    time = [rr.TimeColumn("time", duration=log.t)]
    xyzw = log.quat[:, [1, 2, 3, 0]]
    rec.send_columns(f"{base}/tcp", time, rr.Points3D.columns(positions=log.pos))
    rec.send_columns(
        f"{base}/tcp", time, rr.Transform3D.columns(translation=log.pos, quaternion=xyzw)
    )
    rec.log(f"{base}/tcp", rr.TransformAxes3D(axis_length=0.01), static=True)
    rec.send_columns(f"{base}/setpoint", time, rr.Points3D.columns(positions=log.setpoint_pos))
    series = {
        "force": (log.wrench[:, :3], ["fx (N)", "fy (N)", "fz (N)"]),
        "torque": (log.wrench[:, 3:], ["tx (N·m)", "ty (N·m)", "tz (N·m)"]),
        "feedforward": (log.wrench_ff[:, :3], ["ff x (N)", "ff y (N)", "ff z (N)"]),
        "depth": (depth[:, None] * 1e3, ["depth (mm)"]),
        "node": (log.node[:, None].astype(float), ["active node"]),
    }
    for name, (values, labels) in series.items():
        rec.log(f"{base}/{name}", rr.SeriesLines(names=labels), static=True)
        rec.send_columns(f"{base}/{name}", time, rr.Scalars.columns(scalars=values))
    prims = dict(ep.primitives)
    for v in r.visits:
        rec.set_time("time", duration=v.t_enter)
        what = f" ({prims[v.node]})" if v.node in prims else ""
        rec.log(f"{base}/events", rr.TextLog(f"enter {v.node}{what}; left: {v.reason}"))


def write_rrd(
    path: str | Path, episodes: Iterable[Episode | Any], info: RunInfo, *, name: str = ""
) -> Path:
    """Write a run (the arguments of :func:`~teachfit.execution.recording.write_run_log`) as a
    Rerun recording, atomically; returns the path written."""
    require_rerun()
    import rerun as rr

    path = Path(path)
    run = RunLog.of(episodes, info, path)
    if path.is_dir():
        raise TeachfitError(f"--rrd {path} is a folder: give a file name such as run.rrd")
    rec = rr.RecordingStream("teachfit", recording_id=uuid.uuid4().hex)
    try:
        with atomic_path(path, "Rerun recording") as tmp:
            rec.save(tmp)
            rec.send_recording_name(name or f"{info.kind} {info.method} on {info.task}")
            rec.log(
                "run",
                rr.TextDocument(
                    f"{info.kind} on {info.task} with {info.robot}, method {info.method}, "
                    f"seed {info.seed}\n{info.command}"
                ),
                static=True,
            )
            for i, ep in enumerate(run.episodes):
                _episode(rec, rr, f"episodes/{i:03d}", ep, run.depth(i))
            rec.flush()
            rec.disconnect()  # the file is complete before it is moved into place
    finally:
        rec.disconnect()
    return path
