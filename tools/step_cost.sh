#!/usr/bin/env bash
# Instructions per ordinary step (callgrind, noise-free) of every case of bench_step_cost and of
# the stand-alone Radau IIA reference (bench_radau_ref, s = 3, 4, 5): (I(K2) - I(K1)) / (K2 - K1)
# with only the steps collected. Writes OUT (default bench/results/step_cost.csv).
#   tools/step_cost.sh [BUILD_DIR] [OUT] [CASE...]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
OUT=${2:-bench/results/step_cost.csv}
shift 2 || shift $# || true
K1=2
K2=6
export OPENBLAS_NUM_THREADS=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

instr() { # instructions collected by one run of the command
  valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$tmp/cg.out" "$@" >"$tmp/log" 2>&1 ||
    { cat "$tmp/log" >&2; return 1; }
  awk '/^(summary|totals):/ {print $2; exit}' "$tmp/cg.out"
}

per_step() { # command prefix; the step count is appended (reference: before its s argument)
  local a b
  a=$(instr "$@" "$K1"); b=$(instr "$@" "$K2")
  echo $(( (b - a) / (K2 - K1) ))
}

cases=("$@")
[ ${#cases[@]} -eq 0 ] && mapfile -t cases < <("$BUILD/bench/bench_step_cost" list)
echo "case,instr_per_step" >"$OUT"
for c in "${cases[@]}"; do
  n=$(per_step "$BUILD/bench/bench_step_cost" steps "$c")
  echo "$c,$n" | tee -a "$OUT"
done
for s in 3 4 5; do
  a=$(instr "$BUILD/bench/bench_radau_ref" "$K1" "$s"); b=$(instr "$BUILD/bench/bench_radau_ref" "$K2" "$s")
  echo "radau-ref-s$s,$(( (b - a) / (K2 - K1) ))" | tee -a "$OUT"
done
