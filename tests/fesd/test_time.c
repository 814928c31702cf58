/* Time in the callbacks and the drift, against the same dynamics written the old way:
 *  - x' in -sign(x) + 2 sin(t) with time_dependent = 1, against x, tau with tau' = 1 written
 *    into the modes: the same end state, event times and dx/dx0 (Radau IIA s = 2, 3, fixed
 *    steps; finite-difference and analytic Jacobians);
 *  - a drift f0 = -x/2 + u shared by the modes +-1, against modes that contain it: the same
 *    end state, dx/dx0 and dx/du. */
#include <math.h>
#include <stdio.h>

#include "fesd.h"
#include "../check.h"

static int td_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = (mode == 0 ? -1.0 : 1.0) + 2 * sin(t);
  return 0;
}
static int td_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  J[0] = 0;
  return 0;
}
static int td_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0];
  return 0;
}
static int td_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  J[0] = 1;
  return 0;
}
static int tau_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = (mode == 0 ? -1.0 : 1.0) + 2 * sin(x[1]);
  f[1] = 1;
  return 0;
}
static int tau_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  c[0] = x[0];
  return 0;
}

static int dr_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = mode == 0 ? -1.0 : 1.0;
  return 0;
}
static int dr_drift(double t, const double *x, const double *u, double *f, void *user) {
  f[0] = -0.5 * x[0] + u[0];
  return 0;
}
static int full_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  f[0] = (mode == 0 ? -1.0 : 1.0) - 0.5 * x[0] + u[0];
  return 0;
}

int main(void) {
  int fails = 0;
  const int nm[1] = {2}, ns[1] = {1};
  for (int s = 2; s <= 3; s++)
    for (int jac = 0; jac < 2; jac++) {
      fesd_model A = {.nx = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = td_field, .sw = td_sw,
                      .field_jac = jac ? td_jac : NULL, .sw_jac = jac ? td_sw_jac : NULL, .time_dependent = 1};
      fesd_model B = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = tau_field, .sw = tau_sw};
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      set.sensitivities = 1;
      fesd_integrator *a, *b;
      FESD_TEST_CHECK(fesd_create(&a, &A, &set) == FESD_OK && fesd_create(&b, &B, &set) == FESD_OK, "create");
      const double xa = 0.5, xb[2] = {0.5, 0.3};
      fesd_set_state(a, 0.3, &xa, NULL);
      fesd_set_state(b, 0.3, xb, NULL);
      int sa = 0, sb = 0, evd = 0;
      double ev_diff = 0;
      for (int k = 0; k < 50 && !sa && !sb; k++) {
        sa = fesd_step(a, NULL, 0.1, NULL);
        sb = fesd_step(b, NULL, 0.1, NULL);
        const fesd_event *ea, *eb;
        int na, nb;
        fesd_last_events(a, &ea, &na);
        fesd_last_events(b, &eb, &nb);
        evd += na != nb;
        for (int e = 0; e < na && e < nb; e++) ev_diff = fmax(ev_diff, fabs(ea[e].t - eb[e].t));
      }
      double x1, x2[2], S1, S2[4], t1, t2;
      fesd_get_state(a, &t1, &x1);
      fesd_get_state(b, &t2, x2);
      fesd_get_sensitivities(a, &S1, NULL);
      fesd_get_sensitivities(b, S2, NULL);
      const double dx = fabs(x1 - x2[0]), dS = fabs(S1 - S2[0]);
      FESD_TEST_CHECK(!sa && !sb && evd == 0 && ev_diff <= 1e-11 && dx <= 1e-11 && dS <= 1e-7 && t1 == t2,
                      "time-dependent s=%d jac=%d: %s/%s, x %.3g vs %.3g, dx/dx0 %.9f vs %.9f, events differ %d (%.1e)",
                      s, jac, fesd_status_name(sa), fesd_status_name(sb), x1, x2[0], S1, S2[0], evd, ev_diff);
      printf("x' in -sign(x) + 2 sin t, s=%d, %s Jacobians: |x(T) - x_tau(T)| %.1e, events %.1e, dx/dx0 %.1e apart\n", s,
             jac ? "analytic" : "FD", dx, ev_diff, dS);
      fesd_free(&a);
      fesd_free(&b);
    }
  {
    fesd_model C = {.nx = 1, .nu = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = dr_field, .sw = td_sw,
                    .drift = dr_drift};
    fesd_model D = {.nx = 1, .nu = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = full_field, .sw = td_sw};
    fesd_settings set;
    fesd_settings_default(&set);
    set.sensitivities = 1;
    fesd_integrator *c, *d;
    fesd_create(&c, &C, &set);
    fesd_create(&d, &D, &set);
    const double x0 = 2, u = 0.3;
    fesd_set_state(c, 0, &x0, &u);
    fesd_set_state(d, 0, &x0, &u);
    int st = 0;
    for (int k = 0; k < 40 && !st; k++) st = fesd_step(c, &u, 0.1, NULL) | fesd_step(d, &u, 0.1, NULL);
    double xc, xd, Sc, Sd, Uc, Ud;
    fesd_get_state(c, NULL, &xc);
    fesd_get_state(d, NULL, &xd);
    fesd_get_sensitivities(c, &Sc, &Uc);
    fesd_get_sensitivities(d, &Sd, &Ud);
    FESD_TEST_CHECK(!st && fabs(xc - xd) <= 1e-12 && fabs(Sc - Sd) <= 1e-7 && fabs(Uc - Ud) <= 1e-7,
                    "drift: x %.15f vs %.15f, dx/dx0 %.9f vs %.9f, dx/du %.9f vs %.9f", xc, xd, Sc, Sd, Uc, Ud);
    printf("drift -x/2 + u vs in the modes: |x(T)| diff %.1e, dx/dx0 %.1e, dx/du %.1e\n", fabs(xc - xd), fabs(Sc - Sd),
           fabs(Uc - Ud));
    fesd_free(&c);
    fesd_free(&d);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
