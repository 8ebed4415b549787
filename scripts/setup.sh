#!/usr/bin/env bash
# Installs everything asval needs to build and test on Debian 12 (bookworm), as root.
# Idempotent: quiet and fast when everything is already present.
set -euo pipefail

# Packages from bookworm itself.
BASE_PKGS=(g++ cmake ninja-build pkg-config python3 libvulkan-dev vulkan-tools glslang-tools
           libspdlog-dev vulkan-validationlayers libpng-dev libxxhash-dev nlohmann-json3-dev)
# Packages that must come from bookworm-backports: lavapipe with ray tracing (bookworm's 22.3 has
# none) and Catch2 3 (bookworm has only Catch2 2).
BACKPORT_PKGS=(mesa-vulkan-drivers catch2)
BACKPORTS_LIST=/etc/apt/sources.list.d/asval-bookworm-backports.list

manual_help() {
  cat >&2 <<MSG
asval setup: $1
Install these by hand, then run the command again:
  from Debian 12 (bookworm):      ${BASE_PKGS[*]}
  from bookworm-backports:        mesa-vulkan-drivers (>= 25, lavapipe with ray tracing), catch2 (>= 3)
Never add another Debian suite (testing, trixie): it would upgrade the C library.
MSG
  exit 1
}

missing_pkgs() {
  local p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || echo "$p"
  done
}

# Version checks: a bookworm mesa or Catch2 2 counts as missing.
needs_backport() {
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  if [ -z "$v" ] || dpkg --compare-versions "$v" lt 25; then echo mesa-vulkan-drivers; fi
  v=$(dpkg-query -W -f='${Version}' catch2 2>/dev/null || true)
  if [ -z "$v" ] || dpkg --compare-versions "$v" lt 3; then echo catch2; fi
}

missing=$(missing_pkgs "${BASE_PKGS[@]}")
missing_bp=$(needs_backport)
[ -z "$missing" ] && [ -z "$missing_bp" ] && exit 0

. /etc/os-release 2>/dev/null || true
if [ "${ID:-}" != debian ] || [ "${VERSION_ID:-}" != 12 ]; then
  manual_help "this is not Debian 12 (found ${PRETTY_NAME:-unknown}); automatic install is only for Debian 12."
fi
if [ "$(id -u)" -ne 0 ]; then
  manual_help "automatic install needs root."
fi

export DEBIAN_FRONTEND=noninteractive
if ! grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
  echo "asval setup: enabling bookworm-backports in $BACKPORTS_LIST"
  echo 'deb http://deb.debian.org/debian bookworm-backports main' > "$BACKPORTS_LIST"
fi
echo "asval setup: installing ${missing//$'\n'/ } ${missing_bp//$'\n'/ }"
apt-get update -qq
if [ -n "$missing" ]; then
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi
if [ -n "$missing_bp" ]; then
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends -t bookworm-backports $missing_bp >/dev/null
fi
left=$(missing_pkgs "${BASE_PKGS[@]}"; needs_backport)
[ -z "$left" ] || manual_help "these are still missing after apt-get: ${left//$'\n'/ }"
echo "asval setup: done"
