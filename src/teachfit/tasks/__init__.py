"""Simulated assembly cells generated from parameters (lengths in metres)."""

from teachfit.tasks.base import ContactParams, Task
from teachfit.tasks.key import Key, KeyParams
from teachfit.tasks.peg import AluminiumPeg, AluminiumPegParams
from teachfit.tasks.peg2d import Peg2D, Peg2DParams
from teachfit.tasks.puzzle import Puzzle, PuzzleParams
from teachfit.tasks.registry import TASKS, get_task, load_task
from teachfit.tasks.skill_protocol import SkillProtocolParams, SkillTask
from teachfit.tasks.socket3d import Socket3D, Socket3DParams

__all__ = [
    "TASKS",
    "AluminiumPeg",
    "AluminiumPegParams",
    "ContactParams",
    "Key",
    "KeyParams",
    "Peg2D",
    "Peg2DParams",
    "Puzzle",
    "PuzzleParams",
    "SkillProtocolParams",
    "SkillTask",
    "Socket3D",
    "Socket3DParams",
    "Task",
    "get_task",
    "load_task",
]
