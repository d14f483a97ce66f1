"""Animation of a planned path to mp4: matplotlib 3-D frames written with imageio-ffmpeg."""

from __future__ import annotations

from pathlib import Path

import imageio.v2 as imageio
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from teachfit.core.errors import RenderError  # noqa: E402
from teachfit.plans.collision import pose_to_matrix  # noqa: E402
from teachfit.plans.parts import Assembly  # noqa: E402
from teachfit.viz.plan_figures import MOVING_COLOR, _frame_axes, add_mesh  # noqa: E402

__all__ = ["render_path_video"]


def render_path_video(
    asm: Assembly,
    path: np.ndarray,
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
    path : (N, 7) float
        States ``[x, y, z, qw, qx, qy, qz]`` of ``L2G``; resampled to ``frames`` frames by
        index (the path's own spacing).
    out : path
        Output ``.mp4`` file.
    fps, frames, size_px : int
        Frame rate, number of frames and frame size (even, px).

    Raises
    ------
    RenderError
        No path to draw, or ffmpeg unavailable.
    """
    path = np.asarray(path, dtype=float)
    if path.ndim != 2 or path.shape[1] != 7 or len(path) < 1:
        raise RenderError(f"need an (N, 7) path with N >= 1, got {path.shape}")
    out = Path(out)
    dpi = 80
    inch = (size_px - size_px % 16) / dpi  # libx264 wants sizes divisible by 16 (macroblocks)
    fig = plt.figure(figsize=(inch, inch), dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    add_mesh(ax, asm.fixed)
    _frame_axes(ax, asm, extra=path[:, :3])
    ax.view_init(elev=22, azim=-65)
    ax.plot(*(1e3 * path[:, :3].T), "-", color="C0", lw=0.8)
    idx = np.linspace(0, len(path) - 1, max(frames, 2)).round().astype(int)
    moving = None
    try:
        writer = imageio.get_writer(out, fps=fps, codec="libx264", macro_block_size=16)
    except Exception as exc:  # imageio reports a missing ffmpeg with several exception types
        plt.close(fig)
        raise RenderError(f"cannot open an mp4 writer (imageio-ffmpeg): {exc}") from exc
    try:
        for i in idx:
            if moving is not None:
                moving.remove()
            moving = add_mesh(
                ax,
                asm.moving,
                pose_to_matrix(path[i, :3], path[i, 3:]),
                color=MOVING_COLOR,
                alpha=0.9,
            )
            ax.set_title(f"{asm.task}: pose {i + 1}/{len(path)}")
            fig.canvas.draw()
            frame = np.asarray(fig.canvas.buffer_rgba())[..., :3]
            writer.append_data(frame)
    finally:
        writer.close()
        plt.close(fig)
    return out
