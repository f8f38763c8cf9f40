"""Gate-level Grover search: real Qiskit circuits executed by qiskit-aer's ``AerSimulator``.

The circuit (``aer_grover_circuit``) uses only instructions Aer executes natively (h, x, diagonal,
mcphase, measure), so it is run without a per-call transpile. Each shot is an independent
preparation, k Grover iterations and a measurement (``memory=True`` keeps them per shot).
"""

from __future__ import annotations

import numpy as np
from qiskit_aer import AerSimulator

from ..validation import check_int
from .backend import QuantumSearchBackend, seed_stream
from .circuits import SYNTHESES, aer_grover_circuit

METHODS = ("statevector", "automatic")
#: methods AerSimulator offers that these circuits cannot run, and why (refused at construction)
UNSUPPORTED_METHODS = {
    "density_matrix": "its instruction set lacks the mcphase gate of aer_grover_circuit (and it "
                      "doubles the qubits); use method='statevector' with a noise_model",
    "matrix_product_state": "its instruction set lacks the mcphase gate of aer_grover_circuit",
}


class AerBackend(QuantumSearchBackend):
    """Grover search on ``AerSimulator(method=...)``; seeded through ``seed_simulator``.

    ``noise_model`` (a ``qiskit_aer.noise.NoiseModel``) is passed to the simulator as is;
    ``device="GPU"`` needs Aer's GPU build. ``max_parallel_threads`` = 0 lets Aer use all cores.
    """

    name = "aer"

    def __init__(
        self,
        seed: int | np.random.Generator | None = None,
        method: str = "statevector",
        synthesis: str = "auto",
        noise_model=None,
        device: str = "CPU",
        max_parallel_threads: int = 0,
    ) -> None:
        for name, value in (("method", method), ("synthesis", synthesis), ("device", device)):
            if not isinstance(value, str):
                raise TypeError(f"{name} must be a string, got {value!r}")
        if method in UNSUPPORTED_METHODS:
            raise ValueError(f"method={method!r} is not supported: {UNSUPPORTED_METHODS[method]}")
        if method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {method!r}")
        available = AerSimulator().available_devices()
        if device not in available:
            raise ValueError(f"device must be one of {tuple(available)} for this qiskit-aer build, got {device!r} "
                             "(device='GPU' needs qiskit-aer-gpu and an NVIDIA GPU)")
        if synthesis not in SYNTHESES:
            raise ValueError(f"synthesis must be one of {SYNTHESES}, got {synthesis!r}")
        check_int(max_parallel_threads, "max_parallel_threads", 0, 4096)
        self._rng = seed_stream(seed)
        self.method = method
        self.synthesis = synthesis
        self.simulator = AerSimulator(
            method=method,
            device=device,
            noise_model=noise_model,
            max_parallel_threads=int(max_parallel_threads),
        )
        self.device = device

    @property
    def max_qubits(self) -> int:
        return int(self.simulator.configuration().n_qubits)

    #: calibrated on ``benchmarks/bench_memory.py`` (peak RSS of a round with many marked entries,
    #: so the oracle is one DiagonalGate): the gate's 2^n phases as Python objects, Aer's complex128
    #: state and its converted copy of the phases, then per iteration Aer's own copy of the oracle's
    #: phases (the circuit appends the same gate k times; Aer converts each instance).
    AER_BYTES_PER_ENTRY = 240
    AER_BYTES_PER_ENTRY_PER_ITERATION = 80
    #: per shot: the measured bitstring kept by ``memory=True`` and its conversion to an index
    BYTES_PER_SHOT = 200

    def peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1) -> int:
        """Upper bound of one search with the diagonal-gate oracle (the larger of the two
        syntheses: ``mcz`` is chosen only when it has fewer gates than the diagonal's 2^n - 2 CX)."""
        per_entry = self.AER_BYTES_PER_ENTRY + self.AER_BYTES_PER_ENTRY_PER_ITERATION * iterations
        return (per_entry << num_qubits) + self.BYTES_PER_SHOT * shots

    def _sample(self, marks, num_qubits, iterations, shots, rng) -> np.ndarray:
        circuit = aer_grover_circuit(marks, iterations, measure=True, synthesis=self.synthesis)
        seed = int(rng.integers(0, 2**31 - 1))
        result = self.simulator.run(circuit, shots=shots, seed_simulator=seed, memory=True).result()
        if not result.success:
            raise RuntimeError(f"AerSimulator failed: {result.status}")
        memory = result.get_memory(0)
        return np.fromiter((int(bits, 2) for bits in memory), dtype=np.int64, count=len(memory))
