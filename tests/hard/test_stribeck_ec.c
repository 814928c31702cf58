/* Error control on a stick-slip oscillator with Stribeck friction (Leine's model): a unit mass
 * on a unit spring on a belt at VB, friction mu(c) = sign(c) (mk + (ms - mk) exp(-|c| / VS))
 * in the relative velocity c = v - VB:
 *   x' = v,  v' = -x - mu(v - VB).
 * Stick phases are sliding modes on c = 0 while |x| < ms (x' = VB), left at x = ms. Reference
 * computed here, event by event: stick phases in closed form, slip phases by classical RK4
 * (h = 1e-5) with bisection on c for their end, where the mass sticks again (|x| < ms); c
 * returns to 0 slowly there, so the reference's entry times are good to about 1e-4 (they move
 * by that much between h = 1e-4 and 1e-6), its exits and states much better.
 * Asserted for Radau IIA s = 2, 3 with fesd_integrate at rtol = atol 1e-3 and 1e-6 to T = 40:
 * FESD_OK, the reference's entries and exits in order (times within 10 rtol^(1/2)), x(T)
 * within 100 rtol, and at most 10 Newton iterations per accepted step. Before a failed step
 * went back to the controller unhalved (step.c), Radau s = 2 at rtol 1e-3 took 2542 Newton
 * iterations for 101 steps: single steps were halved up to 6 times before the error test
 * rejected them. */
#include "hard_util.h"

static const double MS = 1.0, MK = 0.5, VS = 0.2, VB = 0.2, T_END = 40;

static double fric(double c) { return c > 0 ? MK + (MS - MK) * exp(-c / VS) : -(MK + (MS - MK) * exp(c / VS)); }
static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  const double c = x[1] - VB;
  f[0] = x[1];
  f[1] = -x[0] - (mode == 0 ? MK + (MS - MK) * exp(-c / VS) : -(MK + (MS - MK) * exp(c / VS)));
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[1] - VB;
  return 0;
}

static void rhs(const double *x, double *f) {
  f[0] = x[1];
  f[1] = -x[0] - fric(x[1] - VB);
}
static void rk4(double *x, double h) {
  double k1[2], k2[2], k3[2], k4[2], y[2];
  rhs(x, k1);
  for (int i = 0; i < 2; i++) y[i] = x[i] + 0.5 * h * k1[i];
  rhs(y, k2);
  for (int i = 0; i < 2; i++) y[i] = x[i] + 0.5 * h * k2[i];
  rhs(y, k3);
  for (int i = 0; i < 2; i++) y[i] = x[i] + h * k3[i];
  rhs(y, k4);
  for (int i = 0; i < 2; i++) x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
}

/* Reference events (kind, time) and x(T_END) from x0 = (0, VB) (stuck). */
static int reference(double *ev_t, int *ev_k, int cap, double *xT) {
  double t = 0, x[2] = {0, VB};
  int n = 0;
  for (;;) { /* stuck at x[0] < MS: slides on c = 0 until x = MS */
    const double te = t + (MS - x[0]) / VB;
    if (te >= T_END) {
      xT[0] = x[0] + VB * (T_END - t), xT[1] = VB;
      return n;
    }
    if (n < cap) ev_t[n] = te, ev_k[n++] = FESD_EVENT_SLIDING_EXIT;
    t = te, x[0] = MS, x[1] = VB;
    const double h = 1e-5; /* slip with c < 0 until c returns to 0 from below */
    rk4(x, h), t += h;
    while (x[1] - VB < 0 && t < T_END) {
      double y[2] = {x[0], x[1]};
      rk4(y, h);
      if (y[1] - VB >= 0) { /* bisection on the RK4 step length */
        double a = 0, b = h;
        for (int i = 0; i < 60; i++) {
          double m[2] = {x[0], x[1]};
          rk4(m, 0.5 * (a + b));
          if (m[1] - VB < 0) a = 0.5 * (a + b);
          else b = 0.5 * (a + b);
        }
        rk4(x, b), t += b;
        x[1] = VB;
        break;
      }
      x[0] = y[0], x[1] = y[1], t += h;
    }
    if (t >= T_END) { /* (not reached with these data: the last phase is a stick) */
      xT[0] = x[0], xT[1] = x[1];
      return -1;
    }
    if (!(fabs(x[0]) < MS)) return -1; /* it would cross instead of sticking: not this problem */
    if (n < cap) ev_t[n] = t, ev_k[n++] = FESD_EVENT_SLIDING_ENTRY;
  }
}

int main(void) {
  int fails = 0;
  double ev_t[64], xT[2] = {NAN, NAN};
  int ev_k[64];
  const int nref = reference(ev_t, ev_k, 64, xT);
  printf("reference: %d events, x(T) = (%.12f, %.12f)\n", nref, xT[0], xT[1]);
  HD_CHECK(nref >= 4, "reference: %d events", nref);
  const int nm[1] = {2}, ns[1] = {1};
  fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field, .sw = sw};
  const double rtols[2] = {1e-3, 1e-6};
  static hd_run R;
  for (int s = 2; s <= 3; s++)
    for (int r = 0; r < 2; r++) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      const double x0[2] = {0, VB};
      fesd_integrate_info info;
      const int st = hd_integrate_set(&m, &set, rtols[r], rtols[r], 0, x0, T_END, &R, &info);
      double worst = 0;
      int order_ok = R.n_ev == nref;
      for (int e = 0; e < R.n_ev && order_ok; e++) {
        order_ok = (int)R.ev[e].kind == ev_k[e];
        worst = fmax(worst, fabs(R.ev[e].t - ev_t[e]));
      }
      const double err = hd_maxdiff(R.x_end, xT, 2);
      printf("Radau IIA s=%d rtol %.0e: %s, %d steps, %d rejected, %d failed attempts, %d Newton iterations, %d/%d events "
             "(worst time error %.1e), x(T) error %.1e\n",
             s, rtols[r], fesd_status_name(st), info.steps, info.rejected, info.failed_attempts, info.newton_iter, R.n_ev,
             nref, worst, err);
      HD_CHECK(st == FESD_OK, "s=%d rtol %g: %s", s, rtols[r], fesd_status_name(st));
      HD_CHECK(order_ok && worst <= 10 * sqrt(rtols[r]), "s=%d rtol %g: %d/%d events, worst time error %.1e", s, rtols[r],
               R.n_ev, nref, worst);
      HD_CHECK(err <= 100 * rtols[r], "s=%d rtol %g: x(T) error %.1e", s, rtols[r], err);
      HD_CHECK(info.newton_iter <= 10 * info.steps, "s=%d rtol %g: %d Newton iterations for %d steps", s, rtols[r],
               info.newton_iter, info.steps);
    }
  printf("%s (%d failures)\n", fails ? "FAILED" : "PASSED", fails);
  return fails ? 1 : 0;
}
