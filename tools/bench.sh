#!/usr/bin/env bash
# Build in release mode (./build-release), run every benchmark of bench/, write CSV and
# PNG plots into bench/results/ and print the summary tables (Markdown).
#   tools/bench.sh           full grids (a few minutes), results in bench/results/
#   tools/bench.sh --quick   small grids (CI), results in build-release/bench-quick/
#   tools/bench.sh --ncp     also the solver backend benchmark bench/ncp_bench (long: up
#                            to n = 5000; --quick runs it up to n = 20)
# Installs gnuplot-nox (and python3) with apt-get if missing. Timings are CPU time of the
# benchmark thread, median of 5 repetitions of >= 0.2 s; nothing is asserted.
set -euo pipefail
cd "$(dirname "$0")/.."
QUICK=0 NCP=0
for a in "$@"; do
  case $a in
    --quick) QUICK=1 ;;
    --ncp) NCP=1 ;;
    *) echo "usage: tools/bench.sh [--quick] [--ncp]" >&2; exit 2 ;;
  esac
done
BUILD_DIR=${BUILD_DIR:-build-release}
extra="gnuplot-nox libsundials-dev" # SUNDIALS: the CVODE comparison of bench_workprec only
command -v python3 >/dev/null || extra+=" python3"
FESD_SETUP_EXTRA="$extra" tools/setup.sh "$BUILD_DIR" -Dbuildtype=release
meson compile -C "$BUILD_DIR" >/dev/null
export OPENBLAS_NUM_THREADS=1 # one thread: CPU time of the calling thread is the whole cost

if [ $QUICK = 1 ]; then
  OUT=$BUILD_DIR/bench-quick ARGS=(--quick) NCP_MAX_N=20 NCP=1
  rm -rf "$OUT"
else
  OUT=bench/results ARGS=() NCP_MAX_N=5000
fi
mkdir -p "$OUT"
t0=$(date +%s)
for b in order sliding_exit sensitivity stewart_anitescu pareto anatomy growth workprec ocp_pareto; do
  echo "== bench_$b"
  "$BUILD_DIR/bench/bench_$b" "${ARGS[@]}" "$OUT"
done
if [ $NCP = 1 ]; then
  echo "== ncp_bench (max n = $NCP_MAX_N)"
  "$BUILD_DIR/bench/ncp_bench" "$OUT/ncp_backends.csv" "$NCP_MAX_N"
fi
gnuplot -e "dir='$OUT'" tools/plot.gp
python3 tools/check_csv.py "$OUT"/*.csv
echo "Results: $OUT (CSV, PNG, summary.md); $(( $(date +%s) - t0 )) s"
echo
{
  echo "Machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//');" \
       "$(date -u +%Y-%m-%d)$([ $QUICK = 1 ] && echo ' (quick mode: small grids, short timings)')"
  echo
  python3 tools/bench_summary.py "$OUT"
} | tee "$OUT/summary.md"
