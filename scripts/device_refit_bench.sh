#!/bin/bash
# The heavy-refit benchmark (bench/refit, docs/performance.md "Heavy-refit frames") on the device machine: the full
# table of issue 27 (N = 1, 10, 100, 1000 bottom-level structures of 1,024 triangles refit per frame, as N calls and
# as one call; no layer, asval at default settings, asval with capture=off; three interleaved rounds of 100 frames),
# then the host-work check (100 structures as 100 calls at 64 and at 4,096 triangles each). The Khronos layer is not
# installed there: run_refit.py skips its row. Expects .gl/ and .devrun/ as scripts/device_integration.sh says
# (.devrun/layer/ with the stripped layer and its build-tree manifest, .devrun/lib/libfmt.so.9), plus
# .devrun/refit_frames (stripped), made here with:
#   cmake --build build -j2 --target refit_frames VkLayer_asval_as_validation
#   mkdir -p .devrun/layer && strip -o .devrun/refit_frames build/bench/refit/refit_frames
#   strip -o .devrun/layer/libVkLayer_asval_as_validation.so build/layer/libVkLayer_asval_as_validation.so
#   cp build/layer/VkLayer_asval_as_validation.json .devrun/layer/
# Call: run(command="bash scripts/device_refit_bench.sh", carry=[".gl", ".devrun"]). The tables land in the output,
# the results (JSON) and logs in $OUT/refit-table.*, $OUT/refit-triangles-64.* and $OUT/refit-triangles-4096.*.
# Arguments are passed to the first run_refit.py (e.g. --structures 100,1000 --rounds 5). The timeouts keep the whole
# command inside the device's 10 minutes (the table takes a few minutes there: 72 runs of about 100 frames).
set -o pipefail
source scripts/device_refit_env.sh  # the loader, NVIDIA's driver, $build
runner="python3 bench/refit/run_refit.py --build $build --layer-dir $PWD/.devrun/layer"
timeout 400 $runner --json $OUT/refit-table.json "$@" 2>&1 | tee $OUT/refit-table.log
# Host work per judged update against the triangle count (issue 27's target: the submit+wait time asval adds at 64
# and at 4,096 triangles within 10% of each other).
timeout 80 $runner --structures 100 --shapes calls --triangles 64 --configs none,asval,asval-capture-off \
  --json $OUT/refit-triangles-64.json 2>&1 | tee $OUT/refit-triangles-64.log
timeout 80 $runner --structures 100 --shapes calls --triangles 4096 --configs none,asval,asval-capture-off \
  --json $OUT/refit-triangles-4096.json 2>&1 | tee $OUT/refit-triangles-4096.log
nvidia-smi --query-gpu=utilization.gpu,memory.used --format=csv,noheader
