#!/bin/bash
# Runs on the device machine (an NVIDIA GPU, see the device tool's README): the integration suite, one process
# per test case (that driver refuses vkCreateInstance after ~29 instances per process), without the tests that
# pass invalid calls down (invalid builds can hang that GPU). Expects, in the working tree sent there:
#   .gl/      Debian's libvulkan1 (and the GL debs) as .deb files, downloaded as the device README says;
#   .devrun/  layer/ (stripped libVkLayer_asval_as_validation.so and its build-tree manifest),
#             asval_integration_tests (stripped), lib/libfmt.so.9.
# Call: run(command="bash scripts/device_integration.sh", carry=[".gl", ".devrun"]). Failures land in
# $OUT/failures.txt. An argument narrows the run further (a Catch2 test spec, e.g. "[protect]"); the tests that pass
# invalid calls down stay out whatever it says.
# ASVAL_DEVICE_KHRONOS=1 stacks the Khronos layer below asval, as the local self-validation run does: .devrun/khronos/
# then holds Debian's libVkLayer_khronos_validation.so, its manifest (library_path "./...") and the run's
# vk_layer_settings.txt (build/tests/integration/khronos_settings/). ASVAL_TEST_NV_NATIVE=1 runs the VK_NV_ray_tracing
# tests ("[nv]") on the GPU's own extension instead of the test driver's (tests/integration/nv_helpers.h).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export LD_LIBRARY_PATH=$PWD/.devrun/lib
if ! ls /usr/share/vulkan/icd.d/nvidia_icd.json >/dev/null 2>&1 && ! ls /etc/vulkan/icd.d/nvidia_icd.json >/dev/null 2>&1; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
export VK_LAYER_PATH=$PWD/.devrun/layer VK_LOADER_LAYERS_DISABLE='~implicit~'
export XDG_DATA_HOME=/tmp/xdg HOME=/tmp/xdg VK_LAYER_SETTINGS_PATH=/tmp/xdg/none; mkdir -p /tmp/xdg
if [ "${ASVAL_DEVICE_KHRONOS:-}" = 1 ]; then
  export VK_LAYER_PATH=$VK_LAYER_PATH:$PWD/.devrun/khronos VK_LAYER_SETTINGS_PATH=$PWD/.devrun/khronos/vk_layer_settings.txt
  export ASVAL_TEST_LAYERS=VK_LAYER_ASVAL_as_validation:VK_LAYER_KHRONOS_validation
fi
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
bin=.devrun/asval_integration_tests
$bin --list-tests --verbosity quiet "${1:-}~[passes-invalid-down]" > /tmp/names.txt
echo "$(wc -l < /tmp/names.txt) test cases"
pass=0; fail=0; : > $OUT/failures.txt
while IFS= read -r name; do
  spec=$(printf '%s' "$name" | sed -e 's/\\/\\\\/g' -e 's/,/\\,/g' -e 's/\[/\\[/g' -e 's/\]/\\]/g')
  if timeout 60 $bin "$spec" > /tmp/one.log 2>&1; then pass=$((pass+1)); else fail=$((fail+1)); { echo "== $name"; tail -40 /tmp/one.log; } >> $OUT/failures.txt; fi
done < /tmp/names.txt
echo "passed $pass failed $fail"
nvidia-smi --query-gpu=utilization.gpu,memory.used --format=csv,noheader
