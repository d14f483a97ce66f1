"""Simulated assembly cells generated from parameters (lengths in metres)."""

from teachfit.tasks.base import ContactParams, Task
from teachfit.tasks.peg2d import Peg2D, Peg2DParams
from teachfit.tasks.registry import TASKS, get_task, load_task
from teachfit.tasks.socket3d import Socket3D, Socket3DParams

__all__ = [
    "TASKS",
    "ContactParams",
    "Peg2D",
    "Peg2DParams",
    "Socket3D",
    "Socket3DParams",
    "Task",
    "get_task",
    "load_task",
]
