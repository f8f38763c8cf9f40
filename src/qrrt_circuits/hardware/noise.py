"""Device noise for the Grover circuits: depolarizing gate errors after transpiling to a device basis,
and fake IBM devices (calibration snapshots) from ``qiskit-ibm-runtime`` (optional extra ``noise``).

Beyond the paper, which assumes a perfect quantum computer.

**Depolarizing model.** After transpiling ``grover_circuit`` to the basis [cx, rz, sx, x] (IBM's:
``rz`` is a virtual frame change, so it carries no error), every ``sx``/``x`` is followed by the
one-qubit depolarizing channel of parameter p1 and every ``cx`` by the two-qubit channel of
parameter p2: E(rho) = (1 - p) rho + p I / 2^q (qiskit-aer's ``depolarizing_error``).

**White-noise approximation.** If every error scrambled the whole register, the state after the
circuit would be F rho_ideal + (1 - F) I / N with F = (1 - p1)^{n1} (1 - p2)^{n2} (n1, n2 the
noisy one- and two-qubit gate counts), so the success probability of one search would be
P_noisy = F P_ideal + (1 - F) m / N. The noise experiment measures P_noisy exactly (density
matrix) and shows how well this approximation holds.

**Relation to the paper's oracle-error lemmas (Lemmas 4-6).** Lemma 4 gives the probability of a
truly good measurement when the oracle's marks are wrong: with m' = m + f marks of which m are
good, P(G*) = (m / m') P(G; N, m', k). Noise leaves the marks right but mixes the final state, so
the two can be matched only through one number: ``effective_false_positive_rate`` solves
P(G*) = P_noisy for the false-positive rate q = f / (N - m). The match fails on anything else: a
false-positive oracle's wrong answers concentrate on its f wrong marks (every worker finds the same
ones, Lemma 5), noise spreads them over all N - m unmarked entries. ``wrong_answer_collision``
measures this (the probability that two independent wrong answers coincide).
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING

import numpy as np

from .._support.validation import check_choice, check_probability
from ..probability import good_probability
from ..search.requests import validate_iterations, validate_marks

if TYPE_CHECKING:
    from types import ModuleType

    from qiskit import QuantumCircuit
    from qiskit.providers import BackendV2
    from qiskit.transpiler import PassManager
    from qiskit_aer.noise import NoiseModel

#: the device basis of the depolarizing sweep (IBM's pre-Heron basis; rz is virtual and error-free)
DEVICE_BASIS = ("cx", "rz", "sx", "x")
#: the gates that carry the one- and two-qubit errors
NOISY_ONE_QUBIT_GATES = ("sx", "x")
NOISY_TWO_QUBIT_GATES = ("cx",)
#: fake heavy-hex devices looked for in qiskit-ibm-runtime's fake provider, preferred first
FAKE_DEVICES = ("FakeSherbrooke", "FakeBrisbane", "FakeTorino", "FakeFez", "FakeKyiv", "FakeMarrakesh")
EXTRA_HINT = "install the optional extra: pip install 'qrrt-circuits[noise]' (it adds qiskit-ibm-runtime)"


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message says which and how to install it."""


def depolarizing_noise_model(p1: float, p2: float) -> NoiseModel:
    """A ``NoiseModel`` with depolarizing errors p1 on sx/x and p2 on cx (see the module text).

    Args:
        p1: One-qubit depolarizing parameter, in [0, 1].
        p2: Two-qubit depolarizing parameter, in [0, 1].

    Returns:
        A qiskit-aer ``NoiseModel`` on the basis ``DEVICE_BASIS`` (no error added for a zero p).

    Raises:
        TypeError: A non-real probability.
        ValueError: A probability outside [0, 1].

    Example:
        >>> from qrrt_circuits.hardware.noise import depolarizing_noise_model
        >>> sorted(depolarizing_noise_model(0.001, 0.01).noise_instructions)
        ['cx', 'sx', 'x']
    """
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    p1 = check_probability(p1, "p1")
    p2 = check_probability(p2, "p2")
    model = NoiseModel(basis_gates=list(DEVICE_BASIS))
    if p1 > 0:
        model.add_all_qubit_quantum_error(depolarizing_error(p1, 1), list(NOISY_ONE_QUBIT_GATES))
    if p2 > 0:
        model.add_all_qubit_quantum_error(depolarizing_error(p2, 2), list(NOISY_TWO_QUBIT_GATES))
    return model


@functools.lru_cache(maxsize=4)
def device_pass_manager(optimization_level: int = 1) -> PassManager:
    """The one pass manager of the depolarizing sweep: basis [cx, rz, sx, x], all-to-all.

    Args:
        optimization_level: Qiskit's preset level, 0-3 (default 1); ``seed_transpiler=0``.

    Returns:
        A cached ``PassManager``.
    """
    from qiskit.transpiler import generate_preset_pass_manager

    return generate_preset_pass_manager(optimization_level=optimization_level, basis_gates=list(DEVICE_BASIS),
                                        seed_transpiler=0)


def available_fake_device() -> str:
    """The name of the first of ``FAKE_DEVICES`` the installed qiskit-ibm-runtime has.

    Returns:
        A name of ``FAKE_DEVICES``.

    Raises:
        MissingExtraError: qiskit-ibm-runtime is not installed or has none of them.
    """
    provider = _fake_provider()
    for name in FAKE_DEVICES:
        if hasattr(provider, name):
            return name
    raise MissingExtraError(f"qiskit-ibm-runtime's fake provider has none of {FAKE_DEVICES}; "
                            "install a newer qiskit-ibm-runtime")


@functools.lru_cache(maxsize=4)
def fake_device(name: str | None = None) -> BackendV2:
    """A fake IBM device (``BackendV2`` with the calibration snapshot's coupling map, gates and
    errors); ``name`` one of ``FAKE_DEVICES`` (default: the first installed).

    Args:
        name: One of ``FAKE_DEVICES``, or None for ``available_fake_device()``.

    Returns:
        The fake backend (cached per name).

    Raises:
        ValueError: A name not in ``FAKE_DEVICES``.
        MissingExtraError: qiskit-ibm-runtime is not installed or lacks that device.
    """
    provider = _fake_provider()
    name = available_fake_device() if name is None else check_choice(name, "device", FAKE_DEVICES)
    if not hasattr(provider, name):
        raise MissingExtraError(f"the installed qiskit-ibm-runtime has no {name}; choose one of "
                                f"{[n for n in FAKE_DEVICES if hasattr(provider, n)]}")
    return getattr(provider, name)()


def _fake_provider() -> ModuleType:
    try:
        from qiskit_ibm_runtime import fake_provider
    except ImportError as exc:
        raise MissingExtraError(f"qiskit-ibm-runtime is not installed, so no fake IBM device is available: "
                                f"{EXTRA_HINT}") from exc
    return fake_provider


def has_fake_devices() -> bool:
    """Whether a fake IBM device is available (the ``noise`` extra is installed)."""
    try:
        available_fake_device()
    except MissingExtraError:
        return False
    return True


def noisy_gate_counts(circuit: QuantumCircuit) -> tuple[int, int]:
    """(one-qubit, two-qubit) gates of a transpiled circuit that carry an error in the depolarizing
    model (rz, barriers and measurements carry none).

    Args:
        circuit: A circuit transpiled to ``DEVICE_BASIS``.

    Returns:
        (n1, n2): the ``sx``/``x`` and the ``cx`` gate counts.
    """
    ops = circuit.count_ops()
    return (int(sum(ops.get(g, 0) for g in NOISY_ONE_QUBIT_GATES)),
            int(sum(ops.get(g, 0) for g in NOISY_TWO_QUBIT_GATES)))


def white_noise_fidelity(one_qubit_gates: int, two_qubit_gates: int, p1: float, p2: float) -> float:
    """F = (1 - p1)^{n1} (1 - p2)^{n2}: the weight left on the ideal state if every error
    depolarized the whole register.

    Args:
        one_qubit_gates: n1, the noisy one-qubit gates.
        two_qubit_gates: n2, the noisy two-qubit gates.
        p1: One-qubit depolarizing parameter.
        p2: Two-qubit depolarizing parameter.

    Returns:
        F in [0, 1] (unvalidated inputs).

    Example:
        >>> from qrrt_circuits.hardware.noise import white_noise_fidelity
        >>> round(white_noise_fidelity(10, 5, p1=0.001, p2=0.01), 6)  # 0.999^10 0.99^5
        0.941523
    """
    return float((1.0 - p1) ** one_qubit_gates * (1.0 - p2) ** two_qubit_gates)


def white_noise_success(num_items: int, num_marked: int, iterations: int, fidelity: float) -> float:
    """P_noisy = F P_ideal + (1 - F) m / N (the white-noise approximation).

    P_ideal = sin^2((2k+1) theta), sin^2 theta = m/N (the paper's Lemma 1, Eq. 1).

    Args:
        num_items: N.
        num_marked: m.
        iterations: k.
        fidelity: F, the weight on the ideal state (``white_noise_fidelity``).

    Returns:
        The approximate probability of measuring a marked entry (unvalidated inputs).

    Example:
        >>> from qrrt_circuits.hardware.noise import white_noise_success
        >>> round(white_noise_success(8, 1, 2, fidelity=1.0), 6), round(white_noise_success(8, 1, 2, 0.9), 6)
        (0.945312, 0.863281)
    """
    ideal = good_probability(num_items, num_marked, iterations)
    return float(fidelity * ideal + (1.0 - fidelity) * num_marked / num_items)


def transpiled_grover(marks: np.ndarray, iterations: int, measure: bool = False,
                      pass_manager: PassManager | None = None) -> QuantumCircuit:
    """``grover_circuit(marks, iterations)`` through ``pass_manager`` (default ``device_pass_manager()``).

    Args:
        marks: Boolean (or 0/1) array of length 2^n.
        iterations: k, 0 .. ``MAX_ITERATIONS``.
        measure: Whether to measure all qubits (default False).
        pass_manager: A Qiskit ``PassManager``, or None for ``device_pass_manager()``.

    Returns:
        The transpiled circuit.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, or k out of range.
        TypeError: A non-integer k.
    """
    from ..search.circuits import grover_circuit

    marks, _ = validate_marks(marks)
    iterations = validate_iterations(iterations)
    manager = device_pass_manager() if pass_manager is None else pass_manager
    return manager.run(grover_circuit(marks, iterations, measure=measure))


def noisy_index_distribution(compiled: QuantumCircuit, noise_model: NoiseModel, num_qubits: int) -> np.ndarray:
    """Exact probabilities of the n index qubits (virtual order) after the transpiled, unmeasured
    circuit ``compiled`` under ``noise_model``: AerSimulator(method="density_matrix") with
    ``save_probabilities`` on the physical qubits the final layout assigns to the index.

    Args:
        compiled: The transpiled circuit without measurements (``transpiled_grover``).
        noise_model: A qiskit-aer ``NoiseModel`` (or None for the ideal distribution).
        num_qubits: n, the index register's width.

    Returns:
        Float array of 2^n probabilities, index i in Qiskit's little-endian order.

    Raises:
        RuntimeError: The simulation failed.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.hardware.noise import (depolarizing_noise_model, noisy_index_distribution,
        ...                                  transpiled_grover)
        >>> marks = np.array([0, 0, 0, 0, 0, 1, 0, 0], dtype=bool)
        >>> compiled = transpiled_grover(marks, 2)
        >>> ideal = noisy_index_distribution(compiled, None, 3)
        >>> noisy = noisy_index_distribution(compiled, depolarizing_noise_model(0.001, 0.01), 3)
        >>> round(float(ideal[5]), 4), bool(noisy[5] < ideal[5])  # sin^2(5 theta), theta = asin(8^-1/2)
        (0.9453, True)
    """
    from qiskit_aer import AerSimulator

    circuit = compiled.copy()
    layout = compiled.layout
    qubits = list(range(num_qubits)) if layout is None else list(layout.final_index_layout())[:num_qubits]
    circuit.save_probabilities(qubits)
    simulator = AerSimulator(method="density_matrix", noise_model=noise_model, max_parallel_threads=1)
    result = simulator.run(circuit).result()
    if not result.success:
        raise RuntimeError(f"AerSimulator failed: {result.status}")
    return np.asarray(result.data(0)["probabilities"], dtype=float)


def wrong_answer_collision(distribution: np.ndarray, marks: np.ndarray) -> float:
    """The probability that two independent wrong (unmarked) answers are the same entry:
    sum_i p_i^2 / (sum_i p_i)^2 over unmarked i. 1 / (N - m) if wrong answers are uniform; 1 / f if
    they are the f false-positive marks of Lemma 4's erroneous oracle.

    Args:
        distribution: Probabilities of the N indices (``noisy_index_distribution``).
        marks: Boolean (or 0/1) array of length N = 2^n.

    Returns:
        The collision probability, or NaN if the unmarked entries have probability 0.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.hardware.noise import wrong_answer_collision
        >>> marks = np.array([1, 0, 0, 0, 0, 0, 0, 0], dtype=bool)
        >>> round(wrong_answer_collision(np.full(8, 1 / 8), marks), 6)  # uniform: 1 / 7
        0.142857
    """
    marks, _ = validate_marks(marks)
    wrong = np.asarray(distribution, dtype=float)[~marks]
    total = wrong.sum()
    return float((wrong**2).sum() / total**2) if total > 0 else math.nan


def effective_false_positive_rate(num_items: int, num_marked: int, iterations: int,
                                  success_probability: float) -> float:
    """The false-positive rate q of an erroneous oracle (Lemma 4 with no false negatives: m' = m + q (N - m)
    marks, m of them good) whose truly-good probability (m / m') P(G; N, m', k) equals
    ``success_probability`` with the same k; m' is treated as continuous. NaN if no q in [0, 1]
    matches (the ideal probability is already below the target, or noise pushes it below every
    false-positive oracle's).

    Solved by locating the first sign change of the gap on a grid of 4001 values of q in [0, 1],
    refined by linear interpolation.

    Args:
        num_items: N.
        num_marked: m.
        iterations: k.
        success_probability: The measured (noisy) probability of a marked entry, in [0, 1].

    Returns:
        The smallest matching q, or NaN (also for m = 0 or m >= N).

    Raises:
        TypeError: A non-real ``success_probability``.
        ValueError: ``success_probability`` outside [0, 1].

    Example:
        >>> from qrrt_circuits.hardware.noise import effective_false_positive_rate
        >>> round(effective_false_positive_rate(64, 2, 4, success_probability=0.8), 4)
        0.0067
    """
    success_probability = check_probability(success_probability, "success_probability")
    if num_marked <= 0 or num_marked >= num_items:
        return math.nan

    def truly_good(q: float) -> float:
        marked = num_marked + q * (num_items - num_marked)
        theta = math.asin(math.sqrt(marked / num_items))
        return num_marked / marked * math.sin((2 * iterations + 1) * theta) ** 2

    grid = np.linspace(0.0, 1.0, 4001)
    values = np.array([truly_good(q) for q in grid])
    gaps = values - success_probability
    crossing = np.flatnonzero(np.sign(gaps[:-1]) != np.sign(gaps[1:]))
    if gaps[0] == 0:
        return 0.0
    if crossing.size == 0:
        return math.nan
    i = int(crossing[0])  # the smallest q that explains the measured probability
    return float(grid[i] + (grid[i + 1] - grid[i]) * gaps[i] / (gaps[i] - gaps[i + 1]))


__all__ = [
    "DEVICE_BASIS",
    "FAKE_DEVICES",
    "MissingExtraError",
    "available_fake_device",
    "depolarizing_noise_model",
    "device_pass_manager",
    "effective_false_positive_rate",
    "fake_device",
    "has_fake_devices",
    "noisy_gate_counts",
    "noisy_index_distribution",
    "transpiled_grover",
    "white_noise_fidelity",
    "white_noise_success",
    "wrong_answer_collision",
]
