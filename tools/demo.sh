#!/usr/bin/env bash
# Fresh machine: install what is missing (Debian packages), build (release), run the demo.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh build
meson compile -C build >/dev/null
OPENBLAS_NUM_THREADS=1 ./build/examples/fesd-demo
