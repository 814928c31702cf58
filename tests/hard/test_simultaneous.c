/* Two independent subsystems switching at the same instant (paper Sec. 2.3):
 * x1' in 2 - sign(x1), x1(0) = -1 (crossing at t = 1/3);
 * variant "crossing": x2' in 3 - 2 sign(x2), x2(0) = -5/3 (crossing at t = 1/3 too);
 * variant "sliding":  x2' in -sign(x2),      x2(0) = 1/3  (sliding entry at t = 1/3).
 * Exact solutions are piecewise linear; FESD must put one element boundary on t = 1/3
 * for both subsystems, with one event per subsystem. N_sim = 3, 15: t = 1/3 is a step end
 * (both subsystems switch at the start of the next step); N_sim = 7: inside a step. */
#include "hard_util.h"

typedef struct {
  double a_pos, a_neg; /* x2' for x2 > 0 / x2 < 0 */
} law2;

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)x, (void)u;
  const law2 *L = user;
  if (sys == 0) {
    f[0] = mode == 0 ? 1.0 : 3.0;
    f[1] = 0;
  } else {
    f[0] = 0;
    f[1] = mode == 0 ? L->a_pos : L->a_neg;
  }
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)u, (void)user;
  c[0] = x[sys];
  return 0;
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const int nm[2] = {2, 2}, ns[2] = {1, 1};
  const law2 laws[2] = {{1.0, 5.0}, {-1.0, 1.0}};
  const double x20[2] = {-5.0 / 3, 1.0 / 3};
  const char *name[2] = {"crossing+crossing", "crossing+sliding"};
  for (int v = 0; v < 2; v++)
    for (int s = 2; s <= 3; s++)
      for (int nsim = 3; nsim <= 24; nsim = nsim * 2 + 1) {
        fesd_model m = {.nx = 2, .nsys = 2, .n_modes = nm, .n_switch = ns, .field = field, .sw = sw,
                        .user = (void *)&laws[v]};
        fesd_settings set;
        fesd_settings_default(&set);
        set.stages = s;
        const double x0[2] = {-1.0, x20[v]}, T = 1.0;
        int st = hd_integrate(&m, &set, 0, x0, NULL, T, nsim, &R);
        double e0 = fabs(hd_event_time(&R, 0, FESD_EVENT_CROSSING, 0) - 1.0 / 3);
        double e1 = fabs(hd_event_time(&R, 1, v == 0 ? FESD_EVENT_CROSSING : FESD_EVENT_SLIDING_ENTRY, 0) - 1.0 / 3);
        /* the whole trajectory: every element boundary on the exact solution */
        double worst = 0;
        for (int e = 0; e <= R.n_el; e++) {
          double t = R.t[e];
          double ex[2] = {t <= 1.0 / 3 ? -1 + 3 * t : t - 1.0 / 3,
                          v == 0 ? (t <= 1.0 / 3 ? -5.0 / 3 + 5 * t : t - 1.0 / 3) : (t <= 1.0 / 3 ? 1.0 / 3 - t : 0)};
          worst = fmax(worst, hd_maxdiff(R.x[e], ex, 2));
        }
        HD_CHECK(st == FESD_OK, "%s s=%d N=%d: %s", name[v], s, nsim, fesd_status_name(st));
        HD_CHECK(R.n_ev == 2, "%s s=%d N=%d: %d events (expected 2)", name[v], s, nsim, R.n_ev);
        HD_CHECK(e0 <= 1e-12 && e1 <= 1e-12, "%s s=%d N=%d: event times off by %.1e, %.1e", name[v], s, nsim, e0, e1);
        HD_CHECK(worst <= 1e-12, "%s s=%d N=%d: trajectory error %.1e", name[v], s, nsim, worst);
        printf("%s s=%d N_sim=%2d%s: err %.1e, event errors %.1e %.1e, splits %d, iters %d (max per step %.0f)\n",
               name[v], s, nsim, nsim % 3 ? "" : " (switch at a step end)", worst, e0, e1, R.stats.splits,
               R.stats.newton_iter, fmax(R.stats.max_iter_switch_step, R.stats.max_iter_ordinary_step));
      }
  printf("%d failures\n", fails);
  return fails != 0;
}
