"""``teachfit bench learning --random-rate``: how often random parameters succeed."""

from __future__ import annotations

import math

import pytest
from typer.testing import CliRunner

from teachfit.bench.learning_random import (
    GRID,
    RandomRate,
    grid_projection,
    random_rate,
    random_rate_markdown,
)
from teachfit.cli import app
from teachfit.core.params import LearningError


def test_random_rate_counts_every_execution_and_bounds_the_rate() -> None:
    r = random_rate("key", trials=2, experiments=1, n_starts=1, workers=0, seed=3)
    assert (r.task, r.executions, r.trials) == ("key", 2, 2)
    assert 0 <= r.successes <= r.executions and r.feasible == r.successes  # 1 start per trial
    assert r.low <= r.rate <= r.high and 0 < r.cpu_s and r.executions_per_cpu_s > 0
    with pytest.raises(LearningError, match="trials and experiments"):
        random_rate("key", trials=0)


def test_projection_and_table_arithmetic() -> None:
    rates = [
        RandomRate("puzzle", 10, 40, 6, 10, 0.14, 0.40, 20.0, 11.0),
        RandomRate("peg", 30, 40, 10, 10, 0.6, 0.86, 60.0, 31.0),
    ]
    per, wall = grid_projection(rates, workers=2)
    assert per == pytest.approx(80 / 80.0)
    assert wall == pytest.approx(math.prod(GRID) / 2)  # 31,200 executions at 1 per CPU-s
    text = random_rate_markdown(rates)
    assert "| puzzle | 40 | 10/40 = 25 % [14, 40] | 6/10 | 2.00 |" in text
    assert "31200 executions" in text and "260 min on 2 cores" in text


def test_cli_random_rate_refuses_an_unknown_task_before_any_work() -> None:
    res = CliRunner().invoke(
        app, ["bench", "learning", "--random-rate", "2", "--tasks", "kye", "--workers", "0"]
    )
    assert res.exit_code == 2 and "kye" in res.output and "Traceback" not in res.output
