"""Trials of whole assemblies: the same taught holes for every method, each method's graph."""

import numpy as np
import pytest
from search_models import raster_model

from teachfit.core.errors import TeachfitError
from teachfit.execution.assembly import (
    _search_context,
    assembly_jobs,
    method_skill,
    run_assembly,
    taught_hole,
)
from teachfit.execution.batch import episode_seed
from teachfit.tasks import get_task


@pytest.fixture(scope="module")
def peg():
    task = get_task("peg2d")
    return task, raster_model(task)


def test_taught_hole_is_off_by_exactly_the_error():
    task = get_task("peg2d")
    for seed in range(3):
        pose = taught_hole(task, 0.003, 0.1, np.random.default_rng(seed))
        off = pose.pos - task.hole2world.pos
        assert np.hypot(off[0], off[1]) == pytest.approx(0.003) and off[2] == 0.0
        assert pose.rz == 0.0  # peg2d's yaw does not matter
    sock = get_task("socket3d")
    yaws = [taught_hole(sock, 0.0, 0.1, np.random.default_rng(s)).rz for s in range(20)]
    assert 0 < max(abs(y) for y in yaws) <= 0.1
    with pytest.raises(TeachfitError, match="hole error"):
        taught_hole(task, -0.001, 0.0, np.random.default_rng(0))


def test_every_method_has_its_graph_and_search_needs_a_model(peg):
    _, model = peg
    names = {
        m: method_skill(m, model, "peg-in-hole", "impedance").name
        for m in ("skill", "search", "open-loop", "joined")
    }
    assert names == {
        "skill": "peg-in-hole",
        "search": "search",
        "open-loop": "open-loop",
        "joined": "peg-in-hole+search",
    }
    task = get_task("peg2d")
    alone = method_skill("search", model, "peg-in-hole", "adaptive", task)
    # the part is put down at the taught pose before the search moves it
    assert alone.start == "contact" and [n.name for n in alone.nodes] == ["contact", "search"]
    follow = alone.node("search").primitive
    assert follow.follow.hold_depth == task.search_hold_depth  # the search executor's hold
    plain = method_skill("search", model, "peg-in-hole", "adaptive").node("search").primitive
    assert plain.follow.hold_depth is None
    with pytest.raises(TeachfitError, match="search model"):
        assembly_jobs("peg2d", ["joined"], [0.0], 1, None)
    with pytest.raises(TeachfitError, match="unknown assembly method"):
        assembly_jobs("peg2d", ["magic"], [0.0], 1, model)


def test_same_trials_for_every_method_and_open_loop_misses_a_far_hole(peg):
    _, model = peg
    learned = (("search_points", 10.0),)  # a short search: the test checks the plumbing
    jobs = assembly_jobs(
        "peg2d", ["open-loop", "joined"], [0.004], 1, model, keep_log=True, learned=learned
    )
    ol, joined = run_assembly(jobs, workers=0)
    assert ol.offset == joined.offset  # the same taught hole
    assert np.hypot(*ol.offset) == pytest.approx(0.004)
    assert not ol.success and ol.nodes == ("approach", "descend")
    assert joined.nodes[:3] == ("approach", "contact", "lateral")
    assert joined.result is not None and joined.result.log.t.size > 10
    assert joined.success == (joined.result.outcome.value == "success")


def test_a_searching_method_is_told_the_error_s_size(peg):
    """The search's least spread is the taught hole's error (its size, not its direction);
    the skill alone has no search to tell."""
    _, model = peg
    jobs = assembly_jobs("peg2d", ["joined", "search", "skill"], [0.003], 1, model, seed=4)
    for job in jobs:
        sk = method_skill(job.method, model, job.skill, "impedance")
        ctx = _search_context(job, sk)
        if job.method == "skill":
            assert ctx == {}
        else:
            assert ctx["search_radius"] == pytest.approx(0.003)
            assert ctx["search_seed"] == float(episode_seed(4, 0))


def test_a_trial_reads_the_same_whatever_ran_before_it_in_the_process(peg):
    """The sensor noise is the trial's own (restarted from its seed), so a method's trial
    does not move when another method's trials run before it in the same process."""
    _, model = peg
    learned = (("search_points", 10.0),)
    jobs = assembly_jobs("peg2d", ["skill"], [0.001], 2, model, keep_log=True, learned=learned)
    alone = run_assembly(jobs[1:], workers=0)[0]
    after = run_assembly(jobs, workers=0)[1]
    assert alone.index == after.index == 1 and alone.result is not None
    assert after.result is not None
    np.testing.assert_array_equal(alone.result.log.wrench, after.result.log.wrench)
