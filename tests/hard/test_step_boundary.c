/* A switch exactly at a step boundary (the next step starts on the surface).
 * Step lengths are binary fractions, so the step grid hits the switch time exactly.
 *  crossing: x' in 2 - sign(x), x0 = -3/4: crosses at t = 1/4, then x = t - 1/4;
 *  entry:    x' in -sign(x),   x0 = 1/2:  reaches 0 at t = 1/2 and slides;
 *  exit:     x' in -sign(x) + t, x0 = 0 (sign-c): slides until t = 1, x = (t-1)^2/2 after;
 *  oscillator (reference problem): crossing at t = 1 = 4 steps of 1/4 (or 8 of 1/8); state
 *    against the closed form, and dx(T)/dx0 against X(T) = expm(A1 (T-1)) J expm(A2)
 *    (paper Prop. 4: the saltation matrix J has to be applied at the step start). */
#include "hard_util.h"
#include "problems/problems.h"

static const double PI = 3.14159265358979323846;

/* osc exact sensitivity (column-major), tests/fesd/test_sensitivity.c */
static void osc_exact_X(double T, double X[4]) {
  double W = 2 * PI, tau = T - 1, e = exp(tau) * exp(1.0), c = cos(W * tau), s = sin(W * tau);
  double RJ[4] = {c - 2 * W * s, -s - 2 * W * c, s, c};
  for (int i = 0; i < 4; i++) X[i] = e * RJ[i];
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const char *names[3] = {"sign-a", "sign-b", "sign-c"};
  const double x0s[3] = {-0.75, 0.5, 0.0}, tsw[3] = {0.25, 0.5, 1.0};
  const int kinds[3] = {FESD_EVENT_CROSSING, FESD_EVENT_SLIDING_ENTRY, FESD_EVENT_SLIDING_EXIT};
  for (int p = 0; p < 3; p++)
    for (int s = 2; s <= 3; s++)
      for (int nsim = 8; nsim <= 16; nsim *= 2) {
        fesd_problem P;
        fesd_problem_get(names[p], &P);
        fesd_settings set;
        fesd_settings_default(&set);
        set.stages = s;
        double x0[2] = {x0s[p], 0}, T = 2.0;
        int st = hd_integrate(&P.model, &set, 0, x0, NULL, T, nsim, &R);
        double worst = 0;
        for (int e = 0; e <= R.n_el; e++) {
          double t = R.t[e], xe;
          if (p == 0) xe = t <= 0.25 ? -0.75 + 3 * t : t - 0.25;
          else if (p == 1) xe = t <= 0.5 ? 0.5 - t : 0;
          else xe = t <= 1 ? 0 : 0.5 * (t - 1) * (t - 1);
          worst = fmax(worst, fabs(R.x[e][0] - xe));
        }
        double et = fabs(hd_event_time(&R, 0, kinds[p], 0) - tsw[p]);
        HD_CHECK(st == FESD_OK, "%s s=%d N=%d: %s", names[p], s, nsim, fesd_status_name(st));
        HD_CHECK(worst <= 1e-12, "%s s=%d N=%d: error %.1e", names[p], s, nsim, worst);
        HD_CHECK(R.n_ev == 1 && et <= 1e-12, "%s s=%d N=%d: %d events, time error %.1e", names[p], s, nsim, R.n_ev, et);
        printf("%s (switch at %.2f = step end) s=%d N_sim=%d: err %.1e, event err %.1e, events %d, iters %d\n",
               names[p], tsw[p], s, nsim, worst, et, R.n_ev, R.stats.newton_iter);
      }
  /* oscillator: orders of the state and of dx(T)/dx0 with the switch on the step grid */
  fesd_problem P;
  fesd_problem_get("oscillator", &P);
  for (int s = 3; s <= 4; s++) {
    double ex[3], es[3], et[3], hs[3];
    for (int g = 0; g < 3; g++) {
      const int nsim = 12 << g;
      const double T = 1.5; /* steps 1/8, 1/16, 1/32: t = 1 is a step end */
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      set.sensitivities = 1;
      fesd_integrator *it;
      fesd_create(&it, &P.model, &set);
      fesd_set_state(it, 0, P.x0, NULL);
      int st = 0, nev = 0;
      double tev = NAN;
      for (int k = 0; k < nsim && !st; k++) {
        st = fesd_step(it, NULL, T / nsim, NULL);
        const fesd_event *ev;
        int ne;
        fesd_last_events(it, &ev, &ne);
        for (int e = 0; e < ne; e++, nev++) tev = ev[e].t;
      }
      double x[2], xe[2], S[4], Se[4];
      fesd_stats stats;
      fesd_get_stats(it, &stats);
      fesd_get_state(it, NULL, x);
      fesd_get_sensitivities(it, S, NULL);
      fesd_problem_oscillator_exact(T, xe);
      osc_exact_X(T, Se);
      hs[g] = T / nsim;
      ex[g] = hd_maxdiff(x, xe, 2);
      es[g] = hd_maxdiff(S, Se, 4) / hd_maxdiff(Se, (double[4]){0}, 4);
      et[g] = fabs(tev - 1);
      HD_CHECK(st == FESD_OK && nev == 1, "oscillator s=%d N=%d: %s, %d events", s, nsim, fesd_status_name(st), nev);
      printf("oscillator (switch at t = 1 = step end) s=%d N_sim=%d: x err %.1e, dx/dx0 rel err %.1e, event err %.1e, "
             "iters %d\n", s, nsim, ex[g], es[g], et[g], stats.newton_iter);
      fesd_free(&it);
    }
    double px = log(ex[1] / ex[2]) / log(hs[1] / hs[2]), ps = log(es[1] / es[2]) / log(hs[1] / hs[2]);
    HD_CHECK(px >= 2 * s - 1.5 || ex[2] <= 1e-12, "oscillator s=%d: state order %.2f", s, px);
    HD_CHECK(ps >= 2 * s - 1.5 || es[2] <= 1e-10, "oscillator s=%d: sensitivity order %.2f", s, ps);
    HD_CHECK(et[2] <= 1e-6 && es[2] <= 1e-5, "oscillator s=%d: event err %.1e, sensitivity err %.1e", s, et[2], es[2]);
    printf("oscillator s=%d: state order %.2f, sensitivity order %.2f\n", s, px, ps);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
