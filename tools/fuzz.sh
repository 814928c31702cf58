#!/usr/bin/env bash
# Build the differential fuzz target tests/fuzz/fuzz_step.c with libFuzzer, AddressSanitizer and
# UBSan against the library sources, and run it for a bounded time.
# Usage: tools/fuzz.sh [SECONDS] [extra libFuzzer args...]   (default 60 s)
# Exit status: 0 if no crash (no disagreement with the reference, no sanitizer report), nonzero
# otherwise; crashing inputs are written to build-fuzz/crash-*. FESD_FUZZ_KNOWN=1 also feeds
# the cases that fail today for known reasons (see tests/fuzz/fuzz_step.c).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_MAX=${1:-60}
shift || true
OUT=build-fuzz

if ! command -v clang >/dev/null 2>&1; then
  echo "fuzz: installing clang"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends clang >/dev/null
fi
tools/setup.sh build >/dev/null # the Debian packages the library needs (SuiteSparse, OpenBLAS)

mkdir -p "$OUT/corpus"
SRCS=$(ls src/common/*.c src/rk/*.c src/ncp/*.c src/fesd/*.c)
BLAS=-lopenblas
pkg-config --exists openblas 2>/dev/null && BLAS=$(pkg-config --libs openblas)
FLAGS=(-std=c11 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
       -fno-omit-frame-pointer -D_POSIX_C_SOURCE=200809L -DFESD_BUILDING -DFESD_LIBFUZZER
       -Iinclude -Isrc -Itests/prop -I/usr/include/suitesparse)
pkg-config --exists openblas 2>/dev/null && FLAGS+=($(pkg-config --cflags openblas))
echo "fuzz: building $OUT/fuzz_step"
clang "${FLAGS[@]}" $SRCS tests/prop/pwa_ref.c tests/fuzz/fuzz_step.c -o "$OUT/fuzz_step" \
  -lumfpack -lklu -lcholmod -lamd -lcolamd -lbtf -lsuitesparseconfig $BLAS -lm

export OPENBLAS_NUM_THREADS=1
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
echo "fuzz: running for ${SECONDS_MAX} s"
set +e
"$OUT/fuzz_step" -max_total_time="$SECONDS_MAX" -max_len=256 -print_final_stats=1 \
  -artifact_prefix="$OUT/" "$@" "$OUT/corpus"
rc=$?
set -e
if [ $rc -ne 0 ]; then
  echo "fuzz: FAILED (exit status $rc); crashing input in $OUT/" >&2
  exit $rc
fi
echo "fuzz: no crash in ${SECONDS_MAX} s"
