#!/usr/bin/env bash
# Install what libfesd needs (Debian packages) if missing, then configure a build.
# Idempotent and non-interactive. Usage: tools/setup.sh [BUILD_DIR] [extra meson args...]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-build}
shift || true

PKGS=(build-essential meson ninja-build pkg-config libsuitesparse-dev libopenblas-dev liblapack-dev libmetis-dev valgrind
      python3-numpy python3-matplotlib python3-pytest)
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

# The Python package (python/fesd): `import fesd` for Debian's python3 from anywhere, by a .pth
# file in its user site directory naming python/ of this tree (the last tree set up wins;
# PYTHONPATH=python, which comes first, works without it). It loads build/libfesd.so of the tree.
if [ -x /usr/bin/python3 ]; then
  site=$(/usr/bin/python3 -m site --user-site 2>/dev/null || true)
  if [ -n "$site" ] && mkdir -p "$site" 2>/dev/null; then
    printf '%s\n' "$PWD/python" > "$site/fesd-source.pth"
  fi
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
