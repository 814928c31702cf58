/* Stewart-Anitescu (paper Sec. 4.5, Fig. ivp_problem left): V(x0) = int_0^2 x^2 dt +
 * (x(2) - 5/3)^2 for x' in 2 - sign(x), and dV/dx0 from the integrator's sensitivities,
 * FESD and standard against the exact formula over x0 in [-3, 0.5]; secant shooting on
 * dV/dx0 = 0 from many starts (x0* = (9 - sqrt(417)) / 8). Paper setting: Gauss-Legendre
 * s = 2, N_FE = 25, one step over [0, 2] (src/problems: fesd_sa_value, fesd_sa_shoot).
 * Output: sa_curves.csv, sa_shoot.csv, sa_summary.csv (errors away from the kink at x0 = 0,
 * shooting successes within 1e-8, CPU time of one value + gradient). */
#include <math.h>

#include "bench_util.h"

typedef struct {
  fesd_integrator *it;
  double x0;
} sa_ctx;

static int sa_eval(void *ctx) {
  sa_ctx *c = ctx;
  double V, dV;
  return fesd_sa_value(c->it, c->x0, 1, &V, &dV);
}

int main(int argc, char **argv) {
  if (bench_init(argc, argv, "Stewart-Anitescu value, gradient and shooting")) return 1;
  fesd_problem P;
  fesd_problem_get("stewart-anitescu", &P);
  fesd_integrator *it[2];
  for (int m = 0; m < 2; m++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.method = m ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
    set.family = FESD_RK_GAUSS_LEGENDRE;
    set.stages = 2;
    set.n_fe = 25;
    set.sensitivities = 1;
    if (!(it[m] = bench_create(&P, &set))) return 1;
  }
  FILE *cur = bench_csv("sa_curves.csv", "x0,V_exact,V_fesd,V_std,dV_exact,dV_fesd,dV_std");
  FILE *sh = bench_csv("sa_shoot.csv", "start,x_fesd,iters_fesd,status_fesd,x_std,iters_std,status_std");
  FILE *sum = bench_csv("sa_summary.csv", "method,max_err_V,max_err_dV,shoot_ok,shoot_starts,median_iters,"
                                          "cpu_ms_value_gradient");
  if (!cur || !sh || !sum) return 1;
  const int npts = bench_opt.quick ? 36 : 351, nstart = bench_opt.quick ? 5 : 50;
  double eV[2] = {0, 0}, edV[2] = {0, 0};
  for (int i = 0; i < npts; i++) {
    double x0 = -3 + 3.5 * i / (npts - 1), dVe, V[2], dV[2];
    double Ve = fesd_sa_exact_value(x0, &dVe);
    for (int m = 0; m < 2; m++)
      if (fesd_sa_value(it[m], x0, 1, &V[m], &dV[m])) V[m] = dV[m] = NAN;
    fprintf(cur, "%.6f,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g\n", x0, Ve, V[0], V[1], dVe, dV[0], dV[1]);
    if (fabs(x0) > 1e-3) /* dV/dx0 jumps at x0 = 0 */
      for (int m = 0; m < 2; m++) eV[m] = fmax(eV[m], fabs(V[m] - Ve)), edV[m] = fmax(edV[m], fabs(dV[m] - dVe));
  }
  const double xstar = (9 - sqrt(417.0)) / 8;
  int ok[2] = {0, 0};
  double iters[2][64];
  for (int k = 0; k < nstart; k++) {
    double xs = -3 + 3.5 * k / (nstart - 1), x[2];
    int n[2], st[2];
    for (int m = 0; m < 2; m++) {
      st[m] = fesd_sa_shoot(it[m], xs, 1, &x[m], &n[m]);
      ok[m] += !st[m] && fabs(x[m] - xstar) <= 1e-8;
      iters[m][k] = n[m];
    }
    fprintf(sh, "%.6f,%.15g,%d,%d,%.15g,%d,%d\n", xs, x[0], n[0], st[0], x[1], n[1], st[1]);
  }
  for (int m = 0; m < 2; m++) {
    sa_ctx c = {it[m], -1.0};
    double t = bench_time(sa_eval, &c);
    fprintf(sum, "%s,%.3e,%.3e,%d,%d,%.1f,%.4f\n", m ? "standard" : "fesd", eV[m], edV[m], ok[m], nstart,
            bench_median(iters[m], nstart), 1e3 * t);
    printf("%-8s max |V - exact| %.1e, max |dV/dx0 - exact| %.1e; shooting reaches x0* = %.10f from %d of %d "
           "starts; %.3f ms per value + gradient\n",
           m ? "standard" : "fesd", eV[m], edV[m], xstar, ok[m], nstart, 1e3 * t);
  }
  fclose(cur);
  fclose(sh);
  fclose(sum);
  fesd_free(&it[0]);
  fesd_free(&it[1]);
  return 0;
}
