"""Fingerprints of whole plans (tree, counters, history, status) for fixed seeds.

``fingerprint`` hashes everything a plan's numbers depend on except the wall time, so a change that
makes any planner draw, test or add differently changes the hash. ``CASES`` are the plans the
reference hashes in ``test_planner_fingerprints.py`` were computed on.
"""

from __future__ import annotations

import hashlib

import numpy as np

import qrrt_circuits as qc

#: the metrics hashed (the counters of DESIGN §2; wall time and later additions left out)
METRIC_KEYS = ("oracle_calls", "quantum_oracle_calls", "verification_calls", "critical_path_oracle_calls",
               "simulation_checks", "nodes", "rounds", "databases", "duplicates", "rejected")
#: the per-round history hashed (the keys that existed when the references were made)
HISTORY_KEYS = ("oracle_calls", "critical_path", "nodes", "entries", "reachable")


def fingerprint(result) -> str:
    digest = hashlib.sha256()
    digest.update(np.ascontiguousarray(result.nodes, dtype=np.float64).tobytes())
    digest.update(np.ascontiguousarray(result.parents, dtype=np.int64).tobytes())
    digest.update(repr([int(result.metrics[key]) for key in METRIC_KEYS]).encode())
    for key in HISTORY_KEYS:
        digest.update(key.encode())
        digest.update(np.ascontiguousarray(result.history[key], dtype=np.int64).tobytes())
    digest.update(str(result.status).encode())
    digest.update(repr(result.goal_node).encode())
    return digest.hexdigest()[:24]


def _sv(seed: int = 11):
    return qc.StatevectorBackend(seed=seed)


def _errors():
    return qc.OracleErrorModel(false_positive=0.1, false_negative=0.2)


def _clutter(seed):
    return qc.paper_clutter(seed=seed)


#: name -> (problem, planner factory, plan keywords)
CASES = {}
for _seed in range(6):
    CASES[f"rrt-clutter-{_seed}"] = (lambda s=_seed: _clutter(s), lambda s=_seed: qc.RRT(seed=s),
                                     {"max_nodes": 60})
for _seed, _calls in ((0, 1), (1, 37), (2, 150), (3, 401)):
    CASES[f"rrt-calls-{_seed}-{_calls}"] = (lambda s=_seed: _clutter(s), lambda s=_seed: qc.RRT(seed=s),
                                            {"max_oracle_calls": _calls})
CASES["rrt-rounds"] = (lambda: _clutter(4), lambda: qc.RRT(seed=4), {"max_rounds": 77})
CASES["rrt-stall"] = (lambda: _clutter(5), lambda: qc.RRT(seed=5), {"stall_rounds": 2, "max_nodes": 200})
CASES["rrt-critical"] = (lambda: _clutter(6), lambda: qc.RRT(seed=6), {"max_critical_path_calls": 55})
CASES["rrt-goal-bias"] = (lambda: _clutter(7), lambda: qc.RRT(seed=7, goal_bias=0.2), {"max_nodes": 300})
CASES["rrt-errors"] = (lambda: _clutter(8), lambda: qc.RRT(seed=8, oracle_errors=_errors()),
                       {"max_nodes": 60})
CASES["rrt-corridor"] = (lambda: qc.narrow_corridor(seed=1), lambda: qc.RRT(seed=1),
                         {"max_nodes": 80})
CASES["rrt-lattice"] = (lambda: qc.lattice(seed=2), lambda: qc.RRT(seed=2), {"max_nodes": 80})
for _seed in range(3):
    CASES[f"prrt-clutter-{_seed}"] = (lambda s=_seed: _clutter(s),
                                      lambda s=_seed: qc.ParallelRRT(workers=8, seed=s), {"max_nodes": 80})
CASES["prrt-calls"] = (lambda: _clutter(3), lambda: qc.ParallelRRT(workers=8, seed=3),
                       {"max_oracle_calls": 101})
CASES["prrt-3-stall"] = (lambda: _clutter(4), lambda: qc.ParallelRRT(workers=3, seed=4),
                         {"stall_rounds": 1, "max_nodes": 100})
CASES["prrt-errors"] = (lambda: _clutter(5), lambda: qc.ParallelRRT(workers=5, seed=5,
                                                                        oracle_errors=_errors()),
                        {"max_nodes": 60})
CASES["prrt-goal-bias"] = (lambda: _clutter(6), lambda: qc.ParallelRRT(workers=4, seed=6, goal_bias=0.1),
                           {"max_nodes": 200})
def _paper() -> qc.PaperIterations:
    """The paper's schedule, named: the cases fingerprint the paper's planners, whatever the default."""
    return qc.PaperIterations()


for _seed in range(3):
    CASES[f"qrrt-sv-{_seed}"] = (lambda s=_seed: _clutter(s),
                                 lambda s=_seed: qc.QRRT(backend=_sv(), num_qubits=6, seed=s,
                                                              search_policy=_paper()),
                                 {"max_nodes": 40})
CASES["qrrt-sv-calls"] = (lambda: _clutter(3), lambda: qc.QRRT(backend=_sv(), num_qubits=5, seed=3,
                                                                  search_policy=_paper()),
                          {"max_oracle_calls": 90})
CASES["qrrt-bbht"] = (lambda: _clutter(4), lambda: qc.QRRT(backend=_sv(), seed=4, search_policy=qc.BBHT()),
                      {"max_nodes": 30})
CASES["qrrt-adaptive"] = (lambda: _clutter(5),
                          lambda: qc.QRRT(backend=_sv(), seed=5, search_policy=qc.Adaptive()),
                          {"max_nodes": 30})
CASES["qrrt-optimal-errors"] = (lambda: _clutter(6),
                                lambda: qc.QRRT(backend=_sv(), seed=6, search_policy=qc.KnownOptimal(),
                                                    oracle_errors=_errors(), goal_bias=0.1),
                                {"max_nodes": 30})
CASES["qrrt-annealing"] = (lambda: qc.paper_clutter(seed=7),
                           lambda: qc.QRRT(backend=_sv(), seed=7, annealing=qc.AnnealingSchedule.paper(),
                                               search_policy=qc.FixedIterations(2)),
                           {"max_nodes": 30})
CASES["pqrrt-shared"] = (lambda: _clutter(8), lambda: qc.PQRRT(backend=_sv(), workers=8, seed=8,
                                                                  search_policy=_paper()),
                         {"max_nodes": 60})
CASES["pqrrt-unshared"] = (lambda: _clutter(9),
                           lambda: qc.PQRRT(backend=_sv(), workers=4, shared_database=False, seed=9,
                                                search_policy=_paper()),
                           {"max_nodes": 40})
CASES["pqrrt-shared-bbht-errors"] = (lambda: _clutter(10),
                                     lambda: qc.PQRRT(backend=_sv(), workers=4, seed=10,
                                                          search_policy=qc.BBHT(), oracle_errors=_errors()),
                                     {"max_oracle_calls": 200})

# trees past tree.BRUTE_FORCE_BELOW, so the grid answers the queries
CASES["rrt-large"] = (lambda: _clutter(13), lambda: qc.RRT(seed=13), {"max_nodes": 700, "goal_radius": 1e-9})
CASES["qrrt-sv-large"] = (lambda: _clutter(11), lambda: qc.QRRT(backend=_sv(), num_qubits=6, seed=11,
                                                                   search_policy=_paper()),
                          {"max_nodes": 700, "goal_radius": 1e-9})
CASES["pqrrt-shared-large"] = (lambda: _clutter(12), lambda: qc.PQRRT(backend=_sv(), workers=8, num_qubits=6,
                                                                        seed=12, search_policy=_paper()),
                               {"max_nodes": 700, "goal_radius": 1e-9})


def run_case(name: str):
    world, make, budgets = CASES[name]
    problem = world()
    budgets = dict(budgets)
    radius = budgets.pop("goal_radius", None)
    if radius is not None:  # the same goal centre with another radius
        problem = problem.with_goal_radius(radius)
    return make().plan(problem, **budgets)


if __name__ == "__main__":  # print the reference table
    for case in CASES:
        print(f"    {case!r}: {fingerprint(run_case(case))!r},")
