"""The ``qrrt`` command line."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from . import probability
from .search import AerBackend, StatevectorBackend

BACKENDS = {"aer": AerBackend, "statevector": StatevectorBackend}


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text}")
    return value


def _nonnegative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0, got {text}")
    return value


def make_backend(name: str, seed: int | None):
    if name not in BACKENDS:
        raise ValueError(f"--backend must be one of {sorted(BACKENDS)}, got {name!r}")
    return BACKENDS[name](seed=seed)


def cmd_search(args: argparse.Namespace) -> int:
    num_items = 1 << args.qubits
    if args.marked > num_items:
        raise ValueError(f"--marked must be in [0, 2**qubits = {num_items}], got {args.marked}")
    backend = make_backend(args.backend, args.seed)
    backend.check_qubits(args.qubits)
    rng = np.random.default_rng(args.seed)
    marks = np.zeros(num_items, dtype=bool)
    marks[rng.choice(num_items, args.marked, replace=False)] = True
    iterations = (probability.optimal_iterations(num_items, args.marked)
                  if args.iterations is None else args.iterations)
    result = backend.search(marks, iterations, shots=args.shots)
    hits = marks[result.indices]
    rate = float(hits.mean())
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
    print("  index   bitstring        count  marked")
    for j in order:
        index = int(values[j])
        print(f"  {index:5d}   {index:0{args.qubits}b}{'':>{max(16 - args.qubits, 1)}} "
              f"{counts[j]:5d}  {'yes' if marks[index] else 'no'}")
    print("note: the phase oracle is built from a classical lookup of the marks "
          "(a simulation shortcut); m is known here")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="qrrt", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    search = sub.add_parser("search", help="Grover-search a random marked database")
    search.add_argument("--qubits", type=_positive_int, default=8)
    search.add_argument("--marked", type=_nonnegative_int, default=12)
    search.add_argument("--shots", type=_positive_int, default=2000)
    search.add_argument("--iterations", type=_nonnegative_int, default=None,
                        help="Grover iterations (default: optimal for the known m)")
    search.add_argument("--backend", choices=sorted(BACKENDS), default="aer")
    search.add_argument("--seed", type=_nonnegative_int, default=0)
    search.add_argument("--top", type=_positive_int, default=10)
    search.set_defaults(func=cmd_search)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except ValueError as exc:
        parser.exit(2, f"qrrt {args.command}: error: {exc}\n")


if __name__ == "__main__":
    sys.exit(main())
