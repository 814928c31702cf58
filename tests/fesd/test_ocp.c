/* ocp-dynamics (paper Sec. 5, two subsystems, u = 0): q' = -sign(c(q)) + v, v' = u,
 * c = (q1 + 0.15 q2^2, -0.05 q1^3 + q2), q0 = (2pi/3, pi/3). Exact facts used:
 * q1' = -1 until q1 = 0, so the co-dimension-2 set c = 0 (the origin) is reached at
 * t = 2pi/3; before, the trajectory reaches c2 = 0 at t1 solving
 * -0.05 (2pi/3 - t)^3 + pi/3 - t = 0 and slides on it (q2 = 0.05 q1^3). After reaching
 * the origin it stays there: |c(q)| <= 1e-9, with no chattering in h or the active sets. */
#include "fesd_test_util.h"

static tu_run R;

static double c_inf(const double *q) {
  return fmax(fabs(q[0] + 0.15 * q[1] * q[1]), fabs(-0.05 * q[0] * q[0] * q[0] + q[1]));
}

int main(void) {
  int fails = 0;
  fesd_problem P;
  fesd_problem_get("ocp-dynamics", &P);
  const double t2 = 2 * 3.14159265358979323846 / 3;
  /* t1 by bisection on the exact expression (independent of the integrator) */
  double a = 0, b = 1.5;
  for (int i = 0; i < 200; i++) {
    double m = 0.5 * (a + b), q1 = t2 - m, f = -0.05 * q1 * q1 * q1 + (t2 / 2 - m);
    if (f > 0) a = m; else b = m;
  }
  const double t1 = 0.5 * (a + b);
  for (int s = 2; s <= 3; s++)
    for (int nsim = 20; nsim <= 80; nsim *= 2) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      int st = tu_integrate(&P, &set, nsim, P.T, &R);
      TU_CHECK(st == FESD_OK, "ocp s=%d N=%d: %s", s, nsim, fesd_status_name(st));
      double worst_c = 0, worst_slide = 0, hvar = 0;
      int flips = 0;
      for (int e = 0; e <= R.n_el; e++) {
        if (R.t[e] >= t2 + 1e-9) worst_c = fmax(worst_c, c_inf(R.x[e]));
        if (R.t[e] > t1 + 1e-9 && R.t[e] < t2 - 1e-9) {
          double q1 = R.x[e][0];
          worst_slide = fmax(worst_slide, fabs(R.x[e][1] - 0.05 * q1 * q1 * q1));
        }
        if (e > 0 && e < R.n_el && (R.act[e][0] != R.act[e - 1][0] || R.act[e][1] != R.act[e - 1][1])) flips++;
        if (e > 0 && e < R.n_el && R.t[e] > t2 + 1e-9 && R.step_of[e] == R.step_of[e - 1])
          hvar = fmax(hvar, fabs(R.h[e] - R.h[e - 1]));
      }
      double et1 = INFINITY, et2 = INFINITY;
      for (int v = 0; v < R.n_ev; v++) {
        if (R.ev[v].sys == 1) et1 = fmin(et1, fabs(R.ev[v].t - t1));
        if (R.ev[v].sys == 0) et2 = fmin(et2, fabs(R.ev[v].t - t2));
      }
      TU_CHECK(worst_c <= 1e-9, "ocp s=%d N=%d: |c(q)| = %.2e after reaching the origin", s, nsim, worst_c);
      TU_CHECK(worst_slide <= 1e-9, "ocp s=%d N=%d: off c2 = 0 by %.2e while sliding", s, nsim, worst_slide);
      TU_CHECK(flips == 2 && R.n_ev == 2, "ocp s=%d N=%d: %d active-set changes, %d events (chattering?)", s, nsim, flips, R.n_ev);
      TU_CHECK(et1 <= 1e-8 && et2 <= 1e-8, "ocp s=%d N=%d: event times off by %.1e, %.1e", s, nsim, et1, et2);
      TU_CHECK(hvar <= 1e-12, "ocp s=%d N=%d: h varies by %.1e inside steps after the origin", s, nsim, hvar);
      printf("ocp s=%d N_sim=%d: |t1 err| %.1e |t2 err| %.1e, max |c| after %.1e, off c2=0 while sliding %.1e,"
             " active-set changes %d, iters %d\n", s, nsim, et1, et2, worst_c, worst_slide, flips,
             R.stats.newton_iter);
    }
  printf("%d failures\n", fails);
  return fails != 0;
}
