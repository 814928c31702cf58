/* Entering and leaving sliding on a co-dimension-2 set: the ocp-dynamics reference problem
 * (two subsystems, q' = -sign(c(q)) + v, v' = u, c = (q1 + 0.15 q2^2, -0.05 q1^3 + q2)).
 * u = 0 until t3 = 2.5: slides on c2 = 0 from t1, reaches the origin (c = 0) at t2 = 2 pi/3
 * and stays (reference problem, tests/fesd/test_ocp.c). From t3 on, u = (a, 0), a = 0.9:
 * v1 = a (t - t3) pushes off c1 = 0; the sliding multiplier of c1 reaches its bound when
 * v1 = 1, at t_e = t3 + 1/a; after that q1 = a (t - t_e)^2 / 2 > 0 (c1 > 0, mode 0), while
 * subsystem 2 keeps sliding on c2 = 0: q2 = 0.05 q1^3 (valid while |0.15 q1^2 q1'| < 1).
 * Closed form after t1 (t1 by bisection). The control changes at a step boundary. */
#include "hard_util.h"
#include "problems/problems.h"

int main(void) {
  int fails = 0;
  static hd_run R;
  fesd_problem P;
  fesd_problem_get("ocp-dynamics", &P);
  const double t1 = fesd_problem_ocp_t1(), t2 = 2 * HD_PI / 3, t3 = 2.5, a = 0.9, te = t3 + 1 / a, T = 4.5;
  for (int s = 2; s <= 3; s++)
    for (int nsim = 18; nsim <= 72; nsim *= 2) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      memset(&R, 0, sizeof(R));
      fesd_integrator *it;
      fesd_create(&it, &P.model, &set);
      double u[2] = {0, 0};
      int st = fesd_set_state(it, 0, P.x0, u);
      const double H = T / nsim;
      for (int k = 0; k < nsim && !st; k++) {
        u[0] = k * H >= t3 - 1e-12 ? a : 0;
        st = fesd_step(it, u, H, &R.info);
        if (!st) hd_collect(it, &P.model, set.active_tol, &R);
      }
      hd_finish(it, &P.model, &R);
      fesd_free(&it);
      double worst = 0;
      for (int e = 0; e <= R.n_el; e++) {
        double t = R.t[e], xe[4];
        if (t < t1 - 1e-9) continue;
        P.exact(fmin(t, t3), xe);
        if (t > t3) {
          double q1 = t > te ? 0.5 * a * (t - te) * (t - te) : 0;
          xe[0] = q1;
          xe[1] = 0.05 * q1 * q1 * q1;
          xe[2] = a * (t - t3);
        }
        worst = fmax(worst, hd_maxdiff(R.x[e], xe, 4));
      }
      double ex = fabs(hd_event_time(&R, 0, FESD_EVENT_SLIDING_EXIT, t3) - te);
      double e1 = fabs(hd_event_time(&R, 1, FESD_EVENT_SLIDING_ENTRY, 0) - t1);
      double e2 = fabs(hd_event_time(&R, 0, FESD_EVENT_SLIDING_ENTRY, 0) - t2);
      int ch = hd_changes(&R, 2);
      HD_CHECK(st == FESD_OK && R.n_ev == 3 && ch == 3, "s=%d N=%d: %s, %d events, %d active-set changes", s, nsim,
               fesd_status_name(st), R.n_ev, ch);
      HD_CHECK(worst <= 1e-12 && e1 <= 1e-9 && e2 <= 1e-12 && ex <= 1e-10,
               "s=%d N=%d: error %.1e, event errors %.1e %.1e %.1e", s, nsim, worst, e1, e2, ex);
      printf("codim-2 s=%d N_sim=%2d: err (t >= t1) %.1e; entry c2 = 0 err %.1e, entry origin err %.1e, exit err %.1e; "
             "active-set changes %d, iters %d\n", s, nsim, worst, e1, e2, ex, ch, R.stats.newton_iter);
    }
  printf("%d failures\n", fails);
  return fails != 0;
}
