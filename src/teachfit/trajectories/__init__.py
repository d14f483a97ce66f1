"""Search trajectories: TSHIX, ergodic coverage, baselines, and the open-tour solver."""

from teachfit.trajectories.baselines import archimedean_spiral, random_walk
from teachfit.trajectories.ergodic import (
    CosineBasis,
    ergodic_metric,
    ergodic_trajectory,
    search_box,
)
from teachfit.trajectories.tshix import (
    SearchTrajectory,
    TshixPlanner,
    default_length_scale,
    metric_weights,
    timed_path,
    tshix,
)
from teachfit.trajectories.tsp import OpenTour, open_tour, path_length

__all__ = [
    "CosineBasis",
    "OpenTour",
    "SearchTrajectory",
    "TshixPlanner",
    "archimedean_spiral",
    "default_length_scale",
    "ergodic_metric",
    "ergodic_trajectory",
    "metric_weights",
    "open_tour",
    "path_length",
    "random_walk",
    "search_box",
    "timed_path",
    "tshix",
]
