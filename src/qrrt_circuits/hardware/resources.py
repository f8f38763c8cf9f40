"""What one oracle call (one Grover iteration) costs in gates, near term and fault tolerant, and what
a q-RRT plan would cost in time (beyond the paper, which counts oracle calls only).

**Near term** (``near_term_counts``): the iteration Q = grover_operator(phase_oracle(marks), H^n)
transpiled (optimization level 1, fixed seed) to the basis [cx, rz, sx, x] on all-to-all, a line,
or IBM's heavy-hex lattice (``CouplingMap.from_heavy_hex``, the topology of the Eagle/Heron
devices): two-qubit gate count, two-qubit depth, depth.

**Fault tolerant** (``fault_tolerant_counts``): the oracle over a classical lookup of the 2^n marks
d_i is QROM (load d_i into a clean qubit), Z on that qubit, QROM^dagger (unload):

- unary-iteration QROM over L = 2^n entries (Babbush et al., "Encoding electronic spectra in
  quantum circuits with linear T complexity", PRX 8, 041015 (2018), Sec. III.A): L - 1 Toffolis
  (4L - 4 T) with a control qubit, L - 2 without one (the lookup here has none);
- select-swap QROM (Low, Kliuchnikov, Schaeffer, "Trading T-gates for dirty qubits in state
  preparation and unitary synthesis", arXiv:1812.00954 (2018)): about L / lambda Toffolis plus
  lambda - 1 controlled swaps per output bit, with lambda extra qubits;
- the diffuser's n-qubit controlled Z: n - 2 Toffolis (And gates) with n - 2 clean ancillas
  (a compute-uncompute And ladder, Gidney, "Halving the cost of quantum addition", Quantum 2, 74
  (2018): an And costs 4 T, its uncomputation is measurement based and costs none).

With Qualtran installed (optional extra ``ft``) the counts are Qualtran's (``QROM``,
``SelectSwapQROM``, ``MultiControlZ`` with ``QECGatesCost``); without it the formulas above.

**Time** (``ProjectionAssumptions``): fault tolerant, one logical Toffoli (And) per 10 µs
(reaction-limited surface code: 1 µs code cycle, 10 µs reaction time, as assumed by Gidney and
Ekerå, "How to factor 2048 bit RSA integers in 8 hours", Quantum 5, 433 (2021)), a T gate a quarter
of that (4 T per And), Cliffords free. A plan of q-RRT costs its quantum oracle calls times the time
of one iteration plus its verifications at the classical time of one reachability test.

**Break-even**: q-RRT beats RRT on the same plans only if one iteration costs less than
(RRT's calls - q-RRT's verifications) x t_test / q-RRT's quantum calls.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .._support.validation import check_choice, check_int, check_positive_float
from ..search.requests import validate_marks
from ..search.synthesis import OracleSynthesis

if TYPE_CHECKING:
    from qiskit import QuantumCircuit
    from qiskit.transpiler import CouplingMap
    from qualtran.resource_counting import GateCounts

CONNECTIVITIES = ("all-to-all", "line", "heavy-hex")
#: the heavy-hex lattice used (57 qubits, distance 5): enough room for n <= 12 plus routing
HEAVY_HEX_DISTANCE = 5
TWO_QUBIT_BASIS = ("cx", "rz", "sx", "x")
QUALTRAN_HINT = "install the optional extra: pip install 'qrrt-circuits[ft]' (it adds qualtran)"


@dataclass(frozen=True)
class NearTermCount:
    """One Grover iteration after transpiling to [cx, rz, sx, x] on ``connectivity``.

    Args:
        num_qubits: n.
        num_marked: m.
        synthesis: The oracle synthesis, ``"diagonal"`` or ``"mcz"``.
        connectivity: One of ``CONNECTIVITIES``.
        two_qubit_gates: CX gates of one iteration.
        two_qubit_depth: Depth counting two-qubit gates only.
        depth: Full depth.
        physical_qubits: Qubits the transpiled circuit touches (with routing).
    """

    num_qubits: int
    num_marked: int
    synthesis: str
    connectivity: str
    two_qubit_gates: int
    two_qubit_depth: int
    depth: int
    physical_qubits: int


@functools.lru_cache(maxsize=8)
def coupling_map(connectivity: str, num_qubits: int) -> CouplingMap | None:
    """None (all-to-all), a line of n qubits, or the distance-5 heavy-hex lattice.

    Args:
        connectivity: One of ``CONNECTIVITIES``.
        num_qubits: n (the line's length).

    Returns:
        A Qiskit ``CouplingMap``, or None for all-to-all.

    Raises:
        ValueError: An unknown ``connectivity``.
    """
    from qiskit.transpiler import CouplingMap

    connectivity = check_choice(connectivity, "connectivity", CONNECTIVITIES)
    if connectivity == "all-to-all":
        return None
    if connectivity == "line":
        return CouplingMap.from_line(num_qubits)
    return CouplingMap.from_heavy_hex(HEAVY_HEX_DISTANCE)


def iteration_circuit(marks: np.ndarray, synthesis: str | OracleSynthesis = "diagonal") -> QuantumCircuit:
    """One Grover iteration Q = grover_operator(phase_oracle(marks, synthesis), H^n): one oracle call.

    Args:
        marks: Boolean (or 0/1) array of length 2^n.
        synthesis: ``"diagonal"`` (default), ``"mcz"`` or ``"auto"``.

    Returns:
        The n-qubit ``QuantumCircuit`` of Q (paper Alg. 2, line 8).

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, or an unknown ``synthesis``.
    """
    from qiskit.circuit.library import grover_operator

    from ..search.circuits import phase_oracle, uniform_preparation

    marks, n = validate_marks(marks)
    return grover_operator(phase_oracle(marks, synthesis), state_preparation=uniform_preparation(n))


def near_term_counts(marks: np.ndarray, synthesis: str | OracleSynthesis = "diagonal", connectivity: str = "all-to-all",
                     optimization_level: int = 1) -> NearTermCount:
    """Two-qubit gate count and depth of one iteration on ``connectivity`` (see the module text).

    Args:
        marks: Boolean (or 0/1) array of length 2^n, n <= 14.
        synthesis: ``"diagonal"`` (default) or ``"mcz"``.
        connectivity: ``"all-to-all"`` (default), ``"line"`` or ``"heavy-hex"``.
        optimization_level: Qiskit's transpiler level, 0-3 (default 1).

    Returns:
        The ``NearTermCount``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, n > 14, an unknown ``synthesis``
            or ``connectivity``, or ``optimization_level`` out of range.
        TypeError: A non-integer ``optimization_level``.
    """
    marks, n = validate_marks(marks)
    synthesis = OracleSynthesis(check_choice(synthesis, "synthesis", (OracleSynthesis.DIAGONAL, OracleSynthesis.MCZ)))
    connectivity = check_choice(connectivity, "connectivity", CONNECTIVITIES)
    check_int(optimization_level, "optimization_level", 0, 3)
    if n > 14:
        raise ValueError(f"near_term_counts transpiles the circuit: n must be <= 14, got {n}")
    compiled = transpile_to(iteration_circuit(marks, synthesis), connectivity, optimization_level)
    used = {compiled.find_bit(q).index for inst in compiled.data for q in inst.qubits}
    return NearTermCount(n, int(marks.sum()), synthesis.value, connectivity,
                         int(compiled.count_ops().get("cx", 0)),
                         int(compiled.depth(lambda inst: inst.operation.num_qubits == 2)),
                         int(compiled.depth()), len(used))


def transpile_to(circuit: QuantumCircuit, connectivity: str = "all-to-all",
                 optimization_level: int = 1) -> QuantumCircuit:
    """``circuit`` transpiled (fixed seed) to [cx, rz, sx, x] on ``connectivity``.

    Args:
        circuit: A ``QuantumCircuit``.
        connectivity: One of ``CONNECTIVITIES`` (default ``"all-to-all"``).
        optimization_level: Qiskit's preset level, 0-3 (default 1).

    Returns:
        The transpiled circuit (``seed_transpiler=0``).

    Raises:
        ValueError: An unknown ``connectivity``.
    """
    from qiskit.transpiler import generate_preset_pass_manager

    connectivity = check_choice(connectivity, "connectivity", CONNECTIVITIES)
    manager = generate_preset_pass_manager(optimization_level=optimization_level, basis_gates=list(TWO_QUBIT_BASIS),
                                           coupling_map=coupling_map(connectivity, circuit.num_qubits),
                                           seed_transpiler=0)
    return manager.run(circuit)


# ---------------------------------------------------------------------------- fault tolerant
def qrom_toffolis(num_qubits: int, controlled: bool = False) -> int:
    """Unary-iteration QROM over L = 2^n entries: L - 1 Toffolis with a control, L - 2 without
    (Babbush et al. 2018, Sec. III.A; each Toffoli an And of 4 T).

    Args:
        num_qubits: n, 1 .. 60.
        controlled: Whether the lookup has a control qubit (default False).

    Returns:
        2^n - 1 with a control, 2^n - 2 without (at least 0).

    Raises:
        TypeError: A non-integer n.
        ValueError: n out of range.

    Example:
        >>> from qrrt_circuits.hardware.resources import qrom_toffolis
        >>> qrom_toffolis(4), qrom_toffolis(4, controlled=True)
        (14, 15)
    """
    n = check_int(num_qubits, "num_qubits", 1, 60)
    size = 1 << n
    return max(size - (1 if controlled else 2), 0)


def multi_controlled_z_toffolis(num_qubits: int) -> int:
    """A Z controlled on n - 1 qubits (phase -1 on |1...1> of n qubits): n - 2 Ands with clean
    ancillas (Gidney 2018); n <= 2 is a Z or CZ (Clifford, no Toffoli).

    Args:
        num_qubits: n, 1 .. 10 000.

    Returns:
        max(n - 2, 0).

    Raises:
        TypeError: A non-integer n.
        ValueError: n out of range.
    """
    n = check_int(num_qubits, "num_qubits", 1, 10_000)
    return max(n - 2, 0)


@dataclass(frozen=True)
class FaultTolerantCount:
    """Logical non-Clifford cost of one oracle call (lookup oracle) and of one diffuser.

    Args:
        num_qubits: n.
        lookup: ``"qrom"`` or ``"select-swap"``.
        oracle_ands: Ands (Toffolis) of lookup + lookup^dagger.
        oracle_t: Extra T gates of the lookup (Qualtran's count; 0 for the formulas).
        diffuser_ands: Ands of the n-qubit controlled Z.
        source: ``"qualtran x.y"`` or ``"formula"``.

    Example:
        >>> from qrrt_circuits.hardware.resources import fault_tolerant_counts
        >>> count = fault_tolerant_counts(6, use_qualtran=False)
        >>> count.oracle_ands, count.diffuser_ands, count.t_count  # 2 (2^6 - 2), 6 - 2, 4 x 128
        (124, 4, 512)
    """

    num_qubits: int
    lookup: str
    oracle_ands: int
    oracle_t: int
    diffuser_ands: int
    source: str

    @property
    def ands(self) -> int:
        """Ands of the oracle and the diffuser together."""
        return self.oracle_ands + self.diffuser_ands

    @property
    def t_count(self) -> int:
        """T gates with 4 T per And (Gidney 2018)."""
        return 4 * self.ands + self.oracle_t

    @property
    def toffoli_equivalents(self) -> float:
        """Ands plus T / 4: the units of one Toffoli time in ``ProjectionAssumptions``."""
        return self.ands + self.oracle_t / 4


def has_qualtran() -> bool:
    """Whether Qualtran (the ``ft`` extra) can be imported."""
    try:
        import qualtran  # noqa: F401
    except ImportError:
        return False
    return True


def fault_tolerant_counts(num_qubits: int, lookup: str = "qrom", use_qualtran: bool | None = None
                          ) -> FaultTolerantCount:
    """Oracle = lookup + Z + lookup^dagger over the 2^n marks, diffuser = n-qubit controlled Z.

    ``use_qualtran``: None uses Qualtran when installed; True requires it; False uses the formulas
    (select-swap needs Qualtran: its block size is Qualtran's choice).

    Args:
        num_qubits: n, 2 .. 30.
        lookup: ``"qrom"`` (default, unary iteration) or ``"select-swap"``.
        use_qualtran: None (default), True or False, as above.

    Returns:
        The ``FaultTolerantCount`` (``source`` says which counted it).

    Raises:
        TypeError: A non-integer n.
        ValueError: n out of range, an unknown ``lookup``, or ``"select-swap"`` without Qualtran.
        ImportError: ``use_qualtran=True`` without Qualtran installed.
        RuntimeError: Qualtran reports arbitrary rotations in a lookup's cost.
    """
    n = check_int(num_qubits, "num_qubits", 2, 30)
    lookup = check_choice(lookup, "lookup", ("qrom", "select-swap"))
    if use_qualtran is None:
        use_qualtran = has_qualtran()
    if use_qualtran:
        return _qualtran_counts(n, lookup)
    if lookup == "select-swap":
        raise ValueError(f"the select-swap count needs Qualtran: {QUALTRAN_HINT}")
    return FaultTolerantCount(n, lookup, 2 * qrom_toffolis(n), 0, multi_controlled_z_toffolis(n), "formula")


@functools.lru_cache(maxsize=64)
def _qualtran_counts(n: int, lookup: str) -> FaultTolerantCount:
    try:

        from qualtran.bloqs.data_loading.qrom import QROM
        from qualtran.bloqs.data_loading.select_swap_qrom import SelectSwapQROM
        from qualtran.bloqs.mcmt import MultiControlZ
        from qualtran.resource_counting import QECGatesCost, get_cost_value
    except ImportError as exc:
        raise ImportError(f"qualtran is not installed: {QUALTRAN_HINT}") from exc
    kind = QROM if lookup == "qrom" else SelectSwapQROM
    bloq = kind.build_from_bitsize((1 << n,), (1,))  # any data: the worst case, no data-dependent pruning
    forward = get_cost_value(bloq, QECGatesCost())
    backward = get_cost_value(bloq.adjoint(), QECGatesCost())
    diffuser = get_cost_value(MultiControlZ(cvs=(1,) * (n - 1)), QECGatesCost())
    return FaultTolerantCount(n, lookup, _ands(forward) + _ands(backward), _ts(forward) + _ts(backward),
                              _ands(diffuser) + _ts(diffuser) // 4, "qualtran " + _version("qualtran"))


def _ands(cost: GateCounts) -> int:
    return int(cost.and_bloq) + int(cost.toffoli) + int(cost.cswap)


def _ts(cost: GateCounts) -> int:
    if int(cost.rotation):
        raise RuntimeError(f"unexpected arbitrary rotations in a lookup's cost: {cost}")
    return int(cost.t)


# ---------------------------------------------------------------------------- time
@dataclass(frozen=True)
class ProjectionAssumptions:
    """Stated gate times. ``toffoli_s``: one logical And/Toffoli (10 µs, reaction-limited surface
    code, Gidney and Ekerå 2021); T gates cost a quarter of it. ``two_qubit_gate_s``: one physical
    two-qubit gate layer on a superconducting device (about 0.5 µs for IBM's ECR/CZ gates; a
    lower bound on the run time of a near-term circuit, errors ignored).

    Args:
        toffoli_s: Seconds per logical And/Toffoli (> 0, default 10e-6).
        two_qubit_gate_s: Seconds per two-qubit gate layer (> 0, default 0.5e-6).

    Raises:
        TypeError: A non-real time.
        ValueError: A time that is not finite and > 0.

    Example:
        >>> from qrrt_circuits.hardware.resources import ProjectionAssumptions, fault_tolerant_counts
        >>> count = fault_tolerant_counts(6, use_qualtran=False)  # 128 Toffoli equivalents
        >>> round(ProjectionAssumptions().fault_tolerant_call_s(count), 9)
        0.00128
    """

    toffoli_s: float = 10e-6
    two_qubit_gate_s: float = 0.5e-6

    def __post_init__(self) -> None:
        check_positive_float(self.toffoli_s, "toffoli_s")
        check_positive_float(self.two_qubit_gate_s, "two_qubit_gate_s")

    def fault_tolerant_call_s(self, count: FaultTolerantCount) -> float:
        """Seconds of one fault-tolerant oracle call: Toffoli equivalents x ``toffoli_s``.

        Args:
            count: The ``FaultTolerantCount`` of one call.

        Returns:
            The seconds.
        """
        return count.toffoli_equivalents * self.toffoli_s

    def near_term_call_s(self, count: NearTermCount) -> float:
        """Seconds of one near-term iteration: two-qubit depth x ``two_qubit_gate_s``.

        Args:
            count: The ``NearTermCount`` of one iteration.

        Returns:
            The seconds (a lower bound, errors ignored).
        """
        return count.two_qubit_depth * self.two_qubit_gate_s


def plan_time_s(quantum_calls: float, verification_calls: float, call_s: float, test_s: float) -> float:
    """q-RRT's time for a plan: quantum calls x one iteration + verifications x one classical test.

    Args:
        quantum_calls: The plan's quantum oracle calls.
        verification_calls: Its verification calls.
        call_s: Seconds per quantum oracle call (one Grover iteration).
        test_s: Seconds per classical reachability test.

    Returns:
        The projected seconds.

    Example:
        >>> from qrrt_circuits.hardware.resources import plan_time_s
        >>> plan_time_s(100, 10, call_s=1e-3, test_s=1e-4)
        0.101
    """
    return float(quantum_calls * call_s + verification_calls * test_s)


def break_even_call_s(rrt_calls: float, quantum_calls: float, verification_calls: float, test_s: float) -> float:
    """The largest time per oracle call (one Grover iteration) at which q-RRT is no slower than RRT
    on the same plans: (rrt_calls - verifications) x t_test / quantum_calls (<= 0: never).

    Args:
        rrt_calls: RRT's oracle calls (all classical tests) on the plans.
        quantum_calls: q-RRT's quantum oracle calls on the same plans.
        verification_calls: q-RRT's verification calls.
        test_s: Seconds per classical reachability test.

    Returns:
        The break-even seconds per quantum call; ``inf`` if q-RRT made no quantum call.

    Example:
        >>> from qrrt_circuits.hardware.resources import break_even_call_s
        >>> break_even_call_s(1000, 100, 10, test_s=1e-4)  # (1000 - 10) x 1e-4 / 100
        0.00099
    """
    if quantum_calls <= 0:
        return math.inf
    return float((rrt_calls - verification_calls) * test_s / quantum_calls)


__all__ = [
    "CONNECTIVITIES",
    "FaultTolerantCount",
    "NearTermCount",
    "ProjectionAssumptions",
    "break_even_call_s",
    "coupling_map",
    "fault_tolerant_counts",
    "has_qualtran",
    "iteration_circuit",
    "multi_controlled_z_toffolis",
    "near_term_counts",
    "transpile_to",
    "plan_time_s",
    "qrom_toffolis",
]


def _version(package: str) -> str:
    from importlib.metadata import version

    return version(package)
