"""Planned paths executed in contact: capture errors, the seating skill, one short trial."""

import numpy as np
import pytest

from teachfit.core.geometry import Pose
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.plan_contact import (
    T2G,
    capture_error,
    contact_skill,
    run_plan_trials,
)
from teachfit.tasks.registry import build_assembly


def test_capture_error_magnitudes_lie_in_their_ranges():
    for seed in range(10):
        e = capture_error(np.random.default_rng(seed))
        t = np.linalg.norm([e["dx"], e["dy"], e["dz"]])
        assert 0.0005 <= t <= 0.003
        from scipy.spatial.transform import Rotation

        r = Rotation.from_euler("xyz", [e["droll"], e["dpitch"], e["dyaw"]]).magnitude()
        assert np.radians(0.5) - 1e-9 <= r <= np.radians(2.0) + 1e-9


def _final_slide(part: str, back: float = 0.005) -> SetpointTrajectory:
    """The last ``back`` m of the insertion along G's -x, as set-points in frame T."""
    goal = Pose.from_matrix(build_assembly(part).goal)
    t = np.linspace(0.0, 0.5, 51)
    poses = [T2G.inverse().compose(goal.translated([back * (1 - s / 0.5), 0, 0])) for s in t]
    return SetpointTrajectory.from_path(
        t, np.array([p.pos for p in poses]), np.array([p.quat for p in poses])
    )


def test_seating_skill_and_open_loop_graphs():
    path = _final_slide("l-groove")
    joined = contact_skill(path, "l-groove", "joined")
    assert [n.name for n in joined.nodes] == ["path", "seat", "retry"]
    assert [n.name for n in contact_skill(path, "l-groove", retries=0).nodes] == ["path", "seat"]
    ctx = joined.params.context
    assert (
        ctx["t_max"].value
        > contact_skill(path, "l-groove", retries=0).params.context["t_max"].value
    )
    assert [n.name for n in contact_skill(path, "l-groove", "open-loop").nodes] == ["path"]
    assert contact_skill(path, "tenon").params.context["seat_depth"].value == pytest.approx(0.006)


def test_the_l_is_seated_against_the_end_wall_despite_a_capture_error():
    path = _final_slide("l-groove")
    (tr,) = run_plan_trials(
        "l-groove", path, 1, seed=3, translation=(0.001, 0.0015), rotation=(0.002, 0.004)
    )
    assert 0.001 <= tr.error_m <= 0.0015
    assert tr.success and tr.ground_truth
    assert tr.result.visits[0].node == "path"  # seated at the path end or by the seat push
