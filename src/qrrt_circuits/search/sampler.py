"""Grover search through any Qiskit ``BaseSamplerV2`` (a noisy fake backend, real hardware).

The logical circuit is ``grover_circuit`` (built with ``grover_operator``). It is transpiled by one
pass manager made once per backend object (``generate_preset_pass_manager``), and each transpiled
circuit is cached by its shape (marks, iterations), so a repeated search transpiles nothing.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
from qiskit.transpiler import generate_preset_pass_manager

from .backend import QuantumSearchBackend
from .circuits import BASIS_GATES, SYNTHESES, grover_circuit


class SamplerBackend(QuantumSearchBackend):
    """Wraps a ``BaseSamplerV2``; ``backend`` (a ``BackendV2``) sets the transpile target.

    Seeding is the sampler's (e.g. ``qiskit_aer.primitives.SamplerV2(seed=...)``).
    """

    name = "sampler"

    def __init__(self, sampler, backend=None, optimization_level: int = 1,
                 synthesis: str = "auto", cache_size: int = 128, max_qubits: int | None = None):
        if not hasattr(sampler, "run"):
            raise ValueError("sampler must be a qiskit BaseSamplerV2 (an object with .run(pubs, shots=...))")
        if synthesis not in SYNTHESES:
            raise ValueError(f"synthesis must be one of {SYNTHESES}, got {synthesis!r}")
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
        self._cache: OrderedDict[tuple, object] = OrderedDict()
        self._cache_size = int(cache_size)
        self.transpile_count = 0
        self._rng = np.random.default_rng(0)  # unused: the sampler owns its randomness

    @property
    def max_qubits(self) -> int:
        return self._max_qubits

    def compiled(self, marks: np.ndarray, iterations: int):
        key = (marks.shape[0], np.packbits(marks).tobytes(), iterations)
        circuit = self._cache.get(key)
        if circuit is None:
            circuit = self.pass_manager.run(grover_circuit(marks, iterations, synthesis=self.synthesis))
            self.transpile_count += 1
            self._cache[key] = circuit
            if len(self._cache) > self._cache_size:
                self._cache.popitem(last=False)
        else:
            self._cache.move_to_end(key)
        return circuit

    def _sample(self, marks, num_qubits, iterations, shots, rng) -> np.ndarray:
        # the sampler seeds itself; ``rng`` cannot reach it
        circuit = self.compiled(marks, iterations)
        result = self.sampler.run([circuit], shots=shots).result()[0]
        bitstrings = result.data.meas.get_bitstrings()
        return np.fromiter((int(bits, 2) for bits in bitstrings), dtype=np.int64,
                           count=len(bitstrings))
