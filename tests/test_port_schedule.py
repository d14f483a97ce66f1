"""Every test that reaches the robot's port is scheduled with the others that do."""

from __future__ import annotations

from pathlib import Path

import pytest
from port_schedule import PORT_FIXTURES, uses_the_port


def test_every_test_reaching_the_port_is_in_a_file_the_scheduler_groups(
    request: pytest.FixtureRequest,
) -> None:
    items = request.session.items  # every collected test (each xdist worker collects all)
    reaching = {
        Path(str(i.path)) for i in items if PORT_FIXTURES & set(getattr(i, "fixturenames", ()))
    }
    if not reaching:  # e.g. this file alone
        pytest.skip("no test reaching the port was collected with this one")
    assert sorted(p.name for p in reaching if not uses_the_port(p)) == []
