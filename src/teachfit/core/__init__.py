"""The values every layer shares: errors, poses and rotations, robot state and commands,
controller settings as data, set-point trajectories, execution outcomes, parameter domains.

``core`` imports no other teachfit package; every other package may import it.
"""
