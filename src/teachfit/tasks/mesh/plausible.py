"""Plausible part sizes: a unit mistake shows as a part too large for a robot cell or smaller
than a millimetre.

A CAD mesh carries no units; the task file declares them (``units``). Read at the wrong units
a part is 10, 25.4 or 1000 times too large or too small: a 100 mm plate in millimetres
declared as centimetres is a 1 m plate, which the simulation accepts and the checks then
judge at the wrong scale. The parts' sizes (in metres, after the declared units) are checked
against :data:`MAX_SIZE` and :data:`MIN_SIZE` before anything else is done with them, and a
refusal names the units at which both parts are plausible.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.spec import UNITS

#: largest plausible extent (m) of each part along any axis: a part a robot arm holds and
#: inserts, and a fixture on its table (within the arm's reach)
MAX_SIZE = {"held": 0.3, "fixed": 0.6}
#: smallest plausible largest extent (m) of a part
MIN_SIZE = 0.001
#: typical largest extent (m) of each part: ranks the units that give plausible sizes
TYPICAL_SIZE = {"held": 0.03, "fixed": 0.1}


@dataclass(frozen=True)
class PartSize:
    """A part's extents along its mesh axes in the mesh's own numbers (file units)."""

    role: str
    path: Path
    extents: np.ndarray

    def problem(self, scale: float) -> str | None:
        """Why the part is implausible at ``scale`` metres per unit (None: plausible)."""
        size = float(self.extents.max()) * scale
        if size > MAX_SIZE[self.role]:
            limit = 1e3 * MAX_SIZE[self.role]
            return f"larger than a robot cell takes (a {self.role} part at most {limit:g} mm)"
        if size < MIN_SIZE:
            return "smaller than a millimetre"
        return None


def plausible_units(parts: Sequence[PartSize]) -> list[str]:
    """The units at which every part is plausible, the one giving the most typical sizes
    first."""
    fits = [u for u, s in UNITS.items() if all(p.problem(s) is None for p in parts)]

    def oddness(unit: str) -> float:
        s = UNITS[unit]
        return sum(abs(np.log10(float(p.extents.max()) * s / TYPICAL_SIZE[p.role])) for p in parts)

    return sorted(fits, key=oddness)


def check_sizes(parts: Sequence[PartSize], units: str, task_file: Path) -> None:
    """Refuse a part implausibly large or small at ``units``, naming its file and the units
    that fit (one line)."""
    scale = UNITS[units]
    for part in parts:
        problem = part.problem(scale)
        if problem is None:
            continue
        dims = " x ".join(_mm(1e3 * e * scale) for e in part.extents)
        raise TaskError(
            f'{task_file} [{part.role}] mesh: {part.path} is {dims} mm at units = "{units}", '
            f"{problem}; {_hint(part, parts)}"
        )


def _mm(value: float) -> str:
    return f"{value:.0f}" if value >= 100 else f"{value:.3g}"


def _hint(part: PartSize, parts: Sequence[PartSize]) -> str:
    """The units to declare: those at which every part is plausible, else this part's."""
    fits = plausible_units(parts)
    if fits:
        u = fits[0]
        return f'the meshes look like "{u}": set units = "{u}" in the task file (--units {u})'
    alone = plausible_units([part])
    if alone:
        return (
            f'this mesh looks like "{alone[0]}", the other part\'s not: export both parts in '
            "the same units, then set units to those"
        )
    return "no units give it a plausible size: check its scale in CAD"
