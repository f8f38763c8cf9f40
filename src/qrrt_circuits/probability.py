"""The paper's probability results for p quantum workers on a shared database (§III.C).

Notation: N = 2^n database entries, m of them marked by the oracle, P(G) the probability that one
worker measures a marked entry after its Grover iterations. With oracle errors, m1 <= m marked
entries are truly good and m2 truly good entries were marked bad.
"""

from __future__ import annotations

import math
from typing import Any

from ._support.validation import check_int, check_probability


def _count(value: Any, name: str, minimum: int = 0) -> int:
    return check_int(value, name, minimum)


def _probability(value: Any, name: str) -> float:
    return check_probability(value, name)


def _marked(num_items: Any, num_marked: Any) -> tuple[int, int]:
    num_items = _count(num_items, "num_items", 1)
    num_marked = _count(num_marked, "num_marked", 0)
    if num_marked > num_items:
        raise ValueError(f"num_marked must be in [0, num_items = {num_items}], got {num_marked}")
    return num_items, num_marked


def harmonic(k: int) -> float:
    """H_k, the sum of 1/i for i = 1 to k (H_0 = 0): the harmonic number of Lemmas 3 and 6.

    Args:
        k: An integer >= 0.

    Returns:
        H_k, summed with ``math.fsum``.

    Raises:
        TypeError: A non-integer k.
        ValueError: k < 0.

    Example:
        >>> from qrrt_circuits.probability import harmonic
        >>> harmonic(3)  # 1 + 1/2 + 1/3
        1.8333333333333333
    """
    return math.fsum(1.0 / i for i in range(1, _count(k, "k") + 1))


def good_probability(num_items: int, num_marked: int, iterations: int) -> float:
    """sin^2((2k+1) theta) with sin^2 theta = m/N, unvalidated (Boyer et al. 1998; the paper's
    Equation 1): the probability that one measurement after k Grover iterations is marked."""
    if num_marked == 0:
        return 0.0
    theta = math.asin(math.sqrt(num_marked / num_items))
    amplitude = math.sin((2 * iterations + 1) * theta)
    return amplitude * amplitude


def success_probability(num_items: int, num_marked: int, iterations: int) -> float:
    """P(G) = sin^2((2k+1) theta), sin^2 theta = m/N (Lemma 1; Boyer et al. 1998).

    Args:
        num_items: N, the database size (>= 1).
        num_marked: m, the marked entries (0 .. N).
        iterations: k, the Grover iterations (>= 0).

    Returns:
        The probability that one measurement after k iterations is a marked entry (0 if m = 0).

    Raises:
        ValueError: N < 1, m outside [0, N] or k < 0.
        TypeError: A non-integer count.
    """
    num_items, num_marked = _marked(num_items, num_marked)
    return good_probability(num_items, num_marked, _count(iterations, "iterations"))


def expected_distinct_found(num_items: int, num_marked: int, iterations: int, workers: int) -> float:
    """E[distinct marked entries measured] when p workers each measure one preparation after k
    iterations of a shared database: m (1 - (1 - P(G) / m)^p).

    After k iterations every marked entry is measured with probability P(G) / m (the proof of
    Lemma 1); a given entry is missed by all p workers with probability (1 - P(G) / m)^p, and the
    expectation sums over the m entries. For p = 1 it is P(G).

    Args:
        num_items: N, the database size (>= 1).
        num_marked: m, the marked entries (0 .. N).
        iterations: k, the Grover iterations (>= 0).
        workers: p, the workers (>= 1).

    Returns:
        The expected number of distinct marked entries found (0 if m = 0).

    Raises:
        ValueError: N < 1, m outside [0, N], k < 0 or p < 1.
        TypeError: A non-integer count.
    """
    num_items, num_marked = _marked(num_items, num_marked)
    workers = _count(workers, "workers", 1)
    if num_marked == 0:
        return 0.0
    found = good_probability(num_items, num_marked, _count(iterations, "iterations"))
    return num_marked * (1.0 - (1.0 - found / num_marked) ** workers)


def optimal_iterations(num_items: int, num_marked: int) -> int:
    """floor(pi / (4 theta)) with sin^2 theta = m/N, and 0 for m = 0 (paper Equation 1, DESIGN §2).

    Args:
        num_items: N, the database size (>= 1).
        num_marked: m, the marked entries (0 .. N).

    Returns:
        The iteration count that maximises P(G) up to the floor (the paper's optimal k).

    Raises:
        ValueError: N < 1 or m outside [0, N].
        TypeError: A non-integer count.
    """
    num_items, num_marked = _marked(num_items, num_marked)
    if num_marked == 0:
        return 0
    theta = math.asin(math.sqrt(num_marked / num_items))
    return int(math.floor(math.pi / (4.0 * theta)))


def prob_all_same(workers: int, num_marked: int, p_good: float) -> float:
    """Lemma 1: P(all p workers measure the same solution) = P(G)^p m^(1-p) (0 if m = 0).

    Args:
        workers: p, independent preparations of one shared database (>= 1).
        num_marked: m, the marked entries (>= 0).
        p_good: P(G), one worker's probability of measuring a marked entry, in [0, 1].

    Returns:
        The probability that all p measurements are the same marked entry.

    Raises:
        ValueError: p < 1, m < 0 or P(G) outside [0, 1].
        TypeError: A non-integer count or a non-numeric probability.
    """
    workers = _count(workers, "workers", 1)
    num_marked = _count(num_marked, "num_marked")
    p_good = _probability(p_good, "p_good")
    if num_marked == 0:
        return 0.0
    return p_good**workers * float(num_marked) ** (1 - workers)


def prob_all_different(workers: int, num_marked: int, p_good: float) -> float:
    """Lemma 2: P(all p workers measure different solutions) = P(G)^p m! / (m^p (m-p)!).

    Stated for m >= p; for p > m it is 0 (pigeonhole), which the formula's (m-p)! cannot say.

    Args:
        workers: p (>= 1).
        num_marked: m (>= 0).
        p_good: P(G) in [0, 1].

    Returns:
        The probability that the p measurements are p distinct marked entries.

    Raises:
        ValueError: p < 1, m < 0 or P(G) outside [0, 1].
        TypeError: A non-integer count or a non-numeric probability.
    """
    workers = _count(workers, "workers", 1)
    num_marked = _count(num_marked, "num_marked")
    p_good = _probability(p_good, "p_good")
    if workers > num_marked:
        return 0.0
    falling = math.prod(range(num_marked - workers + 1, num_marked + 1))  # m! / (m-p)!
    return p_good**workers * falling / float(num_marked) ** workers


def expected_workers_all_found(num_marked: int, p_good: float) -> float:
    """Lemma 3: expected workers (draws) to find all m solutions, E(p) = m H_m / P(G).

    Coupon collection where each draw fails with probability 1 - P(G). Infinite if P(G) = 0 < m.

    Args:
        num_marked: m (>= 0).
        p_good: P(G) in [0, 1].

    Returns:
        The expected number of workers until every marked entry has been measured.

    Raises:
        ValueError: m < 0 or P(G) outside [0, 1].
        TypeError: A non-integer count or a non-numeric probability.
    """
    num_marked = _count(num_marked, "num_marked")
    p_good = _probability(p_good, "p_good")
    if num_marked == 0:
        return 0.0
    if p_good == 0.0:
        return math.inf
    return num_marked * harmonic(num_marked) / p_good


def _error_counts(num_items: Any, num_marked: Any, true_marked: Any, missed_good: Any) -> tuple[int, int, int, int]:
    num_items, num_marked = _marked(num_items, num_marked)
    true_marked = _count(true_marked, "true_marked")
    missed_good = _count(missed_good, "missed_good")
    if true_marked > num_marked:
        raise ValueError(f"true_marked must be in [0, num_marked = {num_marked}], got {true_marked}")
    if missed_good > num_items - num_marked:
        raise ValueError(
            f"missed_good must be in [0, num_items - num_marked = {num_items - num_marked}], "
            f"got {missed_good}"
        )
    return num_items, num_marked, true_marked, missed_good


def prob_true_solution(num_items: int, num_marked: int, true_marked: int, missed_good: int,
                       p_good: float) -> float:
    """Lemma 4: P(G*) = (m1/m) P(G) + (m2/(N-m)) (1 - P(G)), a truly good entry is measured.

    With oracle errors (DESIGN §2, ``OracleErrorModel``) the oracle marks m entries of which m1
    are truly good, and misses m2 truly good entries among the N - m it leaves unmarked. (The
    paper's q = (1 - m1)/m is a typo for (m - m1)/m.)

    Args:
        num_items: N (>= 1).
        num_marked: m, entries the (erroneous) oracle marks (0 .. N).
        true_marked: m1, the truly good entries among them (0 .. m).
        missed_good: m2, truly good entries the oracle leaves unmarked (0 .. N - m).
        p_good: P(G), the probability of measuring a marked entry, in [0, 1].

    Returns:
        P(G*), the probability that one measurement is a truly good entry.

    Raises:
        ValueError: A count outside its range or P(G) outside [0, 1].
        TypeError: A non-integer count or a non-numeric probability.
    """
    n_items, m, m1, m2 = _error_counts(num_items, num_marked, true_marked, missed_good)
    p_good = _probability(p_good, "p_good")
    marked_part = m1 / m * p_good if m else 0.0
    unmarked_part = m2 / (n_items - m) * (1.0 - p_good) if n_items > m else 0.0
    return marked_part + unmarked_part


def prob_all_same_with_errors(workers: int, num_items: int, num_marked: int, true_marked: int,
                              missed_good: int, p_good: float) -> float:
    """Lemma 5: P(all p workers measure the same truly good entry)
    = m1 (P(G)/m)^p + m2 ((1 - P(G))/(N - m))^p.

    Args:
        workers: p (>= 1).
        num_items: N (>= 1).
        num_marked: m (0 .. N).
        true_marked: m1 (0 .. m).
        missed_good: m2 (0 .. N - m).
        p_good: P(G) in [0, 1].

    Returns:
        The probability that all p workers measure one and the same truly good entry.

    Raises:
        ValueError: A count outside its range or P(G) outside [0, 1].
        TypeError: A non-integer count or a non-numeric probability.
    """
    workers = _count(workers, "workers", 1)
    n_items, m, m1, m2 = _error_counts(num_items, num_marked, true_marked, missed_good)
    p_good = _probability(p_good, "p_good")
    marked_part = m1 * (p_good / m) ** workers if m else 0.0
    unmarked_part = m2 * ((1.0 - p_good) / (n_items - m)) ** workers if n_items > m else 0.0
    return marked_part + unmarked_part


def expected_workers_with_errors(num_marked: int, true_marked: int, p_good: float) -> float:
    """Lemma 6: expected workers to find all m1 truly good marked entries,
    E(p*) = m1 H_{m1} / ((m1/m) P(G)) = m H_{m1} / P(G).

    Args:
        num_marked: m (>= 0).
        true_marked: m1 (0 .. m).
        p_good: P(G) in [0, 1].

    Returns:
        The expected number of workers until every truly good marked entry has been measured
        (infinite if P(G) = 0 < m1).

    Raises:
        ValueError: A count outside its range or P(G) outside [0, 1].
        TypeError: A non-integer count or a non-numeric probability.
    """
    num_marked = _count(num_marked, "num_marked")
    true_marked = _count(true_marked, "true_marked")
    if true_marked > num_marked:
        raise ValueError(f"true_marked must be in [0, num_marked = {num_marked}], got {true_marked}")
    p_good = _probability(p_good, "p_good")
    if true_marked == 0:
        return 0.0
    if p_good == 0.0:
        return math.inf
    return true_marked * harmonic(true_marked) / (true_marked / num_marked * p_good)


__all__ = [
    "expected_distinct_found",
    "expected_workers_all_found",
    "expected_workers_with_errors",
    "harmonic",
    "optimal_iterations",
    "prob_all_different",
    "prob_all_same",
    "prob_all_same_with_errors",
    "prob_true_solution",
    "success_probability",
]
