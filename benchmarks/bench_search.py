"""Time per Grover search for each backend, against Aer's floor, and reachability pairs per second.

    python benchmarks/bench_search.py [--quick] [--out FILE]
    python benchmarks/bench_search.py --floor-only [--repeats R] [--out FILE]

Against Aer's floor (n = 4, 8, 12, 16; ``--quick``: 4, 8, 12), m = 12 marked entries (4 at n = 4),
k = 12 iterations, 8 shots, Aer on one thread; in each repeat, in a shuffled order:
- ``floor``: Aer's own floor, a 1-qubit circuit (h, measure) through ``AerSimulator.run`` with 8
  shots, ``memory=True`` and the simulator options ``AerBackend`` uses (and ``floor_all_threads``:
  the same with Aer's default thread count, all cores);
- ``ours``: ``AerBackend.search`` (the compact circuit of ``aer_grover_circuit``, built once per
  search and run through ``AerSimulator.run``), ``build`` its instruction list (the
  ``GroverProgram``), ``build_circuit`` the whole ``QuantumCircuit`` (``build_share``: its share of
  the search), ``run_prebuilt`` ``AerSimulator.run`` of that circuit built beforehand (Aer's share:
  its conversion of the circuit, the simulation and the result), and ``sampler_v2`` the same
  pre-built circuit through qiskit-aer's ``SamplerV2`` (the other documented way to run it);
- ``gate_by_gate``: the circuit gate by gate (``aer_literal_grover_circuit`` with the CX-based
  synthesis choice, bitstring memory parsing), the circuit a noise model runs;
- ``qiskit_algorithms``: qiskit-algorithms' ``Grover`` (12 iterations) with qiskit-aer's
  ``SamplerV2`` (8 shots, one thread) and a preset pass manager for AerSimulator (n <= 12);
- ``ours_diagonal`` / ``ours_mcz``: both oracle forms at n = 8 and 12, to check
  ``simulation_synthesis``'s choice.
``--floor-only`` measures just ``floor`` and ``ours`` with ``--repeats`` repeats per n (default
200; a quarter of them at n = 16) and writes ``bench_search_floor.json``.
Oracle forms (``synthesis``): both forms over n = 8..14 and m = 1..64 (``--quick``: n = 8, 10), the
choice of ``simulation_synthesis`` and its time over the faster form's (the data its cost model's
constants were fitted on).
Medians over the repeats (and the fastest repeat of each); every figure is also given as a ratio
to the floor of the same run.

One job for a round's databases (``one_job``): the p = 8 databases of an unshared Pq-RRT round
(n = 8, k = 3, one shot each, random marks) searched one after the other by
``AerBackend.search_many`` against one ``AerSimulator.run`` of the 8 circuits (what "one Aer job"
would be), interleaved; and whether such a run can give each database its own seed (Aer sets
circuit i's seed to seed_simulator + 2113 i).

A q-RRT round's search (``round_search``): n = 8, k = 3, one shot, a fifth of the entries marked,
the search a q-RRT round on Aer makes, taken apart, interleaved: ``AerBackend.search``, its
circuit's construction (``build_circuit``), ``AerSimulator.run`` of the pre-built circuit at k = 3
and k = 0 (``run_prebuilt``, ``run_prebuilt_k0``) with Aer's own C++ time for the circuit from its
result (``time_taken``), and ``StatevectorBackend.search`` of the same marks.

Search table: Aer for n = 4..16, the exact statevector for n = 4..20. Reachability: one core,
batches of pairs on paper_clutter and annealing_field, for two pair distributions (``uniform``: a
free parent and a uniform child anywhere; ``local``: child = parent + N(0, 1.5^2) per axis, like a
database entry near its nearest tree node). Prints tables and writes JSON.
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np
from _common import machine, median_time, write_json

import qrrt_circuits as qc
from qrrt_circuits.problems.scenarios import SCENARIOS
from qrrt_circuits.registry import BACKENDS
from qrrt_circuits.search import circuits
from qrrt_circuits.search.aer_circuits import aer_grover_program

FLOOR_QUBITS = (4, 8, 12, 16)


def _marks(n: int, rng: np.random.Generator) -> np.ndarray:
    marks = np.zeros(2**n, dtype=bool)
    marks[rng.choice(2**n, min(12, 2**n // 4), replace=False)] = True
    return marks


def _floor_runs(marks: np.ndarray) -> dict:
    """``floor`` and ``ours``: the two contenders of the figure against Aer's floor."""
    from qiskit import QuantumCircuit
    from qiskit_aer import AerSimulator

    simulator = AerSimulator(method="statevector", max_parallel_threads=1)
    floor = QuantumCircuit(1, 1)
    floor.h(0)
    floor.measure(0, 0)
    ours = qc.AerBackend(seed=1, max_parallel_threads=1)
    return {"floor": lambda: simulator.run(floor, shots=8, seed_simulator=1, memory=True).result(),
            "ours": lambda: ours.search(qc.LookupOracle(marks), 12, shots=8)}


def _contenders(n: int, marks: np.ndarray) -> dict:
    """name -> function running one search (k = 12, 8 shots) of ``marks``."""
    from qiskit import QuantumCircuit
    from qiskit_aer import AerSimulator
    from qiskit_aer.primitives import SamplerV2

    simulator = AerSimulator(method="statevector", max_parallel_threads=1)
    floor = QuantumCircuit(1, 1)
    floor.h(0)
    floor.measure(0, 0)
    prebuilt = circuits.aer_grover_circuit(marks, 12)
    sampler = SamplerV2(seed=1, default_shots=8, options={"backend_options": {"max_parallel_threads": 1}})
    seeds = np.random.default_rng(2)

    def gate_by_gate():  # the circuit gate by gate, as a noise model runs it (same seeds per call)
        circuit = circuits.aer_literal_grover_circuit(marks, 12, synthesis="auto")
        result = simulator.run(circuit, shots=8, seed_simulator=int(seeds.integers(2**31 - 1)),
                               memory=True).result()
        return [int(bits, 2) for bits in result.get_memory(0)]

    all_threads = AerSimulator(method="statevector", max_parallel_threads=0)
    runs = {
        **_floor_runs(marks),
        # the same 1-qubit circuit with Aer's default thread count (all cores)
        "floor_all_threads": lambda: all_threads.run(floor, shots=8, seed_simulator=1, memory=True).result(),
        # the circuit's instruction list (its GroverProgram), and the whole QuantumCircuit
        "build": lambda: aer_grover_program(marks, 12),
        "build_circuit": lambda: circuits.aer_grover_circuit(marks, 12),
        # Aer's share of a search: the pre-built circuit through AerSimulator.run
        "run_prebuilt": lambda: simulator.run(prebuilt, shots=8, seed_simulator=1, memory=True).result(),
        "sampler_v2": lambda: sampler.run([prebuilt]).result(),
        "gate_by_gate": gate_by_gate,
    }
    if n in (8, 12):
        for form in ("diagonal", "mcz"):
            backend = qc.AerBackend(seed=1, max_parallel_threads=1, synthesis=form)
            runs[f"ours_{form}"] = lambda b=backend: b.search(qc.LookupOracle(marks), 12, shots=8)
    if n <= 12:
        runs["qiskit_algorithms"] = _qiskit_algorithms_grover(n, marks)
    return runs


def _qiskit_algorithms_grover(n: int, marks: np.ndarray):
    from qiskit import QuantumCircuit
    from qiskit.circuit.library import DiagonalGate
    from qiskit.transpiler import generate_preset_pass_manager
    from qiskit_aer import AerSimulator
    from qiskit_aer.primitives import SamplerV2
    from qiskit_algorithms import AmplificationProblem, Grover

    oracle = QuantumCircuit(n)
    oracle.append(DiagonalGate(np.where(marks, -1.0, 1.0).tolist()), range(n))
    problem = AmplificationProblem(oracle, is_good_state=[format(i, f"0{n}b") for i in np.flatnonzero(marks)])
    pass_manager = generate_preset_pass_manager(optimization_level=1, backend=AerSimulator())
    sampler = SamplerV2(seed=1, default_shots=8, options={"backend_options": {"max_parallel_threads": 1}})
    grover = Grover(iterations=12, sampler=sampler, transpiler=pass_manager)

    def run():
        with warnings.catch_warnings():  # qiskit-algorithms 0.4 builds the deprecated GroverOperator
            warnings.simplefilter("ignore", DeprecationWarning)
            return grover.amplify(problem)

    return run


def _interleaved_times(runs: dict, repeats: int) -> dict[str, list[float]]:
    """Seconds of each of ``runs`` (name -> function) over ``repeats`` rounds, each round in its
    own shuffled order (seeded), so that no contender always follows the same one. A fixed or
    rotated order keeps every contender behind the same neighbour, and a neighbour's after-effects
    enter its times: ``floor_all_threads``, the one contender that starts OpenMP threads, slows
    whichever contender runs right after it."""
    times: dict[str, list[float]] = {name: [] for name in runs}
    names = list(runs)
    order = np.random.default_rng(2026)
    for _ in range(repeats):
        for index in order.permutation(len(names)):
            name = names[index]
            start = time.perf_counter()
            runs[name]()
            times[name].append(time.perf_counter() - start)
    return times


def _floor_row(n: int, marks: np.ndarray, runs: dict, repeats: int) -> dict:
    """Medians, minimums and ratios to the floor of ``runs`` measured interleaved."""
    for run in runs.values():  # warm-up (imports, caches, the pass manager)
        run()
    times = _interleaved_times(runs, repeats)
    medians = {name: float(np.median(values)) for name, values in times.items()}
    minimums = {name: float(np.min(values)) for name, values in times.items()}
    floor = medians["floor"]
    row = {"qubits": n, "marked": int(marks.sum()), "iterations": 12, "shots": 8, "repeats": repeats,
           "synthesis": circuits.simulation_synthesis(marks),
           "instructions": len(circuits.aer_grover_circuit(marks, 12).data),
           "median_ms": {name: value * 1e3 for name, value in medians.items()},
           "ratio_to_floor": {name: value / floor for name, value in medians.items()},
           # the fastest repeat of each: less sensitive to other processes on a busy machine
           "min_ms": {name: value * 1e3 for name, value in minimums.items()},
           "ratio_of_minimums_to_floor": {name: value / minimums["floor"] for name, value in minimums.items()}}
    text = "  ".join(f"{name} {value * 1e3:8.3f} ms ({value / floor:6.1f}x)" for name, value in medians.items())
    print(f"  n={n:2d} m={row['marked']:2d}  {text}")
    text = "  ".join(f"{name} {value:6.1f}x" for name, value in row["ratio_of_minimums_to_floor"].items())
    print(f"        fastest repeats over the fastest floor: {text}")
    return row


def bench_floor(quick: bool) -> list[dict]:
    """Each contender's median time and its ratio to Aer's floor, measured interleaved."""
    rows = []
    rng = np.random.default_rng(0)
    for n in FLOOR_QUBITS[:3] if quick else FLOOR_QUBITS:
        marks = _marks(n, rng)
        repeats = (5 if quick else 30) if n <= 8 else (3 if quick else (12 if n == 12 else 8))
        row = _floor_row(n, marks, _contenders(n, marks), repeats)
        row["instructions_gate_by_gate"] = len(circuits.aer_literal_grover_circuit(marks, 12).data)
        row["build_share"] = row["median_ms"]["build_circuit"] / row["median_ms"]["ours"]
        row["run_share"] = row["median_ms"]["run_prebuilt"] / row["median_ms"]["ours"]
        print(f"        circuit construction {row['build_share']:.1%} of the search, AerSimulator.run "
              f"{row['run_share']:.1%}")
        rows.append(row)
    return rows


def bench_floor_only(repeats: int) -> list[dict]:
    """``ours`` against ``floor`` alone, ``repeats`` interleaved repeats per n (a quarter at n = 16)."""
    rows = []
    rng = np.random.default_rng(0)
    for n in FLOOR_QUBITS:
        marks = _marks(n, rng)
        rows.append(_floor_row(n, marks, _floor_runs(marks), max(3, repeats // 4) if n >= 16 else repeats))
    return rows


def bench_one_job(quick: bool) -> dict:
    """The p databases of one unshared Pq-RRT round in one ``AerSimulator.run`` against
    ``AerBackend.search_many`` (one run each), and the seeds Aer gives the circuits of one run."""
    workers, n, k = 8, 8, 3
    rng = np.random.default_rng(3)
    marks = [rng.random(2**n) < 0.1 for _ in range(workers)]
    seeds = [int(s) for s in rng.integers(0, 2**31 - 1, workers)]
    backend = qc.AerBackend(seed=0, max_parallel_threads=1)
    simulator = backend.simulator
    synthesis = backend.synthesis

    def words(circuits_: list, shots: int, seed: int) -> list[list[str]]:
        result = simulator.run(circuits_, shots=shots, seed_simulator=seed, memory=True,
                               max_parallel_threads=1).result()
        return [list(experiment.data.memory) for experiment in result.results]

    def one_run() -> None:  # the circuits of the round built and run in one AerSimulator.run
        words([circuits.aer_grover_circuit(mk, k, synthesis=synthesis) for mk in marks], 1, seeds[0])

    requests = [qc.SearchRequest(qc.LookupOracle(mk), k, 1, seed) for mk, seed in zip(marks, seeds, strict=True)]
    runs = {"search_many": lambda: backend.search_many(requests), "one_run": one_run}
    for run in runs.values():
        run()
    repeats = 10 if quick else 60
    times = _interleaved_times(runs, repeats)
    medians = {name: float(np.median(values)) * 1e3 for name, values in times.items()}
    # the seeds of one run: circuit i ran with seeds[0] + 2113 i, not with its own seeds[i]
    built = [circuits.aer_grover_circuit(mk, k, synthesis=synthesis) for mk in marks]
    own = [words([circuit], 64, seed)[0] for circuit, seed in zip(built, seeds, strict=True)]
    together64 = words(built, 64, seeds[0])
    shifted = [words([circuit], 64, seeds[0] + 2113 * index)[0] for index, circuit in enumerate(built)]
    row = {"workers": workers, "qubits": n, "iterations": k, "shots_per_database": 1, "repeats": repeats,
           "median_ms": medians,
           "one_run_over_search_many": medians["one_run"] / medians["search_many"],
           "circuit_seeds_are_first_plus_2113_i": together64 == shifted,
           "circuit_seeds_are_their_own": together64 == own}
    print(f"  {workers} databases (n={n}, k={k}, 1 shot): "
          + "  ".join(f"{name} {value:.3f} ms" for name, value in medians.items())
          + f"  one run / search_many = {row['one_run_over_search_many']:.2f}; circuit i seeded "
          f"first + 2113 i: {row['circuit_seeds_are_first_plus_2113_i']}, its own seed: "
          f"{row['circuit_seeds_are_their_own']}")
    return row


def bench_round_search(quick: bool) -> dict:
    """The parts of one q-RRT round's search on Aer (n = 8, k = 3, one shot), median microseconds."""
    n, k = 8, 3
    marks = np.random.default_rng(5).random(2**n) < 0.2
    backend = qc.AerBackend(seed=0, max_parallel_threads=1)
    statevector = qc.StatevectorBackend(seed=0)
    simulator = backend.simulator
    prebuilt = {iterations: circuits.aer_grover_circuit(marks, iterations) for iterations in (k, 0)}
    cpp_us: dict[int, list[float]] = {k: [], 0: []}

    def run_prebuilt(iterations: int) -> None:
        result = simulator.run(prebuilt[iterations], shots=1, seed_simulator=1, memory=True,
                               max_parallel_threads=1).result()
        cpp_us[iterations].append(result.results[0].time_taken * 1e6)

    runs = {"search": lambda: backend.search(qc.LookupOracle(marks), k, 1, seed=1),
            "build_circuit": lambda: circuits.aer_grover_circuit(marks, k),
            "run_prebuilt": lambda: run_prebuilt(k),
            "run_prebuilt_k0": lambda: run_prebuilt(0),
            "statevector_search": lambda: statevector.search(qc.LookupOracle(marks), k, 1, seed=1)}
    for run in runs.values():
        run()
    for samples in cpp_us.values():  # drop the warm-up's
        samples.clear()
    repeats = 200 if quick else 2000
    times = _interleaved_times(runs, repeats)
    medians = {name: float(np.median(values)) * 1e6 for name, values in times.items()}
    medians["aer_cpp"] = float(np.median(cpp_us[k]))
    medians["aer_cpp_k0"] = float(np.median(cpp_us[0]))
    print(f"  n={n}, k={k}, 1 shot: " + "  ".join(f"{name} {value:.1f} us" for name, value in medians.items()))
    return {"qubits": n, "iterations": k, "shots": 1, "marked": int(marks.sum()), "repeats": repeats,
            "median_us": medians}


def bench_search(quick: bool) -> list[dict]:
    rows = []
    rng = np.random.default_rng(0)
    # "statevector-seeded": a seed per call, as the planners search (the compiled default_rng draws)
    for name, registered, options, top in (("aer", "aer", {"max_parallel_threads": 1}, 16),
                                           ("statevector", "statevector", {}, 20),
                                           ("statevector-seeded", "statevector", {}, 20),
                                           ("statevector-iterated", "statevector", {"closed_form": False}, 20)):
        backend = BACKENDS.create(registered, seed=1, **options)
        seed = 12345 if name.endswith("-seeded") else None
        for n in range(4, (12 if quick else top) + 1, 2 if quick else 1):
            m = min(12, 2 ** n // 4)
            marks = np.zeros(2**n, dtype=bool)
            marks[rng.choice(2**n, m, replace=False)] = True
            repeats = 5 if quick else (10 if n >= 15 else 30)
            oracle = qc.LookupOracle(marks)
            med, lo, hi = median_time(lambda b=backend, o=oracle, sd=seed: b.search(o, 12, shots=8, seed=sd), repeats)
            rows.append({"backend": name, "qubits": n, "marked": m, "iterations": 12, "shots": 8,
                         "median_s": med, "min_s": lo, "max_s": hi, "repeats": repeats})
            print(f"  {name:20s} n={n:2d}  {med * 1e3:9.3f} ms  (min {lo * 1e3:.3f}, max {hi * 1e3:.3f})")
    return rows


def bench_synthesis(quick: bool) -> dict:
    """Both oracle forms of ``AerBackend`` (k = 12, 8 shots, one thread) over n and m, interleaved,
    and what ``simulation_synthesis`` picks: per (n, m) the median time of each form, the ratio
    2^n / (2m + 1) the cost model weighs, and the choice's time over the faster form's."""
    from qrrt_circuits.search.aer_circuits import simulation_synthesis

    forms = {form: qc.AerBackend(seed=1, max_parallel_threads=1, synthesis=form) for form in ("diagonal", "mcz")}
    rng = np.random.default_rng(3)
    repeats = 3 if quick else 7
    rows = []
    for n in ((8, 10) if quick else (8, 10, 12, 14)):
        for m in (1, 2, 4, 8, 16, 32, 64):
            if m > 2**n // 4:
                continue
            marks = np.zeros(2**n, dtype=bool)
            marks[rng.choice(2**n, m, replace=False)] = True
            times: dict[str, list[float]] = {form: [] for form in forms}
            for backend in forms.values():
                backend.search(qc.LookupOracle(marks), 12, shots=8, seed=0)
            for repeat in range(repeats):
                for form, backend in forms.items():
                    start = time.perf_counter()
                    backend.search(qc.LookupOracle(marks), 12, shots=8, seed=repeat)
                    times[form].append(time.perf_counter() - start)
            medians = {form: float(np.median(values)) for form, values in times.items()}
            choice = simulation_synthesis(marks)
            rows.append({"qubits": n, "marked": m, "entries_per_instruction": 2**n / (2 * m + 1),
                         "diagonal_ms": medians["diagonal"] * 1e3, "mcz_ms": medians["mcz"] * 1e3,
                         "faster": min(medians, key=medians.__getitem__), "choice": choice,
                         "choice_over_faster": medians[choice] / min(medians.values())})
            row = rows[-1]
            print(f"  n={n:2d} m={m:2d}  2^n/(2m+1) {row['entries_per_instruction']:7.1f}  diagonal "
                  f"{row['diagonal_ms']:8.2f} ms  mcz {row['mcz_ms']:8.2f} ms  chosen {choice:8s} "
                  f"({row['choice_over_faster']:.2f}x the faster)")
    regrets = [row["choice_over_faster"] for row in rows]
    return {"rows": rows, "worst_choice_over_faster": max(regrets),
            "mean_choice_over_faster": float(np.mean(regrets))}


def bench_reachability(quick: bool) -> list[dict]:
    rows = []
    count = 20000 if quick else 200000
    for scenario in ("paper_clutter", "annealing_field"):
        env = SCENARIOS[scenario](seed=0).env
        oracle = qc.ExactCheck(env)
        rng = np.random.default_rng(1)
        parents = env.sample_free(count, rng)
        pairs = {
            "uniform": env.sample_uniform(count, rng),
            "local": np.clip(parents + rng.normal(scale=1.5, size=parents.shape),
                             env.bounds[:, 0], env.bounds[:, 1]),
        }
        oracle.reachable(parents[:10], pairs["uniform"][:10])  # compile
        for kind, children in pairs.items():
            med, lo, hi = median_time(lambda o=oracle, c=children, p=parents: o.reachable(p, c),
                                      3 if quick else 5)
            reach = float(oracle.reachable(parents, children).mean())
            rows.append({"scenario": scenario, "pairs": kind, "count": count,
                         "pairs_per_s": count / med, "reachable_fraction": reach,
                         "median_s": med, "boxes": env.num_boxes})
            print(f"  {scenario:16s} {kind:8s} {count / med / 1e3:9.1f} k pairs/s  "
                  f"(reachable {reach:.3f})")
    return rows


def _floor_summary(floor: list[dict]) -> dict:
    summary: dict = {}
    for row in floor:
        n = row["qubits"]
        summary[f"aer_floor_ms_n{n}"] = row["median_ms"]["floor"]
        for name in ("ours", "run_prebuilt", "sampler_v2", "gate_by_gate", "qiskit_algorithms"):
            if name in row["ratio_to_floor"]:
                summary[f"{name}_over_floor_n{n}"] = row["ratio_to_floor"][name]
                summary[f"{name}_min_over_floor_min_n{n}"] = row["ratio_of_minimums_to_floor"][name]
        summary[f"ours_ms_n{n}"] = row["median_ms"]["ours"]
        for share in ("build_share", "run_share"):
            if share in row:
                summary[f"{share}_n{n}"] = row[share]
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--floor-only", action="store_true",
                        help="only AerBackend.search against Aer's floor, n = 4, 8, 12, 16")
    parser.add_argument("--repeats", type=int, default=200, help="--floor-only: repeats per n (default %(default)s)")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    if args.floor_only:
        print(f"AerBackend.search against Aer's floor (k = 12, 8 shots, {args.repeats} repeats, medians):")
        floor = bench_floor_only(max(1, args.repeats))
        summary = _floor_summary(floor)
        print("summary:", {k: round(v, 3) for k, v in summary.items()})
        path = write_json("bench_search_floor", {"machine": machine(), "against_floor": floor, "summary": summary},
                          args.out)
        print(f"wrote {path}")
        return
    print("Grover search against Aer's floor (k = 12, 8 shots, medians, ratio to the floor):")
    floor = bench_floor(args.quick)
    print("A round's databases in one Aer job:")
    one_job = bench_one_job(args.quick)
    print("A q-RRT round's search on Aer, taken apart (medians):")
    round_search = bench_round_search(args.quick)
    print("Grover search, time per search (k = 12, 8 shots):")
    search = bench_search(args.quick)
    print("Oracle forms for Aer (k = 12, 8 shots) and simulation_synthesis's choice:")
    synthesis = bench_synthesis(args.quick)
    print("Reachability (one core):")
    reach = bench_reachability(args.quick)
    aer12 = next((r["median_s"] for r in search if r["backend"] == "aer" and r["qubits"] == 12), None)
    sv12 = next((r["median_s"] for r in search if r["backend"] == "statevector" and r["qubits"] == 12), None)
    summary = {"aer_n12_ms": aer12 and aer12 * 1e3, "statevector_n12_ms": sv12 and sv12 * 1e3,
               "statevector_speedup_n12": aer12 / sv12 if aer12 and sv12 else None}
    for n in (8, 12):
        for name in ("statevector", "statevector-seeded"):
            time_s = next((r["median_s"] for r in search if r["backend"] == name and r["qubits"] == n), None)
            summary[f"{name.replace('-', '_')}_n{n}_us"] = time_s and time_s * 1e6
    sv20 = next((r["median_s"] for r in search if r["backend"] == "statevector" and r["qubits"] == 20), None)
    summary["statevector_n20_ms"] = sv20 and sv20 * 1e3
    summary.update(_floor_summary(floor))
    for name, value in round_search["median_us"].items():
        summary[f"round_search_{name}_us"] = value
    summary["one_job_over_search_many"] = one_job["one_run_over_search_many"]
    summary["one_job_circuit_seeds_own"] = one_job["circuit_seeds_are_their_own"]
    summary["synthesis_worst_choice_over_faster"] = synthesis["worst_choice_over_faster"]
    summary["synthesis_mean_choice_over_faster"] = synthesis["mean_choice_over_faster"]
    print("summary:", {k: (round(v, 3) if isinstance(v, float) else v) for k, v in summary.items()})
    path = write_json("bench_search" + ("_quick" if args.quick else ""),
                      {"machine": machine(), "quick": args.quick, "against_floor": floor, "one_job": one_job,
                       "round_search": round_search, "search": search,
                       "synthesis": synthesis, "reachability": reach, "summary": summary,
                       "note": "phase oracle built from a classical lookup of all 2^n marks; "
                               "one circuit with 8 shots stands for 8 workers"}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
