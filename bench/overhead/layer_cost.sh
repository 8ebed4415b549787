#!/bin/sh
# layer_cost.sh BUILD_DIR CALLS INFOS GEOMETRIES [own]: the instructions the asval layer adds per
# vkCmdBuildAccelerationStructuresKHR call (every family on, lavapipe), from two callgrind runs of record_builds,
# without and with the layer (docs/performance.md). Prints: Ir without, Ir with, driver per call, layer per call.
set -eu
build=$1; shift
calls=$1
export VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.json VK_LOADER_LAYERS_DISABLE='~implicit~'
out=$(mktemp -d)
total() { sed -n 's/^totals: *//p' "$1"; }
valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file="$out/without" \
  "$build/bench/overhead/record_builds" "$@" >/dev/null 2>&1
VK_ADD_LAYER_PATH="$build/layer" VK_INSTANCE_LAYERS=VK_LAYER_ASVAL_as_validation \
  valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file="$out/with" \
  "$build/bench/overhead/record_builds" "$@" >/dev/null 2>&1
without=$(total "$out/without")
with=$(total "$out/with")
echo "$* : without $without, with $with, driver/call $((without / calls)), layer/call $(((with - without) / calls))"
echo "callgrind files: $out"
