# Sourced by the device scripts of the refit benchmark (device_refit_bench.sh, device_refit_variants.sh), on the
# device machine: the carried loader unpacked, the carried libraries found, NVIDIA's Vulkan driver named for
# run_refit.py (which gives every run the integration environment, lavapipe unless VK_DRIVER_FILES names a driver),
# and a build folder of the shape run_refit.py expects (BUILD/bench/refit/refit_frames) holding the carried program:
# $build.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export LD_LIBRARY_PATH=$PWD/.devrun/lib PYTHONUNBUFFERED=1
for icd in /usr/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json \
           /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json; do
  if [ -f $icd ]; then export VK_DRIVER_FILES=$icd; break; fi
done
[ -n "$VK_DRIVER_FILES" ] || { echo "no NVIDIA Vulkan driver manifest found"; exit 1; }
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
build=/tmp/refit-build; mkdir -p $build/bench/refit; cp .devrun/refit_frames $build/bench/refit/
