/* A smooth OCP with a known solution: the double integrator p' = v, v' = u (one subsystem whose two
 * modes have the same field, so the dynamics are smooth), x(0) = 0, min int_0^1 u^2 dt,
 * p(1) = 1, v(1) = 0, |u| <= 4.2, N = 4 piecewise constant controls (h = 1/4).
 *
 * Exact discrete solution (independent of the solver): with constant u_k the interval maps are
 * exact polynomials, v(1) = sum h u_k, p(1) = sum h^2 (N - k - 1/2) u_k. Without bounds the
 * optimum is u ~ (4.5, 1.5, -1.5, -4.5); with |u| <= 4.2 the bounds of u_0 (upper) and u_3 (lower)
 * are active, u_1 = -u_2 = 3.4, and the multipliers follow from the stationarity of
 * sum h u_k^2 - a sum h u_k - b (sum h^2 (N-k-1/2) u_k - 1): 2 h u_k = a h + b h^2 (N-k-1/2) on
 * the free controls, and the bound multipliers from the same equation on u_0 and u_3 (their signs
 * are the check of the KKT conditions). Checked: controls, states, objective, multipliers and
 * their signs, KKT residuals, for the Gauss-Newton and the BFGS Hessian, FESD and standard
 * (identical here: no switch).
 * And a cost weighted in time, int (1 + t) u^2 on the same time-independent model, without
 * control bounds: the interval weights W_k = h (1 + t_k + h/2) (the cost state integrates the
 * linear weight exactly), u_k = (a h + b c_k) / (2 W_k) with c_k = h^2 (N - k - 1/2), a and b
 * from the two terminal conditions (the OCP makes its model time-dependent for such a term; at
 * x0 = 0 with u = 0 the weight shows nothing, so it probes more points: with x0 and u = 0 only,
 * the integrator's check of the t-dependence refused the model, FESD_ERR_MODEL). */
#include <math.h>
#include <stdio.h>

#include "../check.h"
#include "fesd.h"

#define CHECK FESD_TEST_CHECK
#define N 4
#define UMAX 4.2

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = x[1];
  f[1] = u[0];
  return 0;
}
static int field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                     void *user) {
  J[0] = 0, J[1] = 0, J[2] = 1, J[3] = 0; /* column-major: df/dv = (1, 0) */
  if (Ju) Ju[0] = 0, Ju[1] = 1;
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0] + 10; /* never crossed */
  return 0;
}
static int sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  J[0] = 1, J[1] = 0;
  if (Ju) Ju[0] = 0;
  return 0;
}
static int lsq(double t, const double *x, const double *u, double *r, double *rx, double *ru, void *user) {
  r[0] = u[0];
  if (rx) rx[0] = rx[1] = 0;
  if (ru) ru[0] = 1;
  return 0;
}
static int lagrange(double t, const double *x, const double *u, double *l, double *lx, double *lu, void *user) {
  l[0] = u[0] * u[0];
  if (lx) lx[0] = lx[1] = 0;
  if (lu) lu[0] = 2 * u[0];
  return 0;
}
static int lagrange_t(double t, const double *x, const double *u, double *l, double *lx, double *lu, void *user) {
  (void)x, (void)user;
  l[0] = (1 + t) * u[0] * u[0];
  if (lx) lx[0] = lx[1] = 0;
  if (lu) lu[0] = 2 * (1 + t) * u[0];
  return 0;
}
static int terminal(double t, const double *x, const double *u, double *e, double *ex, double *eu, void *user) {
  e[0] = x[0], e[1] = x[1];
  if (ex) ex[0] = 1, ex[1] = 0, ex[2] = 0, ex[3] = 1;
  return 0;
}

int main(void) {
  int fails = 0;
  const double h = 1.0 / N;
  /* exact solution with the active set {u_0 = UMAX, u_3 = -UMAX} */
  double uex[N] = {UMAX, 0, 0, -UMAX}, bk[N];
  for (int k = 0; k < N; k++) bk[k] = h * h * (N - k - 0.5);
  /* free u_1 = -u_2 (v(1) = 0) and p(1) = 1 */
  uex[1] = (1 - bk[0] * uex[0] - bk[3] * uex[3]) / (bk[1] - bk[2]);
  uex[2] = -uex[1];
  /* multipliers a, b from 2 h u_k = a h + b bk_k, k = 1, 2 */
  const double b = 2 * h * (uex[1] - uex[2]) / (bk[1] - bk[2]), a = (2 * h * uex[1] - b * bk[1]) / h;
  /* bound multipliers in the library's signed convention (L = f - sum m c, lower side positive):
   * d/du_k of L = 2 h u_k - a h - b bk_k - m_k = 0 */
  const double m0 = 2 * h * uex[0] - a * h - b * bk[0], m3 = 2 * h * uex[3] - a * h - b * bk[3];
  double fex = 0;
  for (int k = 0; k < N; k++) fex += h * uex[k] * uex[k];
  CHECK(fabs(uex[1]) < UMAX && m0 < 0 && m3 > 0, "the assumed active set is not the solution");
  printf("exact: u = (%.6f, %.6f, %.6f, %.6f), f = %.12f, bound multipliers %.6f %.6f\n", uex[0], uex[1], uex[2],
         uex[3], fex, m0, m3);

  const int n_modes[1] = {2}, n_switch[1] = {1};
  fesd_model model = {.nx = 2, .nu = 1, .nsys = 1, .n_modes = n_modes, .n_switch = n_switch, .field = field,
                      .field_jac = field_jac, .sw = sw, .sw_jac = sw_jac};
  const double x0[2] = {0, 0}, ul[1] = {-UMAX}, uu[1] = {UMAX}, tb[2] = {1, 0};
  for (int variant = 0; variant < 4; variant++) {
    const int bfgs = variant & 1, standard = variant >> 1;
    fesd_ocp_problem p = {.model = &model, .n_ctrl = N, .t0 = 0, .tf = 1, .x0 = x0, .u_lb = ul, .u_ub = uu,
                          .n_term = 2, .terminal = terminal, .term_lb = tb, .term_ub = tb};
    if (bfgs) p.lagrange = lagrange; /* general form: AUTO picks BFGS */
    else p.n_lagrange_lsq = 1, p.lagrange_lsq = lsq;
    fesd_ocp_settings s;
    fesd_ocp_settings_default(&s);
    s.integrator.method = standard ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
    s.integrator.n_fe = 2;
    fesd_ocp *o;
    int st = fesd_ocp_create(&o, &p, &s);
    CHECK(st == FESD_OK, "create: %s", fesd_status_name(st));
    if (st) continue;
    fesd_ocp_info info;
    st = fesd_ocp_solve(o, &info);
    double u[N], x[2 * (N + 1)];
    fesd_ocp_get_solution(o, x, u);
    fesd_ocp_multipliers m;
    fesd_ocp_get_multipliers(o, &m);
    printf("%s %s: %s, %d iterations, f = %.12f, KKT %.1e %.1e %.1e, min multiplier %.1e\n",
           standard ? "standard" : "FESD", bfgs ? "BFGS" : "Gauss-Newton", fesd_status_name(st), info.iterations,
           info.objective, info.stationarity_rel, info.feasibility, info.complementarity, info.min_multiplier);
    CHECK(st == FESD_OK, "variant %d: %s", variant, fesd_status_name(st));
    CHECK(info.stationarity_rel <= 1e-8 && info.feasibility <= 1e-9 && info.complementarity <= 1e-9 &&
              info.min_multiplier >= -1e-9,
          "variant %d: KKT residuals", variant);
    double eu = 0, ex = 0, v = 0, pp = 0;
    for (int k = 0; k < N; k++) {
      eu = fmax(eu, fabs(u[k] - uex[k]));
      pp += h * v + h * h / 2 * uex[k]; /* exact states of the exact controls */
      v += h * uex[k];
      ex = fmax(ex, fmax(fabs(x[2 * (k + 1)] - pp), fabs(x[2 * (k + 1) + 1] - v)));
    }
    CHECK(eu <= 1e-8 && ex <= 1e-8, "variant %d: |u - u*| = %.1e, |x - x*| = %.1e", variant, eu, ex);
    CHECK(fabs(info.objective - fex) <= 1e-9 * fex, "variant %d: f = %.15g, exact %.15g", variant, info.objective,
          fex);
    /* multipliers: bounds with their signs (upper active: negative), terminal constraints
     * (e(x_N) - lb = 0 with multiplier of the equality; p(1) carries b, v(1) carries a) */
    CHECK(fabs(m.u_bound[0] - m0) <= 1e-6 * fabs(m0) && fabs(m.u_bound[3] - m3) <= 1e-6 * fabs(m3) &&
              fabs(m.u_bound[1]) <= 1e-9 && fabs(m.u_bound[2]) <= 1e-9,
          "variant %d: bound multipliers %.9g %.9g %.9g %.9g, exact %.9g 0 0 %.9g", variant, m.u_bound[0],
          m.u_bound[1], m.u_bound[2], m.u_bound[3], m0, m3);
    CHECK(fabs(m.terminal[0] - b) <= 1e-6 * fabs(b) && fabs(m.terminal[1] - a) <= 1e-6 * fabs(a),
          "variant %d: terminal multipliers %.9g %.9g, exact %.9g %.9g", variant, m.terminal[0], m.terminal[1], b, a);
    /* costate of the last interval: x_N's stationarity gives y_{N-1} = terminal multipliers */
    CHECK(fabs(m.dynamics[2 * (N - 1)] - b) <= 1e-6 * fabs(b) && fabs(m.dynamics[2 * (N - 1) + 1] - a) <= 1e-6 * fabs(a),
          "variant %d: last costate %.9g %.9g", variant, m.dynamics[2 * (N - 1)], m.dynamics[2 * (N - 1) + 1]);
    if (!bfgs) CHECK(info.iterations <= 3, "Gauss-Newton is exact here: %d iterations", info.iterations);
    fesd_ocp_free(&o);
  }
  {
    /* the time-weighted cost */
    const int nm[1] = {2}, ns[1] = {1};
    fesd_model mod = {.nx = 2, .nu = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field,
                      .field_jac = field_jac, .sw = sw, .sw_jac = sw_jac};
    const double z0[2] = {0, 0}, tb2[2] = {1, 0}, hh = 1.0 / N;
    fesd_ocp_problem p = {.model = &mod, .n_ctrl = N, .t0 = 0, .tf = 1, .x0 = z0, .lagrange = lagrange_t,
                          .n_term = 2, .terminal = terminal, .term_lb = tb2, .term_ub = tb2};
    fesd_ocp_settings set;
    fesd_ocp_settings_default(&set);
    fesd_ocp *o;
    CHECK(fesd_ocp_create(&o, &p, &set) == FESD_OK, "create (time-weighted cost)");
    fesd_ocp_info info;
    const int st = fesd_ocp_solve(o, &info);
    double u[N];
    fesd_ocp_get_solution(o, NULL, u);
    double A11 = 0, A12 = 0, A22 = 0, W[N], c[N];
    for (int k = 0; k < N; k++) {
      W[k] = hh * (1 + k * hh + hh / 2), c[k] = hh * hh * (N - k - 0.5);
      A11 += hh * hh / (2 * W[k]), A12 += hh * c[k] / (2 * W[k]), A22 += c[k] * c[k] / (2 * W[k]);
    }
    const double det = A11 * A22 - A12 * A12, aa = -A12 / det, bb = A11 / det; /* [A](a, b) = (0, 1) */
    double J = 0, du = 0;
    for (int k = 0; k < N; k++) {
      const double uk = (aa * hh + bb * c[k]) / (2 * W[k]);
      J += W[k] * uk * uk, du = fmax(du, fabs(u[k] - uk));
    }
    printf("time-weighted cost: %s in %d iterations, f %.12f (exact %.12f), controls within %.1e\n",
           fesd_status_name(st), info.iterations, info.objective, J, du);
    CHECK(st == FESD_OK && fabs(info.objective - J) <= 1e-8 * J && du <= 1e-6, "time-weighted cost: %s, f %.12f vs %.12f",
          fesd_status_name(st), info.objective, J);
    fesd_ocp_free(&o);
  }
  if (fails) printf("%d check(s) failed\n", fails);
  return fails ? 1 : 0;
}
