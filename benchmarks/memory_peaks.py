"""Each backend's search: the measured peak memory against its ``peak_bytes`` bound.

Every case runs in a fresh subprocess: it imports the library, warms the backend up with a small
search (its libraries and compiled code loaded), builds the marks (held by the caller, not part of
the search's estimate), hands the memory freed so far back to the system (glibc's ``malloc_trim``,
so that the search cannot reuse it unseen), resets the process's peak resident set to its current one (Linux:
``"5"`` to ``/proc/self/clear_refs``), reads that baseline (``VmRSS``), runs one
``backend.search(LookupOracle(marks), k, shots, seed)`` and reads the peak
(``resource.getrusage(RUSAGE_SELF).ru_maxrss``). The measured figure is the peak minus the
baseline: what the search added, which is what ``peak_bytes`` bounds. Two estimates are recorded:
the bound over every marked count m (``peak_bytes(n, shots, k)``, what a check compares first) and
the estimate for the search's own m (``peak_bytes(n, shots, k, m)``); both must be at least the
measured figure.

Backends: ``statevector`` (closed form), ``aer`` (statevector method), ``aer-mps``
(``matrix_product_state``, small n: it runs the gate-by-gate circuit) and ``sampler`` (qiskit-aer's
``SamplerV2`` through ``SamplerBackend``: the transpiled circuit). Marks: a quarter of the entries
(``dense``: the diagonal oracle) or three (``sparse``: the mcz oracle where a backend chooses it).

    python benchmarks/memory_peaks.py            # every case (about ten minutes)
    python benchmarks/memory_peaks.py --quick    # n <= 14

Writes ``benchmarks/results/memory_peaks.json`` (rows, and per backend the smallest ratio
estimate / measured) with the run's provenance.
"""

from __future__ import annotations

import argparse
import json

from _common import machine, rows_in_subprocesses, write_json

MIB = 1 << 20
SHOTS = 64

#: (backend, n, marks, k) of every case; ``--quick`` keeps n <= 14
CASES = (
    [("statevector", n, marks, 1) for n in (8, 12, 14, 16, 17, 20, 22) for marks in ("dense", "sparse")]
    + [("aer", n, marks, k) for n in (8, 12, 14, 16, 17, 20) for marks in ("dense", "sparse") for k in (1, 4)]
    + [("aer-mps", n, marks, k) for n in (8, 10, 12) for marks in ("dense", "sparse") for k in (1, 4)]
    + [("sampler", n, marks, k) for n in (8, 12, 14) for marks in ("dense", "sparse") for k in (1, 4)]
    + [("sampler", n, marks, 1) for n in (16, 17) for marks in ("dense", "sparse")]
)


def _status(key: str) -> int:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024
    raise KeyError(key)


def _backend(name: str, seed: int):
    import qrrt_circuits as qc

    if name == "statevector":
        return qc.StatevectorBackend(seed=seed)
    if name == "aer":
        return qc.AerBackend(seed=seed)
    if name == "aer-mps":
        return qc.AerBackend(seed=seed, method="matrix_product_state")
    from qiskit_aer.primitives import SamplerV2

    return qc.SamplerBackend(SamplerV2(), seed=seed)


def run_case(name: str, n: int, kind: str, k: int) -> dict:
    """One search in this (fresh) process: what it added to the peak, and the estimates."""
    import ctypes
    import gc
    import resource
    import time

    import numpy as np

    import qrrt_circuits as qc

    backend = _backend(name, 0)
    warm = np.zeros(16, dtype=bool)
    warm[[3, 7, 9, 12]] = True
    backend.search(qc.LookupOracle(warm), 1, SHOTS, seed=1)
    rng = np.random.default_rng(n)
    marked = (1 << n) // 4 if kind == "dense" else 3
    marks = np.zeros(1 << n, dtype=bool)
    marks[rng.choice(1 << n, marked, replace=False)] = True
    oracle = qc.LookupOracle(marks)
    gc.collect()
    ctypes.CDLL("libc.so.6").malloc_trim(0)  # freed memory back to the system: the search cannot reuse it unseen
    with open("/proc/self/clear_refs", "w") as handle:  # the peak from here on
        handle.write("5")
    base = _status("VmRSS")
    began = time.perf_counter()
    backend.search(oracle, k, SHOTS, seed=2)
    seconds = time.perf_counter() - began
    measured = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - base
    bound = backend.peak_bytes(n, SHOTS, k)
    estimate = backend.peak_bytes(n, SHOTS, k, marked)
    return {"backend": name, "num_qubits": n, "marks": kind, "marked": marked, "iterations": k, "shots": SHOTS,
            "measured_bytes": measured, "bound_bytes": bound, "estimated_bytes": estimate,
            "bound_over_measured": bound / max(measured, 1), "estimate_over_measured": estimate / max(measured, 1),
            "state_bytes": 16 << n, "seconds": round(seconds, 3)}


def _line(row: dict) -> str:
    return (f"{row['backend']:12s} {row['num_qubits']:3d} {row['marks']:6s} {row['iterations']:2d} "
            f"{row['measured_bytes'] / MIB:13.1f} {row['bound_bytes'] / MIB:10.1f} "
            f"{row['estimated_bytes'] / MIB:13.1f} "
            f"{row['bound_over_measured']:10.2f} {row['estimate_over_measured']:9.2f} {row['seconds']:7.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="n <= 14 only")
    parser.add_argument("--only", choices=("statevector", "aer", "aer-mps", "sampler"), help="one backend only")
    parser.add_argument("--out", default=None, help="the JSON to write (default benchmarks/results/memory_peaks.json)")
    parser.add_argument("--case", nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.case:
        name, n, kind, k = args.case
        print(json.dumps(run_case(name, int(n), kind, int(k))))
        return
    cases = [case for case in CASES if (not args.quick or case[1] <= 14) and args.only in (None, case[0])]
    header = (f"{'backend':12s} {'n':>3s} {'marks':6s} {'k':>2s} {'measured MiB':>13s} {'bound MiB':>10s} "
              f"{'estimate MiB':>13s} {'bound/meas':>10s} {'est/meas':>9s} {'s':>7s}")
    rows = rows_in_subprocesses(__file__, cases, header, _line)
    smallest = {}
    for row in rows:
        ratio = min(row["bound_over_measured"], row["estimate_over_measured"])
        smallest[row["backend"]] = min(smallest.get(row["backend"], ratio), ratio)
    path = write_json("memory_peaks", {
        "machine": machine(), "quick": args.quick, "shots": SHOTS, "rows": rows,
        "smallest_estimate_over_measured": smallest,
        "note": "peak RSS a search adds (ru_maxrss after a reset of the peak, less the RSS before it), one fresh "
                "subprocess per case; bound = peak_bytes(n, shots, k), estimate = peak_bytes(n, shots, k, m)"},
        args.out)
    print(f"smallest estimate / measured per backend: {smallest}")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
