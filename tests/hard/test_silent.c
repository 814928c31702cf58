/* No silent wrong answer: cases that used to return FESD_OK with a wrong result.
 *  - bang-bang oscillator x1' = x2, x2' in -sign(x1), x0 = (0.05, -sqrt 2), steps of 3.25..12
 *    holding two crossings each (they collapsed to a false sliding mode at the origin): every
 *    run is exact (event-driven closed form in the test) or fails with a status;
 *  - starts near a repulsive surface, x' in sign(x): x0 = 1e-14 gives x0 + t (the unique
 *    solution; it used to stay on the surface), also with c = 1e-6 x; x0 = 0 exactly is flagged
 *    FESD_FLAG_NONUNIQUE;
 *  - nearly singular sliding: normal components -eps and 3 eps (eps = 1e-2 .. 1e-14): the
 *    sliding multiplier 3/4 (x2 on the closed form) or a status, never theta = 1/2. */
#include "hard_util.h"

static int bb_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = x[1];
  f[1] = mode == 0 ? -1.0 : 1.0;
  return 0;
}
static int bb_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0];
  return 0;
}
/* x1'' = -sign(x1): parabolic arcs between zeros of x1 */
static void bb_exact(double T, const double *x0, double *x) {
  double t = 0, a = x0[0], b = x0[1];
  for (;;) {
    const double sg = a > 0 ? 1 : a < 0 ? -1 : (b > 0 ? 1 : -1); /* sign of x1 on this arc */
    /* a + b tau - sg tau^2 / 2 = 0: the first positive root */
    const double d = sqrt(b * b + 2 * sg * a);
    double tz = INFINITY;
    for (int r = -1; r <= 1; r += 2) {
      const double root = (b + r * d) / sg;
      if (root > 1e-14 && root < tz) tz = root;
    }
    if (t + tz >= T) {
      const double tau = T - t;
      x[0] = a + b * tau - sg * tau * tau / 2;
      x[1] = b - sg * tau;
      return;
    }
    b -= sg * tz;
    a = 0;
    t += tz;
  }
}

typedef struct {
  double scale, sgn; /* c = scale x; x' = sgn * (+-1) */
} rep_law;
static int rep_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = mode == 0 ? 1.0 : -1.0; /* x' in sign(x): away from 0 on both sides */
  return 0;
}
static int rep_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = ((const rep_law *)user)->scale * x[0];
  return 0;
}

static int eps_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  const double eps = *(const double *)user;
  f[0] = mode == 0 ? -eps : 3 * eps;
  f[1] = mode == 0 ? 1.0 : -1.0;
  return 0;
}
static int eps_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0];
  return 0;
}

int main(void) {
  int fails = 0;
  const int nm[1] = {2}, ns[1] = {1};
  /* bang-bang: 36 step lengths x s = 2..4 x N_FE = 2..4 over T = 100 */
  {
    fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = bb_field, .sw = bb_sw};
    const double x0[2] = {0.05, -sqrt(2.0)};
    int runs = 0, exact = 0, failed = 0, wrong = 0;
    double worst = 0;
    for (double h = 3.25; h <= 12.01; h += 0.25)
      for (int s = 2; s <= 4; s++)
        for (int N = 2; N <= 4; N++) {
          fesd_settings set;
          fesd_settings_default(&set);
          set.stages = s;
          set.n_fe = N;
          fesd_integrator *it;
          fesd_create(&it, &m, &set);
          fesd_set_state(it, 0, x0, NULL);
          int st = 0;
          double t = 0;
          while (t < 100 - 1e-9 && !st) {
            const double hh = fmin(h, 100 - t);
            st = fesd_step(it, NULL, hh, NULL);
            if (!st) t += hh;
          }
          double x[2], xe[2];
          fesd_get_state(it, &t, x);
          bb_exact(t, x0, xe);
          const double err = hd_maxdiff(x, xe, 2);
          runs++;
          if (st) failed++;
          else if (err <= 1e-9) exact++, worst = fmax(worst, err);
          else {
            wrong++;
            HD_CHECK(0, "bang-bang h=%.2f s=%d N_FE=%d: FESD_OK with error %.2e", h, s, N, err);
          }
          fesd_free(&it);
        }
    printf("bang-bang, two crossings per step: %d runs, %d exact (worst %.1e), %d failed with a status, %d wrong\n",
           runs, exact, worst, failed, wrong);
  }
  /* repulsive surface */
  {
    const rep_law laws[2] = {{1.0, 1.0}, {1e-6, 1.0}};
    const double starts[2][2] = {{1e-14, 1e-10}, {1e-7, 1e-12}};
    for (int l = 0; l < 2; l++)
      for (int q = 0; q < 2; q++)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
          fesd_model m = {.nx = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = rep_field, .sw = rep_sw,
                          .user = (void *)&laws[l]};
          fesd_settings set;
          fesd_settings_default(&set);
          static hd_run R;
          const double x0 = sgn * starts[l][q];
          int st = hd_integrate(&m, &set, 0, &x0, NULL, 1.0, 10, &R);
          const double xe = x0 + sgn * 1.0;
          HD_CHECK(st == FESD_OK && fabs(R.x_end[0] - xe) <= 1e-12 && R.stats.nonunique_steps == 0,
                   "repulsive c = %g x, x0 = %g: %s, x(1) = %.3g (exact %.3g), nonunique %d", laws[l].scale, x0,
                   fesd_status_name(st), R.x_end[0], xe, R.stats.nonunique_steps);
        }
    fesd_model m = {.nx = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = rep_field, .sw = rep_sw,
                    .user = (void *)&laws[0]};
    fesd_settings set;
    fesd_settings_default(&set);
    fesd_integrator *it;
    fesd_create(&it, &m, &set);
    const double x0 = 0;
    fesd_set_state(it, 0, &x0, NULL);
    fesd_step_info info;
    int st = fesd_step(it, NULL, 0.1, &info);
    HD_CHECK(st == FESD_OK && (info.flags & FESD_FLAG_NONUNIQUE), "x0 = 0 on a repulsive surface: %s, flags %d",
             fesd_status_name(st), info.flags);
    fesd_free(&it);
    printf("repulsive surface: starts 1e-14 .. 1e-7 off it leave on their side (8 runs); x0 = 0 flagged nonunique\n");
  }
  /* nearly singular sliding: x1 reaches 0 at t = 1/2, then slides with theta = (3/4, 1/4),
   * x2' = 1/2: x2(2) = 1/2 + 3/4 */
  {
    int ok = 0, status = 0;
    for (int e = 2; e <= 14; e++) {
      double eps = pow(10.0, -e);
      fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = eps_field, .sw = eps_sw,
                      .user = &eps};
      fesd_settings set;
      fesd_settings_default(&set);
      static hd_run R;
      const double x0[2] = {0.5 * eps, 0};
      int st = hd_integrate(&m, &set, 0, x0, NULL, 2.0, 20, &R);
      const double err = fabs(R.x_end[1] - 1.25);
      if (st) status++;
      else ok += err <= 1e-8;
      HD_CHECK(st || err <= 1e-8, "eps = %g: FESD_OK with x2(2) = %.6f (exact 1.25)", eps, R.x_end[1]);
    }
    printf("nearly singular sliding, eps = 1e-2 .. 1e-14: %d exact, %d failed with a status\n", ok, status);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
