"""Sizes of the coherent oracle's circuits and checks refused from an estimate, before the work,
in a subprocess under an address-space limit (where the work itself would abort or run out)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

LIMIT = 4_000_000_000  # bytes of address space: the issue's ``ulimit -v 4000000``


def run_limited(code: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter under RLIMIT_AS = ``LIMIT`` (set after the imports)."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout)


def test_a_grover_circuit_of_too_many_gates_is_refused_naming_iterations_and_the_oracle():
    """k = 10 000 iterations of a 19 553-gate oracle: 196 M gates, a Rust abort (exit 134) under
    the limit if built; refused before building, in one line."""
    result = run_limited(f"""
        import resource
        from qrrt_circuits.coherent import coherent_phase_oracle
        from qrrt_circuits.coherent.costs import scaling_instance
        from qrrt_circuits.coherent.grover import coherent_grover_circuit
        oracle = coherent_phase_oracle(*scaling_instance(10, 3, parent_bits=2, bits=12, time_samples=8))
        resource.setrlimit(resource.RLIMIT_AS, ({LIMIT}, {LIMIT}))
        try:
            coherent_grover_circuit(oracle, 10, 10_000)
        except ValueError as error:
            print(error)
        fits = coherent_grover_circuit(oracle, 10, 1)
        print("one iteration", fits.size() > oracle.size())
    """)
    assert result.returncode == 0, result.stderr
    assert "iterations = 10000 of an oracle of" in result.stdout and "at most 102 iterations" in result.stdout
    assert "one iteration True" in result.stdout


def test_all_entries_at_n_26_are_refused_from_an_estimate_naming_the_index_bits():
    """reachable_reference and verify_oracle at n = 26 with 512 MiB of address space left: a plain
    MemoryError after seconds if run; refused at once, naming database.num_index_bits."""
    result = run_limited("""
        import resource
        import numpy as np
        from qrrt_circuits import Environment
        from qrrt_circuits.coherent import FixedPointFormat, LatticeDatabase, SampledMotion, reachable_reference
        from qrrt_circuits.coherent.verify import verify_oracle
        env = Environment([[0, 15], [0, 15]], [[[6, 0], [9, 9]]])
        db = LatticeDatabase(FixedPointFormat(13, 0.0, 16.0), 13, np.array([[2.0, 2.0]]))
        motion = SampledMotion.straight_line(2, 3, 1)
        import os
        limit = 512 << 20
        size = int(open(f"/proc/{os.getpid()}/statm").read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
        resource.setrlimit(resource.RLIMIT_AS, (size + limit, size + limit))
        for check in (reachable_reference, verify_oracle):
            try:
                check(env, db, motion)
                print("ran")
            except ValueError as error:
                print(error)
    """)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert len(lines) == 2 and all(line.startswith("database.num_index_bits = 26: ") for line in lines), lines
    assert all("the largest database.num_index_bits that fits is 2" in line for line in lines)
