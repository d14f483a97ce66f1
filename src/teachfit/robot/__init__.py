"""Robots behind one protocol: the interface, the registry, and the simulated floating tool."""

from teachfit.robot.interface import Robot
from teachfit.robot.registry import ROBOTS, make_robot, register

__all__ = ["ROBOTS", "Robot", "make_robot", "register"]
