"""The ``teachfit`` command line (typer + rich)."""

from __future__ import annotations

import os
from typing import Annotated

os.environ.setdefault("MUJOCO_GL", "egl")

import typer  # noqa: E402

from teachfit.cli import (  # noqa: E402
    assemble_cmd,  # noqa: E402
    capture_cmd,
    learn_cmd,
    plan_cmd,
    robot_cmd,
    skill_cmd,
)
from teachfit.cli.bench_parts_cmd import bench_parts  # noqa: E402
from teachfit.cli.bench_search_cmd import bench_search  # noqa: E402
from teachfit.cli.demo_cmd import app as demo_app  # noqa: E402
from teachfit.cli.main_cmds import register  # noqa: E402
from teachfit.cli.search_cmd import learn_search, search_app  # noqa: E402

app = typer.Typer(
    name="teachfit",
    help="Teach robots tight-fit assembly from a few demonstrations and a few trials.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
)


def _version(value: bool) -> None:
    if value:
        from importlib.metadata import PackageNotFoundError, version

        try:
            text = version("teachfit")
        except PackageNotFoundError:  # run from a source tree that was never installed
            text = "unknown (not installed)"
        typer.echo(f"teachfit {text}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option("--version", is_eager=True, callback=_version, help="print the version"),
    ] = False,
) -> None:
    """Teach robots tight-fit assembly from a few demonstrations and a few trials."""


bench_app = typer.Typer(help="Benchmarks that print figures (speed, success rates).")
app.add_typer(demo_app, name="demo")
app.add_typer(bench_app, name="bench")
learn_app = typer.Typer(help="Learn models from demonstrations or trials.", no_args_is_help=True)
learn_app.command("search")(learn_search)
learn_app.command("skill")(learn_cmd.learn_skill)
bench_app.command("learning")(learn_cmd.bench_learning)
app.add_typer(learn_app, name="learn")
app.add_typer(search_app, name="search")
app.add_typer(plan_cmd.parts_app, name="parts")
app.command("plan")(plan_cmd.plan)
demo_app.command("synth")(plan_cmd.demo_synth)
bench_app.command("planning")(plan_cmd.bench_planning_cmd)
app.add_typer(skill_cmd.skill_app, name="skill")
app.add_typer(capture_cmd.capture_app, name="capture")
bench_app.command("capture")(capture_cmd.bench_capture_cmd)
bench_app.command("search")(bench_search)
bench_app.command("parts")(bench_parts)
app.add_typer(robot_cmd.robot_app, name="robot")
bench_app.command("robot")(robot_cmd.bench_robot)
register(app, bench_app)
assemble_cmd.register(app, bench_app)


def main() -> None:
    """Console-script entry point."""
    from teachfit.cli.common import exit_on_sigterm

    exit_on_sigterm()
    app()


__all__ = ["app", "main"]
