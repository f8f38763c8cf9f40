"""Grover search through any Qiskit ``BaseSamplerV2`` (a noisy fake backend, real hardware).

Seeding: a ``BaseSamplerV2`` has no per-call seed. For qiskit-aer's ``SamplerV2`` built without a
seed of its own, each search passes its seed as the simulator's ``seed_simulator`` run option, so a
plan depends on the planner's seed only. Any other sampler (or an Aer sampler with a fixed seed,
which then repeats the same draws on every call) seeds itself: ``labels()`` says so, and the
planners copy that label into their results.

The logical circuit is the oracle's Grover circuit (``CircuitForm.LOGICAL``: ``grover_circuit`` of a
lookup oracle's marks, built with ``grover_operator``, or a circuit oracle's). It is transpiled by
one pass manager made once per backend object (``generate_preset_pass_manager``), and each
transpiled circuit is cached by its shape (the oracle's ``cache_key``, iterations), so a repeated
search transpiles nothing.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from qiskit.transpiler import generate_preset_pass_manager

from ..._support.validation import check_int
from ..circuits import BASIS_GATES, grover_cx_bound
from ..oracles import CircuitForm
from ..synthesis import OracleSynthesis
from .base import QuantumSearchBackend, seed_stream

if TYPE_CHECKING:
    from qiskit import QuantumCircuit
    from qiskit.primitives import BaseSamplerV2
    from qiskit.providers import BackendV2

    from ..iterate_sequence import IterateSequence
    from ..oracles import SearchOracle


#: held from setting a per-call seed on a sampler to its run's result (samplers may be shared)
_SEEDED_RUN = threading.Lock()


class SamplerBackend(QuantumSearchBackend):
    """Grover search (paper Algorithm 2, lines 4-8) through any Qiskit ``BaseSamplerV2``.

    The logical circuit is the oracle's Grover circuit (``grover_circuit(marks, k)`` for a
    ``LookupOracle``; a ``CircuitOracle``'s own); it is transpiled once per shape (oracle,
    iterations) by one preset pass manager and cached (least recently used first out).

    Seeding: for qiskit-aer's ``SamplerV2`` built without a seed, each search sets the sampler's
    ``seed_simulator`` run option from the search's seed (or the backend's stream), so a plan
    depends on the planner's seed only (``per_call_seed`` is True). Any other sampler (or an Aer
    sampler with a fixed seed) seeds itself: then ``labels()`` returns a ``randomness: ...`` label,
    which the planners copy into their results.

    Args:
        sampler: A ``BaseSamplerV2`` (any object with ``.run(pubs, shots=...)``).
        backend: A ``BackendV2`` whose target (coupling map, basis) the circuits are transpiled
            to, and whose ``num_qubits`` caps ``max_qubits``; None: the basis [cx, rz, sx, x],
            all-to-all, at most 24 qubits.
        optimization_level: The preset pass manager's level, 0, 1, 2 or 3.
        synthesis: The oracle's form: ``"auto"``, ``"diagonal"`` or ``"mcz"`` (``phase_oracle``).
        cache_size: How many transpiled circuits are kept.
        max_qubits: A lower cap on n than the target's (None: the target's).
        seed: The backend's own stream for ``search`` calls without a seed: a non-negative
            integer, a ``numpy.random.Generator`` or None (fresh entropy).

    Attributes:
        sampler: The wrapped sampler.
        synthesis: The oracle synthesis.
        pass_manager: The preset pass manager (``seed_transpiler=0``).
        transpile_count: How many circuits were transpiled (cache misses).
        per_call_seed: Whether each search seeds the sampler (see Seeding).

    Raises:
        ValueError: ``sampler`` has no ``run``, an unknown ``synthesis``, an
            ``optimization_level`` other than 0-3, or a negative ``seed``.
        TypeError: A ``seed`` of the wrong type.

    Example:
        >>> import numpy as np
        >>> from qiskit_aer.primitives import SamplerV2
        >>> from qrrt_circuits import LookupOracle, SamplerBackend
        >>> backend = SamplerBackend(SamplerV2(), seed=0)
        >>> marks = np.zeros(8, dtype=bool)
        >>> marks[5] = True
        >>> result = backend.search(LookupOracle(marks), iterations=2, shots=100, seed=1)
        >>> result.oracle_calls, backend.transpile_count, backend.labels()
        (200, 1, ())
    """

    name = "sampler"
    #: per shot: the sampler's result (its bit array and memory), the counts and the measured
    #: indices; a calibrated upper bound of the measured peak per shot of qiskit-aer's ``SamplerV2``
    #: (the generic ``QuantumSearchBackend.BYTES_PER_SHOT`` falls far short of it)
    BYTES_PER_SHOT = 400
    #: per CX of the transpiled circuit (``grover_cx_bound``): the logical circuit, the pass manager's
    #: DAGs and the transpiled circuit, with the single-qubit gates around each CX (a calibrated
    #: upper bound: ``benchmarks/memory_peaks.py`` measures 6.5 - 8.5 KiB)
    BYTES_PER_CX = 10 << 10
    #: what a search adds whatever its size: the pass manager's passes and the sampler's result
    FIXED_BYTES = 32 << 20

    def __init__(self, sampler: BaseSamplerV2, backend: BackendV2 | None = None, optimization_level: int = 1,
                 synthesis: str | OracleSynthesis = "auto", cache_size: int = 128, max_qubits: int | None = None,
                 seed: int | np.random.Generator | None = None) -> None:
        if not hasattr(sampler, "run"):
            raise ValueError("sampler must be a qiskit BaseSamplerV2 (an object with .run(pubs, shots=...))")
        synthesis = OracleSynthesis.parse(synthesis)
        if optimization_level not in (0, 1, 2, 3):
            raise ValueError(f"optimization_level must be 0, 1, 2 or 3, got {optimization_level}")
        self.sampler = sampler
        self.synthesis = synthesis
        if backend is not None:
            self.pass_manager = generate_preset_pass_manager(
                optimization_level=optimization_level, backend=backend, seed_transpiler=0)
            limit = int(backend.num_qubits)
        else:
            self.pass_manager = generate_preset_pass_manager(
                optimization_level=optimization_level, basis_gates=list(BASIS_GATES),
                seed_transpiler=0)
            limit = 24
        self._max_qubits = limit if max_qubits is None else min(int(max_qubits), limit)
        self._cache: OrderedDict[tuple[Any, ...], QuantumCircuit] = OrderedDict()
        self._cache_size = int(cache_size)
        self.transpile_count = 0
        self._rng = seed_stream(seed)
        self.per_call_seed = _accepts_run_seed(sampler)

    @property
    def max_qubits(self) -> int:
        """The largest n: the target's qubits (24 without a backend), capped by ``max_qubits``."""
        return self._max_qubits

    def peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1, marked: int | None = None, *,
                   sequence: bool = False) -> int:
        """A bound of one search's peak memory (``QuantumSearchBackend.peak_bytes``): the transpile of
        its circuit dominates, k oracles of up to 2^n - 2 CX each (a diagonal's).

        Args:
            num_qubits: n, the index register's width.
            shots: Measurements of the search.
            iterations: k, or the generalized iterates of a sequence (the same circuit's shape).
            marked: m, or None (default) for a bound over every m.
            sequence: Whether the search runs generalized iterates (the same bound).

        Returns:
            ``FIXED_BYTES + 16 * 2^n + BYTES_PER_CX * grover_cx_bound(n, k, m, synthesis) +
            BYTES_PER_SHOT * shots`` bytes: the sampler's state, the circuit's CX on an all-to-all
            device (a device's routing adds swaps this does not count).

        Raises:
            ValueError: ``marked`` outside [0, 2^n].
        """
        if marked is not None:
            check_int(marked, "marked", 0, 1 << num_qubits)
        cx = grover_cx_bound(num_qubits, iterations, marked, self.synthesis)
        return self.FIXED_BYTES + (16 << num_qubits) + self.BYTES_PER_CX * cx + self.BYTES_PER_SHOT * shots

    def compiled(self, oracle: SearchOracle, iterations: int) -> QuantumCircuit:
        """The oracle's transpiled Grover circuit of ``iterations`` iterations, from the cache when
        present.

        Args:
            oracle: The ``SearchOracle``.
            iterations: k, the Grover iterations.

        Returns:
            The transpiled, measured ``QuantumCircuit``.
        """
        key = (oracle.cache_key(), iterations)
        return self._cached_transpile(
            key, lambda: oracle.grover_circuit(iterations, CircuitForm.LOGICAL, self.synthesis))

    def compiled_sequence(self, oracle: SearchOracle, sequence: IterateSequence) -> QuantumCircuit:
        """The oracle's transpiled generalized Grover circuit (cached by oracle and phases).

        Args:
            oracle: The ``SearchOracle``.
            sequence: The ``IterateSequence``.

        Returns:
            The transpiled, measured ``QuantumCircuit``.
        """
        key = (oracle.cache_key(), "sequence", sequence.key())
        return self._cached_transpile(
            key, lambda: oracle.sequence_circuit(sequence, CircuitForm.LOGICAL, self.synthesis))

    def _cached_transpile(self, key: tuple[Any, ...], build: Callable[[], QuantumCircuit]) -> QuantumCircuit:
        """The transpiled circuit for ``key`` from the LRU cache, built and transpiled once."""
        circuit = self._cache.get(key)
        if circuit is None:
            circuit = self.pass_manager.run(build())
            self.transpile_count += 1
            self._cache[key] = circuit
            if len(self._cache) > self._cache_size:
                self._cache.popitem(last=False)
        else:
            self._cache.move_to_end(key)
        return circuit

    def labels(self) -> tuple[str, ...]:
        """Labels every result of this backend carries.

        Returns:
            Empty when each search seeds the sampler; else one ``"randomness: ..."`` label saying
            that the sampler seeds itself, so results do not depend on the planner's seed only.
        """
        if self.per_call_seed:
            return ()
        return (f"randomness: the sampler ({type(self.sampler).__name__}) seeds itself, so results "
                "depend on it and not only on the planner's seed",)

    def _sample(self, oracle: SearchOracle, num_qubits: int, iterations: int, shots: int,
                rng: np.random.Generator) -> np.ndarray:
        return self._execute(self.compiled(oracle, iterations), shots, rng)

    def _sample_sequence(self, oracle: SearchOracle, num_qubits: int, sequence: IterateSequence, shots: int,
                         rng: np.random.Generator) -> np.ndarray:
        return self._execute(self.compiled_sequence(oracle, sequence), shots, rng)

    def _execute(self, circuit: QuantumCircuit, shots: int, rng: np.random.Generator) -> np.ndarray:
        if self.per_call_seed:
            # the seed is a run option of the shared sampler, read when its job runs: one search at
            # a time sets it and waits for its result, so threads never run with each other's seed
            seed = int(rng.integers(0, 2**31 - 1))
            with _SEEDED_RUN:
                self.sampler.options.run_options["seed_simulator"] = seed
                result = self.sampler.run([circuit], shots=shots).result()[0]
        else:
            result = self.sampler.run([circuit], shots=shots).result()[0]
        bitstrings = result.data.meas.get_bitstrings()
        return np.fromiter((int(bits, 2) for bits in bitstrings), dtype=np.int64,
                           count=len(bitstrings))


def _accepts_run_seed(sampler: BaseSamplerV2) -> bool:
    """True for qiskit-aer's SamplerV2 without a fixed seed: its ``seed_simulator`` run option
    then seeds each run."""
    try:
        from qiskit_aer.primitives import SamplerV2 as AerSamplerV2
    except ImportError:  # pragma: no cover - qiskit-aer is a core dependency
        return False
    return isinstance(sampler, AerSamplerV2) and sampler.seed is None
