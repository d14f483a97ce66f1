"""Parameter grids of Ehlers et al.'s tasks: variants a new user might build, as task parameter
sets.

``peg2d``: peg diameter 8-30 mm, diametral clearance 0.2-0.5 mm, sliding friction 0.2-0.8,
chamfered (the default 1 mm peg and 0.5 mm hole chamfers) or sharp-edged (no chamfers).
``socket3d``: start yaw within +-10 ... +-40 deg, hole clearances 0.3-0.8 mm (the small hole's
never above the large one's). A :class:`Variant` is one point of a grid: the axes' values as a
reader sees them (mm, deg, a yes/no) and the task parameter overrides they stand for (SI).
:func:`sample_variants` draws a seeded sample of distinct grid points.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.tasks.base import Task
from teachfit.tasks.registry import get_task

#: the peg2d grid, by axis: values as shown (mm, coefficient, chamfered yes/no)
PEG2D_AXES: dict[str, tuple[float, ...]] = {
    "peg_diameter_mm": (8.0, 12.0, 20.0, 30.0),
    "clearance_mm": (0.2, 0.3, 0.5),
    "friction": (0.2, 0.5, 0.8),
    "chamfers": (1.0, 0.0),
}
#: the socket3d grid: start yaw half-range (deg) and the two holes' clearances (mm)
SOCKET3D_AXES: dict[str, tuple[float, ...]] = {
    "start_rz_deg": (10.0, 20.0, 30.0, 40.0),
    "clearance_small_mm": (0.3, 0.5, 0.8),
    "clearance_large_mm": (0.3, 0.5, 0.8),
}
AXES = {"peg2d": PEG2D_AXES, "socket3d": SOCKET3D_AXES}

#: the default peg2d chamfers (m): what "chamfers = 1" means
PEG_CHAMFER, HOLE_CHAMFER = 0.001, 0.0005


@dataclass(frozen=True)
class Variant:
    """One grid point of ``task``: ``values`` as shown (axis name, value) and the task
    parameter ``overrides`` (name, SI value) they stand for."""

    task: str
    values: tuple[tuple[str, float], ...]
    overrides: tuple[tuple[str, float], ...]

    def make(self) -> Task:
        """The task with this variant's parameters."""
        return get_task(self.task, **dict(self.overrides))

    @property
    def label(self) -> str:
        """A short name, e.g. ``"d20 c0.5 mu0.3 chamfered"``."""
        v = dict(self.values)
        if self.task == "peg2d":
            edge = "chamfered" if v["chamfers"] else "sharp"
            return f"d{v['peg_diameter_mm']:g} c{v['clearance_mm']:g} mu{v['friction']:g} {edge}"
        return f"rz±{v['start_rz_deg']:g} c{v['clearance_small_mm']:g}/{v['clearance_large_mm']:g}"


def _overrides(task: str, values: dict[str, float]) -> dict[str, float]:
    if task == "peg2d":
        chamfered = bool(values["chamfers"])
        return {
            "peg_diameter": values["peg_diameter_mm"] * 1e-3,
            "clearance": values["clearance_mm"] * 1e-3,
            "friction": values["friction"],
            "peg_chamfer": PEG_CHAMFER if chamfered else 0.0,
            "hole_chamfer": HOLE_CHAMFER if chamfered else 0.0,
        }
    return {
        "start_rz": float(np.radians(values["start_rz_deg"])),
        "clearance_small": values["clearance_small_mm"] * 1e-3,
        "clearance_large": values["clearance_large_mm"] * 1e-3,
    }


def variant(task: str, **values: float) -> Variant:
    """The variant of ``task`` with the axis ``values`` given (every axis of its grid)."""
    axes = _axes(task)
    if set(values) != set(axes):
        raise TaskError(f"a {task} variant needs the axes {sorted(axes)}, got {sorted(values)}")
    ov = _overrides(task, values)
    get_task(task, **ov)  # the parameters check themselves: a bad point fails here
    return Variant(task, tuple(values.items()), tuple(sorted(ov.items())))


def _axes(task: str) -> dict[str, tuple[float, ...]]:
    try:
        return AXES[task]
    except KeyError:
        raise TaskError(f"no variant grid for task {task!r}; grids: {sorted(AXES)}") from None


def grid(task: str) -> list[Variant]:
    """Every valid point of ``task``'s grid (socket3d: small clearance <= large)."""
    axes = _axes(task)
    out = []
    for combo in itertools.product(*axes.values()):
        values = dict(zip(axes, combo, strict=True))
        if task == "socket3d" and values["clearance_small_mm"] > values["clearance_large_mm"]:
            continue
        out.append(variant(task, **values))
    return out


def sample_variants(task: str, n: int, seed: int = 0) -> list[Variant]:
    """``n`` distinct grid points of ``task`` drawn with ``seed`` (all of them if fewer)."""
    if n < 1:
        raise TaskError(f"number of variants must be >= 1, got {n}")
    points = grid(task)
    idx = np.random.default_rng(seed).permutation(len(points))[: min(n, len(points))]
    return [points[i] for i in sorted(idx)]
