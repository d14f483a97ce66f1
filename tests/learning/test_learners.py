"""Learners behind one ask/tell interface: improvement, bounds, restore, parameter spaces."""

from __future__ import annotations

import math

import numpy as np
import pytest

from teachfit.learning import (
    Finished,
    Learner,
    LearningError,
    ParamDomain,
    ParamSpace,
    make_learner,
)

SPACE = ParamSpace(
    {
        "force": ParamDomain(1.0, 20.0),
        "freq": ParamDomain(0.1, 10.0, log=True),
        "amp": ParamDomain(-0.01, 0.01),
    }
)
OPTIMUM = {"force": 12.0, "freq": 3.0, "amp": -0.004}
OPTIONS = {"cmaes": {}, "pso": {}, "lhs": {"n": 60}, "bo": {"sampler": "tpe"}}


def shifted_sphere(p: dict[str, float]) -> float:
    u = SPACE.to_unit(p) - SPACE.to_unit(OPTIMUM)
    return float(u @ u)


def drive(learner: Learner, n: int) -> list[float]:
    costs = []
    for _ in range(n):
        cand = learner.ask()
        assert cand is not None
        assert all(0.0 <= u <= 1.0 for u in cand.u)
        params = SPACE.from_unit(cand.u)
        SPACE.validate(params)  # inside every domain
        costs.append(shifted_sphere(params))
        learner.tell(cand, costs[-1])
    return costs


@pytest.mark.parametrize("method", ["cmaes", "pso", "bo", "lhs"])
def test_each_learner_improves_within_a_small_budget(method: str) -> None:
    learner = make_learner(method, SPACE, seed=3, options=OPTIONS[method])
    assert isinstance(learner, Learner)
    costs = drive(learner, 60)
    first = float(np.mean(costs[:10]))
    best = min(costs)
    assert best < 0.25 * first
    if method != "lhs":  # the informed learners get close; the reference only samples
        assert best < 0.03


def test_gp_bayesian_optimisation_is_the_default_and_learns(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    torch = pytest.importorskip("torch")
    threadpoolctl = pytest.importorskip("threadpoolctl")
    learner = make_learner("bo", SPACE, seed=1, options={"n_startup": 4})
    sampler = learner._study.sampler
    assert type(sampler).__name__ == "GPSampler"
    threads, blas, fit = [], [], sampler.sample_relative

    def counted(*a):  # noqa: ANN002, ANN202
        threads.append(torch.get_num_threads())
        blas.append(max(p["num_threads"] for p in threadpoolctl.threadpool_info()))
        return fit(*a)

    monkeypatch.setattr(sampler, "sample_relative", counted)
    blas_before = threadpoolctl.threadpool_info()
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        costs = drive(learner, 12)  # 8 GP-guided trials after 4 random ones
        after = torch.get_num_threads()
    finally:
        torch.set_num_threads(before)
    assert min(costs[4:]) < 0.02 < min(costs[:4])
    # the GP works on one thread (its tensors are small), and the caller keeps its count
    assert threads == [1] * 12 and after == 2
    assert blas == [1] * 12  # BLAS and OpenMP too (a waiting OpenBLAS thread spins)
    assert threadpoolctl.threadpool_info() == blas_before


@pytest.mark.parametrize("method", ["cmaes", "pso", "lhs"])
def test_a_restored_learner_asks_what_the_original_would(method: str) -> None:
    a = make_learner(method, SPACE, seed=5, options=OPTIONS[method])
    finished = []
    for _ in range(23):  # mid-generation for both population learners
        cand = a.ask()
        assert cand is not None
        cost = shifted_sphere(SPACE.from_unit(cand.u))
        a.tell(cand, cost)
        finished.append(Finished(cand, cost))
    b = make_learner(method, SPACE, seed=5, options=OPTIONS[method])
    b.restore(finished)
    for _ in range(12):
        ca, cb = a.ask(), b.ask()
        assert ca is not None and cb is not None
        assert ca.key == cb.key and np.allclose(ca.u, cb.u)
        assert ca.key not in {f.candidate.key for f in finished}
        cost = shifted_sphere(SPACE.from_unit(ca.u))
        a.tell(ca, cost)
        b.tell(cb, cost)


def test_population_learners_wait_for_their_generation() -> None:
    learner = make_learner("cmaes", SPACE, seed=0, options={"popsize": 4})
    cands = [learner.ask() for _ in range(4)]
    assert learner.ask() is None  # nothing until the generation is told
    for c in cands:
        assert c is not None
        learner.tell(c, 1.0)
    assert learner.ask() is not None
    with pytest.raises(LearningError):
        learner.tell(cands[0], 1.0)  # an old generation


def test_lhs_design_is_stratified_and_exhausts() -> None:
    learner = make_learner("lhs", SPACE, seed=0, options={"n": 8})
    cands = [learner.ask() for _ in range(8)]
    assert learner.ask() is None
    u = np.array([c.u for c in cands if c is not None])
    for j in range(SPACE.dim):  # one point per stratum in every coordinate
        assert sorted(np.floor(u[:, j] * 8).astype(int)) == list(range(8))


def test_param_space_validation_names_the_parameter() -> None:
    with pytest.raises(LearningError, match="force"):
        SPACE.validate({"force": 30.0, "freq": 1.0, "amp": 0.0})
    with pytest.raises(LearningError, match="unknown"):
        SPACE.validate({"force": 3.0, "freq": 1.0, "amp": 0.0, "speed": 1.0})
    with pytest.raises(LearningError, match="missing"):
        SPACE.validate({"force": 3.0})
    with pytest.raises(LearningError):
        ParamDomain(1.0, 1.0)
    with pytest.raises(LearningError):
        ParamDomain(0.0, 1.0, log=True)
    with pytest.raises(LearningError):
        make_learner("random", SPACE)
    u = SPACE.to_unit(OPTIMUM)
    back = SPACE.from_unit(u)
    assert all(math.isclose(back[k], v, rel_tol=1e-12, abs_tol=1e-15) for k, v in OPTIMUM.items())
    assert ParamSpace.from_json(SPACE.to_json()) == SPACE
