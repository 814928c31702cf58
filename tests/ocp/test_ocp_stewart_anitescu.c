/* Stewart-Anitescu through the OCP API (paper Sec. 5.3): min over x0 of int_0^2 x^2 dt +
 * (x(2) - 5/3)^2, x' in 2 - sign(x): the initial state is the only degree of freedom (a free
 * component of x_0), the Lagrange term is integrated by the solver's cost state (general form:
 * BFGS). FESD Gauss-Legendre s = 2, N_FE = 25 (the paper's grid), one control interval, from 20
 * starts in [-3, 0.5]: every solve reaches the exact minimiser x0* = (9 - sqrt(417)) / 8 and the
 * exact value V(x0*) (closed form, fesd_sa_exact_value). The standard method with the same optimizer
 * is run from 5 of the starts and reported (its value function has artificial local minima). */
#include <math.h>
#include <stdio.h>

#include "../check.h"
#include "fesd.h"
#include "problems/problems.h"

#define CHECK FESD_TEST_CHECK

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = mode == 0 ? 1.0 : 3.0; /* 2 - sign(x): mode 0 is x > 0 */
  return 0;
}
static int field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                     void *user) {
  J[0] = 0;
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0];
  return 0;
}
static int sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  J[0] = 1;
  return 0;
}
static int lagrange(double t, const double *x, const double *u, double *l, double *lx, double *lu, void *user) {
  l[0] = x[0] * x[0];
  if (lx) lx[0] = 2 * x[0];
  return 0;
}
static int mayer(double t, const double *x, const double *u, double *m, double *mx, double *mu, void *user) {
  m[0] = (x[0] - 5.0 / 3) * (x[0] - 5.0 / 3);
  if (mx) mx[0] = 2 * (x[0] - 5.0 / 3);
  return 0;
}

int main(void) {
  int fails = 0;
  const int n_modes[1] = {2}, n_switch[1] = {1};
  fesd_model m = {.nx = 1, .nu = 0, .nsys = 1, .n_modes = n_modes, .n_switch = n_switch, .field = field,
                  .field_jac = field_jac, .sw = sw, .sw_jac = sw_jac};
  const double lb = -10, ub = 10, xstar = (9 - sqrt(417.0)) / 8, Vstar = fesd_sa_exact_value(xstar, NULL);
  double x0 = -1;
  fesd_ocp_problem p = {.model = &m, .n_ctrl = 1, .t0 = 0, .tf = 2, .x0 = &x0, .x0_lb = &lb, .x0_ub = &ub,
                        .lagrange = lagrange, .mayer = mayer};
  printf("x0* = %.12f, V(x0*) = %.12f\n", xstar, Vstar);
  for (int method = 0; method < 2; method++) {
    fesd_ocp_settings s;
    fesd_ocp_settings_default(&s);
    s.integrator.method = method ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
    s.integrator.family = FESD_RK_GAUSS_LEGENDRE;
    s.integrator.stages = 2;
    s.integrator.n_fe = 25;
    if (method) s.max_iter = 30, s.max_backtracks = 10; /* reported only */
    fesd_ocp *o;
    int st = fesd_ocp_create(&o, &p, &s);
    CHECK(st == FESD_OK, "create: %s", fesd_status_name(st));
    if (st) return 1;
    int reached = 0, iters = 0;
    for (int k = 0; k < 20; k += method ? 4 : 1) {
      double start = -3 + 3.5 * k / 19, xs[2];
      fesd_ocp_set_x0(o, &start);
      fesd_ocp_set_guess(o, NULL, NULL);
      fesd_ocp_info info;
      st = fesd_ocp_solve(o, &info);
      fesd_ocp_get_solution(o, xs, NULL);
      printf("%-8s start %7.4f: %-22s x0 = %15.12f  |x0 - x0*| = %.1e  V = %.12f  %2d iterations\n",
             method ? "standard" : "FESD", start, fesd_status_name(st), xs[0], fabs(xs[0] - xstar), info.objective,
             info.iterations);
      if (method) continue;
      iters += info.iterations;
      reached += st == FESD_OK && fabs(xs[0] - xstar) <= 1e-7;
      CHECK(st == FESD_OK && fabs(xs[0] - xstar) <= 1e-7, "FESD from %.4f: %s, x0 = %.12f", start,
            fesd_status_name(st), xs[0]);
      CHECK(fabs(info.objective - Vstar) <= 1e-9, "FESD from %.4f: V = %.15f, exact %.15f", start, info.objective,
            Vstar);
    }
    if (!method) printf("FESD: %d of 20 starts reach x0*, %.1f SQP iterations on average\n", reached, iters / 20.0);
    fesd_ocp_free(&o);
  }
  if (fails) printf("%d check(s) failed\n", fails);
  return fails ? 1 : 0;
}
