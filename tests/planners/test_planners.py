import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from conftest import BACKENDS, make_backend
from planner_checks import assert_path_valid, assert_tree_edges_valid, posed
from tolerances import binomial_counts, z_bound

import qrrt_circuits as qc
from qrrt_circuits.registry import PLANNERS
from qrrt_circuits.world.environment import Environment

METRIC_KEYS = {"oracle_calls", "quantum_oracle_calls", "verification_calls",
               "critical_path_oracle_calls", "simulation_checks", "nodes", "rounds", "databases",
               "duplicates", "rejected", "wall_time_s", "wasted_checks"}


def make(name, seed, **kw):
    """The registry's planner ``name`` on the exact statevector, 8 workers where it has workers."""
    defaults = {"seed": seed, "workers": 8, "backend": qc.StatevectorBackend(seed=seed)}
    takes = PLANNERS.resolve(name).options()
    return PLANNERS.create(name, **{key: value for key, value in defaults.items() if key in takes}, **kw)


PLANNER_NAMES = list(PLANNERS)  # every registered planner


@pytest.mark.parametrize("name", PLANNER_NAMES)
def test_metrics_identities_and_every_edge_rechecked(name, clutter):
    result = make(name, seed=3).plan(clutter, max_nodes=60)
    m = result.metrics
    assert set(m.keys()) == METRIC_KEYS
    assert m.oracle_calls == m.quantum_oracle_calls + m.verification_calls
    assert m.nodes == len(result.nodes) - 1 and result.parents[0] == -1
    assert m.rounds == len(result.history["oracle_calls"])
    assert m.critical_path_oracle_calls <= m.oracle_calls
    assert_tree_edges_valid(clutter.env, qc.LinearTrackingDynamics.paper(), result)
    assert_path_valid(result)
    graph = result.tree
    assert graph.number_of_nodes() == m.nodes + 1 and graph.number_of_edges() == m.nodes
    assert graph.nodes[0]["pos"] == tuple(result.nodes[0])


def test_rrt_oracle_calls_are_its_reachability_tests(clutter):
    problem = clutter.replace(predicate=qc.ExactCheck(clutter.env))  # its own count of evaluations
    result = qc.RRT(seed=1).plan(problem, max_rounds=300)
    assert result.metrics.oracle_calls == 300 == result.metrics.rounds
    # batched rounds: every evaluation is a round's test or a dropped test of a later round
    assert problem.predicate.evaluations == 300 + result.metrics.wasted_checks
    assert result.metrics.quantum_oracle_calls == 0 and result.metrics.simulation_checks == 0


def test_parallel_rrt_counts_per_worker_and_critical_path(clutter):
    result = qc.ParallelRRT(workers=5, seed=2).plan(clutter, max_rounds=40)
    assert result.metrics.oracle_calls == 200
    assert result.metrics.critical_path_oracle_calls == 40


def test_quantum_counting_with_fixed_iterations(clutter):
    k, p, rounds = 3, 4, 25
    result = qc.PQRRT(backend=qc.StatevectorBackend(seed=0), workers=p,
                      search_policy=qc.FixedIterations(k), seed=0).plan(clutter, max_rounds=rounds)
    m = result.metrics
    assert m.quantum_oracle_calls == rounds * p * k
    assert m.verification_calls == rounds * p
    assert m.critical_path_oracle_calls == rounds * (k + 1)
    assert m.simulation_checks == rounds * 256 and m.databases == rounds
    assert m.nodes + m.duplicates + m.rejected == rounds * p
    unshared = qc.PQRRT(backend=qc.StatevectorBackend(seed=0), workers=p,
                        shared_database=False, search_policy=qc.FixedIterations(k),
                        seed=0).plan(clutter, max_rounds=rounds)
    assert unshared.metrics.databases == rounds * p
    assert unshared.metrics.simulation_checks == rounds * p * 256
    assert unshared.metrics.duplicates == 0


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_qrrt_adds_nodes_at_the_grover_rate(backend_name, clutter):
    """Each q-RRT round adds a node with probability sin^2((2k+1) theta_r), sin^2 theta_r = m_r/N,
    m_r the round's reachable entries (from the history): the node count must lie in the Poisson-
    binomial interval of the rounds' probabilities (normal bound with the exact variance)."""
    k, rounds, observed, mean, variance = 2, 120, 0, 0.0, 0.0
    for seed in range(3):
        result = qc.QRRT(backend=make_backend(backend_name, seed), search_policy=qc.FixedIterations(k),
                         seed=seed).plan(clutter, max_rounds=rounds)
        p = np.array([qc.probability.success_probability(256, int(m), k) for m in result.history["reachable"]])
        observed += result.metrics.nodes
        mean += p.sum()
        variance += (p * (1 - p)).sum()
        assert result.metrics.rejected == rounds - result.metrics.nodes
    assert abs(observed - mean) <= z_bound() * math.sqrt(variance)


def test_shared_database_duplicates_are_dropped(clutter):
    # 32 workers on a 16-entry database: many measure the same solution
    result = qc.PQRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=4, workers=32,
                      search_policy=qc.FixedIterations(1), seed=0).plan(clutter, max_rounds=20)
    assert result.metrics.duplicates > 0
    rows = {tuple(row) for row in result.nodes}
    assert len(rows) == len(result.nodes)


@pytest.mark.parametrize("backend_name", ["aer", "statevector"])
def test_same_seed_same_tree(backend_name, clutter):
    def run():
        backend = qc.AerBackend() if backend_name == "aer" else qc.StatevectorBackend()
        return qc.PQRRT(backend=backend, workers=4, seed=9).plan(clutter, max_rounds=15)

    a, b = run(), run()
    assert np.array_equal(a.nodes, b.nodes) and np.array_equal(a.parents, b.parents)
    assert a.metrics.oracle_calls == b.metrics.oracle_calls


@pytest.mark.parametrize("name", ["ParallelRRT", "PQRRT-unshared"])
def test_executor_does_not_change_the_result(name, clutter):
    serial = make(name, seed=4).plan(clutter, max_rounds=12)
    with ThreadPoolExecutor(max_workers=3) as pool:
        threaded = make(name, seed=4, executor=pool).plan(clutter, max_rounds=12)
    assert np.array_equal(serial.nodes, threaded.nodes)
    assert serial.metrics.oracle_calls == threaded.metrics.oracle_calls


@pytest.mark.parametrize("name", ["ParallelRRT", "PQRRT-unshared"])
def test_process_pool_executor_gives_the_serial_result(name, clutter):
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    serial = make(name, seed=6).plan(clutter, max_rounds=4)
    with ProcessPoolExecutor(max_workers=2, mp_context=multiprocessing.get_context("spawn")) as pool:
        parallel = make(name, seed=6, executor=pool).plan(clutter, max_rounds=4)
    assert np.array_equal(serial.nodes, parallel.nodes)
    assert serial.metrics.oracle_calls == parallel.metrics.oracle_calls


def test_unreachable_goal_ends_without_reaching():
    # the goal is walled in: no plan can reach it
    boxes = np.array([[[14, 14], [18, 14.5]], [[14, 17.5], [18, 18]], [[14, 14], [14.5, 18]],
                      [[17.5, 14], [18, 18]]], dtype=float)
    env = Environment(np.array([[0, 20], [0, 20]]), boxes)
    for planner in (qc.RRT(seed=0), qc.QRRT(backend=qc.StatevectorBackend(0), seed=0)):
        result = planner.plan(posed(env, start=[2, 2], goal=[16, 16], goal_radius=0.5), max_oracle_calls=400)
        assert result.status == qc.PlanStatus.MAX_ORACLE_CALLS == "max_oracle_calls"
        assert result.path is None and not result.reached
        assert 400 <= result.metrics.oracle_calls < 400 + 7


def test_default_round_limit_ends_a_plan_with_no_budget(monkeypatch):
    """With no budget at all the plan still ends, after DEFAULT_MAX_ROUNDS rounds (the goal is
    walled in, so only the round limit can end it)."""
    from qrrt_circuits.planners import termination

    monkeypatch.setattr(termination, "DEFAULT_MAX_ROUNDS", 17)
    boxes = np.array([[[14, 14], [18, 14.5]], [[14, 17.5], [18, 18]], [[14, 14], [14.5, 18]],
                      [[17.5, 14], [18, 18]]], dtype=float)
    env = Environment(np.array([[0, 20], [0, 20]]), boxes)
    result = qc.RRT(seed=0).plan(posed(env, start=[1, 1], goal=[16, 16], goal_radius=0.5))
    assert result.status == "max_rounds" and result.metrics.rounds == 17
    assert result.settings["termination"] == {"max_rounds": 17, "stall_rounds": termination.DEFAULT_STALL_ROUNDS,
                                              "max_nodes": termination.DEFAULT_MAX_NODES}


def test_bbht_terminates_with_no_solution_and_respects_its_bound():
    policy = qc.BBHT()
    backend = qc.StatevectorBackend(seed=0)
    rng = np.random.default_rng(0)
    size = 256
    none = np.zeros(size, dtype=bool)
    out = policy.run(lambda j: int(backend.search(qc.LookupOracle(none), j, 1).indices[0]), lambda i: False, size, rng)
    assert out.index is None and out.iterations <= policy.cap(size)
    for m in (1, 4, 16):
        marks = np.zeros(size, dtype=bool)
        marks[rng.choice(size, m, replace=False)] = True
        costs = []
        for _ in range(300):
            out = policy.run(lambda j, mk=marks: int(backend.search(qc.LookupOracle(mk), j, 1).indices[0]),
                             lambda i, mk=marks: bool(mk[i]), size, rng)
            costs.append(out.iterations)
        costs = np.array(costs)
        bound = 9 / 4 * math.sqrt(size / m)
        assert costs.mean() <= bound + 5 * costs.std() / math.sqrt(len(costs)) + 1


def test_known_optimal_is_labelled_and_adaptive_is_not(clutter):
    known = qc.QRRT(backend=qc.StatevectorBackend(0), search_policy=qc.KnownOptimal(),
                    seed=0).plan(clutter, max_rounds=5)
    assert any("true marked count" in label for label in known.labels)
    adaptive = qc.QRRT(backend=qc.StatevectorBackend(0), search_policy=qc.Adaptive(),
                       seed=0).plan(clutter, max_rounds=5)
    assert not any("true marked count" in label for label in adaptive.labels)
    assert any("classical lookup" in label for label in adaptive.labels)


@pytest.mark.parametrize("marked", [3, 25, 90])
def test_adaptive_posterior_covers_the_hidden_fraction_and_picks_its_argmax(marked):
    """From verified outcomes alone, Adaptive's posterior over f = m/N contains the hidden f in its
    central 99 % credible interval at least as often as a calibrated posterior would (its forgetting
    only widens it), and the k it picks maximises expected success per oracle call under it."""
    runs, covered = 40, 0
    for run in range(runs):
        state = qc.Adaptive().start(256)
        rng = np.random.default_rng([marked, run])
        for _ in range(150):
            k = state.choose_iterations(tree_nodes=50)
            state.observe(k, bool(rng.random() < qc.probability.success_probability(256, marked, k)))
        weights = np.exp(state.log_posterior - state.log_posterior.max())
        cdf = np.cumsum(weights) / weights.sum()
        low, high = state.fractions[np.searchsorted(cdf, 0.005)], state.fractions[np.searchsorted(cdf, 0.995)]
        covered += int(low <= marked / 256 <= high)
        theta = np.arcsin(np.sqrt(state.fractions))
        expected = [np.sum(weights * np.sin((2 * j + 1) * theta) ** 2) / weights.sum() / (j + 1)
                    for j in state.candidates]
        assert state.choose_iterations(50) == int(np.argmax(expected))
    assert covered >= binomial_counts(runs, 0.99)[0]


def test_annealing_first_band_distance(clutter):
    schedule = qc.AnnealingSchedule(bands=[(2.7, 4.2), (0.8, 2.0)], switch_at=[1000])
    planner = qc.QRRT(backend=qc.StatevectorBackend(0), search_policy=qc.FixedIterations(2),
                      annealing=schedule, seed=0)
    result = planner.plan(clutter, max_nodes=25)
    distances = np.linalg.norm(result.nodes[1:] - result.nodes[result.parents[1:]], axis=1)
    assert 2.7 <= distances.min() and distances.max() <= 4.2
    assert abs(distances.mean() - 3.45) < 5 * (1.5 / math.sqrt(12)) / math.sqrt(len(distances))
    assert schedule.band(999) == (2.7, 4.2) and schedule.band(1000) == (0.8, 2.0)


@pytest.mark.parametrize("kwargs, message", [
    ({"start": [-1, 5]}, r"start \[-1.0, 5.0\] is out of bounds"),
    ({"goal": [30, 5]}, "goal .* is out of bounds"),
    ({"goal_radius": 0}, "goal_radius must be"),
    ({"goal_radius": -2}, "goal_radius must be"),
    ({"start": [1, 2, 3]}, "dimension mismatch: start has 3 coordinates"),
])
def test_bad_problem_input(kwargs, message, clutter):
    arguments = {"start": clutter.start, "goal": clutter.goal.centre, "goal_radius": 0.75} | kwargs
    with pytest.raises(ValueError, match=message):
        qc.Problem.build(clutter.env, **arguments)


def test_bad_plan_input(clutter):
    with pytest.raises(ValueError, match="max_nodes must be an integer >= 1"):
        qc.RRT(seed=0).plan(clutter, max_nodes=0)
    with pytest.raises(TypeError, match="problem must be a Problem"):
        qc.RRT(seed=0).plan(clutter.env, max_nodes=3)
    with pytest.raises(TypeError, match="takes 2 positional arguments|positional"):
        qc.RRT(seed=0).plan(clutter, None, 100)  # the budgets are keyword-only


def test_start_or_goal_in_collision_names_which(clutter):
    inside = clutter.env.boxes[0].mean(axis=0)
    with pytest.raises(ValueError, match="start .* is in collision"):
        qc.RRT().plan(posed(clutter, start=inside))
    with pytest.raises(ValueError, match="goal .* is in collision"):
        qc.QRRT(backend=qc.StatevectorBackend(0)).plan(posed(clutter, goal=inside))


def test_bad_planner_settings(clutter):
    with pytest.raises(ValueError, match=r"workers must be an integer in \[1, 4096\], got 0"):
        qc.PQRRT(backend=qc.StatevectorBackend(0), workers=0)
    with pytest.raises(ValueError, match=r"workers must be an integer in \[1, 4096\], got 0"):
        qc.ParallelRRT(workers=0)
    with pytest.raises(TypeError, match="workers must be an integer"):
        qc.ParallelRRT(workers=2.5)
    with pytest.raises(ValueError, match="num_qubits = 40 is outside"):
        qc.QRRT(backend=qc.StatevectorBackend(0), num_qubits=40)
    with pytest.raises(ValueError, match=r"r_min must be <= r_max"):
        qc.AnnealingSchedule(bands=[(3.0, 1.0)])
    with pytest.raises(ValueError, match="switch_at"):
        qc.AnnealingSchedule(bands=[(1.0, 2.0), (0.5, 1.0)], switch_at=[])
    with pytest.raises(ValueError, match="dimension mismatch"):
        qc.Problem.build(clutter.env, clutter.start, clutter.goal,
                         dynamics=qc.LinearTrackingDynamics(-np.eye(3), np.eye(3), np.zeros((3, 3))))
    with pytest.raises(TypeError, match="RRT does not take dynamics"):
        qc.RRT(dynamics=qc.LinearTrackingDynamics.paper())
    with pytest.raises(ValueError, match="k must be an integer"):
        qc.FixedIterations(-1)
