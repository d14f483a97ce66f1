import functools
import os
import shutil
import tempfile
import uuid
from pathlib import Path

import pytest
import typer.testing

ROOT = Path(__file__).resolve().parents[1]
os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("COLUMNS", "200")


@pytest.fixture(scope="session")
def mesh_examples(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """The shipped mesh task examples written once per session: name -> task file path (their
    decompositions are cached beside them)."""
    from teachfit.tasks.mesh.examples import EXAMPLES, write_example

    folder = tmp_path_factory.mktemp("mesh_examples")
    return {name: str(write_example(name, folder / name)) for name in EXAMPLES}


@functools.cache
def _gl_context_error() -> str | None:
    """Why MuJoCo cannot render offscreen here (None: it can)."""
    try:
        import mujoco

        model = mujoco.MjModel.from_xml_string(
            '<mujoco><worldbody><geom size="0.1"/></worldbody></mujoco>'
        )
        with mujoco.Renderer(model, 16, 16) as renderer:
            renderer.update_scene(mujoco.MjData(model))
            renderer.render()
    except Exception as exc:  # any failure to get a GL context: EGL, OSMesa, GLFW
        return f"{type(exc).__name__}: {exc}"
    return None


@pytest.fixture(scope="session")
def needs_gl() -> None:
    """Skip (with the reason) a test that renders with MuJoCo when no GL context exists."""
    error = _gl_context_error()
    if error is not None:
        pytest.skip(f"no OpenGL context for offscreen rendering (MUJOCO_GL=egl/osmesa): {error}")


# typer's CliRunner builds the whole click command tree from the functions' signatures on
# every invoke (0.1-0.15 s for teachfit's commands, most of a misuse walk's time): built once
# per app here. The apps are not changed after import, so the tree built first stays right.
typer.testing._get_command = functools.cache(typer.testing._get_command)

_CACHE_ENV = "TEACHFIT_TEACHER_CACHE"


def pytest_configure(config: pytest.Config) -> None:
    """One teacher cache for the whole run, shared by the xdist workers (they inherit the
    controller's environment): the seeded teacher's recordings that several tests make
    (10-20 s each) are simulated once per run, and the folder is removed at the end."""
    if os.environ.get(_CACHE_ENV):
        return  # a worker (or a cache the user chose)
    root = Path(tempfile.gettempdir()) / f"teachfit-teacher-cache-{uuid.uuid4().hex[:12]}"
    os.environ[_CACHE_ENV] = str(root)
    config.stash[_owned_cache] = root


_owned_cache = pytest.StashKey[Path]()


def pytest_unconfigure(config: pytest.Config) -> None:
    root = config.stash.get(_owned_cache, None)
    if root is not None:  # the controller (or a run without xdist) made it
        shutil.rmtree(root, ignore_errors=True)


@pytest.fixture
def no_teacher_cache(monkeypatch: pytest.MonkeyPatch) -> None:
    """Tests of the teacher itself record for real."""
    monkeypatch.delenv(_CACHE_ENV, raising=False)


# the libfranka-protocol simulator and its port, for tests/robot and tests/cli alike: registered
# here only (a second registration would start a second simulator, see franka_fixtures)
from franka_fixtures import (  # noqa: E402, F401
    ctrl_c,
    expected_tcp,
    franka_port,
    franka_sim,
    franka_twin,
    listener,
    push_file,
    robot_port,
)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    """Every test file that uses the robot's port runs on one worker, the other tests one by
    one wherever a worker is free: a second worker would otherwise wait at its first such test
    for the lock until the first worker's run ends (pytest-xdist's ``xdist_group`` marks do not
    reach its scheduler under this pytest)."""
    from port_schedule import uses_the_port
    from xdist.scheduler import LoadScopeScheduling

    class PortScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = nodeid.split("::", 1)[0]
            return "robot-port" if uses_the_port(ROOT / path) else nodeid

    return PortScheduling(config, log)
