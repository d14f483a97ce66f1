"""MuJoCo's interactive (passive) viewer on a recorded motion of the floating tool's scene.

The viewer needs a display: on Linux an X11 (``DISPLAY``) or Wayland (``WAYLAND_DISPLAY``)
session. Without one, :func:`view_motion` raises a :class:`~teachfit.RenderError` that says so
(offscreen videos, ``teachfit render``, work without a display).
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from teachfit.core.errors import RenderError
from teachfit.tasks.base import Task

__all__ = ["has_display", "require_display", "view_motion"]


def has_display() -> bool:
    """Whether a window can be opened here (macOS and Windows always have a display)."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def require_display() -> None:
    """Raise a one-line :class:`~teachfit.RenderError` where no window can be opened."""
    if not has_display():
        raise RenderError(
            "no display for the viewer (DISPLAY unset); teachfit render makes a video"
        )


def view_motion(
    task: Task, t: np.ndarray, pos: np.ndarray, quat: np.ndarray, *, speed: float = 1.0
) -> None:
    """Play the held part along recorded TCP poses (world frame) in MuJoCo's viewer, at
    ``speed`` times real time, then hold the last pose until the window is closed.

    Parameters
    ----------
    t : (T,) s;  pos : (T, 3) m;  quat : (T, 4) w-x-y-z
    """
    require_display()
    if not speed > 0:
        raise RenderError(f"--speed must be > 0, got {speed}")
    import mujoco
    import mujoco.viewer

    from teachfit.robot.floating import build_scene

    model = mujoco.MjModel.from_xml_string(build_scene(task))
    data = mujoco.MjData(model)
    jnt = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "tool_free")
    adr = int(model.jnt_qposadr[jnt])
    try:
        handle = mujoco.viewer.launch_passive(model, data)
    except Exception as exc:  # noqa: BLE001 - GLFW and the platform raise many types
        raise RenderError(f"MuJoCo's viewer could not open a window: {exc}") from exc
    with handle as viewer:
        handle.cam.lookat[:] = task.hole2world.pos
        handle.cam.distance = 0.16
        t0 = time.perf_counter()
        while viewer.is_running():
            now = t[0] + speed * (time.perf_counter() - t0)
            i = int(np.clip(np.searchsorted(t, now), 0, t.size - 1))
            data.qpos[adr : adr + 3] = pos[i]
            data.qpos[adr + 3 : adr + 7] = quat[i]
            mujoco.mj_forward(model, data)
            viewer.sync()
            time.sleep(1 / 60)
