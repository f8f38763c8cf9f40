"""Fixed-point amplitude amplification (Yoder, Low and Chuang, PRL 113, 210501, 2014): phases,
success probability and the generalized Grover circuits that apply them.

Generalized Grover iterate (Yoder et al., Eq. 1 and the text around it)::

    G(alpha, beta) = -S_s(alpha) S_t(beta),
    S_t(beta)  = I - (1 - e^{+i beta})  |T><T|    (phase oracle diag(e^{i beta marks}))
    S_s(alpha) = I - (1 - e^{-i alpha}) |s><s|    (|s> = H^n |0>, the uniform state)

With alpha = beta = pi, G is the standard Grover iterate (oracle, then inversion about the mean).
The sequence applies G(alpha_1, beta_1) first and G(alpha_l, beta_l) last to |s>. For a target
error delta and L = 2l + 1, the paper's closed form is::

    1 / gamma = T_{1/L}(1 / delta),
    alpha_j = -beta_{l - j + 1} = 2 cot^{-1}( tan(2 pi j / L) sqrt(1 - gamma^2) ),   j = 1..l

and the probability of measuring a marked index, for a marked fraction f = m / N, is::

    P_L(f) = 1 - delta^2 T_L( T_{1/L}(1/delta) sqrt(1 - f) )^2,

which is >= 1 - delta^2 for every f >= w whenever sqrt(1 - w) T_{1/L}(1/delta) <= 1, i.e.
w >= 1 - gamma^2 (|T_L| <= 1 on [-1, 1]). The paper's sufficient length is
L >= log(2 / delta) / sqrt(w) (``length_rule="paper"``); ``"tight"`` takes the smallest L with
1 - gamma^2 <= w, which carries the same guarantee with fewer queries. The sign conventions
matter: flipping the sign of alpha or of beta alone breaks P_L (the tests compare the exact
evolution with P_L).

Counting (DESIGN §2): each iterate queries the oracle once, so a sequence of l iterates costs l
quantum oracle calls per preparation; the paper's L = 2l + 1 counts the applications of the state
preparation H^n (and its inverse), exactly as k Grover iterations reach sin^2((2k + 1) theta).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._support.validation import check_float, check_int
from .requests import MAX_ITERATIONS, validate_marks
from .synthesis import OracleSynthesis

if TYPE_CHECKING:
    from qiskit import QuantumCircuit

LENGTH_RULES = ("paper", "tight")


def chebyshev(order: float, x: float) -> float:
    """T_order(x) = cos(order acos x) on [-1, 1] and cosh(order acosh x) for x > 1 (real order).

    The Chebyshev polynomial of Yoder et al.'s closed form (its order 1/L is not an integer).

    Args:
        order: The order (any real number).
        x: The argument, >= -1.

    Returns:
        T_order(x).

    Raises:
        ValueError: x < -1.

    Example:
        >>> from qrrt_circuits.search.iterate_sequence import chebyshev
        >>> round(chebyshev(2, 0.5), 6)  # T_2(x) = 2 x^2 - 1
        -0.5
    """
    if abs(x) <= 1.0:
        return math.cos(order * math.acos(x))
    if x > 1.0:
        return math.cosh(order * math.acosh(x))
    raise ValueError(f"chebyshev is used here for x > -1 only, got x = {x}")


def gamma(delta: float, length: int) -> float:
    """gamma with 1 / gamma = T_{1/L}(1 / delta) (Yoder et al.).

    Args:
        delta: The target error, in (0, 1) (unvalidated).
        length: L = 2l + 1, the sequence's length.

    Returns:
        gamma in (0, 1].
    """
    return 1.0 / chebyshev(1.0 / length, 1.0 / delta)


def check_delta(delta: Any) -> float:
    """The target error delta in (0, 1) (delta = 1 would promise nothing).

    Args:
        delta: The value to check.

    Returns:
        ``delta`` as a float.

    Raises:
        TypeError: A non-real ``delta``.
        ValueError: ``delta`` not in (0, 1).
    """
    value = check_float(delta, "delta", 0.0, 1.0, open_minimum=True)
    if value == 1.0:
        raise ValueError("delta must be in (0, 1) (the guarantee is P >= 1 - delta^2), got 1.0")
    return value


def check_fraction(fraction: Any, name: str = "min_fraction") -> float:
    """A marked fraction w in (0, 1].

    Args:
        fraction: The value to check.
        name: The argument's name for the error message.

    Returns:
        ``fraction`` as a float.

    Raises:
        TypeError: A non-real ``fraction``.
        ValueError: ``fraction`` not in (0, 1].
    """
    return check_float(fraction, name, 0.0, 1.0, open_minimum=True)


def fixed_point_iterates(delta: float, min_fraction: float, length_rule: str = "paper") -> int:
    """The number l of generalized iterates (oracle calls) for error ``delta`` and marked fraction
    >= ``min_fraction``: the smallest l with L = 2l + 1 >= log(2/delta)/sqrt(w) (``"paper"``), or the
    smallest with 1 - gamma(L)^2 <= w (``"tight"``; never larger than the paper's; searched up to
    ``MAX_ITERATIONS``, beyond which it is the paper's l).

    Args:
        delta: The target error delta in (0, 1): P >= 1 - delta^2 for every fraction >= w.
        min_fraction: w, the smallest marked fraction m/N the guarantee must cover, in (0, 1].
        length_rule: ``"paper"`` (default) or ``"tight"``.

    Returns:
        l >= 0.

    Raises:
        TypeError: A non-real ``delta`` or ``min_fraction``.
        ValueError: ``delta`` not in (0, 1), ``min_fraction`` not in (0, 1], or an unknown
            ``length_rule``.

    Example:
        >>> from qrrt_circuits.search.iterate_sequence import fixed_point_iterates
        >>> fixed_point_iterates(0.5, 0.05)
        3
    """
    delta = check_delta(delta)
    w = check_fraction(min_fraction)
    if length_rule not in LENGTH_RULES:
        raise ValueError(f"length_rule must be one of {LENGTH_RULES}, got {length_rule!r}")
    bound = math.log(2.0 / delta) / math.sqrt(w)
    paper = max(0, math.ceil((bound - 1.0) / 2.0))
    if length_rule == "paper":
        return paper
    for iterates in range(min(paper, MAX_ITERATIONS) + 1):  # (no search runs more than MAX_ITERATIONS)
        if 1.0 - gamma(delta, 2 * iterates + 1) ** 2 <= w:
            return iterates
    return paper


def fixed_point_phases(delta: float, iterates: int) -> tuple[np.ndarray, np.ndarray]:
    """(alphas, betas) of length l for error ``delta`` (Yoder et al.'s closed form).

    alpha_j = -beta_{l-j+1} = 2 cot^{-1}(tan(2 pi j / L) sqrt(1 - gamma^2)), L = 2l + 1.

    Args:
        delta: The target error, in (0, 1).
        iterates: l, 0 .. ``MAX_ITERATIONS``.

    Returns:
        Two float arrays of length l: the alphas and the betas.

    Raises:
        TypeError: A non-real ``delta`` or a non-integer ``iterates``.
        ValueError: ``delta`` not in (0, 1) or ``iterates`` out of range.
    """
    delta = check_delta(delta)
    iterates = check_int(iterates, "iterates", 0, MAX_ITERATIONS)
    length = 2 * iterates + 1
    root = math.sqrt(max(0.0, 1.0 - gamma(delta, length) ** 2))
    j = np.arange(1, iterates + 1)
    # cot^{-1}(x) = atan2(1, x); another branch changes alpha by 2 pi (the same phase e^{i alpha})
    alphas = 2.0 * np.arctan2(1.0, np.tan(2.0 * np.pi * j / length) * root)
    betas = -alphas[::-1]
    return alphas, betas


def fixed_point_success_probability(delta: float, iterates: int, fraction: float) -> float:
    """P_L(f) = 1 - delta^2 T_L(T_{1/L}(1/delta) sqrt(1 - f))^2, L = 2l + 1 (Yoder et al.).

    Args:
        delta: The target error, in (0, 1).
        iterates: l, 0 .. ``MAX_ITERATIONS``.
        fraction: f = m/N, the marked fraction, in [0, 1].

    Returns:
        The probability of measuring a marked index after the l iterates.

    Raises:
        TypeError: A non-real ``delta`` or ``fraction``, or a non-integer ``iterates``.
        ValueError: ``delta`` not in (0, 1), ``fraction`` not in [0, 1] or ``iterates`` out of
            range.

    Example:
        >>> from qrrt_circuits.search.iterate_sequence import fixed_point_success_probability
        >>> round(fixed_point_success_probability(0.5, 3, 0.05), 4)  # >= 1 - 0.5^2
        0.9003
    """
    delta = check_delta(delta)
    fraction = check_float(fraction, "fraction", 0.0, 1.0)
    length = 2 * check_int(iterates, "iterates", 0, MAX_ITERATIONS) + 1
    x = chebyshev(1.0 / length, 1.0 / delta) * math.sqrt(1.0 - fraction)
    return 1.0 - delta**2 * chebyshev(length, x) ** 2


@dataclass(frozen=True, eq=False)
class IterateSequence:
    """Generalized Grover iterates G(alpha_j, beta_j), applied to ``|s>`` in order j = 1, 2, ...

    G(alpha, beta) = -S_s(alpha) S_t(beta) (Yoder, Low and Chuang 2014, Eq. 1); alpha = beta = pi
    is the standard Grover iterate of the paper's Alg. 2 / 3. ``oracle_calls`` = l per preparation
    (one phase oracle per iterate, DESIGN §2).

    Args:
        alphas: The l state-reflection phases (finite; stored as a read-only float array).
        betas: The l oracle phases, the same length (finite).

    Raises:
        ValueError: ``alphas`` and ``betas`` of different lengths, more than ``MAX_ITERATIONS``
            iterates, or a non-finite phase.

    Example:
        >>> from qrrt_circuits import IterateSequence
        >>> grover = IterateSequence.grover(1)
        >>> grover.oracle_calls, round(grover.good_probability(0.25), 6)  # sin^2(3 theta) = 1
        (1, 1.0)
        >>> fixed = IterateSequence.fixed_point(delta=0.5, iterates=3)
        >>> all(fixed.good_probability(f) >= 0.75 for f in (0.05, 0.3, 0.9))
        True
    """

    alphas: np.ndarray
    betas: np.ndarray

    def __post_init__(self) -> None:
        alphas = np.array(self.alphas, dtype=float).reshape(-1)
        betas = np.array(self.betas, dtype=float).reshape(-1)
        if alphas.shape != betas.shape:
            raise ValueError(f"alphas and betas must have the same length, got {alphas.size} and {betas.size}")
        if alphas.size > MAX_ITERATIONS:
            raise ValueError(f"an iterate sequence has at most {MAX_ITERATIONS} iterates, got {alphas.size}")
        if not (np.all(np.isfinite(alphas)) and np.all(np.isfinite(betas))):
            raise ValueError("alphas and betas must be finite")
        alphas.setflags(write=False)
        betas.setflags(write=False)
        object.__setattr__(self, "alphas", alphas)
        object.__setattr__(self, "betas", betas)

    @classmethod
    def grover(cls, iterations: int) -> IterateSequence:
        """k standard Grover iterations: alpha = beta = pi.

        Args:
            iterations: k, 0 .. ``MAX_ITERATIONS``.

        Returns:
            The sequence of k standard iterates.

        Raises:
            TypeError: A non-integer k.
            ValueError: k out of range.
        """
        k = check_int(iterations, "iterations", 0, MAX_ITERATIONS)
        return cls(np.full(k, math.pi), np.full(k, math.pi))

    @classmethod
    def fixed_point(cls, delta: float, iterates: int) -> IterateSequence:
        """Yoder et al.'s fixed-point sequence of l iterates for error delta (``fixed_point_phases``).

        Args:
            delta: The target error, in (0, 1).
            iterates: l, 0 .. ``MAX_ITERATIONS``.

        Returns:
            The sequence; P >= 1 - delta^2 for every marked fraction >= 1 - gamma^2.

        Raises:
            TypeError: A non-real ``delta`` or a non-integer ``iterates``.
            ValueError: ``delta`` not in (0, 1) or ``iterates`` out of range.
        """
        return cls(*fixed_point_phases(delta, iterates))

    @property
    def oracle_calls(self) -> int:
        """l: oracle calls of one preparation (one per iterate)."""
        return int(self.alphas.size)

    def __len__(self) -> int:
        return int(self.alphas.size)

    def key(self) -> bytes:
        """Hashable identity (for caches of compiled circuits)."""
        return self.alphas.tobytes() + b"|" + self.betas.tobytes()

    def marked_amplitude(self, fraction: float) -> tuple[complex, complex]:
        """(amplitude on the normalized marked state, on the unmarked one) after the sequence, for
        marked fraction ``fraction``: the exact 2-dimensional evolution (every operator keeps the
        span of ``|T>`` and ``|s>``).

        Args:
            fraction: f = m/N, in [0, 1].

        Returns:
            (a_T, a_U): the amplitudes on the normalized marked and unmarked states.

        Raises:
            TypeError: A non-real ``fraction``.
            ValueError: ``fraction`` not in [0, 1].
        """
        f = check_float(fraction, "fraction", 0.0, 1.0)
        s = np.array([math.sqrt(f), math.sqrt(1.0 - f)], dtype=complex)
        psi = s.copy()
        for alpha, beta in zip(self.alphas, self.betas, strict=True):
            psi[0] *= np.exp(1j * beta)
            psi = -(psi - (1.0 - np.exp(-1j * alpha)) * s * np.vdot(s, psi))
        return complex(psi[0]), complex(psi[1])

    def good_probability(self, fraction: float) -> float:
        """Probability of measuring a marked index after the sequence (exact): ``|a_T|^2``.

        Args:
            fraction: f = m/N, in [0, 1].

        Returns:
            The probability, in [0, 1].

        Raises:
            TypeError: A non-real ``fraction``.
            ValueError: ``fraction`` not in [0, 1].
        """
        return float(abs(self.marked_amplitude(fraction)[0]) ** 2)


def statevector_after(marks: np.ndarray, sequence: IterateSequence) -> np.ndarray:
    """The full 2^n-dimensional statevector after ``sequence``, iterated operator by operator
    (O(N) per iterate): S_t(beta) multiplies marked amplitudes by e^{i beta}, S_s(alpha) subtracts
    (1 - e^{-i alpha}) <s|psi> |s>, then the sign of G.

    Args:
        marks: Boolean (or 0/1) array of length 2^n.
        sequence: The ``IterateSequence``.

    Returns:
        Complex array of length 2^n.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean.
    """
    marks, _ = validate_marks(marks)
    size = marks.shape[0]
    state = np.full(size, 1.0 / math.sqrt(size), dtype=complex)
    for alpha, beta in zip(sequence.alphas, sequence.betas, strict=True):
        state[marks] *= np.exp(1j * beta)
        overlap = state.sum() / math.sqrt(size)
        state = -(state - (1.0 - np.exp(-1j * alpha)) * overlap / math.sqrt(size))
    return state


# ----------------------------------------------------------------------------------------- circuits
def phase_oracle_beta(marks: np.ndarray, beta: float, synthesis: str | OracleSynthesis = "diagonal") -> QuantumCircuit:
    """S_t(beta) = diag(e^{i beta marks}) on n qubits. ``"diagonal"``: one ``DiagonalGate``;
    ``"mcz"``: one multi-controlled phase(beta) per marked index, conjugated by X on its zero bits
    (``"auto"`` picks the cheaper as ``circuits.choose_synthesis`` does).

    Args:
        marks: Boolean (or 0/1) array of length 2^n.
        beta: The phase beta.
        synthesis: ``"diagonal"`` (default), ``"mcz"`` or ``"auto"``.

    Returns:
        An n-qubit ``QuantumCircuit``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, or an unknown ``synthesis``.
    """
    from .circuits import _flip, choose_synthesis

    marks, n = validate_marks(marks)
    synthesis = OracleSynthesis.parse(synthesis)
    if synthesis is OracleSynthesis.AUTO:
        synthesis = choose_synthesis(marks)
    from qiskit import QuantumCircuit
    from qiskit.circuit.library import DiagonalGate

    circuit = QuantumCircuit(n, name=f"oracle({beta:.3f})")
    if synthesis is OracleSynthesis.DIAGONAL:
        circuit.append(DiagonalGate(np.where(marks, np.exp(1j * beta), 1.0).tolist()), range(n))
        return circuit
    full = (1 << n) - 1
    flipped = 0
    for index in np.flatnonzero(marks):
        wanted = ~int(index) & full
        _flip(circuit, flipped ^ wanted)
        flipped = wanted
        _mcphase(circuit, beta, n)
    _flip(circuit, flipped)
    return circuit


def _mcphase(circuit: QuantumCircuit, angle: float, n: int) -> None:
    """Phase e^{i angle} on |1...1> (an MCPhase, which Aer runs natively)."""
    if n == 1:
        circuit.p(angle, 0)
    else:
        circuit.mcp(angle, list(range(n - 1)), n - 1)


def append_state_reflection(circuit: QuantumCircuit, alpha: float) -> None:
    """S_s(alpha) = I - (1 - e^{-i alpha}) |s><s| = H^n X^n MCPhase(-alpha) X^n H^n: the phase
    e^{-i alpha} on |1...1> is the phase on |s> once conjugated by X^n H^n.

    Args:
        circuit: The circuit to append to, on all its qubits (modified in place).
        alpha: The phase alpha.
    """
    qubits = list(range(circuit.num_qubits))
    circuit.h(qubits)
    circuit.x(qubits)
    _mcphase(circuit, -alpha, circuit.num_qubits)
    circuit.x(qubits)
    circuit.h(qubits)


def generalized_grover_circuit(marks: np.ndarray, sequence: IterateSequence, measure: bool = True,
                               synthesis: str | OracleSynthesis = "auto") -> QuantumCircuit:
    """H^n |0>, then G(alpha_j, beta_j) = -S_s(alpha_j) S_t(beta_j) for j = 1..l, from gates Aer runs
    natively (h, x, diagonal, mcphase); the sign of each G is the circuit's global phase, so the
    circuit's operator equals the product of the G's times H^n exactly. Measured into ``meas``.

    Args:
        marks: Boolean (or 0/1) array of length 2^n.
        sequence: The ``IterateSequence`` to apply.
        measure: Whether to measure all qubits (default True).
        synthesis: The oracles' synthesis: ``"auto"`` (default), ``"diagonal"`` or ``"mcz"``.

    Returns:
        An n-qubit ``QuantumCircuit``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, or an unknown ``synthesis``.
        TypeError: ``sequence`` not an ``IterateSequence``.
    """
    marks, n = validate_marks(marks)
    if not isinstance(sequence, IterateSequence):
        raise TypeError(f"sequence must be an IterateSequence, got {type(sequence).__name__}")
    from qiskit import QuantumCircuit

    circuit = QuantumCircuit(n, name="fixed_point")
    circuit.h(range(n))
    for alpha, beta in zip(sequence.alphas, sequence.betas, strict=True):
        oracle = phase_oracle_beta(marks, float(beta), synthesis)
        circuit.compose(oracle, inplace=True)
        append_state_reflection(circuit, float(alpha))
        circuit.global_phase += math.pi
    if measure:
        circuit.measure_all()
    return circuit
