#!/bin/sh
# static_scene_cost.sh BUILD_DIR [FRAMES_A FRAMES_B]: the instructions asval adds per frame of the sample scene's
# static mode (built in frame 0, then only traced: one submission with one vkCmdTraceRaysKHR per frame), from
# callgrind runs (all threads) of asval_scene --static at two frame counts, without and with the layer (default
# settings, lavapipe). The difference of the two counts removes start-up and shader compilation; run it once
# before measuring so that Mesa's shader cache is warm (the first run compiles every shader). docs/performance.md.
set -eu
build=$1
a=${2:-3}
b=${3:-23}
export VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.json VK_LOADER_LAYERS_DISABLE='~implicit~'
out=$(mktemp -d)
total() { sed -n 's/^totals: *//p' "$1"; }
run() {  # name frames [asval]
  if [ "${3:-}" = asval ]; then
    VK_ADD_LAYER_PATH="$build/layer" VK_INSTANCE_LAYERS=VK_LAYER_ASVAL_as_validation \
      valgrind --tool=callgrind --callgrind-out-file="$out/$1" "$build/examples/scene/asval_scene" --static \
      --frames "$2" --size 16x16 >/dev/null 2>&1
  else
    valgrind --tool=callgrind --callgrind-out-file="$out/$1" "$build/examples/scene/asval_scene" --static \
      --frames "$2" --size 16x16 >/dev/null 2>&1
  fi
}
run none_a "$a"; run none_b "$b"; run asval_a "$a" asval; run asval_b "$b" asval
none=$((($(total "$out/none_b") - $(total "$out/none_a")) / (b - a)))
asval=$((($(total "$out/asval_b") - $(total "$out/asval_a")) / (b - a)))
echo "static frame, Ir: no layer $none, asval $asval, asval adds $((asval - none))"
echo "callgrind files: $out"
