/* Error control at tolerances near the step solves' own: sliding on a curved surface.
 * Unit circle c = x1^2 + x2^2 - 1; inside (mode 1) x' = [1 -2; 2 1] x, an unstable focus;
 * outside (mode 0) x' = (-x2, x1) + (x1 / |x| - 1/2) x, i.e. r' = r (cos phi - 1/2), phi' = 1.
 * From x0 = (0, 1/2): x(t) = e^t R(2t) x0 reaches the circle at t_in = ln 2 exactly; on it the
 * normal components are 1 (inside) and x1 - 1/2 (outside), so the flow slides while x1 < 1/2
 * with theta_0 = 1 / (3/2 - x1) and phi' = 2 - theta_0, and leaves tangentially at
 * phi = 5 pi / 3 (t_out by quadrature of dt = dphi / phi'); after it ln r = sin phi - sin phi_e
 * - (t - t_out) / 2, which stays positive up to T = 3 (no re-entry).
 * rtol 1e-11 with atol 1e-13 asks x2 for 1e-13 where it passes zero, tighter than the
 * default newton_tol (1e-12) to which the sliding constraint is solved: before the solves'
 * tolerance followed the error test's (integrate.c), Radau s = 2 stalled at t = 0.81 after
 * 674k Newton iterations (FESD_ERR_TOO_MANY_STEPS). Asserted for Radau s = 2, 3 and Lobatto
 * IIIC s = 3: FESD_OK, the entry and the exit (within 1e-8), x(3) within 1e-8,
 * fewer than 3 Newton iterations per accepted step.
 * Second part, the event log over T = 20 in fixed steps: after the first exit the motion is
 * periodic (outside until ln r returns to 0 after tau_r, then sliding back to phi = 5 pi / 3),
 * so every entry and exit has a semi-analytic time. Lobatto IIIC s = 2, h = 1/64 (its exits are
 * placed 3e-4 to 3e-3 off, a documented limit): every event of a step not flagged
 * FESD_FLAG_AMBIGUOUS is within 5e-3 of a reference event of its kind, and every reference event
 * is reported. Before the zero-length-phase flag one step logged exit, entry, exit within 2e-12
 * of 18.3123 unflagged (the reference has one exit there). That exit lies 3e-5 before a step end,
 * where the family's multiplier of the leaving mode is still positive (its algebraic error
 * puts its own exit after the step end): before the deferred exit of step.c, six halvings and
 * FESD_ERR_STEP_FAILED with one BLAS kernel (OpenBLAS Haswell/Zen), those three events with
 * another (SkylakeX). Asserted: no halving.
 * Third part, the coarse-step flag: the inside field alone (x' = [a -2; 2 a] x, the surface far
 * away), fixed steps of h, every step compared with the exact flow e^{ah} R(2h) from its start:
 * a step whose local error exceeds 0.1 |x| must carry FESD_FLAG_COARSE (a = 1, h = 5.3: the
 * L-stable methods damp the growing focus and their embedded estimate with it; before the
 * growth check of step.c one such step with a local error of 0.50 passed unflagged), and no
 * step is flagged where h is small (h = 0.05, a = +-1). */
#include "hard_util.h"

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  if (mode == 0) {
    const double g = x[0] / sqrt(x[0] * x[0] + x[1] * x[1]) - 0.5;
    f[0] = -x[1] + g * x[0];
    f[1] = x[0] + g * x[1];
  } else {
    f[0] = x[0] - 2 * x[1];
    f[1] = 2 * x[0] + x[1];
  }
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[0] * x[0] + x[1] * x[1] - 1;
  return 0;
}

static int sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)t, (void)u, (void)Ju, (void)user;
  J[0] = 2 * x[0];
  J[1] = 2 * x[1];
  return 0;
}

/* t_out - t_in = int dphi / (2 - 1 / (3/2 - cos phi)) over [phi_in, 5 pi / 3]: composite
 * 8-point Gauss-Legendre on 200 panels (smooth integrand, denominator >= 1 there). */
static double slide_time(double a, double b) {
  static const double xg[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
  static const double wg[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  const int P = 200;
  const double hp = (b - a) / P;
  double sum = 0;
  for (int p = 0; p < P; p++) {
    const double mid = a + (p + 0.5) * hp;
    for (int q = 0; q < 4; q++)
      for (int sg = -1; sg <= 1; sg += 2) {
        const double phi = mid + sg * 0.5 * hp * xg[q];
        sum += 0.5 * hp * wg[q] / (2 - 1 / (1.5 - cos(phi)));
      }
  }
  return sum;
}

/* ln r after the exit, tau after it: sin(phi_e + tau) - sin(phi_e) - tau / 2 */
static double ln_r(double phi_e, double tau) { return sin(phi_e + tau) - sin(phi_e) - 0.5 * tau; }

static int fixed_step_log(const fesd_model *m, double t_in, double t_out, double phi_e) {
  int fails = 0;
  double a = 1, b = 6; /* the positive root of ln r: ln r > 0 at 1, < 0 at 6 */
  for (int i = 0; i < 200; i++) {
    const double c = 0.5 * (a + b);
    if (ln_r(phi_e, c) > 0) a = c;
    else b = c;
  }
  const double tau_r = 0.5 * (a + b), P = tau_r + slide_time(phi_e + tau_r, phi_e + 2 * 3.14159265358979323846);
  double ref_t[16];
  int ref_k[16], nref = 0;
  ref_t[nref] = t_in, ref_k[nref++] = FESD_EVENT_SLIDING_ENTRY;
  for (int k = 0; nref < 15; k++) {
    if (t_out + k * P < 20) ref_t[nref] = t_out + k * P, ref_k[nref++] = FESD_EVENT_SLIDING_EXIT;
    if (t_out + tau_r + k * P < 20) ref_t[nref] = t_out + tau_r + k * P, ref_k[nref++] = FESD_EVENT_SLIDING_ENTRY;
    else break;
  }
  fesd_settings set;
  fesd_settings_default(&set);
  set.family = FESD_RK_LOBATTO_IIIC;
  set.stages = 2;
  fesd_integrator *it = NULL;
  const double x0[2] = {0, 0.5};
  int st = fesd_create(&it, m, &set);
  if (!st) st = fesd_set_state(it, 0, x0, NULL);
  int found[16] = {0}, flagged = 0, unmatched = 0, logged = 0, splits = 0;
  double worst = 0;
  const int nsteps = 1280;
  for (int k = 0; k < nsteps && !st; k++) {
    fesd_step_info si;
    st = fesd_step(it, NULL, 20.0 / nsteps, &si);
    splits += si.splits;
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    if (st || !ne) continue;
    if (si.flags & FESD_FLAG_AMBIGUOUS) {
      flagged++;
      for (int r = 0; r < nref; r++) /* the reference events in its span count as reported */
        if (ref_t[r] > k * 20.0 / nsteps - 5e-3 && ref_t[r] <= (k + 1) * 20.0 / nsteps + 5e-3) found[r] = 1;
      continue;
    }
    for (int e = 0; e < ne; e++) {
      logged++;
      int best = -1;
      for (int r = 0; r < nref; r++)
        if ((int)ev[e].kind == ref_k[r] && (best < 0 || fabs(ev[e].t - ref_t[r]) < fabs(ev[e].t - ref_t[best]))) best = r;
      if (best < 0 || fabs(ev[e].t - ref_t[best]) > 5e-3) {
        unmatched++;
        printf("  unflagged event %d at %.12f matches no reference event\n", (int)ev[e].kind, ev[e].t);
        continue;
      }
      found[best] = 1;
      worst = fmax(worst, fabs(ev[e].t - ref_t[best]));
    }
  }
  int missing = 0;
  for (int r = 0; r < nref; r++) missing += !found[r];
  printf("Lobatto IIIC s=2, h = 1/64, T = 20: %s, %d reference events (period %.6f), %d logged in unflagged steps "
         "(worst time error %.1e), %d steps flagged ambiguous, %d unmatched, %d missing, %d halvings\n",
         fesd_status_name(st), nref, P, logged, worst, flagged, unmatched, missing, splits);
  HD_CHECK(st == FESD_OK, "fixed steps: %s", fesd_status_name(st));
  HD_CHECK(unmatched == 0 && missing == 0, "fixed steps: %d unmatched, %d missing events", unmatched, missing);
  HD_CHECK(splits == 0, "fixed steps: %d halvings", splits);
  fesd_free(&it);
  return fails;
}

static double focus_a; /* growth rate of the focus */
static int focus(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)mode, (void)t, (void)u, (void)user;
  f[0] = focus_a * x[0] - 2 * x[1];
  f[1] = 2 * x[0] + focus_a * x[1];
  return 0;
}
static int far_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[0] - 1e300; /* never reached: mode 1 throughout */
  return 0;
}

static int coarse_flags(void) {
  int fails = 0;
  const int nm[1] = {2}, ns[1] = {1};
  fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = focus, .sw = far_sw};
  const struct { fesd_rk_family fam; int s; } fam[] = {
      {FESD_RK_RADAU_IIA, 2}, {FESD_RK_RADAU_IIA, 3}, {FESD_RK_LOBATTO_IIIC, 2}, {FESD_RK_LOBATTO_IIIC, 3}};
  const double as[3] = {1, 1, -1}, hs[3] = {5.3, 0.05, 0.05};
  for (int c = 0; c < 3; c++)
    for (size_t f = 0; f < sizeof fam / sizeof fam[0]; f++) {
      focus_a = as[c];
      fesd_settings set;
      fesd_settings_default(&set);
      set.family = fam[f].fam;
      set.stages = fam[f].s;
      fesd_integrator *it = NULL;
      const double x0[2] = {1e-3, 2e-3};
      int st = fesd_create(&it, &m, &set);
      if (!st) st = fesd_set_state(it, 0, x0, NULL);
      const int nsteps = c == 0 ? 6 : 200;
      int flagged = 0, bad = 0, missed = 0;
      for (int k = 0; k < nsteps && !st; k++) {
        double xa[2], xb[2];
        fesd_get_state(it, NULL, xa);
        fesd_step_info si;
        st = fesd_step(it, NULL, hs[c], &si);
        if (st) break;
        fesd_get_state(it, NULL, xb);
        const double h = hs[c], g = exp(as[c] * h), cs = cos(2 * h), sn = sin(2 * h);
        const double ex[2] = {g * (cs * xa[0] - sn * xa[1]), g * (sn * xa[0] + cs * xa[1])};
        const double err = hd_maxdiff(xb, ex, 2), size = fmax(fabs(ex[0]), fabs(ex[1]));
        const int coarse = (si.flags & FESD_FLAG_COARSE) != 0;
        flagged += coarse;
        bad += err > 0.1 * size;
        missed += err > 0.1 * size && !coarse;
      }
      printf("focus a = %+g, h = %g, %s s=%d: %s, %d steps with local error > 0.1 |x|, %d flagged COARSE, %d missed\n",
             as[c], hs[c], fam[f].fam == FESD_RK_RADAU_IIA ? "Radau IIA" : "Lobatto IIIC", fam[f].s, fesd_status_name(st),
             bad, flagged, missed);
      HD_CHECK(st == FESD_OK && missed == 0, "focus a=%g h=%g family %d s=%d: %s, %d inaccurate steps unflagged", as[c], hs[c],
               (int)fam[f].fam, fam[f].s, fesd_status_name(st), missed);
      HD_CHECK(c == 0 || flagged == 0, "focus a=%g h=%g: %d steps flagged COARSE at a small step", as[c], hs[c], flagged);
      fesd_free(&it);
    }
  return fails;
}

int main(void) {
  int fails = 0;
  const double pi = 3.14159265358979323846, T = 3;
  const double t_in = log(2.0), phi_in = pi / 2 + 2 * t_in, phi_e = 5 * pi / 3;
  const double t_out = t_in + slide_time(phi_in, phi_e);
  const double phi_T = phi_e + (T - t_out), r_T = exp(sin(phi_T) - sin(phi_e) - 0.5 * (T - t_out));
  const double xT[2] = {r_T * cos(phi_T), r_T * sin(phi_T)};
  const int nm[1] = {2}, ns[1] = {1};
  fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field, .sw = sw, .sw_jac = sw_jac};
  const struct { fesd_rk_family fam; int s; const char *name; } cases[] = {
      {FESD_RK_RADAU_IIA, 2, "Radau IIA s=2"}, {FESD_RK_RADAU_IIA, 3, "Radau IIA s=3"},
      {FESD_RK_LOBATTO_IIIC, 3, "Lobatto IIIC s=3"}};
  printf("reference: entry %.15f, exit %.15f, x(3) = (%.15f, %.15f)\n", t_in, t_out, xT[0], xT[1]);
  static hd_run R;
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.family = cases[c].fam;
    set.stages = cases[c].s;
    const double x0[2] = {0, 0.5};
    fesd_integrate_info info;
    const int st = hd_integrate_set(&m, &set, 1e-11, 1e-13, 0, x0, T, &R, &info);
    double e_in = INFINITY, e_out = INFINITY;
    for (int e = 0; e < R.n_ev; e++) {
      if (R.ev[e].kind == FESD_EVENT_SLIDING_ENTRY) e_in = fmin(e_in, fabs(R.ev[e].t - t_in));
      if (R.ev[e].kind == FESD_EVENT_SLIDING_EXIT) e_out = fmin(e_out, fabs(R.ev[e].t - t_out));
    }
    const double err = hd_maxdiff(R.x_end, xT, 2);
    printf("%-16s rtol 1e-11 atol 1e-13: %s, %d steps, %d rejected, %d Newton iterations, %d events, entry err %.1e, "
           "exit err %.1e, x(3) err %.1e\n",
           cases[c].name, fesd_status_name(st), info.steps, info.rejected, info.newton_iter, R.n_ev, e_in, e_out, err);
    HD_CHECK(st == FESD_OK, "%s: %s", cases[c].name, fesd_status_name(st));
    /* the exit within 1e-8 (the exit-time check of error.c brings it to 1.2e-14 .. 9.4e-13 for
     * Radau s = 2, 3; Lobatto IIIC s = 3 4.1e-14 .. 9.5e-10 depending on the OpenBLAS kernel,
     * where a retry that does not move the exit ends the check; 3.1e-10 .. 7.6e-10 before) */
    HD_CHECK(R.n_ev == 2 && e_in <= 1e-8 && e_out <= 1e-8, "%s: %d events, entry err %.1e, exit err %.1e", cases[c].name,
             R.n_ev, e_in, e_out);
    HD_CHECK(err <= 1e-8, "%s: x(3) err %.1e", cases[c].name, err);
    HD_CHECK(!st && info.newton_iter < 3 * info.steps, "%s: %d Newton iterations for %d steps", cases[c].name,
             info.newton_iter, info.steps);
  }
  fails += fixed_step_log(&m, t_in, t_out, phi_e);
  fails += coarse_flags();
  printf("%s (%d failures)\n", fails ? "FAILED" : "PASSED", fails);
  return fails ? 1 : 0;
}
