#!/bin/bash
# The heavy-refit benchmark (bench/refit) under several builds of the layer in one device call, to compare changes
# of the capture on a GPU (docs/performance.md, issue 27), then the capture tests with .devrun/layer on that GPU.
# Stage each build in .devrun/<name>/ (stripped libVkLayer_asval_as_validation.so and its build-tree manifest, as
# scripts/device_refit_bench.sh says for .devrun/layer), plus .devrun/refit_frames, .devrun/lib/libfmt.so.9 and,
# for the tests, .devrun/asval_integration_tests (scripts/device_integration.sh). Call:
#   run(command="VARIANTS='v_base v_new' bash scripts/device_refit_variants.sh", carry=[".gl", ".devrun"])
# Each variant runs 100 and 1,000 structures of 1,024 triangles and 100 of 64 and of 4,096, both shapes, against no
# layer in the same run_refit.py call, one round each, twice over (variants interleaved); the table rows print.
set -o pipefail
source scripts/device_refit_env.sh  # the loader, NVIDIA's driver, $build
first=${VARIANTS%% *}
for round in 1 2; do
  for v in ${VARIANTS:?name the variants: VARIANTS=\"a b\"}; do
    for tri in 1024 64 4096; do
      structures=100,1000; [ $tri != 1024 ] && structures=100
      configs=none,asval; [ $v = $first ] && configs=none,asval,asval-capture-off
      echo "=== round $round variant $v triangles $tri"
      timeout 120 python3 bench/refit/run_refit.py --build $build --layer-dir $PWD/.devrun/$v \
        --structures $structures --triangles $tri --rounds 1 --configs $configs 2>&1 | grep -E "^\|" | tee -a $OUT/$v.log
    done
  done
done
# The capture tests (valid cases only) with .devrun/layer.
[ -x .devrun/asval_integration_tests ] && timeout 280 bash scripts/device_integration.sh "[capture]" 2>&1 | tail -5
true
