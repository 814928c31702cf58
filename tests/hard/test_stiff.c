/* A stiff mode: x = (y, z), y' = 1 (y = t); region z > 1/2 (c = z - 1/2 > 0, mode 0):
 * z' = -K (z - cos y), K = 1e6 (eigenvalue -1e6); region z < 1/2 (mode 1): z' = -1.
 * z(0) = 2 (an initial layer of width 1e-6). Exact: z = zp(t) + (2 - zp(0)) e^{-K t} with
 * zp = K (K cos t + sin t) / (K^2 + 1), until zp(t_s) = 1/2 (Newton on the closed form,
 * t_s ~ pi/3), then z = 1/2 - (t - t_s). Radau IIA (L-stable) with h >> 1/K; the error is
 * measured from t = 0.5 on (the unresolved layer leaves R(-K h) ~ 1/(K h) at the first step
 * end, damped by R(-K h) per element after that).
 * Default newton_tol: the rows are weighted by the size of their terms (K |z| for the stiff
 * field rows, whose round-off is eps K |z|), so the relative tolerance 1e-12 is reachable (with
 * absolute tolerances it was not: newton_tol = 1e-9 had to be set).
 * (Before the fix in src/fesd/guess.c the fixed-point sweeps of the initial guess diverged
 * by (K h)^3 and every step failed.) */
#include "hard_util.h"

static const double K = 1e6;

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)u, (void)user;
  f[0] = 1;
  f[1] = mode == 0 ? -K * (x[1] - cos(x[0])) : -1.0;
  return 0;
}
static int field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)u, (void)Ju, (void)user;
  J[0] = 0;
  J[1] = mode == 0 ? -K * sin(x[0]) : 0;
  J[2] = 0;
  J[3] = mode == 0 ? -K : 0;
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[1] - 0.5;
  return 0;
}
static double zp(double t) { return K * (K * cos(t) + sin(t)) / (K * K + 1); }
static double zpd(double t) { return K * (-K * sin(t) + cos(t)) / (K * K + 1); }

int main(void) {
  int fails = 0;
  static hd_run R;
  double ts = 1.0;
  for (int i = 0; i < 50; i++) ts -= (zp(ts) - 0.5) / zpd(ts);
  const int nm[1] = {2}, ns[1] = {1};
  for (int jac = 0; jac < 2; jac++)
    for (int s = 1; s <= 3; s++)
      for (int nsim = 10; nsim <= 40; nsim *= 2) {
        fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field,
                        .field_jac = jac ? field_jac : NULL, .sw = sw};
        fesd_settings set;
        fesd_settings_default(&set);
        set.stages = s;
        const double x0[2] = {0, 2}, T = 2.0;
        int st = hd_integrate(&m, &set, 0, x0, NULL, T, nsim, &R);
        double worst = 0;
        for (int e = 1; e <= R.n_el; e++) {
          double t = R.t[e], ze = t <= ts ? zp(t) + (2 - zp(0)) * exp(-K * t) : 0.5 - (t - ts);
          if (t >= 0.5) worst = fmax(worst, fabs(R.x[e][1] - ze));
        }
        double et = fabs(hd_event_time(&R, 0, FESD_EVENT_CROSSING, 0) - ts);
        const double tol_t[4] = {0, 5e-8, 1e-9, 1e-11}, tol_x[4] = {0, 2e-7, 4e-9, 4e-11};
        HD_CHECK(st == FESD_OK && R.n_ev == 1 && R.stats.splits == 0, "%s s=%d N=%d: %s, %d events, %d splits",
                 jac ? "jac" : "fd", s, nsim, fesd_status_name(st), R.n_ev, R.stats.splits);
        HD_CHECK(et <= tol_t[s] && worst <= tol_x[s], "%s s=%d N=%d: t_s error %.1e, state error %.1e", jac ? "jac" : "fd",
                 s, nsim, et, worst);
        printf("stiff K=1e6, %s Jacobian, s=%d N_sim=%d (element h = %.3f = %.0e / K): err (t >= 0.5) %.1e, t_s err %.1e, "
               "iters %d (max per step %g)\n", jac ? "exact" : "FD   ", s, nsim, 1.0 / nsim, K / nsim, worst, et,
               R.stats.newton_iter, fmax(R.stats.max_iter_ordinary_step, R.stats.max_iter_switch_step));
      }
  printf("%d failures\n", fails);
  return fails != 0;
}
