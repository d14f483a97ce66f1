"""Figure of a tracked capture: ``L2G`` position and orientation over time, frames without a
trustworthy pose shaded, and the per-frame quality (predicted error, reprojection, markers)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from teachfit.capture.track import Track  # noqa: E402
from teachfit.core.geometry import wxyz_to_rotation  # noqa: E402
from teachfit.demonstrations.dataset import Demonstration  # noqa: E402
from teachfit.viz.output import save_figure

__all__ = ["track_figure"]


def _rpy(R: np.ndarray) -> np.ndarray:
    return Rotation.from_matrix(R).as_euler("xyz", degrees=True)


def track_figure(track: Track, out: str | Path, truth: Demonstration | None = None) -> Path:
    """Write a three-panel png of ``track`` (and ``truth`` dashed, when given)."""
    out = Path(out)
    t, ok = track.t, track.valid
    fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    pos = np.full((len(t), 3), np.nan)
    rpy = np.full((len(t), 3), np.nan)
    pos[ok] = 1e3 * track.L2G[ok, :3, 3]
    if ok.any():
        rpy[ok] = _rpy(track.L2G[ok, :3, :3])
    for k, label in enumerate("xyz"):
        axes[0].plot(t, pos[:, k], ".-", ms=3, color=f"C{k}", label=label)
        axes[1].plot(t, rpy[:, k], ".-", ms=3, color=f"C{k}", label=("roll", "pitch", "yaw")[k])
        if truth is not None:
            R = wxyz_to_rotation(truth.quat).as_matrix()
            axes[0].plot(truth.t, 1e3 * truth.pos[:, k], "--", color=f"C{k}", lw=0.8)
            axes[1].plot(truth.t, _rpy(R)[:, k], "--", color=f"C{k}", lw=0.8)
    dt = np.median(np.diff(t)) if len(t) > 1 else 1.0
    for ax in axes:
        for i in np.flatnonzero(~ok):
            ax.axvspan(t[i] - dt / 2, t[i] + dt / 2, color="0.85", lw=0)
    axes[0].set_ylabel("L in G position (mm)")
    axes[1].set_ylabel("L in G angles (deg)")
    axes[2].plot(t, track.std_mm, label="predicted 1-sigma (mm)")
    axes[2].plot(t, track.std_deg, label="predicted 1-sigma (deg)")
    axes[2].plot(t, track.rms_px, label="reprojection RMS (px)")
    ax2 = axes[2].twinx()
    ax2.step(
        t,
        track.n_markers.sum(axis=1),
        where="mid",
        color="0.4",
        lw=0.8,
        label="markers used (right axis)",
    )
    ax2.set_ylabel("markers used")
    ax2.yaxis.set_major_locator(MaxNLocator(integer=True))
    axes[2].set_yscale("log")
    axes[2].set_ylabel("quality (mm, deg or px)")
    axes[2].set_xlabel("time (s)")
    for ax in axes[:2]:
        ax.legend(loc="upper right", fontsize=7)
    lines = axes[2].get_legend_handles_labels()
    more = ax2.get_legend_handles_labels()
    axes[2].legend(lines[0] + more[0], lines[1] + more[1], loc="upper right", fontsize=7)
    title = f"capture: {int(ok.sum())}/{track.n_frames} frames valid (grey: no trustworthy pose)"
    if truth is not None:
        title += "; dashed: ground truth (under the track where they agree)"
    axes[0].set_title(title)
    fig.tight_layout()
    return save_figure(fig, out, dpi=110)
