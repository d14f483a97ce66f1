"""What every simulated assembly task is: parameters, geometry and the success test.

A task is a frozen parameter dataclass (lengths in metres) plus the cell it describes. The
world frame has z up; the fixture's top surface is at ``surface_z``; the *hole frame* sits at
the centre of the (first) hole on that surface, z up. The *tool centre point* (TCP) is the
lowest point of the held part on its axis (peg tip, pin-tip midpoint), so a TCP at
``hole2world`` means the part is aligned and just touching the entry.

A :class:`Task` holds its geometry and success test itself (concern of the subclasses in
:mod:`teachfit.tasks.geometry`) and reaches the two other concerns through attributes:
:attr:`Task.scene` (MuJoCo bodies, :mod:`teachfit.tasks.scene`) and :attr:`Task.protocol`
(search poses and the papers' start poses, :mod:`teachfit.tasks.protocols`).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from abc import ABC, abstractmethod
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Self

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose, quat_conj_into, quat_rotate_into

if TYPE_CHECKING:
    from teachfit.tasks.protocols.base import Protocol
    from teachfit.tasks.scene.builder import SceneBuilder


class Task(ABC):
    """A tight-fit assembly cell: geometry and success test; scene and protocols attached."""

    name: ClassVar[str]
    description: ClassVar[str]
    #: names of the searched degrees of freedom, e.g. ("x", "y") or ("x", "y", "rz")
    search_dims: ClassVar[tuple[str, ...]]
    params_type: ClassVar[type]
    scene_type: ClassVar[type[SceneBuilder]]
    protocol_type: ClassVar[type[Protocol]]

    def __init__(self, params: Any | None = None) -> None:
        self.params = self.params_type() if params is None else params
        if not isinstance(self.params, self.params_type):
            raise TaskError(f"{self.name} needs {self.params_type.__name__}, got {params!r}")
        #: the cell's MuJoCo bodies (fixture and held part)
        self.scene: SceneBuilder = self.scene_type(self)
        #: the cell's search poses and start protocols
        self.protocol: Protocol = self.protocol_type(self)

    # ----------------------------------------------------------------------------- geometry
    @property
    @abstractmethod
    def surface_z(self) -> float:
        """Height of the surface the part slides on before it enters (m, world)."""

    @property
    def hole2world(self) -> Pose:
        """Ground-truth pose of the hole frame (entry centre, z up) in the world; by default on
        the world z axis, unturned, with the entry at :attr:`surface_z`."""
        return Pose(np.array([0.0, 0.0, self.surface_z]))

    @property
    def success_depth(self) -> float:
        """Depth below the entry (m) the TCP must pass for the insertion to count."""
        return float(self.params.success_depth)

    @property
    def capture_radius(self) -> float:
        """Lateral TCP offset (m) beyond which the part cannot be inside the hole: the
        clearance plus 0.1 mm of soft-contact give."""
        return float(self.params.clearance) + 1e-4

    @property
    def has_rz(self) -> bool:
        """Whether the yaw about z is searched (and must match the hole's)."""
        return "rz" in self.search_dims

    def contact_pose(self, xy: np.ndarray, rz: float = 0.0) -> Pose:
        """TCP pose resting on the surface at world ``xy`` (m) with yaw ``rz`` (rad)."""
        return Pose.from_xyz_rz(float(xy[0]), float(xy[1]), self.surface_z, rz)

    def insertion_depth(self, tool2world: Pose) -> float:
        """How far the TCP is below the hole entry along the hole axis (m, positive inside)."""
        rel = self.hole2world.inverse().compose(tool2world)
        return float(-rel.pos[2])

    def lateral_error(self, tool2world: Pose) -> float:
        """Distance of the TCP from the hole axis (m)."""
        rel = self.hole2world.inverse().compose(tool2world)
        return float(np.hypot(rel.pos[0], rel.pos[1]))

    # ------------------------------------------------------------------------ success test
    def ground_truth_inserted(self, tool2world: Pose) -> bool:
        """Simulator ground truth (benchmarks only): the TCP is deeper than
        :attr:`success_depth` below the *true* hole entry and on the true hole axis."""
        return (
            self.insertion_depth(tool2world) >= self.success_depth
            and self.lateral_error(tool2world) < self.capture_radius
        )

    @property
    def nominal_hole2world(self) -> Pose:
        """The hole frame as the cell's drawing gives it (world); the simulated cell is built
        exactly to its drawing, so this is :attr:`hole2world`."""
        return self.hole2world

    @property
    def entry_height(self) -> float:
        """Nominal height of the hole entry (m, world z): what the cell's drawing says."""
        return float(self.nominal_hole2world.pos[2])

    @property
    @abstractmethod
    def detection_radius(self) -> float:
        """Lateral TCP distance (m) from the nominal hole axis within which the held part
        stands wholly over the fixture's top, whose only opening is the hole: there, a TCP
        below the entry is in the hole. Beyond it the part may go down beside the fixture."""

    def detect_success(self, tool2world: Pose) -> bool:
        """The success detector, from what a robot measures (its TCP pose, world) and what the
        cell's drawing says: the TCP is at least :attr:`success_depth` below the nominal entry
        height and within :attr:`detection_radius` of the nominal hole axis."""
        if self.entry_height - float(tool2world.pos[2]) < self.success_depth:
            return False  # most ticks: checked first, without the frame change
        hole = self.nominal_hole2world
        rel = np.empty(3)  # the TCP in the hole frame: R^T (p - p_hole), R^T by the conjugate
        quat_rotate_into(rel, quat_conj_into(np.empty(4), hole.quat), tool2world.pos - hole.pos)
        return float(np.hypot(rel[0], rel[1])) <= float(self.detection_radius)

    # ------------------------------------------------------------------------------- I/O
    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]) -> Self:
        """Build from a mapping of parameter names to values (unknown names are an error)."""
        fields = {f.name: f for f in dataclasses.fields(cls.params_type)}
        unknown = sorted(set(values) - set(fields))
        if unknown:
            raise TaskError(f"unknown {cls.name} parameter(s) {unknown}; known: {sorted(fields)}")
        defaults = cls.params_type()
        kwargs = {
            key: _typed(cls.name, key, val, getattr(defaults, key)) for key, val in values.items()
        }
        return cls(cls.params_type(**kwargs))

    @classmethod
    def from_toml(cls, path: str | Path) -> Self:
        """Load parameters from a TOML file (a flat table, or a ``[params]`` table)."""
        data = read_task_toml(path)
        data = data.get("params", data)
        if not isinstance(data, dict):
            raise TaskError(f"task file {path}: [params] must be a table, got {data!r}")
        try:
            return cls.from_mapping({k: v for k, v in data.items() if k != "task"})
        except TaskError as exc:
            raise TaskError(f"task file {path}: {exc}") from exc

    def param_table(self) -> list[tuple[str, Any, str]]:
        """``(name, value, description)`` rows for listing a task's parameters."""
        rows = []
        for f in dataclasses.fields(self.params):
            rows.append((f.name, getattr(self.params, f.name), f.metadata.get("doc", "")))
        return rows


def read_task_toml(path: str | Path) -> dict[str, Any]:
    """The table of a task TOML file; :class:`TaskError` (naming the file) if it is missing,
    not UTF-8 text (a binary file) or not TOML."""
    try:
        return tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise TaskError(f"cannot read task file {path}: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise TaskError(f"task file {path} is not a text (TOML) file: {exc.reason}") from exc
    except tomllib.TOMLDecodeError as exc:
        raise TaskError(f"task file {path} is not valid TOML: {exc}") from exc


def _typed(task: str, key: str, val: Any, default: Any) -> Any:
    """``val`` as the type of the parameter's default, refusing what TOML would convert
    silently (a boolean as a number, 12.9 as an integer, ``nan``, a string or a table)."""
    where = f"{task} parameter {key!r}"
    if isinstance(default, bool):
        if not isinstance(val, bool):
            raise TaskError(f"{where} must be true or false, got {val!r}")
        return val
    if isinstance(default, tuple):
        if not isinstance(val, list | tuple) or len(val) != len(default):
            raise TaskError(f"{where} must be a list of {len(default)} values, got {val!r}")
        return tuple(
            _typed(task, f"{key}[{i}]", v, d)
            for i, (v, d) in enumerate(zip(val, default, strict=True))
        )
    if isinstance(default, int | float):
        if isinstance(val, bool) or not isinstance(val, int | float):
            raise TaskError(f"{where} must be a number, got {val!r}")
        if not math.isfinite(val):
            raise TaskError(f"{where} must be a finite number, got {val!r}")
        if isinstance(default, int):
            if float(val) != int(val):
                raise TaskError(f"{where} must be a whole number, got {val!r}")
            return int(val)
        return float(val)
    if isinstance(default, str) and not isinstance(val, str):
        raise TaskError(f"{where} must be a string, got {val!r}")
    return val
