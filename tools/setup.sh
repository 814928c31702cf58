#!/usr/bin/env bash
# Install what libfesd needs (Debian packages) if missing, then configure a build.
# Idempotent and non-interactive. Usage: tools/setup.sh [BUILD_DIR] [extra meson args...]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-build}
shift || true

PKGS=(build-essential meson ninja-build pkg-config libsuitesparse-dev libopenblas-dev liblapack-dev libmetis-dev valgrind)
[ "${FESD_SETUP_EXTRA:-}" ] && PKGS+=(${FESD_SETUP_EXTRA})
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [ ! -f "$BUILD_DIR/build.ninja" ]; then
  log=$(mktemp)
  if ! meson setup "$BUILD_DIR" "$@" >"$log" 2>&1; then
    cat "$log" >&2
    rm -f "$log"
    echo "setup: meson setup failed" >&2
    exit 1
  fi
  rm -f "$log"
fi
