"""The authors' planning code run under GNU Octave, as reported, and our planners under its design.

The paper's planners were published as MATLAB code. One run of that code under GNU Octave 7.3 is
reported (it is not part of this repository and cannot be rerun from it), with these departures
from the published code (``OCTAVE_RUN_DEPARTURES``): ``drawrandin.m`` is missing from the published
code and was replaced by a stand-in (a point more than 20 from its parent is moved toward it until
the distance is 20); ``vf.m``'s signature, which does not match its callers, was fixed; the gain K
was the paper's hard-coded one; copies of the four algorithm files were capped at 30 nodes or
240 s; ``parfor`` ran serially. Seven trees per planner, one per seed. Every q-RRT tree stopped at
the 240 s cap with 5-17 nodes; 4 of the 7 Pq-RRT trees stopped at 24-29 nodes; the classical trees
reached 30. Each reported figure is a pooled ratio (the trees' calls summed over their nodes
summed), and the per-tree calls per node ranged as ``REPORTED[kind].per_tree_range`` says.

Like for like means the same estimator over trees of the same sizes: ``pooled_ratio_design``
resamples seven of our trees per replicate, stops each at a size drawn uniformly from its reported
range (the exact sizes were not reported: an assumption), and returns the pooled ratio and the
median tree's calls per node of each replicate. Only the range of the seven per-tree values is
reported, not the values: the range [min, max] of n independent values covers the median tree's
value with probability 1 - 2^(1-n) (98.4 % for n = 7, whatever the distribution), which is the
interval the reported figures can be given.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .random_bound_fit import calls_at_bounds

__all__ = ["OCTAVE_RUN_DEPARTURES", "REPORTED", "ReportedRun", "median_coverage", "pooled_ratio_design"]


@dataclass(frozen=True)
class ReportedRun:
    """One planner's reported figures from the authors' code under Octave.

    Attributes:
        pooled: Sum of oracle calls over sum of nodes, over the trees.
        per_tree_range: The smallest and largest calls per node of one tree.
        tree_sizes: Per tree, the smallest and largest node count it may have stopped at.
    """

    pooled: float
    per_tree_range: tuple[float, float]
    tree_sizes: tuple[tuple[int, int], ...]

    @property
    def trees(self) -> int:
        """How many trees the figure pools."""
        return len(self.tree_sizes)


_FULL = ((30, 30),)
#: the reported figures per planner (the keys of the oracle-efficiency experiment)
REPORTED: dict[str, ReportedRun] = {
    "RRT": ReportedRun(25.6, (14.2, 74.7), _FULL * 7),
    "ParallelRRT": ReportedRun(31.2, (20.3, 42.4), _FULL * 7),
    "QRRT": ReportedRun(6.95, (5.53, 8.57), ((5, 17),) * 7),
    "PQRRT": ReportedRun(8.84, (6.62, 12.3), _FULL * 3 + ((24, 29),) * 4),
}

#: how the reported run departs from the published code and from the paper's Fig. 9 design
OCTAVE_RUN_DEPARTURES = (
    "GNU Octave 7.3, not MATLAB",
    "drawrandin.m is missing from the published code: a stand-in moves a point more than 20 from its parent "
    "toward it until the distance is 20",
    "vf.m's published signature does not match its callers and was fixed",
    "K is the paper's hard-coded gain",
    "copies of the four algorithm files capped at 30 nodes or 240 s: every q-RRT tree stopped at 240 s with "
    "5-17 nodes, 4 of 7 Pq-RRT trees at 24-29 nodes",
    "parfor ran serially",
    "7 trees per planner, one per seed; pooled ratios, not the paper's least-squares slope",
)


def median_coverage(trees: int) -> float:
    """P(min <= median <= max) for ``trees`` independent values of a continuous distribution:
    1 - 2 * 0.5^trees.

    Args:
        trees: How many values (at least 2).

    Returns:
        The coverage of the range as an interval for the median.

    Raises:
        ValueError: If ``trees`` is below 2.
    """
    if trees < 2:
        raise ValueError(f"trees must be >= 2, got {trees}")
    return 1.0 - 2.0 * 0.5**trees


def pooled_ratio_design(curves: Sequence[np.ndarray], tree_sizes: Sequence[tuple[int, int]], resamples: int,
                        rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """The reported run's estimators, replicated from our trees.

    Each replicate draws ``len(tree_sizes)`` of our trees with replacement; tree i stops at the first
    round with at least s_i nodes, s_i uniform on the integers of ``tree_sizes[i]``
    (``random_bound_fit.calls_at_bounds``); the replicate gives its pooled ratio
    sum(calls) / sum(nodes) and its median tree's calls / nodes.

    Args:
        curves: One growth curve per tree of one planner (rows: nodes, oracle calls, ...).
        tree_sizes: Per tree of a replicate, the smallest and largest size (1 <= low <= high).
        resamples: Replicates.
        rng: The random generator.

    Returns:
        (pooled, median) ratios, each of shape (resamples,); NaN where a drawn tree never reached
        its size.

    Raises:
        ValueError: If there is no curve, fewer than 2 trees, ``resamples`` < 1 or a size range is
            not 1 <= low <= high.
    """
    if not curves:
        raise ValueError("pooled_ratio_design needs at least one growth curve")
    if len(tree_sizes) < 2 or resamples < 1:
        raise ValueError(f"tree_sizes must name >= 2 trees and resamples must be >= 1, got {len(tree_sizes)} "
                         f"and {resamples}")
    low = np.array([size[0] for size in tree_sizes])
    high = np.array([size[1] for size in tree_sizes])
    if np.any(low < 1) or np.any(high < low):
        raise ValueError(f"each tree size must be (low, high) with 1 <= low <= high, got {list(tree_sizes)}")
    table = np.stack([calls_at_bounds(curve, int(high.max())) for curve in curves])  # (trees, bound, 2)
    which = rng.integers(len(curves), size=(resamples, len(tree_sizes)))
    size = rng.integers(low, high + 1, size=(resamples, len(tree_sizes)))
    points = table[which, size - 1]  # (resamples, trees, 2)
    nodes, calls = points[..., 0], points[..., 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        pooled = calls.sum(axis=1) / nodes.sum(axis=1)
        median = np.median(calls / nodes, axis=1)
    return pooled, median
