/* The optimal control problem ocp_step_eq of the paper (Sec. 6.3): x = (q, v) in R^4,
 * q' = -sign(c(q)) + v, v' = u (two subsystems, model "ocp-dynamics"), x(0) = (2pi/3, pi/3, 0, 0),
 * T = 4, |v| <= 2, |u| <= 10, cost int u'u + v'v dt + 1e3 ||q(4) - (-pi/6, -pi/4)||_1. */
#include <math.h>
#include <string.h>

#include "problems/problems.h"

#define PI 3.14159265358979323846

static int lsq(double t, const double *x, const double *u, double *r, double *rx, double *ru, void *user) {
  (void)t, (void)user;
  r[0] = u[0], r[1] = u[1], r[2] = x[2], r[3] = x[3];
  if (rx) {
    memset(rx, 0, 16 * sizeof(double));
    rx[2 * 4 + 2] = 1, rx[3 * 4 + 3] = 1; /* column-major 4 x 4 */
  }
  if (ru) {
    memset(ru, 0, 8 * sizeof(double));
    ru[0 * 4 + 0] = 1, ru[1 * 4 + 1] = 1;
  }
  return 0;
}

static int l1(double t, const double *x, const double *u, double *r, double *rx, double *ru, void *user) {
  (void)t, (void)u, (void)ru, (void)user;
  const double *qf = fesd_ocp_step_eq_target();
  r[0] = x[0] - qf[0], r[1] = x[1] - qf[1];
  if (rx) {
    memset(rx, 0, 8 * sizeof(double));
    rx[0] = 1, rx[1 * 2 + 1] = 1;
  }
  return 0;
}

const double *fesd_ocp_step_eq_target(void) {
  static const double qf[2] = {-PI / 6, -PI / 4};
  return qf;
}

void fesd_ocp_step_eq(fesd_ocp_problem *p, const fesd_model *model) {
  static const double x0[4] = {2 * PI / 3, PI / 3, 0, 0};
  static const double xl[4] = {-INFINITY, -INFINITY, -2, -2}, xu[4] = {INFINITY, INFINITY, 2, 2};
  static const double ul[2] = {-10, -10}, uu[2] = {10, 10}, w[2] = {1e3, 1e3};
  memset(p, 0, sizeof(*p));
  p->model = model;
  p->n_ctrl = 6;
  p->t0 = 0;
  p->tf = 4;
  p->x0 = x0;
  p->x_lb = xl, p->x_ub = xu;
  p->u_lb = ul, p->u_ub = uu;
  p->n_lagrange_lsq = 4;
  p->lagrange_lsq = lsq;
  p->n_l1 = 2;
  p->l1 = l1;
  p->l1_weight = w;
}

void fesd_ocp_step_eq_guess(double *u, int n_ctrl) {
  for (int k = 0; k < n_ctrl; k++) u[2 * k] = u[2 * k + 1] = 2 * k < n_ctrl ? -1.0 : 0.0;
}

int fesd_ocp_step_eq_resimulate(const fesd_model *model, const double *x0, const double *u, int n_ctrl, double T,
                                int nsub, double *xT) {
  fesd_settings s;
  fesd_settings_default(&s);
  s.stages = 4; /* Radau IIA order 7, FESD: the switches on element boundaries */
  fesd_integrator *it;
  int st = fesd_create(&it, model, &s);
  if (st) return st;
  double x[4] = {x0[0], x0[1], x0[2], x0[3]};
  st = fesd_set_state(it, 0.0, x, u);
  const double h = T / n_ctrl / nsub;
  for (int k = 0; k < n_ctrl && !st; k++)
    for (int j = 0; j < nsub && !st; j++) st = fesd_step(it, u + 2 * k, h, NULL);
  if (!st) fesd_get_state(it, NULL, xT);
  fesd_free(&it);
  return st;
}

double fesd_ocp_step_eq_error(const double *xT) {
  const double *qf = fesd_ocp_step_eq_target();
  return hypot(xT[0] - qf[0], xT[1] - qf[1]);
}
