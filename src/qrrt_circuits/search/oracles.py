"""What a Grover search searches: its phase oracle, a part of the search problem, not of the backend.

A backend's ``search(oracle, iterations, shots, seed)`` prepares ``W|0> = H^n|0>`` on the
oracle's n index qubits, applies k Grover iterations Q = (``2|s><s|`` - I) O, O the oracle, and measures the
index register; a marked index comes out with probability sin^2((2k+1) theta), sin^2 theta = m / 2^n
(paper Eq. 1, Lemma 1), whichever oracle it is:

- ``LookupOracle(marks)``: O = diag((-1)^marks) on n qubits, built from the classical lookup of all
  2^n marks. This is the paper's simulation shortcut: the marks come from evaluating the predicate
  on every entry (a plan reports that work as ``simulation_checks`` and labels its results).
  Every backend searches it: the statevector backend in closed form, Aer and a sampler as circuits.
- ``CircuitOracle(circuit, index_qubits)``: a phase-oracle circuit: on ``|i>|0...0>`` it gives
  (-1)^f(i) ``|i>|0...0>``, its ancillas starting and ending in ``|0>`` (the coherent reversible
  reachability check of ``qrrt_circuits.coherent``, or a user's circuit). The backends that run
  circuits search it: Aer (``matrix_product_state`` for an oracle with many ancillas, or any other
  method) and a sampler. The statevector backend's closed form needs the marks; it refuses one.

Backends never ask which oracle they have: they ask the oracle for what they run. That is
``lookup_marks`` for a simulation of the lookup itself (the statevector backend's closed form,
amplitude estimation), or ``grover_circuit`` / ``sequence_circuit`` for a measured circuit in one
of the instruction sets of ``CircuitForm``. ``marked_count`` gives m where it is known (simulation
knowledge: ``KnownOptimal``, a tighter memory estimate) and ``cache_key`` keys a transpiled circuit.

The circuits measure the index into a classical register ``meas`` or ``c`` of n bits (bit j =
index bit j, Qiskit's little-endian order), so a measured word reads as the index.
"""

from __future__ import annotations

import abc
import enum
import functools
import uuid
from collections.abc import Hashable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from .._support.validation import check_instance, check_int
from .requests import validate_iterations, validate_marks
from .synthesis import OracleSynthesis

if TYPE_CHECKING:
    from qiskit import QuantumCircuit

    from .iterate_sequence import IterateSequence

__all__ = ["AER_BASIC_GATES", "CircuitForm", "CircuitOracle", "LookupOracle", "SearchOracle", "check_oracle"]

#: the most gates a circuit oracle's Grover circuit holds (k iterations of the oracle and the
#: reflection; about the size ``coherent.oracle.MAX_BUILD_GATES`` bounds for one oracle): larger
#: ones are refused before they are built
MAX_GROVER_GATES = 2_000_000

#: gates every Aer method runs, ``matrix_product_state`` included (it has no multi-controlled
#: gates): the instruction set of ``CircuitForm.AER_BASIC``, which a circuit oracle's Grover circuit
#: is transpiled to for Aer
AER_BASIC_GATES = ("x", "z", "h", "cx", "ccx", "u", "p", "measure")


class CircuitForm(enum.StrEnum):
    """The instruction set a backend asks an oracle's Grover circuit in.

    - ``AER`` (``"aer"``): instructions Aer's statevector method runs natively, as few as possible
      (``aer_grover_circuit``: Walsh-Hadamard blocks, a ``diagonal`` or ``pauli`` + ``mcphase``
      oracle, one ``mcphase`` per diffuser); run without a transpile.
    - ``AER_GATES`` (``"aer-gates"``): gate by gate (``aer_literal_grover_circuit``: h, x,
      ``mcphase`` and the hardware oracle), so that per-gate noise acts on the paper's gates.
    - ``AER_BASIC`` (``"aer-basic"``): ``AER_BASIC_GATES`` only, gates every Aer method runs
      (``matrix_product_state`` has no multi-controlled gates, and would apply an n-qubit
      ``diagonal`` as a dense 4^n matrix): the ``AER_GATES`` circuit transpiled.
    - ``LOGICAL`` (``"logical"``): ``grover_operator``'s circuit (``grover_circuit``), for a
      transpiler (a sampler's pass manager).
    """

    AER = "aer"
    AER_GATES = "aer-gates"
    AER_BASIC = "aer-basic"
    LOGICAL = "logical"


class SearchOracle(abc.ABC):
    """The phase oracle of one Grover search (module docstring): ``LookupOracle`` or
    ``CircuitOracle``."""

    @property
    @abc.abstractmethod
    def num_qubits(self) -> int:
        """n, the index register's width (the database holds 2^n entries)."""

    @abc.abstractmethod
    def marked_count(self) -> int | None:
        """m, the marked entries, where known (simulation knowledge); None where it is not."""

    @abc.abstractmethod
    def lookup_marks(self, user: str) -> np.ndarray:
        """The 2^n marks, for a caller that simulates the lookup itself (``user`` names it in the
        refusal of an oracle that is not a lookup).

        Raises:
            ValueError: A circuit oracle (the message names what searches one).
        """

    @abc.abstractmethod
    def grover_circuit(self, iterations: int, form: CircuitForm,
                       synthesis: OracleSynthesis = OracleSynthesis.AUTO) -> QuantumCircuit:
        """``W|0>``, k Grover iterations with this oracle and the measurement of the index, in ``form``.

        Args:
            iterations: k (validated by the caller).
            form: The instruction set (``CircuitForm``).
            synthesis: A lookup oracle's form (``OracleSynthesis``); a circuit oracle has its own.

        Returns:
            The measured ``QuantumCircuit``.
        """

    @abc.abstractmethod
    def sequence_circuit(self, sequence: IterateSequence, form: CircuitForm,
                         synthesis: OracleSynthesis = OracleSynthesis.AUTO) -> QuantumCircuit:
        """``W|0>``, the generalized iterates of ``sequence`` and the measurement of the index.

        Raises:
            ValueError: An oracle that cannot give the phase e^{i beta} its iterates need.
        """

    @abc.abstractmethod
    def cache_key(self) -> Hashable:
        """A key equal for oracles whose circuits are equal (a transpiled circuit's cache key)."""

    def describe(self) -> str:
        """The oracle in words."""
        return f"{type(self).__name__} on {self.num_qubits} index qubits"


def check_oracle(oracle: Any, name: str = "oracle") -> SearchOracle:
    """``oracle`` if it is a ``SearchOracle``, else a ``TypeError`` naming the two kinds.

    Args:
        oracle: The value to check.
        name: The argument's name for the message.

    Returns:
        ``oracle``.

    Raises:
        TypeError: Anything else (a bare marks array included: wrap it in ``LookupOracle``).
    """
    if isinstance(oracle, np.ndarray | list | tuple):
        raise TypeError(f"{name} must be a search oracle, got marks ({type(oracle).__name__}): search "
                        "LookupOracle(marks) for a lookup of them, or a CircuitOracle for a phase-oracle circuit")
    return check_instance(oracle, name, SearchOracle, "a search oracle (LookupOracle(marks) or CircuitOracle(...))")


class LookupOracle(SearchOracle):
    """The phase oracle diag((-1)^marks), from the classical lookup of the 2^n marks (the paper's
    simulation shortcut; module docstring).

    Args:
        marks: Boolean (or 0/1) array of length 2^n, n >= 1; entry i marks basis state ``|i>``.

    Attributes:
        marks: The marks as a bool array (the caller's own where it was one: not copied, so not to be
            changed while the oracle is searched).

    Raises:
        ValueError: ``marks`` not 1-D of length 2^n (n >= 1) or not boolean.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import LookupOracle, StatevectorBackend
        >>> oracle = LookupOracle(np.array([0, 0, 0, 0, 0, 1, 0, 0], dtype=bool))
        >>> oracle.num_qubits, oracle.marked_count()
        (3, 1)
        >>> StatevectorBackend(seed=0).search(oracle, iterations=2, shots=4).oracle_calls
        8
    """

    def __init__(self, marks: np.ndarray) -> None:
        self.marks, num_qubits = validate_marks(marks)
        self._num_qubits = num_qubits

    @property
    def num_qubits(self) -> int:
        return self._num_qubits

    @functools.cached_property
    def _count(self) -> int:
        return int(np.count_nonzero(self.marks))

    def marked_count(self) -> int:
        """m, the number of marked entries (counted once)."""
        return self._count

    def lookup_marks(self, user: str) -> np.ndarray:
        """The marks."""
        return self.marks

    def grover_circuit(self, iterations: int, form: CircuitForm,
                       synthesis: OracleSynthesis = OracleSynthesis.AUTO) -> QuantumCircuit:
        """``aer_grover_circuit`` (``AER``), ``aer_literal_grover_circuit`` (``AER_GATES``), the
        latter transpiled to ``AER_BASIC_GATES`` (``AER_BASIC``) or ``grover_circuit``
        (``LOGICAL``) of the marks; the oracle in ``synthesis``'s form."""
        from .circuits import aer_grover_circuit, aer_literal_grover_circuit, grover_circuit

        if form is CircuitForm.LOGICAL:
            return grover_circuit(self.marks, iterations, synthesis=synthesis)
        if form is CircuitForm.AER:
            return aer_grover_circuit(self.marks, iterations, measure=True, synthesis=synthesis)
        circuit = aer_literal_grover_circuit(self.marks, iterations, measure=True, synthesis=synthesis)
        return _basic(circuit) if form is CircuitForm.AER_BASIC else circuit

    def sequence_circuit(self, sequence: IterateSequence, form: CircuitForm,
                         synthesis: OracleSynthesis = OracleSynthesis.AUTO) -> QuantumCircuit:
        """``generalized_grover_circuit`` of the marks (gate by gate from h, x, diagonal and
        mcphase), transpiled to ``AER_BASIC_GATES`` for ``AER_BASIC``."""
        from .iterate_sequence import generalized_grover_circuit

        circuit = generalized_grover_circuit(self.marks, sequence, measure=True, synthesis=synthesis)
        return _basic(circuit) if form is CircuitForm.AER_BASIC else circuit

    def cache_key(self) -> Hashable:
        """(N, the marks packed into bytes)."""
        return (self.marks.shape[0], np.packbits(self.marks).tobytes())

    def describe(self) -> str:
        return f"lookup oracle of {self.marked_count()} marked entries among 2^{self.num_qubits}"


class CircuitOracle(SearchOracle):
    """A phase-oracle circuit: (-1)^f(i) on ``|i>``, its ancillas starting and ending in ``|0>`` (module
    docstring).

    Its Grover circuit is W = H^n on the index qubits, then k times the oracle followed by the
    reflection about ``W|0>`` on the index qubits only (``grover_operator`` with ``reflection_qubits``),
    then the index measured into ``meas``; the ancillas are never touched between oracle calls. For
    Aer it is transpiled to ``AER_BASIC_GATES`` once per iteration count and kept.

    Args:
        circuit: A ``QuantumCircuit`` without classical bits acting on ``|i>|0...0>`` as the phase oracle.
        index_qubits: The index register: n (the circuit's first n qubits, qubit j index bit j), or
            the n distinct qubit positions of index bits 0, 1, ..., n - 1.
        marks: The 2^n marks the circuit computes, where known (simulation knowledge: ``KnownOptimal``
            reads their count, and a memory estimate may use it); never used to search. Default None.

    Attributes:
        circuit: The oracle circuit.
        index_qubits: The index bits' qubit positions, bit 0 first.
        marks: The known marks (read-only) or None.

    Raises:
        TypeError: ``circuit`` not a ``QuantumCircuit``, or index positions that are not integers.
        ValueError: A circuit with classical bits, an index outside the circuit or with a repeated
            qubit, or ``marks`` not of length 2^n.

    Example:
        >>> import numpy as np
        >>> from qiskit import QuantumCircuit
        >>> from qrrt_circuits import AerBackend, CircuitOracle
        >>> flip = QuantumCircuit(3)
        >>> _ = flip.x(1), flip.ccz(0, 1, 2), flip.x(1)  # (-1) on |i> = |101>: index 5
        >>> oracle = CircuitOracle(flip, 3)
        >>> result = AerBackend(seed=0).search(oracle, iterations=2, shots=100, seed=1)
        >>> bool(np.mean(result.indices == 5) > 0.8)
        True
    """

    def __init__(self, circuit: QuantumCircuit, index_qubits: int | Sequence[int],
                 marks: np.ndarray | None = None) -> None:
        from qiskit import QuantumCircuit

        check_instance(circuit, "circuit", QuantumCircuit, "a QuantumCircuit")
        if circuit.num_clbits:
            raise ValueError(f"circuit must have no classical bits (it has {circuit.num_clbits}): the search "
                             "measures the index register itself")
        width = circuit.num_qubits
        if isinstance(index_qubits, Sequence):
            positions = tuple(check_int(q, "index_qubits[...]", 0, width - 1) for q in index_qubits)
            if not positions or len(set(positions)) != len(positions):
                raise ValueError(f"index_qubits must be distinct qubits of the circuit, got {list(index_qubits)}")
        else:
            positions = tuple(range(check_int(index_qubits, "index_qubits", 1, width)))
        self.circuit = circuit
        self.index_qubits = positions
        self.marks: np.ndarray | None = None
        if marks is not None:
            checked, n = validate_marks(marks)
            if n != len(positions):
                raise ValueError(f"marks must have length 2**{len(positions)} (the index register), "
                                 f"got {checked.shape[0]}")
            self.marks = checked.copy()
            self.marks.setflags(write=False)
        self._token = uuid.uuid4().hex  # (an object's id can be reused once it is freed)
        self._built: dict[int, QuantumCircuit] = {}  # transpiled, per iteration count

    @property
    def num_qubits(self) -> int:
        return len(self.index_qubits)

    @property
    def width(self) -> int:
        """All the circuit's qubits: the index and the ancillas."""
        return int(self.circuit.num_qubits)

    def marked_count(self) -> int | None:
        """m from the known marks, or None where none were given."""
        return None if self.marks is None else int(np.count_nonzero(self.marks))

    def lookup_marks(self, user: str) -> np.ndarray:
        """Refused: a circuit oracle is simulated gate by gate, not looked up."""
        raise ValueError(
            f"{user} simulates a lookup oracle's marks and cannot simulate a circuit oracle "
            f"({self.width} qubits, {self.num_qubits} of them the index): search a CircuitOracle with "
            "AerBackend(method='matrix_product_state') (or another Aer method where the circuit's qubits fit "
            "its memory) or a SamplerBackend")

    def grover_circuit(self, iterations: int, form: CircuitForm,
                       synthesis: OracleSynthesis = OracleSynthesis.AUTO) -> QuantumCircuit:
        """The Grover circuit of the class text: as built for ``LOGICAL`` (a new circuit each call),
        transpiled to ``AER_BASIC_GATES`` for every Aer form (built once per k and kept: not to be
        changed); ``synthesis`` does not apply (the circuit is the oracle's own)."""
        iterations = self.check_grover_size(iterations)
        if form is CircuitForm.LOGICAL:
            return self._grover(iterations)
        built = self._built.get(iterations)
        if built is None:
            built = self._built[iterations] = _basic(self._grover(iterations))
        return built

    def iteration_gates(self) -> int:
        """Gates of one Grover iteration: the oracle's and the reflection's (H, X on each index
        qubit before and after one multi-controlled Z: 4 n + 1)."""
        return int(self.circuit.size()) + 4 * self.num_qubits + 1

    def check_grover_size(self, iterations: int) -> int:
        """k, validated, and refused (``ValueError``) before anything is built where k iterations
        of this oracle would hold more than ``MAX_GROVER_GATES`` gates.

        Args:
            iterations: k.

        Returns:
            k as a Python ``int``.

        Raises:
            TypeError: A non-integer k.
            ValueError: k out of range, or k x ``iteration_gates()`` above ``MAX_GROVER_GATES``; the
                message names ``iterations``, the oracle's size and the most iterations that fit.
        """
        iterations = validate_iterations(iterations)
        per_iteration = self.iteration_gates()
        if iterations * per_iteration > MAX_GROVER_GATES:
            raise ValueError(
                f"iterations = {iterations} of an oracle of {self.circuit.size()} gates on {self.width} qubits "
                f"({per_iteration} gates an iteration with the reflection) would build a circuit of "
                f"{iterations * per_iteration} gates, more than {MAX_GROVER_GATES}: at most "
                f"{MAX_GROVER_GATES // per_iteration} iterations of this oracle fit (or build a smaller oracle)")
        return iterations

    def _grover(self, iterations: int) -> QuantumCircuit:
        from qiskit import ClassicalRegister, QuantumCircuit
        from qiskit.circuit.library import grover_operator

        index = list(self.index_qubits)
        preparation = QuantumCircuit(self.width, name="W")
        preparation.h(index)
        circuit = QuantumCircuit(*self.circuit.qregs, name="circuit_oracle_grover")
        if circuit.num_qubits != self.width:  # qubits outside registers
            circuit = QuantumCircuit(self.width, name="circuit_oracle_grover")
        circuit.compose(preparation, inplace=True)
        if iterations:
            step = grover_operator(self.circuit, state_preparation=preparation, reflection_qubits=index)
            for _ in range(iterations):
                circuit.compose(step, inplace=True)
        bits = ClassicalRegister(len(index), "meas")
        circuit.add_register(bits)
        circuit.measure(index, bits)
        return circuit

    def sequence_circuit(self, sequence: IterateSequence, form: CircuitForm,
                         synthesis: OracleSynthesis = OracleSynthesis.AUTO) -> QuantumCircuit:
        """Refused: a generalized iterate needs the phase e^{i beta} on the marked entries, and a
        phase-flip circuit gives only (-1)."""
        raise ValueError("a CircuitOracle gives the phase flip (-1)^f only, and generalized Grover iterates "
                         "(search_sequence, fixed-point amplification) need the phase e^{i beta}: search it with "
                         "Grover iterations (search), or search a LookupOracle")

    def cache_key(self) -> Hashable:
        """This oracle's own random token, kept through pickling (two circuit oracles are never taken
        for each other, in any process)."""
        return ("circuit", self._token)

    def describe(self) -> str:
        return f"circuit oracle of {self.width} qubits, {self.num_qubits} of them the index"


def _basic(circuit: QuantumCircuit) -> QuantumCircuit:
    """``circuit`` transpiled to ``AER_BASIC_GATES`` (its multi-controlled gates decomposed)."""
    from qiskit import transpile

    return transpile(circuit, basis_gates=list(AER_BASIC_GATES), optimization_level=0)
