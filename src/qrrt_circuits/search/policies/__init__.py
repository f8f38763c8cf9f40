"""Search policies: how the workers of a round search one database (paper Alg. 2 and 3).

One concept per module: ``base`` the ``IterationPolicy`` base class, the ``PolicyState`` every
planner round runs through and ``verified_outcomes``; ``schedules`` the policies that fix k by a
rule (the paper's schedule, a fixed k, the optimal k of Eq. 1 for a known m); ``bbht`` BBHT;
``adaptive`` the Bayesian adaptive policy; ``thompson`` the bandit over k;
``fixed_point_amplification`` fixed-point amplitude amplification; ``estimated`` the iteration
count from an amplitude estimate of m.
"""

from .adaptive import Adaptive, AdaptiveState
from .base import IterationPolicy, PolicyState
from .bbht import BBHT, BBHTOutcome
from .schedules import FixedIterations, KnownOptimal, PaperIterations
from .thompson import ThompsonIterations, ThompsonState

__all__ = ["BBHT", "Adaptive", "AdaptiveState", "BBHTOutcome", "FixedIterations", "IterationPolicy", "KnownOptimal",
           "PaperIterations", "PolicyState", "ThompsonIterations", "ThompsonState"]
