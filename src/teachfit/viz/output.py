"""Writing figures: atomically (:mod:`teachfit.core.atomic`), the format from the suffix."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from teachfit.core.atomic import atomic_path
from teachfit.core.errors import OutputError


def save_figure(fig: Figure, path: str | Path, dpi: int = 120, **kwargs: Any) -> Path:
    """Write ``fig`` to ``path`` atomically (folder created if missing) and close it.

    Raises
    ------
    OutputError
        The suffix is not a format matplotlib writes, or the file cannot be written.
    """
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower()
    supported = fig.canvas.get_supported_filetypes()
    try:
        if fmt not in supported:
            raise OutputError(
                f"cannot write figure {path}: unknown image format {path.suffix!r}; "
                f"use one of {', '.join('.' + k for k in sorted(supported))}"
            )
        with atomic_path(path, "figure") as tmp:
            fig.savefig(tmp, dpi=dpi, format=fmt, **kwargs)
    finally:
        plt.close(fig)
    return path
