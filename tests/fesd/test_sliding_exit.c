/* Pinned sliding exits (beyond the paper; docs/sliding_exit.md): with the exit rows on,
 * leaving a sliding mode is as accurate as a crossing.
 * sign-c (T = 2.1, exit at t = 1 off the step grid): x is piecewise polynomial, so the
 *   state and the exit time are exact to round-off once the exit is pinned.
 * slide-exit-2d (nonlinear exit from a curved surface; reference computed independently:
 *   bisection + Simpson for the exit, closed form afterwards): the step length is chosen
 *   per N so that the exit sits at 0.4 of its step; state error order >= 2s - 1.5 and exit
 *   time order >= s - 0.5 (or at the round-off / Newton-tolerance floor). */
#include "fesd_test_util.h"

static tu_run R;

static double fit(const double *h, const double *e, int n, double floor) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  for (int i = 0; i < n; i++)
    if (e[i] > floor) {
      double lx = log(h[i]), ly = log(e[i]);
      sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, m++;
    }
  return m >= 3 ? (m * sxy - sx * sy) / (m * sxx - sx * sx) : INFINITY; /* INFINITY: at the floor */
}

static double exit_time(const tu_run *r) {
  for (int v = 0; v < r->n_ev; v++)
    if (r->ev[v].kind == FESD_EVENT_SLIDING_EXIT) return r->ev[v].t;
  return NAN;
}

int main(void) {
  int fails = 0;
  const int grid[] = {10, 20, 40, 80, 160, 320};
  const int ng = 6;
  fesd_problem P;
  fesd_problem_get("sign-c", &P);
  for (int s = 2; s <= 3; s++) {
    double ex = 0, et = 0;
    for (int g = 0; g < ng; g++) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      int st = tu_integrate(&P, &set, grid[g], P.T, &R);
      double xe[2];
      P.exact(P.T, xe);
      TU_CHECK(st == FESD_OK, "sign-c s=%d N=%d: %s", s, grid[g], fesd_status_name(st));
      ex = fmax(ex, fabs(R.xT[0] - xe[0]));
      et = fmax(et, fabs(exit_time(&R) - 1.0));
    }
    TU_CHECK(ex <= 1e-12 && et <= 1e-10, "sign-c s=%d: state error %.1e, exit time error %.1e", s, ex, et);
    printf("sign-c s=%d, N_sim = 10..320: max state error %.1e, max exit-time error %.1e\n", s, ex, et);
  }
  fesd_problem_get("slide-exit-2d", &P);
  double ts, ys;
  fesd_problem_slide_exit_point(&ts, &ys);
  for (int s = 2; s <= 3; s++) {
    double h[6], ex[6], et[6];
    for (int g = 0; g < ng; g++) {
      double H0 = 2.1 / grid[g], H = ts / (floor(ts / H0) + 0.4), T = grid[g] * H, xe[2];
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      int st = tu_integrate(&P, &set, grid[g], T, &R);
      TU_CHECK(st == FESD_OK, "slide-exit-2d s=%d N=%d: %s", s, grid[g], fesd_status_name(st));
      P.exact(T, xe);
      h[g] = H;
      ex[g] = fmax(fabs(R.xT[0] - xe[0]), fabs(R.xT[1] - xe[1]));
      et[g] = fabs(exit_time(&R) - ts);
    }
    if (getenv("TU_VERBOSE")) for (int g = 0; g < ng; g++) printf("   N=%d state %.3e time %.3e\n", grid[g], ex[g], et[g]);
    /* floors: round-off accumulated over 320 steps (1e-13 measured), Newton tolerance */
    double px = fit(h, ex, ng, 2e-13), pt = fit(h, et, ng, 1e-9);
    TU_CHECK(px >= 2 * s - 1.5, "slide-exit-2d s=%d: state order %.2f", s, px);
    TU_CHECK(pt >= s - 0.5, "slide-exit-2d s=%d: exit-time order %.2f", s, pt);
    printf("slide-exit-2d s=%d: state error %.1e .. %.1e (order %.2f), exit time error %.1e .. %.1e "
           "(order %.2f)\n", s, ex[0], ex[ng - 1], px, et[0], et[ng - 1], pt);
  }
  /* No regression: on problems without sliding exits the option changes nothing, neither
   * the result nor the Newton iterations (within 10 %). */
  const char *probs[] = {"oscillator", "sign-a", "sign-b", "ocp-dynamics"};
  for (int p = 0; p < 4; p++)
    for (int s = 2; s <= 3; s++) {
      fesd_problem Q;
      fesd_problem_get(probs[p], &Q);
      int it_on, it_off;
      double diff = 0;
      static tu_run R2;
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      int st1 = tu_integrate(&Q, &set, 40, Q.T, &R);
      it_on = R.stats.newton_iter;
      set.exit_rows = 0;
      int st2 = tu_integrate(&Q, &set, 40, Q.T, &R2);
      it_off = R2.stats.newton_iter;
      for (int i = 0; i < Q.model.nx; i++) diff = fmax(diff, fabs(R.xT[i] - R2.xT[i]));
      TU_CHECK(!st1 && !st2 && diff <= 1e-14 && abs(it_on - it_off) <= 0.1 * it_off,
               "%s s=%d: exit rows on/off differ: |dx| %.1e, iterations %d vs %d", probs[p], s, diff, it_on, it_off);
      printf("%-12s s=%d N_sim=40: exit rows on/off: |x(T) difference| %.1e, Newton iterations %d / %d\n",
             probs[p], s, diff, it_on, it_off);
    }
  printf("%d failures\n", fails);
  return fails != 0;
}
