import functools
import os

import pytest

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
