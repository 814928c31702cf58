/* settings.presolve on ocp_step_eq (N_ctrl = 6):
 *  - FESD Radau IIA s = 2, N_FE = 2 with and without the presolve reach the same KKT point
 *    (objective and controls of the solve without it, which starts from the guess);
 *  - the presolve's start is used (info fields) and costs fewer integrations in all;
 *  - a re-solve from the previous solution, and a standard discretisation no finer than the
 *    presolve's, run none; a finer standard one does;
 *  - a changed x0 (fesd_ocp_set_x0; v0 != 0 changes the objective) with the presolve: the
 *    same objective as without it;
 *  - a presolve whose point the requested discretisation cannot evaluate falls back to the guess
 *    (then the solve is the one without presolve);
 *  - a presolve whose point the SQP cannot solve from (a relay oscillator, v' = -20 sign(x) + u,
 *    3 crossings per interval: LINE_SEARCH at iteration 0 from it, where the guess converges):
 *    the solve is repeated from the guess and matches the solve without presolve;
 *  - the settings' ranges;
 *  - the model's callbacks never see a non-finite t, x or u (the semismooth Newton's line
 *    search used to evaluate trial points of a direction with NaN entries: t = NaN in the
 *    model; a user's model may assert on that). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../check.h"
#include "fesd.h"
#include "problems/problems.h"

#define CHECK FESD_TEST_CHECK
#define N 6

static int fails;

/* The model with its callbacks wrapped: counts calls with non-finite arguments. */
static fesd_model inner;
static int nonfinite_calls;
static void check_args(double t, const double *x, const double *u) {
  int ok = isfinite(t);
  for (int i = 0; i < inner.nx; i++) ok &= isfinite(x[i]);
  for (int i = 0; i < inner.nu; i++) ok &= isfinite(u[i]);
  nonfinite_calls += !ok;
}
static int w_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  check_args(t, x, u);
  return inner.field(sys, mode, t, x, u, f, user);
}
static int w_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                       void *user) {
  check_args(t, x, u);
  return inner.field_jac(sys, mode, t, x, u, J, Ju, user);
}
static int w_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  check_args(t, x, u);
  return inner.sw(sys, t, x, u, c, user);
}
static int w_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  check_args(t, x, u);
  return inner.sw_jac(sys, t, x, u, J, Ju, user);
}

static fesd_ocp *make(const fesd_ocp_problem *op, int method, fesd_rk_family fam, int s, int nfe, int presolve) {
  fesd_ocp_settings set;
  fesd_ocp_settings_default(&set);
  set.integrator.method = method;
  set.integrator.family = fam;
  set.integrator.stages = s;
  set.integrator.n_fe = nfe;
  set.presolve = presolve;
  fesd_ocp *o = NULL;
  CHECK(fesd_ocp_create(&o, op, &set) == FESD_OK, "create");
  return o;
}

static int solve(fesd_ocp *o, const double *x0, double *u, fesd_ocp_info *info) {
  double ug[2 * N];
  fesd_ocp_step_eq_guess(ug, N);
  if (x0) fesd_ocp_set_x0(o, x0);
  fesd_ocp_set_guess(o, NULL, ug);
  int st = fesd_ocp_solve(o, info);
  fesd_ocp_get_solution(o, NULL, u);
  return st;
}

/* relay oscillator x' = v, v' = -20 sign(x) + u, min int u^2 + 1e3 |(x, v)(T)|^2 */
static int osc_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)user;
  f[0] = x[1], f[1] = -20.0 * (mode == 0 ? 1.0 : -1.0) + u[0];
  return 0;
}
static int osc_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                   void *user) {
  (void)sys, (void)mode, (void)t, (void)x, (void)u, (void)user;
  J[0] = 0, J[1] = 0, J[2] = 1, J[3] = 0; /* column-major */
  if (Ju) Ju[0] = 0, Ju[1] = 1;
  return 0;
}
static int osc_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)t, (void)x, (void)u, (void)user;
  J[0] = 1, J[1] = 0;
  if (Ju) Ju[0] = 0;
  return 0;
}
static int osc_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[0];
  return 0;
}
static int osc_lsq(double t, const double *x, const double *u, double *r, double *rx, double *ru, void *user) {
  (void)t, (void)x, (void)user;
  r[0] = u[0];
  if (rx) rx[0] = rx[1] = 0;
  if (ru) ru[0] = 1;
  return 0;
}
static int osc_mayer(double t, const double *x, const double *u, double *r, double *rx, double *ru, void *user) {
  (void)t, (void)u, (void)ru, (void)user;
  const double w = sqrt(1e3);
  r[0] = w * x[0], r[1] = w * x[1];
  if (rx) rx[0] = w, rx[1] = 0, rx[2] = 0, rx[3] = w;
  return 0;
}

int main(void) {
  fesd_problem P;
  fesd_problem_get("ocp-dynamics", &P);
  inner = P.model;
  fesd_model wrapped = inner;
  wrapped.field = w_field;
  wrapped.sw = w_sw;
  if (inner.field_jac) wrapped.field_jac = w_field_jac;
  if (inner.sw_jac) wrapped.sw_jac = w_sw_jac;
  fesd_ocp_problem op;
  fesd_ocp_step_eq(&op, &wrapped);
  double u0[2 * N], u1[2 * N];
  fesd_ocp_info i0, i1;

  /* the same KKT point with and without */
  fesd_ocp *a = make(&op, FESD_METHOD_FESD, FESD_RK_RADAU_IIA, 2, 2, 0);
  fesd_ocp *b = make(&op, FESD_METHOD_FESD, FESD_RK_RADAU_IIA, 2, 2, 1);
  if (!a || !b) return 1;
  int s0 = solve(a, NULL, u0, &i0), s1 = solve(b, NULL, u1, &i1);
  double du = 0;
  for (int j = 0; j < 2 * N; j++) du = fmax(du, fabs(u0[j] - u1[j]));
  printf("without: %s, %d it, %d integrations, f %.12f\n", fesd_status_name(s0), i0.iterations, i0.integrations,
         i0.objective);
  printf("with:    %s, %d it (presolve %d it, %s), %d integrations, f %.12f, max |du| %.1e\n", fesd_status_name(s1),
         i1.iterations, i1.presolve_iterations, fesd_status_name(i1.presolve_status), i1.integrations, i1.objective,
         du);
  CHECK(s0 == FESD_OK && s1 == FESD_OK, "status %s / %s", fesd_status_name(s0), fesd_status_name(s1));
  CHECK(fabs(i0.objective - i1.objective) <= 1e-8 * fabs(i0.objective), "objective %.12f vs %.12f", i1.objective,
        i0.objective);
  CHECK(du < 1e-5, "controls differ by %.1e", du);
  CHECK(i0.presolve_run == 0 && i1.presolve_run == 1 && i1.presolve_used == 1 && i1.presolve_status == FESD_OK &&
            i1.presolve_iterations > 0,
        "presolve fields: run %d/%d used %d status %d it %d", i0.presolve_run, i1.presolve_run, i1.presolve_used,
        i1.presolve_status, i1.presolve_iterations);
  CHECK(i1.integrations < i0.integrations, "integrations %d with, %d without", i1.integrations, i0.integrations);
  CHECK(i1.stationarity_rel <= 1e-8 && i1.feasibility <= 1e-9, "KKT %.1e %.1e", i1.stationarity_rel, i1.feasibility);

  /* a re-solve from the previous solution: no presolve, converged at once */
  int s2 = fesd_ocp_solve(b, &i1);
  CHECK(s2 == FESD_OK && i1.presolve_run == 0 && i1.iterations <= 1, "re-solve: %s, presolve %d, %d it",
        fesd_status_name(s2), i1.presolve_run, i1.iterations);

  /* a changed x0 reaches the presolve */
  const double x0[4] = {2.0, 1.0, 0.3, -0.2};
  s0 = solve(a, x0, u0, &i0), s1 = solve(b, x0, u1, &i1);
  printf("x0 = (2, 1, 0.3, -0.2): f %.12f without, %.12f with (%s, %s)\n", i0.objective, i1.objective,
         fesd_status_name(s0), fesd_status_name(s1));
  CHECK(s0 == FESD_OK && s1 == FESD_OK && i1.presolve_used == 1 &&
            fabs(i0.objective - i1.objective) <= 1e-8 * fabs(i0.objective),
        "x0: %s / %s, f %.12f vs %.12f", fesd_status_name(s0), fesd_status_name(s1), i1.objective, i0.objective);
  fesd_ocp_free(&a);
  fesd_ocp_free(&b);

  /* standard discretisations: none when no finer than the presolve's (implicit Euler, 2
   * elements), else one */
  a = make(&op, FESD_METHOD_STANDARD, FESD_RK_RADAU_IIA, 1, 2, 1);
  b = make(&op, FESD_METHOD_STANDARD, FESD_RK_RADAU_IIA, 2, 2, 1);
  if (!a || !b) return 1;
  s0 = solve(a, NULL, u0, &i0), s1 = solve(b, NULL, u1, &i1);
  CHECK(s0 == FESD_OK && i0.presolve_run == 0, "standard s = 1: %s, presolve %d", fesd_status_name(s0),
        i0.presolve_run);
  CHECK(s1 == FESD_OK && i1.presolve_run == 1, "standard s = 2: %s, presolve %d", fesd_status_name(s1),
        i1.presolve_run);
  fesd_ocp_free(&a);
  fesd_ocp_free(&b);

  /* fallback: when the presolve's point cannot be evaluated (FESD Gauss-Legendre s = 1,
   * N_FE = 3 at the time of writing), the solve is the one from the guess */
  a = make(&op, FESD_METHOD_FESD, FESD_RK_GAUSS_LEGENDRE, 1, 3, 0);
  b = make(&op, FESD_METHOD_FESD, FESD_RK_GAUSS_LEGENDRE, 1, 3, 1);
  if (!a || !b) return 1;
  s0 = solve(a, NULL, u0, &i0), s1 = solve(b, NULL, u1, &i1);
  printf("Gauss s = 1, N_FE = 3: presolve used %d; %s / %s, f %.12f / %.12f\n", i1.presolve_used,
         fesd_status_name(s0), fesd_status_name(s1), i0.objective, i1.objective);
  CHECK(i1.presolve_run == 1, "Gauss: no presolve");
  if (!i1.presolve_used)
    CHECK(s0 == s1 && i0.iterations == i1.iterations && i0.objective == i1.objective,
          "fallback differs: %s %d it f %.15g vs %s %d it f %.15g", fesd_status_name(s1), i1.iterations,
          i1.objective, fesd_status_name(s0), i0.iterations, i0.objective);
  fesd_ocp_free(&a);
  fesd_ocp_free(&b);

  /* a presolve point the SQP cannot solve from */
  {
    const int nm[1] = {2}, nsw[1] = {1};
    fesd_model om = {.nx = 2, .nu = 1, .nsys = 1, .n_modes = nm, .n_switch = nsw, .field = osc_field,
                     .field_jac = osc_jac, .sw = osc_sw, .sw_jac = osc_sw_jac};
    const double ox0[2] = {1, 0}, oul[1] = {-50}, ouu[1] = {50};
    fesd_ocp_problem oop = {.model = &om, .n_ctrl = 8, .t0 = 0, .tf = 4, .x0 = ox0, .u_lb = oul, .u_ub = ouu,
                            .n_lagrange_lsq = 1, .lagrange_lsq = osc_lsq, .n_mayer_lsq = 2, .mayer_lsq = osc_mayer};
    fesd_ocp_info oi[2];
    int os[2];
    for (int pre = 0; pre < 2; pre++) {
      fesd_ocp_settings oset;
      fesd_ocp_settings_default(&oset);
      oset.presolve = pre;
      fesd_ocp *oo;
      CHECK(fesd_ocp_create(&oo, &oop, &oset) == FESD_OK, "create oscillator");
      os[pre] = fesd_ocp_solve(oo, &oi[pre]);
      fesd_ocp_free(&oo);
    }
    printf("relay oscillator: presolve run %d used %d: %s, %d it, f %.10f; without: %s, %d it, f %.10f\n",
           oi[1].presolve_run, oi[1].presolve_used, fesd_status_name(os[1]), oi[1].iterations, oi[1].objective,
           fesd_status_name(os[0]), oi[0].iterations, oi[0].objective);
    CHECK(os[0] == FESD_OK && os[1] == FESD_OK, "oscillator: %s / %s", fesd_status_name(os[0]),
          fesd_status_name(os[1]));
    CHECK(oi[1].presolve_run == 1 && oi[1].presolve_used == 0, "oscillator: presolve run %d used %d",
          oi[1].presolve_run, oi[1].presolve_used);
    CHECK(fabs(oi[1].objective - oi[0].objective) <= 1e-8 * oi[0].objective, "oscillator: f %.12f vs %.12f",
          oi[1].objective, oi[0].objective);
  }

  /* ranges */
  fesd_ocp_settings set;
  const int bad[3][2] = {{2, 2}, {1, 0}, {1, 101}};
  for (int i = 0; i < 3; i++) {
    fesd_ocp_settings_default(&set);
    set.presolve = bad[i][0], set.presolve_n_fe = bad[i][1];
    fesd_ocp *o = NULL;
    CHECK(fesd_ocp_create(&o, &op, &set) == FESD_ERR_INVALID_ARG, "presolve %d, n_fe %d accepted", bad[i][0],
          bad[i][1]);
    fesd_ocp_free(&o);
  }
  fesd_ocp_settings_default(&set);
  CHECK(set.presolve == 1 && set.presolve_n_fe == 2, "defaults %d %d", set.presolve, set.presolve_n_fe);
  printf("model calls with non-finite t, x or u: %d\n", nonfinite_calls);
  CHECK(nonfinite_calls == 0, "%d model calls with non-finite arguments", nonfinite_calls);
  if (fails) printf("%d check(s) failed\n", fails);
  return fails ? 1 : 0;
}
