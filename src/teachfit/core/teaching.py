"""How a person demonstrating a task would adapt to its cell and to the robot they guide.

A task knows its cell (a clearance of a tenth of a millimetre asks for raster rows that close
together), a robot knows its hand feel (a heavy arm is guided slower). Both state it as
:class:`TeacherHints`; the simulated blind teacher
(:class:`~teachfit.execution.teacher.BlindTeacher`) applies them to the fields of its style
that the user left at their defaults. Units as in the teacher's style: m, m/s, s, rad, N,
N/m, Hz.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class TeacherHints:
    """Overrides of the blind teacher's style; ``None`` leaves a field as it is.

    Attributes
    ----------
    pattern : {"sweep", "spiral", "zigzag"}, optional
        The search pattern.
    speed : float, optional
        Hand speed along the pattern (m/s).
    belief_sigma, spiral_pitch, sweep_halfwidth, wander_amplitude : float, optional
        Belief spread, raster row spacing, raster half-width and slow wander (m).
    hand_smoothing : float, optional
        Time constant of the hand's low-pass (s).
    rz_belief_sigma, rz_wiggle : float, optional
        Yaw belief spread and wiggle amplitude (rad).
    rz_wiggle_frequency : float, optional
        Yaw wiggle frequency (Hz).
    push_force, press_feel : float, optional
        Press (N) and the gain of pressing by feel (1).
    arm_stiffness : float, optional
        Lateral stiffness of the guiding hand (N/m).
    max_duration : float, optional
        Longest demonstration (s).
    hold_depth : float, optional
        Sinking (m) after which the hand stops moving the part sideways.
    tilt, tilt_reach : float, optional
        Tilt of the held part (rad) and how far a dropped part is slid (m).
    """

    pattern: str | None = None
    speed: float | None = None
    belief_sigma: float | None = None
    spiral_pitch: float | None = None
    sweep_halfwidth: float | None = None
    wander_amplitude: float | None = None
    hand_smoothing: float | None = None
    rz_belief_sigma: float | None = None
    rz_wiggle: float | None = None
    rz_wiggle_frequency: float | None = None
    push_force: float | None = None
    press_feel: float | None = None
    arm_stiffness: float | None = None
    max_duration: float | None = None
    hold_depth: float | None = None
    tilt: float | None = None
    tilt_reach: float | None = None

    def overrides(self) -> dict[str, Any]:
        """The hinted fields, by name (the ``None`` ones left out)."""
        return {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if getattr(self, f.name) is not None
        }

    def then(self, other: TeacherHints) -> TeacherHints:
        """These hints with ``other``'s hinted fields on top (``other`` wins)."""
        return dataclasses.replace(self, **other.overrides())


#: no hints at all (a robot a person guides as the paper's teacher did)
NO_TEACHER_HINTS = TeacherHints()
