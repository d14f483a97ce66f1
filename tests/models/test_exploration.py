import numpy as np
import pytest

from teachfit.core.errors import ModelError, TeachfitError
from teachfit.models.exploration import ExplorationDistribution, fit_exploration


def test_ml_gaussian_matches_sample_moments():
    rng = np.random.default_rng(0)
    cov = np.array([[4e-4, 1e-4], [1e-4, 1e-4]])
    x = rng.multivariate_normal([0.01, -0.02], cov, size=4000)
    e = fit_exploration(x, ("x", "y"), rel_floor=0.0, abs_floor=[0.0, 0.0])
    assert e.n_components == 1
    np.testing.assert_allclose(e.means[0], x.mean(axis=0), atol=1e-12)
    np.testing.assert_allclose(e.covs[0], np.cov(x.T, bias=True), rtol=1e-9)


def test_degenerate_line_is_well_posed_and_thin():
    t = np.linspace(0.0, 0.02, 200)
    x = np.stack([t, 0.5 * t], axis=1)  # all on a line
    e = fit_exploration(x, ("x", "y"))
    eig = np.linalg.eigvalsh(e.covs[0])
    assert eig.min() > 0
    # across the line: at most a few percent of the spread along it
    assert np.sqrt(eig.min() / eig.max()) < 0.1
    s = e.sample(2000, np.random.default_rng(1))
    d = np.abs(s[:, 1] - 0.5 * s[:, 0]) / np.hypot(1, 0.5)
    assert np.percentile(d, 95) < 0.1 * np.ptp(x[:, 0])


def test_constant_rotation_dim_gets_absolute_floor():
    rng = np.random.default_rng(2)
    x = np.column_stack([rng.normal(size=(100, 2)) * 0.01, np.zeros(100)])
    e = fit_exploration(x, ("x", "y", "rz"))
    assert np.sqrt(e.covs[0][2, 2]) == pytest.approx(1e-3, rel=0.01)


def test_bic_picks_two_clusters_and_pdf_integrates():
    rng = np.random.default_rng(3)
    x = np.vstack([rng.normal([0, 0], 0.002, (300, 2)), rng.normal([0.03, 0], 0.002, (300, 2))])
    e = fit_exploration(x, ("x", "y"), n_components="bic", max_components=4)
    assert e.n_components == 2
    one = fit_exploration(x, ("x", "y"))
    assert e.logpdf(x).mean() > one.logpdf(x).mean()
    lo, hi = e.bounding_box(5.0)
    g = np.stack(np.meshgrid(*[np.linspace(a, b, 300) for a, b in zip(lo, hi, strict=True)]), -1)
    cell = np.prod((hi - lo) / 299)
    assert e.pdf(g.reshape(-1, 2)).sum() * cell == pytest.approx(1.0, abs=0.02)


def test_sampling_is_seeded_and_matches_moments():
    e = ExplorationDistribution(
        ("x", "y"), np.ones(1), np.array([[1.0, 2.0]]), np.array([[[2.0, 0.5], [0.5, 1.0]]])
    )
    a = e.sample(20000, np.random.default_rng(5))
    b = e.sample(20000, np.random.default_rng(5))
    np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(a.mean(axis=0), [1.0, 2.0], atol=0.05)
    np.testing.assert_allclose(np.cov(a.T), e.covs[0], atol=0.06)
    lo, hi = e.bounding_box(3.0)
    np.testing.assert_allclose(lo, [1 - 3 * np.sqrt(2), -1.0])
    np.testing.assert_allclose(hi, [1 + 3 * np.sqrt(2), 5.0])


@pytest.mark.parametrize(
    "x",
    [
        np.zeros((10, 2)),  # constant
        np.ones((2, 2)) * [[0], [1]],  # fewer than D + 1 samples
        np.array([[0.0, 0.0], [1.0, np.nan], [2.0, 1.0], [0.0, 3.0]]),
    ],
)
def test_bad_data_raises_model_error(x):
    with pytest.raises(ModelError):
        fit_exploration(x, ("x", "y"))


def test_bad_sample_count_and_roundtrip():
    e = fit_exploration(np.random.default_rng(0).normal(size=(50, 2)), ("x", "y"))
    for n in (0, -3):
        with pytest.raises(TeachfitError):
            e.sample(n, np.random.default_rng(0))
    e2 = ExplorationDistribution.from_dict(e.to_dict())
    np.testing.assert_array_equal(e2.covs, e.covs)
    with pytest.raises(ModelError):
        ExplorationDistribution(("x", "y"), np.ones(1), np.zeros((1, 2)), -np.eye(2)[None])


def test_qmc_samples_have_the_distributions_mean_and_covariance():
    from teachfit.models.exploration import ExplorationDistribution

    cov = np.array([[4.0, 1.0, 0.2], [1.0, 1.0, -0.3], [0.2, -0.3, 0.5]])
    e = ExplorationDistribution(
        ("x", "y", "rz"), np.array([1.0]), np.array([[1.0, 2.0, -1.0]]), cov[None]
    )
    x = e.sample(4096, np.random.default_rng(0), qmc=True)
    assert np.allclose(x.mean(axis=0), [1.0, 2.0, -1.0], atol=0.01)
    assert np.allclose(np.cov(x.T), cov, atol=0.03)


def test_qmc_samples_cover_more_evenly_than_iid_draws():
    from scipy.spatial import cKDTree

    from teachfit.models.exploration import ExplorationDistribution

    e = ExplorationDistribution(("x", "y"), np.array([1.0]), np.zeros((1, 2)), np.eye(2)[None])
    grid = np.stack(np.meshgrid(np.linspace(-1, 1, 41), np.linspace(-1, 1, 41)), -1).reshape(-1, 2)
    gaps = []
    for qmc in (True, False):
        pts = e.sample(300, np.random.default_rng(1), qmc=qmc)
        gaps.append(cKDTree(pts).query(grid)[0].max())  # largest empty hole in the core
    assert gaps[0] < gaps[1]


def test_diagonal_covariance_drops_correlations_and_keeps_variances():
    from teachfit.models.exploration import fit_exploration

    rng = np.random.default_rng(0)
    t = rng.uniform(-1, 1, 500)
    x = np.column_stack([0.01 * t, 0.01 * t + 0.001 * rng.standard_normal(500)])
    full = fit_exploration(x, ("x", "y"))
    diag = fit_exploration(x, ("x", "y"), covariance="diag")
    assert abs(full.cov[0, 1]) > 0.9 * np.sqrt(full.cov[0, 0] * full.cov[1, 1])
    assert diag.cov[0, 1] == 0.0
    assert np.allclose(np.diag(diag.cov), np.diag(full.cov), rtol=1e-6)
    two = fit_exploration(x, ("x", "y"), n_components=2, covariance="diag")
    assert two.covs.shape == (2, 2, 2) and np.all(two.covs[:, 0, 1] == 0.0)
    with pytest.raises(ModelError):
        fit_exploration(x, ("x", "y"), covariance="spherical")


def test_mirrored_is_even_in_the_mirrored_dofs_only():
    rng = np.random.default_rng(4)
    x = rng.multivariate_normal([0.002, -0.001, 0.25], np.diag([1e-5, 4e-6, 0.1]), size=500)
    e = fit_exploration(x, ("x", "y", "rz"))
    m = e.mirrored(["rz"])
    assert m.n_components == 2 * e.n_components
    flip = np.array([1.0, 1.0, -1.0])
    s = e.sample(50, np.random.default_rng(5))
    np.testing.assert_allclose(m.pdf(s), m.pdf(s * flip), rtol=1e-9)
    np.testing.assert_allclose(m.pdf(s), 0.5 * (e.pdf(s) + e.pdf(s * flip)), rtol=1e-9)
    # the turn's mean goes to zero and its variance takes the mean's square; x, y unchanged
    np.testing.assert_allclose(m.mean, [e.mean[0], e.mean[1], 0.0], atol=1e-15)
    assert m.cov[2, 2] == pytest.approx(e.cov[2, 2] + e.mean[2] ** 2)
    assert e.mirrored([]) is e
    with pytest.raises(ModelError, match=r"cannot mirror \['z'\]"):
        e.mirrored(["z"])
