"""Offscreen frames of the simulated cell: the floating tool's scene posed along a motion.

Rendering needs OpenGL: on a headless machine set ``MUJOCO_GL=egl`` (EGL through Mesa works on
the CPU) or ``MUJOCO_GL=osmesa``. Without a usable GL context :class:`~teachfit.RenderError`
explains what to set instead of failing deep inside MuJoCo.
"""

from __future__ import annotations

import os
from collections.abc import Iterator

import mujoco
import numpy as np

from teachfit.core.errors import RenderError
from teachfit.robot.floating import build_scene
from teachfit.tasks.base import Task


def make_renderer(model: mujoco.MjModel, width: int, height: int) -> mujoco.Renderer:
    """A MuJoCo offscreen renderer, or a :class:`RenderError` saying how to get one."""
    try:
        return mujoco.Renderer(model, height=height, width=width)
    except Exception as exc:  # noqa: BLE001 - GL back-ends raise many unrelated types
        backend = os.environ.get("MUJOCO_GL", "(unset)")
        raise RenderError(
            f"offscreen rendering is unavailable (MUJOCO_GL={backend}): {exc}. On a headless "
            "machine set MUJOCO_GL=egl (Mesa's EGL works without a GPU) or MUJOCO_GL=osmesa."
        ) from exc


def motion_frames(
    task: Task,
    t: np.ndarray,
    pos: np.ndarray,
    quat: np.ndarray,
    *,
    fps: int = 30,
    width: int = 640,
    height: int = 480,
    slowdown: float = 1.0,
    robot: str = "floating",
) -> Iterator[np.ndarray]:
    """RGB frames (H, W, 3) of the held part following recorded TCP poses (world frame).

    Parameters
    ----------
    t : (T,) s;  pos : (T, 3) m;  quat : (T, 4) w-x-y-z
    slowdown : play back this many times slower than real time.
    """
    if robot != "floating":
        raise RenderError(f"rendering shows the floating tool only, not robot {robot!r}")
    if not (fps > 0 and width > 0 and height > 0 and slowdown > 0):
        raise RenderError(f"fps, width, height and slowdown must be > 0: {fps}, {width}x{height}")
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        raise RenderError("need at least two poses to render a motion")
    model = mujoco.MjModel.from_xml_string(build_scene(task))
    data = mujoco.MjData(model)
    renderer = make_renderer(model, width, height)
    jnt = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "tool_free")
    adr = int(model.jnt_qposadr[jnt])
    cam = mujoco.MjvCamera()
    cam.lookat[:] = task.hole2world.pos + np.array([0.0, 0.0, 0.01])
    cam.distance = 0.16
    cam.azimuth = 135.0
    cam.elevation = -28.0
    frame_times = np.arange(t[0], t[-1] + 1e-9, 1.0 / (fps * slowdown))
    idx = np.clip(np.searchsorted(t, frame_times), 0, t.size - 1)
    try:
        for i in idx:
            data.qpos[adr : adr + 3] = pos[i]
            data.qpos[adr + 3 : adr + 7] = quat[i]
            mujoco.mj_forward(model, data)
            renderer.update_scene(data, camera=cam)
            yield renderer.render()
    finally:
        renderer.close()
