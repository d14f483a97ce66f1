"""A torque-controlled Franka Research 3 in MuJoCo: model, torque law, IK, sensing, robot."""

from teachfit.robot.fr3.params import FR3Params
from teachfit.robot.fr3.robot import FR3Robot

__all__ = ["FR3Params", "FR3Robot"]
