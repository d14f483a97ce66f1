"""Assembly figures: success against the taught-hole error per method."""

from media_checks import read_png

from teachfit.metrics.stats import summarize
from teachfit.viz.assembly_figures import plot_success_by_error


def test_success_by_error_draws_every_method(tmp_path):
    rows = {
        m: [
            (e, summarize([True] * k + [False] * (4 - k), [1.0] * 4))
            for e, k in ((0.0, 4), (0.003, j))
        ]
        for m, j in (("skill", 1), ("joined", 4))
    }
    path = plot_success_by_error(rows, tmp_path / "s.png", "peg2d")
    assert path == tmp_path / "s.png" and not list(tmp_path.glob(".*"))  # no temporary left
    read_png(path)
