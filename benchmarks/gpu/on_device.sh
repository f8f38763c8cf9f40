#!/usr/bin/env bash
# Runs benchmarks/bench_gpu.py on a GPU machine without a package index, from the folder .gpu/ that
# benchmarks/gpu/make_carry.sh built (the qiskit-aer-gpu wheel, qiskit, CUDA 12's runtime, stubs).
#
#   bash benchmarks/gpu/on_device.sh OUT_DIR [bench_gpu.py arguments]
#
# Installs the wheels into /tmp/site (the machine's own numpy, scipy, numba, networkx, matplotlib,
# tqdm and psutil are used), puts the stubs on LD_LIBRARY_PATH and writes OUT_DIR/bench_gpu.json,
# OUT_DIR/bench_gpu.log and OUT_DIR/environment.txt.
set -uo pipefail
out=${1:?usage: on_device.sh OUT_DIR [bench_gpu.py arguments]}
shift
cd "$(dirname "$0")/../.."
mkdir -p "$out"
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .gpu/whl/*.whl \
  || exit 1
export PYTHONPATH=/tmp/site:$PWD/src PYTHONUNBUFFERED=1
export LD_LIBRARY_PATH=$PWD/.gpu/lib:/tmp/site/nvidia/cuda_runtime/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
{
  nvidia-smi
  nproc
  python3 --version
  python3 -m pip list 2>/dev/null | grep -iE '^(numpy|scipy|numba|networkx|matplotlib|psutil) '
  python3 -c 'import qiskit, qiskit_aer; from qiskit_aer import AerSimulator
print("qiskit", qiskit.__version__, "qiskit-aer", qiskit_aer.__version__, AerSimulator().available_devices())'
} > "$out/environment.txt" 2>&1
cat "$out/environment.txt"
python3 benchmarks/bench_gpu.py --out "$out/bench_gpu.json" "$@" 2>&1 | tee "$out/bench_gpu.log"
