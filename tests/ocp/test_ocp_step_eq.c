/* ocp_step_eq (paper Sec. 6.3) with FESD Radau IIA s = 2, N_FE = 6, N_ctrl = 6:
 *  - the solver's KKT residuals and multiplier signs;
 *  - the stationarity of the Lagrangian checked independently: the interval maps (state and cost)
 *    are differentiated by central differences of a separately built model (cost integrand in the
 *    mode fields instead of the solver's cost state) and combined with the returned multipliers
 *    (for the controls, the v states and x_N; the q states at nodes on a sliding manifold are
 *    skipped: the map is not differentiable there);
 *  - the L1 multipliers against the subgradient of 1e3 |r|;
 *  - the switching structure (four events: two sliding entries, the stay on c = 0 across t = 2,
 *    two sliding exits) and the re-simulation of the optimal controls (terminal error E(T)).
 *  - the standard time-stepping discretisation with the same optimizer: its re-simulated error. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../check.h"
#include "fesd.h"
#include "problems/problems.h"

#define CHECK FESD_TEST_CHECK
#define N 6
#define T (4.0 / N)

/* independent model: (q, v, l) with l' = u'u + v'v carried by subsystem 0's fields */
static int aug_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  const double sg = mode == 0 ? -1.0 : 1.0;
  memset(f, 0, 5 * sizeof(double));
  if (sys == 0) {
    f[0] = sg + x[2], f[1] = x[3], f[2] = u[0], f[3] = u[1];
    f[4] = u[0] * u[0] + u[1] * u[1] + x[2] * x[2] + x[3] * x[3];
  } else {
    f[1] = sg;
  }
  return 0;
}
static int aug_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = sys == 0 ? x[0] + 0.15 * x[1] * x[1] : -0.05 * x[0] * x[0] * x[0] + x[1];
  return 0;
}

static fesd_integrator *aug;
/* (Phi_k, l_k) of the independent model; 0 on success */
static int phi(int k, const double *xk, const double *uk, double *out) {
  double x[5] = {xk[0], xk[1], xk[2], xk[3], 0};
  int st = fesd_set_state(aug, k * T, x, uk);
  if (!st) st = fesd_step(aug, uk, T, NULL);
  if (!st) fesd_get_state(aug, NULL, out);
  return st;
}

int main(void) {
  int fails = 0;
  fesd_problem P;
  fesd_problem_get("ocp-dynamics", &P);
  fesd_ocp_problem op;
  fesd_ocp_step_eq(&op, &P.model);
  fesd_ocp_settings s;
  fesd_ocp_settings_default(&s);
  s.integrator.n_fe = 6;
  fesd_ocp *o;
  int st = fesd_ocp_create(&o, &op, &s);
  CHECK(st == FESD_OK, "create: %s", fesd_status_name(st));
  if (st) return 1;
  double ug[2 * N], x[4 * (N + 1)], u[2 * N];
  fesd_ocp_step_eq_guess(ug, N);
  fesd_ocp_set_guess(o, NULL, ug);
  fesd_ocp_info info;
  st = fesd_ocp_solve(o, &info);
  fesd_ocp_get_solution(o, x, u);
  fesd_ocp_multipliers m;
  fesd_ocp_get_multipliers(o, &m);
  printf("FESD: %s, %d iterations, f = %.10f, KKT %.1e %.1e %.1e, min multiplier %.1e, %.0f ms\n",
         fesd_status_name(st), info.iterations, info.objective, info.stationarity_rel, info.feasibility,
         info.complementarity, info.min_multiplier, 1e3 * info.time_total);
  CHECK(st == FESD_OK, "solve: %s", fesd_status_name(st));
  CHECK(info.stationarity_rel <= 1e-8 && info.feasibility <= 1e-9 && info.complementarity <= 1e-9 &&
            info.min_multiplier >= -1e-9,
        "KKT residuals");
  /* default Hessian (GN_SR1): superlinear; Gauss-Newton alone needed 36 iterations (linear) */
  CHECK(info.iterations <= 20, "GN_SR1: %d iterations (measured 11)", info.iterations);
  const double f_sr1 = info.objective;

  /* independent stationarity check by central differences */
  const int n_modes[2] = {2, 2}, n_switch[2] = {1, 1};
  fesd_model am = {.nx = 5, .nu = 2, .nsys = 2, .n_modes = n_modes, .n_switch = n_switch, .field = aug_field,
                   .sw = aug_sw};
  fesd_settings is = s.integrator;
  is.sensitivities = 0;
  CHECK(fesd_create(&aug, &am, &is) == FESD_OK, "independent model");
  const double hfd = 1e-6, *qf = fesd_ocp_step_eq_target();
  double worst = 0, scale = 1;
  for (int k = 0; k < N; k++)
    for (int i = 0; i < 4; i++) scale = fmax(scale, fabs(m.dynamics[4 * k + i]));
  for (int k = 0; k <= N; k++) {
    const double *xk = x + 4 * k;
    const double c1 = xk[0] + 0.15 * xk[1] * xk[1], c2 = -0.05 * xk[0] * xk[0] * xk[0] + xk[1];
    const int on_surface = fabs(c1) < 1e-6 || fabs(c2) < 1e-6;
    for (int j = 0; j < 6; j++) { /* w = (x_k (4), q_k (2)) */
      if (k == N && j >= 4) break;
      if (j < 4 && (k == 0 || (j < 2 && on_surface))) continue; /* fixed x_0; kinks */
      double g = 0; /* dL/dw_j */
      if (k < N) {
        double xp[4], xm[4], upv[2], umv[2], fp[5], fm[5];
        memcpy(xp, xk, sizeof(xp)), memcpy(xm, xk, sizeof(xm));
        memcpy(upv, u + 2 * k, sizeof(upv)), memcpy(umv, u + 2 * k, sizeof(umv));
        if (j < 4) xp[j] += hfd, xm[j] -= hfd;
        else upv[j - 4] += hfd, umv[j - 4] -= hfd;
        if (phi(k, xp, upv, fp) || phi(k, xm, umv, fm)) {
          CHECK(0, "interval %d: perturbed step failed", k);
          continue;
        }
        g += (fp[4] - fm[4]) / (2 * hfd); /* interval cost */
        for (int i = 0; i < 4; i++) g -= m.dynamics[4 * k + i] * (fp[i] - fm[i]) / (2 * hfd);
      }
      if (j < 4) {
        g += m.dynamics[4 * (k - 1) + j]; /* from Phi_{k-1} - x_k */
        g -= m.x_bound[4 * k + j];
        if (k == N && j < 2) g -= m.l1[j]; /* r1 = q_N - q_final */
      } else {
        g -= m.u_bound[2 * k + j - 4];
      }
      worst = fmax(worst, fabs(g));
      if (fabs(g) > 1e-5 * scale) printf("  dL/dw: k = %d, j = %d: %.3e\n", k, j, g);
    }
  }
  printf("independent stationarity (central differences): max |dL/dw| = %.1e (multipliers up to %.1f)\n", worst,
         scale);
  CHECK(worst <= 1e-5 * scale, "independent stationarity %.1e", worst);
  for (int i = 0; i < 2; i++) {
    const double r = x[4 * N + i] - qf[i];
    CHECK(fabs(m.l1[i]) <= 1e3 * (1 + 1e-9) && (fabs(r) < 1e-9 || fabs(m.l1[i] - 1e3 * (r > 0 ? 1 : -1)) < 1e-6),
          "L1 multiplier %d: %.9g for r = %.1e", i, m.l1[i], r);
  }
  fesd_free(&aug);

  /* switching structure */
  int nev = 0, kinds[8], syss[8];
  for (int k = 0; k < N; k++) {
    const fesd_event *ev;
    int n;
    CHECK(fesd_ocp_interval(o, k, NULL, &ev, &n) == FESD_OK, "interval %d", k);
    for (int e = 0; e < n && nev < 8; e++) kinds[nev] = ev[e].kind, syss[nev] = ev[e].sys, nev++;
  }
  printf("events:");
  for (int e = 0; e < nev; e++) printf(" (sys %d, kind %d)", syss[e], kinds[e]);
  printf("; x_3 = (%.1e, %.1e)\n", x[12], x[13]);
  CHECK(nev == 4 && kinds[0] == FESD_EVENT_SLIDING_ENTRY && kinds[1] == FESD_EVENT_SLIDING_ENTRY &&
            kinds[2] == FESD_EVENT_SLIDING_EXIT && kinds[3] == FESD_EVENT_SLIDING_EXIT && syss[0] != syss[1] &&
            syss[2] != syss[3],
        "switching structure");
  CHECK(fabs(x[12]) < 1e-9 && fabs(x[13]) < 1e-9, "x_3 on the co-dimension-2 set c = 0");

  /* re-simulation of the optimal controls */
  double xT[4];
  CHECK(fesd_ocp_step_eq_resimulate(&P.model, P.x0, u, N, 4.0, 40, xT) == FESD_OK, "re-simulation");
  const double E = fesd_ocp_step_eq_error(xT);
  printf("re-simulation: E(T) = %.2e, |x_N - x_sim(T)| = %.1e\n", E,
         fmax(fabs(xT[0] - x[4 * N]), fabs(xT[1] - x[4 * N + 1])));
  CHECK(E < 1e-6, "E(T) = %.2e", E);
  fesd_ocp_free(&o);

  /* the standard discretisation with the same optimizer: first-order accurate */
  s.integrator.method = FESD_METHOD_STANDARD;
  CHECK(fesd_ocp_create(&o, &op, &s) == FESD_OK, "create standard");
  fesd_ocp_set_guess(o, NULL, ug);
  st = fesd_ocp_solve(o, &info);
  fesd_ocp_get_solution(o, NULL, u);
  CHECK(fesd_ocp_step_eq_resimulate(&P.model, P.x0, u, N, 4.0, 40, xT) == FESD_OK, "re-simulation standard");
  const double Es = fesd_ocp_step_eq_error(xT);
  printf("standard: %s, %d iterations, f = %.10f, E(T) = %.2e\n", fesd_status_name(st), info.iterations,
         info.objective, Es);
  CHECK(st == FESD_OK, "standard: %s", fesd_status_name(st));
  CHECK(Es > 100 * E, "FESD not more accurate than standard: %.1e vs %.1e", E, Es);
  fesd_ocp_free(&o);

  /* plain Gauss-Newton reaches the same KKT point (slower) */
  s.integrator.method = FESD_METHOD_FESD;
  s.hessian = FESD_OCP_HESSIAN_GAUSS_NEWTON;
  CHECK(fesd_ocp_create(&o, &op, &s) == FESD_OK, "create GN");
  fesd_ocp_set_guess(o, NULL, ug);
  st = fesd_ocp_solve(o, &info);
  printf("FESD Gauss-Newton: %s, %d iterations, f = %.10f\n", fesd_status_name(st), info.iterations, info.objective);
  CHECK(st == FESD_OK && fabs(info.objective - f_sr1) <= 1e-8 * fabs(f_sr1), "GN: %s, f = %.12f vs %.12f",
        fesd_status_name(st), info.objective, f_sr1);
  fesd_ocp_free(&o);

  /* the monotone line search (no merit memory) reaches the same KKT point */
  s.hessian = FESD_OCP_HESSIAN_AUTO;
  s.nonmonotone = 1;
  CHECK(fesd_ocp_create(&o, &op, &s) == FESD_OK, "create monotone");
  fesd_ocp_set_guess(o, NULL, ug);
  st = fesd_ocp_solve(o, &info);
  printf("FESD monotone line search: %s, %d iterations, %d integrations, f = %.10f\n", fesd_status_name(st),
         info.iterations, info.integrations, info.objective);
  CHECK(st == FESD_OK && fabs(info.objective - f_sr1) <= 1e-8 * fabs(f_sr1), "monotone: %s, f = %.12f vs %.12f",
        fesd_status_name(st), info.objective, f_sr1);
  fesd_ocp_free(&o);
  if (fails) printf("%d check(s) failed\n", fails);
  return fails ? 1 : 0;
}
