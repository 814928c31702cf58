/* Sensitivities (paper Sec. 2.4, Theorem 5).
 * 1. Error of dx(T)/dx0 on the oscillator vs h, FESD and standard. Exact (as in
 *    tests/fesd/test_sensitivity.c): X(T) = expm(A1 (T-1)) J expm(A2) with the saltation
 *    matrix J at the crossing. Error = max entry of |S - X(T)|.
 * 2. Overhead: CPU time per integration with settings.sensitivities = 1 against 0.
 * Output: sensitivity.csv, sensitivity_overhead.csv. */
#include <math.h>

#include "bench_util.h"

static const double W = 2 * 3.14159265358979323846;

static void exact_X(double T, double X[4]) { /* column-major */
  double tau = T - 1, e = exp(tau) * exp(1.0), c = cos(W * tau), s = sin(W * tau);
  double RJ[4] = {c - 2 * W * s, -s - 2 * W * c, s, c}; /* R = [[c, s], [-s, c]], J = [[1, 0], [-2w, 1]] */
  for (int i = 0; i < 4; i++) X[i] = e * RJ[i];
}

static void errors(FILE *csv, const fesd_problem *P, const int *grid, int ng) {
  static const struct {
    fesd_rk_family fam;
    int s;
  } cases[] = {{FESD_RK_RADAU_IIA, 2}, {FESD_RK_RADAU_IIA, 3}, {FESD_RK_RADAU_IIA, 4}, {FESD_RK_GAUSS_LEGENDRE, 2}};
  double X[4];
  exact_X(P->T, X);
  printf("|dx(T)/dx0 - exact|, oscillator:\n");
  for (int c = 0; c < 4; c++)
    for (int m = 0; m < 2; m++) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.family = cases[c].fam;
      set.stages = cases[c].s;
      set.method = m ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
      set.sensitivities = 1;
      fesd_integrator *it = bench_create(P, &set);
      if (!it) continue;
      double h[32], e[32];
      for (int g = 0; g < ng; g++) {
        bench_job j = {it, P, grid[g], P->T};
        bench_run r;
        int st = bench_integrate(&j, &r);
        double S[4];
        fesd_get_sensitivities(it, S, NULL);
        h[g] = P->T / grid[g];
        e[g] = 0;
        for (int i = 0; i < 4; i++) e[g] = fmax(e[g], fabs(S[i] - X[i]));
        if (st) e[g] = NAN;
        fprintf(csv, "%s,%d,%s,%d,%.6e,%.6e,%.6e,%d\n", fesd_rk_family_name(set.family), set.stages,
                m ? "standard" : "fesd", grid[g], h[g], e[g], r.err, st);
      }
      fesd_free(&it);
      printf("  %-6s s=%d %-8s  %.1e (N=%d) .. %.1e (N=%d), order %.2f\n", fesd_rk_family_name(set.family),
             set.stages, m ? "standard" : "fesd", e[0], grid[0], e[ng - 1], grid[ng - 1],
             bench_slope(h, e, ng, 1e-11, 1e3, NULL));
    }
}

static void overhead(FILE *csv) {
  static const struct {
    const char *prob;
    fesd_method method;
    int s, nsim;
  } cases[] = {{"oscillator", FESD_METHOD_FESD, 3, 40}, {"oscillator", FESD_METHOD_FESD, 5, 10},
               {"oscillator", FESD_METHOD_STANDARD, 3, 40}, {"sign-c", FESD_METHOD_FESD, 2, 20},
               {"ocp-dynamics", FESD_METHOD_FESD, 2, 40}};
  const int nc = bench_opt.quick ? 2 : 5;
  printf("sensitivity overhead (CPU per integration):\n");
  for (int c = 0; c < nc; c++) {
    fesd_problem P;
    fesd_problem_get(cases[c].prob, &P);
    double t[2];
    int iters[2];
    for (int on = 0; on < 2; on++) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.method = cases[c].method;
      set.stages = cases[c].s;
      set.sensitivities = on;
      fesd_integrator *it = bench_create(&P, &set);
      if (!it) return;
      bench_job j = {it, &P, cases[c].nsim, P.T};
      bench_run r;
      bench_integrate(&j, &r);
      iters[on] = r.stats.newton_iter;
      t[on] = bench_time(bench_integrate_fn, &j);
      fesd_free(&it);
    }
    const char *mname = cases[c].method ? "standard" : "fesd";
    fprintf(csv, "%s,%s,radau,%d,%d,%.4f,%.4f,%.3f,%d,%d\n", P.name, mname, cases[c].s, cases[c].nsim, 1e3 * t[0],
            1e3 * t[1], t[1] / t[0], iters[0], iters[1]);
    printf("  %-12s %-8s s=%d N=%3d: %.3f ms -> %.3f ms (x%.2f)\n", P.name, mname, cases[c].s, cases[c].nsim,
           1e3 * t[0], 1e3 * t[1], t[1] / t[0]);
  }
}

int main(int argc, char **argv) {
  if (bench_init(argc, argv, "sensitivity errors (oscillator) and overhead")) return 1;
  static const int full_n[] = {10, 14, 20, 28, 40, 57, 80, 113, 160, 226, 320}, quick_n[] = {10, 40};
  FILE *err = bench_csv("sensitivity.csv", "family,s,method,nsim,h,err_sens,err_state,status");
  FILE *ovh = bench_csv("sensitivity_overhead.csv",
                        "problem,method,family,s,nsim,cpu_ms_off,cpu_ms_on,ratio,newton_off,newton_on");
  if (!err || !ovh) return 1;
  fesd_problem P;
  fesd_problem_get("oscillator", &P);
  errors(err, &P, bench_opt.quick ? quick_n : full_n, bench_opt.quick ? 2 : 11);
  overhead(ovh);
  fclose(err);
  fclose(ovh);
  return 0;
}
