/* More switches inside one step than N_FE = 2 elements can resolve.
 * x' = i + 1 in region i of R (regions [-inf,.1), [.1,.2), [.2,.3), [.3,inf)), given by
 * Stewart indicators g_i(x) = -(i x + b_i) (region i = argmax of the affine pieces),
 * x(0) = 0: switches at t = 0.1, 0.15, 0.55/3, then x = 0.3 + 4 (t - 0.55/3).
 * One step of length 0.25 holds three switches: the step gets one element boundary per switch
 * (4 elements, more than N_FE = 2) and one solve resolves them: exact, without halving
 * (max_splits = 0 and 6 alike), in at most 12 Newton iterations for the step. */
#include "hard_util.h"

static const double B[4] = {0.0, -0.1, -0.3, -0.6};

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)x, (void)u, (void)user;
  f[0] = mode + 1.0;
  return 0;
}
static int ind(int sys, double t, const double *x, const double *u, double *g, void *user) {
  (void)sys, (void)u, (void)user;
  for (int i = 0; i < 4; i++) g[i] = -(i * x[0] + B[i]);
  return 0;
}
static double exact(double t) {
  const double ts[3] = {0.1, 0.15, 0.55 / 3};
  if (t <= ts[0]) return t;
  if (t <= ts[1]) return 0.1 + 2 * (t - ts[0]);
  if (t <= ts[2]) return 0.2 + 3 * (t - ts[1]);
  return 0.3 + 4 * (t - ts[2]);
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const int nm[1] = {4}, ns[1] = {0};
  fesd_model m = {.nx = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field, .sw = ind};
  const double x0[1] = {0}, ts[3] = {0.1, 0.15, 0.55 / 3};
  for (int s = 1; s <= 3; s++)
    for (int splits = 0; splits <= 6; splits += 6) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      set.max_splits = splits;
      for (int nsim = 1; nsim <= 2; nsim++) {
        double T = 0.25 * nsim;
        int st = hd_integrate(&m, &set, 0, x0, NULL, T, nsim, &R);
        double worst = 0, ev_err = 0;
        for (int e = 0; e <= R.n_el; e++) worst = fmax(worst, fabs(R.x[e][0] - exact(R.t[e])));
        for (int k = 0; k < 3; k++)
          ev_err = fmax(ev_err, k < R.n_ev ? fabs(R.ev[k].t - ts[k]) : INFINITY);
        HD_CHECK(st == FESD_OK, "s=%d T=%g max_splits=%d: %s", s, T, splits, fesd_status_name(st));
        HD_CHECK(R.n_ev == 3 && ev_err <= 1e-12, "s=%d T=%g: %d events, time error %.1e", s, T, R.n_ev, ev_err);
        HD_CHECK(worst <= 1e-12, "s=%d T=%g: error %.1e", s, T, worst);
        HD_CHECK(R.stats.splits == 0 && R.stats.max_iter_switch_step <= 12,
                 "s=%d T=%g: %d splits, %g iterations in the switch step", s, T, R.stats.splits,
                 R.stats.max_iter_switch_step);
        printf("s=%d T=%g max_splits=%d: err %.1e, event err %.1e, steps %d, splits %d, iters %d (switch step %g)\n",
               s, T, splits, worst, ev_err, R.stats.steps, R.stats.splits, R.stats.newton_iter,
               R.stats.max_iter_switch_step);
      }
    }
  /* N_FE = 4 has a boundary per switch already */
  for (int s = 1; s <= 3; s++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.stages = s;
    set.n_fe = 4;
    int st = hd_integrate(&m, &set, 0, x0, NULL, 0.25, 1, &R);
    double worst = 0;
    for (int e = 0; e <= R.n_el; e++) worst = fmax(worst, fabs(R.x[e][0] - exact(R.t[e])));
    HD_CHECK(st == FESD_OK && R.n_ev == 3 && worst <= 1e-12 && R.stats.splits == 0,
             "N_FE=4 s=%d: %s, %d events, error %.1e, %d splits", s, fesd_status_name(st), R.n_ev, worst,
             R.stats.splits);
    printf("N_FE=4 s=%d T=0.25: err %.1e, events %d, splits %d, iters %d\n", s, worst, R.n_ev, R.stats.splits,
           R.stats.newton_iter);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
