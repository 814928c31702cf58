/* x0 exactly on a switching surface.
 *  crossing:  x' in 2 - sign(x), x0 = 0: both fields point to x > 0, x = t;
 *  sliding:   x' in -sign(x),    x0 = 0: x = 0;
 *  2-D crossing: oscillator field from x0 = (1, 0) on the unit circle: both fields point
 *             outwards, x = e^t (cos 2 pi t, -sin 2 pi t) (outer mode A1);
 *             (before the fix in src/fesd/active.c this failed at once: with both modes
 *             active the sliding DAE has no solution, since both normal components are 1);
 *  2-D sliding on a curve: slide-exit-2d from x0 = 0 (on c = x1 + x2^2/2 = 0): slides, exit
 *             time from the independent bisection + Simpson reference;
 *  co-dimension 2: x1' in -sign(x1), x2' in -sign(x2) (two subsystems) from the origin: stays. */
#include "hard_util.h"
#include "problems/problems.h"

typedef struct {
  double pos, neg; /* x_k' for x_k > 0 (mode 0) and x_k < 0 (mode 1) */
  int nx;          /* one subsystem per coordinate */
} law;

static int f_sign(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)x, (void)u;
  const law *L = user;
  memset(f, 0, (size_t)L->nx * sizeof(double));
  f[sys] = mode == 0 ? L->pos : L->neg;
  return 0;
}
static int c_sign(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)u, (void)user;
  c[0] = x[sys];
  return 0;
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const int nm1[1] = {2}, ns1[1] = {1}, nm2[2] = {2, 2}, ns2[2] = {1, 1};
  for (int s = 1; s <= 3; s++)
    for (int v = 0; v < 2; v++) {
      law L = {v == 0 ? 1.0 : -1.0, v == 0 ? 3.0 : 1.0, 1};
      fesd_model m = {.nx = 1, .nsys = 1, .n_modes = nm1, .n_switch = ns1, .field = f_sign, .sw = c_sign, .user = &L};
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      const double x0[1] = {0};
      int st = hd_integrate(&m, &set, 0, x0, NULL, 1.0, 10, &R);
      double worst = 0;
      for (int e = 0; e <= R.n_el; e++) worst = fmax(worst, fabs(R.x[e][0] - (v == 0 ? R.t[e] : 0)));
      HD_CHECK(st == FESD_OK && worst <= 1e-12, "%s s=%d: %s err %.1e", v ? "sliding" : "crossing", s,
               fesd_status_name(st), worst);
      printf("x0 = 0, %s, s=%d: err %.1e, events %d, iters %d\n", v ? "sliding x' in -sign(x)" : "crossing x' in 2 - sign(x)",
             s, worst, R.n_ev, R.stats.newton_iter);
    }
  /* oscillator from the circle: both fields point outwards, x = e^t (cos 2 pi t, -sin 2 pi t) */
  fesd_problem P;
  fesd_problem_get("oscillator", &P);
  for (int s = 2; s <= 4; s++) {
    double err[3];
    int iters = 0;
    for (int g = 0; g < 3; g++) {
      int nsim = 20 << g;
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      const double x0[2] = {1, 0}, T = 0.5;
      int st = hd_integrate(&P.model, &set, 0, x0, NULL, T, nsim, &R);
      err[g] = 0;
      for (int e = 0; e <= R.n_el; e++) {
        double t = R.t[e], xe[2] = {exp(t) * cos(2 * HD_PI * t), -exp(t) * sin(2 * HD_PI * t)};
        err[g] = fmax(err[g], hd_maxdiff(R.x[e], xe, 2));
      }
      iters += R.stats.newton_iter;
      HD_CHECK(st == FESD_OK && R.n_ev == 0, "oscillator from the circle s=%d N=%d: %s, %d events", s, nsim,
               fesd_status_name(st), R.n_ev);
    }
    double p = log2(err[1] / err[2]);
    HD_CHECK(p >= 2 * s - 1.5 || err[2] <= 1e-13, "oscillator from the circle s=%d: order %.2f", s, p);
    printf("oscillator x0 = (1,0) on c = 0, s=%d, N_sim = 20/40/80: err %.1e %.1e %.1e (order %.2f), iters %d\n", s,
           err[0], err[1], err[2], p, iters);
  }
  /* slide-exit-2d from x0 = 0 (on c = 0, sliding) */
  fesd_problem_get("slide-exit-2d", &P);
  double ts, ys;
  fesd_problem_slide_exit_point(&ts, &ys);
  for (int s = 2; s <= 3; s++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.stages = s;
    int st = hd_integrate(&P.model, &set, 0, P.x0, NULL, P.T, 40, &R);
    double xe[2];
    P.exact(P.T, xe);
    double ex = hd_maxdiff(R.x_end, xe, 2), et = fabs(hd_event_time(&R, 0, FESD_EVENT_SLIDING_EXIT, 0) - ts);
    HD_CHECK(st == FESD_OK && R.n_ev == 1 && ex <= (s == 2 ? 3e-6 : 1e-10) && et <= (s == 2 ? 1e-4 : 3e-7),
             "slide-exit-2d s=%d: %s, %d events, error %.1e, exit time error %.1e", s, fesd_status_name(st), R.n_ev, ex, et);
    printf("slide-exit-2d x0 = 0 on c = 0 (sliding), s=%d N_sim=40: err %.1e, exit time err %.1e, events %d, iters %d\n",
           s, ex, et, R.n_ev, R.stats.newton_iter);
  }
  /* co-dimension 2 */
  for (int s = 1; s <= 3; s++) {
    law L = {-1, 1, 2};
    fesd_model m = {.nx = 2, .nsys = 2, .n_modes = nm2, .n_switch = ns2, .field = f_sign, .sw = c_sign, .user = &L};
    fesd_settings set;
    fesd_settings_default(&set);
    set.stages = s;
    const double x0[2] = {0, 0};
    int st = hd_integrate(&m, &set, 0, x0, NULL, 1.0, 10, &R);
    double worst = 0;
    for (int e = 0; e <= R.n_el; e++) worst = fmax(worst, fmax(fabs(R.x[e][0]), fabs(R.x[e][1])));
    HD_CHECK(st == FESD_OK && worst <= 1e-12, "co-dimension 2 s=%d: %s, max |x| %.1e", s, fesd_status_name(st), worst);
    printf("x0 = (0,0), x' in -sign(x1), -sign(x2), s=%d: max |x| %.1e, events %d, iters %d\n", s, worst, R.n_ev,
           R.stats.newton_iter);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
