/* Relay feedback with a sliding mode (first-order sliding-mode control):
 *   x1' = x2,  x2' = u,  u in -sign(s),  s = x1 + x2,  x(0) = (1, 0).
 * Reaching phase (u = -1): s = 1 - t - t^2/2 = 0 at t_r = sqrt(3) - 1; then sliding on s = 0
 * (|u_eq| = |x1| < 1): x1 = x1(t_r) e^{-(t - t_r)}, x2 = -x1. Closed form throughout.
 * FESD (Radau IIA): exactly one active-set change (the sliding entry, at t_r to 1e-12), no
 * chattering, the state on the closed form with order 2s - 1. Standard time-stepping with
 * explicit Euler chatters (an active-set change in at least every other element, asserted so
 * the case is a chattering one); implicit standard time-stepping is reported alongside. */
#include "hard_util.h"

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)u, (void)user;
  f[0] = x[1];
  f[1] = mode == 0 ? -1.0 : 1.0; /* mode 0: s > 0 -> u = -1 */
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[0] + x[1];
  return 0;
}
static void exact(double t, double *x) {
  const double tr = sqrt(3.0) - 1;
  if (t <= tr) {
    x[0] = 1 - t * t / 2;
    x[1] = -t;
  } else {
    x[0] = (1 - tr * tr / 2) * exp(-(t - tr));
    x[1] = -x[0];
  }
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const int nm[1] = {2}, ns[1] = {1};
  fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field, .sw = sw};
  const double x0[2] = {1, 0}, T = 5.0, tr = sqrt(3.0) - 1;
  /* FESD with Radau IIA: one event, no chattering, closed-form accuracy of order 2s - 1 */
  for (int s = 2; s <= 3; s++) {
    double err[3];
    for (int g = 0; g < 3; g++) {
      const int nsim = 25 << g;
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      int st = hd_integrate(&m, &set, 0, x0, NULL, T, nsim, &R);
      double xe[2];
      err[g] = 0;
      for (int e = 0; e <= R.n_el; e++) {
        exact(R.t[e], xe);
        err[g] = fmax(err[g], hd_maxdiff(R.x[e], xe, 2));
      }
      int ch = hd_changes(&R, 1);
      double te = fabs(hd_event_time(&R, 0, FESD_EVENT_SLIDING_ENTRY, 0) - tr);
      HD_CHECK(st == FESD_OK && ch == 1 && R.n_ev == 1 && te <= 1e-12, "FESD s=%d N=%d: %s, %d active-set changes, %d events, "
               "entry error %.1e", s, nsim, fesd_status_name(st), ch, R.n_ev, te);
      printf("relay FESD, Radau s=%d N_sim=%3d: err %.1e, active-set changes %d, entry err %.1e, iters %d\n", s, nsim,
             err[g], ch, te, R.stats.newton_iter);
    }
    double p = log2(err[1] / err[2]);
    HD_CHECK(p >= 2 * s - 1.5 || err[2] <= 1e-12, "FESD s=%d: order %.2f", s, p);
  }
  /* standard time-stepping on the same problem: explicit Euler chatters around s = 0 */
  for (int nsim = 25; nsim <= 100; nsim *= 2) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.method = FESD_METHOD_STANDARD;
    set.family = FESD_RK_EXPLICIT;
    set.stages = 1;
    int st = hd_integrate(&m, &set, 0, x0, NULL, T, nsim, &R);
    int ch = hd_changes(&R, 1);
    HD_CHECK(st == FESD_OK && ch >= nsim / 2, "standard explicit Euler N=%d: %s, %d changes (expected chattering)", nsim,
             fesd_status_name(st), ch);
    printf("relay standard time-stepping, explicit Euler, N_sim=%3d: active-set changes %d\n", nsim, ch);
    set.family = FESD_RK_RADAU_IIA;
    set.stages = 2;
    st = hd_integrate(&m, &set, 0, x0, NULL, T, nsim, &R);
    printf("relay standard time-stepping, Radau IIA s=2, N_sim=%3d: %s, active-set changes %d\n", nsim,
           fesd_status_name(st), hd_changes(&R, 1));
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
