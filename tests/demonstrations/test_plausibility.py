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
from teachfit.demonstrations.rawlog import RawLog


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
