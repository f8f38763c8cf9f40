"""Time per Grover search for each backend, against Aer's floor, and reachability pairs per second.

    python benchmarks/bench_search.py [--quick] [--out FILE]

Against Aer's floor (n = 4, 8, 12, 16; ``--quick``: 4, 8, 12), m = 12 marked entries (4 at n = 4),
k = 12 iterations, 8 shots, Aer on one thread; in each repeat, one after the other:
- ``floor``: Aer's own floor, a 1-qubit circuit (h, measure) run with 8 shots (and
  ``floor_all_threads``: the same with Aer's default thread count, all cores);
- ``floor_controller``: that 1-qubit circuit on Aer's controller directly (``aer_direct``), the
  floor of the path ``AerBackend`` takes from 13 qubits on;
- ``floor_state``: the floor of Aer's state (``aer_state``): a 1-qubit state reset, one h and 8
  samples;
- ``ours``: ``AerBackend.search`` (the compact circuit of ``aer_grover_circuit``, its instructions
  applied to Aer's state below 13 qubits, ``aer_state``, else handed to Aer's controller),
  ``ours_controller`` the same searches on the controller (``aer_direct``, the path before
  ``aer_state``), ``build`` its construction per search (the ``GroverProgram``: its
  share of the search), ``assemble`` the program's conversion into Aer's circuit object (which
  Aer's own assembler did inside ``AerSimulator.run`` before), ``build_circuit`` the same circuit as
  a ``QuantumCircuit``, and ``ours_via_run`` the same searches through ``AerSimulator.run`` (the
  path before ``aer_direct``);
- ``gate_by_gate``: the previous implementation (``aer_literal_grover_circuit`` with the CX-based
  synthesis choice, bitstring memory parsing), for before/after figures from one run;
- ``qiskit_algorithms``: qiskit-algorithms' ``Grover`` (12 iterations) with qiskit-aer's
  ``SamplerV2`` (8 shots, one thread) and a preset pass manager for AerSimulator (n <= 12);
- ``ours_diagonal`` / ``ours_mcz``: both oracle forms at n = 8 and 12, to check
  ``simulation_synthesis``'s choice.
Oracle forms (``synthesis``): both forms over n = 8..14 and m = 1..64 (``--quick``: n = 8, 10), the
choice of ``simulation_synthesis`` and its time over the faster form's (the data its cost model's
constants were fitted on).
Medians over the repeats (and the fastest repeat of each); every figure is also given as a ratio
to the floor of the same run.

One job for a round's databases (``one_job``): the p = 8 databases of an unshared Pq-RRT round
(n = 8, k = 3, one shot each, random marks) searched one after the other by
``AerBackend.search_many`` against one controller call with the 8 circuits (what "one Aer job"
would be), interleaved; and whether such a call can give each database its own seed (Aer sets
circuit i's seed to seed_simulator + 2113 i, whatever the circuit carries).

A q-RRT round's search (``round_search``): n = 8, k = 3, one shot, a fifth of the entries marked,
the search a q-RRT round on Aer makes, taken apart, interleaved: ``AerBackend.search``,
``aer_direct.execute_grover`` (assembly into the recycled circuit and the controller's run),
``assemble_grover`` (assembly into a new circuit), the controller's call on an assembled circuit
(``controller_call``) and, from its output, the controller's own C++ time for the circuit
(``time_taken``, k = 3 and k = 0), a new ``AerCircuit()`` alone (its ``std::random_device`` seed),
``aer_state.execute_grover`` (the circuit on Aer's state, ``AerBackend``'s path since ``aer_state``),
``search_on_controller`` (``AerBackend.search`` kept on the controller) and
``StatevectorBackend.search`` of the same marks.

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
from qrrt_circuits.registry import BACKENDS
from qrrt_circuits.search import aer_direct, aer_state, circuits
from qrrt_circuits.search.aer_circuits import aer_grover_program

FLOOR_QUBITS = (4, 8, 12, 16)


def _marks(n: int, rng: np.random.Generator) -> np.ndarray:
    marks = np.zeros(2**n, dtype=bool)
    marks[rng.choice(2**n, min(12, 2**n // 4), replace=False)] = True
    return marks


def _contenders(n: int, marks: np.ndarray) -> dict:
    """name -> function running one search (k = 12, 8 shots) of ``marks``."""
    from qiskit import QuantumCircuit
    from qiskit_aer import AerSimulator

    simulator = AerSimulator(method="statevector", max_parallel_threads=1)
    floor = QuantumCircuit(1, 1)
    floor.h(0)
    floor.measure(0, 0)
    ours = qc.AerBackend(seed=1, max_parallel_threads=1)
    via_run = qc.AerBackend(seed=1, max_parallel_threads=1)
    via_run._use_controller = False  # the same circuits through AerSimulator.run (the path before aer_direct)
    on_controller = qc.AerBackend(seed=1, max_parallel_threads=1)
    on_controller._use_state = False  # the same circuits on the controller (the path before aer_state)
    state_floor = np.zeros(2, dtype=bool)  # k = 0: the state's reset, W (one h) and 8 samples
    program = aer_grover_program(marks, 12)
    seeds = np.random.default_rng(2)

    def gate_by_gate():  # the implementation before this benchmark's figures (same seeds per call)
        circuit = circuits.aer_literal_grover_circuit(marks, 12, synthesis="auto")
        result = simulator.run(circuit, shots=8, seed_simulator=int(seeds.integers(2**31 - 1)),
                               memory=True).result()
        return [int(bits, 2) for bits in result.get_memory(0)]

    all_threads = AerSimulator(method="statevector", max_parallel_threads=0)
    runs = {
        "floor": lambda: simulator.run(floor, shots=8, seed_simulator=1, memory=True).result(),
        # the same 1-qubit circuit with Aer's default thread count (all cores), as AerBackend ran
        # every circuit before it kept circuits under 14 qubits on one thread
        "floor_all_threads": lambda: all_threads.run(floor, shots=8, seed_simulator=1, memory=True).result(),
        # the same 1-qubit circuit on Aer's controller directly (aer_direct): the floor of the
        # path AerBackend takes without a noise model from 13 qubits on
        "floor_controller": lambda: aer_direct.execute(simulator, floor, 8, 1, 1),
        # a 1-qubit circuit (h, 8 samples) on Aer's state: the floor of the path AerBackend takes
        # below 13 qubits
        "floor_state": lambda: aer_state.execute_grover(state_floor, 0, "diagonal", 8, 1),
        "ours": lambda: ours.search(marks, 12, shots=8),
        "ours_controller": lambda: on_controller.search(marks, 12, shots=8),
        # the circuit's construction (its GroverProgram: what AerBackend builds per search), and
        # its conversion into Aer's circuit object (what Aer's own assembler did inside run)
        "build": lambda: aer_grover_program(marks, 12),
        "assemble": lambda: aer_direct.assemble_program(program),
        # both at once from cached call arguments (AerBackend's path for the diagonal form)
        "assemble_grover": lambda: aer_direct.assemble_grover(marks, 12),
        "build_circuit": lambda: circuits.aer_grover_circuit(marks, 12),
        "ours_via_run": lambda: via_run.search(marks, 12, shots=8),
        "gate_by_gate": gate_by_gate,
    }
    if n in (8, 12):
        for form in ("diagonal", "mcz"):
            backend = qc.AerBackend(seed=1, max_parallel_threads=1, synthesis=form)
            runs[f"ours_{form}"] = lambda b=backend: b.search(marks, 12, shots=8)
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
    own shuffled order (seeded), so no contender always follows the same one. (A rotated order,
    used before, keeps every contender behind the same neighbour: ``ours`` always ran a few calls
    after ``floor_all_threads``, the one contender that starts OpenMP threads, and its n = 12
    median was 11.00 and 10.65 ms in two runs, ``run_ed52c13.json`` and ``run_54c2b9a.json``,
    against 7.05 with the order shuffled, ``run_c22abd7.json``.)"""
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


def bench_floor(quick: bool) -> list[dict]:
    """Each contender's median time and its ratio to Aer's floor, measured interleaved."""
    rows = []
    rng = np.random.default_rng(0)
    for n in FLOOR_QUBITS[:3] if quick else FLOOR_QUBITS:
        marks = _marks(n, rng)
        runs = _contenders(n, marks)
        for run in runs.values():  # warm-up (imports, caches, the pass manager)
            run()
        repeats = (5 if quick else 30) if n <= 8 else (3 if quick else (12 if n == 12 else 8))
        # shuffled order (the all-threads floor leaves OpenMP threads that can slow whatever runs
        # right after it)
        times = _interleaved_times(runs, repeats)
        medians = {name: float(np.median(values)) for name, values in times.items()}
        minimums = {name: float(np.min(values)) for name, values in times.items()}
        floor = medians["floor"]
        row = {"qubits": n, "marked": int(marks.sum()), "iterations": 12, "shots": 8, "repeats": repeats,
               "synthesis": circuits.simulation_synthesis(marks),
               "instructions": len(circuits.aer_grover_circuit(marks, 12).data),
               "instructions_gate_by_gate": len(circuits.aer_literal_grover_circuit(marks, 12).data),
               "median_ms": {name: value * 1e3 for name, value in medians.items()},
               "ratio_to_floor": {name: value / floor for name, value in medians.items()},
               # the fastest repeat of each: less sensitive to other processes on a busy machine
               "min_ms": {name: value * 1e3 for name, value in minimums.items()},
               "ratio_of_minimums_to_floor": {name: value / minimums["floor"] for name, value in minimums.items()},
               "build_share": medians["build"] / medians["ours"],
               "assemble_share": medians["assemble"] / medians["ours"]}
        rows.append(row)
        text = "  ".join(f"{name} {value * 1e3:8.3f} ms ({value / floor:6.1f}x)" for name, value in medians.items())
        print(f"  n={n:2d} m={row['marked']:2d}  {text}  build share {row['build_share']:.1%}, "
              f"assembly share {row['assemble_share']:.1%}")
        text = "  ".join(f"{name} {value:6.1f}x" for name, value in row["ratio_of_minimums_to_floor"].items())
        print(f"        fastest repeats over the fastest floor: {text}")
    return rows


def bench_one_job(quick: bool) -> dict:
    """The p databases of one unshared Pq-RRT round in one Aer controller call against
    ``AerBackend.search_many`` (one call each), and the seeds Aer gives the circuits of one call."""
    workers, n, k = 8, 8, 3
    rng = np.random.default_rng(3)
    marks = [rng.random(2**n) < 0.1 for _ in range(workers)]
    seeds = [int(s) for s in rng.integers(0, 2**31 - 1, workers)]
    backend = qc.AerBackend(seed=0, max_parallel_threads=1)
    simulator = backend.simulator
    synthesis = backend.synthesis

    def one_by_one() -> None:  # the simulator seeds as AerBackend draws them, one call per database
        for mk, seed in zip(marks, seeds, strict=True):
            aer_direct.execute(simulator, aer_grover_program(mk, k, synthesis), 1, seed, 1)

    requests = [qc.SearchRequest(mk, k, 1, seed) for mk, seed in zip(marks, seeds, strict=True)]
    runs = {"search_many": lambda: backend.search_many(requests), "one_by_one_controller": one_by_one,
            "one_controller_call": lambda: _one_call_words(simulator, marks, k, synthesis, seeds[0], 1)}
    for run in runs.values():
        run()
    repeats = 10 if quick else 60
    times = _interleaved_times(runs, repeats)
    medians = {name: float(np.median(values)) * 1e3 for name, values in times.items()}
    # the seeds of one call: circuit i ran with seeds[0] + 2113 i, not with its own seeds[i]
    own = [aer_direct.execute(simulator, aer_grover_program(mk, k, synthesis), 64, seed, 1)
           for mk, seed in zip(marks, seeds, strict=True)]
    together64 = _one_call_words(simulator, marks, k, synthesis, seeds[0], 64, circuit_seeds=seeds)
    shifted = [aer_direct.execute(simulator, aer_grover_program(mk, k, synthesis), 64,
                                  seeds[0] + 2113 * index, 1) for index, mk in enumerate(marks)]
    row = {"workers": workers, "qubits": n, "iterations": k, "shots_per_database": 1, "repeats": repeats,
           "median_ms": medians,
           "one_call_over_search_many": medians["one_controller_call"] / medians["search_many"],
           "circuit_seeds_are_first_plus_2113_i": together64 == shifted,
           "circuit_seeds_are_their_own": together64 == own}
    print(f"  {workers} databases (n={n}, k={k}, 1 shot): "
          + "  ".join(f"{name} {value:.3f} ms" for name, value in medians.items())
          + f"  one call / search_many = {row['one_call_over_search_many']:.2f}; circuit i seeded "
          f"first + 2113 i: {row['circuit_seeds_are_first_plus_2113_i']}, its own seed: "
          f"{row['circuit_seeds_are_their_own']}")
    return row


def bench_round_search(quick: bool) -> dict:
    """The parts of one q-RRT round's search on Aer (n = 8, k = 3, one shot), median microseconds."""
    from qiskit_aer.backends.controller_wrappers import AerCircuit

    n, k = 8, 3
    marks = np.random.default_rng(5).random(2**n) < 0.2
    backend = qc.AerBackend(seed=0, max_parallel_threads=1)
    statevector = qc.StatevectorBackend(seed=0)
    on_controller = qc.AerBackend(seed=0, max_parallel_threads=1)
    on_controller._use_state = False
    simulator = backend.simulator
    assembled = {iterations: aer_direct.assemble_grover(marks, iterations, "diagonal") for iterations in (k, 0)}
    width = aer_direct._Width(n, n)
    cpp_us: dict[int, list[float]] = {k: [], 0: []}

    def controller(iterations: int) -> None:
        config = aer_direct._configuration(simulator, width, 1, 1, 1)
        output = simulator._execute_circuits([assembled[iterations]], None, config)
        cpp_us[iterations].append(output["results"][0]["time_taken"] * 1e6)

    runs = {"search": lambda: backend.search(marks, k, 1, seed=1),
            "execute_grover": lambda: aer_direct.execute_grover(simulator, marks, k, "diagonal", 1, 1, 1),
            "assemble_grover": lambda: aer_direct.assemble_grover(marks, k, "diagonal"),
            "controller_call": lambda: controller(k),
            "controller_call_k0": lambda: controller(0),
            "new_aer_circuit": AerCircuit,
            "state_execute_grover": lambda: aer_state.execute_grover(marks, k, "diagonal", 1, 1),
            "search_on_controller": lambda: on_controller.search(marks, k, 1, seed=1),
            "statevector_search": lambda: statevector.search(marks, k, 1, seed=1)}
    for run in runs.values():
        run()
    for samples in cpp_us.values():  # drop the warm-up's
        samples.clear()
    repeats = 200 if quick else 2000
    times = _interleaved_times(runs, repeats)
    medians = {name: float(np.median(values)) * 1e6 for name, values in times.items()}
    medians["controller_cpp"] = float(np.median(cpp_us[k]))
    medians["controller_cpp_k0"] = float(np.median(cpp_us[0]))
    print(f"  n={n}, k={k}, 1 shot: " + "  ".join(f"{name} {value:.1f} us" for name, value in medians.items()))
    return {"qubits": n, "iterations": k, "shots": 1, "marked": int(marks.sum()), "repeats": repeats,
            "median_us": medians}


def _one_call_words(simulator, marks, k: int, synthesis: str, seed: int, shots: int,
                    circuit_seeds: list[int] | None = None) -> list[list[str]]:
    """The measured words of one controller call with one Grover circuit per marks array, with
    ``seed_simulator = seed`` and, if given, circuit i's own ``seed`` attribute set to
    ``circuit_seeds[i]`` (to show that Aer replaces it by seed + 2113 i)."""
    from qiskit_aer.backends.aer_compiler import generate_aer_config

    circuits_ = []
    for index, mk in enumerate(marks):
        aer = aer_direct.assemble_program(aer_grover_program(mk, k, synthesis))
        aer.circ_id = index
        if circuit_seeds is not None:
            aer.seed = circuit_seeds[index]
        circuits_.append(aer)
    n = int(marks[0].shape[0]).bit_length() - 1
    config = generate_aer_config([aer_direct._Width(n, n)] * len(marks), simulator.options, shots=shots,
                                 seed_simulator=seed, memory=True, max_parallel_threads=1)
    output = simulator._execute_circuits(circuits_, None, config)
    return [list(result["data"]["memory"]) for result in output["results"]]


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
            med, lo, hi = median_time(lambda b=backend, mk=marks, sd=seed: b.search(mk, 12, shots=8, seed=sd),
                                      repeats)
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
                backend.search(marks, 12, shots=8, seed=0)
            for repeat in range(repeats):
                for form, backend in forms.items():
                    start = time.perf_counter()
                    backend.search(marks, 12, shots=8, seed=repeat)
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


def bench_state_paths(quick: bool) -> dict:
    """The two paths of ``AerBackend`` for the same search: ``aer_state.execute_grover`` (Aer's
    state) against ``aer_direct.execute_grover`` (Aer's controller, one thread), both oracle forms,
    n = 10..13, m = 1 and 12, k = 12, 8 shots, interleaved; per case the medians and state /
    controller (the data that ``aer.STATE_CHOSEN_BELOW_QUBITS`` rests on)."""
    rng = np.random.default_rng(4)
    rows = []
    repeats = 6 if quick else 20
    simulator = qc.AerBackend(seed=1, max_parallel_threads=1).simulator
    widths = (10, 11, 12, 13)
    for n in widths:
        for marked in (1, 12):
            marks = np.zeros(2**n, dtype=bool)
            marks[rng.choice(2**n, marked, replace=False)] = True
            for form in ("diagonal", "mcz"):
                runs = {"state": lambda mk=marks, f=form: aer_state.execute_grover(mk, 12, f, 8, 1),
                        "controller": lambda mk=marks, f=form: aer_direct.execute_grover(simulator, mk, 12, f, 8, 1, 1)}
                times = _interleaved_times(runs, repeats)
                medians = {name: float(np.median(values)) * 1e3 for name, values in times.items()}
                rows.append({"qubits": n, "marked": marked, "synthesis": form, "median_ms": medians,
                             "state_over_controller": medians["state"] / medians["controller"]})
                print(f"  n={n:2d} m={marked:2d} {form:8s} state {medians['state']:7.3f} ms  controller "
                      f"{medians['controller']:7.3f} ms  ratio {rows[-1]['state_over_controller']:.2f}")
    return {"rows": rows, "repeats": repeats,
            "worst_state_over_controller_by_qubits": {
                str(n): max(row["state_over_controller"] for row in rows if row["qubits"] == n) for n in widths}}


def bench_reachability(quick: bool) -> list[dict]:
    rows = []
    count = 20000 if quick else 200000
    for scenario in ("paper_clutter", "annealing_field"):
        env = qc.scenarios.by_name(scenario, seed=0)
        oracle = qc.ReachabilityOracle(env)
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
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
    print("AerBackend.search on Aer's state against the controller (k = 12, 8 shots, medians):")
    state_paths = bench_state_paths(args.quick)
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
    for row in floor:
        n = row["qubits"]
        summary[f"aer_floor_ms_n{n}"] = row["median_ms"]["floor"]
        for name in ("ours", "ours_controller", "floor_state", "gate_by_gate", "qiskit_algorithms"):
            if name in row["ratio_to_floor"]:
                summary[f"{name}_over_floor_n{n}"] = row["ratio_to_floor"][name]
                summary[f"{name}_min_over_floor_min_n{n}"] = row["ratio_of_minimums_to_floor"][name]
        summary[f"ours_ms_n{n}"] = row["median_ms"]["ours"]
        summary[f"build_share_n{n}"] = row["build_share"]
        summary[f"assemble_share_n{n}"] = row["assemble_share"]
    for name, value in round_search["median_us"].items():
        summary[f"round_search_{name}_us"] = value
    summary["one_job_over_search_many"] = one_job["one_call_over_search_many"]
    summary["one_job_circuit_seeds_own"] = one_job["circuit_seeds_are_their_own"]
    for n, ratio in state_paths["worst_state_over_controller_by_qubits"].items():
        summary[f"state_worst_over_controller_n{n}"] = ratio
    summary["synthesis_worst_choice_over_faster"] = synthesis["worst_choice_over_faster"]
    summary["synthesis_mean_choice_over_faster"] = synthesis["mean_choice_over_faster"]
    print("summary:", {k: (round(v, 3) if isinstance(v, float) else v) for k, v in summary.items()})
    path = write_json("bench_search" + ("_quick" if args.quick else ""),
                      {"machine": machine(), "quick": args.quick, "against_floor": floor, "one_job": one_job,
                       "round_search": round_search, "search": search, "state_paths": state_paths,
                       "synthesis": synthesis, "reachability": reach, "summary": summary,
                       "note": "phase oracle built from a classical lookup of all 2^n marks; "
                               "one circuit with 8 shots stands for 8 workers"}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
