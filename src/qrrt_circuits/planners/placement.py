"""The readings of Alg. 4, line 7 ("Constrain t to disc of dist. H(h) from P"): how a database's
candidates are placed in the annealing band [a, b], one strategy object per reading, chosen once
by ``AnnealingSchedule.placement`` (see its docstring for the paper's words behind each).

With t a uniform sample, P its nearest node and r = |t - P|:

- ``BandPlacement``: t moved along P -> t to a distance uniform in [a, b] (the default);
- ``ClampPlacement``: t moved to the distance clip(r, a, b), only samples outside the band move;
- ``AnnulusPlacement``: t moved to a distance whose density grows with the radius, uniform over the
  annulus' area;
- ``AdmitPlacement``: samples kept where they are and admitted only when r lies in [a, b].
"""

from __future__ import annotations

import abc

import numpy as np

from ..problems.goals import Goal, sample_goal
from ..world.environment import Environment
from ..world.nearest import NearestNeighbors
from .tree import Tree

__all__ = ["ADMIT_DRAWS_PER_ENTRY", "PLACEMENTS", "Placement", "uniform_samples"]

#: ``AdmitPlacement``: the most samples drawn per database entry before the band is declared empty
ADMIT_DRAWS_PER_ENTRY = 10_000


def uniform_samples(size: int, env: Environment, rng: np.random.Generator, goal: Goal | None,
                    goal_bias: float) -> np.ndarray:
    """``size`` uniform samples of the workspace, a fraction ``goal_bias`` drawn in the goal instead
    (paper Alg. 1, line 4)."""
    samples = env.sample_uniform(size, rng)
    if goal_bias > 0 and goal is not None:
        biased = rng.random(size) < goal_bias
        count = int(biased.sum())
        if count:
            samples[biased] = sample_goal(goal, count, rng)
    return samples


class Placement(abc.ABC):
    """One reading of Alg. 4, line 7: the candidates (and their nearest nodes) of one database."""

    @abc.abstractmethod
    def candidates(self, tree: Tree, neighbors: NearestNeighbors, size: int, env: Environment,
                   rng: np.random.Generator, goal: Goal | None, goal_bias: float,
                   band: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
        """``size`` candidates placed for the band, and the tree row of each one's parent (its
        nearest node, found by ``neighbors``, the tree's structure)."""


class _Moved(Placement):
    """Samples paired with their nearest nodes, then moved along P -> t to a distance in the band."""

    def candidates(self, tree: Tree, neighbors: NearestNeighbors, size: int, env: Environment,
                   rng: np.random.Generator, goal: Goal | None, goal_bias: float,
                   band: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
        samples = uniform_samples(size, env, rng, goal, goal_bias)
        parents = neighbors.nearest(samples)
        origin = tree.nodes.take(parents, axis=0)
        offset = samples - origin
        norm = np.linalg.norm(offset, axis=1)
        zero = norm == 0
        if np.any(zero):  # a sample on its parent: any direction will do
            offset[zero] = rng.normal(size=(int(zero.sum()), origin.shape[1]))
            norm[zero] = np.linalg.norm(offset[zero], axis=1)
        distance = self.distances(np.where(zero, 0.0, norm), band, rng)
        return origin + offset / norm[:, None] * distance[:, None], parents

    @abc.abstractmethod
    def distances(self, sample_distance: np.ndarray, band: tuple[float, float],
                  rng: np.random.Generator) -> np.ndarray:
        """Each candidate's distance from its parent, given its sample's (0 for a sample on it)."""


class BandPlacement(_Moved):
    """A distance uniform in the band."""

    def distances(self, sample_distance: np.ndarray, band: tuple[float, float],
                  rng: np.random.Generator) -> np.ndarray:
        return rng.uniform(band[0], band[1], len(sample_distance))


class ClampPlacement(_Moved):
    """The sample's own distance, clipped to the band."""

    def distances(self, sample_distance: np.ndarray, band: tuple[float, float],
                  rng: np.random.Generator) -> np.ndarray:
        return np.clip(sample_distance, band[0], band[1])


class AnnulusPlacement(_Moved):
    """A distance uniform over the annulus' area (density proportional to the radius)."""

    def distances(self, sample_distance: np.ndarray, band: tuple[float, float],
                  rng: np.random.Generator) -> np.ndarray:
        low, high = band
        return np.sqrt(rng.uniform(low * low, high * high, len(sample_distance)))


class AdmitPlacement(Placement):
    """Samples kept where they are, admitted only when their Euclidean distance to their nearest node
    lies in the band: batches of ``size`` samples, in order, until ``size`` are admitted.

    Raises:
        RuntimeError: Fewer than ``size`` admitted in ``ADMIT_DRAWS_PER_ENTRY * size`` samples.
    """

    def candidates(self, tree: Tree, neighbors: NearestNeighbors, size: int, env: Environment,
                   rng: np.random.Generator, goal: Goal | None, goal_bias: float,
                   band: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
        kept_samples: list[np.ndarray] = []
        kept_parents: list[np.ndarray] = []
        admitted = 0
        for _ in range(ADMIT_DRAWS_PER_ENTRY):
            samples = uniform_samples(size, env, rng, goal, goal_bias)
            parents = neighbors.nearest(samples)
            distance = np.linalg.norm(samples - tree.nodes.take(parents, axis=0), axis=1)
            inside = (distance >= band[0]) & (distance <= band[1])
            kept_samples.append(samples.compress(inside, axis=0))
            kept_parents.append(parents[inside])
            admitted += int(inside.sum())
            if admitted >= size:
                return np.concatenate(kept_samples)[:size], np.concatenate(kept_parents)[:size]
        raise RuntimeError(f"annealing placement 'admit': {admitted} of {size} samples admitted to the band "
                           f"{band} in {ADMIT_DRAWS_PER_ENTRY * size} draws; the band is (nearly) empty of samples")


#: ``AnnealingSchedule.placement`` -> its reading
PLACEMENTS: dict[str, Placement] = {"band": BandPlacement(), "clamp": ClampPlacement(),
                                    "annulus": AnnulusPlacement(), "admit": AdmitPlacement()}
