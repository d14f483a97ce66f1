"""Test helper: a search model fitted (by the real fitting code) to a generated blind-search
demonstration -- a seeded raster on the task's surface with friction against the motion --
so that tests need not record a simulated teacher (seconds of physics)."""

from __future__ import annotations

import numpy as np

from teachfit.core.geometry import quat_from_rz
from teachfit.demonstrations.dataset import Demonstration
from teachfit.models.search_model import SearchModel
from teachfit.tasks.base import Task


def raster_demo(
    task: Task, seed: int = 0, rate: float = 100.0, speed: float = 0.01
) -> Demonstration:
    """A 12 s raster from 1 cm beside the hole over it (m, world), rz wiggle where searched."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 12.0, 1.0 / rate)
    s = speed * t
    x = 0.01 - 0.0025 * np.floor(s / 0.012)  # rows 2.5 mm apart, towards the hole
    y = 0.006 * np.sin(2 * np.pi * s / 0.024)
    xy = np.column_stack([x, y]) + rng.normal(0.0, 1e-4, (t.size, 2)) + task.hole2world.pos[:2]
    pos = np.column_stack([xy, np.full(t.size, task.surface_z)])
    rz = 0.1 * np.sin(0.8 * t) if task.has_rz else np.zeros(t.size)
    vel = np.gradient(xy, t, axis=0)
    wrench = np.zeros((t.size, 6))
    wrench[:, :2] = -2.0 * vel / np.maximum(np.linalg.norm(vel, axis=1, keepdims=True), 1e-9)
    wrench[:, 2] = 6.0
    return Demonstration(
        t=t, pos=pos, quat=quat_from_rz(rz), wrench=wrench, task=task.name,
        source="simulated-teacher", frame="world", child_frame="tcp",
    )  # fmt: skip


def raster_model(task: Task, seed: int = 0) -> SearchModel:
    """The search model of :func:`raster_demo` (GMR dynamics included)."""
    return SearchModel.fit([raster_demo(task, seed)], task.name)
