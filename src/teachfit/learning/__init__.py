"""Meta-learning of skill parameters: ask/tell learners, resumable studies, parallel trials."""

from teachfit.core.params import LearningError, ParamDomain, ParamSpace
from teachfit.learning.base import Candidate, Finished, Learner, TrialResult
from teachfit.learning.bo import BayesOpt
from teachfit.learning.cmaes import CMAES
from teachfit.learning.lhs import LatinHypercube
from teachfit.learning.pso import PSO
from teachfit.learning.runner import Interrupts, RunReport, run_study
from teachfit.learning.study import METHODS, Study, StudyMismatchError, make_learner

__all__ = [
    "CMAES",
    "METHODS",
    "PSO",
    "BayesOpt",
    "Candidate",
    "Finished",
    "Interrupts",
    "LatinHypercube",
    "Learner",
    "LearningError",
    "ParamDomain",
    "ParamSpace",
    "RunReport",
    "Study",
    "StudyMismatchError",
    "TrialResult",
    "make_learner",
    "run_study",
]
