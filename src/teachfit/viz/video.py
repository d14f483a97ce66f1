"""Offscreen MuJoCo rendering of recorded motions, written as mp4.

Rendering needs OpenGL: on a headless machine set ``MUJOCO_GL=egl`` (EGL through Mesa works on
the CPU) or ``MUJOCO_GL=osmesa``. Without a usable GL context :class:`~teachfit.RenderError`
explains what to set instead of failing deep inside MuJoCo.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import imageio.v2 as imageio
import numpy as np
from imageio.core.format import Format

from teachfit.core.atomic import atomic_path
from teachfit.robot.render import motion_frames
from teachfit.tasks.base import Task


@contextmanager
def video_writer(path: str | Path, fps: int = 30) -> Iterator[Format.Writer]:
    """An mp4 writer (H.264 through the ``imageio-ffmpeg`` packaged binary)."""
    with atomic_path(path, "video") as tmp:
        writer = imageio.get_writer(tmp, fps=fps, codec="libx264", quality=7, macro_block_size=8)
        try:
            yield writer
        finally:
            writer.close()


def render_motion(
    task: Task,
    t: np.ndarray,
    pos: np.ndarray,
    quat: np.ndarray,
    out: str | Path,
    *,
    fps: int = 30,
    width: int = 640,
    height: int = 480,
    slowdown: float = 1.0,
    robot: str = "floating",
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Render the held part following recorded TCP poses (world frame) to an mp4.

    Parameters
    ----------
    t : (T,) s;  pos : (T, 3) m;  quat : (T, 4) w-x-y-z
    slowdown : play back this many times slower than real time.
    progress : called with (frames written, frames in all) after each frame.
    """
    total = frame_count(t, fps, slowdown)
    frames = motion_frames(
        task, t, pos, quat, fps=fps, width=width, height=height, slowdown=slowdown, robot=robot
    )
    with video_writer(out, fps=fps) as writer:
        for k, frame in enumerate(frames, start=1):
            writer.append_data(frame)
            if progress is not None:
                progress(k, total)
    return Path(out)


def frame_count(t: np.ndarray, fps: int, slowdown: float = 1.0) -> int:
    """Frames of a video of the motion sampled at times ``t`` (s): one per 1/(fps slowdown) s."""
    t = np.asarray(t, dtype=float)
    if t.size < 2 or not fps > 0 or not slowdown > 0:
        return 0
    return int(np.arange(t[0], t[-1] + 1e-9, 1.0 / (fps * slowdown)).size)
