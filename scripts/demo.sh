#!/usr/bin/env bash
# Installs what is missing (Debian 12, as root), builds, then runs the bundled sample program under the
# asval layer on lavapipe and prints what the layer reported.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

bash scripts/setup.sh
build=${ASVAL_BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j"$(nproc)" --target VkLayer_asval_as_validation minimal_build

echo
echo "== minimal_build under VK_LAYER_ASVAL_as_validation (lavapipe) =="
VK_ADD_LAYER_PATH="$build/layer" \
VK_INSTANCE_LAYERS=VK_LAYER_ASVAL_as_validation \
VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.json} \
VK_LOADER_LAYERS_DISABLE='~implicit~' \
  "$build/examples/minimal/minimal_build"
