"""Amplitude estimation of a database's marked fraction with qiskit-algorithms (Grinko, Gacon,
Zoufal and Woerner, "Iterative quantum amplitude estimation", npj Quantum Inf. 7, 52, 2021).

The ``EstimationProblem`` is built from our circuits: the state preparation A = H^n (the paper's
W), the Grover operator Q = one standard iterate (phase oracle diag((-1)^marks), then the
inversion about the mean; ``circuits.phase_oracle`` and ``fixed_point.append_state_reflection``
with alpha = pi), and the good states are the marked indices (all n qubits are objective qubits;
a measured bitstring b is index int(b, 2), Qiskit's little-endian order). qiskit-algorithms'
``IterativeAmplitudeEstimation`` runs Q^k A|0> circuits through a ``SamplerV2``: here qiskit-aer's
``SamplerV2``, wrapped so that (a) the composed powers Q^k are flattened to the gates Aer runs
natively (Aer's sampler does not transpile, and ``Q.power(k)`` wraps Q in a custom gate) and
(b) every sampler call gets its own ``seed_simulator`` from the policy's random stream, so an
estimate is reproducible from the plan's seed and successive calls are independent.

Oracle calls (DESIGN §2, documented here because qiskit-algorithms counts differently): one shot
of Q^k A|0> applies the oracle k times inside Q^k, and deciding whether the measured index is
good takes one more oracle query (on hardware the good-state flag is computed into an objective
qubit by one query; in the planners it is the 1-call verification). So one estimation costs
``sum_i shots_i (k_i + 1)`` oracle calls, counted as quantum oracle calls;
qiskit-algorithms' ``num_oracle_queries`` reports ``sum_i shots_i k_i`` (checked on every estimate).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from qiskit import QuantumCircuit
from qiskit.primitives import BaseSamplerV2
from qiskit.primitives.containers.sampler_pub import SamplerPub

from .backend import validate_marks
from .circuits import phase_oracle
from .fixed_point import append_state_reflection

#: operations Aer's SamplerV2 executes without a transpile (our circuits use only these)
AER_NATIVE = frozenset({"h", "x", "p", "diagonal", "mcphase", "measure", "barrier", "unitary"})


def grover_iterate(marks: np.ndarray, synthesis: str = "auto") -> QuantumCircuit:
    """Q = -S_s(pi) S_t(pi): the phase oracle, then the inversion about the mean (Aer-native)."""
    marks, n = validate_marks(marks)
    circuit = QuantumCircuit(n, name="Q")
    circuit.compose(phase_oracle(marks, synthesis), inplace=True)
    append_state_reflection(circuit, np.pi)
    circuit.global_phase += np.pi
    return circuit


def estimation_problem(marks: np.ndarray, synthesis: str = "auto"):
    """qiskit-algorithms' ``EstimationProblem`` for the marked fraction a = m / N of ``marks``."""
    from qiskit_algorithms import EstimationProblem

    marks, n = validate_marks(marks)
    preparation = QuantumCircuit(n, name="A")
    preparation.h(range(n))
    table = marks.copy()
    return EstimationProblem(state_preparation=preparation, objective_qubits=list(range(n)),
                             grover_operator=grover_iterate(marks, synthesis),
                             is_good_state=lambda bits: bool(table[int(bits, 2)]))


def flatten(circuit: QuantumCircuit) -> QuantumCircuit:
    """``circuit`` with every composite instruction replaced by its definition, recursively, down
    to ``AER_NATIVE`` operations (global phases of the definitions are kept)."""
    out = circuit.copy_empty_like()

    def add(source: QuantumCircuit, qubits: list, clbits: list) -> None:
        for instruction in source.data:
            operation = instruction.operation
            targets = [qubits[source.find_bit(q).index] for q in instruction.qubits]
            bits = [clbits[source.find_bit(c).index] for c in instruction.clbits]
            if operation.name in AER_NATIVE or operation.definition is None:
                out.append(operation, targets, bits, copy=False)
            else:
                definition = operation.definition
                out.global_phase += definition.global_phase
                add(definition, targets, bits)

    add(circuit, list(out.qubits), list(out.clbits))
    return out


class SeededAerSampler(BaseSamplerV2):
    """qiskit-aer's ``SamplerV2`` with ``shots`` per circuit, a fresh ``seed_simulator`` from
    ``rng`` for every call, and composite gates flattened to Aer-native ones."""

    def __init__(self, shots: int, rng: np.random.Generator) -> None:
        from qiskit_aer.primitives import SamplerV2

        self._sampler = SamplerV2(default_shots=int(shots))
        self._rng = rng
        self.calls = 0

    def run(self, pubs, *, shots: int | None = None):
        coerced = [SamplerPub.coerce(pub) for pub in pubs]
        flat = [(flatten(pub.circuit), pub.parameter_values, pub.shots) for pub in coerced]
        self._sampler.options.run_options["seed_simulator"] = int(self._rng.integers(0, 2**31 - 1))
        self.calls += 1
        return self._sampler.run(flat, shots=shots)


@dataclass(frozen=True)
class AmplitudeEstimate:
    """One estimation of the marked fraction a = m / N.

    ``powers``: the k of each sampler round (Q^k A|0>, ``shots`` shots each);
    ``oracle_calls`` = sum shots (k + 1) (see the module docstring);
    ``library_oracle_queries``: qiskit-algorithms' ``num_oracle_queries`` (= sum shots k)."""

    estimate: float
    interval: tuple[float, float]
    alpha: float
    powers: tuple[int, ...]
    shots: int
    oracle_calls: int
    library_oracle_queries: int

    def marked_count(self, num_items: int) -> int:
        """The estimate of m: round(a N), at least 1 (a search for none would be pointless)."""
        return max(1, int(round(self.estimate * num_items)))

    def count_interval(self, num_items: int) -> tuple[float, float]:
        """The confidence interval on m = a N."""
        return (self.interval[0] * num_items, self.interval[1] * num_items)

    def calls_per_worker(self, workers: int) -> tuple[int, ...]:
        """The estimation's oracle calls when its shots are shared by ``workers`` devices: in each
        sampler round worker w runs shots // p shots (one more for w < shots % p), each costing
        k + 1 calls. Worker 0 carries the largest share, which is the estimation's critical path
        (the rounds are sequential; the shots within one are independent)."""
        calls = [0] * workers
        for k in self.powers:
            base, extra = divmod(self.shots, workers)
            for worker in range(workers):
                calls[worker] += (base + (worker < extra)) * (k + 1)
        return tuple(calls)


def estimate_marked_fraction(marks: np.ndarray, *, epsilon: float, alpha: float, shots: int,
                             rng: np.random.Generator, confidence_method: str = "beta",
                             synthesis: str = "auto") -> AmplitudeEstimate:
    """Run qiskit-algorithms' ``IterativeAmplitudeEstimation`` (target half-width ``epsilon`` on a,
    confidence 1 - ``alpha``, Clopper-Pearson ``"beta"`` or ``"chernoff"`` intervals) on ``marks``
    with a seeded Aer ``SamplerV2`` of ``shots`` shots per circuit."""
    from qiskit_algorithms import IterativeAmplitudeEstimation

    sampler = SeededAerSampler(shots, rng)
    algorithm = IterativeAmplitudeEstimation(epsilon_target=epsilon, alpha=alpha, sampler=sampler,
                                             confint_method=confidence_method)
    result = algorithm.estimate(estimation_problem(marks, synthesis))
    powers = tuple(int(k) for k in result.powers[1:])  # powers[0] = 0 is the prior, not a round
    if len(powers) != sampler.calls:
        raise RuntimeError(f"IterativeAmplitudeEstimation ran {sampler.calls} circuits but reports "
                           f"{len(powers)} powers")
    queries = int(result.num_oracle_queries)
    if queries != shots * sum(powers):
        raise RuntimeError(f"oracle-call count mismatch: qiskit-algorithms reports {queries}, "
                           f"shots x sum(k) = {shots * sum(powers)}")
    low, high = (float(v) for v in result.confidence_interval)
    return AmplitudeEstimate(float(result.estimation), (low, high), float(alpha), powers, int(shots),
                             shots * sum(k + 1 for k in powers), queries)
