"""Amplitude estimation of a database's marked fraction with qiskit-algorithms.

Two methods: maximum-likelihood amplitude estimation (``"mlae"``, the default; Suzuki et al.,
"Amplitude estimation without phase estimation", Quantum Inf. Process. 19, 75, 2020) and
iterative amplitude estimation (``"iae"``; Grinko, Gacon, Zoufal and Woerner, npj Quantum Inf. 7,
52, 2021).

The ``EstimationProblem`` is built from our circuits: the state preparation A = H^n (the paper's
W), the Grover operator Q = one standard iterate (phase oracle diag((-1)^marks), then the
inversion about the mean; ``circuits.phase_oracle`` and ``iterate_sequence.append_state_reflection``
with alpha = pi), and the good states are the marked indices (all n qubits are objective qubits;
a measured bitstring b is index int(b, 2), Qiskit's little-endian order). qiskit-algorithms'
estimators run Q^k A|0> circuits through a ``SamplerV2``: here qiskit-aer's
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

Why MLAE is the default: qiskit-algorithms 0.4.0's ``IterativeAmplitudeEstimation`` can loop
forever with few shots per round (for example n = 5, 6 of 32 marked, 16 shots, alpha 0.2): once a
round's Clopper-Pearson interval on the lower half-circle reaches a = 0, its theta_max is 1, the
upper end of the theta interval grows by 1 / (4k + 2) every round and k never changes. The
sampler here therefore refuses to run more than ``MAX_IAE_ROUNDS`` circuits for one estimate
(a ``RuntimeError`` instead of a hang). MLAE runs one fixed schedule of powers [0, 1, 2, 4, ...]
(cost known in advance) and its likelihood-ratio interval is used.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from qiskit import QuantumCircuit
from qiskit.primitives import BaseSamplerV2
from qiskit.primitives.containers.sampler_pub import SamplerPub

from .circuits import phase_oracle
from .iterate_sequence import append_state_reflection
from .requests import validate_marks
from .synthesis import OracleSynthesis

if TYPE_CHECKING:
    from qiskit.primitives import PrimitiveJob
    from qiskit_algorithms import EstimationProblem

#: operations Aer's SamplerV2 executes without a transpile (our circuits use only these)
AER_NATIVE = frozenset({"h", "x", "p", "diagonal", "mcphase", "measure", "barrier", "unitary"})


def grover_iterate(marks: np.ndarray, synthesis: str | OracleSynthesis = "auto") -> QuantumCircuit:
    """Q = -S_s(pi) S_t(pi): the phase oracle, then the inversion about the mean (Aer-native).

    One standard Grover iterate (the paper's Alg. 2 / 3 loop body; Yoder et al.'s G(pi, pi)).

    Args:
        marks: Boolean (or 0/1) array of length 2^n.
        synthesis: The oracle's synthesis: ``"auto"`` (default), ``"diagonal"`` or ``"mcz"``.

    Returns:
        An n-qubit ``QuantumCircuit`` named ``"Q"``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, or an unknown ``synthesis``.
    """
    marks, n = validate_marks(marks)
    circuit = QuantumCircuit(n, name="Q")
    circuit.compose(phase_oracle(marks, synthesis), inplace=True)
    append_state_reflection(circuit, np.pi)
    circuit.global_phase += np.pi
    return circuit


def estimation_problem(marks: np.ndarray, synthesis: str | OracleSynthesis = "auto") -> EstimationProblem:
    """qiskit-algorithms' ``EstimationProblem`` for the marked fraction a = m / N of ``marks``.

    State preparation A = H^n (the paper's W), Grover operator ``grover_iterate(marks)``, all n
    qubits objective qubits, and a bitstring b good when ``marks[int(b, 2)]``.

    Args:
        marks: Boolean (or 0/1) array of length 2^n.
        synthesis: The oracle's synthesis: ``"auto"`` (default), ``"diagonal"`` or ``"mcz"``.

    Returns:
        A ``qiskit_algorithms.EstimationProblem``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, or an unknown ``synthesis``.
    """
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
    to ``AER_NATIVE`` operations (global phases of the definitions are kept).

    Args:
        circuit: Any ``QuantumCircuit``.

    Returns:
        A new circuit on the same qubits and clbits with the same operator.
    """
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


#: the most sampler calls one iterative estimation may make (its own bound is ~log2(pi/(8 eps)) + 1
#: distinct powers; repeats of a power are legitimate, an unbounded number is the library's loop)
MAX_IAE_ROUNDS = 200
METHODS = ("mlae", "iae")


class SeededAerSampler(BaseSamplerV2):
    """qiskit-aer's ``SamplerV2`` with ``shots`` per circuit, a fresh ``seed_simulator`` from
    ``rng`` for every call, and composite gates flattened to Aer-native ones. More than
    ``max_calls`` calls raise a RuntimeError (see the module docstring).

    Args:
        shots: Shots per circuit (default of every call).
        rng: The generator that draws each call's ``seed_simulator``.
        max_calls: The most ``run`` calls allowed, or None for no limit.
    """

    def __init__(self, shots: int, rng: np.random.Generator, max_calls: int | None = None) -> None:
        from qiskit_aer.primitives import SamplerV2

        self._sampler = SamplerV2(default_shots=int(shots))
        self._rng = rng
        self.default_shots = int(shots)
        self.max_calls = max_calls
        self.calls = 0

    def run(self, pubs: Iterable[Any], *, shots: int | None = None) -> PrimitiveJob:
        """Run the pubs on Aer's ``SamplerV2``, flattened, with a fresh ``seed_simulator``.

        Args:
            pubs: Sampler pubs (circuits, or (circuit, parameter values, shots) tuples).
            shots: Shots per pub; None for ``default_shots``.

        Returns:
            Aer's ``PrimitiveJob``.

        Raises:
            RuntimeError: More than ``max_calls`` calls.
        """
        if self.max_calls is not None and self.calls >= self.max_calls:
            raise RuntimeError(f"amplitude estimation made more than {self.max_calls} sampler calls "
                               "(qiskit-algorithms' IterativeAmplitudeEstimation loops forever when a "
                               "round's interval reaches a = 0 on the lower half-circle; use method='mlae' "
                               "or more shots)")
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
    ``library_oracle_queries``: qiskit-algorithms' ``num_oracle_queries`` (= sum shots k).

    Args:
        estimate: The estimate of a = m / N.
        interval: The confidence interval (low, high) on a, at confidence 1 - alpha.
        alpha: The interval's error level.
        powers: k of each sampler round.
        shots: Shots per round.
        oracle_calls: sum over rounds of shots (k + 1), DESIGN §2.
        library_oracle_queries: qiskit-algorithms' count, sum over rounds of shots k.

    Example:
        >>> from qrrt_circuits.search.estimation import AmplitudeEstimate
        >>> estimate = AmplitudeEstimate(estimate=0.25, interval=(0.2, 0.3), alpha=0.05,
        ...                              powers=(0, 1, 2), shots=10, oracle_calls=60,
        ...                              library_oracle_queries=30)
        >>> estimate.marked_count(16), estimate.count_interval(16)
        (4, (3.2, 4.8))
        >>> estimate.calls_per_worker(4)  # 10 shots a round: 3, 3, 2, 2 shots of k + 1 calls
        (18, 18, 12, 12)
    """

    estimate: float
    interval: tuple[float, float]
    alpha: float
    powers: tuple[int, ...]
    shots: int
    oracle_calls: int
    library_oracle_queries: int

    def marked_count(self, num_items: int) -> int:
        """The estimate of m: round(a N), at least 1 (a search for none would be pointless).

        Args:
            num_items: N, the database size.

        Returns:
            max(1, round(a N)).
        """
        return max(1, int(round(self.estimate * num_items)))

    def count_interval(self, num_items: int) -> tuple[float, float]:
        """The confidence interval on m = a N.

        Args:
            num_items: N, the database size.

        Returns:
            (low N, high N).
        """
        return (self.interval[0] * num_items, self.interval[1] * num_items)

    def calls_per_worker(self, workers: int) -> tuple[int, ...]:
        """The estimation's oracle calls when its shots are shared by ``workers`` devices: in each
        sampler round worker w runs shots // p shots (one more for w < shots % p), each costing
        k + 1 calls. Worker 0 carries the largest share, which is the estimation's critical path
        (the rounds are sequential; the shots within one are independent).

        Args:
            workers: p, the devices sharing the shots (>= 1).

        Returns:
            p oracle-call counts, worker 0 first (they sum to ``oracle_calls``).
        """
        calls = [0] * workers
        for k in self.powers:
            base, extra = divmod(self.shots, workers)
            for worker in range(workers):
                calls[worker] += (base + (worker < extra)) * (k + 1)
        return tuple(calls)


def _theta_grid(max_power: int = 0) -> np.ndarray:
    """qiskit-algorithms' MLAE grid: max(10^4, pi/2 10^3 2 max_power) points in (0, pi/2)."""
    eps = 1e-15  # as qiskit-algorithms: keeps log(sin^2) finite at the ends
    return np.linspace(eps, np.pi / 2 - eps, max(10_000, int(np.pi / 2 * 1000 * 2 * max_power)))


def grid_minimizer(objective: Callable[[Any], Any], bounds: Sequence[tuple[float, float]]) -> float:
    """MLAE's minimizer hook: the library's own grid search (``brute`` over 10 000 points, then a
    local polish) evaluated on the whole grid at once (its log-likelihood accepts an array of
    theta), then polished by a bounded scalar minimization between the neighbouring grid points.

    Args:
        objective: The negative log-likelihood of theta, accepting an array of thetas.
        bounds: ((theta_low, theta_high),), the search interval.

    Returns:
        The minimizing theta.
    """
    from scipy.optimize import minimize_scalar

    grid = np.linspace(bounds[0][0], bounds[0][1], 10_000)
    with np.errstate(divide="ignore"):
        values = np.asarray(objective(grid), dtype=float)
    best = int(np.nanargmin(values))
    low, high = grid[max(best - 1, 0)], grid[min(best + 1, grid.size - 1)]
    polished = minimize_scalar(objective, bounds=(low, high), method="bounded")
    return float(polished.x) if polished.fun <= values[best] else float(grid[best])


def log_likelihood(theta: np.ndarray, powers: Sequence[int], good_counts: Sequence[int], shots: int) -> np.ndarray:
    """MLAE's log-likelihood: sum_k good_k log sin^2((2k+1) theta) + bad_k log cos^2((2k+1) theta).

    Suzuki et al. 2020: after k Grover iterates the good probability is sin^2((2k+1) theta)
    with a = sin^2 theta (the paper's Eq. 1 with a = m/N).

    Args:
        theta: Array of angles in (0, pi/2).
        powers: k of each round.
        good_counts: Good outcomes of each round.
        shots: Shots per round.

    Returns:
        The log-likelihood at each theta (-inf where a term's probability is 0).
    """
    total = np.zeros_like(np.asarray(theta, dtype=float))
    with np.errstate(divide="ignore"):
        for k, good in zip(powers, good_counts, strict=True):
            angle = (2 * k + 1) * np.asarray(theta)
            total = total + good * np.log(np.sin(angle) ** 2) + (shots - good) * np.log(np.cos(angle) ** 2)
    return total


def likelihood_ratio_interval(theta_mle: float, powers: Sequence[int], good_counts: Sequence[int], shots: int,
                              alpha: float) -> tuple[float, float]:
    """The likelihood-ratio interval of qiskit-algorithms' MLAE (``kind="likelihood_ratio"``: the
    thetas whose log-likelihood is within chi2_{1-alpha, 1} / 2 of the maximum, outermost ones,
    mapped to a = sin^2 theta), computed on the same grid but vectorized (the library loops over
    10 000 points in Python; tests check the two agree).

    Args:
        theta_mle: The maximum-likelihood theta.
        powers: k of each round.
        good_counts: Good outcomes of each round.
        shots: Shots per round.
        alpha: The error level (confidence 1 - alpha).

    Returns:
        (a_low, a_high).
    """
    from scipy.stats import chi2

    grid = _theta_grid(max(powers))
    values = log_likelihood(grid, powers, good_counts, shots)
    threshold = log_likelihood(np.array([theta_mle]), powers, good_counts, shots)[0] - chi2.ppf(1 - alpha, df=1) / 2
    inside = grid[values >= threshold]
    low, high = (float(inside.min()), float(inside.max())) if inside.size else (0.0, np.pi / 2)
    return float(np.sin(low) ** 2), float(np.sin(high) ** 2)


def estimate_marked_fraction(marks: np.ndarray, *, alpha: float, shots: int, rng: np.random.Generator,
                             method: str = "mlae", schedule: int = 3, epsilon: float = 0.05,
                             synthesis: str | OracleSynthesis = "auto") -> AmplitudeEstimate:
    """Estimate the marked fraction of ``marks`` with confidence 1 - ``alpha`` on a seeded Aer
    ``SamplerV2`` of ``shots`` shots per circuit.

    ``"mlae"``: ``MaximumLikelihoodAmplitudeEstimation`` with the powers [0, 1, 2, ..., 2^(schedule-1)]
    and its likelihood-ratio confidence interval. ``"iae"``: ``IterativeAmplitudeEstimation`` with
    target half-width ``epsilon`` on a and Clopper-Pearson intervals.

    Args:
        marks: Boolean (or 0/1) array of length 2^n.
        alpha: The confidence interval's error level, in (0, 1).
        shots: Shots per sampler round.
        rng: The generator that seeds every sampler call.
        method: ``"mlae"`` (default) or ``"iae"``.
        schedule: MLAE's evaluation schedule: k = 0 and 2^0 .. 2^(schedule-1) (default 3: k = 0, 1, 2,
            4).
        epsilon: IAE's target half-width on a (default 0.05).
        synthesis: The oracle's synthesis: ``"auto"`` (default), ``"diagonal"`` or ``"mcz"``.

    Returns:
        The ``AmplitudeEstimate``, its oracle calls counted as sum shots (k + 1).

    Raises:
        ValueError: An unknown ``method``, ``marks`` not of length 2^n or not boolean, an unknown
            ``synthesis``, or qiskit-algorithms' own refusal of an argument.
        RuntimeError: IAE running more than ``MAX_IAE_ROUNDS`` circuits (its endless loop), or an
            oracle-query count that disagrees with qiskit-algorithms'.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.search.estimation import estimate_marked_fraction
        >>> marks = np.zeros(16, dtype=bool)
        >>> marks[[1, 5, 9, 13]] = True
        >>> estimate = estimate_marked_fraction(marks, alpha=0.05, shots=64,
        ...                                     rng=np.random.default_rng(0))
        >>> estimate.powers, estimate.oracle_calls, estimate.library_oracle_queries
        ((0, 1, 2, 4), 704, 448)
        >>> estimate.marked_count(16)
        4
    """
    from qiskit_algorithms import IterativeAmplitudeEstimation, MaximumLikelihoodAmplitudeEstimation

    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    problem = estimation_problem(marks, synthesis)
    if method == "mlae":
        sampler = SeededAerSampler(shots, rng, max_calls=1)
        algorithm = MaximumLikelihoodAmplitudeEstimation(schedule, sampler=sampler, minimizer=grid_minimizer)
        result = algorithm.estimate(problem)
        powers = tuple(int(k) for k in result.evaluation_schedule)
        interval = likelihood_ratio_interval(result.theta, powers, result.good_counts, shots, alpha)
    else:
        sampler = SeededAerSampler(shots, rng, max_calls=MAX_IAE_ROUNDS)
        algorithm = IterativeAmplitudeEstimation(epsilon_target=epsilon, alpha=alpha, sampler=sampler,
                                                 confint_method="beta")
        result = algorithm.estimate(problem)
        powers = tuple(int(k) for k in result.powers[1:])  # powers[0] = 0 is the prior, not a round
        if len(powers) != sampler.calls:
            raise RuntimeError(f"IterativeAmplitudeEstimation ran {sampler.calls} circuits but reports "
                               f"{len(powers)} powers")
        interval = result.confidence_interval
    queries = int(result.num_oracle_queries)
    if queries != shots * sum(powers):
        raise RuntimeError(f"oracle-call count mismatch: qiskit-algorithms reports {queries}, "
                           f"shots x sum(k) = {shots * sum(powers)}")
    low, high = (float(v) for v in interval)
    return AmplitudeEstimate(float(result.estimation), (low, high), float(alpha), powers, int(shots),
                             shots * sum(k + 1 for k in powers), queries)
