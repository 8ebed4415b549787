#!/bin/bash
# Runs on the device machine (an NVIDIA GPU, see the device tool's README): protect mode against the faults that
# hang that GPU when they reach its driver (issue 16; docs/protect.md). Each fault is an accuracy-corpus case run
# under scripts/asval-run, whose protect mode is on, with the corpus messenger answering VK_FALSE
# (ASVAL_CORPUS_MESSENGER=report-only): only protect mode keeps the fault from the driver. Never run these cases
# any other way there. After each, a valid ray-traced scene (2 frames, no layer) must run within its timeout: the
# GPU is still responsive. Then each of the sample scene's faults the same way (a fault run of the scene turns
# protect mode on itself and never submits a hang-prone fault unless asval announced it withheld it; its messenger
# returns VK_FALSE). A case that times out stops the run (a hang must not be driven further).
# Expects, in the working tree sent there:
#   .gl/      Debian's libvulkan1 (and the GL debs) as .deb files, downloaded as the device README says;
#   .devrun/  build/ (layer/ with the build-tree manifest, tests/corpus/asval_corpus, examples/scene/asval_scene,
#             stripped), lib/ (libfmt.so.9, libpng16.so.16).
# Call: run(command="bash scripts/device_protect.sh", carry=[".gl", ".devrun"]). Results: $OUT/protect-h200.json,
# and each case's report and output, <case>.jsonl and .out (scene faults: scene-<fault>.*), in $OUT/logs.tgz.
set -u
for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
export LD_LIBRARY_PATH=$PWD/.devrun/lib
icd=$(ls /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json \
        /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json 2>/dev/null | head -1)
export VK_DRIVER_FILES=$icd VK_LOADER_LAYERS_DISABLE='~implicit~'
export XDG_DATA_HOME=/tmp/xdg HOME=/tmp/xdg VK_LAYER_SETTINGS_PATH=/tmp/xdg/none; mkdir -p /tmp/xdg
build=$PWD/.devrun/build
corpus=$build/tests/corpus/asval_corpus
scene=$build/examples/scene/asval_scene
gpu=$(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)
echo "$gpu"
# The hang-prone faults named in issue 16, one corpus case each (two for the transform's null-ness).
cases=(history-generic-structure-refit-as-other-level history-refit-aabbs-of-triangle-build
       history-refit-vertex-format-differs history-refit-adds-transform history-refit-drops-transform
       aliasing-two-destinations-same-memory aliasing-destination-over-refit-source
       handles-two-builds-one-destination alignment-index-data-misaligned)
elapsed() { python3 -c "import sys; print('%.2f' % (float(sys.argv[2]) - float(sys.argv[1])))" "$1" "$EPOCHREALTIME"; }
probe() {  # a valid scene without any layer: seconds taken and its exit status
  local start status
  start=$EPOCHREALTIME
  timeout 60 "$scene" --frames 2 --size 64x64 --instances 200 > /tmp/probe.log 2>&1; status=$?
  printf '{"status": %d, "seconds": %s}' "$status" "$(elapsed "$start")"
}
results=$OUT/protect-h200.json
printf '{"gpu": "%s",\n "probe_before": %s,\n "cases": [\n' "$gpu" "$(probe)" > "$results"
first=1
for c in "${cases[@]}"; do
  start=$EPOCHREALTIME
  ASVAL_CORPUS_MESSENGER=report-only timeout 120 python3 scripts/asval-run --layer-path "$build/layer" \
    --report "$OUT/$c.jsonl" -- "$corpus" "$c" > "$OUT/$c.out" 2>&1
  status=$?
  seconds=$(elapsed "$start")
  errors=$(grep -c '"severity":"error"' "$OUT/$c.jsonl" 2>/dev/null)
  withheld=$(grep -c '"vuid":"ASVAL-Protect-Withheld"' "$OUT/$c.jsonl" 2>/dev/null)
  vuids=$(grep -o '"vuid":"VUID-[^"]*"' "$OUT/$c.jsonl" 2>/dev/null | sort -u | cut -d'"' -f4 | paste -sd, -)
  p=$(probe)
  [ $first = 1 ] || printf ',\n' >> "$results"; first=0
  printf '  {"case": "%s", "asval_run_exit": %d, "seconds": %.2f, "errors": %s, "withheld_calls": %s, "vuids": "%s", "probe_after": %s}' \
    "$c" "$status" "$seconds" "${errors:-0}" "${withheld:-0}" "$vuids" "$p" >> "$results"
  echo "$c: asval-run exit $status in ${seconds}s, errors ${errors:-0}, withheld ${withheld:-0}, probe $p"
  if [ $status = 124 ]; then echo "timed out: stopping"; break; fi
done
printf '\n ],\n "scene_faults": [\n' >> "$results"
first=1
[ "${status:-0}" = 124 ] || for f in $("$scene" --list-faults | grep -v "^#" | awk '{print $1}'); do
  start=$EPOCHREALTIME
  timeout 120 python3 scripts/asval-run --layer-path "$build/layer" --report "$OUT/scene-$f.jsonl" -- \
    "$scene" --frames 2 --size 64x64 --instances 200 --inject "$f" > "$OUT/scene-$f.out" 2>&1
  status=$?
  seconds=$(elapsed "$start")
  errors=$(grep -c '"severity":"error"' "$OUT/scene-$f.jsonl" 2>/dev/null)
  withheld=$(grep -c '"vuid":"ASVAL-Protect-Withheld"' "$OUT/scene-$f.jsonl" 2>/dev/null)
  reported=$(grep -c "^fault $f: expected .*: reported" "$OUT/scene-$f.out")
  p=$(probe)
  [ $first = 1 ] || printf ',\n' >> "$results"; first=0
  printf '  {"fault": "%s", "asval_run_exit": %d, "seconds": %s, "errors": %s, "withheld_calls": %s, "expected_vuid_reported": %s, "probe_after": %s}' \
    "$f" "$status" "$seconds" "${errors:-0}" "${withheld:-0}" "$reported" "$p" >> "$results"
  echo "scene $f: asval-run exit $status in ${seconds}s, errors ${errors:-0}, withheld ${withheld:-0}, probe $p"
  if [ $status = 124 ]; then echo "timed out: stopping"; break; fi
done
printf '\n ],\n "gpu_after": "%s"}\n' "$(nvidia-smi --query-gpu=utilization.gpu,memory.used --format=csv,noheader)" >> "$results"
cat "$results"
# The per-case files in one archive (the device tool brings back a few files only).
(cd "$OUT" && tar czf logs.tgz --remove-files ./*.jsonl ./*.out)
