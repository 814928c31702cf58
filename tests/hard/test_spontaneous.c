/* Spontaneous switch (sign-d, paper Sec. 2): x' in sign(x). From x0 = 0 every
 * x = +-(t - tau)_+ is a Filippov solution (non-unique); from x0 = +-1e-9 the solution is
 * unique: x = +-(1e-9 + t). Asserted from x0 = 0: theta on the simplex, |x'| <= 1 on every
 * element (x' in the convex hull of {-1, 1}), and once |x| > 1e-9 the element moves away at
 * unit speed (x' = sign(x) off the surface). Two subsystems x_k' in sign(x_k) from the
 * origin: the same per component. */
#include "hard_util.h"

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)x, (void)u;
  const int *nx = user;
  memset(f, 0, (size_t)*nx * sizeof(double));
  f[sys] = mode == 0 ? 1.0 : -1.0; /* mode 0: x > 0 */
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)u, (void)user;
  c[0] = x[sys];
  return 0;
}

/* max violation of the Filippov conditions along the element boundaries of R */
static double filippov_violation(const hd_run *R, int nx) {
  double worst = 0;
  for (int e = 0; e < R->n_el; e++) {
    double h = R->t[e + 1] - R->t[e];
    for (int r = 0; r < nx; r++) {
      double a = R->x[e][r], b = R->x[e + 1][r];
      worst = fmax(worst, fabs(b - a) - h);                     /* |x'| <= 1 */
      if (fabs(a) > 1e-9) worst = fmax(worst, fabs(fabs(b) - fabs(a) - h)); /* away at speed 1 */
    }
  }
  return worst;
}

int main(void) {
  int fails = 0;
  static hd_run R;
  const int nm[2] = {2, 2}, ns[2] = {1, 1};
  for (int nx = 1; nx <= 2; nx++)
    for (int s = 1; s <= 3; s++)
      for (int v = 0; v < 3; v++) {
        const double x00 = v == 0 ? 0.0 : v == 1 ? 1e-9 : -1e-9;
        fesd_model m = {.nx = nx, .nsys = nx, .n_modes = nm, .n_switch = ns, .field = field, .sw = sw, .user = &nx};
        fesd_settings set;
        fesd_settings_default(&set);
        set.stages = s;
        const double x0[2] = {x00, x00}, T = 1.0;
        int st = hd_integrate(&m, &set, 0, x0, NULL, T, 10, &R);
        double viol = filippov_violation(&R, nx), err = 0;
        if (v > 0)
          for (int e = 0; e <= R.n_el; e++)
            for (int r = 0; r < nx; r++) err = fmax(err, fabs(R.x[e][r] - x00 - (v == 1 ? 1 : -1) * R.t[e]));
        HD_CHECK(st == FESD_OK, "nx=%d s=%d x0=%g: %s", nx, s, x00, fesd_status_name(st));
        HD_CHECK(viol <= 1e-12, "nx=%d s=%d x0=%g: not a Filippov solution (%.1e)", nx, s, x00, viol);
        HD_CHECK(err <= 1e-12, "nx=%d s=%d x0=%g: error %.1e", nx, s, x00, err);
        printf("sign-d, %d subsystem(s), s=%d, x0 = %-6g: x(1) = %+.6f, Filippov violation %.1e, error %.1e, iters %d\n",
               nx, s, x00, R.x_end[0], fmax(viol, 0), err, R.stats.newton_iter);
      }
  printf("%d failures\n", fails);
  return fails != 0;
}
