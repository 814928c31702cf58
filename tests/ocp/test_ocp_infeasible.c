/* Infeasible problems end with FESD_ERR_INFEASIBLE and return the point of least violation found:
 *  1. the double integrator p' = v, v' = u, x(0) = 0, |u| <= 1, N = 4 (h = 1/4), terminal
 *     p(1) = 10, v(1) = 0. The least l1 violation |p(1) - 10| + |v(1)| over |u| <= 1 is reached by
 *     u = (1, 1, -1, -1) (p(1) = sum h^2 (N - k - 1/2) u_k = 1/4, v(1) = 0): 9.75 (a linear
 *     program, solved by hand in the comment of the check below);
 *  2. ocp_step_eq with the terminal condition q(4) = q_final as a hard constraint and |v| <= 0.5:
 *     the field -sign(c) + v, |v| < 1, keeps q on the attracting surfaces and the target is out of
 *     reach (nonlinear infeasibility: the linearisations are inconsistent at every iterate).
 * And the feasible counterpart of 2 (|v| <= 2) converges to the L1 version's solution.
 *  3. a mass at rest under Coulomb friction, x' = v, v' = u - mu sign(v), mu = 1, |u| <= 0.8, asked
 *     to reach x(2) = 1: it never moves (closed form), so the least violation is 1, at every
 *     control. Before the SQP sent an inconsistent linearisation to the elastic QP when the
 *     regularised QP "solved" it without reducing the violation, this ran 200 iterations (and the
 *     presolve 200) to FESD_ERR_ITER_LIMIT, its steps 1e-16 and the penalty at 1e11. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../check.h"
#include "fesd.h"
#include "problems/problems.h"

#define CHECK FESD_TEST_CHECK

static int di_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = x[1], f[1] = u[0];
  return 0;
}
static int di_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0] + 100; /* never crossed */
  return 0;
}
static int di_lsq(double t, const double *x, const double *u, double *r, double *rx, double *ru, void *user) {
  r[0] = u[0];
  if (rx) rx[0] = rx[1] = 0;
  if (ru) ru[0] = 1;
  return 0;
}
static int ident2(double t, const double *x, const double *u, double *e, double *ex, double *eu, void *user) {
  e[0] = x[0], e[1] = x[1];
  if (ex) ex[0] = 1, ex[1] = 0, ex[2] = 0, ex[3] = 1;
  return 0;
}
static int fr_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = x[1], f[1] = u[0] - (mode == 0 ? 1.0 : -1.0);
  return 0;
}
static int fr_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[1];
  return 0;
}
static int pos1(double t, const double *x, const double *u, double *e, double *ex, double *eu, void *user) {
  e[0] = x[0] - 1;
  if (ex) ex[0] = 1, ex[1] = 0;
  return 0;
}

static int q_target(double t, const double *x, const double *u, double *e, double *ex, double *eu, void *user) {
  const double *qf = fesd_ocp_step_eq_target();
  e[0] = x[0] - qf[0], e[1] = x[1] - qf[1];
  if (ex)
    for (int i = 0; i < 8; i++) ex[i] = i == 0 || i == 3 ? 1 : 0;
  return 0;
}

int main(void) {
  int fails = 0;
  /* 1. double integrator */
  const int n_modes[1] = {2}, n_switch[1] = {1};
  fesd_model di = {.nx = 2, .nu = 1, .nsys = 1, .n_modes = n_modes, .n_switch = n_switch, .field = di_field,
                   .sw = di_sw};
  const double x0[2] = {0, 0}, ul[1] = {-1}, uu[1] = {1}, tb[2] = {10, 0};
  fesd_ocp_problem p = {.model = &di, .n_ctrl = 4, .t0 = 0, .tf = 1, .x0 = x0, .u_lb = ul, .u_ub = uu,
                        .n_lagrange_lsq = 1, .lagrange_lsq = di_lsq, .n_term = 2, .terminal = ident2,
                        .term_lb = tb, .term_ub = tb};
  fesd_ocp_settings s;
  fesd_ocp_settings_default(&s);
  fesd_ocp *o;
  CHECK(fesd_ocp_create(&o, &p, &s) == FESD_OK, "create 1");
  fesd_ocp_info info;
  int st = fesd_ocp_solve(o, &info);
  double x[2 * 5], u[4];
  fesd_ocp_get_solution(o, x, u);
  /* l1 violation of the returned iterate: terminal and continuity (the latter ~0) */
  const double viol = fabs(x[8] - 10) + fabs(x[9]);
  printf("double integrator: %s after %d iterations; u = (%.4f, %.4f, %.4f, %.4f), p(1) = %.6f, v(1) = %.1e, "
         "violation %.6f (least: 9.75)\n",
         fesd_status_name(st), info.iterations, u[0], u[1], u[2], u[3], x[8], x[9], viol);
  CHECK(st == FESD_ERR_INFEASIBLE, "1: %s", fesd_status_name(st));
  /* max p(1) - |v(1)|: coefficients h^2 (N-k-1/2) -+ h of u_k are negative for v > 0 and positive
   * for v < 0, so v(1) = 0 at the optimum and p(1) = 1/4 with u = (1, 1, -1, -1) */
  CHECK(fabs(viol - 9.75) <= 1e-6, "1: violation %.9f, least 9.75", viol);
  CHECK(fabs(u[0] - 1) + fabs(u[1] - 1) + fabs(u[2] + 1) + fabs(u[3] + 1) <= 1e-6, "1: controls");
  CHECK(!strcmp(fesd_status_name(FESD_ERR_INFEASIBLE), "FESD_ERR_INFEASIBLE") &&
            strcmp(fesd_status_string(FESD_ERR_INFEASIBLE), "unknown status"),
        "status string");
  fesd_ocp_free(&o);

  /* 2. ocp_step_eq with a hard terminal constraint */
  fesd_problem P;
  fesd_problem_get("ocp-dynamics", &P);
  for (int feasible = 0; feasible < 2; feasible++) {
    const double vb = feasible ? 2.0 : 0.5, z[2] = {0, 0};
    const double xl[4] = {-INFINITY, -INFINITY, -vb, -vb}, xu[4] = {INFINITY, INFINITY, vb, vb};
    fesd_ocp_problem op;
    fesd_ocp_step_eq(&op, &P.model);
    op.x_lb = xl, op.x_ub = xu;
    op.n_l1 = 0, op.l1 = NULL, op.l1_weight = NULL;
    op.n_term = 2, op.terminal = q_target, op.term_lb = z, op.term_ub = z;
    fesd_ocp_settings_default(&s);
    s.integrator.n_fe = 4;
    CHECK(fesd_ocp_create(&o, &op, &s) == FESD_OK, "create 2");
    double ug[12];
    fesd_ocp_step_eq_guess(ug, 6);
    fesd_ocp_set_guess(o, NULL, ug);
    st = fesd_ocp_solve(o, &info);
    double xs[28];
    fesd_ocp_get_solution(o, xs, NULL);
    printf("ocp_step_eq, hard terminal constraint, |v| <= %.1f: %s after %d iterations (%d elastic QPs), "
           "violation %.3e, q(4) = (%.4f, %.4f), f = %.8f\n",
           vb, fesd_status_name(st), info.iterations, info.qp_elastic, info.feasibility, xs[24], xs[25],
           info.objective);
    if (feasible) {
      CHECK(st == FESD_OK && info.feasibility <= 1e-9, "2 (|v| <= 2): %s", fesd_status_name(st));
      CHECK(fabs(info.objective - 9.1496) < 1e-3, "2 (|v| <= 2): f = %.8f (L1 version: 9.1496)", info.objective);
    } else {
      CHECK(st == FESD_ERR_INFEASIBLE, "2 (|v| <= 0.5): %s", fesd_status_name(st));
      CHECK(info.feasibility > 0.1, "2: violation %.3e", info.feasibility);
    }
    fesd_ocp_free(&o);
  }
  /* 3. a mass stuck by friction */
  {
    fesd_model fr = {.nx = 2, .nu = 1, .nsys = 1, .n_modes = n_modes, .n_switch = n_switch, .field = fr_field,
                     .sw = fr_sw};
    const double ul3[1] = {-0.8}, uu3[1] = {0.8}, zero[1] = {0};
    fesd_ocp_problem p3 = {.model = &fr, .n_ctrl = 10, .t0 = 0, .tf = 2, .x0 = x0, .u_lb = ul3, .u_ub = uu3,
                           .n_lagrange_lsq = 1, .lagrange_lsq = di_lsq, .n_term = 1, .terminal = pos1,
                           .term_lb = zero, .term_ub = zero};
    fesd_ocp_settings_default(&s);
    CHECK(fesd_ocp_create(&o, &p3, &s) == FESD_OK, "create 3");
    double ug3[10];
    for (int k = 0; k < 10; k++) ug3[k] = 0.8;
    fesd_ocp_set_guess(o, NULL, ug3);
    st = fesd_ocp_solve(o, &info);
    double x3[22];
    fesd_ocp_get_solution(o, x3, NULL);
    printf("stuck mass, |u| <= 0.8 < mu: %s after %d iterations (presolve %d), x(2) = %.2e, violation %.6f "
           "(least: 1)\n",
           fesd_status_name(st), info.iterations, info.presolve_iterations, x3[20], info.feasibility);
    CHECK(st == FESD_ERR_INFEASIBLE, "3: %s", fesd_status_name(st));
    CHECK(info.iterations + info.presolve_iterations <= 10, "3: %d + %d iterations", info.iterations,
          info.presolve_iterations);
    CHECK(fabs(x3[20]) <= 1e-12 && fabs(info.feasibility - 1) <= 1e-9, "3: x(2) %.3e, violation %.9f", x3[20],
          info.feasibility);
    fesd_ocp_free(&o);
  }
  if (fails) printf("%d check(s) failed\n", fails);
  return fails ? 1 : 0;
}
