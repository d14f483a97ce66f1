"""What every simulated assembly task provides.

A task is a frozen parameter dataclass (lengths in metres) plus the scene it generates. The
world frame has z up; the fixture's top surface is at ``surface_z``; the *hole frame* sits at
the centre of the (first) hole on that surface, z up. The *tool centre point* (TCP) is the
lowest point of the held part on its axis (peg tip, pin-tip midpoint), so a TCP at
``hole2world`` means the part is aligned and just touching the entry.
"""

from __future__ import annotations

import dataclasses
import tomllib
import xml.etree.ElementTree as ET
from abc import ABC, abstractmethod
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar, Self

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.tasks.mjcf import SceneXml


@dataclasses.dataclass(frozen=True)
class ContactParams:
    """Contact model shared by the fixture and the held part.

    ``solref``/``solimp`` make contacts stiff enough for sub-millimetre clearances at a 1 ms
    step (MuJoCo needs ``solref[0] >= 2 * timestep``). ``friction`` is the sliding coefficient.
    """

    friction: float = 0.3
    solref: tuple[float, float] = (0.002, 1.0)
    solimp: tuple[float, float, float] = (0.95, 0.99, 0.0005)
    margin: float = 0.0


class Task(ABC):
    """A tight-fit assembly cell: fixture geometry, held part, ground truth and protocols."""

    name: ClassVar[str]
    description: ClassVar[str]
    #: names of the searched degrees of freedom, e.g. ("x", "y") or ("x", "y", "rz")
    search_dims: ClassVar[tuple[str, ...]]
    params_type: ClassVar[type]

    def __init__(self, params: Any | None = None) -> None:
        self.params = self.params_type() if params is None else params
        if not isinstance(self.params, self.params_type):
            raise TaskError(f"{self.name} needs {self.params_type.__name__}, got {params!r}")

    # ----------------------------------------------------------------------------- geometry
    @property
    @abstractmethod
    def surface_z(self) -> float:
        """Height of the surface the part slides on before it enters (m, world)."""

    @property
    @abstractmethod
    def hole2world(self) -> Pose:
        """Ground-truth pose of the hole frame (entry centre, z up) in the world."""

    @property
    @abstractmethod
    def success_depth(self) -> float:
        """Depth below the entry (m) the TCP must pass for the insertion to count."""

    @abstractmethod
    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        """Add the fixed parts (with the hole) to ``scene.worldbody``."""

    @abstractmethod
    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        """Add the held part's geoms to ``body`` whose frame is the TCP (part axis along +z)."""

    @property
    @abstractmethod
    def held_part_length(self) -> float:
        """Height of the held part above the TCP (m): where the wrist F/T sensor sits."""

    # ----------------------------------------------------------------------- ground truth
    def insertion_depth(self, tool2world: Pose) -> float:
        """How far the TCP is below the hole entry along the hole axis (m, positive inside)."""
        rel = self.hole2world.inverse().compose(tool2world)
        return float(-rel.pos[2])

    def lateral_error(self, tool2world: Pose) -> float:
        """Distance of the TCP from the hole axis (m)."""
        rel = self.hole2world.inverse().compose(tool2world)
        return float(np.hypot(rel.pos[0], rel.pos[1]))

    def ground_truth_inserted(self, tool2world: Pose) -> bool:
        """Simulator ground truth (benchmarks only): the TCP is deeper than
        :attr:`success_depth` below the *true* hole entry and on the true hole axis."""
        return (
            self.insertion_depth(tool2world) >= self.success_depth
            and self.lateral_error(tool2world) < self.capture_radius
        )

    @property
    def entry_height(self) -> float:
        """Nominal height of the hole entry (m, world z): what the cell's drawing says."""
        return float(self.hole2world.pos[2])

    def detect_success(self, tool2world: Pose) -> bool:
        """The success detector, from what a robot measures: its TCP is at least
        :attr:`success_depth` below the nominal entry height. Nothing but a hole lets the part
        that low, so no knowledge of where the hole is is needed."""
        return self.entry_height - float(tool2world.pos[2]) >= self.success_depth

    @property
    def contact(self) -> ContactParams:
        """Contact model of this cell; a ``friction`` task parameter sets the coefficient."""
        friction = getattr(self.params, "friction", None)
        return ContactParams() if friction is None else ContactParams(friction=float(friction))

    @property
    def capture_radius(self) -> float:
        """Lateral TCP offset (m) beyond which the part cannot be inside the hole."""
        return 0.005

    # --------------------------------------------------------------------------- protocols
    @abstractmethod
    def search_pose(self, state: np.ndarray, search2world: Pose, height: float = 0.0) -> Pose:
        """Tool pose for a search state (``search_dims``) given the search frame."""

    def contact_pose(self, xy: np.ndarray, rz: float = 0.0) -> Pose:
        """TCP pose resting on the surface at world ``xy`` with yaw ``rz``."""
        return Pose.from_xyz_rz(float(xy[0]), float(xy[1]), self.surface_z, rz)

    @abstractmethod
    def teacher_start(self, rng: np.random.Generator) -> Pose:
        """A worst-case start for a blind demonstration (on the surface, off the hole)."""

    @abstractmethod
    def protocol_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None = None
    ) -> list[Pose]:
        """Start poses for a paper protocol (``"table1"``, ``"table3"``, ...)."""

    # ------------------------------------------------------------------------------- I/O
    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]) -> Self:
        """Build from a mapping of parameter names to values (unknown names are an error)."""
        fields = {f.name: f for f in dataclasses.fields(cls.params_type)}
        unknown = sorted(set(values) - set(fields))
        if unknown:
            raise TaskError(f"unknown {cls.name} parameter(s) {unknown}; known: {sorted(fields)}")
        kwargs = {}
        for key, val in values.items():
            default = getattr(cls.params_type(), key)
            kwargs[key] = tuple(val) if isinstance(default, tuple) else type(default)(val)
        return cls(cls.params_type(**kwargs))

    @classmethod
    def from_toml(cls, path: str | Path) -> Self:
        """Load parameters from a TOML file (a flat table, or a ``[params]`` table)."""
        try:
            data = tomllib.loads(Path(path).read_text())
        except (OSError, tomllib.TOMLDecodeError) as exc:
            raise TaskError(f"cannot read task file {path}: {exc}") from exc
        data = data.get("params", data)
        data = {k: v for k, v in data.items() if k != "task"}
        return cls.from_mapping(data)

    def param_table(self) -> list[tuple[str, Any, str]]:
        """``(name, value, description)`` rows for listing a task's parameters."""
        rows = []
        for f in dataclasses.fields(self.params):
            rows.append((f.name, getattr(self.params, f.name), f.metadata.get("doc", "")))
        return rows
