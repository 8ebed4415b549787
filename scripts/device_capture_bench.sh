#!/bin/bash
# The sample scene on the device machine with capture off, updates (copied, and by default reduced) and all (docs/performance.md, "Execution-time
# capture"), after the capture tests' valid twins. Expects .gl/ and .devrun/ as scripts/device_integration.sh says,
# plus .devrun/asval_scene (stripped). Call: run(command="bash scripts/device_capture_bench.sh", carry=[".gl", ".devrun"]).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export LD_LIBRARY_PATH=$PWD/.devrun/lib
if ! ls /usr/share/vulkan/icd.d/nvidia_icd.json >/dev/null 2>&1 && ! ls /etc/vulkan/icd.d/nvidia_icd.json >/dev/null 2>&1; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
export VK_LOADER_LAYERS_DISABLE='~implicit~' XDG_DATA_HOME=/tmp/xdg HOME=/tmp/xdg VK_LAYER_SETTINGS_PATH=/tmp/xdg/none; mkdir -p /tmp/xdg
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
bin=.devrun/asval_integration_tests
$bin --list-tests --verbosity quiet "[capture]" > /tmp/names.txt
pass=0; fail=0
while IFS= read -r name; do
  case "$name" in *"valid twin"*|*"capture=off"*) ;; *) continue;; esac
  spec=$(printf '%s' "$name" | sed -e 's/\\/\\\\/g' -e 's/,/\\,/g' -e 's/\[/\\[/g' -e 's/\]/\\]/g')
  if VK_LAYER_PATH=$PWD/.devrun/layer timeout 120 $bin "$spec" > /tmp/one.log 2>&1; then pass=$((pass+1)); else fail=$((fail+1)); echo "FAIL $name"; tail -20 /tmp/one.log; fi
done < /tmp/names.txt
echo "capture valid tests: passed $pass failed $fail"
# Modes: no layer; capture off; capture=updates with capture_method=copy; updates and all with the default
# capture_method (auto: reduce on this GPU).
for round in 1 2 3 4 5; do for mode in none off copy updates all; do
  capture=$mode; method=auto; if [ $mode = copy ]; then capture=updates; method=copy; fi
  if [ $mode = none ]; then r=$(timeout 120 .devrun/asval_scene --frames 300 2>&1 | grep -E "refits|validation messages" | tr '\n' ' ');
  else r=$(VK_ADD_LAYER_PATH=$PWD/.devrun/layer VK_INSTANCE_LAYERS=VK_LAYER_ASVAL_as_validation VK_ASVAL_AS_VALIDATION_CAPTURE=$capture VK_ASVAL_AS_VALIDATION_CAPTURE_METHOD=$method VK_ASVAL_AS_VALIDATION_REPORT_FLAGS=error,warn,info timeout 120 .devrun/asval_scene --frames 300 2>&1 | grep -E "refits|validation messages|Execution-time" | tr '\n' ' '); fi
  echo "$round $mode: $r"
done; done
