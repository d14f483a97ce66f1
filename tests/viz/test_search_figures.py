import numpy as np
import pytest
from media_checks import read_png

from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.tshix import TshixPlanner
from teachfit.viz import search_figures as sf


@pytest.fixture
def expl3():
    return ExplorationDistribution(
        ("x", "y", "rz"),
        np.ones(1),
        np.array([[0.01, 0.005, 0.05]]),
        np.diag([1e-4, 4e-5, 0.01])[None],
    )


def test_all_figures_render(tmp_path, expl3):
    e2 = ExplorationDistribution(("x", "y"), np.ones(1), expl3.means[:, :2], expl3.covs[:, :2, :2])
    rng = np.random.default_rng(0)
    tr = TshixPlanner(e2, 0.01).plan(60, rng)
    tr3 = TshixPlanner(expl3, 0.01).plan(60, rng)
    figs = {
        "samples": sf.samples_over_distribution(e2, rng, ns=(100, 200)),
        "samples3": sf.samples_over_distribution(expl3, rng, ns=(100,)),
        "stages": sf.tshix_stages(tr, e2),
        "ff": sf.feedforward_arrows(tr, np.tile([1.0, -0.5], (tr.t.size, 1)), every=20),
        "traj3d": sf.trajectory_3d(tr3),
        "pve": sf.planned_vs_executed(tr.states, tr.states + 1e-4),
    }
    for name, fig in figs.items():
        p = sf.save(fig, tmp_path / f"{name}.png", dpi=40)
        w, h = fig.get_size_inches() * 40
        img = read_png(p, min_px=60)
        assert abs(img.shape[1] - w) <= 1 and abs(img.shape[0] - h) <= 1, (name, img.shape)
    with pytest.raises(ValueError):
        sf.trajectory_3d(tr)
