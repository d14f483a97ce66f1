"""Simulated assembly cells generated from parameters (lengths in metres).

Three concerns, three sub-packages: :mod:`~teachfit.tasks.geometry` (parameters, hole frame,
success test: the :class:`Task` classes), :mod:`~teachfit.tasks.scene` (MuJoCo bodies,
``task.scene``) and :mod:`~teachfit.tasks.protocols` (search and start poses,
``task.protocol``).
"""

from teachfit.tasks.base import Task
from teachfit.tasks.geometry.key import Key, KeyParams
from teachfit.tasks.geometry.peg import AluminiumPeg, AluminiumPegParams
from teachfit.tasks.geometry.peg2d import Peg2D, Peg2DParams
from teachfit.tasks.geometry.puzzle import Puzzle, PuzzleParams
from teachfit.tasks.geometry.skill import SkillTask
from teachfit.tasks.geometry.socket3d import Socket3D, Socket3DParams
from teachfit.tasks.protocols.base import Protocol
from teachfit.tasks.protocols.skill import SkillProtocol, SkillProtocolParams
from teachfit.tasks.registry import TASKS, get_task, load_task, search_dims_of
from teachfit.tasks.scene.builder import SceneBuilder
from teachfit.tasks.scene.mjcf import ContactParams

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
    "Protocol",
    "PuzzleParams",
    "SceneBuilder",
    "SkillProtocol",
    "SkillProtocolParams",
    "SkillTask",
    "Socket3D",
    "Socket3DParams",
    "Task",
    "get_task",
    "load_task",
    "search_dims_of",
]
