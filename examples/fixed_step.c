/* Fixed steps with fesd_step and sensitivities (README, "Using the library"):
 * x' in 2 - sign(x), x(0) = -1: crosses 0 at t = 1/3, then x = t - 1/3; dx(1)/dx0 = 1/3. */
#include <math.h>
#include <stdio.h>
#include "fesd.h"

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)x, (void)u, (void)user;
  f[0] = mode == 0 ? 1.0 : 3.0; /* mode 0: c > 0, mode 1: c < 0 */
  return 0;
}
static int switching(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[0];
  return 0;
}

int main(void) {
  const int n_modes[1] = {2}, n_switch[1] = {1};
  fesd_model model = {.nx = 1, .nu = 0, .nsys = 1, .n_modes = n_modes, .n_switch = n_switch,
                      .field = field, .sw = switching};
  fesd_settings set;
  fesd_settings_default(&set); /* FESD, Radau IIA s = 2, N_FE = 2 */
  set.sensitivities = 1;
  fesd_integrator *it;
  int st = fesd_create(&it, &model, &set);
  if (st) {
    fprintf(stderr, "setup: %s\n", fesd_status_string(st));
    return 1;
  }
  double x0 = -1.0, x, dxdx0;
  fesd_set_state(it, 0.0, &x0, NULL);
  for (int k = 0; k < 10 && !st; k++) {
    fesd_step_info info;
    st = fesd_step(it, NULL, 0.1, &info);
    const fesd_event *ev;
    int n;
    fesd_last_events(it, &ev, &n);
    for (int e = 0; e < n; e++) printf("switch at t = %.15f\n", ev[e].t);
  }
  fesd_get_state(it, NULL, &x);
  fesd_get_sensitivities(it, &dxdx0, NULL);
  printf("x(1) = %.15f (exact %.15f), dx(1)/dx0 = %.15f (exact 1/3)\n", x, 2.0 / 3, dxdx0);
  fesd_free(&it);
  return st || fabs(x - 2.0 / 3) > 1e-12 || fabs(dxdx0 - 1.0 / 3) > 1e-12;
}
