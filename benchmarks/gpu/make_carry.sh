#!/usr/bin/env bash
# Builds .gpu/, the folder that benchmarks/gpu/on_device.sh installs on a GPU machine that cannot
# reach a package index (this project's lent device machines): the qiskit-aer-gpu wheel, qiskit and
# its small dependencies, CUDA 12's runtime, and stubs for the CUDA libraries that the wheel's
# extension links but the measured path never calls.
#
#   bash benchmarks/gpu/make_carry.sh        # here, with pip reaching PyPI; writes .gpu/ (~34 MB)
#
# Why stubs: qiskit-aer-gpu 0.18.2's controller links libcusolver.so.11, libcusparse.so.12,
# libcustatevec.so.1 and libcutensornet.so.2 (with cuBLAS behind them: several hundred MB of wheels,
# more than the 64 MiB a device call carries). It imports no symbol of cuSOLVER or cuSPARSE
# (nm -D --undefined-only), and calls cuStateVec only with cuStateVec_enable=True and cuTensorNet
# only for the tensor_network method, neither of which the benchmark uses. The stubs define those
# symbols (with the wheel's symbol versions) as functions that print their name and abort, so a
# call would end the run loudly rather than measure something else. On a machine with a package
# index, `pip install qiskit-aer-gpu` brings the real libraries and none of this is needed.
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo '/.gpu/' >> .git/info/exclude
rm -rf .gpu && mkdir -p .gpu/whl .gpu/lib .gpu/stub-src
PLATFORMS=(--platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 --platform manylinux_2_17_x86_64
           --platform manylinux2014_x86_64)
python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
  "${PLATFORMS[@]}" -d .gpu/whl qiskit-aer-gpu==0.18.2 qiskit==2.6.2 rustworkx==0.18.1 dill==0.4.1 \
  stevedore==5.10.0 nvidia-cuda-runtime-cu12==12.6.77
work=$(mktemp -d)
unzip -q -o .gpu/whl/qiskit_aer_gpu-*.whl 'qiskit_aer/backends/controller_wrappers*.so' -d "$work"
undefined=$(nm -D --undefined-only "$work"/qiskit_aer/backends/controller_wrappers*.so | awk '{print $2}')
stub() {  # stub SONAME VERSION PREFIX: a library defining every PREFIX* symbol the extension imports
  local soname=$1 version=$2 prefix=$3 src=.gpu/stub-src/$1.c map=.gpu/stub-src/$1.map
  printf '#include <stdio.h>\n#include <stdlib.h>\n' > "$src"
  printf '%s {\n  global:\n' "$version" > "$map"
  for symbol in $(echo "$undefined" | grep "^${prefix}" | sed "s/@.*//" | sort -u); do
    printf 'int %s(void) { fprintf(stderr, "stub %s called (benchmarks/gpu/make_carry.sh)\\n"); abort(); }\n' \
      "$symbol" "$symbol" >> "$src"
    printf '    %s;\n' "$symbol" >> "$map"
  done
  printf '  local: *;\n};\n' >> "$map"
  gcc -shared -fPIC -O1 -o ".gpu/lib/$soname" "$src" -Wl,-soname,"$soname" -Wl,--version-script="$map"
}
stub libcustatevec.so.1 libcustatevec.so.0 custatevec
stub libcutensornet.so.2 libcutensornet.so.0 cutensornet
for soname in libcusolver.so.11 libcusparse.so.12; do  # linked, but no symbol imported
  printf 'void qrrt_empty_%s(void) {}\n' "${soname//./_}" > ".gpu/stub-src/$soname.c"
  gcc -shared -fPIC -o ".gpu/lib/$soname" ".gpu/stub-src/$soname.c" -Wl,-soname,"$soname"
done
rm -rf "$work"
du -sh .gpu
