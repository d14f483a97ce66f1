"""Which test files use the robot's port (127.0.0.1:1337), for the scheduler in ``conftest.py``.

The fixtures of :mod:`franka_fixtures` that take the port also take a machine-wide lock, which a
pytest-xdist worker holds to the end of its run once it has it; the files that name one of them
run on one worker. ``tests/test_port_schedule.py`` checks that every test whose fixtures reach
the port is in such a file (a fixture that reaches it only through another must be listed).
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

#: the fixtures that take the port, directly or through another
PORT_FIXTURES = frozenset(
    {"franka_port", "franka_sim", "robot_port", "franka_twin", "listener", "expected_tcp"}
)
_NAMED = re.compile(r"\b(" + "|".join(sorted(PORT_FIXTURES)) + r")\b")


@functools.cache
def uses_the_port(path: Path) -> bool:
    """Whether the test file ``path`` names a fixture of :data:`PORT_FIXTURES`."""
    try:
        return _NAMED.search(path.read_text()) is not None
    except OSError:
        return False
