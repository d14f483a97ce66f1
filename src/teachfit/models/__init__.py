"""Learned models: exploration distribution, task dynamics, and the SearchModel bundling them."""

from teachfit.models.dynamics import DynamicsModel, fit_dynamics
from teachfit.models.exploration import ExplorationDistribution, fit_exploration
from teachfit.models.search_data import (
    DemoArrays,
    SearchData,
    dims_for_task,
    search_data,
)
from teachfit.models.search_model import SearchModel

__all__ = [
    "DemoArrays",
    "DynamicsModel",
    "ExplorationDistribution",
    "SearchData",
    "SearchModel",
    "dims_for_task",
    "fit_dynamics",
    "fit_exploration",
    "search_data",
]
