import json

import numpy as np
import pytest

from teachfit.core.errors import ModelError
from teachfit.models.search_data import DemoArrays, search_data, yaw_relative
from teachfit.models.search_model import SearchModel


def _yaw_quat(yaw):
    return np.stack([np.cos(yaw / 2), 0 * yaw, 0 * yaw, np.sin(yaw / 2)], axis=1)


def make_demo(seed=0, n=400, rate=100.0, rot=True, offset=(0.3, -0.2, 0.1), wrench=True):
    """A blind-search-like demo: a slow wobbly sweep with friction opposing the motion."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    xy = np.cumsum(rng.normal(size=(n, 2)) * 2e-4 + [1e-4, 0.5e-4], axis=0)
    pos = np.column_stack([xy, np.zeros(n)]) + offset
    yaw = 0.2 * np.sin(t) if rot else np.zeros(n)
    w = None
    if wrench:
        vel = np.gradient(xy, t, axis=0)
        f = -5.0 * vel / (np.linalg.norm(vel, axis=1, keepdims=True) + 1e-9)  # friction
        w = np.column_stack([f, -10 * np.ones(n), np.zeros((n, 2)), -0.3 * np.gradient(yaw, t)])
    return DemoArrays(t=t, pos=pos, quat=_yaw_quat(yaw + 0.7), wrench=w, name=f"demo{seed}")


def test_search_data_frames_and_actions():
    d = make_demo()
    data = search_data([d], ("x", "y", "rz"))
    np.testing.assert_allclose(data.states[0], 0.0, atol=1e-12)
    np.testing.assert_allclose(data.states[:, 2], 0.2 * np.sin(d.t), atol=1e-9)
    assert data.steps.shape == data.actions.shape == (399, 3)
    np.testing.assert_allclose(data.actions[:, 0], -d.wrench[:-1, 0])
    np.testing.assert_allclose(data.actions[:, 2], -d.wrench[:-1, 5])
    assert data.rate_hz == pytest.approx(100.0)
    assert 0.005 < data.speed < 0.05
    np.testing.assert_allclose(yaw_relative(_yaw_quat(np.array([3.0, 3.2, 3.4]))), [0, 0.2, 0.4])


def test_resampling_to_common_rate():
    a, b = make_demo(0, rate=100.0), make_demo(1, n=200, rate=50.0)
    data = search_data([a, b], ("x", "y"), rate_hz=100.0)
    assert data.n_demos == 2 and data.states.shape == (400 + 399, 2)
    assert data.steps.shape[0] == 399 + 398


def test_fit_save_load_roundtrip(tmp_path):
    m = SearchModel.fit([make_demo(0), make_demo(1)], "socket3d")
    assert m.dims == ("x", "y", "rz") and m.n_demos == 2 and m.angular_speed > 0
    path = m.save(tmp_path / "m.json")
    doc = json.loads(path.read_text())
    assert doc["format"] == "teachfit.search_model" and doc["version"] == 1
    m2 = SearchModel.load(path, task="socket3d", dims=("x", "y", "rz"))
    np.testing.assert_array_equal(m2.exploration.covs, m.exploration.covs)
    np.testing.assert_array_equal(m2.dynamics.means, m.dynamics.means)
    v = np.array([[0.01, 0.0, 0.0]])
    np.testing.assert_allclose(m2.feedforward(v), m.feedforward(v))
    with pytest.raises(ModelError, match="task"):
        SearchModel.load(path, task="peg2d")
    with pytest.raises(ModelError, match="dims"):
        SearchModel.load(path, dims=("x", "y"))
    (tmp_path / "bad.json").write_text('{"format": "other"}')
    with pytest.raises(ModelError):
        SearchModel.load(tmp_path / "bad.json")
    with pytest.raises(ModelError):
        SearchModel.load(tmp_path / "missing.json")


def test_feedforward_pushes_along_motion():
    m = SearchModel.fit([make_demo(0)], "peg2d")
    ff = m.feedforward(np.array([[0.02, 0.0], [-0.02, 0.0]]))
    assert ff[0, 0] > 0 > ff[1, 0]


def test_no_wrench_gives_zero_feedforward_and_bad_demo_raises():
    m = SearchModel.fit([make_demo(0, wrench=False)], "peg2d")
    assert m.dynamics is None
    np.testing.assert_array_equal(m.feedforward(np.ones((3, 2))), 0.0)
    d = make_demo(0)
    bad = DemoArrays(d.t, d.pos * np.nan, d.quat, d.wrench)
    with pytest.raises(ModelError):
        SearchModel.fit([bad], "peg2d")
    still = DemoArrays(d.t, np.zeros_like(d.pos), d.quat, d.wrench)
    with pytest.raises(ModelError):
        SearchModel.fit([still], "peg2d")
    with pytest.raises(ModelError):
        SearchModel.fit([d], "no-such-task")


def test_with_demonstration_type():
    from teachfit.demonstrations.dataset import Demonstration  # a failed import fails here

    d = make_demo(0)
    demo = Demonstration(
        t=d.t, pos=d.pos, quat=d.quat, wrench=d.wrench, task="peg2d", source="synthetic"
    )
    m = SearchModel.fit([demo], "peg2d")
    m_arr = SearchModel.fit([d], "peg2d")
    # the search frame may rotate positions, but the spread must be the same
    np.testing.assert_allclose(
        np.trace(m.exploration.covs[0]), np.trace(m_arr.exploration.covs[0]), rtol=1e-6
    )


def test_a_searched_yaw_is_made_even_by_default_and_offsets_are_not():
    demos = [make_demo(0), make_demo(1)]
    even = SearchModel.fit(demos, "socket3d")  # rz searched: auto mirror in rz
    plain = SearchModel.fit(demos, "socket3d", mirror=())
    e, p = even.exploration, plain.exploration
    assert e.n_components == 2 * p.n_components
    assert e.mean[2] == pytest.approx(0.0, abs=1e-12) and abs(p.mean[2]) > 1e-3
    np.testing.assert_allclose(e.mean[:2], p.mean[:2])  # x, y keep their side
    flat = SearchModel.fit(demos, "peg2d")  # no rz: nothing mirrored
    assert flat.exploration.n_components == p.n_components
