"""Stateful conditions over the percept: a stalled insertion."""

from __future__ import annotations

import tomllib

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.skills.conditions import DepthStalled, condition_from_toml
from teachfit.skills.percept import Percept


def _walk(check, depths: list[float], dt: float = 0.1) -> list[bool]:
    pc = Percept(Pose(np.zeros(3)), dt)
    out = []
    for i, d in enumerate(depths):
        pc.t_node = i * dt
        pc.p[2] = -d
        out.append(check(pc))
    return out


def test_depth_stalled_fires_only_after_the_duration_without_progress() -> None:
    cond = DepthStalled("gain", "hold")
    check = cond.compile({"gain": 0.001, "hold": 0.3})
    # steady progress of 1 mm per 0.1 s never stalls; then it rests (within 0.5 mm) for 0.5 s
    fired = _walk(check, [0.0, 0.001, 0.002, 0.003, 0.0032, 0.0035, 0.0031, 0.0034, 0.0033])
    assert fired == [False] * 6 + [True] * 3  # 0.3 s after the last 1 mm gain (t = 0.3 s)
    again = cond.compile({"gain": 0.001, "hold": 0.3})  # a fresh compile: its own state
    assert _walk(again, [0.0, 0.0, 0.0, 0.0]) == [False, False, False, True]
    # a node re-entered (time since the node started went back) starts afresh
    assert _walk(again, [0.0, 0.0]) == [False, False]
    back = condition_from_toml(tomllib.loads(f"c = {_inline(cond.to_toml())}")["c"])
    assert back == cond and "0.3" not in cond.describe() and "gain" in cond.describe()


def _inline(d: dict) -> str:
    return "{ " + ", ".join(f'{k} = "{v}"' for k, v in d.items()) + " }"


def test_x_below_reads_a_negated_parameter_from_toml() -> None:
    cond = condition_from_toml({"kind": "x_below", "value": "-pass_end"})
    check = cond.compile({"pass_end": 0.004})
    pc = Percept(Pose(np.zeros(3)), 0.01)
    pc.p[0] = -0.0039
    assert not check(pc)
    pc.p[0] = -0.0041
    assert check(pc)
    assert cond.to_toml() == {"kind": "x_below", "value": "-pass_end"}
