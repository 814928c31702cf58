/* Grazing: x1' = x2, x2' = -1 in both modes; mode 1 (c = x1 < 0): f = (x2, -1), mode 0
 * (x1 > 0): f = (x2 - 1, -1), which points back into x1 < 0 near the surface.
 * (a) x0 = (-1/2, 1): x1 = -(t-1)^2/2 touches c = 0 tangentially at t = 1 and leaves;
 *     the Filippov solution is unique (mode 1 throughout): no event, polynomial solution.
 * (b) x0 = (-1/2 + d, 1), d = 1e-4: crosses c = 0 at t_e = 1 - sqrt(2d), where mode 0
 *     pushes back: sliding on x1 = 0 (theta_0 = x2) until x2 = 0 at t = 1, then
 *     x1 = -(t-1)^2/2 again: a sliding entry and exit 0.014 apart.
 * (c) x0 = (-1/2 - d, 1): misses the surface by d: no event.
 * The grazing time t = 1 is placed at a step end, inside a step and at 3/4 of a step.
 * (a), (c): exact, no event. (b): both events exact once the elements are shorter than the
 * episode; longer elements may step over it (a limitation of any method that checks signs
 * at discrete points: the interior check of src/fesd/active.c catches it only when a
 * midpoint falls inside), with an error of at most d. */
#include "hard_util.h"

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)u, (void)user;
  f[0] = x[1] - (mode == 0 ? 1.0 : 0.0);
  f[1] = -1;
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[0];
  return 0;
}

static void exact(int variant, double d, double t, double *x) {
  x[1] = 1 - t;
  double te = 1 - sqrt(2 * d);
  if (variant == 0) x[0] = -0.5 * (t - 1) * (t - 1);
  if (variant == 2) x[0] = -0.5 * (t - 1) * (t - 1) - d;
  if (variant == 1) {
    if (t <= te) x[0] = -0.5 * (t - 1) * (t - 1) + d;
    else if (t <= 1) x[0] = 0;
    else x[0] = -0.5 * (t - 1) * (t - 1);
  }
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const int nm[1] = {2}, ns[1] = {1};
  fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field, .sw = sw};
  const double d = 1e-4, te = 1 - sqrt(2 * d);
  const char *vname[3] = {"touch", "near-touch hit", "near-touch miss"};
  /* step lengths: t = 1 at a step end (0.25), inside a step (0.3), at 3/4 of a step (0.2667);
   * 0.02: elements shorter than the 0.014 sliding episode of the near-touch hit */
  const double Hs[4] = {0.25, 0.3, 0.8 / 3, 0.02};
  for (int v = 0; v < 3; v++)
    for (int s = 2; s <= 3; s++)
      for (int hi = 0; hi < 4; hi++) {
        fesd_settings set;
        fesd_settings_default(&set);
        set.stages = s;
        const double H = Hs[hi];
        const int nsim = (int)ceil(2.0 / H - 1e-9);
        const double x0[2] = {-0.5 + (v == 1 ? d : v == 2 ? -d : 0), 1};
        int st = hd_integrate(&m, &set, 0, x0, NULL, nsim * H, nsim, &R);
        double worst = 0;
        for (int e = 0; e <= R.n_el; e++) {
          double xe[2];
          exact(v, d, R.t[e], xe);
          worst = fmax(worst, hd_maxdiff(R.x[e], xe, 2));
        }
        HD_CHECK(st == FESD_OK, "%s s=%d H=%g: %s", vname[v], s, H, fesd_status_name(st));
        if (v != 1) {
          HD_CHECK(worst <= 1e-13 && R.n_ev == 0, "%s s=%d H=%g: error %.1e, %d events", vname[v], s, H, worst, R.n_ev);
          printf("%-15s s=%d H=%.4f: err %.1e, events %d, iters %d\n", vname[v], s, H, worst, R.n_ev, R.stats.newton_iter);
          continue;
        }
        double e_in = fabs(hd_event_time(&R, 0, FESD_EVENT_SLIDING_ENTRY, 0) - te);
        double e_out = fabs(hd_event_time(&R, 0, FESD_EVENT_SLIDING_EXIT, 0) - 1);
        int resolved = R.n_ev == 2 && e_in <= 1e-10 && e_out <= 1e-10 && worst <= 1e-12;
        /* elements longer than the episode may step over it unseen (documented limitation):
         * then the state is off by at most the depth d of the excursion */
        HD_CHECK(resolved || (H > 0.1 && worst <= 1.01 * d), "%s s=%d H=%g: %d events (entry err %.1e, exit err %.1e), error %.1e",
                 vname[v], s, H, R.n_ev, e_in, e_out, worst);
        printf("%-15s s=%d H=%.4f: %s, err %.1e, events %d (entry err %.1e, exit err %.1e), splits %d, iters %d\n",
               vname[v], s, H, resolved ? "resolved" : "stepped over", worst, R.n_ev, e_in, e_out, R.stats.splits,
               R.stats.newton_iter);
      }
  printf("%d failures\n", fails);
  return fails != 0;
}
