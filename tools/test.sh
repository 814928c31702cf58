#!/usr/bin/env bash
# Set up (if needed), build and run the whole test suite.
# Usage: tools/test.sh                 -> release build in ./build
#        FESD_SANITIZE=1 tools/test.sh -> AddressSanitizer/UBSan build in ./build-asan
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${FESD_SANITIZE:-0}" = 1 ]; then
  BUILD_DIR=${BUILD_DIR:-build-asan}
  tools/setup.sh "$BUILD_DIR" -Db_sanitize=address,undefined -Dbuildtype=debugoptimized -Db_lundef=false
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
else
  BUILD_DIR=${BUILD_DIR:-build}
  tools/setup.sh "$BUILD_DIR"
fi
export OPENBLAS_NUM_THREADS=1
meson compile -C "$BUILD_DIR" >/dev/null
set +e
meson test -C "$BUILD_DIR" --print-errorlogs --num-processes 2 "$@" | tee "$BUILD_DIR/test-summary.txt"
rc=${PIPESTATUS[0]}
set -e
ok=$(awk '/^Ok:/{print $2}' "$BUILD_DIR/test-summary.txt")
fail=$(awk '/^Fail:/{print $2}' "$BUILD_DIR/test-summary.txt")
to=$(awk '/^Timeout:/{print $2}' "$BUILD_DIR/test-summary.txt")
echo "tests: ${ok:-0} passed, $(( ${fail:-0} + ${to:-0} )) failed"
exit $rc
