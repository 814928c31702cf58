/* The scalar examples of the paper (Example 2 and Sec. 2): crossing (sign-a), entering a
 * sliding mode (sign-b), leaving it (sign-c), and the non-unique sign-d; plus step
 * equilibration (equal h in steps without switch, boundary on the switch otherwise). */
#include "fesd_test_util.h"

static tu_run R;

int main(void) {
  int fails = 0;
  fesd_problem P;
  fesd_settings set;
  /* sign-a: x' in 2 - sign(x), x0 = -1: switch at 1/3 within 1e-12 for every N_sim */
  fesd_problem_get("sign-a", &P);
  for (int s = 2; s <= 3; s++)
    for (int nsim = 2; nsim <= 64; nsim *= 2) {
      fesd_settings_default(&set);
      set.stages = s;
      int st = tu_integrate(&P, &set, nsim, P.T, &R);
      double xe[2];
      P.exact(P.T, xe);
      double dts = R.n_ev == 1 ? fabs(R.ev[0].t - 1.0 / 3) : INFINITY;
      TU_CHECK(st == FESD_OK, "sign-a s=%d N=%d status %s", s, nsim, fesd_status_name(st));
      TU_CHECK(R.n_ev == 1 && R.ev[0].kind == FESD_EVENT_CROSSING, "sign-a s=%d N=%d: %d events", s, nsim, R.n_ev);
      TU_CHECK(dts <= 1e-12, "sign-a s=%d N=%d: |t_s - 1/3| = %.2e", s, nsim, dts);
      TU_CHECK(fabs(R.xT[0] - xe[0]) <= 1e-12, "sign-a s=%d N=%d: error %.2e", s, nsim, fabs(R.xT[0] - xe[0]));
      printf("sign-a s=%d N_sim=%2d: |t_s-1/3| = %.1e  err = %.1e  iters %d\n", s, nsim, dts,
             fabs(R.xT[0] - xe[0]), R.stats.newton_iter);
      /* step equilibration: equal h within every step without a switch; boundary on the switch */
      for (int e = 0; e + 1 < R.n_el; e++) {
        if (R.step_of[e] != R.step_of[e + 1]) continue;
        int switch_here = fabs(R.t[e + 1] - 1.0 / 3) < 1e-9;
        int step_has_switch = R.t[e] < 1.0 / 3 + 1e-9 && R.t[e + 1] + R.h[e + 1] > 1.0 / 3 - 1e-9;
        if (!step_has_switch)
          TU_CHECK(fabs(R.h[e + 1] - R.h[e]) <= 1e-12, "sign-a: unequal h %.3e %.3e in a step without switch", R.h[e], R.h[e + 1]);
        (void)switch_here;
      }
    }
  /* sign-b: reaches 0 at t = 1 and slides: x stays on 0 to 1e-10 */
  fesd_problem_get("sign-b", &P);
  for (int s = 2; s <= 3; s++)
    for (int nsim = 5; nsim <= 80; nsim *= 2) {
      fesd_settings_default(&set);
      set.stages = s;
      int st = tu_integrate(&P, &set, nsim, P.T, &R);
      double worst = 0;
      for (int e = 0; e <= R.n_el; e++)
        if (R.t[e] >= 1.0 - 1e-9) worst = fmax(worst, fabs(R.x[e][0]));
      double dts = R.n_ev >= 1 ? fabs(R.ev[0].t - 1.0) : INFINITY;
      TU_CHECK(st == FESD_OK, "sign-b s=%d N=%d status %s", s, nsim, fesd_status_name(st));
      TU_CHECK(worst <= 1e-10, "sign-b s=%d N=%d: |x| = %.2e while sliding", s, nsim, worst);
      TU_CHECK(R.n_ev == 1 && R.ev[0].kind == FESD_EVENT_SLIDING_ENTRY, "sign-b s=%d N=%d: %d events", s, nsim, R.n_ev);
      TU_CHECK(dts <= 1e-10, "sign-b s=%d N=%d: |t_entry - 1| = %.2e", s, nsim, dts);
      printf("sign-b s=%d N_sim=%2d: |t_entry-1| = %.1e  max|x| sliding = %.1e  iters %d\n", s, nsim,
             dts, worst, R.stats.newton_iter);
    }
  /* sign-c (paper formulation, exit rows off): slides on x = 0, leaves near t = 1 */
  fesd_problem_get("sign-c", &P);
  for (int s = 2; s <= 3; s++)
    for (int nsim = 10; nsim <= 80; nsim *= 2) {
      fesd_settings_default(&set);
      set.stages = s;
      set.exit_rows = 0;
      int st = tu_integrate(&P, &set, nsim, P.T, &R);
      double worst = 0, hnom = P.T / nsim;
      for (int e = 0; e <= R.n_el; e++)
        if (R.t[e] <= 1.0 - hnom) worst = fmax(worst, fabs(R.x[e][0]));
      double xe[2];
      P.exact(P.T, xe);
      double texit = NAN;
      for (int v = 0; v < R.n_ev; v++)
        if (R.ev[v].kind == FESD_EVENT_SLIDING_EXIT) texit = R.ev[v].t;
      TU_CHECK(st == FESD_OK, "sign-c s=%d N=%d status %s", s, nsim, fesd_status_name(st));
      TU_CHECK(worst <= 1e-10, "sign-c s=%d N=%d: |x| = %.2e while sliding", s, nsim, worst);
      TU_CHECK(fabs(texit - 1) <= hnom, "sign-c s=%d N=%d: exit at %.6f", s, nsim, texit);
      TU_CHECK(fabs(R.xT[0] - xe[0]) <= 1e-4, "sign-c s=%d N=%d: error %.2e", s, nsim, fabs(R.xT[0] - xe[0]));
      printf("sign-c s=%d N_sim=%2d (paper formulation): exit at %.10f (error %.1e)  x(T) error %.1e\n", s,
             nsim, texit, fabs(texit - 1), fabs(R.xT[0] - xe[0]));
    }
  /* sign-d: x' in sign(x), x0 = 0: any Filippov solution; theta on the simplex and
   * |dx/dt| <= 1 between boundaries (x' in the convex hull of {-1, 1}). */
  fesd_problem_get("sign-d", &P);
  for (int s = 1; s <= 3; s++) {
    fesd_settings_default(&set);
    set.stages = s;
    int st = tu_integrate(&P, &set, 10, P.T, &R);
    double worst = 0;
    for (int e = 0; e < R.n_el; e++) worst = fmax(worst, fabs(R.x[e + 1][0] - R.x[e][0]) / R.h[e] - 1.0);
    TU_CHECK(st == FESD_OK, "sign-d s=%d status %s", s, fesd_status_name(st));
    TU_CHECK(R.th_min >= -1e-10 && R.th_sum_err <= 1e-10, "sign-d s=%d: theta off the simplex", s);
    TU_CHECK(worst <= 1e-10, "sign-d s=%d: |x'| exceeds 1 by %.2e", s, worst);
    printf("sign-d s=%d: x(T) = %.6f (Filippov: |x'| <= 1 holds to %.1e)\n", s, R.xT[0], fmax(worst, 0));
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
