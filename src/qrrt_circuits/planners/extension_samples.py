"""The classical planners' extension samples: one per (round, worker), drawn in round order from the
plan's sequential streams, so that rounds drawn in batches draw what rounds drawn one by one would.
"""

from __future__ import annotations

import numpy as np

from .._support.randomness import RandomStreams, Stream
from ..problems.goals import Goal, sample_goal
from ..world.environment import Environment

__all__ = ["ExtensionSamples"]


class ExtensionSamples:
    """The classical planners' extension samples (paper Alg. 1, line 4), one per (round, worker),
    drawn in that order from the plan's two sequential streams (``RandomStreams.sequence``).

    Sample i (i = round p + worker) is the point low + (high - low) u of doubles i (d + b) ..
    i (d + b) + d - 1 of the ``Stream.EXTENSION_SAMPLES`` generator (``Environment.box_points``),
    where b = 1 with goal bias and 0 without; with goal bias, double i (d + b) + d is the sample's
    bias draw, and where it is below ``goal_bias`` the point is drawn in the goal instead, from the
    ``Stream.GOAL_SAMPLES`` generator, one biased sample after the other. Each sample takes a fixed
    share of the first stream and the biased ones are drawn one at a time, so ``next(a)`` then
    ``next(b)`` gives what ``next(a + b)`` gives: a batch of rounds tested ahead draws what the
    rounds drawn one by one (on an executor, or without look-ahead) would.

    Args:
        streams: The plan's ``RandomStreams``.
        env: The ``Environment`` whose workspace is sampled.
        goal: The ``Goal`` of the goal-biased samples, or None.
        goal_bias: Fraction in [0, 1) of samples drawn in the goal.

    Example:
        >>> import numpy as np
        >>> import qrrt_circuits as qc
        >>> from qrrt_circuits._support.randomness import RandomStreams
        >>> from qrrt_circuits.planners.extension_samples import ExtensionSamples
        >>> env = qc.paper_clutter(seed=0).env
        >>> one, other = (ExtensionSamples(RandomStreams.from_seed(3), env, None, 0.0) for _ in range(2))
        >>> bool(np.array_equal(one.next(5), np.concatenate((other.next(2), other.next(3)))))
        True
    """

    def __init__(self, streams: RandomStreams, env: Environment, goal: Goal | None, goal_bias: float) -> None:
        self.env, self.goal_bias = env, goal_bias
        self.points = streams.sequence(Stream.EXTENSION_SAMPLES)
        #: the goal and the generator of its points, for goal-biased samples only
        self.biased = None if goal is None or goal_bias <= 0 else (goal, streams.sequence(Stream.GOAL_SAMPLES))

    def next(self, count: int) -> np.ndarray:
        """The next ``count`` samples, (count, d)."""
        dim, biased = self.env.dim, self.biased
        draws = self.points.random((count, dim + (biased is not None)))
        samples = self.env.box_points(draws[:, :dim])
        if biased is not None:
            goal, goal_points = biased
            for row in (draws[:, dim] < self.goal_bias).nonzero()[0]:
                samples[row] = sample_goal(goal, 1, goal_points)[0]
        return samples
