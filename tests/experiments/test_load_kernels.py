"""The process pools' warm-up on the problem families (``experiments.problems.load_kernels``): the
fork server swallows a failing warm-up, so it is run here directly, in a fresh interpreter."""

import json
import subprocess
import sys

#: what the fresh interpreter runs: the warm-up, then its threads and the signatures its kernels hold
PROBE = """
import json, threading
from qrrt_circuits.experiments.problems import load_kernels
from qrrt_circuits.search.backends import statevector
from qrrt_circuits.world import nearest
load_kernels(calls=3)
kernels = {"nearest_into": nearest.nearest_into, "_se2_nearest_into": nearest._se2_nearest_into,
           "_file_by_cell": nearest._file_by_cell, "_bounding_box": nearest._bounding_box,
           "_ranked_indices": statevector._ranked_indices}
print(json.dumps({"threads": threading.active_count(),
                  "signatures": {name: len(kernel.signatures) for name, kernel in kernels.items()}}))
"""


def test_load_kernels_loads_the_planners_kernels_and_starts_no_thread():
    """In a fresh interpreter it plans every family without error, starts no thread (the fork server
    forks after it), and leaves the kernels a plan calls from Python loaded: the nearest-neighbour
    queries (Euclidean and SE(2)), the grid a large tree builds, the statevector's draw."""
    done = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True, timeout=600)
    probe = json.loads(done.stdout.strip().splitlines()[-1])
    assert probe["threads"] == 1
    assert all(count >= 1 for count in probe["signatures"].values()), probe["signatures"]
