#!/usr/bin/env bash
# Fixed costs under callgrind (instructions): fesd_create (with set_state), every step of a
# fixed-step integration (its kind, Newton iterations, factorizations, solves) and fesd_free.
#   tools/phases.sh [BUILD_DIR] [PROB S NSIM]   (default: oscillator 5 10, the run of the
#                                                CVODE comparison at error <= 1e-10)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
PROB=${2:-oscillator}
S=${3:-5}
NSIM=${4:-10}
export OPENBLAS_NUM_THREADS=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$tmp/cg.out" \
  "$BUILD/bench/bench_step_cost" phases "$PROB" "$S" "$NSIM" >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; exit 1; }
total=0
for f in $(ls "$tmp"/cg.out.* | sort -V); do
  d=$(grep -m1 '^desc: Trigger' "$f" | sed 's/.*Client Request: //')
  i=$(awk '/^(summary|totals):/ {print $2; exit}' "$f")
  total=$((total + i))
  printf '%-60s %9d\n' "$d" "$i"
done
printf '%-60s %9d\n' total "$total"
