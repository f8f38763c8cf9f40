"""How a quantum planner builds one round's database, and which oracle its workers search: a
strategy object chosen once, when the planner is made (``database=``).

- ``NearestParents()`` (the default): the paper's database (Alg. 1, lines 4-8): 2^n samples, each
  paired with its nearest tree node; the phase oracle is the lookup of the predicate's 2^n answers.
- ``LatticeCandidates(cell_bits, bits)``: the structured database of ``qrrt_circuits.coherent``:
  the index names a lattice cell per axis (its centre on the ``bits``-bit fixed-point grid
  covering the workspace) and one of 2^m tree nodes, n = d a + m. Each round draws the 2^m nodes
  uniformly from the tree (with replacement while the tree is smaller), so every pairing of a cell
  with a drawn node is an entry: a sample is on the lattice, not uniform, and its parent any drawn
  node, not the nearest. With ``coherent=True`` the workers search the reversible circuit of the
  motion check (``coherent.build_coherent_oracle``, a ``CircuitOracle``) on the planner's backend
  instead of a lookup (``AerBackend(method="matrix_product_state")`` suits its many ancillas; the
  statevector backend's closed form cannot run a circuit): its marks are the fixed-point
  reference's (``coherent.reachable_reference``, the circuit checked equal to it entry for entry),
  and each measured entry is verified by the planner's own predicate, as every candidate is.
"""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING, Any

import numpy as np

from .._support.randomness import Stream
from .._support.validation import check_bool, check_instance, check_int
from ..reachability.dynamics import LinearTrackingDynamics
from ..search.oracles import LookupOracle, SearchOracle
from .database import Database, stream_database

if TYPE_CHECKING:
    from ..world.environment import Environment
    from .context import RoundView, WorkerContext

__all__ = ["Candidates", "LatticeCandidates", "NearestParents"]


class Candidates(abc.ABC):
    """A quantum planner's database strategy (module docstring)."""

    @abc.abstractmethod
    def build(self, context: WorkerContext, view: RoundView, worker: int) -> Database:
        """The round's 2^n entries: children and their parents (tree rows)."""

    def check(self, env: Environment, num_qubits: int, workers_see_errors: bool) -> None:
        """Refuse, before planning, a planner this database cannot serve (default: any serves)."""
        return None

    def oracle_marks(self, context: WorkerContext, db: Database, truth: np.ndarray) -> np.ndarray:
        """The phase oracle's marks given the predicate's answers (default: the lookup of them)."""
        return truth

    def search_oracle(self, context: WorkerContext, db: Database, marks: np.ndarray) -> SearchOracle:
        """The phase oracle the workers search ``db`` with, given its (possibly erroneous) marks
        (default: their lookup, ``LookupOracle``)."""
        return LookupOracle(marks)

    @abc.abstractmethod
    def describe(self) -> dict:
        """JSON-able settings."""

    def labels(self) -> tuple[str, ...]:
        """The simulation shortcuts this database adds (default: none)."""
        return ()


class NearestParents(Candidates):
    """The paper's database: 2^n samples, each with its nearest tree node (the default)."""

    def build(self, context: WorkerContext, view: RoundView, worker: int) -> Database:
        return stream_database(view.tree, context.database_size, context.env, context.streams, view.round_index,
                               worker, view.goal, context.goal_bias, context.annealing,
                               view.temperature_index, context.max_extension, context.space, view.neighbors)

    def describe(self) -> dict:
        return {"kind": "nearest-parents"}


class LatticeCandidates(Candidates):
    """Lattice cells paired with drawn tree nodes, searched by lookup or by the coherent circuit
    (module docstring).

    Args:
        cell_bits: a, 1 .. ``bits``: 2^a cells per axis; the planner's n must exceed d a (the
            parent field has m = n - d a bits).
        bits: b, the fixed-point coordinates' bits (1 .. 24; default 8).
        coherent: Search the reversible circuit (True; a ``CircuitOracle``, on a backend that runs
            circuits: ``AerBackend(method="matrix_product_state")``) or the lookup (False, default),
            on the planner's backend either way.
        time_samples: K of the coherent circuit's sampled motion (default 4).
        fraction_bits: f, the circuit's coefficient bits (default ``bits``).
        dynamics: The closed loop the circuit samples (default the paper's); give the dynamics of
            the planner's predicate so that the circuit checks the motion the predicate verifies.

    Raises:
        ValueError: Out-of-range bits or samples.
        TypeError: Non-integer bits, or a non-bool ``coherent``.
    """

    def __init__(self, cell_bits: int, bits: int = 8, coherent: bool = False, time_samples: int = 4,
                 fraction_bits: int | None = None, dynamics: LinearTrackingDynamics | None = None) -> None:
        self.bits = check_int(bits, "bits", 1, 24)
        self.cell_bits = check_int(cell_bits, "cell_bits", 1, self.bits)
        self.coherent = check_bool(coherent, "coherent")
        self.time_samples = check_int(time_samples, "time_samples", 2, 4096)
        self.fraction_bits = self.bits if fraction_bits is None else check_int(fraction_bits, "fraction_bits", 0, 24)
        self.dynamics = LinearTrackingDynamics.paper() if dynamics is None else check_instance(
            dynamics, "dynamics", LinearTrackingDynamics, "a LinearTrackingDynamics or None")
        from ..coherent import SampledMotion

        self.motion = SampledMotion.from_dynamics(self.dynamics, self.time_samples, self.fraction_bits)

    def check(self, env: Environment, num_qubits: int, workers_see_errors: bool) -> None:
        from ..coherent import FixedPointFormat

        cells = env.dim * self.cell_bits
        if num_qubits <= cells:
            raise ValueError(f"num_qubits must exceed d * cell_bits = {cells} (the parent field takes the rest), "
                             f"got {num_qubits}")
        if self.coherent and workers_see_errors:
            raise ValueError("oracle_errors cannot corrupt a coherent oracle's marks: leave one of them out")
        FixedPointFormat.covering(env, self.bits).check_environment(env)

    def _database(self, context: WorkerContext, view: RoundView, worker: int) -> tuple[Any, np.ndarray]:
        """The coherent package's ``LatticeDatabase`` of this round and the tree rows it drew."""
        from ..coherent import FixedPointFormat, LatticeDatabase

        parent_bits = int(np.log2(context.database_size)) - context.env.dim * self.cell_bits
        rng = context.streams.generator(view.round_index, worker, Stream.CANDIDATES)
        size = view.tree.size
        rows = rng.choice(size, 1 << parent_bits, replace=size < (1 << parent_bits))
        fmt = FixedPointFormat.covering(context.env, self.bits)
        return LatticeDatabase(fmt, self.cell_bits, view.tree.nodes[rows], parent_bits=parent_bits), rows

    def build(self, context: WorkerContext, view: RoundView, worker: int) -> Database:
        database, rows = self._database(context, view, worker)
        entries = database.entries()
        return Database(entries.samples, rows[entries.parent_index], lattice=database)

    def oracle_marks(self, context: WorkerContext, db: Database, truth: np.ndarray) -> np.ndarray:
        if not self.coherent:
            return truth
        from ..coherent import reachable_reference

        return reachable_reference(context.env, db.lattice, self.motion)

    def search_oracle(self, context: WorkerContext, db: Database, marks: np.ndarray) -> SearchOracle:
        if not self.coherent:
            return LookupOracle(marks)
        from ..coherent import build_coherent_oracle, coherent_search_oracle

        built = build_coherent_oracle(context.env, db.lattice, self.motion)
        return coherent_search_oracle(built.circuit, db.lattice.num_index_bits, marks=marks)

    def describe(self) -> dict:
        return {"kind": "lattice", "cell_bits": self.cell_bits, "bits": self.bits, "coherent": self.coherent,
                "time_samples": self.time_samples, "fraction_bits": self.fraction_bits}

    def labels(self) -> tuple[str, ...]:
        if self.coherent:
            return ("coherent oracle: the workers search the reversible circuit of the motion check (a "
                    "CircuitOracle) on the planner's backend; its marks are the fixed-point reference's",)
        return ()
