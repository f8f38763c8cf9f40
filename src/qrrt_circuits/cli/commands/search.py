"""``qrrt search``: Grover-search a random marked database and list what was measured."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from ..._support.memory import MemoryEstimate
    from ...search.backends.base import QuantumSearchBackend, SearchResult



def cmd_search(args: argparse.Namespace) -> int:
    from ... import probability
    from ...registry import BACKENDS

    backend = BACKENDS.create(args.backend, seed=args.seed)
    backend.check_qubits(args.qubits)  # before 2**qubits is computed (a huge --qubits is refused, not allocated)
    num_items = 1 << args.qubits
    if args.marked > num_items:
        raise ValueError(f"--marked must be in [0, 2**qubits = {num_items}], got {args.marked}")
    iterations = (probability.optimal_iterations(num_items, args.marked)
                  if args.iterations is None else args.iterations)
    from ..._support.memory import OutOfMemory, check_fits, out_of_memory
    from ...search.backends.base import validate_iterations, validate_shots

    shots = validate_shots(args.shots)
    estimate = _search_estimate(backend, shots, validate_iterations(iterations), args.marked)
    what = f"this {backend.name} search ({shots} shots, {iterations} iterations, {args.marked} marked)"
    check_fits(estimate, args.qubits, what)  # the command's one memory check, before the marks exist
    try:
        marks, result = _run_search(args, backend, num_items, iterations)
    except OutOfMemory:
        raise
    except MemoryError as error:
        raise out_of_memory(error, estimate, args.qubits, what) from error
    _print_search(args, marks, iterations, result)
    return 0


def _run_search(args: argparse.Namespace, backend: QuantumSearchBackend, num_items: int,
                iterations: int) -> tuple[np.ndarray, SearchResult]:
    """The marks (``--marked`` entries drawn with ``--seed``) and their search, which the
    command's own memory check covered."""
    import numpy as np

    rng = np.random.default_rng(args.seed)
    marks = np.zeros(num_items, dtype=bool)
    marks[rng.choice(num_items, args.marked, replace=False)] = True
    from ...search.oracles import LookupOracle

    return marks, backend.run(LookupOracle(marks), iterations, shots=args.shots)


#: the marks (1 byte per entry) and numpy's draw of the marked entries (a permutation, 8 bytes)
SEARCH_MARKS_BYTES_PER_ENTRY = 9


def _search_estimate(backend: QuantumSearchBackend, shots: int, iterations: int,
                     marked: int) -> Callable[[int], MemoryEstimate]:
    """``qrrt search``'s peak as a function of n: the marks and the search of ``marked`` entries
    (the backend's ``peak_bytes``)."""
    from ..._support.memory import MemoryEstimate

    def estimate(n: int) -> MemoryEstimate:
        return MemoryEstimate(n, resident_bytes=SEARCH_MARKS_BYTES_PER_ENTRY << n,
                              search_bytes=backend.peak_bytes(n, shots, iterations, marked), scratch_bytes=0)

    return estimate


def _print_search(args: argparse.Namespace, marks: np.ndarray, iterations: int, result: SearchResult) -> None:
    import numpy as np

    from ... import probability

    num_items = marks.shape[0]
    rate = float(marks[result.indices].mean())
    theory = probability.success_probability(num_items, args.marked, iterations)
    sigma = math.sqrt(max(theory * (1 - theory), 1e-300) / args.shots)
    print(f"Grover search on {args.backend}: n = {args.qubits} qubits (N = {num_items}), "
          f"m = {args.marked} marked, k = {iterations} iterations"
          f"{' (optimal for the known m)' if args.iterations is None else ''}, "
          f"{args.shots} shots, seed {args.seed}")
    print(f"success rate      {rate:.4f}")
    print(f"sin^2((2k+1)th)   {theory:.4f}   (binomial sigma {sigma:.4f}, "
          f"deviation {(rate - theory) / sigma if sigma > 0 else 0.0:+.2f} sigma)")
    print(f"oracle calls      {result.oracle_calls}  (= k x shots)")
    values, counts = np.unique(result.indices, return_counts=True)
    order = np.argsort(-counts, kind="stable")[: args.top]
    print(f"top {len(order)} measured indices:")
    width = max(5, len(str(num_items - 1)))  # the widest index
    bits = max(args.qubits, len("bitstring"))
    print(f"  {'index':>{width}}   {'bitstring':<{bits}}  count  marked")
    for j in order:
        index = int(values[j])
        print(f"  {index:{width}d}   {index:0{args.qubits}b}{'':<{bits - args.qubits}}  "
              f"{counts[j]:5d}  {'yes' if marks[index] else 'no'}")
    print("note: the phase oracle is built from a classical lookup of the marks "
          "(a simulation shortcut); m is known here")
