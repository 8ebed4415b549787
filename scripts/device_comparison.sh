#!/bin/bash
# Runs on the device machine (an NVIDIA GPU, see the device tool's README) what docs/comparison.md measures on
# lavapipe: `overhead` runs bench/overhead (wall time; that image has no valgrind), `corpus` runs the accuracy
# corpus and the scene's faults. The Khronos layer there is Debian's 1.3.239, carried along (the image has none),
# and runs only the corpus's valid programs: an invalid build it does not catch would reach the GPU, and some hang
# it. asval runs every case: it keeps each fault it reports from the driver (the corpus messenger returns VK_TRUE).
# Expects, in the working tree sent there:
#   .gl/       Debian's libvulkan1 (and the GL debs) as .deb files, as the device README says;
#   .devrun/   build/ (a build tree's layer/, tests/corpus/asval_corpus, examples/scene/asval_scene and
#              bench/overhead programs, stripped), khronos/ (Debian's libVkLayer_khronos_validation.so and its
#              manifest with KHRONOS_DIR for its folder), lib/ (libfmt.so.9, libpng16.so.16).
# Call: run(command="bash scripts/device_comparison.sh overhead|corpus", carry=[".gl", ".devrun"]).
set -u
what=${1:-corpus}
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
export LD_LIBRARY_PATH=$PWD/.devrun/lib
icd=$(ls /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json \
        /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json 2>/dev/null | head -1)
export VK_DRIVER_FILES=$icd
mkdir -p /usr/share/vulkan/explicit_layer.d
sed "s|KHRONOS_DIR|$PWD/.devrun/khronos|" .devrun/khronos/VkLayer_khronos_validation.json \
  > /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
build=$PWD/.devrun/build
case $what in
  overhead)
    timeout 400 python3 bench/overhead/run_overhead.py --build "$build" --rounds 7 --json "$OUT/overhead-h200.json"
    # The run time against error view: the dynamic frame with each family switched off (comparison.py's FAMILY_CONFIGS).
    families=(features handles structure alignment addresses aliasing host copies history)
    view=(); names=none
    for f in "${families[@]}"; do
      rest=$(printf '%s\n' "${families[@]}" | grep -vx "$f" | paste -sd, -)
      view+=(--config "asval-no-$f:VK_ASVAL_AS_VALIDATION_ENABLED_CHECKS=$rest"); names+=",asval-no-$f"
    done
    timeout 150 python3 bench/overhead/run_overhead.py --build "$build" --rounds 9 --rows "frame dynamic" \
      --configs "$names" "${view[@]}" --json "$OUT/overhead-h200-families.json"
    ;;
  corpus)
    timeout 560 python3 tests/corpus/run_corpus.py --corpus "$build/tests/corpus/asval_corpus" \
      --scene "$build/examples/scene/asval_scene" --layer-path "$build/layer" --driver-files "$icd" \
      --valid-only khronos --jobs 8 --json "$OUT/corpus-h200.json"
    ;;
esac
nvidia-smi --query-gpu=utilization.gpu,memory.used --format=csv,noheader
