#!/usr/bin/env bash
# Issue 26's and 32's checks on a lent GPU machine, in one call (see docs/guide/bench.md):
#   the machine, the GPU bench (rotframe bench gpu, with the user-force rows), your own problem beside the scenes'
#   ensemble (tools/gpu_user_rows.py; USER_ROWS=0 skips it), your own problems on the GPU against the CPU
#   (tools/gpu_user_check.py), the GPU kernel's register limits (tools/gpu_variants.py; VARIANTS=0 skips
#   them) and the CPU ensemble bench on every core (CPU=0 skips it). The most wanted first: a run cut short by its
#   limit still leaves what it finished in $OUT.
# Run from the repository root; results land in $OUT (default /tmp/rotframe-device).
set -u
OUT=${OUT:-/tmp/rotframe-device}
mkdir -p "$OUT"
export PYTHONPATH=$PWD/tools/device_shim:$PWD/src PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false ROTFRAME_DEBUG=1
PY=${PY:-python3}
nvidia-smi --query-gpu=name,memory.total,driver_version,clocks.sm,clocks.max.sm --format=csv 2>&1 | tee "$OUT/machine.txt"
nproc | tee -a "$OUT/machine.txt"
$PY - <<'PY' 2>&1 | tee -a "$OUT/machine.txt"
import numba, numpy
print("numba", numba.__version__, "numpy", numpy.__version__)
from numba import cuda
print("cuda available", cuda.is_available())
try:
    import jax
    print("jax", jax.__version__, jax.devices())
except Exception as e:
    print("jax:", type(e).__name__, e)
try:
    import cupy
    print("cupy", cupy.__version__)
except Exception as e:
    print("cupy:", type(e).__name__, e)
PY
t0=$(date +%s)
# rotframe bench gpu --json, its rows written after every case: a run cut by its limit keeps the cases it finished
timeout ${GPU_TIMEOUT:-300} $PY - "$OUT/gpu.json" <<'PY' 2> "$OUT/gpu.err"
import json, math, sys
from rotframe.app.bench.gpu import gpu_rows
def write(rows):
    clean = [{k: None if isinstance(v, float) and math.isnan(v) else v for k, v in r.items()} for r in rows]
    with open(sys.argv[1], "w") as f:
        json.dump(clean, f, default=str)
    print(f"bench gpu: {len(rows)} rows written", file=sys.stderr, flush=True)
gpu_rows(False, each=write)
PY
echo "bench gpu: rc=$? in $(( $(date +%s) - t0 )) s"; tail -c 3000 "$OUT/gpu.err"
$PY tools/gpu_table.py "$OUT/gpu.json" | tee "$OUT/gpu.md"
if [ "${USER_ROWS:-1}" = 1 ]; then
  t0=$(date +%s)
  # your own problem on the GPU beside the scenes' ensemble, the time in its compiled calls apart (docs/bench/gpu-user-rows.txt)
  timeout ${USER_ROWS_TIMEOUT:-240} $PY tools/gpu_user_rows.py 1048576 8192 2>&1 | grep -v Warning | tee "$OUT/user_rows.txt"
  echo "gpu user rows: in $(( $(date +%s) - t0 )) s"
fi
t0=$(date +%s)
# your own problem on the GPU against the CPU (rotframe.simulate(device="gpu")): exits 1 unless they agree to 1e-9
timeout ${USER_TIMEOUT:-240} $PY tools/gpu_user_check.py ${USER_PARTICLES:-4096} 2>&1 | tee "$OUT/user_check.txt" | grep -v Warning
echo "gpu user check: rc=${PIPESTATUS[0]} in $(( $(date +%s) - t0 )) s"
if [ "${VARIANTS:-1}" = 1 ]; then
  t0=$(date +%s)
  timeout ${VARIANTS_TIMEOUT:-120} $PY tools/gpu_variants.py 2>&1 | tee "$OUT/variants.txt" | grep -v Warning
  echo "gpu variants: in $(( $(date +%s) - t0 )) s"
fi
if [ "${CPU:-1}" = 1 ]; then
  t0=$(date +%s)
  timeout ${CPU_TIMEOUT:-240} $PY -m rotframe bench ensemble --json > "$OUT/ensemble.json" 2> "$OUT/ensemble.err"
  echo "bench ensemble: rc=$? in $(( $(date +%s) - t0 )) s"; tail -c 2000 "$OUT/ensemble.err"
  $PY - "$OUT/ensemble.json" <<'PY'
import json, sys
for r in json.load(open(sys.argv[1])):
    if "of_ceiling" in r:
        print(f"{r['method'][:75]:<75} {r['particle_steps_per_s']:.3g}/s of_ceiling {r['of_ceiling']:.3f}"
              + (f" eff {r['parallel_efficiency']:.2f} bitwise {r['bitwise_identical_to_1_thread']}" if "parallel_efficiency" in r and "bitwise_identical_to_1_thread" in r else ""))
PY
fi
