"""Replay a demonstration from new start poses: the baseline before any learning."""

from __future__ import annotations

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.demonstrations.dataset import Demonstration


def replay_trajectory(
    demo: Demonstration, start: Pose, wrench_ff: bool = False
) -> SetpointTrajectory:
    """The demonstrated motion, relative to its own first pose, re-anchored at ``start``.

    ``search2world`` is ``start``: the demonstration's search frame (first pose = origin) is
    placed at the new start. With ``wrench_ff`` the demonstrated action wrench (the negated
    measured wrench, x-y and torques only) is fed forward.
    """
    rel = demo.in_search_frame()
    ff = np.zeros((rel.n_samples, 6))
    if wrench_ff and rel.wrench is not None:
        ff = -np.array(rel.wrench)
        ff[:, 2] = 0.0  # the runner's push handles the normal direction
    traj = SetpointTrajectory(
        t=rel.t, pos=rel.pos, quat=rel.quat, wrench_ff=ff, name=f"replay:{demo.name}"
    )
    return traj.transformed(start)
