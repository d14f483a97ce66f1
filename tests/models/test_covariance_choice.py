import json

import numpy as np
import pytest

from teachfit.core.errors import ModelError
from teachfit.models.covariance_choice import CovarianceChoice, choose_covariance
from teachfit.models.exploration import fit_exploration
from teachfit.models.search_data import DemoArrays
from teachfit.models.search_model import SearchModel

DIMS = ("x", "y")


def _fit(states, structure):
    return fit_exploration(states, DIMS, covariance=structure)


def _states(slope: float, seed: int, n: int = 300) -> np.ndarray:
    """A sweep along y = slope * x with a little spread across it (m)."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-0.01, 0.01, n)
    return np.column_stack([x, slope * x + rng.normal(0.0, 0.0005, n)])


def test_correlations_that_flip_between_demonstrations_choose_per_dof_variances():
    choice = choose_covariance([_states(1.0, 0), _states(-1.0, 1)], _fit)
    assert choice.covariance == "diag" and choice.criterion == "held-out"
    assert choice.scores["diag"] > choice.scores["full"]
    assert "leave-one-demonstration-out" in choice.describe()


def test_a_correlation_every_demonstration_shares_keeps_the_full_covariance():
    choice = choose_covariance([_states(1.0, 0), _states(1.0, 1), _states(1.0, 2)], _fit)
    assert choice.covariance == "full" and choice.scores["full"] > choice.scores["diag"]


def test_one_demonstration_keeps_the_papers_full_covariance():
    choice = choose_covariance([_states(1.0, 0)], _fit)
    assert (choice.covariance, choice.criterion, choice.scores) == (
        "full",
        "single demonstration",
    ) + ({},)
    with pytest.raises(ModelError, match="covariance"):
        CovarianceChoice("spherical", "given")


def _demo(slope: float, seed: int) -> DemoArrays:
    s = _states(slope, seed)
    order = np.argsort(s[:, 0])
    n = s.shape[0]
    pos = np.column_stack([s[order], np.zeros(n)])
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    return DemoArrays(t=np.arange(n) / 100.0, pos=pos, quat=quat, wrench=None, name=f"d{seed}")


def test_the_model_records_the_choice_and_its_file_keeps_it(tmp_path):
    model = SearchModel.fit([_demo(1.0, 0), _demo(-1.0, 1)], "peg2d")
    assert model.covariance_choice.covariance == "diag"
    assert np.allclose(model.exploration.covs[0], np.diag(np.diag(model.exploration.covs[0])))
    path = model.save(tmp_path / "m.json")
    again = SearchModel.load(path)
    assert again.covariance_choice == model.covariance_choice
    given = SearchModel.fit([_demo(1.0, 0), _demo(-1.0, 1)], "peg2d", covariance="full")
    assert given.covariance_choice.criterion == "given"
    assert abs(given.exploration.covs[0][0, 1]) > 1e-7  # the full fit keeps the correlation
    # a model file from before the choice was recorded still loads
    doc = json.loads(path.read_text())
    del doc["covariance_choice"]
    (tmp_path / "old.json").write_text(json.dumps(doc))
    assert SearchModel.load(tmp_path / "old.json").covariance_choice is None
    with pytest.raises(ModelError, match="auto"):
        SearchModel.fit([_demo(1.0, 0)], "peg2d", covariance="spherical")
