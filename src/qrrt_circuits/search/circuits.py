"""Grover-search circuits over an n-qubit index register (paper Algorithm 2, lines 4-8).

Index i of the database is the computational basis state ``|i>`` in Qiskit's little-endian order
(qubit 0 is the least significant bit), so a measured bitstring b reads as i = int(b, 2).

- ``phase_oracle(marks)``: the unitary diag((-1)^marks) (the oracle X of the paper).
- ``grover_circuit(marks, k)``: W = H^n on ``|0>``, then k applications of
  Q = grover_operator(oracle, W), then measurement. After k iterations the probability of a
  marked index is sin^2((2k+1) theta), sin^2 theta = m / 2^n (Lemma 1).
- ``aer_grover_circuit(marks, k)`` (defined in ``aer_circuits``): the same unitary (up to a global
  phase) written with few instructions AerSimulator executes natively (unitary Walsh-Hadamard
  blocks, diagonal or pauli + mcphase oracles, mcphase), so no transpile is needed; its oracle form
  is chosen for simulation speed (``simulation_synthesis``), not by CX count.
- ``aer_literal_grover_circuit(marks, k)``: the same circuit gate by gate (h, x, mcphase and the
  hardware oracle), for noisy simulation, where a noise model acts per gate.
- ``resource_estimate(marks, k)``: qubits, CX count and depth in the basis [cx, rz, sx, x].
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from qiskit import QuantumCircuit, transpile
from qiskit.circuit.library import DiagonalGate, grover_operator

from .aer_circuits import aer_grover_circuit, simulation_synthesis
from .requests import validate_iterations, validate_marks
from .synthesis import OracleSynthesis

__all__ = [
    "BASIS_GATES",
    "OracleSynthesis",
    "ResourceCount",
    "ResourceEstimate",
    "aer_grover_circuit",
    "aer_literal_grover_circuit",
    "choose_synthesis",
    "grover_circuit",
    "grover_cx_bound",
    "oracle_cx_estimate",
    "phase_oracle",
    "resource_estimate",
    "simulation_synthesis",
    "uniform_preparation",
]

#: the gate set ``resource_estimate`` transpiles to (IBM's native basis)
BASIS_GATES = ("cx", "rz", "sx", "x")


def phase_oracle(marks: np.ndarray, synthesis: str | OracleSynthesis = "auto") -> QuantumCircuit:
    """The paper's phase oracle X (Algorithm 2, line 7): a circuit on n qubits equal to diag((-1)^marks).

    Args:
        marks: Boolean (or 0/1) array of length 2^n, n >= 1; entry i marks basis state i
            (little-endian: qubit 0 is the least significant bit).
        synthesis: ``"diagonal"``: one ``DiagonalGate`` (about 2^n - 2 CX once synthesised);
            ``"mcz"``: one multi-controlled Z per marked index, conjugated by X on its zero bits;
            ``"auto"``: whichever has the smaller estimated CX count (``choose_synthesis``).

    Returns:
        A ``QuantumCircuit`` named ``oracle`` on n qubits, without measurements.

    Raises:
        ValueError: ``marks`` not 1-D of length 2^n (n >= 1) or not boolean, or an unknown
            ``synthesis``.
    """
    marks, n = validate_marks(marks)
    synthesis = OracleSynthesis.parse(synthesis)
    if synthesis is OracleSynthesis.AUTO:
        synthesis = choose_synthesis(marks)
    circuit = QuantumCircuit(n, name="oracle")
    if synthesis is OracleSynthesis.DIAGONAL:
        circuit.append(DiagonalGate(np.where(marks, -1.0, 1.0).tolist()), range(n))
        return circuit
    full = (1 << n) - 1
    flipped = 0  # qubits currently conjugated by X
    for index in np.flatnonzero(marks):
        wanted = ~int(index) & full  # X on the zero bits maps |index> to |1...1>
        _flip(circuit, flipped ^ wanted)
        flipped = wanted
        _mcz(circuit, n)
    _flip(circuit, flipped)
    return circuit


def _flip(circuit: QuantumCircuit, mask: int) -> None:
    for qubit in range(circuit.num_qubits):
        if mask >> qubit & 1:
            circuit.x(qubit)


def _mcz(circuit: QuantumCircuit, n: int) -> None:
    """Phase -1 on |1...1> (an MCPhase(pi), which Aer runs natively)."""
    if n == 1:
        circuit.p(math.pi, 0)
    else:
        circuit.mcp(math.pi, list(range(n - 1)), n - 1)


@functools.lru_cache(maxsize=64)
def _mcz_cx_count(n: int) -> int:
    circuit = QuantumCircuit(n)
    _mcz(circuit, n)
    compiled = transpile(circuit, basis_gates=list(BASIS_GATES), optimization_level=1)
    return int(compiled.count_ops().get("cx", 0))


def oracle_cx_estimate(num_qubits: int, num_marked: int) -> dict[str, int]:
    """Estimated CX count of each oracle synthesis (the hardware cost ``choose_synthesis`` compares).

    Args:
        num_qubits: n, the index register's width (>= 1).
        num_marked: m, the marked entries (>= 0).

    Returns:
        ``{"diagonal": 2^n - 2, "mcz": m * c_n}``: the uniformly controlled Rz network of a
        diagonal, and m multi-controlled Z gates, c_n being the CX count of one n-qubit MCZ
        transpiled to [cx, rz, sx, x] (counted once per n and cached).
    """
    diagonal = max((1 << num_qubits) - 2, 0)
    return {"diagonal": diagonal, "mcz": num_marked * _mcz_cx_count(num_qubits)}


#: an n-qubit multi-controlled Z transpiled to [cx, rz, sx, x] takes at most this many times n^2 CX
#: (``_mcz_cx_count``: 3.6 n^2 at n = 30, checked for every n up to 30)
MCZ_CX_PER_SQUARED_QUBIT = 4


def grover_cx_bound(num_qubits: int, iterations: int, marked: int | None,
                    synthesis: str | OracleSynthesis = "auto") -> int:
    """A bound of the CX count of k Grover iterations of the gate-by-gate circuit once transpiled
    (``grover_circuit``, ``aer_literal_grover_circuit``): per iteration the oracle and the
    diffuser's multi-controlled Z, each such gate counted as c = ``MCZ_CX_PER_SQUARED_QUBIT`` n^2 CX
    (at least ``oracle_cx_estimate``'s c_n). The oracle: 2^n - 2 for ``"diagonal"``, m c for
    ``"mcz"``, the smaller for ``"auto"`` (the CX-based choice of ``choose_synthesis`` takes the
    form with fewer CX, so its count is at most both); without m, the largest over every m (m = 2^n).

    Args:
        num_qubits: n.
        iterations: k.
        marked: m, or None for the bound over every m.
        synthesis: The oracle's form (``OracleSynthesis``).

    Returns:
        k (oracle + c) CX.

    Example:
        >>> from qrrt_circuits.search.circuits import grover_cx_bound
        >>> grover_cx_bound(10, 2, 1), grover_cx_bound(10, 2, None)  # 2 (400 + 400), 2 (1022 + 400)
        (1600, 2844)
    """
    synthesis = OracleSynthesis.parse(synthesis)
    mcz = MCZ_CX_PER_SQUARED_QUBIT * num_qubits * num_qubits
    diagonal = max((1 << num_qubits) - 2, 0)
    flips = (1 << num_qubits) if marked is None else marked
    if synthesis is OracleSynthesis.DIAGONAL:
        oracle = diagonal
    elif synthesis is OracleSynthesis.MCZ:
        oracle = flips * mcz
    else:
        oracle = min(diagonal, flips * mcz)
    return iterations * (oracle + mcz)


def choose_synthesis(marks: np.ndarray) -> OracleSynthesis:
    """The oracle synthesis with the fewer estimated CX gates (``oracle_cx_estimate``).

    This is the hardware-cost choice that ``resource_estimate`` and
    ``phase_oracle(synthesis="auto")`` use; Aer's circuits use ``simulation_synthesis`` instead.

    Args:
        marks: Boolean (or 0/1) array of length 2^n, n >= 1.

    Returns:
        ``"mcz"`` if m MCZ gates need fewer CX than the diagonal, else ``"diagonal"``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean.
    """
    marks, n = validate_marks(marks)
    estimate = oracle_cx_estimate(n, int(np.count_nonzero(marks)))
    return OracleSynthesis.MCZ if estimate["mcz"] < estimate["diagonal"] else OracleSynthesis.DIAGONAL


def uniform_preparation(num_qubits: int) -> QuantumCircuit:
    """W = H^n, the paper's Walsh-Hadamard state preparation (Algorithms 2 and 3, worker line 6).

    Args:
        num_qubits: n, the index register's width.

    Returns:
        An n-qubit ``QuantumCircuit`` named ``W`` of n Hadamard gates.

    Example:
        >>> from qrrt_circuits.search.circuits import uniform_preparation
        >>> dict(uniform_preparation(3).count_ops())
        {'h': 3}
    """
    circuit = QuantumCircuit(num_qubits, name="W")
    circuit.h(range(num_qubits))
    return circuit


def grover_circuit(
    marks: np.ndarray, iterations: int, measure: bool = True, synthesis: str | OracleSynthesis = "auto"
) -> QuantumCircuit:
    """The Grover search circuit of one worker (paper Algorithm 2, lines 4-8).

    Prepares W applied to the all-zero state (W = H^n, line 6), applies ``iterations`` times
    Q = grover_operator(phase_oracle(marks), W) (lines 7-8) and measures. A marked index is then
    measured with probability sin^2((2k+1) theta), sin^2 theta = m / 2^n (paper Eq. 1, Lemma 1).

    Args:
        marks: Boolean (or 0/1) array of length 2^n, n >= 1.
        iterations: k, 0 .. ``MAX_ITERATIONS``.
        measure: Measure all qubits into a classical register named ``meas`` (``measure_all``).
        synthesis: The oracle's form (``phase_oracle``): ``"auto"``, ``"diagonal"`` or ``"mcz"``.

    Returns:
        A ``QuantumCircuit`` named ``grover`` on n qubits.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, k out of range, or an unknown
            ``synthesis``.
        TypeError: A non-integer k.
    """
    marks, n = validate_marks(marks)
    iterations = validate_iterations(iterations)
    preparation = uniform_preparation(n)
    circuit = QuantumCircuit(n, name="grover")
    circuit.compose(preparation, inplace=True)
    if iterations:
        q = grover_operator(phase_oracle(marks, synthesis), state_preparation=preparation)
        for _ in range(iterations):
            circuit.compose(q, inplace=True)
    if measure:
        circuit.measure_all()
    return circuit


def aer_literal_grover_circuit(
    marks: np.ndarray, iterations: int, measure: bool = True, synthesis: str | OracleSynthesis = "auto"
) -> QuantumCircuit:
    """The Grover circuit gate by gate from Aer-native gates, for noisy simulation: H^n, then per
    iteration the oracle (``phase_oracle``: CX-based ``synthesis`` choice, as on hardware) followed
    by the diffuser H^n X^n MCZ X^n H^n (``= -(2|s><s| - I)``); equal to ``grover_circuit`` up to a
    global phase. A noise model attached to h, x or mcphase acts on every such gate of the paper's
    circuit (``aer_grover_circuit`` merges them into fewer instructions, which is faster but would
    change where such noise applies).

    Args:
        marks: Boolean (or 0/1) array of length 2^n, n >= 1.
        iterations: k, 0 .. ``MAX_ITERATIONS``.
        measure: Measure all qubits into ``meas`` (default True).
        synthesis: The oracle's form (``phase_oracle``): ``"auto"``, ``"diagonal"`` or ``"mcz"``.

    Returns:
        An n-qubit ``QuantumCircuit`` named ``grover_aer``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, k out of range, or an unknown
            ``synthesis``.
        TypeError: A non-integer k.

    Example:
        >>> import numpy as np
        >>> from qiskit.quantum_info import Operator
        >>> from qrrt_circuits.search.circuits import aer_literal_grover_circuit, grover_circuit
        >>> marks = np.array([0, 0, 0, 0, 0, 1, 0, 0], dtype=bool)
        >>> literal = aer_literal_grover_circuit(marks, 2, measure=False)
        >>> Operator(literal).equiv(Operator(grover_circuit(marks, 2, measure=False)))
        True
    """
    marks, n = validate_marks(marks)
    iterations = validate_iterations(iterations)
    oracle = phase_oracle(marks, synthesis)
    circuit = QuantumCircuit(n, name="grover_aer")
    qubits = list(range(n))
    circuit.h(qubits)
    # append the oracle's operations without copying them (a DiagonalGate carries 2^n phases)
    oracle_ops = [(inst.operation, [oracle.find_bit(q).index for q in inst.qubits])
                  for inst in oracle.data]
    for _ in range(iterations):
        for operation, targets in oracle_ops:
            circuit.append(operation, targets, copy=False)
        circuit.h(qubits)
        circuit.x(qubits)
        _mcz(circuit, n)
        circuit.x(qubits)
        circuit.h(qubits)
    if measure:
        circuit.measure_all()
    return circuit


@dataclass(frozen=True)
class ResourceCount:
    """One transpiled circuit's cost in the basis [cx, rz, sx, x].

    Args:
        qubits: Width of the transpiled circuit.
        cx: CX gates.
        depth: Circuit depth.
        size: Total gates.
    """

    qubits: int
    cx: int
    depth: int
    size: int


@dataclass(frozen=True)
class ResourceEstimate:
    """Cost of ``iterations`` Grover iterations after transpiling to [cx, rz, sx, x].

    Args:
        num_qubits: n, the index register's width.
        num_marked: m, the marked entries.
        iterations: k.
        synthesis: The oracle synthesis used (``"diagonal"`` or ``"mcz"``).
        no_ancilla: Qubits, CX count, depth and size on n qubits.
        one_ancilla: The same with one extra clean qubit the multi-controlled gates may use.
    """

    num_qubits: int
    num_marked: int
    iterations: int
    synthesis: str
    no_ancilla: ResourceCount
    one_ancilla: ResourceCount


def resource_estimate(
    marks: np.ndarray, iterations: int, synthesis: str | OracleSynthesis = "auto", optimization_level: int = 1
) -> ResourceEstimate:
    """Qubits, CX count and depth of the Grover circuit in the basis [cx, rz, sx, x].

    Transpiles ``grover_circuit(marks, iterations, measure=False)`` twice (``seed_transpiler=0``):
    on its n qubits, and with one extra (clean) ancilla qubit the multi-controlled gates may use.

    Args:
        marks: Boolean (or 0/1) array of length 2^n, 1 <= n <= 14.
        iterations: k, 0 .. ``MAX_ITERATIONS``.
        synthesis: ``"auto"`` (``choose_synthesis``), ``"diagonal"`` or ``"mcz"``.
        optimization_level: Qiskit's transpiler level, 0-3.

    Returns:
        A ``ResourceEstimate`` with the chosen synthesis and both counts.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, n > 14 (the full circuit is
            transpiled), k out of range, or an unknown ``synthesis``.
        TypeError: A non-integer k.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.search.circuits import resource_estimate
        >>> marks = np.array([0, 0, 0, 0, 0, 1, 0, 0], dtype=bool)
        >>> estimate = resource_estimate(marks, iterations=2)
        >>> estimate.num_qubits, estimate.num_marked, estimate.synthesis
        (3, 1, 'diagonal')
        >>> estimate.no_ancilla.qubits, estimate.one_ancilla.qubits, estimate.no_ancilla.cx > 0
        (3, 4, True)
    """
    marks, n = validate_marks(marks)
    iterations = validate_iterations(iterations)
    if n > 14:
        raise ValueError(f"resource_estimate transpiles the full circuit: n must be <= 14, got {n}")
    synthesis = OracleSynthesis.parse(synthesis)
    chosen = choose_synthesis(marks) if synthesis is OracleSynthesis.AUTO else synthesis
    circuit = grover_circuit(marks, iterations, measure=False, synthesis=chosen)
    counts = []
    for ancillas in (0, 1):
        wide = QuantumCircuit(n + ancillas)
        wide.compose(circuit, range(n), inplace=True)
        compiled = transpile(wide, basis_gates=list(BASIS_GATES),
                             optimization_level=optimization_level, seed_transpiler=0)
        counts.append(ResourceCount(n + ancillas, int(compiled.count_ops().get("cx", 0)),
                                    int(compiled.depth()), int(compiled.size())))
    return ResourceEstimate(n, int(np.count_nonzero(marks)), iterations, chosen.value, *counts)
