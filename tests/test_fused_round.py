"""The fused quantum round (planners/fused_round.py) gives the generic round's plans bit for bit,
is taken exactly where it applies, and refuses what the generic round refuses."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
import pytest
from planner_checks import assert_tree_edges_valid
from planner_fingerprints import fingerprint

import qrrt_circuits as qc
from qrrt_circuits.planners import fused_round
from qrrt_circuits.search.policies import PolicyState


@pytest.fixture()
def fused_calls(monkeypatch):
    """Counts the fused round's compiled calls (candidates, measurements) and the databases it
    hands to the backend's search_many."""
    calls = {"candidates": 0, "measure": 0, "searched": 0}
    candidates, measure = fused_round._candidates, fused_round._measure
    searched = fused_round.FusedRound._searched

    def counted_candidates(*args):
        calls["candidates"] += 1
        return candidates(*args)

    def counted_measure(*args):
        calls["measure"] += 1
        return measure(*args)

    def counted_searched(self, built, *args):
        calls["searched"] += len(built)
        return searched(self, built, *args)

    monkeypatch.setattr(fused_round, "_candidates", counted_candidates)
    monkeypatch.setattr(fused_round, "_measure", counted_measure)
    monkeypatch.setattr(fused_round.FusedRound, "_searched", counted_searched)
    return calls


def _sv(seed=5, **kw):
    return qc.StatevectorBackend(seed=seed, **kw)


class CountingPredicate:
    """The exact check, recording every batch it is asked (to compare the two rounds' calls)."""

    def __init__(self, env):
        self.inner = qc.ReachabilityOracle(env)
        self.batches = []

    dim = property(lambda self: self.inner.dim)
    name = property(lambda self: self.inner.name)

    def describe(self):
        return self.inner.describe()

    def reachable(self, parents, children):
        self.batches.append((np.array(parents), np.array(children)))
        return self.inner.reachable(parents, children)


#: planner factories (env, seed, fused) covering every feature the fused round handles
CONFIGURATIONS = {
    "qrrt-paper": lambda env, s, f: qc.QRRT(env, backend=_sv(), seed=s, fused_round=f),
    "qrrt-n5-fixed": lambda env, s, f: qc.QRRT(env, backend=_sv(), num_qubits=5, seed=s,
                                               search_policy=qc.FixedIterations(1), fused_round=f),
    "qrrt-n3-fixed0": lambda env, s, f: qc.QRRT(env, backend=_sv(), num_qubits=3, seed=s,
                                                search_policy=qc.FixedIterations(0), fused_round=f),
    "qrrt-adaptive": lambda env, s, f: qc.QRRT(env, backend=_sv(), num_qubits=6, seed=s,
                                               search_policy=qc.Adaptive(), fused_round=f),
    "qrrt-errors": lambda env, s, f: qc.QRRT(env, backend=_sv(), num_qubits=5, seed=s, fused_round=f,
                                             oracle_errors=qc.OracleErrorModel(0.1, 0.3)),
    "pqrrt-shared": lambda env, s, f: qc.PQRRT(env, backend=_sv(), workers=8, seed=s, fused_round=f),
    "pqrrt-shared-errors": lambda env, s, f: qc.PQRRT(env, backend=_sv(), workers=5, num_qubits=6, seed=s,
                                                      oracle_errors=qc.OracleErrorModel(0.2, 0.1), fused_round=f),
    "pqrrt-unshared": lambda env, s, f: qc.PQRRT(env, backend=_sv(), workers=3, shared_database=False, seed=s,
                                                 fused_round=f),
    "qrrt-known-optimal": lambda env, s, f: qc.QRRT(env, backend=_sv(), num_qubits=6, seed=s,
                                                    search_policy=qc.KnownOptimal(), fused_round=f),
    # the databases fused, the searches through the policy and the backend
    "pqrrt-unshared-bbht": lambda env, s, f: qc.PQRRT(env, backend=_sv(), workers=3, num_qubits=5, seed=s,
                                                      shared_database=False, search_policy=qc.BBHT(), fused_round=f),
    "qrrt-iterated": lambda env, s, f: qc.QRRT(env, backend=_sv(closed_form=False), num_qubits=5, seed=s,
                                               fused_round=f),
    "pqrrt-aer": lambda env, s, f: qc.PQRRT(env, backend=qc.AerBackend(seed=1), workers=4, num_qubits=4, seed=s,
                                            fused_round=f),
    "pqrrt-unshared-aer": lambda env, s, f: qc.PQRRT(env, backend=qc.AerBackend(seed=1), workers=3, num_qubits=4,
                                                     shared_database=False, seed=s, fused_round=f),
    "qrrt-aer-errors": lambda env, s, f: qc.QRRT(env, backend=qc.AerBackend(seed=1), num_qubits=5, seed=s,
                                                 search_policy=qc.KnownOptimal(), fused_round=f,
                                                 oracle_errors=qc.OracleErrorModel(0.1, 0.3)),
}

#: the configurations whose searches are drawn by the fused round itself
CLOSED_FORM = {"qrrt-paper", "qrrt-n5-fixed", "qrrt-n3-fixed0", "qrrt-adaptive", "qrrt-errors", "pqrrt-shared",
               "pqrrt-shared-errors", "pqrrt-unshared", "qrrt-known-optimal"}
#: the configurations whose backend searches (its search_many called by the fused round) and whose
#: measured indices the fused round verifies
BACKEND_SEARCHED = {"qrrt-iterated", "pqrrt-aer", "pqrrt-unshared-aer", "qrrt-aer-errors"}


@pytest.mark.parametrize("name", sorted(CONFIGURATIONS))
@pytest.mark.parametrize("seed", range(3))
def test_fused_round_gives_the_generic_plan(name, seed, fused_calls):
    env = qc.scenarios.paper_clutter(seed=seed)
    make = CONFIGURATIONS[name]
    fused = make(env, seed, True).plan(max_nodes=40)
    assert fused_calls["candidates"] == fused.metrics.databases > 0
    assert fused_calls["measure"] == (fused.metrics.databases if name in CLOSED_FORM else 0)
    assert fused_calls["searched"] == (fused.metrics.databases if name in BACKEND_SEARCHED else 0)
    generic = make(env, seed, False).plan(max_nodes=40)
    assert fused_calls["candidates"] == fused.metrics.databases  # the generic plan made none
    assert fingerprint(fused) == fingerprint(generic)
    counters = [{k: v for k, v in r.metrics.as_dict().items() if k != "wall_time_s"} for r in (fused, generic)]
    assert counters[0] == counters[1]
    assert fused.labels == generic.labels and fused.settings == generic.settings
    assert_tree_edges_valid(env, qc.LinearTrackingDynamics.paper(), fused)


def test_the_predicate_sees_the_same_batches():
    env = qc.scenarios.paper_clutter(seed=2)
    seen = {}
    for fused in (True, False):
        predicate = CountingPredicate(env)
        qc.PQRRT(env, backend=_sv(), workers=4, shared_database=False, predicate=predicate, seed=2,
                 fused_round=fused).plan(max_nodes=25)
        seen[fused] = predicate.batches
    assert len(seen[True]) == len(seen[False]) > 0
    for (p1, c1), (p2, c2) in zip(seen[True], seen[False], strict=True):
        assert np.array_equal(p1, p2) and np.array_equal(c1, c2)


def test_large_trees_use_the_grid_and_still_agree(fused_calls):
    """Past tree.BRUTE_FORCE_BELOW nodes the nearest nodes come from the grid inside the fused call."""
    env = qc.scenarios.paper_clutter(seed=1)
    nodes = qc.tree.BRUTE_FORCE_BELOW + 60
    results = [qc.QRRT(env, backend=_sv(), num_qubits=5, seed=1, fused_round=fused).plan(max_nodes=nodes,
                                                                                       goal_radius=1e-9)
               for fused in (True, False)]
    assert results[0].metrics.nodes == nodes
    assert fused_calls["candidates"] == results[0].metrics.databases  # the fused plan's rounds, all of them
    assert fingerprint(results[0]) == fingerprint(results[1])


def _uses_fused(planner) -> bool:
    return planner._fused_round() is not None


def _closed_form(planner) -> bool:
    return planner._fused_round().closed_form


def test_fused_round_taken_only_where_it_applies():
    env = qc.scenarios.paper_clutter(seed=0)
    assert _uses_fused(qc.QRRT(env, backend=_sv(), seed=0))
    assert _uses_fused(qc.PQRRT(env, backend=_sv(), workers=4, shared_database=False, seed=0))
    assert not _uses_fused(qc.QRRT(env, backend=_sv(), seed=0, fused_round=False))
    assert _uses_fused(qc.QRRT(env, backend=qc.AerBackend(seed=0), seed=0))  # the databases only
    assert not _closed_form(qc.QRRT(env, backend=qc.AerBackend(seed=0), seed=0))
    assert not _closed_form(qc.QRRT(env, backend=_sv(closed_form=False), seed=0))
    assert _closed_form(qc.QRRT(env, backend=_sv(), seed=0))
    assert not _uses_fused(qc.QRRT(env, backend=_sv(), seed=0, goal_bias=0.1))
    assert not _uses_fused(qc.QRRT(env, backend=_sv(), seed=0, annealing=qc.AnnealingSchedule.paper()))
    with ThreadPoolExecutor(2) as pool:
        assert not _uses_fused(qc.PQRRT(env, backend=_sv(), workers=2, shared_database=False, executor=pool,
                                        seed=0))

    class Tilted(qc.StatevectorBackend):  # a subclass that draws differently keeps its own search
        def _sample_seeded(self, marks, num_qubits, iterations, shots, seed):
            return np.zeros(shots, dtype=np.int64)

    assert not _closed_form(qc.QRRT(env, backend=Tilted(), seed=0))
    assert qc.StatevectorBackend().draws_closed_form(32) and not qc.StatevectorBackend().draws_closed_form(33)


def test_policy_states_say_whether_they_search_by_default():
    for policy in (qc.PaperSchedule(), qc.FixedIterations(2), qc.KnownOptimal(), qc.Adaptive()):
        assert policy.start(256).searches_by_default(), policy
    for policy in (qc.BBHT(), qc.FixedPointAmplification(), qc.EstimatedOptimal()):
        assert not policy.start(256).searches_by_default(), policy

    class OwnRun(PolicyState):
        def run(self, problem, workers, tree_nodes):
            return super().run(problem, workers, tree_nodes)

    class OwnRunMany(PolicyState):
        def run_many(self, problems, workers, tree_nodes):
            return super().run_many(problems, workers, tree_nodes)

    assert not OwnRun(qc.PaperSchedule(), 256).searches_by_default()
    assert not OwnRunMany(qc.PaperSchedule(), 256).searches_by_default()


def test_the_database_reading_policy_is_drawn_by_the_fused_round_too(fused_calls):
    env = qc.scenarios.paper_clutter(seed=3)
    result = qc.QRRT(env, backend=_sv(), seed=3, search_policy=qc.KnownOptimal()).plan(max_nodes=10)
    assert result.metrics.nodes == 10
    assert fused_calls["candidates"] == fused_calls["measure"] == result.metrics.databases


@dataclass(frozen=True)
class CyclingIterations(qc.FixedIterations):
    """k = 0, 1, 2, 3, 0, ... each time the policy is asked (stands for any k drawn per database)."""

    asked: list = field(default_factory=lambda: [0], compare=False)

    def _iterations(self, num_items, tree_nodes, num_marked):
        self.asked[0] += 1
        return self.asked[0] % 4

    def iterations_bound(self, num_items):
        return 3


class ChoosesOne(PolicyState):
    """A state that overrides only ``choose_iterations`` (the default round never asks it)."""

    def choose_iterations(self, tree_nodes, num_marked=None):
        return 1


@dataclass(frozen=True)
class ChoosingOne(qc.PaperSchedule):
    def start(self, num_items):
        return ChoosesOne(self, num_items)


@pytest.mark.parametrize("shared", [True, False], ids=["shared", "unshared"])
@pytest.mark.parametrize("make_policy", [CyclingIterations, ChoosingOne], ids=["asked-per-database", "own-choice"])
def test_k_is_asked_as_the_generic_round_asks_it(shared, make_policy):
    """k comes from iterations_for on each database, in order, as run_many asks it: a policy with
    state, or a state overriding another method, gives the generic round's plan."""
    env = qc.scenarios.paper_clutter(seed=0)
    results = [qc.PQRRT(env, backend=_sv(), num_qubits=5, workers=4, shared_database=shared,
                        search_policy=make_policy(), seed=0, fused_round=fused).plan(max_nodes=30)
               for fused in (True, False)]
    assert results[0].metrics.nodes >= 30  # (an unshared round may add several)
    assert fingerprint(results[0]) == fingerprint(results[1])


class Answering:
    """The exact check, its answers passed through ``transform`` (a predicate that answers oddly)."""

    def __init__(self, env, transform):
        self.inner = qc.ReachabilityOracle(env)
        self.transform = transform

    dim = property(lambda self: self.inner.dim)
    name = "answering"

    def describe(self):
        return {"name": self.name}

    def reachable(self, parents, children):
        return self.transform(self.inner.reachable(parents, children))


class ReusedBuffer:
    """Answers written into one reused uint8 buffer (returned every call)."""

    def __init__(self):
        self.buffer = None

    def __call__(self, answers):
        if self.buffer is None or len(self.buffer) != len(answers):
            self.buffer = np.empty(len(answers), dtype=np.uint8)
        self.buffer[:] = answers
        return self.buffer


#: answers both rounds accept (and plan alike with) ...
ACCEPTED = {"list": lambda a: a.tolist(), "ints": lambda a: a.astype(np.int64), "floats": lambda a: a.astype(float),
            "reused-uint8-buffer": ReusedBuffer()}
#: ... and answers both refuse, with the message
REFUSED = {"one-short": (lambda a: a[:-1], "shape"), "half": (lambda a: a[: len(a) // 2], "shape"),
           "double": (lambda a: np.concatenate([a, a]), "shape"), "column": (lambda a: a[:, None], "shape"),
           "scalar": (lambda a: True, "shape"), "halves": (lambda a: np.full(len(a), 0.5), "0/1")}


@pytest.mark.parametrize("name", sorted(ACCEPTED))
def test_both_rounds_accept_the_same_answers(name):
    env = qc.scenarios.paper_clutter(seed=1)
    results = [qc.PQRRT(env, backend=_sv(), num_qubits=5, workers=3, shared_database=False, seed=1,
                        predicate=Answering(env, ACCEPTED[name]), fused_round=fused).plan(max_nodes=25)
               for fused in (True, False)]
    reference = qc.PQRRT(env, backend=_sv(), num_qubits=5, workers=3, shared_database=False, seed=1,
                         fused_round=False).plan(max_nodes=25)
    assert fingerprint(results[0]) == fingerprint(results[1]) == fingerprint(reference)


@pytest.mark.parametrize("errors", [False, True], ids=["exact-marks", "oracle-errors"])
@pytest.mark.parametrize("fused", [True, False], ids=["fused", "generic"])
@pytest.mark.parametrize("name", sorted(REFUSED))
def test_both_rounds_refuse_the_same_answers(name, fused, errors):
    transform, message = REFUSED[name]
    env = qc.scenarios.paper_clutter(seed=0)
    planner = qc.QRRT(env, backend=_sv(), num_qubits=4, predicate=Answering(env, transform), seed=0,
                      oracle_errors=qc.OracleErrorModel(0.1, 0.1) if errors else None, fused_round=fused)
    with pytest.raises(ValueError, match=f"predicate 'answering' answered.*{message}"):
        planner.plan(max_rounds=3)


@pytest.mark.parametrize("name", sorted(REFUSED) + ["strings", "nans"])
@pytest.mark.parametrize("planner", ["rrt", "rrt-goal-bias", "prrt", "prrt-executor"])
def test_classical_planners_refuse_the_answers_the_quantum_rounds_refuse(planner, name):
    """RRT and ParallelRRT (batched rounds, and the extensions an executor runs) check a predicate's
    answers as the quantum rounds do (before, answers of "no" or NaN counted as reachable and added
    nodes)."""
    from concurrent.futures import ThreadPoolExecutor

    transform, message = {**REFUSED, "strings": (lambda a: np.array(["no"] * len(a)), "0/1"),
                          "nans": (lambda a: np.full(len(a), np.nan), "0/1")}[name]
    env = qc.scenarios.paper_clutter(seed=0)
    predicate = Answering(env, transform)
    with ThreadPoolExecutor(2) as pool:
        made = {"rrt": lambda: qc.RRT(env, predicate=predicate, seed=0),
                "rrt-goal-bias": lambda: qc.RRT(env, predicate=predicate, seed=0, goal_bias=0.2),
                "prrt": lambda: qc.ParallelRRT(env, workers=3, predicate=predicate, seed=0),
                "prrt-executor": lambda: qc.ParallelRRT(env, workers=3, predicate=predicate, seed=0, executor=pool),
                }[planner]()
        with pytest.raises(ValueError, match=f"predicate 'answering' answered.*{message}"):
            made.plan(max_rounds=3)


@pytest.mark.parametrize("name", sorted(ACCEPTED))
def test_classical_planners_accept_what_the_quantum_rounds_accept(name):
    env = qc.scenarios.paper_clutter(seed=1)
    result = qc.ParallelRRT(env, workers=3, predicate=Answering(env, ACCEPTED[name]), seed=1).plan(max_nodes=15)
    reference = qc.ParallelRRT(env, workers=3, seed=1).plan(max_nodes=15)
    assert fingerprint(result) == fingerprint(reference)


def test_fused_round_flag_is_checked():
    env = qc.scenarios.paper_clutter(seed=0)
    with pytest.raises(TypeError, match="fused_round"):
        qc.QRRT(env, backend=_sv(), fused_round=1)


def test_learn_feeds_every_observation_to_a_state_that_observes():
    """``learn`` skips its loop only for the no-op ``observe``; a state that observes sees them all, in order."""

    class Recording(PolicyState):
        def __init__(self, policy, num_items):
            super().__init__(policy, num_items)
            self.seen = []

        def observe(self, iterations, success):
            self.seen.append((iterations, success))

    outcomes = [qc.SearchOutcome(3, 2, 1, ((2, True),)), qc.SearchOutcome(None, 4, 2, ((2, False), (2, False)))]
    state = Recording(qc.FixedIterations(2), 64)
    state.learn(iter(outcomes))
    assert state.seen == [(2, True), (2, False), (2, False)]
    consumed = []
    PolicyState(qc.FixedIterations(2), 64).learn(consumed.append(o) or o for o in outcomes)
    assert consumed == []  # the no-op observe: the outcomes are not even read


@pytest.mark.parametrize("fused", [True, False], ids=["fused", "generic"])
def test_bbht_ends_on_two_entry_databases_with_nothing_marked(fused):
    """N = 2: BBHT's range [0, M) never reaches 1, so every attempt runs 0 iterations and the
    iteration cap is never spent; each worker now stops after cap attempts (it looped forever)."""
    env = qc.scenarios.paper_clutter(seed=0)
    nothing = Answering(env, lambda answers: np.zeros_like(answers))
    result = qc.QRRT(env, backend=_sv(), num_qubits=1, search_policy=qc.BBHT(), predicate=nothing, seed=0,
                     fused_round=fused).plan(max_rounds=5)
    cap = qc.BBHT().cap(2)
    assert cap == 7 and result.metrics.rounds == 5 and result.metrics.nodes == 0
    assert result.metrics.verification_calls == 5 * cap and result.metrics.quantum_oracle_calls == 0


@dataclass(frozen=True)
class NumpyIterations(qc.FixedIterations):
    """k as a numpy uint8 (it used to leak into the counters, which then wrapped at 256)."""

    def _iterations(self, num_items, tree_nodes, num_marked):
        return np.uint8(self.k)


@pytest.mark.parametrize("fused", [True, False], ids=["fused", "generic"])
def test_a_numpy_integer_k_is_counted_as_an_int(fused):
    env = qc.scenarios.paper_clutter(seed=2)
    result = qc.QRRT(env, backend=_sv(), num_qubits=5, search_policy=NumpyIterations(3), seed=2,
                     fused_round=fused).plan(max_rounds=200, goal_radius=1e-9)
    assert type(result.metrics.quantum_oracle_calls) is int
    assert result.metrics.quantum_oracle_calls == 3 * result.metrics.rounds == 600


@pytest.mark.parametrize("seed", range(6))
def test_a_closed_form_tally_is_the_worker_by_worker_tally(seed):
    """``ClosedFormOutcome.tally`` (arrays) counts what ``DatabaseOutcome.tally`` counts from the
    same workers' ``SearchOutcome`` objects: calls, rejections, the longest worker, duplicates and
    the candidates added in worker order."""
    from qrrt_circuits.planners.workers import DatabaseOutcome
    from qrrt_circuits.randomness import RandomStreams
    from qrrt_circuits.search.problem import SearchOutcome

    rng = np.random.default_rng(seed)
    size = 16
    truth = rng.random(size) < 0.3
    truth[0] = True
    marks = truth ^ (rng.random(size) < 0.2)  # some wrong marks: measured entries that do not verify
    marks[0] = True
    entropy = RandomStreams.from_seed(seed)._run_entropy
    workers, k = 40, int(rng.integers(0, 4))
    children, parents = rng.random((size, 2)), rng.integers(0, 50, size)
    indices, added, reachable, good = fused_round._measure(
        entropy, 3, 0, marks, truth, 0, workers)  # k = 0: P(G) = m/N, many verify
    verified = truth[indices]
    assert reachable == int(truth.sum()) and good == int(verified.sum())
    first_verified = list(dict.fromkeys(indices[verified].tolist()))  # in worker order, each entry once
    assert added.tolist() == first_verified
    outcome = fused_round.ClosedFormOutcome(size, reachable, k, indices, truth, added, children, parents,
                                            SearchOutcome(None, k, 1, ((k, False),)), good)
    assert np.array_equal(outcome.verified, verified)
    assert np.array_equal(outcome.added_children, children[added])
    assert np.array_equal(outcome.added_parents, parents[added])
    assert verified.any() and not verified.all() and len(set(indices[verified].tolist())) < verified.sum()
    generic = DatabaseOutcome(size, int(truth.sum()), outcome.outcomes, outcome.found)
    fast, slow = outcome.tally(), generic.tally()
    assert fast[:5] == slow[:5]
    assert np.array_equal(fast[5], slow[5]) and np.array_equal(fast[6], slow[6])
    assert fast[0] == workers * k and fast[1] == workers and fast[3] == k + 1


class OutOfRange(qc.StatevectorBackend):
    """A backend whose search measures an index outside the database (a faulty subclass)."""

    def __init__(self, index):
        super().__init__(seed=0)
        self.index = index

    def _sample_seeded(self, marks, num_qubits, iterations, shots, seed):
        return np.full(shots, self.index, dtype=np.int64)


@pytest.mark.parametrize("index", [16, -1, 100_000_000])
@pytest.mark.parametrize("fused", [True, False])
def test_a_backend_measuring_outside_the_database_is_refused(index, fused):
    """Both rounds refuse indices outside [0, 2^n) with the backend named (the fused round used to
    read them inside a compiled call: a wrong plan, or a crash for a far index)."""
    env = qc.scenarios.paper_clutter(seed=0)
    planner = qc.QRRT(env, backend=OutOfRange(index), num_qubits=4, seed=0, fused_round=fused)
    with pytest.raises(RuntimeError, match=r"outside \[0, 16\)"):
        planner.plan(max_nodes=5)
