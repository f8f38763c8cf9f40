"""The coherent oracle (``qrrt_circuits.coherent``): the largest instance verified exhaustively,
Toffolis against the lookup oracle up to n = 30 and B = 1000, and Grover on Aer.

    python benchmarks/bench_coherent_oracle.py [--quick] [--out FILE]

Sections (each instance from ``coherent.costs.scaling_instance``: the paper's clutter world
``paper_clutter(seed=0, num_boxes=B)`` on [0, 20]^2, a tree of 2^m nodes uniform over its free
space, (n - m) / 2 cell bits per axis, b-bit coordinates covering the world, the paper's dynamics
at K time samples with f = b fraction bits):

1. ``exhaustive``: ``verify_oracle`` (build, read the circuit back, simulate it on all 2^n index
   states, compare with ``reachable_reference``) for n = 8, 10, ... (m = 2, b = 12, K = 8, B = 20),
   until one takes more than ``EXHAUSTIVE_BUDGET_S`` or n reaches ``EXHAUSTIVE_MAX_BITS``; the
   largest that passed is ``figures.exhaustive_max_index_bits``.
2. ``costs``: qubits and Toffolis of one oracle call for n = 10 .. 30 and B = 10, 100, 1000
   (m = 6, b = f = 16, K = 16), counted in closed form (``oracle_costs``), against the lookup
   oracle over the 2^n marks (unary-iteration QROM and Qualtran's select-swap, load and unload).
   ``ands`` counts Toffolis with measurement-based uncomputation (an AND's undo costs none),
   ``toffolis`` every CCX. Then the optimizations at n = 30, B = 1000 (each switched off alone),
   the comparisons against Qiskit's comparator, and at one buildable size the closed form checked
   against the built circuit and the Toffoli depth of the built circuit.
3. ``grover``: Grover search with the coherent oracle on Aer's ``matrix_product_state`` method
   (index register in the middle of the chain, ``coherent_grover_circuit(index_in_middle=True)``),
   in a corridor world (``corridor``: [0, 20]^2 less two boxes, free for 7 < y < 13; two tree nodes
   in the corridor; b = f = max(6, a + 1), K = 4, the paper's dynamics), n = 5, 7, 9, ... (m = 1,
   a = (n - 1) / 2 cell bits per axis), k = ``optimal_iterations(2^n, m)``, 64 shots,
   one transpile per circuit: the wall time of one search (``AerSimulator.run`` of that circuit,
   the shots sampled from one evolution; Aer's default threads) and the marked share against
   sin^2((2k+1) theta). Each search runs in a child process, stopped past ``GROVER_BUDGET_S``
   (plus two minutes for its build); the sizes stop at the first search past the budget.

Prints a table and writes JSON with a flat ``figures`` object.
"""

from __future__ import annotations

import argparse
import math
import multiprocessing
import time

import numpy as np
from _common import machine, write_json

from qrrt_circuits import Environment, LinearTrackingDynamics
from qrrt_circuits.coherent import (
    FixedPointFormat,
    LatticeDatabase,
    OracleOptions,
    SampledMotion,
    build_coherent_oracle,
    coherent_grover_circuit,
    lookup_costs,
    oracle_costs,
    oracle_plan,
    reachable_reference,
    verify_oracle,
)
from qrrt_circuits.coherent.costs import comparison_costs, scaling_instance, toffoli_depth
from qrrt_circuits.probability import optimal_iterations

EXHAUSTIVE_BUDGET_S = 120.0
EXHAUSTIVE_MAX_BITS = 24
GROVER_BUDGET_S = 300.0
BASIS = ["x", "z", "h", "cx", "ccx", "u", "p", "measure"]


def exhaustive(quick: bool) -> list[dict]:
    rows = []
    print(f"{'n':>3s} {'qubits':>7s} {'gates':>9s} {'marked':>9s} {'seconds':>8s} ok")
    for n in range(8, (14 if quick else EXHAUSTIVE_MAX_BITS) + 1, 2):
        env, database, motion = scaling_instance(n, 20, parent_bits=2, bits=12, time_samples=8)
        start = time.perf_counter()
        result = verify_oracle(env, database, motion)
        seconds = time.perf_counter() - start
        rows.append({"index_bits": n, "qubits": result.qubits, "gates": result.gates, "marked": result.marked,
                     "seconds": seconds, "ok": result.ok, "mismatches": result.mismatches,
                     "ancillas_clean": result.ancillas_clean, "other_toffolis": result.other_toffolis})
        print(f"{n:3d} {result.qubits:7d} {result.gates:9d} {result.marked:9d} {seconds:8.1f} {result.ok}")
        if not result.ok or seconds > EXHAUSTIVE_BUDGET_S:
            break
    return rows


def costs(quick: bool) -> tuple[list[dict], dict]:
    rows = []
    sizes = (10, 20, 30) if quick else (10, 14, 18, 22, 26, 30)
    print(f"\n{'n':>3s} {'B':>5s} {'qubits':>7s} {'ands':>10s} {'toffolis':>10s} {'lookup qrom':>12s} "
          f"{'select-swap':>12s} {'count s':>8s}")
    for n in sizes:
        lookup = lookup_costs(n)
        for boxes in (10, 100, 1000):
            env, database, motion = scaling_instance(n, boxes)
            start = time.perf_counter()
            cost = oracle_costs(env, database, motion)
            seconds = time.perf_counter() - start
            rows.append({"index_bits": n, "boxes": boxes, "qubits": cost.qubits, "ands": cost.ands,
                         "toffolis": cost.toffolis, "gates": cost.gates, "points": cost.points,
                         "box_tests": cost.box_tests, "box_tests_kept": cost.box_tests_kept,
                         "lookup_qrom_ands": lookup.qrom_ands, "lookup_select_swap_ands": lookup.select_swap_ands,
                         "count_seconds": seconds})
            swap = f"{lookup.select_swap_ands:12.0f}" if lookup.select_swap_ands is not None else f"{'-':>12s}"
            print(f"{n:3d} {boxes:5d} {cost.qubits:7d} {cost.ands:10d} {cost.toffolis:10d} {lookup.qrom_ands:12d} "
                  f"{swap} {seconds:8.2f}")
    env, database, motion = scaling_instance(30, 1000)
    variants = {"default": OracleOptions(), "unaligned": OracleOptions(align=False),
                "binary_digits": OracleOptions("binary"), "unpruned": OracleOptions(prune=False)}
    effects = {}
    print(f"\noptimizations at n = 30, B = 1000: {'qubits':>7s} {'ands':>10s} {'toffolis':>10s}")
    for name, options in variants.items():
        cost = oracle_costs(env, database, motion, options)
        effects[name] = {"qubits": cost.qubits, "ands": cost.ands, "toffolis": cost.toffolis}
        print(f"{name:33s}: {cost.qubits:7d} {cost.ands:10d} {cost.toffolis:10d}")
    compared = comparison_costs(oracle_plan(env, database, motion))
    effects["comparisons"] = {"count": compared.comparisons, "ands": compared.ands, "toffolis": compared.toffolis,
                              "full_width_ands": compared.full_width_ands,
                              "qiskit_comparator_toffolis": compared.qiskit_toffolis}
    print(f"comparisons: {compared.comparisons} per half; ANDs {compared.ands} (full-width chains "
          f"{compared.full_width_ands}); CCX {compared.toffolis} vs Qiskit's comparator {compared.qiskit_toffolis}")
    env, database, motion = scaling_instance(10, 10)
    start = time.perf_counter()
    oracle = build_coherent_oracle(env, database, motion)
    built_seconds = time.perf_counter() - start
    counted = oracle_costs(env, database, motion)
    depth = toffoli_depth(oracle.gates, oracle.circuit.num_qubits)
    effects["built_n10_b10"] = {"closed_form_equals_built": counted.tally == oracle.tally
                                and counted.qubits == oracle.circuit.num_qubits,
                                "qubits": oracle.circuit.num_qubits, "gates": oracle.circuit.size(),
                                "toffolis": oracle.tally.toffolis, "toffoli_depth": depth,
                                "build_seconds": built_seconds}
    equal = effects["built_n10_b10"]["closed_form_equals_built"]
    print(f"built n = 10, B = 10: {oracle.circuit.size()} gates, closed form equal: {equal}, "
          f"Toffoli depth {depth} of {oracle.tally.toffolis} CCX")
    return rows, effects


def corridor(index_bits: int) -> tuple[Environment, LatticeDatabase, SampledMotion]:
    """[0, 20]^2 less the boxes y <= 7 and y >= 13; nodes (3, 10) and (17, 10); a = (n - 1) / 2
    cell bits per axis; b = max(6, a + 1)-bit coordinates; the paper's dynamics at K = 4 with f = b."""
    env = Environment([[0.0, 20.0], [0.0, 20.0]], [[[0.0, 0.0], [20.0, 7.0]], [[0.0, 13.0], [20.0, 20.0]]])
    cell_bits = (index_bits - 1) // 2
    bits = max(6, cell_bits + 1)
    database = LatticeDatabase(FixedPointFormat.covering(env, bits), cell_bits, np.array([[3.0, 10.0], [17.0, 10.0]]))
    return env, database, SampledMotion.from_dynamics(LinearTrackingDynamics.paper(), 4, bits)


def one_search(index_bits: int, queue: object) -> None:
    """Build, transpile and run one search of the corridor instance (in a child process, so that
    a search past the budget can be stopped); put its row on ``queue``."""
    from qiskit import transpile
    from qiskit_aer import AerSimulator

    env, database, motion = corridor(index_bits)
    oracle = build_coherent_oracle(env, database, motion)
    marks = reachable_reference(env, database, motion)
    marked = int(marks.sum())
    iterations = optimal_iterations(1 << index_bits, marked)
    circuit = transpile(coherent_grover_circuit(oracle.circuit, index_bits, iterations, index_in_middle=True),
                        basis_gates=BASIS, optimization_level=0)
    simulator = AerSimulator(method="matrix_product_state")
    start = time.perf_counter()
    counts = simulator.run(circuit, shots=64, seed_simulator=index_bits).result().get_counts()
    seconds = time.perf_counter() - start
    hits = sum(count for bits, count in counts.items() if marks[int(bits, 2)])
    theta = math.asin(math.sqrt(marked / (1 << index_bits))) if marked else 0.0
    expected = math.sin((2 * iterations + 1) * theta) ** 2
    sd = math.sqrt(max(expected * (1 - expected), 1e-12) / 64)
    queue.put({"index_bits": index_bits, "qubits": oracle.circuit.num_qubits,  # type: ignore[attr-defined]
               "oracle_gates": oracle.circuit.size(), "marked": marked, "iterations": iterations,
               "seconds_per_search": seconds, "shots": 64, "hit_rate": hits / 64, "expected": expected,
               "within_4_sd": abs(hits / 64 - expected) <= 4 * sd})


def grover(quick: bool) -> list[dict]:
    context = multiprocessing.get_context("spawn")
    rows: list[dict] = []
    print(f"\n{'n':>3s} {'qubits':>7s} {'gates':>7s} {'m':>5s} {'k':>3s} {'s/search':>9s} {'hit':>6s} {'theory':>7s}")
    for n in range(5, (9 if quick else 21) + 1, 2):
        queue = context.Queue()
        child = context.Process(target=one_search, args=(n, queue))
        child.start()
        child.join(GROVER_BUDGET_S + 120)  # (the child's imports and the build come first)
        if child.is_alive():
            child.terminate()
            child.join()
            rows.append({"index_bits": n, "timed_out": True, "seconds_per_search": None})
            print(f"{n:3d} stopped: past {GROVER_BUDGET_S:.0f} s")
            break
        row = queue.get()
        rows.append(row)
        print(f"{n:3d} {row['qubits']:7d} {row['oracle_gates']:7d} {row['marked']:5d} {row['iterations']:3d} "
              f"{row['seconds_per_search']:9.2f} {row['hit_rate']:6.3f} {row['expected']:7.3f}")
        if row["seconds_per_search"] > GROVER_BUDGET_S:
            break
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    verified = exhaustive(args.quick)
    cost_rows, effects = costs(args.quick)
    searches = grover(args.quick)
    passed = [row for row in verified if row["ok"]]
    timed = [row for row in searches if (row["seconds_per_search"] or math.inf) <= GROVER_BUDGET_S]
    figures = {
        "exhaustive_max_index_bits": passed[-1]["index_bits"] if passed else None,
        "exhaustive_max_qubits": passed[-1]["qubits"] if passed else None,
        "exhaustive_max_seconds": passed[-1]["seconds"] if passed else None,
        "grover_max_index_bits": timed[-1]["index_bits"] if timed else None,
        "grover_max_qubits": timed[-1]["qubits"] if timed else None,
        "grover_seconds_per_search": timed[-1]["seconds_per_search"] if timed else None,
        "grover_all_within_4_sd": all(row["within_4_sd"] for row in timed),
        **{f"n{row['index_bits']}.b{row['boxes']}.{key}": row[key] for row in cost_rows
           for key in ("qubits", "ands", "lookup_qrom_ands", "lookup_select_swap_ands")},
        **{f"n30.b1000.{name}.ands": value["ands"] for name, value in effects.items() if "ands" in value
           and name != "comparisons"},
    }
    path = write_json("bench_coherent_oracle" + ("_quick" if args.quick else ""),
                      {"machine": machine(), "quick": args.quick, "exhaustive": verified, "costs": cost_rows,
                       "optimizations": effects, "grover": searches, "figures": figures,
                       "note": "one core; Toffolis of one oracle call (compute, phase, uncompute); ands: with "
                               "measurement-based uncomputation; lookup: the marks' QROM load and unload, its "
                               "2^n classical motion checks not counted"}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
