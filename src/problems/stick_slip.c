/* stick-slip (problems.h): a unit mass on a unit spring, on a belt moving at vb = 1, with
 * Coulomb friction F = 2 that weakens linearly with the slip speed (beta = 0.1, which makes the
 * slip oscillation grow and the stick phases recur):
 *   x' = v,  v' = -x - F sign(v - vb) + beta (v - vb),  c = v - vb.
 * Stick phases are sliding modes on c = 0 (theta_0 - theta_1 = -x/F), left when x = F.
 * Semi-analytic reference: from x0 = (0, vb) (stuck) the mass sticks until x = F (t = 2); every
 * slip phase then starts at (F, vb) and solves X'' - beta X' + X = 0, X = x - (F - beta vb), in
 * closed form; it ends when v returns to vb (the first upward root, bisection), where the mass
 * sticks again until x = F: a periodic stick-slip cycle. */
#include "problems/problems.h"

#include <math.h>

static const double VB = 1.0, FR = 2.0, BETA = 0.1;

int fesd_stick_slip_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  f[0] = x[1];
  f[1] = -x[0] + (mode == 0 ? -FR : FR) + BETA * (x[1] - VB);
  return 0;
}
int fesd_stick_slip_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                              void *user) {
  (void)sys, (void)mode, (void)t, (void)x, (void)u, (void)Ju, (void)user;
  J[0] = 0, J[1] = -1, J[2] = 1, J[3] = BETA;
  return 0;
}
int fesd_stick_slip_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[1] - VB;
  return 0;
}
int fesd_stick_slip_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)t, (void)x, (void)u, (void)Ju, (void)user;
  J[0] = 0, J[1] = 1;
  return 0;
}

/* slip phase from (F, vb): state at time tau after the exit */
static void slip(double tau, double *x) {
  const double w = sqrt(1 - BETA * BETA / 4), A = BETA * VB, B = (VB - BETA * A / 2) / w;
  const double e = exp(BETA * tau / 2), c = cos(w * tau), s = sin(w * tau);
  x[0] = FR - BETA * VB + e * (A * c + B * s);
  x[1] = e * ((BETA * A / 2 + B * w) * c + (BETA * B / 2 - A * w) * s);
}

fesd_stick_slip_cycle fesd_stick_slip_reference(void) {
  fesd_stick_slip_cycle cy;
  double x[2], a = 0.01, b;
  for (;; a += 0.01) { /* first upward crossing of v = vb after the (tangential) exit */
    slip(a + 0.01, x);
    if (x[1] > VB) break;
  }
  b = a + 0.01;
  for (int i = 0; i < 200; i++) {
    const double mid = 0.5 * (a + b);
    slip(mid, x);
    if (x[1] > VB) b = mid;
    else a = mid;
  }
  cy.tau_slip = 0.5 * (a + b);
  slip(cy.tau_slip, x);
  cy.x_stick = x[0];
  cy.period = cy.tau_slip + (FR - cy.x_stick) / VB;
  cy.t_first_exit = FR / VB;
  return cy;
}

int fesd_stick_slip_exact(double t, double *x) {
  const fesd_stick_slip_cycle cy = fesd_stick_slip_reference(); /* ~1e3 flops: no cache (reentrant) */
  if (t <= FR / VB) {
    x[0] = VB * t, x[1] = VB;
    return 0;
  }
  const double tc = fmod(t - FR / VB, cy.period);
  if (tc <= cy.tau_slip) {
    slip(tc, x);
  } else {
    x[0] = cy.x_stick + VB * (tc - cy.tau_slip);
    x[1] = VB;
  }
  return 0;
}
