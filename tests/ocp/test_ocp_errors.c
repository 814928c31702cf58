/* Invalid problems and settings, callback failures and call order of the OCP API: every case
 * returns its documented status, nothing crashes or leaks (run under the sanitizers in CI). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../check.h"
#include "fesd.h"

#define CHECK FESD_TEST_CHECK

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = (mode == 0 ? -1.0 : 1.0) + u[0];
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0];
  return 0;
}
static int lsq(double t, const double *x, const double *u, double *r, double *rx, double *ru, void *user) {
  r[0] = u[0];
  if (rx) rx[0] = 0;
  if (ru) ru[0] = 1;
  return 0;
}
static int mode_path; /* 0: fine, 1: error code, 2: NaN, 3: output left unwritten */
static int path(double t, const double *x, const double *u, double *g, double *gx, double *gu, void *user) {
  if (mode_path == 1) return 7;
  if (mode_path != 3) g[0] = mode_path == 2 ? NAN : x[0];
  if (gx) gx[0] = 1;
  if (gu) gu[0] = 0;
  return 0;
}

int main(void) {
  int fails = 0;
  const int n_modes[1] = {2}, n_switch[1] = {1};
  fesd_model m = {.nx = 1, .nu = 1, .nsys = 1, .n_modes = n_modes, .n_switch = n_switch, .field = field, .sw = sw};
  const double x0[1] = {1}, plb[1] = {-5}, pub[1] = {5};
  const fesd_ocp_problem good = {.model = &m, .n_ctrl = 3, .t0 = 0, .tf = 1, .x0 = x0, .n_lagrange_lsq = 1,
                                 .lagrange_lsq = lsq, .n_path = 1, .path = path, .path_lb = plb, .path_ub = pub};
  fesd_ocp_settings s;
  fesd_ocp *o = NULL;
  CHECK(fesd_ocp_settings_default(NULL) == FESD_ERR_NULL, "default(NULL)");
  fesd_ocp_settings_default(&s);
  CHECK(fesd_ocp_create(NULL, &good, &s) == FESD_ERR_NULL, "create(NULL ws)");
  CHECK(fesd_ocp_create(&o, NULL, &s) == FESD_ERR_NULL && !o, "create(NULL problem)");
  CHECK(fesd_ocp_create(&o, &good, NULL) == FESD_OK, "create with default settings");
  fesd_ocp_free(&o);
  CHECK(!o, "free sets NULL");
  fesd_ocp_free(&o); /* accepts NULL */
  fesd_ocp_free(NULL);

  /* settings out of range */
  for (int c = 0; c < 18; c++) {
    fesd_ocp_settings_default(&s);
    switch (c) {
    case 0: s.max_iter = 0; break;
    case 1: s.tol_stat = 0; break;
    case 2: s.tol_feas = NAN; break;
    case 3: s.tol_comp = 2; break;
    case 4: s.penalty0 = -1; break;
    case 5: s.penalty_max = 0.5; break;
    case 6: s.armijo = 0.5; break;
    case 7: s.backtrack = 1; break;
    case 8: s.max_backtracks = 0; break;
    case 9: s.soc = 2; break;
    case 10: s.reg_primal = -1e-3; break;
    case 11: s.qp_tol = 1e-2; break;
    case 12: s.qp_max_iter = 5000; break;
    case 13: s.hessian = (fesd_ocp_hessian)7; break;
    case 14: s.init = (fesd_ocp_init)3; break;
    case 15: s.verbose = 2; break;
    case 16: s.nonmonotone = 0; break;
    case 17: s.nonmonotone = FESD_OCP_MAX_NONMONOTONE + 1; break;
    }
    int st = fesd_ocp_create(&o, &good, &s);
    CHECK(st == FESD_ERR_INVALID_ARG && !o, "setting case %d: %s", c, fesd_status_name(st));
  }
  fesd_ocp_settings_default(&s);
  s.integrator.n_fe = 0; /* the integrator's own validation */
  CHECK(fesd_ocp_create(&o, &good, &s) == FESD_ERR_INVALID_ARG, "integrator settings");
  fesd_ocp_settings_default(&s);
  s.hessian = FESD_OCP_HESSIAN_GAUSS_NEWTON;
  fesd_ocp_problem p = good;
  p.n_lagrange_lsq = 0, p.lagrange_lsq = NULL;
  CHECK(fesd_ocp_create(&o, &p, &s) == FESD_ERR_INVALID_ARG, "Gauss-Newton without least-squares terms");

  /* invalid problems */
  fesd_ocp_settings_default(&s);
  const double nan1[1] = {NAN}, big[1] = {10}, neg[1] = {-1};
  fesd_sparsity sp = {0};
  fesd_model sm = m;
  sm.sparsity = &sp;
  for (int c = 0; c < 12; c++) {
    int expect = FESD_ERR_INVALID_ARG;
    p = good;
    switch (c) {
    case 0: p.n_ctrl = 0; break;
    case 1: p.tf = p.t0; break;
    case 2: p.x0 = nan1; break;
    case 3: p.path_lb = big; break; /* lb > ub */
    case 4: p.path = NULL, expect = FESD_ERR_NULL; break;
    case 5: p.n_l1 = 1, p.l1 = path, p.l1_weight = neg; break;
    case 6: p.x0_lb = neg; break; /* without x0_ub */
    case 7: p.model = &sm, expect = FESD_ERR_MODEL; break;
    case 8: p.model = NULL, expect = FESD_ERR_NULL; break;
    case 9: p.n_term = -1, expect = FESD_ERR_DIMENSION; break;
    case 10: p.u_lb = nan1; break;
    case 11: p.tf = INFINITY; break;
    }
    int st = fesd_ocp_create(&o, &p, &s);
    CHECK(st == expect && !o, "problem case %d: %s (expected %s)", c, fesd_status_name(st), fesd_status_name(expect));
  }

  /* call order and callback failures */
  CHECK(fesd_ocp_create(&o, &good, &s) == FESD_OK, "create");
  double x[4], u[3];
  CHECK(fesd_ocp_get_solution(o, x, u) == FESD_ERR_NOT_READY, "solution before a guess");
  CHECK(fesd_ocp_interval(o, 0, NULL, NULL, NULL) == FESD_ERR_NOT_READY, "interval before a guess");
  CHECK(fesd_ocp_solve(NULL, NULL) == FESD_ERR_NULL, "solve(NULL)");
  const int bad_modes[3] = {1, 2, 3}, bad_status[3] = {FESD_ERR_CALLBACK, FESD_ERR_NONFINITE, FESD_ERR_NONFINITE};
  for (int c = 0; c < 3; c++) {
    mode_path = bad_modes[c];
    fesd_ocp_info info;
    int st = fesd_ocp_solve(o, &info);
    CHECK(st == bad_status[c] && info.status == st, "path callback mode %d: %s", mode_path, fesd_status_name(st));
  }
  mode_path = 0;
  fesd_ocp_info info;
  int st = fesd_ocp_solve(o, &info);
  CHECK(st == FESD_OK, "solve after the failures: %s", fesd_status_name(st));
  CHECK(fesd_ocp_get_solution(o, x, u) == FESD_OK && fabs(u[0]) < 1e-8, "solution: u = %g", u[0]);
  CHECK(fesd_ocp_interval(o, 3, NULL, NULL, NULL) == FESD_ERR_INVALID_ARG, "interval out of range");
  CHECK(fesd_ocp_interval(o, 2, NULL, NULL, NULL) == FESD_OK, "interval");
  CHECK(fesd_ocp_set_x0(o, nan1) == FESD_ERR_INVALID_ARG, "set_x0(NaN)");
  CHECK(fesd_ocp_set_guess(NULL, NULL, NULL) == FESD_ERR_NULL, "set_guess(NULL)");
  int nv, ne, ni;
  CHECK(fesd_ocp_dims(o, &nv, &ne, &ni) == FESD_OK && nv == 3 * 2 + 1 && ne == 1 + 3 && ni == 2 * 4,
        "dims %d %d %d", nv, ne, ni);
  fesd_ocp_free(&o);

  /* status strings of the new codes */
  const int codes[3] = {FESD_ERR_INFEASIBLE, FESD_ERR_ITER_LIMIT, FESD_ERR_QP};
  for (int i = 0; i < 3; i++)
    CHECK(strncmp(fesd_status_name(codes[i]), "FESD_ERR_", 9) == 0 &&
              strcmp(fesd_status_string(codes[i]), "unknown status") != 0,
          "status %d", codes[i]);
  if (fails) printf("%d check(s) failed\n", fails);
  else printf("all error cases return their status\n");
  return fails ? 1 : 0;
}
