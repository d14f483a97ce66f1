"""Checks that a written figure or video holds a picture, not just bytes."""

from __future__ import annotations

from pathlib import Path

import imageio.v2 as imageio
import matplotlib.image as mpimg
import numpy as np


def _assert_not_blank(img: np.ndarray, what: str) -> None:
    rgb = np.asarray(img, dtype=float)[..., :3].reshape(-1, 3)
    background = np.median(rgb, axis=0)
    drawn = np.any(np.abs(rgb - background) > 0.05 * max(float(rgb.max()), 1e-9), axis=1)
    assert drawn.mean() > 0.01, f"{what} is (nearly) blank: {drawn.mean():.4f} drawn"
    # distinct colours counted on the sorted rows (np.unique(axis=0) takes seconds on a figure)
    rows = rgb[np.lexsort(rgb.T)]
    colours = 1 + int(np.any(rows[1:] != rows[:-1], axis=1).sum())
    assert colours > 16, f"{what} has too few colours to be a drawing"


def read_png(path: Path, *, min_px: int = 100) -> np.ndarray:
    """Decode ``path`` (matplotlib), check it is an RGB(A) image of at least ``min_px`` a side
    with something drawn on it, and return it (H, W, C)."""
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[2] in (3, 4), img.shape
    assert min(img.shape[:2]) >= min_px, img.shape
    _assert_not_blank(img, str(path))
    return img


def read_video(path: Path) -> np.ndarray:
    """Decode every frame of ``path`` (imageio-ffmpeg), check the first is not blank, and
    return them (N, H, W, 3)."""
    with imageio.get_reader(path) as reader:
        frames = np.stack([np.asarray(f) for f in reader])
    assert frames.ndim == 4 and frames.shape[-1] == 3, frames.shape
    _assert_not_blank(frames[0], f"first frame of {path}")
    return frames
