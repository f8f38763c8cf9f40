"""The memory guard: a plan or a direct search whose estimated peak exceeds the available memory is
refused by one check before anything large is allocated, naming the size, the estimate, the
available memory (the smallest of MemAvailable, the control groups' room and the address space
left under RLIMIT_AS) and the largest size that fits; a MemoryError while one runs is one line."""

import functools
import re
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits import cli
from qrrt_circuits._support import available_memory as probe
from qrrt_circuits._support import memory

MIB = 1 << 20


@pytest.fixture(scope="module")
def env():
    return qc.paper_clutter(seed=0)


@pytest.fixture
def small_memory(monkeypatch):
    """The machine reports 300 MiB available (machine-independent refusals)."""
    monkeypatch.setattr(probe, "available_memory", lambda: (300 * MIB, probe.MACHINE_SOURCE))
    return 300 * MIB


def _plan_total(planner, num_qubits, max_rounds=1):
    """The plan's estimate (its round and its tree and history) at ``max_rounds`` and n."""
    return memory.PlanSize(10**6, planner.workers, max_rounds, 2, functools.partial(planner.memory_estimate, dim=2),
                           num_qubits).estimate().total_bytes


def _peak_rss() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _largest(message: str) -> int:
    return int(re.search(r"the largest num_qubits that fits is (\d+)", message).group(1))


@pytest.mark.parametrize("make_backend", [lambda: qc.StatevectorBackend(0), lambda: qc.AerBackend(0)],
                         ids=["statevector", "aer"])
def test_plan_refused_before_its_first_allocation_with_the_largest_fitting_n(env, small_memory, make_backend):
    backend = make_backend()
    planner = qc.PQRRT(backend=backend, num_qubits=28, seed=0)  # construction allocates nothing
    before = _peak_rss()
    with pytest.raises(ValueError, match=r"num_qubits = 28: this plan could need about .* at its peak .*more "
                                         r"than the 300 MiB of memory available \(MemAvailable\)") as info:
        planner.plan(env, max_rounds=1)
    assert _peak_rss() - before < 64 * MIB  # refused before the 2^28-entry database was built
    largest = _largest(str(info.value))
    assert _plan_total(planner, largest) <= small_memory < _plan_total(planner, largest + 1)


def test_the_estimate_grows_with_what_the_run_holds(env):
    sv = qc.StatevectorBackend(0)
    paper = qc.PaperIterations()  # at most 5 iterations: fewer than the 20 below
    base = qc.QRRT(backend=sv, num_qubits=10, seed=0, search_policy=paper).memory_estimate(24, dim=2)
    annealed = qc.QRRT(backend=sv, num_qubits=10, seed=0, search_policy=paper,
                       annealing=qc.AnnealingSchedule.paper()).memory_estimate(24, dim=2)
    aer = qc.QRRT(backend=qc.AerBackend(0), num_qubits=10, seed=0, search_policy=paper).memory_estimate(24, dim=2)
    aer_more_k = qc.QRRT(backend=qc.AerBackend(0), num_qubits=10, seed=0,
                         search_policy=qc.FixedIterations(20)).memory_estimate(24, dim=2)
    assert base.total_bytes < annealed.total_bytes
    assert base.total_bytes < aer.total_bytes < aer_more_k.total_bytes
    # the per-entry part doubles with one more qubit; shots add a per-shot part
    shot = sv.peak_bytes(20, 2) - sv.peak_bytes(20, 1)
    fixed = sv.FIXED_BYTES
    assert shot > 0 and sv.peak_bytes(21, 1) - shot - fixed == 2 * (sv.peak_bytes(20, 1) - shot - fixed)
    assert qc.Adaptive(grid_size=100_000, max_iterations=1_000_000).state_bytes(1 << 10) > 1 << 40


#: measures what one call adds to the process's peak memory: the peak (VmHWM) is reset to the
#: current RSS first (Linux: "5" to /proc/self/clear_refs), so compiling or importing before the
#: call, which can peak higher, does not hide it
_PEAK_OF = """
def _status(key):
    for line in open("/proc/self/status"):
        if line.startswith(key + ":"):
            return int(line.split()[1]) * 1024
    raise KeyError(key)

def added_peak(call):
    with open("/proc/self/clear_refs", "w") as handle:
        handle.write("5")
    before = _status("VmRSS")
    call()
    return _status("VmHWM") - before
"""


def _can_reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as handle:
            handle.write("5")
        return True
    except OSError:
        return False


_UNSHARED_PEAK = _PEAK_OF + """
import sys
import numpy as np
import qrrt_circuits as qc

class Nowhere:  # a predicate that costs nothing: the round's memory is its databases and searches
    dim, name = 2, "nowhere"
    def describe(self):
        return {"name": self.name}
    def reachable(self, parents, children):
        return np.zeros(len(children), dtype=bool)

env = qc.paper_clutter(seed=0)
problem = env.replace(predicate=Nowhere())
def planner(n, workers):
    return qc.PQRRT(backend=qc.StatevectorBackend(0), num_qubits=n, workers=workers, shared_database=False,
                    search_policy=qc.FixedIterations(1), seed=0)
planner(8, 2).plan(problem, max_rounds=1)  # compiled code loaded before the measurement
big = planner(20, int(sys.argv[1]))
print(added_peak(lambda: big.plan(problem, max_rounds=1)), big.memory_estimate(dim=2).total_bytes)
"""


@pytest.mark.skipif(not _can_reset_peak(), reason="needs Linux's /proc/self/clear_refs to reset the peak RSS")
def test_unshared_databases_are_counted_once_per_worker_without_an_executor(env):
    """A round builds every worker's database before searching them, so the estimate grows with p
    (it counted one database without an executor: 122 MiB at n = 20 for any p, against a measured
    1.8 GiB at p = 64), and it covers the peak a round adds at n = 20, measured in a fresh process
    (the peak reset just before the round)."""
    def estimate(workers):
        return qc.PQRRT(backend=qc.StatevectorBackend(0), num_qubits=16, workers=workers,
                        shared_database=False, seed=0).memory_estimate(dim=2)

    one, eight = estimate(1), estimate(8)
    assert eight.database_bytes == 8 * one.database_bytes and eight.search_bytes == 8 * one.search_bytes
    for workers in (4, 16):
        run = subprocess.run([sys.executable, "-c", _UNSHARED_PEAK, str(workers)], capture_output=True, text=True,
                             timeout=300, check=True)
        added, estimated = map(int, run.stdout.split())
        assert 0 < added <= estimated, (workers, added, estimated)


def test_adaptive_with_a_huge_table_is_refused_before_allocating_it(env):
    policy = qc.Adaptive(grid_size=100_000, max_iterations=1_000_000)  # a 2.4 TB success table
    planner = qc.QRRT(backend=qc.StatevectorBackend(0), num_qubits=8, seed=0, search_policy=policy)
    with pytest.raises(ValueError, match=r"num_qubits = 8: this plan could need about .*search policy"):
        planner.plan(env, max_rounds=1)


@pytest.mark.parametrize("make_backend", [lambda: qc.StatevectorBackend(0, max_qubits=24),
                                          lambda: qc.AerBackend(0)], ids=["statevector", "aer"])
def test_direct_search_refused(small_memory, make_backend):
    backend = make_backend()
    marks = np.zeros(1 << 24, dtype=bool)
    marks[::3] = True
    with pytest.raises(ValueError, match=r"num_qubits = 24: this .* search \(1 shots, 5 iterations\) needs "
                                         r"about .*the largest num_qubits that fits is \d+"):
        backend.search(qc.LookupOracle(marks), 5)


def test_an_aer_search_with_the_mcz_oracle_is_held_to_its_own_footprint(small_memory):
    """The diagonal form's bound (320 MiB at n = 20, k = 1) does not fit in 300 MiB; 12 marked
    entries take the mcz form (the state, about 48 MiB): accepted and run. A third of the entries
    marked take the diagonal form: refused by the bound (their count cannot lower it)."""
    backend = qc.AerBackend(0)
    assert backend.peak_bytes(20, 8, 1) > small_memory
    sparse = np.zeros(1 << 20, dtype=bool)
    sparse[np.random.default_rng(0).choice(1 << 20, 12, replace=False)] = True
    assert backend.oracle_form(20, 12) == "mcz"
    assert backend.peak_bytes(20, 8, 1, marked=12) < 64 * MIB + backend.FIXED_BYTES
    result = backend.search(qc.LookupOracle(sparse), 1, shots=8)
    assert result.indices.shape == (8,)
    dense = np.zeros(1 << 20, dtype=bool)
    dense[::3] = True
    with pytest.raises(ValueError, match=r"num_qubits = 20: this aer search \(8 shots, 1 iterations\) needs about"):
        backend.search(qc.LookupOracle(dense), 1, shots=8)
    assert qc.AerBackend(0, synthesis="diagonal").peak_bytes(20, 8, 1, marked=12) == backend.peak_bytes(20, 8, 1)


def _every_backend():
    from qiskit_aer.noise import NoiseModel
    from qiskit_aer.primitives import SamplerV2

    yield "statevector", qc.StatevectorBackend(0)
    yield "statevector-iterated", qc.StatevectorBackend(0, closed_form=False)
    for synthesis in ("auto", "diagonal", "mcz"):
        yield f"aer-{synthesis}", qc.AerBackend(0, synthesis=synthesis)
        yield f"aer-mps-{synthesis}", qc.AerBackend(0, method="matrix_product_state", synthesis=synthesis)
        yield f"aer-noise-{synthesis}", qc.AerBackend(0, synthesis=synthesis, noise_model=NoiseModel())
        yield f"sampler-{synthesis}", qc.SamplerBackend(SamplerV2(), synthesis=synthesis, seed=0)


@pytest.mark.parametrize("sequence", [False, True])
def test_every_backends_estimate_grows_and_holds_at_least_the_state(sequence):
    """``peak_bytes`` is a bound of the measured peak (``benchmarks/memory_peaks.py``); as a formula
    it grows with n, with k, with the shots and, without a count, bounds every m; and it is never
    below the 2^n complex128 amplitudes of the index register's state."""
    for name, backend in _every_backend():
        for n in range(1, 31):
            for k in (0, 1, 5, 50):
                peak = backend.peak_bytes(n, 8, k, sequence=sequence)
                assert peak >= 16 << n, (name, n, k)
                assert backend.peak_bytes(n + 1, 8, k, sequence=sequence) >= peak, (name, n, k)
                assert backend.peak_bytes(n, 8, k + 1, sequence=sequence) >= peak, (name, n, k)
                assert backend.peak_bytes(n, 9, k, sequence=sequence) > peak, (name, n, k)
                for m in {0, 1, min(3, 1 << n), (1 << n) // 3, 1 << n}:
                    assert backend.peak_bytes(n, 8, k, m, sequence=sequence) <= peak, (name, n, k, m)


@pytest.mark.parametrize("num_qubits", [4, 10, 16, 24, 30])
def test_the_mcz_estimate_stays_below_the_bound_for_every_m(num_qubits):
    """``peak_bytes`` without a count is a bound for every marked count m and every k: the mcz
    form's estimate (state plus instructions) never exceeds it where ``simulation_synthesis``
    chooses that form."""
    backend = qc.AerBackend(0)
    entries = 1 << num_qubits
    counts = {0, 1, 12, entries // 601, entries // 600, entries // 2, entries - 1, entries}
    for marked in sorted(count for count in counts if 0 <= count <= entries):
        for iterations in (0, 1, 12, 1000):
            bound = backend.peak_bytes(num_qubits, 8, iterations)
            assert backend.peak_bytes(num_qubits, 8, iterations, marked) <= bound


def test_cli_search_refused_before_the_marks(small_memory, capsys):
    before = _peak_rss()
    with pytest.raises(SystemExit) as info:
        cli.main(["search", "--backend", "aer", "--qubits", "26", "--marked", "1"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "num_qubits = 26" in err and "largest num_qubits that fits" in err
    assert _peak_rss() - before < 32 * MIB  # the 2^26 marks were never allocated


def test_cli_plan_reproductions_refused(small_memory, capsys):
    for argv in (["plan", "--planner", "qrrt", "--backend", "statevector", "--qubits", "28", "--max-rounds", "1"],
                 ["plan", "--backend", "aer", "--qubits", "24"]):
        with pytest.raises(SystemExit) as info:
            cli.main(argv)
        assert info.value.code == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "this plan could need about" in err and "300 MiB of memory available" in err


@pytest.mark.parametrize("argv_backend, qubits, planner", [("statevector", 28, qc.QRRT), ("aer", 24, qc.PQRRT)])
def test_issue_reproductions_on_this_machine(env, argv_backend, qubits, planner):
    """The issue's two runs, with this machine's real available memory: refused when their estimate
    exceeds it (skipped on a machine that has the memory: they then run, as they should)."""
    backend = qc.StatevectorBackend(0) if argv_backend == "statevector" else qc.AerBackend(0)
    estimate = planner(backend=backend, num_qubits=12, seed=0).memory_estimate(qubits, dim=2)
    available = probe.available_memory_bytes()
    if available is None or estimate.total_bytes <= available:
        pytest.skip(f"this machine has {available} bytes available, enough for the estimated "
                    f"{estimate.total_bytes}")
    with pytest.raises(ValueError, match=f"num_qubits = {qubits}: this plan could need about"):
        planner(backend=backend, num_qubits=qubits, seed=0).plan(env, max_rounds=1)


def test_available_memory_reads_meminfo():
    available = probe.available_memory_bytes()
    assert available is not None and available > 0
    with open("/proc/meminfo") as meminfo:
        total = next(int(line.split()[1]) * 1024 for line in meminfo if line.startswith("MemTotal:"))
    assert available <= total


_SAMPLER_SHOT_PEAK = _PEAK_OF + """
import numpy as np
import qrrt_circuits as qc
backend = qc.registry.BACKENDS.create("sampler", seed=0)
marks = np.zeros(256, dtype=bool)
marks[::7] = True
oracle = qc.LookupOracle(marks)
backend.search(oracle, 1, shots=10)
print(added_peak(lambda: backend.search(oracle, 1, shots=1_000_000)), backend.peak_bytes(8, 1_000_000, 1))
"""


@pytest.mark.skipif(not _can_reset_peak(), reason="needs Linux's /proc/self/clear_refs to reset the peak RSS")
def test_the_sampler_backends_estimate_covers_a_million_shots():
    """The sampler's results take about 240 bytes a shot (measured); the generic 64 did not cover them."""
    run = subprocess.run([sys.executable, "-c", _SAMPLER_SHOT_PEAK], capture_output=True, text=True, timeout=300,
                         check=True)
    added, estimated = map(int, run.stdout.split())
    assert 100 * 1_000_000 < added <= estimated, (added, estimated)


_TREE_PEAK = _PEAK_OF + """
import sys
import numpy as np
import qrrt_circuits as qc
from qrrt_circuits._support.memory import plan_bytes

dim, nodes = int(sys.argv[1]), int(sys.argv[2])
boxes = []
for axis in range(dim):  # a wall around the corner cube [16, 20]^d: the goal (18, ..., 18) is walled in
    low, high = np.full(dim, 16.0), np.full(dim, 20.0)
    high[axis] = 16.5
    boxes.append([low, high])
env = qc.Environment(np.array([[0.0, 20.0]] * dim), np.array(boxes))
dynamics = None if dim == 2 else qc.LinearTrackingDynamics(-np.eye(dim), np.eye(dim), np.eye(dim))
def plan(workers, **limits):
    problem = qc.Problem.build(env, np.full(dim, 2.0), np.full(dim, 18.0), 0.5, dynamics=dynamics)
    return qc.ParallelRRT(workers=workers, seed=0).plan(problem, **limits)
plan(8, max_rounds=3)  # compiled code loaded before the measurement,
plan(64, max_nodes=1000)  # the nearest-node grid's too (from 400 nodes): compiled inside it on a cold cache
results = []
added = added_peak(lambda: results.append(plan(4096, max_nodes=nodes)))
result = results[0]
tree, history = plan_bytes(nodes, 4096, result.metrics.rounds, dim)
print(result.status, result.metrics.nodes, added, tree + history)
"""


@pytest.mark.skipif(not _can_reset_peak(), reason="needs Linux's /proc/self/clear_refs to reset the peak RSS")
@pytest.mark.parametrize("dim", [2, 4])
def test_the_tree_estimate_covers_a_tree_grown_to_its_node_limit(dim):
    """4 096 parallel-RRT workers fill a world whose goal is walled in up to a node limit of
    100 000 (``plan_bytes`` is what ``check_plan_fits`` compares with the available memory): the
    peak the plan adds, measured in a fresh process, is within the estimate, and not far below it."""
    run = subprocess.run([sys.executable, "-c", _TREE_PEAK, str(dim), "100000"], capture_output=True, text=True,
                         timeout=300, check=True)
    status, nodes, added, estimated = run.stdout.split()
    assert status == "max_nodes" and 100_000 <= int(nodes) < 100_000 + 4096
    assert 0.25 * int(estimated) < int(added) <= int(estimated), (added, estimated)


def _cgroup(tmp_path, monkeypatch, limit: str, usage: int, stat: str, version: int = 2, parent_limit=None):
    """Fake control-group files of ``version`` for a process in group ``/box`` (parent: the root),
    and point ``memory`` at them."""

    root = tmp_path / "cgroup"
    names = ("memory.max", "memory.current", "memory.stat") if version == 2 else (
        "memory.limit_in_bytes", "memory.usage_in_bytes", "memory.stat")
    mount = root if version == 2 else root / "memory"
    for folder, group_limit in ((mount / "box", limit), (mount, parent_limit)):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / names[0]).write_text((group_limit or ("max" if version == 2 else "9223372036854771712")) + "\n")
        (folder / names[1]).write_text(f"{usage}\n")
        (folder / names[2]).write_text(stat)
    proc = tmp_path / "cgroup.txt"
    proc.write_text("0::/box\n" if version == 2 else "5:cpu,cpuacct:/box\n4:memory:/box\n0::/\n")
    monkeypatch.setattr(probe, "CGROUP_ROOT", str(root))
    monkeypatch.setattr(probe, "PROC_CGROUP", str(proc))
    probe._smallest_limit_cached.cache_clear()  # (read once per process)


@pytest.mark.parametrize("version", [2, 1])
def test_a_control_group_limit_bounds_the_available_memory(tmp_path, monkeypatch, version):
    """In a container the kernel kills the process at its group's limit, whatever the machine has
    free: the room is the limit less the usage, the inactive page cache not counted as used."""

    prefix = "" if version == 2 else "total_"
    stat = f"{prefix}active_file {50 * MIB}\n{prefix}inactive_file {100 * MIB}\nanon 7\n"
    _cgroup(tmp_path, monkeypatch, str(1024 * MIB), 450 * MIB, stat, version)
    assert probe.cgroup_available_bytes() == (1024 - 300) * MIB  # the page cache (150 MiB) is not used memory
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: 20 * 1024 * MIB)
    assert probe.available_memory_bytes() == 724 * MIB
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: 500 * MIB)
    assert probe.available_memory_bytes() == 500 * MIB
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: None)
    assert probe.available_memory_bytes() == 724 * MIB


@pytest.mark.parametrize("limit, version", [("max", 2), (str(9223372036854771712), 1), ("garbage", 2)])
def test_no_control_group_limit_leaves_the_machine_figure(tmp_path, monkeypatch, limit, version):

    _cgroup(tmp_path, monkeypatch, limit, 400 * MIB, "", version)
    assert probe.cgroup_available_bytes() is None
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: 3 * MIB)
    assert probe.available_memory_bytes() == 3 * MIB


def test_a_plan_in_a_small_control_group_is_refused(tmp_path, monkeypatch, env):
    """q-RRT at n = 24 needs over a GiB: refused in a 512 MiB group on a machine with 20 GiB free."""

    _cgroup(tmp_path, monkeypatch, str(512 * MIB), 100 * MIB, "")
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: 20 * 1024 * MIB)
    planner = qc.QRRT(backend=qc.StatevectorBackend(0, max_qubits=24), num_qubits=24, seed=0)
    with pytest.raises(ValueError, match=r"num_qubits = 24: .* more than the 412 MiB of memory available "
                                         r"\(the memory control group's room\)"):
        planner.plan(env, max_rounds=1)


@pytest.mark.parametrize("version", [2, 1])
def test_an_ancestor_group_with_less_room_bounds_the_available_memory(tmp_path, monkeypatch, version):
    """A group without a limit inside a parent with one (or a tighter parent): the smallest room."""

    _cgroup(tmp_path, monkeypatch, str(1024 * MIB), 100 * MIB, "", version, parent_limit=str(300 * MIB))
    assert probe.cgroup_available_bytes() == 200 * MIB
    _cgroup(tmp_path, monkeypatch, "max" if version == 2 else "9223372036854771712", 100 * MIB, "", version,
            parent_limit=str(300 * MIB))
    assert probe.cgroup_available_bytes() == 200 * MIB


def test_without_control_group_files_the_machine_figure_stands(tmp_path, monkeypatch):

    monkeypatch.setattr(probe, "PROC_CGROUP", str(tmp_path / "absent"))
    assert probe.cgroup_available_bytes() is None
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: 5 * MIB)
    assert probe.available_memory_bytes() == 5 * MIB


@pytest.fixture(autouse=True)
def _fresh_group_limit():
    """The smallest group limit is read once per process: each test starts and ends without it."""

    probe._smallest_limit_cached.cache_clear()
    yield
    probe._smallest_limit_cached.cache_clear()


def test_v1_hidden_ancestor_and_swap_limits_bound_the_room(tmp_path, monkeypatch):
    """A container's v1 mount hides its parent's limit except as ``hierarchical_memory_limit``; with
    swap accounting the kernel kills at the memory + swap limit."""

    _cgroup(tmp_path, monkeypatch, "9223372036854771712", 100 * MIB, f"hierarchical_memory_limit {600 * MIB}\n", 1)
    assert probe.cgroup_available_bytes() == 500 * MIB
    box = tmp_path / "cgroup" / "memory" / "box"
    (box / "memory.limit_in_bytes").write_text(f"{600 * MIB}\n")
    (box / "memory.memsw.limit_in_bytes").write_text(f"{600 * MIB}\n")
    (box / "memory.memsw.usage_in_bytes").write_text(f"{550 * MIB}\n")  # 450 MiB of it in swap
    assert probe.cgroup_available_bytes() == 50 * MIB


def test_a_small_group_lowers_the_size_accepted_unchecked(tmp_path, monkeypatch):
    """In a 130 MB group an estimate of 180 MiB was accepted without a look and the kernel killed
    the run: up to an eighth of the group's limit is accepted unchecked, not 256 MiB."""
    from qrrt_circuits._support import memory

    _cgroup(tmp_path, monkeypatch, str(130 * 10**6), 50 * MIB, "")
    assert probe.always_fits_bytes() == 130 * 10**6 // 8
    estimate = memory.MemoryEstimate(21, database_bytes=180 * MIB)
    with pytest.raises(ValueError, match="num_qubits = 21"):
        memory.check_fits(lambda n: estimate, 21, "this plan")


def test_a_group_name_that_is_not_utf8_is_read(tmp_path, monkeypatch):

    _cgroup(tmp_path, monkeypatch, str(1024 * MIB), 100 * MIB, "")
    proc = Path(probe.PROC_CGROUP)
    proc.write_bytes(b"0::/box\xff\n")
    assert probe.cgroup_available_bytes() is None  # no such folder: no limit read, and no error


def test_on_the_gpu_auto_takes_the_mcz_form_above_14_qubits_and_the_bound_covers_it():
    """Aer's GPU buffer for an n-qubit diagonal is 16 * 4^n bytes (out of GPU memory at n = 18 on
    an H200), so ``"auto"`` on the GPU builds the mcz form above ``GPU_DIAGONAL_CHOSEN_UP_TO_QUBITS``
    whatever the marks; the bound over every m then covers the mcz form's most instructions. (The
    rule alone, on a CPU backend whose simulator is told it is on the GPU after construction, as a
    user may: this machine has no GPU, and nothing runs.)"""
    from qrrt_circuits.search.backends.aer import GPU_DIAGONAL_CHOSEN_UP_TO_QUBITS as widest

    backend = qc.AerBackend(0)
    backend.simulator.set_options(device="GPU")
    assert backend.synthesis_for(widest) == "auto" and backend.synthesis_for(widest + 1) == "mcz"
    half = 1 << widest  # half the entries of n = widest + 1: the diagonal form on the CPU
    assert qc.AerBackend(0).oracle_form(widest + 1, half) == "diagonal"
    assert backend.oracle_form(widest + 1, half) == "mcz"
    for iterations in (0, 1, 5):
        bound = backend.peak_bytes(widest + 1, 8, iterations)
        assert bound == backend.peak_bytes(widest + 1, 8, iterations, half)
        assert all(backend.peak_bytes(widest + 1, 8, iterations, m) <= bound for m in (0, 1, 12, half - 1, 2 * half))
    explicit = qc.AerBackend(0, synthesis="diagonal")
    explicit.simulator.set_options(device="GPU")
    assert explicit.synthesis_for(widest + 10) == "diagonal"  # run as asked


_LITERAL_MCZ_PEAK = _PEAK_OF + """
import numpy as np
from qiskit_aer.noise import NoiseModel
import qrrt_circuits as qc
backend = qc.AerBackend(0, synthesis="mcz", noise_model=NoiseModel())  # a noise model: the gate-by-gate circuit
marks = np.zeros(1 << 10, dtype=bool)
marks[np.random.default_rng(0).choice(1 << 10, 400, replace=False)] = True
backend.search(qc.LookupOracle(marks), 1, shots=1)
added = added_peak(lambda: backend.search(qc.LookupOracle(marks), 8, shots=1))
print(added, backend.peak_bytes(10, 1, 8, 400), backend.peak_bytes(10, 1, 8))
"""


@pytest.mark.skipif(not _can_reset_peak(), reason="needs Linux's /proc/self/clear_refs to reset the peak RSS")
def test_the_gate_by_gate_mcz_estimate_covers_its_instructions():
    """With a noise model the mcz oracle is built gate by gate: up to n X gates and one mcphase per
    marked entry (not the compact circuit's 2 per flipped entry). Measured in a fresh process, the
    search's peak is within the estimate for its m, which is within the bound over every m."""
    run = subprocess.run([sys.executable, "-c", _LITERAL_MCZ_PEAK], capture_output=True, text=True, timeout=300,
                         check=True)
    added, estimated, bound = map(int, run.stdout.split())
    assert 4 * MIB < added <= estimated <= bound, (added, estimated, bound)


def test_a_sequence_is_held_to_its_own_circuits_footprint(small_memory):
    """``search_sequence`` builds its circuit gate by gate with the CX-based form: 12 marked entries
    at n = 20 take the mcz form, which fits in 300 MiB where the bound over every m does not."""
    from qrrt_circuits.search.iterate_sequence import IterateSequence

    backend = qc.AerBackend(0)
    assert backend.peak_bytes(20, 8, 1, sequence=True) > small_memory
    assert backend.peak_bytes(20, 8, 1, 12, sequence=True) < 64 * MIB + backend.FIXED_BYTES
    sparse = np.zeros(1 << 20, dtype=bool)
    sparse[np.random.default_rng(0).choice(1 << 20, 12, replace=False)] = True
    assert backend.search_sequence(qc.LookupOracle(sparse), IterateSequence.grover(1), shots=8).indices.shape == (8,)


def test_the_marked_count_is_checked_and_the_largest_fitting_width_is_found_past_a_form_change(small_memory):
    backend = qc.AerBackend(0)
    for marked in (-1, (1 << 20) + 1):
        with pytest.raises(ValueError, match=r"marked must be an integer in \[0, 1048576\]"):
            backend.peak_bytes(20, 8, 1, marked=marked)
    # k = 2000, 12 marked: the diagonal form (n <= 12) needs 160 KB per entry, the mcz form (n >= 13)
    # about 48 B per entry plus its instructions, so n = 11 does not fit where n = 20 does
    assert backend.peak_bytes(11, 8, 2000, 12) > small_memory > backend.peak_bytes(20, 8, 2000, 12)
    size = memory.SearchSize(lambda n, m: backend.peak_bytes(n, 8, 2000, m), 24, backend.name, 8, 2000, lambda: 12)
    refusal = r"num_qubits = 24: this aer search \(8 shots, 2000 iterations, 12 marked\)"
    with pytest.raises(ValueError, match=refusal) as info:
        memory.check_searches([size])
    assert _largest(str(info.value)) >= 20


def test_a_refusal_that_the_marked_count_cannot_change_names_no_count(small_memory):
    marks = np.zeros(1 << 24, dtype=bool)
    marks[:12] = True
    with pytest.raises(ValueError, match=r"search \(1 shots, 1 iterations\) needs"):
        qc.StatevectorBackend(0, max_qubits=24).search(qc.LookupOracle(marks), 1)


# ------------------------------------------------------------------ one check per plan, and per direct search
@pytest.fixture
def counted_reads(monkeypatch):
    """Every size is checked (nothing is accepted unread), and each read of the available memory is
    counted."""
    reads = []
    real = probe.available_memory

    def counting():
        reads.append(1)
        return real()

    monkeypatch.setattr(probe, "ALWAYS_FITS_BYTES", 0)
    monkeypatch.setattr(probe, "available_memory", counting)
    return reads


@pytest.mark.parametrize("make_planner", [
    lambda env: qc.QRRT(backend=qc.StatevectorBackend(0), num_qubits=8, seed=0),
    lambda env: qc.PQRRT(backend=qc.AerBackend(0), num_qubits=6, workers=3, shared_database=False, seed=0),
    lambda env: qc.PQRRT(backend=qc.StatevectorBackend(0), num_qubits=6, workers=2, seed=0,
                         search_policy=qc.BBHT()),
    lambda env: qc.QRRT(backend=qc.AerBackend(0), num_qubits=6, seed=0,
                        search_policy=qc.FixedPointAmplification()),
    lambda env: qc.RRT(seed=0),
], ids=["qrrt", "pqrrt-unshared-aer", "bbht", "fixed-point-aer", "rrt"])
def test_a_plan_reads_the_available_memory_once_whatever_its_rounds(env, counted_reads, make_planner):
    result = make_planner(env).plan(env, max_rounds=12)
    assert result.metrics.rounds >= 1 and len(counted_reads) == 1


def test_a_direct_search_checks_once_per_call(counted_reads):
    backend = qc.StatevectorBackend(0)
    marks = np.zeros(1 << 10, dtype=bool)
    marks[::7] = True
    backend.search(qc.LookupOracle(marks), 2, shots=4)
    assert len(counted_reads) == 1
    backend.search_many([qc.SearchRequest(qc.LookupOracle(marks), k, 2, seed=k) for k in range(5)])
    assert len(counted_reads) == 2
    from qrrt_circuits.search.iterate_sequence import IterateSequence

    backend.search_sequence(qc.LookupOracle(marks), IterateSequence.grover(2), shots=3)
    assert len(counted_reads) == 3


def test_the_plan_check_counts_the_round_the_tree_and_the_history_together(env):
    """Each part alone fits where the sum does not: the plan's one check refuses the sum, naming the
    larger part (here the tree's node limit)."""
    planner = qc.PQRRT(backend=qc.StatevectorBackend(0), num_qubits=20, workers=8, seed=0)
    size = memory.PlanSize(2_000_000, 8, 10**6, 2, functools.partial(planner.memory_estimate, dim=2), 20)
    estimate = size.estimate()
    available = estimate.total_bytes - 1
    assert estimate.round_bytes < available and estimate.limits_bytes < available
    with pytest.raises(ValueError, match=r"max_nodes = 2000000: this plan could need about .*database build .*tree "
                                         r".*round history .*; the largest max_nodes that fits is about \d+"):
        size.check(available)
    small_round = memory.PlanSize(1000, 8, 20000, 2, functools.partial(planner.memory_estimate, dim=2), 26)
    with pytest.raises(ValueError, match=r"num_qubits = 26: .*the largest num_qubits that fits is 2[0-5]"):
        small_round.check(1 << 30)


def test_the_fixed_point_policy_is_sized_by_its_sequence_circuit(env):
    planner = qc.QRRT(backend=qc.AerBackend(0), num_qubits=16, seed=0,
                      search_policy=qc.FixedPointAmplification())
    policy = planner.search_policy
    expected = planner.backend.peak_bytes(16, 1, policy.iterates, sequence=True)
    assert planner.memory_estimate(dim=2).search_bytes == expected


# ------------------------------------------------------------------ what is available: RLIMIT_AS
def test_the_address_space_left_under_rlimit_as_bounds_the_available_memory(tmp_path, monkeypatch):
    """The room under ``ulimit -v`` is the limit less the virtual size (/proc/self/statm's first
    field in pages); it is taken where it is the smallest figure, and named."""
    import os

    page = os.sysconf("SC_PAGE_SIZE")
    statm = tmp_path / "statm"
    statm.write_text(f"{(700 * MIB) // page} 1 2 3 4 5 6\n")
    monkeypatch.setattr(probe, "PROC_STATM", str(statm))
    monkeypatch.setattr(probe, "address_space_limit", lambda: 1024 * MIB)
    monkeypatch.setattr(probe, "cgroup_available_bytes", lambda: None)
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: 20 * 1024 * MIB)
    assert probe.virtual_memory_bytes() == (700 * MIB) // page * page
    room = 1024 * MIB - probe.virtual_memory_bytes()
    assert probe.address_space_available_bytes() == room
    assert probe.available_memory() == (room, probe.ADDRESS_SPACE_SOURCE)
    assert probe.always_fits_bytes() == min(probe.ALWAYS_FITS_BYTES, room)
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: 100 * MIB)
    assert probe.available_memory() == (100 * MIB, probe.MACHINE_SOURCE)
    monkeypatch.setattr(probe, "PROC_STATM", str(tmp_path / "absent"))
    assert probe.address_space_available_bytes() is None  # no virtual size: the limit is not taken
    monkeypatch.setattr(probe, "address_space_limit", lambda: None)
    assert probe.address_space_available_bytes() is None


def test_without_a_limit_the_address_space_is_not_a_figure():
    import resource

    if resource.getrlimit(resource.RLIMIT_AS)[0] != resource.RLIM_INFINITY:
        pytest.skip("this process runs under a RLIMIT_AS")
    assert probe.address_space_limit() is None and probe.address_space_available_bytes() is None


# ------------------------------------------------------------------ the refusals on the command line: one line each
def _error_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.strip()]


def test_cli_plan_refused_under_a_control_group_limit_in_one_line(tmp_path, monkeypatch, capsys):
    """A 512 MiB group on a machine with 20 GiB free: ``qrrt plan`` at n = 24 is refused in one line
    naming the group's room and the largest n that fits, and writes nothing."""
    _cgroup(tmp_path, monkeypatch, str(512 * MIB), 100 * MIB, "")
    monkeypatch.setattr(probe, "_machine_available_bytes", lambda: 20 * 1024 * MIB)
    out = tmp_path / "plan.json"
    with pytest.raises(SystemExit) as info:
        cli.main(["plan", "--planner", "qrrt", "--backend", "statevector", "--qubits", "24", "--max-rounds", "1",
                  "--json", str(out)])
    assert info.value.code == 2
    lines = _error_lines(capsys.readouterr().err)
    assert len(lines) == 1, lines
    assert re.fullmatch(r"qrrt plan: error: num_qubits = 24: this plan could need about \S+ [MG]iB at its peak \(.*\), "
                        r"more than the 412 MiB of memory available \(the memory control group's room\); "
                        r"the largest num_qubits that fits is 2[0-2]", lines[0]), lines[0]
    assert not out.exists()


_LINUX_RLIMIT = pytest.mark.skipif(not Path("/proc/self/statm").exists(),
                                   reason="needs Linux's /proc/self/statm for the virtual size")


def _limited(limit_bytes: int):
    """preexec_fn: the child runs under ``ulimit -v`` of ``limit_bytes``."""
    def apply():
        resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))
    return apply


@_LINUX_RLIMIT
def test_cli_plan_refused_under_ulimit_v_in_one_line(tmp_path):
    """``ulimit -v`` of 2 GiB on a machine with more free: q-RRT at n = 28 (about 14.6 GiB) is
    refused in one line naming the address space left and the largest n that fits, exit status 2,
    no traceback, no output file."""
    available = probe.available_memory_bytes()
    if available is not None and available < 3 << 30:
        pytest.skip("the machine has less than 3 GiB available: RLIMIT_AS would not be the smallest figure")
    out = tmp_path / "plan.json"
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "qrrt", "--backend",
                          "statevector", "--qubits", "28", "--max-rounds", "1", "--json", str(out)],
                         capture_output=True, text=True, timeout=300, preexec_fn=_limited(2 << 30))
    assert run.returncode == 2 and "Traceback" not in run.stderr
    lines = _error_lines(run.stderr)
    assert len(lines) == 1, run.stderr
    assert re.fullmatch(r"qrrt plan: error: num_qubits = 28: this plan could need about \S+ GiB at its peak \(.*\), "
                        r"more than the \S+ [MG]iB of memory available \(the address space left under RLIMIT_AS, "
                        r"ulimit -v\); the largest num_qubits that fits is 2[0-4]", lines[0]), lines[0]
    assert not out.exists()


@_LINUX_RLIMIT
def test_cli_search_refused_under_ulimit_v_in_one_line():
    available = probe.available_memory_bytes()
    if available is not None and available < 3 << 30:
        pytest.skip("the machine has less than 3 GiB available: RLIMIT_AS would not be the smallest figure")
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "search", "--backend", "statevector",
                          "--qubits", "28", "--marked", "1", "--iterations", "1"],
                         capture_output=True, text=True, timeout=300, preexec_fn=_limited(2 << 30))
    assert run.returncode == 2 and "Traceback" not in run.stderr
    lines = _error_lines(run.stderr)
    assert len(lines) == 1 and "num_qubits = 28: this statevector search" in lines[0], run.stderr
    assert "(the address space left under RLIMIT_AS, ulimit -v); the largest num_qubits that fits is" in lines[0]


# ------------------------------------------------------------------ a MemoryError while a run runs: one line
def _unable_to_allocate(*args, **kwargs):
    """What numpy raises for an array that cannot be had (``_ArrayMemoryError``), without allocating."""
    return np.empty(1 << 62, dtype=np.uint8)


def test_a_memory_error_in_a_plan_is_one_out_of_memory_line(env, monkeypatch):
    from qrrt_circuits.planners import workers

    monkeypatch.setattr(workers, "make_database", _unable_to_allocate)
    planner = qc.QRRT(backend=qc.StatevectorBackend(0), num_qubits=10, seed=0)
    with pytest.raises(memory.OutOfMemory) as info:
        planner.plan(env, max_rounds=3)
    message = str(info.value)
    assert "\n" not in message and isinstance(info.value.__cause__, MemoryError)
    assert re.fullmatch(r"num_qubits = 10: this plan ran out of memory \(Unable to allocate .*\) with an estimated "
                        r"peak of about .*; the largest num_qubits below 10 whose estimate fits in the .* of memory "
                        r"available now \(.*\) is 9", message), message
    assert info.value.__cause__.__traceback__ is None  # the failed run's frames (and arrays) were let go


def test_a_memory_error_growing_a_classical_tree_names_the_limit(env, monkeypatch):
    from qrrt_circuits.planners.run_state import RunState

    monkeypatch.setattr(RunState, "add_node", _unable_to_allocate)
    monkeypatch.setattr(RunState, "add_nodes", _unable_to_allocate)
    with pytest.raises(memory.OutOfMemory, match=r"^max_nodes = 1000000 \(the default: the plan was given none\): "
                                                 r"this plan ran out of memory .*the largest max_nodes below 1000000 "
                                                 r"whose estimate fits"):
        qc.ParallelRRT(workers=64, seed=0).plan(env)  # the tree (a million nodes) outweighs the history


def test_a_memory_error_in_a_direct_search_is_one_out_of_memory_line(monkeypatch):
    backend = qc.StatevectorBackend(0)
    monkeypatch.setattr(qc.StatevectorBackend, "_sample", _unable_to_allocate)
    marks = np.zeros(1 << 12, dtype=bool)
    marks[3] = True
    with pytest.raises(memory.OutOfMemory, match=r"^num_qubits = 12: this statevector search \(5 shots, 2 iterations\) "
                                                 r"ran out of memory \(Unable to allocate .*\).* is 11$"):
        backend.search(qc.LookupOracle(marks), 2, shots=5)
    with pytest.raises(memory.OutOfMemory, match=r"^num_qubits = 12: this statevector search \(1 shots, 4 "):
        backend.search_many([qc.SearchRequest(qc.LookupOracle(marks), 4)])


@pytest.mark.parametrize("argv", [
    ["plan", "--planner", "qrrt", "--backend", "statevector", "--qubits", "10", "--max-rounds", "3"],
    ["search", "--backend", "statevector", "--qubits", "10", "--marked", "3"],
], ids=["plan", "search"])
def test_cli_memory_errors_are_one_line_with_a_nonzero_status(argv, monkeypatch, capsys, tmp_path):
    from qrrt_circuits.planners import workers

    monkeypatch.setattr(workers, "make_database", _unable_to_allocate)
    monkeypatch.setattr(qc.StatevectorBackend, "_sample", _unable_to_allocate)
    out = tmp_path / "out.json"
    with pytest.raises(SystemExit) as info:
        cli.main(argv + (["--json", str(out)] if argv[0] == "plan" else []))
    assert info.value.code == 1
    captured = capsys.readouterr()
    lines = _error_lines(captured.err)
    assert len(lines) == 1 and lines[0].startswith(f"qrrt {argv[0]}: error: num_qubits = 10: this ") and \
        "ran out of memory (Unable to allocate" in lines[0] and "is 9" in lines[0], lines
    assert captured.out == "" and not out.exists()


def test_a_memory_error_while_writing_leaves_no_partial_file(env, monkeypatch, capsys, tmp_path):
    """The outputs are written after the plan, each into a temporary file renamed over the target:
    a MemoryError halfway through a write leaves the target as it was (absent here) and no
    temporary file, and the command says so in one line."""
    from qrrt_circuits.planners.result import PlanResult

    def half_then_fail(self, handle):
        handle.write('{"half": ')
        np.empty(1 << 62, dtype=np.uint8)

    monkeypatch.setattr(PlanResult, "write_json", half_then_fail)
    out = tmp_path / "plan.json"
    with pytest.raises(SystemExit) as info:
        cli.main(["plan", "--planner", "rrt", "--max-rounds", "3", "--json", str(out)])
    assert info.value.code == 1
    lines = _error_lines(capsys.readouterr().err)
    assert len(lines) == 1 and "--json: writing" in lines[0] and "out of memory: Unable to allocate" in lines[0]
    assert list(tmp_path.iterdir()) == []


_SHORT_ESTIMATE = """
import sys
import qrrt_circuits as qc
from qrrt_circuits import cli
from qrrt_circuits._support import memory

def short(self, num_qubits=None, *, dim):  # an estimate that falls short: 16 bytes an entry
    n = self.num_qubits if num_qubits is None else num_qubits
    return memory.MemoryEstimate(n, database_bytes=16 << n)

qc.PQRRT.memory_estimate = short
sys.exit(cli.main(sys.argv[1:]))
"""


@_LINUX_RLIMIT
def test_a_real_memory_error_under_ulimit_v_is_one_line(tmp_path):
    """An estimate that falls short passes the check under ``ulimit -v`` of 3 GiB and the round
    really runs out of address space: one line naming n, what the allocator reported and the
    largest smaller n whose estimate fits in what was available when the plan started; exit status
    1, no traceback, no output file."""
    out = tmp_path / "plan.json"
    run = subprocess.run([sys.executable, "-c", _SHORT_ESTIMATE, "plan", "--planner", "qrrt", "--backend",
                          "statevector", "--qubits", "26", "--max-rounds", "1", "--json", str(out)],
                         capture_output=True, text=True, timeout=300, preexec_fn=_limited(6 << 29))
    assert run.returncode == 1 and "Traceback" not in run.stderr, run.stderr
    lines = _error_lines(run.stderr)
    assert len(lines) == 1, run.stderr
    assert re.fullmatch(r"qrrt plan: error: num_qubits = 26: this plan ran out of memory \(.+\) with an estimated "
                        r"peak of about .*; the largest num_qubits below 26 whose estimate fits in the .* of memory "
                        r"available when it started \(the address space left under RLIMIT_AS, ulimit -v\) is 2[0-5]",
                        lines[0]), lines[0]
    assert not out.exists()
