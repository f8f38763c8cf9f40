"""Candidate generation: the database of (sample, nearest parent) pairs (paper Algorithm 1, lines
4-8) and Quantum Database Annealing (Algorithm 4).

``build_database`` draws 2^n samples,
uniform over the workspace (a fraction ``goal_bias`` drawn in the goal instead), and pairs
each with its nearest tree node. With an ``AnnealingSchedule`` each candidate keeps the direction
from its parent to the sample but is moved to a distance drawn uniformly in the current band
[r_min, r_max] (DESIGN §1); the schedule's ``placement`` names the other readings of Alg. 4, line 7
that the paper's text allows.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._support.randomness import RandomStreams, Stream
from .._support.validation import check_choice, check_float, check_int
from ..problems.goals import Goal
from ..world.environment import Environment
from ..world.nearest import NearestNeighbors
from ..world.spaces import RealVectorSpace, StateSpace
from .placement import PLACEMENTS, uniform_samples
from .tree import Tree


def _check_bands(bands: Any) -> tuple[tuple[float, float], ...]:
    """(r_min, r_max) pairs of finite distances >= 0, as floats (strings are not coerced)."""
    if not isinstance(bands, tuple | list) or not bands:
        raise TypeError(f"bands must be a non-empty sequence of (r_min, r_max) pairs, got {bands!r}")
    checked = []
    for i, band in enumerate(bands):
        if not isinstance(band, tuple | list | np.ndarray) or len(band) != 2:
            raise TypeError(f"bands[{i}] must be an (r_min, r_max) pair, got {band!r}")
        checked.append((check_float(band[0], f"bands[{i}] r_min", 0.0), check_float(band[1], f"bands[{i}] r_max", 0.0)))
    return tuple(checked)




@dataclass(frozen=True)
class AnnealingSchedule:
    """Quantum Database Annealing (paper Algorithm 4): the temperature array H as distance bands.

    Band i = (r_min, r_max) is in force while ``switch_at[i-1] <= h < switch_at[i]``; the last band
    stays in force. The temperature index h (Alg. 4's ``h``) counts databases built
    (``counter="databases"``, Alg. 4's h++ per loop) or nodes in the tree (``counter="nodes"``).
    In Alg. 4 every database adds a node, so the two coincide; with the classical verification a
    database can add none, and counting nodes keeps the hot phase for the tree's first ``switch_at[0]`` nodes.

    ``placement`` is the reading of Alg. 4, line 7 ("Constrain t to disc of dist. H(h) from P"; §IV.D:
    "constrained to be within a ball of radius H(h) ... while maintaining child-sample direction";
    §V.D: "databases of points at a distance between 2.7 and 4.2 units from current nodes", "only
    further away nodes are admitted to the database"). With t a uniform sample, P its nearest node,
    r the Euclidean distance from P to t and the band [a, b]:

    - ``"band"`` (default): t moved along P -> t to a distance drawn uniformly in [a, b];
    - ``"clamp"``: t projected onto the band along P -> t, to distance min(max(r, a), b) (the
      constraint as a projection: only samples outside the band move);
    - ``"annulus"``: t moved along P -> t to a distance sqrt(U(a^2, b^2)), the distance of a point
      uniform over the annulus a <= r <= b around P (§IV.D's "sample initially over a disc");
    - ``"admit"``: t kept where it is, and admitted to the database only if a <= r <= b (samples are
      drawn until the database is full).

    Distances are Euclidean (the paper's "disc").

    Args:
        bands: Non-empty sequence of (r_min, r_max) distance bands, finite, 0 <= r_min <= r_max and
            r_max > 0; band i is the distance range of Alg. 4's temperature H[i].
        switch_at: ``len(bands) - 1`` strictly increasing integers >= 1: the temperature indices at
            which the next band takes over (default ``()`` for one band).
        counter: What h counts: ``"databases"`` (default, Alg. 4) or ``"nodes"``.
        placement: The reading of Alg. 4, line 7: ``"band"`` (default), ``"clamp"``, ``"annulus"``
            or ``"admit"`` (above).

    Raises:
        TypeError: ``bands`` not a sequence of pairs, a non-real distance, ``switch_at`` not a
            tuple or list, or a non-integer entry of it.
        ValueError: An empty ``bands``, a negative or non-finite distance, r_min > r_max, r_max = 0,
            ``switch_at`` of the wrong length or not strictly increasing and >= 1, or an unknown
            ``counter`` or ``placement``.

    Example:
        >>> from qrrt_circuits import AnnealingSchedule
        >>> schedule = AnnealingSchedule(bands=((2.7, 4.2), (0.8, 2.0)), switch_at=(8,))
        >>> schedule.band(0), schedule.band(7), schedule.band(8)
        ((2.7, 4.2), (2.7, 4.2), (0.8, 2.0))
    """

    bands: tuple[tuple[float, float], ...]
    switch_at: tuple[int, ...] = ()
    counter: str = "databases"
    placement: str = "band"

    def __post_init__(self) -> None:
        bands = _check_bands(self.bands)
        for i, (lo, hi) in enumerate(bands):
            if lo > hi:
                raise ValueError(f"bands[{i}] = ({lo}, {hi}): r_min must be <= r_max")
            if hi == 0:
                raise ValueError(f"bands[{i}]: r_max must be > 0")
        if not isinstance(self.switch_at, tuple | list):
            raise TypeError(f"switch_at must be a tuple of increasing integers >= 1, got {self.switch_at!r}")
        switch_at = tuple(check_int(s, f"switch_at[{i}]", 1) for i, s in enumerate(self.switch_at))
        if len(switch_at) != len(bands) - 1:
            raise ValueError(
                f"switch_at must have len(bands) - 1 = {len(bands) - 1} entries, got {len(switch_at)}"
            )
        steps = np.diff(np.asarray(switch_at, dtype=np.int64))
        if any(s <= 0 for s in switch_at) or np.any(steps <= 0):
            raise ValueError(f"switch_at must be strictly increasing positive integers, got {switch_at}")
        check_choice(self.counter, "counter", ("databases", "nodes"))
        check_choice(self.placement, "placement", tuple(PLACEMENTS))
        object.__setattr__(self, "bands", bands)
        object.__setattr__(self, "switch_at", switch_at)

    @classmethod
    def paper(cls, switch_at: int = 8) -> AnnealingSchedule:
        """The paper's §V.D bands: [2.7, 4.2], then [0.8, 2.0] (the switch point is ours).

        Args:
            switch_at: The temperature index (databases built) at which the second band takes over,
                an integer >= 1 (default 8).

        Returns:
            ``AnnealingSchedule(bands=((2.7, 4.2), (0.8, 2.0)), switch_at=(switch_at,))``.

        Raises:
            TypeError: A non-integer ``switch_at``.
            ValueError: ``switch_at`` < 1.
        """
        return cls(bands=((2.7, 4.2), (0.8, 2.0)), switch_at=(switch_at,))

    def temperature_index(self, databases: int, nodes: int) -> int:
        """The temperature index h of paper Algorithm 4 (databases built or tree nodes, per ``counter``).

        Args:
            databases: Databases built so far.
            nodes: Nodes in the tree so far.

        Returns:
            ``nodes`` if ``counter == "nodes"``, else ``databases``.
        """
        return nodes if self.counter == "nodes" else databases

    def describe(self) -> dict:
        """The schedule as JSON-able settings: ``bands``, ``switch_at``, ``counter`` and ``placement``."""
        return {"bands": [list(band) for band in self.bands], "switch_at": list(self.switch_at),
                "counter": self.counter, "placement": self.placement}

    def band(self, temperature_index: int) -> tuple[float, float]:
        """The band in force at temperature index h (h = 0, 1, ...).

        Args:
            temperature_index: h, an integer >= 0.

        Returns:
            (r_min, r_max) of band i, where i is the number of ``switch_at`` entries <= h.
        """
        index = int(np.searchsorted(np.asarray(self.switch_at), temperature_index, side="right"))
        return self.bands[index]


@dataclass(frozen=True)
class Database:
    """2^n candidates: ``children`` (N, d) and their ``parents`` (N,) as tree indices.

    Args:
        children: Float (N, d), the candidate points (Alg. 1's x_new, one per database entry).
        parents: Int (N,), the tree row of each candidate's nearest node.
        band: The annealing band (r_min, r_max) the candidates were moved into, or None.
        lattice: The ``coherent.LatticeDatabase`` whose entries these are (``LatticeCandidates``),
            or None.
    """

    children: np.ndarray
    parents: np.ndarray
    band: tuple[float, float] | None = None
    lattice: Any = None


def build_database(
    tree: Tree,
    size: int,
    env: Environment,
    rng: np.random.Generator,
    goal: Goal | None = None,
    goal_bias: float = 0.0,
    annealing: AnnealingSchedule | None = None,
    temperature_index: int = 0,
    max_extension: float | None = None,
    space: StateSpace | None = None,
    neighbors: NearestNeighbors | None = None,
) -> Database:
    """Build one database: ``size`` samples, each paired with its nearest tree node.

    Paper Algorithm 1, lines 4-8 (and Algorithm 4, line 7, with ``annealing``).

    Args:
        tree: The ``Tree`` whose nearest nodes become the parents.
        size: Candidates N (2^n for a quantum database).
        env: The ``Environment`` whose workspace is sampled.
        rng: The generator of the samples.
        goal: The ``Goal`` whose ``sample`` draws the goal-biased samples, or None.
        goal_bias: Fraction in [0, 1) of samples drawn in the goal (``goal.sample``).
        annealing: An ``AnnealingSchedule`` (Alg. 4), or None.
        temperature_index: Alg. 4's h, which picks the annealing band.
        max_extension: The longest step from a parent (``steer``), or None (default: the raw
            samples, as the paper's Alg. 1 takes them).
        space: The ``StateSpace`` whose metric steers (and whose nearest-neighbour structure picks
            the parents without ``neighbors``); None for ``RealVectorSpace`` (Euclidean, the paper's).
        neighbors: The tree's nearest-neighbour structure (``world.nearest``: the tree's nodes,
            at the same indices), or None for a new one of ``space`` filled with them.

    Returns:
        The ``Database`` of candidates and their nearest parents.
    """
    space = RealVectorSpace(tree.dim) if space is None else space
    if neighbors is None:
        neighbors = space.nearest_neighbors()
        neighbors.add(tree.nodes)
    band = None
    if annealing is None:
        samples = uniform_samples(size, env, rng, goal, goal_bias)
        parents = neighbors.nearest(samples)
    else:  # Alg. 4, line 7, under the schedule's reading (``placement.PLACEMENTS``)
        band = annealing.band(temperature_index)
        samples, parents = PLACEMENTS[annealing.placement].candidates(tree, neighbors, size, env, rng, goal,
                                                                      goal_bias, band)
    return Database(steer(space, tree.nodes.take(parents, axis=0), samples, max_extension), parents, band)


#: the smallest positive normal double (a sample on its origin moves nowhere)
_TINY = float(np.finfo(float).tiny)


def steer(space: StateSpace, origins: np.ndarray, samples: np.ndarray, max_extension: float | None,
          length: np.ndarray | None = None) -> np.ndarray:
    """Each sample moved toward its origin until it lies at most ``max_extension`` from it under
    the space's metric (OMPL's RRT ``range``; the step bound of the authors' ``drawrandin``):
    x = interpolate(o, s, min(1, r / distance(o, s))); in R^d, o + (s - o) min(1, r / |s - o|).

    Args:
        space: The ``StateSpace``.
        origins: Float (M, d), each candidate's parent position.
        samples: Float (M, d), the raw samples.
        max_extension: r > 0, or None for the samples unchanged.
        length: ``space.distance(origins, samples)`` where the caller has it, else None.

    Returns:
        ``samples`` itself for None, else a new (M, d) array.
    """
    if max_extension is None:
        return samples
    if length is None:
        length = space.distance(origins, samples)
    fraction = np.minimum(1.0, max_extension / np.maximum(length, _TINY))
    return space.interpolate(origins, samples, fraction)

def stream_database(
    tree: Tree,
    size: int,
    env: Environment,
    streams: RandomStreams,
    round_index: int,
    worker: int,
    goal: Goal | None = None,
    goal_bias: float = 0.0,
    annealing: AnnealingSchedule | None = None,
    temperature_index: int = 0,
    max_extension: float | None = None,
    space: StateSpace | None = None,
    neighbors: NearestNeighbors | None = None,
) -> Database:
    """``build_database`` with the generator of (round, worker, ``Stream.CANDIDATES``).

    Args:
        tree: The ``Tree`` whose nearest nodes become the parents.
        size: Candidates N.
        env: The ``Environment`` whose workspace is sampled.
        streams: The plan's ``RandomStreams``.
        round_index: The round (the generator's key).
        worker: The worker (the generator's key).
        goal: The ``Goal`` of the goal-biased samples, or None.
        goal_bias: Fraction in [0, 1) of samples drawn in the goal.
        annealing: An ``AnnealingSchedule`` (Alg. 4), or None.
        temperature_index: Alg. 4's h.
        max_extension: The longest step from a parent (``steer``), or None.
        space: The ``StateSpace`` (None: ``RealVectorSpace``).
        neighbors: The tree's nearest-neighbour structure, or None (``build_database``).

    Returns:
        The ``Database``.
    """
    return build_database(tree, size, env, streams.generator(round_index, worker, Stream.CANDIDATES), goal,
                          goal_bias, annealing, temperature_index, max_extension, space, neighbors)
