"""Plausibility checks: each fires on what it is meant to catch, and only on that."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from panda_logs import panda_log, tool_down_quat

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.plausibility import (
    Finding,
    Limits,
    check_demo_shape,
    check_orientation,
    check_rate,
    check_wrench_sign,
    enforce,
)
from teachfit.demonstrations.rawlog import RawLog, sampling_rate


def raw(fix_in: str | None = "map.toml", **changes) -> RawLog:
    log = panda_log("search")
    fields = dict(t=log["t"], pos=log["pos"], quat=log["quat"], wrench=log["wrench"])
    fields.update(changes)
    n = fields["t"].size
    meta = {"wrench_sign": 1}
    return RawLog(
        path="log.csv",
        frame="panda_link0",
        rows=np.arange(n) + 2,
        meta=meta,
        fix_in=fix_in,
        time_step_units=0.05,
        **fields,
    )


def test_a_good_log_passes_every_check() -> None:
    log, limits = raw(), Limits()
    assert check_rate(log, limits) is None and check_orientation(log, limits) is None
    assert check_wrench_sign(log, limits) is None
    assert check_demo_shape(log.t, log.pos, log, limits) == []


def test_rate_suggests_the_scale_that_fits() -> None:
    log = panda_log("search")
    ns = replace(raw(t=log["t"] * 1e9), time_step_units=0.05 * 1e9)  # ns read as s
    finding = check_rate(ns, Limits())
    assert finding is not None and "if it is in ns, set time_scale = 1e-09 in map.toml" in (
        finding.fix
    )
    cli = replace(raw(fix_in=None, t=log["t"] * 1e3), time_step_units=None)  # --rate 0.02
    assert "pass --rate <Hz>" in check_rate(cli, Limits()).fix


def test_orientation_and_wrench_thresholds() -> None:
    yaw = np.radians(np.linspace(0.0, 278.0, 500))
    assert check_orientation(raw(quat=tool_down_quat(yaw)), Limits()) is None  # yaw is free
    tilted = tool_down_quat(yaw)[:, [1, 0, 2, 3]]  # w and x swapped: tumbling
    finding = check_orientation(raw(quat=tilted), Limits())
    assert finding is not None and finding.check == "orientation"
    light = raw(wrench=-panda_log("search")["wrench"])
    assert check_wrench_sign(light, Limits()) is not None
    assert check_wrench_sign(light, Limits(contact_force_n=20.0)) is None  # never in contact
    assert check_wrench_sign(raw(wrench=None), Limits()) is None


def test_shape_checks() -> None:
    log = raw()
    found = check_demo_shape(log.t * 10, log.pos * 10, log, Limits())
    assert [f.check for f in found] == ["duration", "extent"]
    still = check_demo_shape(log.t, np.zeros_like(log.pos), log, Limits())
    assert [f.check for f in still] == ["speed"] and "0 mm/s" in still[0].message


def test_enforce_accepts_by_name() -> None:
    findings = [Finding("rate", "too slow", "fix it"), Finding("extent", "too wide", "cut it")]
    with pytest.raises(DatasetError) as info:
        enforce(findings, set(), "log.csv")
    message = str(info.value)
    assert message.startswith("file log.csv: implausible rate: too slow. Fix: fix it")
    assert "(also implausible: extent)" in message and "--accept rate" in message
    with pytest.raises(DatasetError, match="implausible extent"):
        enforce(findings, {"rate"}, "log.csv")
    notes = enforce(findings, {"rate", "extent"}, "log.csv")
    assert notes == ["accepted implausible rate: too slow", "accepted implausible extent: too wide"]
    assert len(enforce(findings, {"all"}, "log.csv")) == 2
    with pytest.raises(DatasetError, match="unknown check 'rates'"):
        enforce(findings, {"rates"}, "log.csv")


def test_orientation_fix_names_the_order_that_fits() -> None:
    yaw = np.radians(np.linspace(0.0, 278.0, 500))
    truth = tool_down_quat(yaw)
    as_xyzw = replace(raw(quat=truth[:, [3, 0, 1, 2]]), quat_order="x,y,z,w")  # wxyz read as xyzw
    finding = check_orientation(as_xyzw, Limits())
    assert finding is not None and "read as x,y,z,w" in finding.message
    assert 'in w,x,y,z order (read so, the track fits): set quat_order = "w,x,y,z"' in finding.fix
    bag = replace(raw(fix_in=None, quat=truth[:, [1, 2, 3, 0]]))  # fields filled x,y,z,w
    assert "x,y,z,w order" in check_orientation(bag, Limits()).fix
    assert "fix its publisher" in check_orientation(bag, Limits()).fix


@pytest.mark.parametrize(
    ("t", "rate"),
    [
        (np.arange(2000) * 0.05 + 64.0, 20.0),  # float steps of 0.050000000000011 s
        (
            (np.arange(500) * 50_000_000 + 1_718_023_402_000_000_000 - 1_718_023_402_000_000_000)
            * 1e-9,
            20.0,
        ),
        (np.arange(1000) / 999.97, 999.97),  # a rate that is not round stays as measured
        (np.arange(1000) * 0.001 + np.random.default_rng(0).normal(0, 2e-7, 1000), 1000.0),
        (np.arange(100) / 7.0 * 3.0, 2.33333),
    ],
)
def test_sampling_rate_is_rounded_to_what_the_steps_support(t: np.ndarray, rate: float) -> None:
    assert sampling_rate(t) == rate
    assert abs(1.0 / sampling_rate(t) - np.median(np.diff(t))) <= 1e-5 * np.median(np.diff(t))
