"""The process pools' warm-up plan on every problem family (``experiments.problems.load_kernels``):
the fork server swallows a failing warm-up, so it is asked here directly."""

import threading

from qrrt_circuits.experiments.problems import FAMILIES, build_problem, load_kernels


def test_load_kernels_plans_every_family_and_starts_no_thread():
    """It plans without error on each family and starts no thread (the fork server forks after it)."""
    threads = threading.active_count()
    load_kernels(calls=3)
    assert threading.active_count() == threads
    assert all(build_problem(family, 0).predicate.evaluations == 0 for family in FAMILIES)
