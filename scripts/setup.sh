#!/usr/bin/env bash
# Installs everything asval needs to build and test, as root, on Debian 12 (bookworm, with bookworm-backports) or
# Debian 13 (trixie, main only). Anywhere else it stops with the list of what to install by hand.
# Idempotent: quiet and fast when everything is already present.
set -euo pipefail

# Packages of the system's own suite.
BASE_PKGS=(g++ cmake ninja-build pkg-config python3 libvulkan-dev vulkan-tools glslang-tools
           libspdlog-dev vulkan-validationlayers libpng-dev libxxhash-dev nlohmann-json3-dev valgrind clang)
# The libFuzzer runtime for the fuzz build (scripts/test.sh) is packaged per LLVM version: that of the suite's
# default clang (Debian 12: 14, Debian 13: 19).
. /etc/os-release 2>/dev/null || true
case "${ID:-}:${VERSION_ID:-}" in
  debian:12) BASE_PKGS+=(libclang-rt-14-dev) ;;
  debian:13) BASE_PKGS+=(libclang-rt-19-dev) ;;
esac
# Packages that need a newer version than Debian 12 has: lavapipe with ray tracing (bookworm's Mesa 22.3 has none)
# and Catch2 3 (bookworm has only Catch2 2). Debian 13 has both in main; Debian 12 takes them from
# bookworm-backports.
NEWER_PKGS=(mesa-vulkan-drivers catch2)
BACKPORTS_LIST=/etc/apt/sources.list.d/asval-bookworm-backports.list

manual_help() {
  cat >&2 <<MSG
asval setup: $1
Install these by hand, then run the command again:
  from your system's suite:       ${BASE_PKGS[*]}
  at least these versions:        mesa-vulkan-drivers >= 25 (lavapipe with ray tracing), catch2 >= 3
                                  (Debian 12: from bookworm-backports; Debian 13: from trixie itself)
Never add another Debian suite than your system's own (e.g. testing on Debian 12): it would upgrade the C library.
MSG
  exit 1
}

missing_pkgs() {
  local p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || echo "$p"
  done
}

# Version checks: Debian 12's own Mesa or Catch2 2 counts as missing.
too_old() {
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  if [ -z "$v" ] || dpkg --compare-versions "$v" lt 25; then echo mesa-vulkan-drivers; fi
  v=$(dpkg-query -W -f='${Version}' catch2 2>/dev/null || true)
  if [ -z "$v" ] || dpkg --compare-versions "$v" lt 3; then echo catch2; fi
}

missing=$(missing_pkgs "${BASE_PKGS[@]}")
missing_newer=$(too_old)
[ -z "$missing" ] && [ -z "$missing_newer" ] && exit 0

if [ "${ID:-}" != debian ] || { [ "${VERSION_ID:-}" != 12 ] && [ "${VERSION_ID:-}" != 13 ]; }; then
  manual_help "this is not Debian 12 or 13 (found ${PRETTY_NAME:-unknown}); automatic install is only for those."
fi
if [ "$(id -u)" -ne 0 ]; then
  manual_help "automatic install needs root."
fi

export DEBIAN_FRONTEND=noninteractive
newer_from=()  # Debian 13: its own suite
if [ "$VERSION_ID" = 12 ]; then
  newer_from=(-t bookworm-backports)
  if ! grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
    echo "asval setup: enabling bookworm-backports in $BACKPORTS_LIST"
    echo 'deb http://deb.debian.org/debian bookworm-backports main' > "$BACKPORTS_LIST"
  fi
fi
echo "asval setup: installing ${missing//$'\n'/ } ${missing_newer//$'\n'/ }"
apt-get update -qq
if [ -n "$missing" ]; then
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi
if [ -n "$missing_newer" ]; then
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends "${newer_from[@]}" $missing_newer >/dev/null
fi
left=$(missing_pkgs "${BASE_PKGS[@]}"; too_old)
[ -z "$left" ] || manual_help "these are still missing after apt-get: ${left//$'\n'/ }"
echo "asval setup: done"
