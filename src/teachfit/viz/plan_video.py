"""Animation of a planned path to mp4: matplotlib 3-D frames written with imageio-ffmpeg."""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import ExitStack
from pathlib import Path
from typing import cast

import imageio.v2 as imageio
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402

from teachfit.core.atomic import atomic_path  # noqa: E402
from teachfit.core.errors import RenderError  # noqa: E402
from teachfit.core.geometry import Pose  # noqa: E402
from teachfit.tasks.parts import Assembly  # noqa: E402
from teachfit.viz.plan_figures import MOVING_COLOR, _frame_axes, add_mesh  # noqa: E402

__all__ = ["render_path_video"]


def render_path_video(
    asm: Assembly,
    path: Sequence[Pose],
    out: str | Path,
    *,
    fps: int = 20,
    frames: int = 80,
    size_px: int = 480,
) -> Path:
    """Write an mp4 of the moving part following ``path``.

    Parameters
    ----------
    asm : Assembly
        Parts (drawn in frame ``G``, mm).
    path : sequence of Pose
        Poses ``L2G`` of the moving part in ``G`` (m); resampled to ``frames`` frames by index
        (the path's own spacing).
    out : path
        Output ``.mp4`` file.
    fps, frames, size_px : int
        Frame rate, number of frames and frame size (even, px).

    Raises
    ------
    RenderError
        No path to draw, or ffmpeg unavailable.
    """
    if len(path) < 1 or not all(isinstance(p, Pose) for p in path):
        raise RenderError(f"need a path of at least one Pose, got {len(path)} item(s)")
    positions = np.stack([p.pos for p in path])
    out = Path(out)
    dpi = 80
    inch = (size_px - size_px % 16) / dpi  # libx264 wants sizes divisible by 16 (macroblocks)
    fig = plt.figure(figsize=(inch, inch), dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    add_mesh(ax, asm.fixed)
    _frame_axes(ax, asm, extra=positions)
    ax.view_init(elev=22, azim=-65)
    ax.plot(*(1e3 * positions.T), "-", color="C0", lw=0.8)
    idx = np.linspace(0, len(path) - 1, max(frames, 2)).round().astype(int)
    with ExitStack() as stack:
        stack.callback(plt.close, fig)
        tmp = stack.enter_context(atomic_path(out, "video"))
        try:
            writer = imageio.get_writer(tmp, fps=fps, codec="libx264", macro_block_size=16)
        except Exception as exc:  # imageio reports a missing ffmpeg with several exception types
            raise RenderError(f"cannot open an mp4 writer (imageio-ffmpeg): {exc}") from exc
        stack.callback(writer.close)  # closed (and flushed) before the file is moved into place
        moving = None
        for i in idx:
            if moving is not None:
                moving.remove()
            moving = add_mesh(ax, asm.moving, path[i].matrix, color=MOVING_COLOR, alpha=0.9)
            ax.set_title(f"{asm.task}: pose {i + 1}/{len(path)}")
            fig.canvas.draw()
            canvas = cast(FigureCanvasAgg, fig.canvas)  # the Agg backend: see plan_figures
            writer.append_data(np.asarray(canvas.buffer_rgba())[..., :3])
    return out
