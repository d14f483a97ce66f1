"""Offscreen frames of the simulated cell posed along a motion: the floating tool, or the FR3.

The FR3 (``robot="fr3"``, with its visual meshes) follows the TCP poses by inverse kinematics
warm-started from the previous frame (:func:`teachfit.robot.fr3.ik.solve_ik`, no posture
phase: the arm moves continuously); each frame shows the whole arm beside a close-up of the
part at the hole.

Rendering needs OpenGL: on a headless machine set ``MUJOCO_GL=egl`` (EGL through Mesa works on
the CPU) or ``MUJOCO_GL=osmesa``. Without a usable GL context :class:`~teachfit.RenderError`
explains what to set instead of failing deep inside MuJoCo.
"""

from __future__ import annotations

import os
from collections.abc import Iterator

import mujoco
import numpy as np

from teachfit.core.errors import LimitViolation, RenderError
from teachfit.core.geometry import Pose
from teachfit.robot.floating import build_scene
from teachfit.tasks.base import Task

ROBOTS = ("floating", "fr3")


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


def _camera(lookat: np.ndarray, distance: float, azimuth: float, elevation: float) -> object:
    cam = mujoco.MjvCamera()
    cam.lookat[:] = lookat
    cam.distance, cam.azimuth, cam.elevation = distance, azimuth, elevation
    return cam


class _FloatingPoser:
    """The floating tool's free joint set to each TCP pose."""

    def __init__(self, task: Task) -> None:
        self.model = mujoco.MjModel.from_xml_string(build_scene(task))
        jnt = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, "tool_free")
        self.adr = int(self.model.jnt_qposadr[jnt])
        self.cameras = [_camera(task.hole2world.pos + np.array([0.0, 0.0, 0.01]), 0.16, 135, -28)]
        self.scene_off: tuple[int, ...] = ()

    def pose(self, data: mujoco.MjData, pos: np.ndarray, quat: np.ndarray) -> None:
        data.qpos[self.adr : self.adr + 3] = pos
        data.qpos[self.adr + 3 : self.adr + 7] = quat


class _FR3Poser:
    """The FR3's joints by inverse kinematics for each TCP pose, warm-started."""

    def __init__(self, task: Task) -> None:
        from teachfit.robot.fr3 import FR3Params
        from teachfit.robot.fr3 import model as fr3_model
        from teachfit.robot.fr3.ik import IKSettings, solve_ik
        from teachfit.robot.fr3.params import READY_Q

        params = FR3Params(visual=True)
        self.model = fr3_model.build_fr3_model(task, params)
        self._solve, self._site = solve_ik, fr3_model.TCP_SITE
        self._settings = IKSettings(posture_iterations=0, pos_tol=1e-5, rot_tol=1e-4)
        self._q = np.array(READY_Q)
        self._first = True
        hole = task.hole2world.pos
        mid = (np.asarray(params.base_pos) + hole) / 2 + np.array([0.0, 0.0, 0.3])
        self.cameras = [_camera(mid, 1.5, 150, -20), _camera(hole + [0, 0, 0.01], 0.2, 135, -28)]
        # the arm's meshes are detailed: shadows and reflections would triple the render time
        self.scene_off = (mujoco.mjtRndFlag.mjRND_SHADOW, mujoco.mjtRndFlag.mjRND_REFLECTION)

    def pose(self, data: mujoco.MjData, pos: np.ndarray, quat: np.ndarray) -> None:
        target = Pose(np.asarray(pos), np.asarray(quat))
        settings = None if self._first else self._settings  # the first pose: with posture
        try:
            self._q = self._solve(self.model, self._site, target, self._q, self._q, settings).q
        except LimitViolation as exc:
            raise RenderError(f"the FR3 cannot show this motion: {exc}") from exc
        self._first = False
        data.qpos[:] = self._q


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
    robot : ``"floating"`` (the tool alone, close up) or ``"fr3"`` (the arm; the whole arm on
        the left half of each frame, the part at the hole on the right half).
    """
    if robot not in ROBOTS:
        raise RenderError(f"rendering shows robots {ROBOTS}, not {robot!r}")
    if not (fps > 0 and width > 0 and height > 0 and slowdown > 0):
        raise RenderError(f"fps, width, height and slowdown must be > 0: {fps}, {width}x{height}")
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        raise RenderError("need at least two poses to render a motion")
    poser = _FloatingPoser(task) if robot == "floating" else _FR3Poser(task)
    model = poser.model
    data = mujoco.MjData(model)
    renderer = make_renderer(model, width // len(poser.cameras), height)
    frame_times = np.arange(t[0], t[-1] + 1e-9, 1.0 / (fps * slowdown))
    idx = np.clip(np.searchsorted(t, frame_times), 0, t.size - 1)
    try:
        for i in idx:
            poser.pose(data, pos[i], quat[i])
            mujoco.mj_forward(model, data)
            views = []
            for cam in poser.cameras:
                renderer.update_scene(data, camera=cam)
                for flag in poser.scene_off:
                    renderer.scene.flags[flag] = False
                views.append(renderer.render())
            yield np.hstack(views) if len(views) > 1 else views[0]
    finally:
        renderer.close()
