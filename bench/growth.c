/* Growth with problem size: a chain of n masses with Coulomb friction on a belt
 * (n independent switching subsystems, n_x = 2n, sparse model API), n = 8 .. 1024.
 * Belt speed 5: every mass keeps slipping over the horizon, so every step is an ordinary
 * step and the time measures how the sparse step system scales. Two series: "default"
 * (the guess sweeps converge, few Newton iterations) and "newton" (one sweep, so every step
 * factorizes the sparse step Jacobian). CPU time per step by bench_time (median of
 * repetitions). Writes OUTDIR/growth.csv and prints the fitted exponent of time per step
 * against n.
 *   bench_growth [--quick] [OUTDIR]   (--quick: n = 8 .. 128, short timings) */
#include <math.h>
#include <stdio.h>

#include "bench_util.h"
#include "problems/friction_chain.h"

typedef struct {
  fesd_integrator *it;
  const double *x0;
  int nsteps;
} chain_job;

static int run_chain(void *ctx) {
  chain_job *j = ctx;
  int st = fesd_set_state(j->it, 0, j->x0, NULL);
  for (int k = 0; k < j->nsteps && !st; k++) st = fesd_step(j->it, NULL, 0.2, NULL);
  return st;
}

int main(int argc, char **argv) {
  if (bench_init(argc, argv, "bench_growth [--quick] [OUTDIR]")) return 2;
  FILE *out = bench_csv("growth.csv", "series,n,nx,unknowns_per_step,ms_per_step,"
                                      "newton_iter_per_step,factorizations_per_step");
  if (!out) return 1;
  printf("%-8s %6s %6s %9s %12s %10s\n", "series", "n", "n_x", "unknowns", "ms/step", "iter/step");
  const int nsteps = 30, nmax = bench_opt.quick ? 128 : 1024;
  int rc = 0;
  for (int series = 0; series < 2; series++) {
    const char *name = series ? "newton" : "default";
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int m = 0;
    for (int n = 8; n <= nmax; n *= 2) {
      fesd_friction_chain fc;
      if (fesd_friction_chain_init(&fc, n, 5.0)) return 1;
      fesd_settings set;
      fesd_settings_default(&set);
      if (series) set.max_sweeps = 1;
      fesd_integrator *it;
      int st = fesd_create(&it, &fc.model, &set);
      if (st) {
        fprintf(stderr, "bench_growth: %s\n", fesd_status_string(st));
        return 1;
      }
      chain_job job = {it, fc.x0, nsteps};
      double ms = 1e3 * bench_time(run_chain, &job) / nsteps;
      fesd_stats S;
      fesd_get_stats(it, &S);
      /* unknowns of one step system: per stage v, theta, lambda, mu; x_{n+1}, h per element */
      int unknowns = set.n_fe * (set.stages * (2 * n + 2 * (2 * n) + n) + 2 * n + 1);
      double iters = (double)S.newton_iter / S.steps;
      printf("%-8s %6d %6d %9d %12.4f %10.2f%s\n", name, n, 2 * n, unknowns, ms, iters,
             isnan(ms) ? "  (failed)" : "");
      fprintf(out, "%s,%d,%d,%d,%.6f,%.3f,%.3f\n", name, n, 2 * n, unknowns, ms, iters,
              (double)S.factorizations / S.steps);
      rc |= isnan(ms);
      double lx = log((double)n), ly = log(ms);
      sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, m++;
      fesd_free(&it);
      fesd_friction_chain_free(&fc);
    }
    printf("%s: fitted exponent of time per step vs n: %.2f (target <= 1.2)\n", name,
           (m * sxy - sx * sy) / (m * sxx - sx * sx));
  }
  fclose(out);
  return rc;
}
