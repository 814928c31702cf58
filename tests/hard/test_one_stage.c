/* Sliding phases near a step start, for the one-stage method (implicit Euler: Radau IIA s = 1,
 * whose only stage is the element end) and, as a control, for more stages.
 *
 * Model (closed form): x1' = d(x2) - sign(x1), x2' = 1 (a clock), d(x2) = 0.9 - 4 x2. From
 * x1(0) = x0 near 0, x2(0) = 0 the state reaches x1 = 0 at
 *   t_e = (1.9 - sqrt(3.61 + 8 x0)) / 4   (x0 < 0),   (-0.1 + sqrt(0.01 + 8 x0)) / 4   (x0 > 0),
 * slides while |d| <= 1, leaves downwards at t_x = 0.475 (d = -1, the field below tangent) and
 * then follows x1 = -2 (t - t_x)^2: x(1) = (-0.55125, 1) for every small x0. The flow map is
 * constant in x0, so the discrete one must at least be continuous there.
 *
 * Measured before (ocp_step_eq's dynamics, where the optimal control problem puts nodes on
 * sliding surfaces): implicit Euler stepped over the sliding phase of a start below the surface
 * (one element ending below it again: 0 Newton iterations, no event), showed a sliding phase of
 * one element not at all in its events (the leaving mode's theta is zero at the exit, its only
 * stage) and one element early otherwise, took an entry right after the start for a wrong entry
 * and cycled, and gave the free motion after the exit one element less when an entry right after
 * the start took one: the end state jumped by 0.02 to 0.06 across the surface and the SQP stalled.
 *
 * Checks per method, N_FE and step count, over starts x0 = 0, +-1e-12 .. 1e-3: FESD_OK; the
 * events are a sliding entry (none for x0 = 0: the start slides) and one exit, the exit within
 * h_el of t_x (within 1e-3 for s >= 2); |x(1; x0) - x(1; 0)| <= 20 |x0| + 1e-10 (continuity);
 * x(1) within 2 h_el (s = 1: first order) / 1e-3 of the closed form. */
#include "hard_util.h"

#define TX 0.475

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  f[0] = 0.9 - 4 * x[1] + (mode == 0 ? -1.0 : 1.0);
  f[1] = 1.0;
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[0];
  return 0;
}

typedef struct {
  int st, n_entry, n_exit, n_other, splits;
  double t_entry, t_exit, x[2];
} one_run;

static one_run run(fesd_rk_family fam, int s, int nfe, int steps, double x0) {
  static const int n_modes[1] = {2}, n_switch[1] = {1};
  fesd_model m = {0};
  m.nx = 2, m.nsys = 1, m.n_modes = n_modes, m.n_switch = n_switch, m.field = field, m.sw = sw;
  fesd_settings set;
  fesd_settings_default(&set);
  set.family = fam, set.stages = s, set.n_fe = nfe;
  one_run r = {0};
  fesd_integrator *it;
  if ((r.st = fesd_create(&it, &m, &set))) return r;
  double x[2] = {x0, 0.0};
  r.st = fesd_set_state(it, 0.0, x, NULL);
  for (int k = 0; k < steps && !r.st; k++) {
    fesd_step_info info;
    r.st = fesd_step(it, NULL, 1.0 / steps, &info);
    r.splits += info.splits;
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    for (int e = 0; e < ne; e++) {
      if (ev[e].kind == FESD_EVENT_SLIDING_ENTRY) r.n_entry++, r.t_entry = ev[e].t;
      else if (ev[e].kind == FESD_EVENT_SLIDING_EXIT) r.n_exit++, r.t_exit = ev[e].t;
      else r.n_other++;
    }
  }
  fesd_get_state(it, NULL, r.x);
  fesd_free(&it);
  return r;
}

int main(void) {
  int fails = 0;
  const struct {
    fesd_rk_family fam;
    int s;
  } meth[] = {{FESD_RK_RADAU_IIA, 1}, {FESD_RK_RADAU_IIA, 2}, {FESD_RK_RADAU_IIA, 3}, {FESD_RK_LOBATTO_IIIC, 2}};
  const double exact[2] = {-2 * (1 - TX) * (1 - TX), 1.0};
  for (unsigned mi = 0; mi < sizeof meth / sizeof *meth; mi++)
    for (int nfe = 2; nfe <= 4; nfe++)
      for (int steps = 1; steps <= 2; steps++) {
        const int s = meth[mi].s;
        const double h_el = 1.0 / (steps * nfe);
        const one_run r0 = run(meth[mi].fam, s, nfe, steps, 0.0);
        int runs = 0, bad_ev = 0, bad_cont = 0, bad_st = 0;
        double worst_cont = 0, worst_exit = fabs(r0.t_exit - TX), err0 = hd_maxdiff(r0.x, exact, 2);
        HD_CHECK(r0.st == FESD_OK && r0.n_entry == 0 && r0.n_exit == 1 && r0.n_other == 0,
                 "%s s=%d nfe=%d steps=%d x0=0: %s, %d entries %d exits %d others", fesd_rk_family_name(meth[mi].fam), s,
                 nfe, steps, fesd_status_name(r0.st), r0.n_entry, r0.n_exit, r0.n_other);
        for (int sg = -1; sg <= 1; sg += 2)
          for (double e = -12; e <= -3 + 1e-9; e += 0.5) {
            const double x0 = sg * pow(10.0, e);
            const one_run r = run(meth[mi].fam, s, nfe, steps, x0);
            runs++;
            if (r.st != FESD_OK) {
              bad_st++;
              printf("  %s s=%d nfe=%d steps=%d x0=%+.1e: %s\n", fesd_rk_family_name(meth[mi].fam), s, nfe, steps, x0,
                     fesd_status_name(r.st));
              continue;
            }
            const double te = x0 < 0 ? (1.9 - sqrt(3.61 + 8 * x0)) / 4 : (-0.1 + sqrt(0.01 + 8 * x0)) / 4;
            const int ev_ok = r.n_entry == 1 && r.n_exit == 1 && r.n_other == 0 && fabs(r.t_entry - te) <= h_el &&
                              fabs(r.t_exit - TX) <= (s == 1 ? h_el : 1e-3);
            if (!ev_ok) {
              bad_ev++;
              printf("  %s s=%d nfe=%d steps=%d x0=%+.1e: %d entries (%.4f, exact %.4f), %d exits (%.4f), %d others\n",
                     fesd_rk_family_name(meth[mi].fam), s, nfe, steps, x0, r.n_entry, r.t_entry, te, r.n_exit,
                     r.t_exit, r.n_other);
            }
            worst_exit = fmax(worst_exit, fabs(r.t_exit - TX));
            const double d = hd_maxdiff(r.x, r0.x, 2);
            worst_cont = fmax(worst_cont, d / fabs(x0));
            if (!(d <= 20 * fabs(x0) + 1e-10)) {
              bad_cont++;
              printf("  %s s=%d nfe=%d steps=%d x0=%+.1e: x(1) %.6f, %.6f at x0 = 0 (jump %.2e)\n",
                     fesd_rk_family_name(meth[mi].fam), s, nfe, steps, x0, r.x[0], r0.x[0], d);
            }
          }
        printf("%-16s s=%d nfe=%d steps=%d: %d starts, %d failed, %d wrong events, %d discontinuous; "
               "|dx(1)|/|x0| <= %.2g, exit time off <= %.2e, error at x0 = 0 %.2e\n",
               fesd_rk_family_name(meth[mi].fam), s, nfe, steps, runs, bad_st, bad_ev, bad_cont, worst_cont,
               worst_exit, err0);
        HD_CHECK(bad_st == 0 && bad_ev == 0 && bad_cont == 0, "%d failed, %d wrong events, %d discontinuous", bad_st,
                 bad_ev, bad_cont);
        HD_CHECK(err0 <= (s == 1 ? 2 * h_el : 1e-3), "error %.3e at x0 = 0", err0);
      }
  printf("%d failures\n", fails);
  return fails != 0;
}
