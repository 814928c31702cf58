/* Grazes under error control: x1' = x2 + [x1 > 0], x2' = -1 from (-1/2 + d, 1). x1 rises to d
 * at t = 1; for d > 0 it crosses 0 at t_e = 1 - sqrt(2 d) and, pushed by the extra +1, stays
 * above: x1(1.5) = 1.875 - 2 t_e + t_e^2 / 2 (closed form); missing the touch leaves
 * x1(1.5) = -0.125 + d. The solution is polynomial, so the error estimate is zero and the steps
 * grow until one holds the whole excursion between its check points: before the graze check of
 * fesd_integrate (graze.c) Radau s = 4 at rtol 1e-10 stepped over every d up to 2e-4 (24 of 51),
 * FESD_OK with x1(1.5) 0.5 off; s = 2 at rtol 1e-6 up to 8e-5 (20 of 51). */
#include "hard_util.h"

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  f[0] = x[1] + (mode == 0 ? 1.0 : 0.0), f[1] = -1;
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[0];
  return 0;
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const int nm[1] = {2}, ns[1] = {1};
  fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field, .sw = sw};
  int runs = 0, right = 0;
  double worst = 0;
  for (int s = 2; s <= 4; s++)
    for (int e = 0; e < 2; e++) {
      const double rtol = e ? 1e-10 : 1e-6;
      int missed = 0;
      for (int i = 0; i <= 50; i++) {
        const double d = pow(10.0, -6 + 5.0 * i / 50), te = 1 - sqrt(2 * d);
        const double xe = 1.875 - 2 * te + te * te / 2;
        fesd_settings set;
        fesd_settings_default(&set);
        set.stages = s;
        fesd_integrate_info info;
        const double x0[2] = {-0.5 + d, 1};
        const int st = hd_integrate_set(&m, &set, rtol, 1e-2 * rtol, 0, x0, 1.5, &R, &info);
        const double err = fabs(R.x_end[0] - xe);
        const int ok = st == FESD_OK && R.n_ev == 1 && err <= 1e3 * rtol;
        runs++, right += ok, missed += st == FESD_OK && R.n_ev == 0;
        if (st == FESD_OK) worst = fmax(worst, err / rtol);
        HD_CHECK(ok, "s=%d rtol %.0e d %.2e: %s, %d events, x1(1.5) %.6f (exact %.6f)", s, rtol, d,
                 fesd_status_name(st), R.n_ev, R.x_end[0], xe);
      }
      printf("Radau s=%d rtol %.0e: d = 1e-6..1e-1 (51 runs): %d touches stepped over\n", s, rtol, missed);
    }
  printf("grazes under error control: %d of %d runs cross with x1(1.5) within 1e3 rtol (worst %.1f rtol)\n", right,
         runs, worst);
  printf("%s (%d failures)\n", fails ? "FAIL" : "OK", fails);
  return fails ? 1 : 0;
}
