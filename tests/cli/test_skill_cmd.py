"""``teachfit skill show|run`` through typer's CliRunner."""

from media_checks import read_png, read_video
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.skills import get_skill, load_skill
from teachfit.skills.loader import skill_to_toml

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_skill_show_prints_and_plots_the_graph(tmp_path):
    png, toml = tmp_path / "skill.png", tmp_path / "skill.toml"
    res = invoke("skill", "show", "peg-in-hole", "--plot", png, "--toml", toml)
    assert res.exit_code == 0, res.output
    sk = get_skill("peg-in-hole", "adaptive")
    lines = res.output.splitlines()
    for node in sk.nodes:  # every node is listed with its primitive
        assert any(node.name in ln and node.primitive.describe()[:20] in ln for ln in lines)
    cells = [[c.strip() for c in ln.split("│")] for ln in lines if "│" in ln]
    for name in sk.params.learned:  # every learned parameter has its row
        assert any(len(row) > 2 and row[1] == name for row in cells), name
    # the TOML written is the skill's, and loads back as the same skill
    assert toml.read_text() == skill_to_toml(sk)
    assert load_skill(toml) == sk
    read_png(png, min_px=300)
    res = invoke("skill", "show", toml, "--controller", "impedance")  # the TOML loads back
    assert res.exit_code == 0, res.output
    res = invoke("skill", "show", "screw-in")
    assert res.exit_code == 2 and "unknown skill 'screw-in'" in res.output


def _run(tmp_path, *extra):
    best = tmp_path / "best.toml"
    best.write_text("force = 10.0\nspeed_factor = 0.8\n")
    return invoke(
        "skill",
        "run",
        "peg-in-hole",
        "--task",
        "peg2d",
        "--params",
        best,
        "--controller",
        "impedance",
        "--starts",
        "1",
        "--seed",
        "3",
        *extra,
    )


def test_skill_run_with_params_and_plot(tmp_path):
    plot = tmp_path / "run.png"
    res = _run(tmp_path, "--plot", plot)
    assert res.exit_code == 0, res.output
    assert "1/1 succeeded" in res.output
    read_png(plot, min_px=300)


def test_skill_run_renders_the_execution(tmp_path, needs_gl):
    video = tmp_path / "run.mp4"
    res = _run(tmp_path, "--render", video, "--fps", "5", "--width", "160", "--height", "120")
    assert res.exit_code == 0, res.output
    frames = read_video(video)
    assert frames.shape[1:] == (120, 160, 3) and len(frames) >= 2


def test_skill_run_rejects_unknown_or_out_of_domain_params(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("force = 10.0\nforse = 3.0\n")
    res = invoke("skill", "run", "--task", "peg2d", "--params", bad, "--starts", "1")
    assert res.exit_code == 2 and "forse" in res.output and "unknown" in res.output
    far = tmp_path / "far.toml"
    far.write_text("tilt = 1.0\n")
    res = invoke("skill", "run", "--task", "peg2d", "--params", far, "--starts", "1")
    assert res.exit_code == 2 and "'tilt' = 1.0 is outside" in res.output


def test_setups_wiring_learn_over_setups_then_run_held_out(tmp_path):
    """``learn skill --setups`` stores the count with its study (a resume with another count is
    refused), ``skill run --setups`` runs held-out set-ups and reports them."""
    db, best = tmp_path / "s.db", tmp_path / "best.toml"
    quick = ("--task", "peg2d", "--starts", "1", "--workers", "0", "--study", db)
    res = invoke("learn", "skill", *quick, "--trials", 2, "--setups", 2, "--out", best)
    assert res.exit_code == 0, res.output
    assert "1 start(s) x 2 set-ups per trial" in res.output and "--setups 20" in res.output
    res = invoke("learn", "skill", *quick, "--trials", 3, "--setups", 3, "--resume")
    assert res.exit_code == 2 and "another study" in res.output
    res = invoke("skill", "run", "--task", "peg2d", "--params", best, "--starts", 1, "--setups", 2)
    assert res.exit_code == 0, res.output
    assert "2 held-out set-ups, 1 start(s) each; taught hole off by" in res.output
    line = next(ln for ln in res.output.splitlines() if "held-out set-ups with every" in ln)
    assert "/2 = " in line
    res = invoke("skill", "run", "--task", "peg2d", "--setups", 0)
    assert res.exit_code == 2
