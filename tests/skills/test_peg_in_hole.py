"""The peg-in-hole skill on the FR3 arm with its default parameters; the key's task context."""

import numpy as np
import pytest

from teachfit.core.errors import SkillError
from teachfit.core.geometry import Pose
from teachfit.core.outcome import Outcome
from teachfit.execution.skill_trial import SkillTrial, peg_in_hole_setup
from teachfit.skills import peg_in_hole
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.primitive import Insert
from teachfit.tasks import get_task


def test_default_skill_inserts_on_the_arm_after_a_real_lateral_move():
    # the arm lands with ~15 N (its apparent mass), whose friction alone once marked the lateral
    # move constrained at its first tick; with friction in the joints the soft align and insert
    # then never made up the skipped 3 mm and pressed beside the hole up to the force limit
    setup = peg_in_hole_setup(get_task("peg2d"), seed=0, n_starts=1)
    trial = SkillTrial(setup, robot="fr3", seed=0)
    out = trial()
    (run,) = out.traces
    assert run.outcome is Outcome.SUCCESS and out.successes == (True,)
    lateral = next(v for v in run.visits if v.node == "lateral")
    assert lateral.t_exit - lateral.t_enter > setup.skill.params.context["t_settle"].value


def test_key_context_fixes_the_tilt_and_learns_the_rest():
    # Johannsmeier et al. 2019 (Sec. V) does not learn the key's initial alignment; the other tasks
    # learn it
    key = get_task("key")
    ctx = peg_in_hole.hole_context(key, np.random.default_rng(0))
    assert ctx.fixed == {"tilt": key.params.fixed_tilt}
    assert ctx.values["drop_depth"] == key.skill_context["drop_depth"]
    skill = peg_in_hole_setup(key, seed=0, n_starts=1).skill
    assert "tilt" not in skill.space.names and skill.params.context["tilt"].value == 0.1
    assert "tilt" in peg_in_hole_setup(get_task("peg"), seed=0, n_starts=1).skill.space.names


def test_the_insert_push_fades_with_the_parts_speed_into_the_hole():
    # a part that comes free in the hole is not driven on (a real arm's reset must brake it
    # in the millimetres left); a jammed one gets the whole push
    run = Insert(force=10.0, depth=0.01, sink=0.02, v_press=0.05).compile({})
    pc, out = Percept(Pose(np.zeros(3)), 0.001), MPCommand()
    run.enter(pc)
    pushes = []
    for speed in (0.0, 0.05, 0.075, 0.1, 0.2, -0.05):  # m/s into the hole (-z)
        pc.v[2] = -speed
        run.command(pc, out)
        pushes.append(-out.wrench[2])
    assert pushes == pytest.approx([10.0, 10.0, 5.0, 0.0, 0.0, 10.0])
    insert = peg_in_hole.build().node("insert").primitive
    assert insert.v_press == "v_press" and "fading above v_press" in insert.describe()
    with pytest.raises(SkillError, match="v_press"):
        Insert(v_press=0.0).compile({})


def test_an_extra_pass_approaches_an_arm_at_rest_a_little_short_of_its_pose() -> None:
    from teachfit.robot.interface import RobotState

    def pc_at(dx: float, speed: float) -> Percept:
        pc = Percept(Pose(np.zeros(3)), 0.01)
        state = RobotState(
            0.0, np.array([dx, 0.0, 0.0]), np.array([1.0, 0, 0, 0]),
            np.array([speed, 0.0, 0.0]), np.zeros(3), np.zeros(6),
        )  # fmt: skip
        pc.update(state, 0.0)
        pc.goal[:] = 0.0
        pc.done = True
        return pc

    def holds(suffix: str, dx: float, speed: float) -> bool:
        check = peg_in_hole._at_approach_pose(suffix).compile({"v_still": 0.002})
        pc = pc_at(dx, speed)
        out = []
        for k in range(15):
            pc.t_node = 0.01 * k
            out.append(check(pc))
        return out[-1]

    assert holds("", 5e-4, 0.0) and holds("_2", 5e-4, 0.05)  # within 1 mm: as before
    assert not holds("", 0.0015, 0.0)  # the first approach still wants 1 mm
    assert holds("_2", 0.0015, 0.0) and holds("_3", 0.0025, 0.0)  # an extra pass at rest
    assert not holds("_2", 0.0015, 0.01)  # still moving there
    assert not holds("_2", 0.0035, 0.0)  # too far
