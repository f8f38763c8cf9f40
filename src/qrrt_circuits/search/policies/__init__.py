"""Search policies: how the workers of a round search one database (paper Alg. 2 and 3).

``iteration`` holds the policies that choose a Grover iteration count (the paper's schedule, fixed
k, the optimal k of Eq. 1 for a known m, BBHT, the adaptive policy); ``thompson`` the
bandit over k and the ``PolicyState`` every
planner round runs through; ``fixed_point_amplification`` fixed-point amplitude amplification; ``estimated`` the
iteration count from an amplitude estimate of m.
"""

from .iteration import (
    BBHT,
    Adaptive,
    AdaptiveState,
    BBHTOutcome,
    FixedIterations,
    IterationPolicy,
    KnownOptimal,
    PaperIterations,
    PolicyState,
)
from .thompson import ThompsonIterations, ThompsonState

__all__ = ["BBHT", "Adaptive", "AdaptiveState", "BBHTOutcome", "FixedIterations", "IterationPolicy", "KnownOptimal",
           "PaperIterations", "PolicyState", "ThompsonIterations", "ThompsonState"]
