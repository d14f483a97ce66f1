"""Skill formalism: profiles, conditions, parameters, graph validation, TOML (no simulation)."""

import dataclasses
import math
import os
import tomllib
from pathlib import Path

import numpy as np
import pytest

from teachfit.core.atomic import current_umask
from teachfit.core.errors import SkillError
from teachfit.core.geometry import Pose
from teachfit.core.params import ParamDomain
from teachfit.core.state import RobotState
from teachfit.skills import peg_in_hole
from teachfit.skills.conditions import (
    All,
    Any_,
    DepthAbove,
    ForceAbove,
    SpeedBelow,
    TimeAbove,
    condition_from_toml,
)
from teachfit.skills.graph import Node, Skill, Transition
from teachfit.skills.loader import load_skill, skill_from_dict, skill_to_toml
from teachfit.skills.params import (
    ContextParam,
    LearnedParam,
    SkillParams,
    read_params_toml,
    write_params_toml,
)
from teachfit.skills.percept import Percept
from teachfit.skills.primitive import Move, MoveTo
from teachfit.skills.profile import Trapezoid, synchronized

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "skills" / "peg_in_hole.toml"


# ----------------------------------------------------------------------------- profile
@pytest.mark.parametrize("d", [0.05, 0.001])  # trapezoid (cruises) and triangle
def test_trapezoid_respects_limits_and_arrives(d):
    p = Trapezoid(d, v_max=0.1, a_max=1.0)
    t = np.linspace(0, p.duration, 2001)
    s = np.array([p.position(x) for x in t])
    v = np.array([p.velocity(x) for x in t])
    assert s[0] == 0 and s[-1] == pytest.approx(d)
    assert np.all(np.diff(s) >= -1e-15) and v.max() <= 0.1 + 1e-12
    acc = np.diff(v) / np.diff(t)
    assert np.abs(acc).max() <= 1.0 + 1e-6
    np.testing.assert_allclose(np.gradient(s, t)[5:-5], v[5:-5], atol=2e-3)
    if d == 0.05:  # reaches v_max: T = d / v + v / a
        assert p.duration == pytest.approx(0.05 / 0.1 + 0.1)
        assert p.velocity(p.duration / 2) == pytest.approx(0.1)
    else:  # triangle: T = 2 sqrt(d / a)
        assert p.duration == pytest.approx(2 * math.sqrt(0.001))
        assert p.v_peak < 0.1


def test_synchronized_profile_keeps_every_limit():
    prof = synchronized((0.02, 0.5), (0.1, 1.0), (1.0, 5.0))
    assert prof.distance == 1.0
    assert prof.v_peak * 0.02 <= 0.1 + 1e-12 and prof.v_peak * 0.5 <= 1.0 + 1e-12
    assert prof.a_max * 0.5 <= 5.0 + 1e-12
    assert synchronized((0.0, 0.0), (1.0, 1.0), (1.0, 1.0)).duration == 0.0
    with pytest.raises(SkillError):
        Trapezoid(1.0, 0.0, 1.0)


# ---------------------------------------------------------------------------- conditions
def _percept(force=(0, 0, 0), pos=(0, 0, 0), vel=(0, 0, 0), t=0.0):
    pc = Percept(Pose.from_xyz_rz(0.1, 0.0, 0.5, math.pi / 2), 0.01)
    # world quantities for a task frame rotated +90 deg about z: task x = world y
    state = RobotState(
        t,
        np.array(pos, float) + [0.1, 0, 0.5],
        np.array([1.0, 0, 0, 0]),
        np.array(vel, float),
        np.zeros(3),
        np.array([*force, 0, 0, 0], float),
    )
    pc.update(state, t)
    return pc


def test_conditions_read_the_task_frame():
    pc = _percept(force=(0.0, -5.0, 2.0), pos=(0.0, 0.0, -0.004))
    assert pc.f[0] == pytest.approx(-5.0)  # world -y is task -x
    assert ForceAbove(4.0, axis="-x").compile({})(pc)
    assert not ForceAbove(4.0, axis="+x").compile({})(pc)
    assert ForceAbove("f", axis="norm").compile({"f": 5.3})(pc)
    assert not ForceAbove("f", axis="norm").compile({"f": 5.4})(pc)
    assert DepthAbove("-d").compile({"d": -0.003})(pc)  # negated reference: depth >= 3 mm
    assert not DepthAbove(0.005).compile({})(pc)
    both = All((DepthAbove(0.003), ForceAbove(1.0, axis="+z")))
    assert both.compile({})(pc)
    assert not (both & TimeAbove(1.0)).compile({})(pc)
    assert (both & TimeAbove(1.0) | TimeAbove(0.0)).compile({})(pc)
    assert not (~both).compile({})(pc)
    with pytest.raises(SkillError, match="unknown parameter 'f'"):
        ForceAbove("f").compile({})
    with pytest.raises(SkillError, match="axis"):
        ForceAbove(1.0, axis="up")


def test_speed_below_must_be_sustained_and_restarts_per_node():
    check = SpeedBelow(0.002, duration=0.05).compile({})
    pc = _percept(vel=(0.0, 0.001, 0.0))
    out = []
    for k in range(8):
        pc.t_node = 0.01 * k
        out.append(check(pc))
    assert out == [False] * 5 + [True] * 3
    pc.t_node = 0.0  # node re-entered: the clock restarts
    assert not check(pc)
    fast = _percept(vel=(0.01, 0.0, 0.0))
    fast.t_node = 0.5
    assert not check(fast)


def test_condition_toml_round_trip_and_errors():
    cond = Any_(
        (
            ForceAbove("f_lateral", axis="-x"),
            All((TimeAbove(0.2), SpeedBelow("v", duration=0.1))),
            ~DepthAbove(0.01),
        )
    )
    assert condition_from_toml(cond.to_toml()) == cond
    assert cond.refs() == {"f_lateral", "v"}
    with pytest.raises(SkillError, match="unknown condition kind 'hot'"):
        condition_from_toml({"kind": "hot"})
    with pytest.raises(SkillError, match="time_above"):
        condition_from_toml({"kind": "time_above", "value": 1.0, "scope": "week"})


# ---------------------------------------------------------------------------- validation
def _params(**learned):
    lrn = {"speed": LearnedParam(0.01, ParamDomain(0.001, 0.05), "m/s")}
    lrn.update(learned)
    return SkillParams({"t_lim": ContextParam(1.0, "s")}, lrn)


def _skill(nodes, transitions, params=None, **kw):
    return Skill(
        "test",
        tuple(nodes),
        tuple(transitions),
        nodes[0].name,
        params or _params(),
        DepthAbove(0.01),
        TimeAbove("t_lim", scope="skill"),
        **kw,
    )


_TIMEOUT = TimeAbove(1.0)


def _down(name, speed="speed", error=_TIMEOUT):
    return Node(name, Move(speed=speed), error)


def test_a_valid_skill_builds():
    sk = _skill([_down("a"), _down("b")], [Transition("a", "b", ForceAbove(2.0))])
    assert sk.space.names == ("speed",)
    assert sk.users() == {"speed": ["a", "b"]}


def test_unreachable_node_is_named():
    with pytest.raises(SkillError, match="unreachable") as err:
        _skill([_down("a"), _down("b"), _down("lost")], [Transition("a", "b", TimeAbove(0.1))])
    assert err.value.node == "lost" and "'lost'" in str(err.value)


def test_primitive_without_error_exit_is_named():
    with pytest.raises(SkillError, match="no error exit") as err:
        _skill([_down("a"), _down("b", error=None)], [Transition("a", "b", TimeAbove(0.1))])
    assert err.value.node == "b"


def test_out_of_domain_parameter_names_the_node():
    params = _params(force=LearnedParam(30.0, ParamDomain(2.0, 20.0), "N"))
    nodes = [_down("a"), Node("push", MoveTo(push="force"), TimeAbove(1.0))]
    with pytest.raises(SkillError, match="outside its domain") as err:
        _skill(nodes, [Transition("a", "push", TimeAbove(0.1))], params)
    assert err.value.node == "push" and "'force'" in str(err.value)
    sk = _skill([_down("a")], [])
    with pytest.raises(SkillError, match=r"'speed' = 0.5 is outside.*\['a'\]"):
        sk.resolve({"speed": 0.5})


def test_bad_references_and_values_are_named():
    with pytest.raises(SkillError, match="undeclared parameter") as err:
        _skill([_down("a"), _down("b", speed="warp")], [Transition("a", "b", TimeAbove(0.1))])
    assert err.value.node == "b"
    with pytest.raises(SkillError, match="speed must be > 0") as err:
        _skill([_down("a"), _down("b", speed=-0.01)], [Transition("a", "b", TimeAbove(0.1))])
    assert err.value.node == "b"
    with pytest.raises(SkillError, match="unknown node 'c'") as err:
        _skill([_down("a")], [Transition("a", "c", TimeAbove(0.1))])
    assert err.value.node == "a"


# ----------------------------------------------------------------------------- parameters
def test_peg_in_hole_spaces():
    adaptive, fixed = peg_in_hole.build("adaptive"), peg_in_hole.build("impedance")
    assert fixed.space.names == tuple(peg_in_hole.LEARNED)
    assert adaptive.space.dim == fixed.space.dim + 8 and "beta_t" in adaptive.space.names
    mid = adaptive.space.from_unit(np.full(adaptive.space.dim, 0.5))
    adaptive.compile(mid)  # any point of the space is a valid parameter set
    assert adaptive.space.domains["force"] == ParamDomain(2.0, 20.0)


def test_params_file_errors_are_clear(tmp_path):
    sk = peg_in_hole.build("impedance")
    good = tmp_path / "best.toml"
    good.write_text("force = 12.0\ntilt = 0.05\n")
    vals = read_params_toml(good, sk.params)
    assert vals["force"] == 12.0 and vals["a_t"] == peg_in_hole.LEARNED["a_t"].default
    bad = tmp_path / "bad.toml"
    bad.write_text("[params]\nforce = 12.0\nforse = 3.0\ndepth = 0.01\n")
    with pytest.raises(SkillError, match=r"bad.toml.*unknown.*'depth', 'forse'.*context"):
        read_params_toml(bad, sk.params)
    far = tmp_path / "far.toml"
    far.write_text("force = 200.0\n")
    with pytest.raises(SkillError, match=r"far.toml.*'force' = 200.0 is outside .*insert"):
        read_params_toml(far, sk.params, sk.users())
    text = tmp_path / "text.toml"
    text.write_text('force = "strong"\n')
    with pytest.raises(SkillError, match="must be numbers"):
        read_params_toml(text, sk.params)


def test_written_params_read_back_exactly(tmp_path):
    sk = peg_in_hole.build("impedance")
    values = {"force": 12.345678901234567, "tilt": 0.05, "a_t": 0.001 / 3.0}
    path = write_params_toml(tmp_path / "out" / "best.toml", values, "best of cmaes\ntrial 4")
    text = path.read_text()
    assert text.startswith("# best of cmaes\n# trial 4\n[params]\n")
    back = read_params_toml(path, sk.params)
    assert {k: back[k] for k in values} == values  # floats round-trip to the last bit
    assert [p.name for p in path.parent.iterdir()] == ["best.toml"]  # no temporary left
    assert path.stat().st_mode & 0o777 == 0o666 & ~current_umask()  # the umask applies


def test_a_failed_params_write_keeps_the_old_file_and_no_temporary(tmp_path, monkeypatch):
    path = write_params_toml(tmp_path / "best.toml", {"force": 5.0})
    old = path.read_text()

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(SkillError, match=r"cannot write parameter file .*best.toml.*No space"):
        write_params_toml(path, {"force": 6.0})
    assert path.read_text() == old
    assert [p.name for p in tmp_path.iterdir()] == ["best.toml"]
    for bad, match in (({"force": math.nan}, "finite"), ({"for ce": 1.0}, "identifiers")):
        with pytest.raises(SkillError, match=match):
            write_params_toml(tmp_path / "other.toml", bad)
    assert not (tmp_path / "other.toml").exists()


# ------------------------------------------------------------------------------------ TOML
def test_toml_round_trip_and_example_file():
    sk = peg_in_hole.build("adaptive")
    back = skill_from_dict(tomllib.loads(skill_to_toml(sk)))
    assert back == sk
    assert load_skill(EXAMPLE) == sk
    kept = sk.node("insert")
    sk2 = dataclasses.replace(
        sk, nodes=tuple(dataclasses.replace(n, keep_orientation=n is kept) for n in sk.nodes)
    )
    text = skill_to_toml(sk2)
    assert text.count("keep_orientation = true") == 1
    assert skill_from_dict(tomllib.loads(text)) == sk2 != sk


def test_toml_errors_name_the_node(tmp_path):
    data = tomllib.loads(skill_to_toml(peg_in_hole.build("impedance")))
    del data["nodes"]["lateral"]["error"]
    bad = tmp_path / "bad.toml"
    bad.write_text(
        skill_to_toml(peg_in_hole.build("impedance")).replace(
            'primitive = "insert"', 'primitive = "insert"\nwobble = 1.0'
        )
    )
    with pytest.raises(SkillError, match=r"bad.toml: node 'insert'.*unknown field.*wobble") as e:
        load_skill(bad)
    assert e.value.node == "insert"
    with pytest.raises(SkillError, match="'lateral'.*no error exit"):
        skill_from_dict(data)


def test_with_context_replaces_values_only():
    sk = peg_in_hole.build("impedance").with_context({"depth": 0.02})
    assert sk.params.context["depth"].value == 0.02
    with pytest.raises(SkillError, match="unknown context"):
        sk.with_context({"force": 3.0})
    assert dataclasses.replace(sk.params.context["depth"], value=0.02) == sk.params.context["depth"]


def test_with_fixed_moves_a_learned_parameter_to_the_context():
    sk = peg_in_hole.build("impedance").with_fixed({"tilt": 0.05})
    assert "tilt" not in sk.space.names and sk.params.context["tilt"].value == 0.05
    assert sk.resolve({})["tilt"] == 0.05  # "-tilt" in approach still resolves
    with pytest.raises(SkillError, match="outside its domain"):
        peg_in_hole.build("impedance").with_fixed({"tilt": 0.5})
    with pytest.raises(SkillError, match="unknown learned"):
        sk.with_fixed({"tilt": 0.05})  # already fixed


def test_with_domains_bounds_a_learned_parameter_and_clips_its_default():
    sk = peg_in_hole.build("impedance").with_domains({"a_r": ParamDomain(0.0, 0.01)})
    assert sk.space.domains["a_r"] == ParamDomain(0.0, 0.01)
    assert sk.params.learned["a_r"].default == 0.01  # 0.02 clipped into the new domain
    assert sk.space.domains["force"] == peg_in_hole.LEARNED["force"].domain  # the others kept
    with pytest.raises(SkillError, match=r"outside its domain \[0, 0.01\] \(used by") as err:
        sk.resolve({"a_r": 0.05})
    assert ";" not in str(err.value)  # no one to name as the bound's author
    why = "task t bounds it"
    named = peg_in_hole.build("impedance").with_domains({"a_r": ParamDomain(0.0, 0.01)}, why)
    with pytest.raises(SkillError, match=r"\['insert'\]\); task t bounds it$"):
        named.resolve({"a_r": 0.05})
    with pytest.raises(SkillError, match="unknown learned"):
        sk.with_domains({"stiffness_z": ParamDomain(0.0, 1.0)})
    fixed = peg_in_hole.build("impedance").with_fixed({"tilt": 0.05})
    assert "tilt" not in fixed.with_domains({"tilt": ParamDomain(0.0, 0.1)}).space.names


def test_move_to_turns_to_rz_ry_rx_of_yaw_tilt_and_roll() -> None:
    from scipy.spatial.transform import Rotation

    from teachfit.core.geometry import Pose, wxyz_to_rotation
    from teachfit.skills.percept import MPCommand, Percept

    run = MoveTo(yaw=0.2, tilt=-0.1, roll=0.05, w_max=10.0, dw_max=100.0).compile({})
    pc = Percept(Pose(np.zeros(3)), 0.001)
    run.enter(pc)
    turn = np.zeros(3)
    while not pc.done:
        out = MPCommand()
        run.command(pc, out)
        turn += out.twist[3:] * pc.dt
        pc.t_node += pc.dt
    want = Rotation.from_euler("ZYX", [0.2, -0.1, 0.05])
    got = Rotation.from_rotvec(turn) * wxyz_to_rotation(pc.q_d)
    assert (got.inv() * want).magnitude() < 1e-3
    low = want.apply([[0.0, -0.004, 0.0], [0.0, 0.004, 0.0]])[:, 2]
    assert low[0] < low[1]  # a positive roll lowers the -y side
