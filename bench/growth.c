/* Growth with problem size: a chain of n masses with Coulomb friction on a belt
 * (n independent switching subsystems, n_x = 2n, sparse model API), n = 8 .. 1024.
 * Belt speed 5: every mass keeps slipping over the horizon, so every step is an ordinary
 * step and the time measures how the sparse step system scales. CPU time per step:
 * median of 5 repetitions, each repeated until >= 0.2 s. Writes OUTDIR/growth.csv and
 * prints the fitted exponent of time per step vs n.
 *   bench_growth [--quick] [OUTDIR]   (--quick: n = 8 .. 128, short timings) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fesd.h"
#include "problems/friction_chain.h"

static double cpu(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int main(int argc, char **argv) {
  const char *dir = "bench/results";
  int quick = 0;
  for (int a = 1; a < argc; a++) {
    if (!strcmp(argv[a], "--quick")) quick = 1;
    else dir = argv[a];
  }
  char path[4096];
  snprintf(path, sizeof(path), "%s/growth.csv", dir);
  FILE *out = fopen(path, "w");
  if (!out) {
    fprintf(stderr, "growth: cannot write %s\n", path);
    return 1;
  }
  fprintf(out, "series,n,nx,unknowns_per_step,ms_per_step,newton_iter_per_step,factorizations_per_step\n");
  printf("%-8s %6s %6s %9s %12s %10s\n", "series", "n", "n_x", "unknowns", "ms/step", "iter/step");
  const int nsteps = 30, nmax = quick ? 128 : 1024;
  /* series "default": the guess sweeps converge and most steps need no Newton iteration;
   * series "newton": one sweep, so every step factorizes the sparse step Jacobian (KLU) */
  for (int series = 0; series < 2; series++) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  const char *name = series ? "newton" : "default";
  for (int n = 8; n <= nmax; n *= 2) {
    fesd_friction_chain fc;
    if (fesd_friction_chain_init(&fc, n, 5.0)) return 1;
    fesd_settings set;
    fesd_settings_default(&set);
    if (series) set.max_sweeps = 1;
    fesd_integrator *it;
    int st = fesd_create(&it, &fc.model, &set);
    if (st) {
      fprintf(stderr, "growth: %s\n", fesd_status_string(st));
      return 1;
    }
    double med[5];
    fesd_stats S = {0};
    for (int r = 0; r < 5; r++) {
      int reps = 0;
      double t0 = cpu(), el;
      do {
        fesd_set_state(it, 0, fc.x0, NULL);
        for (int k = 0; k < nsteps && !st; k++) st = fesd_step(it, NULL, 0.2, NULL);
        reps++;
        el = cpu() - t0;
      } while (el < (quick ? 0.02 : 0.2) && !st);
      med[r] = 1e3 * el / (reps * nsteps);
    }
    fesd_get_stats(it, &S);
    qsort(med, 5, sizeof(double), cmp);
    int unknowns = 0;
    { /* unknowns of one step system: per stage v, theta, lambda, mu; x_{n+1}, h per element */
      int nth = 2 * n;
      unknowns = set.n_fe * (set.stages * (2 * n + 2 * nth + n) + 2 * n + 1);
    }
    printf("%-8s %6d %6d %9d %12.4f %10.2f%s\n", name, n, 2 * n, unknowns, med[2],
           (double)S.newton_iter / S.steps, st ? "  (failed)" : "");
    fprintf(out, "%s,%d,%d,%d,%.6f,%.3f,%.3f\n", name, n, 2 * n, unknowns, med[2],
            (double)S.newton_iter / S.steps, (double)S.factorizations / S.steps);
    double lx = log((double)n), ly = log(med[2]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, m++;
    fesd_free(&it);
    fesd_friction_chain_free(&fc);
  }
  double slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
  printf("%s: fitted exponent of time per step vs n: %.2f (target <= 1.2)\n", name, slope);
  }
  fclose(out);
  return 0;
}
