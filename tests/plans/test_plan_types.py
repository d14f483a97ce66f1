"""The planner's settings and results as values."""

import numpy as np
import pytest

from teachfit.core.errors import PlanningError, TeachfitError
from teachfit.plans.plan_types import PlannerConfig, PlanResult


@pytest.mark.parametrize(
    "kwargs",
    [
        {"planner": "DDRRT"},
        {"te": 0.0},
        {"max_checks": 0},
        {"smooth_steps": -1},
        {"key_region": -1},
    ],
)
def test_bad_config_is_refused(kwargs):
    with pytest.raises(PlanningError):
        PlannerConfig(**kwargs)


def test_result_poses_and_transforms():
    path = np.array([[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], [0.01, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]])
    r = PlanResult(True, path, 0.1, 0.2, 1, 2, 6, 0, 100, "RRTConnect", "ok")
    assert len(r.poses) == 2
    T = r.L2G()
    assert T.shape == (2, 4, 4)
    np.testing.assert_allclose(T[1, :3, 3], [0.01, 0.0, 0.0])
    np.testing.assert_allclose(T[1, :3, :3], np.diag([-1.0, -1.0, 1.0]), atol=1e-12)


def test_result_saves_its_path_and_leaves_nothing_on_failure(tmp_path):
    path = np.array([[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], [0.01, 0.02, 0.0, 0.0, 0.0, 0.0, 1.0]])
    r = PlanResult(True, path, 0.1, 0.2, 1, 2, 6, 0, 100, "RRTConnect", "ok")
    out = r.save(tmp_path / "sub" / "path.npy")
    np.testing.assert_array_equal(np.load(out), path)
    blocked = tmp_path / "file"
    blocked.write_text("x")
    with pytest.raises(TeachfitError, match="path file"):
        r.save(blocked / "path.npy")  # its folder is a file
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "sub"]
