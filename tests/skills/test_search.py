"""The learned-search primitive and the peg-in-hole skill whose recovery it is."""

import numpy as np
import pytest
from search_models import raster_model

from teachfit.core.errors import SkillError
from teachfit.core.geometry import Pose
from teachfit.execution.engine import execute
from teachfit.robot.registry import make_robot
from teachfit.skills import peg_in_hole, peg_in_hole_search
from teachfit.skills.controllers import controller_spec
from teachfit.skills.library import get_skill
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.search import recentred, states_to_setpoints, surface_radius
from teachfit.skills.search_tilted import TILT_BLEND, lean_of
from teachfit.skills.tilt_context import KEY, TiltContext
from teachfit.tasks import get_task


@pytest.fixture(scope="module")
def peg():
    task = get_task("peg2d")
    return task, raster_model(task)


def test_recentred_keeps_the_shape_and_moves_the_mean(peg):
    _, model = peg
    ex = recentred(model.exploration, 0.5)
    assert np.allclose(ex.mean, 0.0)
    assert np.allclose(ex.cov, 0.25 * model.exploration.cov, rtol=1e-6)
    with pytest.raises(SkillError, match="scale"):
        recentred(model.exploration, 0.0)


def test_setpoints_blend_orientation_and_carry_the_feedforward(peg):
    _, model = peg
    t = np.linspace(0.0, 1.0, 101)
    states = np.column_stack([0.01 * t, np.zeros_like(t)])
    tilted = np.array([np.cos(0.05), 0.0, np.sin(0.05), 0.0])  # 0.1 rad about y
    sp = states_to_setpoints(t, states, ("x", "y"), 0.002, model, tilted)
    assert np.allclose(sp.pos[:, 0], states[:, 0]) and np.allclose(sp.pos[:, 2], 0.002)
    assert np.allclose(np.abs(sp.quat[0]), tilted) and np.allclose(
        np.abs(sp.quat[-1]), [1, 0, 0, 0]
    )
    assert np.allclose(sp.wrench_ff[:, :2], model.feedforward_along(t, states))
    assert sp.wrench_ff[50, 0] > 0  # the learned action pushes along +x, the motion


def test_joined_graph_and_its_learned_switches(peg):
    _, model = peg
    sk = peg_in_hole_search.build(model, "impedance")
    learned = set(sk.params.learned)
    assert {"t_switch", "t_stuck", "search_scale", "search_points"} <= learned
    assert set(peg_in_hole.LEARNED) <= learned
    edges = {(t.source, t.target) for t in sk.transitions}
    assert {("lateral", "search"), ("insert", "search"), ("search", "align")} <= edges
    with pytest.raises(SkillError, match="search model"):
        get_skill("peg-in-hole+search:/nonexistent.model")


def test_an_insert_stalled_in_the_hole_is_pushed_once_more(peg):
    """A stall with the part dropped in leaves ``insert`` for ``realign`` -> ``reinsert`` (not
    the error); a stall above the hole, or a second one, is still the error."""
    _, model = peg
    sk = peg_in_hole_search.build(model, "impedance")
    edges = {(t.source, t.target) for t in sk.transitions}
    assert {("insert", "realign"), ("realign", "reinsert")} <= edges
    assert not any(t.source == "reinsert" for t in sk.transitions)
    values = sk.resolve({})
    deep = 2 * values["drop_depth"]
    n = int(values["stall_time"] / 0.1) + 3

    def fired(node: str, depth: float) -> bool:
        check = sk.node(node).error.compile(values)
        pc = Percept(Pose(np.zeros(3)), 0.1)
        pc.p[2] = -depth
        hits = []
        for i in range(n):
            pc.t_node = 0.1 * i
            hits.append(check(pc))
        return any(hits)

    assert fired("insert", 0.0) and not fired("insert", deep)
    assert fired("reinsert", deep)
    assert sk.node("realign").primitive == sk.node("align").primitive


def test_search_recovers_a_hole_beyond_the_lateral_reach(peg):
    """5 mm taught-hole error across the lateral move: the plain skill fails; the joined
    skill searches from where it gave up and inserts."""
    task, model = peg
    robot = make_robot("floating", task, seed=0)
    ctx = peg_in_hole.hole_context(task, np.random.default_rng(0))
    est = task.hole2world.compose(Pose.from_xyz_rz(0.0031, 0.0039, 0.0, 0.0))
    start = est.compose(Pose.from_xyz_rz(0.002, 0.001, 0.025, 0.0))
    learned = {"search_scale": 0.5, "search_points": 30.0}  # covers the 5 mm error
    out = {}
    for name, sk in (
        ("plain", peg_in_hole.build("adaptive")),
        ("joined", peg_in_hole_search.build(model, "adaptive")),
    ):
        seed = {"search_seed": 1.0} if "search_seed" in sk.params.context else {}
        sk = sk.with_context(ctx.values | seed)
        values = {k: v for k, v in learned.items() if k in sk.params.learned}
        spec = controller_spec("adaptive", sk.resolve(values))
        out[name] = execute(
            sk, robot, start, est, values, task=task, goal2world=ctx.goal2world, controller=spec
        )
    assert not out["plain"].success
    joined = out["joined"]
    assert joined.success and joined.ground_truth_inserted
    assert [v.node for v in joined.visits][-3:] == ["search", "align", "insert"]


def test_recentred_widens_a_spread_narrower_than_the_radius_only(peg):
    _, model = peg
    ex = model.exploration
    r0 = surface_radius(ex)
    assert r0 > 0
    wide = recentred(ex, 1.0, 3.0 * r0)  # a taught-hole error beyond the human's search
    assert surface_radius(wide) == pytest.approx(3.0 * r0)
    assert np.allclose(wide.cov, 9.0 * ex.cov, rtol=1e-6)  # the shape kept
    kept = recentred(ex, 1.0, 0.5 * r0)  # already wider: the learned scale alone
    assert np.allclose(kept.cov, ex.cov, rtol=1e-6)
    with pytest.raises(SkillError, match="radius"):
        recentred(ex, 1.0, -0.001)


def _lateral_switch(sk, source: str):
    return [t.condition for t in sk.transitions if (t.source, t.target) == (source, "search")]


def test_joined_lateral_moves_search_only_after_reaching_the_hole(peg):
    """A fit's long lateral move (``t_reach`` to the taught hole) is not cut at ``t_switch``;
    every pass gives up to the search, and the last pass's miss searches."""
    _, model = peg
    sk = peg_in_hole_search.build(model, "impedance")
    values = sk.resolve({"t_switch": 0.8}) | {"t_reach": 2.0, "roi": 0.1, "pass_end": 0.006}
    pc = Percept(Pose(np.zeros(3)), 0.01)
    for lateral in peg_in_hole_search.LATERALS:
        switch, *miss = (c.compile(values) for c in _lateral_switch(sk, lateral))
        fired = []
        for t in (1.0, 1.9, 2.1):
            pc.t_node = t
            fired.append(switch(pc))
        assert fired == [False, False, True]
        pc.t_node = 0.1
        pc.p[0] = -0.007  # past the hole
        assert [m(pc) for m in miss] == ([True] if lateral == "lateral_3" else [])
        pc.p[0] = 0.0
    built_in = sk.resolve({"t_switch": 0.8}) | {"roi": 0.1}  # t_reach 0: t_switch alone
    pc.t_node = 0.9
    assert _lateral_switch(sk, "lateral")[0].compile(built_in)(pc)
    # a resistance along +x (the far wall where the fit did not expect it) searches at once
    stop = _lateral_switch(sk, "lateral")[0].compile(values | {"f_lateral_rev": 8.0})
    pc.t_node, pc.f[0] = 0.1, 9.0
    assert stop(pc)
    pc.f[0] = 0.0
    assert not stop(pc)


def _tour(model, repeat: float):
    """A learned search entered at the origin, stepped past its first tour's end."""
    sk = peg_in_hole_search.build(model, "impedance")
    values = sk.resolve({"search_points": 10.0}) | {"search_repeat": repeat}
    run = sk.node("search").primitive.compile(values)
    pc, out = Percept(Pose(np.zeros(3)), 0.01), MPCommand()
    run.enter(pc)
    first = run.trajectory
    pc.t_node = first.duration + 0.01
    run.command(pc, out)
    return run, first, pc


def test_a_search_without_a_catch_tours_again_from_where_it_ended(peg):
    _, model = peg
    run, first, pc = _tour(model, 1.0)
    assert not pc.done and run.trajectory is not first  # a fresh tour, from here
    assert run.t0 == pytest.approx(first.duration + 0.01)
    assert np.allclose(run.trajectory.pos[0, :2], pc.p[:2], atol=1e-9)
    _, _, pc_once = _tour(model, 0.0)  # Ehlers et al.'s: one tour, done
    assert pc_once.done


def _tilted_search(model, tilt: float):
    """The joined skill's search node entered 4 mm along +x from the taught hole with
    ``search_tilt`` ``tilt``; its first command's orientation set-point and the percept after
    one command once the tilt is in (``TILT_BLEND``)."""
    sk = peg_in_hole_search.build(model, "impedance")
    values = sk.resolve({"search_points": 10.0}) | {"search_tilt": tilt, "search_lead": 0.001}
    run = sk.node("search").primitive.compile(values)
    pc = Percept(Pose(np.zeros(3)), 0.01)
    pc.p[:] = (0.004, 0.0, 0.001)
    run.enter(pc)
    pc.t = pc.t_node = 0.01
    run.command(pc, MPCommand())
    first = (pc.q_d.copy(), pc.p_d[:2].copy())
    pc.t = pc.t_node = TILT_BLEND + 0.01
    pc.p[2] = 0.0008  # the TCP sinks: the set-point's height follows it
    run.command(pc, MPCommand())
    return sk, values, run, pc, first


def test_a_sharp_edged_part_searches_tilted_in_nodes_of_the_joined_graph(peg):
    _, model = peg
    sk, values, run, pc, first = _tilted_search(model, 0.25)
    edges = {(t.source, t.target) for t in sk.transitions}
    assert {
        ("search", "search_slide"),
        ("search_slide", "search_align"),
        ("search_slide", "search"),
        ("search_align", "search"),
        ("search_align", "align"),
    } <= edges
    assert ("search_slide", "align") not in edges  # a tilted corner dips deep while sliding
    ctx = pc.shared[KEY]
    assert isinstance(ctx, TiltContext) and ctx.cfg.angle == 0.25
    assert ctx.cfg.retry_angle is None  # search_retry_tilt 0: none
    tilt = 2.0 * np.degrees(np.arccos(np.clip(abs(pc.q_d[0]), 0, 1)))
    assert tilt == pytest.approx(np.degrees(0.25))
    assert 2.0 * np.degrees(np.arccos(abs(first[0][0]))) < 0.05 * tilt  # turned in, blended
    assert pc.p_d[2] == pytest.approx(0.0008)  # only the push presses along z
    # leaning toward the taught hole (-x), the tour starts at the low rim, the axis stays
    assert np.allclose(ctx.d, [-1.0, 0.0])
    assert np.allclose(ctx.traj.pos[0, :2], [0.003, 0.0], atol=1e-9)
    assert np.allclose(first[1], [0.004, 0.0], atol=2e-4)
    felt = next(
        t.condition for t in sk.transitions if (t.source, t.target) == ("search", "search_slide")
    ).compile(values)
    pc.p[2] = ctx.z_top - 3e-4  # 0.3 mm below the resting height, past the tilt's settling
    assert felt(pc)
    # still tilting: a part that sinks below where the tour started (its edge) has dropped
    ctx.z_top, ctx.t0, pc.t, pc.p[2] = 0.0, 0.0, 0.1, 0.0007
    assert felt(pc)
    pc.p[2] = 0.0009
    assert not felt(pc)
    # a tour without a catch: a fresh tilted search from here
    pc.t = ctx.traj.duration + 0.1
    run.command(pc, MPCommand())
    assert pc.shared[KEY] is not ctx and not pc.done
    # entered again (a missed align stood upright): the tilt turns in again, not at once
    pc.q[:] = (1.0, 0.0, 0.0, 0.0)
    pc.t += 1.0  # past the fresh tour's own turn-in
    run.enter(pc)
    pc.t += 0.01
    run.command(pc, MPCommand())
    assert 2.0 * np.degrees(np.arccos(abs(pc.q_d[0]))) < 0.05 * tilt
    # upright (the default, every built-in task): no tilted context, the drop never felt
    _, _, upright, pc_up, _ = _tilted_search(model, 0.0)
    assert KEY not in pc_up.shared and np.allclose(np.abs(pc_up.q_d), [1, 0, 0, 0], atol=1e-6)
    assert not felt(pc_up)


def test_a_tilted_part_leans_a_corner_ahead_toward_the_taught_hole():
    """Upright: toward the taught hole; tilted by the skill's lateral move: 45 degrees from
    its lean toward the taught hole's side (no roll over the tip; a corner leads)."""
    pc = Percept(Pose(np.zeros(3)), 0.01)
    pc.p[:] = (0.004, 0.0, 0.0)
    assert np.allclose(lean_of(pc), [-1.0, 0.0])
    pc.q[:] = (np.cos(0.05), 0.0, np.sin(0.05), 0.0)  # 0.1 rad about y: leans along +x
    pc.p[:] = (0.004, 0.001, 0.0)  # the taught hole ahead along -x, a little along -y
    assert np.allclose(lean_of(pc), [np.sqrt(0.5), -np.sqrt(0.5)])
    pc.p[:] = (0.004, -0.001, 0.0)
    assert np.allclose(lean_of(pc), [np.sqrt(0.5), np.sqrt(0.5)])
