#!/usr/bin/env bash
# The CUDA checks for a lent GPU machine, in one command of under 10 minutes (docs/benchmarks.md,
# "GPU checks"): the tests' CUDA cases, then the GPU benchmarks that the issues ask for.
#
# It expects Warp and the pure-Python dependencies importable (PYTHONPATH) and writes its log and
# JSON records to $OUT (the device tool's folder; /tmp/gpu_checks elsewhere). Each step has its own
# time limit (540 s in all) so that a slow one cannot take the others' records with it. The beam and
# photon benchmarks run their quick sizes: their full runs spend minutes in numpy, and the photons'
# camera scenes need pyvista's meshes (VTK is too large to carry). Try it here first with
#   DEVICE=cpu QUICK=1 bash benchmarks/gpu_checks.sh
set -u -o pipefail
export PYTHONUNBUFFERED=1
out=${OUT:-/tmp/gpu_checks}
device=${DEVICE:-cuda:0}
quick=${QUICK:+--quick}
mkdir -p "$out"
log="$out/gpu_checks.log"
step() {  # step SECONDS NAME COMMAND...: run one step under a time limit, log it, go on either way
  local limit=$1 name=$2
  shift 2
  echo "== $name (limit ${limit} s): $*" | tee -a "$log"
  local t0=$SECONDS
  timeout "$limit" "$@" 2>&1 | tee -a "$log"
  echo "== $name: exit ${PIPESTATUS[0]} after $((SECONDS - t0)) s" | tee -a "$log"
}

step 20 devices python3 -c "import warp as wp; wp.init(); print([str(d) for d in wp.get_devices()])"
# The tests' CUDA cases (the `device` fixture's cuda:0 parameter); the CPU cases ran in CI.
if [ "$device" != cpu ]; then
  step 150 cuda-tests python3 -m pytest -q -ra --continue-on-collection-errors -k "cuda and not compiles_for_cuda" tests
fi
# Issue 3: the FFT ocean step and the pool substep to 2048² on CUDA, against numpy in the same run.
step 100 pool-step python3 -m benchmarks.pool_step $quick --device "$device" --out "$out/pool_step.json"
step 120 ocean-step python3 -m benchmarks.ocean_step $quick --device "$device" --out "$out/ocean_step.json"
# Issue 6: the beam rasteriser's beams/s and shaded pixels/s against numpy, and its scaling.
step 90 beams python3 -m benchmarks.beams --quick --device "$device" --out "$out/beams.json"
# Issues 5 and 10: the photon rate.
step 60 photons python3 -m benchmarks.photons --quick --device "$device" --out "$out/photons.json"
# The scaling plots land in docs/images/ (named by device); bring them back with the records.
cp docs/images/*_"${device//:/}".png "$out"/ 2>/dev/null
echo "== done" | tee -a "$log"
