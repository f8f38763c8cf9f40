"""Gate-level Grover search: real Qiskit circuits executed by qiskit-aer's ``AerSimulator``.

Each search asks its oracle (``search/oracles.py``) for its Grover circuit once and hands it to
``AerSimulator.run`` with ``shots``, ``seed_simulator``, ``memory=True`` (the measured word of every
shot, in order) and ``max_parallel_threads``; nothing else of qiskit-aer is used. A lookup oracle's
circuit (``aer_grover_circuit``: Walsh-Hadamard blocks, the oracle as one ``diagonal`` or as
``pauli`` + ``mcphase`` pairs, one ``mcphase`` per diffuser) uses only instructions Aer executes
natively, so it is run without a transpile; with a ``noise_model`` the gate-by-gate circuit
(``aer_literal_grover_circuit``: h, x, mcphase) is run instead, so per-gate noise acts on the
paper's gates. With ``method="matrix_product_state"``, which has no multi-controlled gates, the
gate-by-gate circuit is transpiled to ``AER_BASIC_GATES``. A circuit oracle's Grover circuit is
transpiled to those gates once per iteration count, whatever the method. Each shot is an
independent preparation, k Grover iterations and a measurement.

Independent searches (``search_many``) run one after the other: in a multi-circuit run Aer seeds
circuit i with ``seed_simulator + 2113 i``, so one run cannot give each database its own seed.

Threads: Aer parallelises a state update only from ``statevector_parallel_threshold`` (14) qubits
on; below it, extra OpenMP threads only cost their start-up and synchronisation, so circuits
narrower than ``SERIAL_BELOW_QUBITS`` run on one thread whatever ``max_parallel_threads`` says.
From 14 qubits on, the default (``max_parallel_threads=None``) runs each search on the cores free
when it starts (``_support.free_cores``: the usable cores less the cores other work kept busy,
measured from the kernel's CPU time counters less this process's own time, or the system load
before a first measurement; to the nearest core, at least one), so a search on a busy machine
does not wait on threads that have no core.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from qiskit_aer import AerSimulator

from ..._support.free_cores import free_cores
from ..._support.validation import check_int
from ..aer_circuits import simulation_synthesis_for
from ..circuits import grover_cx_bound, oracle_cx_estimate
from ..oracles import CircuitForm
from ..synthesis import OracleSynthesis
from .base import QuantumSearchBackend, seed_stream

if TYPE_CHECKING:
    from qiskit import QuantumCircuit
    from qiskit_aer.noise import NoiseModel

    from ..iterate_sequence import IterateSequence
    from ..oracles import SearchOracle

METHODS = ("statevector", "automatic", "matrix_product_state")
#: circuits on fewer qubits run single-threaded (Aer's default statevector_parallel_threshold)
SERIAL_BELOW_QUBITS = 14
#: On the GPU, Aer sizes its matrix buffer for a dense matrix on the widest instruction's qubits
#: (4^b complex128 entries for b qubits), so a diagonal oracle on n qubits takes 16 * 4^n bytes of
#: GPU memory. ``synthesis="auto"`` on the GPU therefore takes the diagonal form only up to this
#: width (4 GiB) and the ``mcz`` form above it, whatever the marks; ``synthesis="diagonal"`` is
#: run as asked (Aer reports its out-of-memory error where the buffer does not fit).
GPU_DIAGONAL_CHOSEN_UP_TO_QUBITS = 14
#: methods AerSimulator offers that these circuits cannot run, and why (refused at construction)
UNSUPPORTED_METHODS = {
    "density_matrix": "its instruction set lacks the mcphase gate of aer_grover_circuit (and it "
                      "doubles the qubits); use method='statevector' with a noise_model",
}


class AerBackend(QuantumSearchBackend):
    """Gate-level Grover search (paper Algorithm 2, lines 4-8) on ``AerSimulator(method=...)``.

    Each search builds the Grover circuit of its oracle once (for a ``LookupOracle``
    ``aer_grover_circuit``; with a noise model given here, the gate-by-gate
    ``aer_literal_grover_circuit``; for ``matrix_product_state`` that one transpiled; for a
    ``CircuitOracle`` its own, transpiled) and runs it through
    ``AerSimulator.run`` with ``shots`` shots and ``memory=True``; a marked index is measured with
    probability sin^2((2k+1) theta), sin^2 theta = m / 2^n (paper Eq. 1, Lemma 1). Every call
    draws a ``seed_simulator`` from its stream, so a plan depends on the planner's seed only.
    Oracle calls: ``iterations * shots`` (DESIGN §2).

    Args:
        seed: The backend's own stream for ``search`` calls without a seed: a non-negative
            integer, a ``numpy.random.Generator`` (used as is) or None (fresh entropy).
        method: ``"statevector"`` (default), ``"automatic"`` or ``"matrix_product_state"``
            (``METHODS``; the last for a circuit oracle with many ancillas, such as the coherent
            reachability check). ``"density_matrix"`` is refused (``UNSUPPORTED_METHODS``).
        synthesis: The oracle's form: ``"auto"`` (``simulation_synthesis``, or with a noise model
            the CX-based ``choose_synthesis``), ``"diagonal"`` or ``"mcz"`` (``OracleSynthesis``).
        noise_model: A ``qiskit_aer.noise.NoiseModel`` passed to the simulator as is, or None.
            With one, the gate-by-gate circuit runs, so per-gate noise acts on the paper's gates.
        device: One of ``AerSimulator().available_devices()`` for this qiskit-aer build:
            ``"CPU"`` (default) or ``"GPU"`` (needs qiskit-aer-gpu and an NVIDIA GPU).
        max_parallel_threads: Aer's thread limit for circuits of 14 or more qubits: None (default)
            for the cores free when each search starts (``free_cores``), 0 for all cores, or a
            limit in 1 .. 4096. Circuits on fewer than ``SERIAL_BELOW_QUBITS`` (14) qubits always
            run on one thread.

    Attributes:
        method: The Aer simulation method.
        synthesis: The oracle synthesis requested.
        simulator: The ``AerSimulator`` the circuits run on.
        device: ``"CPU"`` or ``"GPU"``.
        max_parallel_threads: The thread limit for circuits of 14 or more qubits (None: the free
            cores, per search).

    Raises:
        TypeError: ``method``, ``synthesis`` or ``device`` is not a string, or
            ``max_parallel_threads`` / ``seed`` is not an integer.
        ValueError: An unsupported or unknown ``method``, a ``device`` this build does not offer,
            an unknown ``synthesis``, ``max_parallel_threads`` outside [0, 4096] (or None) or a negative
            ``seed``.
    """

    name = "aer"

    def __init__(
        self,
        seed: int | np.random.Generator | None = None,
        method: str = "statevector",
        synthesis: str | OracleSynthesis = "auto",
        noise_model: NoiseModel | None = None,
        device: str = "CPU",
        max_parallel_threads: int | None = None,
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
        synthesis = OracleSynthesis.parse(synthesis)
        if max_parallel_threads is not None:
            check_int(max_parallel_threads, "max_parallel_threads", 0, 4096)
        self._rng = seed_stream(seed)
        self.method = method
        self.synthesis = synthesis
        self.simulator = AerSimulator(
            method=method,
            device=device,
            noise_model=noise_model,
            max_parallel_threads=0 if max_parallel_threads is None else int(max_parallel_threads),
        )
        self.device = device
        self.max_parallel_threads = None if max_parallel_threads is None else int(max_parallel_threads)
        self._literal = noise_model is not None
        if method == "matrix_product_state":  # no multi-controlled gates: the circuits are transpiled
            self._circuit_form = self._sequence_form = CircuitForm.AER_BASIC
            self._literal = False
        else:
            self._circuit_form = CircuitForm.AER_GATES if self._literal else CircuitForm.AER
            self._sequence_form = CircuitForm.AER_GATES

    @property
    def max_qubits(self) -> int:
        """The largest n the simulator's configuration accepts (``configuration().n_qubits``,
        memory-limited; read on every call, so ``set_max_qubits`` and option changes count)."""
        return int(self.simulator.configuration().n_qubits)

    #: upper bounds fitted to the measured peak memory of a search whose oracle is one diagonal: the
    #: oracle's 2^n phases, Aer's complex128 state and its converted copy of the phases, then per
    #: iteration the circuit's and Aer's copies of the oracle's phases (the circuit holds the same
    #: gate k times; Aer converts each instance)
    AER_BYTES_PER_ENTRY = 240
    AER_BYTES_PER_ENTRY_PER_ITERATION = 80
    #: per shot: the measured word kept by ``memory=True`` and its conversion to an index
    BYTES_PER_SHOT = 200

    #: the ``mcz`` oracle's footprint per entry: Aer's complex128 state and about one more 16-byte
    #: array, with a margin
    AER_MCZ_BYTES_PER_ENTRY = 48
    #: per ``mcphase`` / ``pauli`` instruction of the ``mcz`` form (2 per flipped entry per
    #: iteration): the circuit's instruction and Aer's operation, with a margin. Below the diagonal
    #: form's bound whenever ``simulation_synthesis`` picks ``mcz`` (f < 2^n / 600)
    AER_BYTES_PER_MCZ_INSTRUCTION = 4096
    #: what an Aer search adds whatever its size: its result, Aer's thread and simulator buffers
    FIXED_BYTES = 16 << 20
    #: ``matrix_product_state`` runs the gate-by-gate circuit transpiled to ``AER_BASIC_GATES``: per CX
    #: of it (``grover_cx_bound``: the circuit, its transpile and Aer's copy, with the single-qubit
    #: gates around each CX), and per entry the method's tensors (at most the state's amplitudes twice)
    MPS_BYTES_PER_CX = 8 << 10
    MPS_BYTES_PER_ENTRY = 32

    def synthesis_for(self, num_qubits: int) -> OracleSynthesis:
        """The ``synthesis`` a circuit on ``num_qubits`` qubits is built with: the constructor's,
        except ``"auto"`` on the GPU above ``GPU_DIAGONAL_CHOSEN_UP_TO_QUBITS`` qubits, which is
        ``"mcz"`` (Aer's GPU buffer for an n-qubit diagonal is 16 * 4^n bytes). The device is read
        from the simulator's options, so one set there after construction counts too."""
        on_gpu = getattr(self.simulator.options, "device", self.device) == "GPU"
        if self.synthesis is OracleSynthesis.AUTO and on_gpu and num_qubits > GPU_DIAGONAL_CHOSEN_UP_TO_QUBITS:
            return OracleSynthesis.MCZ
        return self.synthesis

    def oracle_form(self, num_qubits: int, marked: int) -> OracleSynthesis:
        """The oracle form a search of m = ``marked`` entries among 2^n is built with:
        ``synthesis_for(n)`` where it names one; else (``"auto"``) ``simulation_synthesis``'s
        choice (``"mcz"`` when 2^n > ENTRIES_PER_INSTRUCTION (2 min(m, 2^n - m) + 1)), or with a
        noise model (the gate-by-gate circuit) the CX-based ``choose_synthesis``'s.

        Args:
            num_qubits: n.
            marked: m, 0 .. 2^n.

        Returns:
            ``"diagonal"`` or ``"mcz"``.
        """
        return self._form(num_qubits, marked, self._literal)

    def peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1, marked: int | None = None, *,
                   sequence: bool = False) -> int:
        """Upper bound of one search's peak memory (``QuantumSearchBackend.peak_bytes``).

        Args:
            num_qubits: n, the index register's width.
            shots: Measurements of the search.
            iterations: k, the Grover iterations (Aer copies the diagonal oracle's phases once per
                iteration), or the generalized iterates of a sequence.
            marked: m (0 .. 2^n), or None (default) for a bound over every m.
            sequence: Whether the search runs generalized iterates (``search_sequence``: its circuit,
                ``generalized_grover_circuit``, is built gate by gate, whatever the noise model).

        Returns:
            The diagonal form: ``(AER_BYTES_PER_ENTRY + AER_BYTES_PER_ENTRY_PER_ITERATION * k) *
            2^n`` bytes; the ``mcz`` form: ``AER_MCZ_BYTES_PER_ENTRY * 2^n +
            AER_BYTES_PER_MCZ_INSTRUCTION * i f (k + 1)``, with i = 2 instructions (``pauli``,
            ``mcphase``) per flipped entry and f = min(m, 2^n - m) in the compact circuit, i = n + 1
            (X gates, ``mcphase``) and f = m in the gate-by-gate one; plus ``BYTES_PER_SHOT * shots``.
            The form is the one the search builds (``synthesis_for``; for ``"auto"``, the form
            chosen for m: ``simulation_synthesis``'s in the compact circuit, which picks the mcz
            form only where it is the smaller, the CX-based one in the gate-by-gate circuit). Without m,
            the largest estimate over every m (for the gate-by-gate ``"auto"``, the larger of the
            diagonal form's and the mcz form's with m < 2^n / (n - 1): an n-qubit MCZ needs at least
            n - 1 CX, so the CX-based choice takes the mcz form for no larger m). With
            ``matrix_product_state``: ``MPS_BYTES_PER_ENTRY * 2^n + MPS_BYTES_PER_CX *
            grover_cx_bound(n, k, m, synthesis_for(n))`` (the gate-by-gate circuit, transpiled). Plus
            ``FIXED_BYTES``.

        Raises:
            ValueError: ``marked`` outside [0, 2^n].
        """
        if self._circuit_form is CircuitForm.AER_BASIC:
            if marked is not None:
                check_int(marked, "marked", 0, 1 << num_qubits)
            cx = grover_cx_bound(num_qubits, iterations, marked, self.synthesis_for(num_qubits))
            body = (self.MPS_BYTES_PER_ENTRY << num_qubits) + self.MPS_BYTES_PER_CX * cx + self.BYTES_PER_SHOT * shots
        else:
            body = self._peak(num_qubits, shots, iterations, marked, sequence or self._literal)
        return self.FIXED_BYTES + body

    def _peak(self, num_qubits: int, shots: int, iterations: int, marked: int | None, literal: bool) -> int:
        """``peak_bytes`` of the compact (``literal`` False) or the gate-by-gate circuit."""
        entries = 1 << num_qubits
        if marked is not None:
            check_int(marked, "marked", 0, entries)
        diagonal = (self.AER_BYTES_PER_ENTRY + self.AER_BYTES_PER_ENTRY_PER_ITERATION * iterations) << num_qubits
        synthesis = self.synthesis_for(num_qubits) if marked is None else self._form(num_qubits, marked, literal)
        if synthesis is OracleSynthesis.DIAGONAL:
            body = diagonal
        elif synthesis is OracleSynthesis.MCZ:
            worst = marked if marked is not None else (entries if literal else entries // 2)
            body = self._mcz_bytes(num_qubits, iterations, worst, literal)
        elif literal:  # "auto" over every m: the CX-based choice takes the mcz form only while m c_n < 2^n - 2,
            # and an n-qubit MCZ needs at least n - 1 CX (its qubits must all interact), so m < 2^n / (n - 1)
            most = max(0, min(entries, (entries - 3) // max(1, num_qubits - 1)))
            body = max(diagonal, self._mcz_bytes(num_qubits, iterations, most, literal))
        else:
            body = diagonal  # simulation_synthesis picks the mcz form only where it is the smaller
        return body + self.BYTES_PER_SHOT * shots

    def _form(self, num_qubits: int, marked: int, literal: bool) -> OracleSynthesis:
        """The form built for m marked entries: ``synthesis_for(n)`` where it names one; for
        ``"auto"`` the CX-based choice in the gate-by-gate circuit (an MCZ's CX count is transpiled
        once per n and cached), else ``simulation_synthesis``'s."""
        synthesis = self.synthesis_for(num_qubits)
        if synthesis is not OracleSynthesis.AUTO:
            return synthesis
        if literal:
            estimate = oracle_cx_estimate(num_qubits, marked)
            return OracleSynthesis.MCZ if estimate["mcz"] < estimate["diagonal"] else OracleSynthesis.DIAGONAL
        return simulation_synthesis_for(num_qubits, marked)

    def _mcz_bytes(self, num_qubits: int, iterations: int, marked: int, literal: bool) -> int:
        """The mcz form's estimate without the shots (see ``peak_bytes``)."""
        if literal:
            instructions = (num_qubits + 1) * marked * (iterations + 1)
        else:
            instructions = 2 * min(marked, (1 << num_qubits) - marked) * (iterations + 1)
        return (self.AER_MCZ_BYTES_PER_ENTRY << num_qubits) + self.AER_BYTES_PER_MCZ_INSTRUCTION * instructions

    def threads_for(self, num_qubits: int) -> int:
        """The ``max_parallel_threads`` a circuit on ``num_qubits`` qubits runs with.

        Args:
            num_qubits: n, the circuit's width.

        Returns:
            1 below ``SERIAL_BELOW_QUBITS`` qubits; else the constructor's ``max_parallel_threads``,
            or with None the cores free now (``free_cores()``).
        """
        if num_qubits < SERIAL_BELOW_QUBITS:
            return 1
        return free_cores() if self.max_parallel_threads is None else self.max_parallel_threads

    def describe(self) -> str:
        """The backend's settings in words: ``"aer (method=..., device=..., synthesis=...)"``, the
        method and device as the simulator's options give them, the oracle synthesis requested,
        and ``", noise model"`` where the simulator has one (with one given to the constructor the
        circuit is the gate-by-gate one, ``", noise model, gate-by-gate circuit"``)."""
        options = self.simulator.options
        text = (f"{self.name} (method={getattr(options, 'method', self.method)}, "
                f"device={getattr(options, 'device', self.device)}, synthesis={self.synthesis}")
        if getattr(options, "noise_model", None) is not None or self._literal:
            text += ", noise model" + (", gate-by-gate circuit" if self._literal else "")
        return text + ")"

    def _run(self, circuit: QuantumCircuit, num_qubits: int, shots: int, seed: int) -> np.ndarray:
        """The measured index of every shot of ``circuit``: ``AerSimulator.run`` with ``shots``,
        ``seed_simulator = seed``, ``memory=True`` and ``max_parallel_threads = threads_for(n)``.

        Raises:
            RuntimeError: Aer reports a failed simulation.
        """
        result = self.simulator.run(circuit, shots=shots, seed_simulator=seed, memory=True,
                                    max_parallel_threads=self.threads_for(num_qubits)).result()
        if not result.success:
            raise RuntimeError(f"AerSimulator failed: {result.status}")
        return _indices(result.results[0].data.memory)

    def _sample_seeded(self, oracle: SearchOracle, num_qubits: int, iterations: int, shots: int,
                       seed: int | np.random.Generator | None) -> np.ndarray:
        """The oracle's Grover circuit in this backend's form (``CircuitForm``: Aer-native, gate by
        gate with a noise model, or transpiled to the gates every method runs for
        ``matrix_product_state``), run once; the simulator seed is the first
        ``integers(0, 2**31 - 1)`` of the search's generator."""
        seed_simulator = self._first_integer(seed, 2**31 - 1)
        circuit = oracle.grover_circuit(iterations, self._circuit_form, self.synthesis_for(num_qubits))
        return self._run(circuit, num_qubits, shots, seed_simulator)

    def _sample(self, oracle: SearchOracle, num_qubits: int, iterations: int, shots: int,
                rng: np.random.Generator) -> np.ndarray:
        return self._sample_seeded(oracle, num_qubits, iterations, shots, rng)

    def _sample_sequence(self, oracle: SearchOracle, num_qubits: int, sequence: IterateSequence, shots: int,
                         rng: np.random.Generator) -> np.ndarray:
        """Fixed-point amplification: the generalized iterates of ``sequence`` as one circuit
        (gate by gate; transpiled for ``matrix_product_state``)."""
        circuit = oracle.sequence_circuit(sequence, self._sequence_form, self.synthesis_for(num_qubits))
        return self._run(circuit, num_qubits, shots, int(rng.integers(0, 2**31 - 1)))


def _indices(words: list[str]) -> np.ndarray:
    """The measured indices of Aer's hexadecimal memory words."""
    return np.fromiter((int(word, 16) for word in words), dtype=np.int64, count=len(words))
