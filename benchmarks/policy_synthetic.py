"""Search policies on a synthetic stream of databases: calls per distinct verified entry against the
best fixed k for the stream's distribution, where that optimum is known in closed form.

Each database of a stream has N = 2^8 entries and m ~ Poisson(lambda) marked ones (capped at N);
p workers search it through the policy's own ``PolicyState.run`` on the exact statevector backend,
and the state learns from the outcomes grouped by database, exactly as a planner's round does. The
stream stops once ``budget`` oracle calls (DESIGN §2) are spent. The figure of merit is the calls
per distinct verified entry (a new node of the tree) over ``runs`` streams, divided by the best
fixed k's expected cost p (k + 1) / D(k), D(k) = E[m (1 - (1 - P_k(m) / m)^p)] (the derivation in
``qrrt_circuits.search.policies.thompson``). Scenarios: sparse databases (lambda 0.5, 1, 5, with
many empty), dense ones (lambda 100), and short streams of dense databases (the open-space case,
where a plan ends after a few tens of calls).

Run: ``python benchmarks/policy_synthetic.py [--runs 20] [--out PATH]``; writes
``benchmarks/results/policy_synthetic.json``.
"""

from __future__ import annotations

import argparse
import math

import numpy as np
from _common import machine, write_json
from scipy.stats import poisson
from tqdm import tqdm

import qrrt_circuits as qc
from qrrt_circuits._support.randomness import RandomStreams
from qrrt_circuits.probability import expected_distinct_found, optimal_iterations

QUBITS = 8
#: (lambda, workers, budget in oracle calls)
SCENARIOS = [(0.5, 1, 3000), (1.0, 1, 3000), (5.0, 1, 3000), (100.0, 1, 3000), (150.0, 1, 30), (30.0, 1, 100),
             (0.5, 8, 24000), (1.0, 8, 24000), (5.0, 8, 24000), (100.0, 8, 24000), (150.0, 8, 240), (30.0, 8, 800)]
POLICIES = {"thompson": qc.ThompsonIterations(),
            "thompson log-uniform prior": qc.ThompsonIterations(prior="log-uniform"),
            "adaptive": qc.Adaptive(), "paper": qc.PaperIterations(), "bbht": qc.BBHT()}


def best_fixed_cost(lam: float, workers: int, num_items: int) -> float:
    """min over k of p (k + 1) / D(k) for m ~ Poisson(lambda) capped at N (module docstring)."""
    marked = np.arange(num_items + 1)
    weights = poisson.pmf(marked, lam)
    weights[-1] += poisson.sf(num_items, lam)
    costs = []
    for k in range(optimal_iterations(num_items, 1) + 1):
        distinct = np.array([expected_distinct_found(num_items, int(m), k, workers) for m in marked])
        costs.append(workers * (k + 1) / float(np.sum(weights * distinct)))
    return min(costs)


def stream_cost(policy: qc.IterationPolicy, lam: float, workers: int, budget: int, seed: int) -> float:
    """Calls per distinct verified entry of one stream of databases (inf if none was found)."""
    num_items = 1 << QUBITS
    rng = np.random.default_rng([seed, 1])
    streams = RandomStreams(seed)
    backend = qc.StatevectorBackend(seed=seed)
    state = policy.start(num_items)
    spent = found = 0
    index = 0
    while spent < budget:
        marks = np.zeros(num_items, dtype=bool)
        marks[rng.choice(num_items, min(int(rng.poisson(lam)), num_items), replace=False)] = True
        problem = qc.DatabaseSearch(qc.LookupOracle(marks), marks, backend, streams, index)
        outcomes = state.run(problem, workers, tree_nodes=index)
        state.learn([outcomes])
        spent += sum(o.oracle_calls for o in outcomes)
        found += len({o.index for o in outcomes if o.index is not None})
        index += 1
    return spent / found if found else math.inf


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20, help="streams per scenario and policy (default 20)")
    parser.add_argument("--out", default=None, help="output JSON (default benchmarks/results/policy_synthetic.json)")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error(f"--runs must be >= 1, got {args.runs}")
    results = []
    for lam, workers, budget in tqdm(SCENARIOS, desc="scenarios"):
        best = best_fixed_cost(lam, workers, 1 << QUBITS)
        row = {"lambda": lam, "workers": workers, "budget": budget, "best_fixed_k_cost": round(best, 4),
               "ratio_to_best_fixed_k": {}}
        for name, policy in POLICIES.items():
            costs = [stream_cost(policy, lam, workers, budget, seed) for seed in range(args.runs)]
            finite = [c for c in costs if math.isfinite(c)]
            row["ratio_to_best_fixed_k"][name] = round(float(np.mean(finite)) / best, 4) if finite else None
        results.append(row)
    worst = {name: max((r["ratio_to_best_fixed_k"][name] or math.inf) for r in results) for name in POLICIES}
    path = write_json("policy_synthetic", {
        "what": "calls per distinct verified entry over the best fixed k's expected cost, mean over streams",
        "runs": args.runs, "qubits": QUBITS, "policies": {n: p.describe() for n, p in POLICIES.items()},
        "scenarios": results, "worst_ratio": worst, "machine": machine()}, args.out)
    print(f"wrote {path}")
    for name, value in worst.items():
        print(f"  {name}: worst ratio {value:.2f}")


if __name__ == "__main__":
    main()
