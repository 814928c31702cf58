/* Stick-slip friction oscillator: a unit mass on a unit spring, on a belt moving at vb = 1,
 * with Coulomb friction F = 2 that weakens linearly with the slip speed (coefficient
 * beta = 0.1, which makes the slip oscillation grow and the stick phases recur):
 *   x' = v,  v' = -x - F sign(v - vb) + beta (v - vb),  c = v - vb.
 * Stick phases are sliding modes on c = 0 (theta_0 - theta_1 = -x/F), left when x = F.
 * Semi-analytic reference: from x0 = (0, vb) (on the surface: stick) the mass sticks until
 * x = F (t = 2); every slip phase then starts at (F, vb) and solves
 * X'' - beta X' + X = 0, X = x - (F - beta vb), in closed form; it ends when v returns to vb
 * (first upward root, bisection), where the mass sticks again until x = F: a periodic
 * stick-slip cycle of period P. Asserted: event times and all element boundary states.
 * Radau IIA s = 2..4; with the argument "lobatto" the cart that starts stuck is integrated with
 * Lobatto IIIA s = 3 instead (order 2s - 2 = 4, sliding exits pinned by its last stage). */
#include "hard_util.h"

static const double VB = 1.0, FR = 2.0, BETA = 0.1;

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)u, (void)user;
  f[0] = x[1];
  f[1] = -x[0] + (mode == 0 ? -FR : FR) + BETA * (x[1] - VB);
  return 0;
}
static int field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)mode, (void)x, (void)u, (void)Ju, (void)user;
  J[0] = 0, J[1] = -1, J[2] = 1, J[3] = BETA;
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[1] - VB;
  return 0;
}
static int sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)x, (void)u, (void)Ju, (void)user;
  J[0] = 0, J[1] = 1;
  return 0;
}

/* slip phase from (F, vb): state at time tau after the exit */
static void slip(double tau, double *x) {
  const double w = sqrt(1 - BETA * BETA / 4), A = BETA * VB, B = (VB - BETA * A / 2) / w;
  double e = exp(BETA * tau / 2), c = cos(w * tau), s = sin(w * tau);
  x[0] = FR - BETA * VB + e * (A * c + B * s);
  x[1] = e * ((BETA * A / 2 + B * w) * c + (BETA * B / 2 - A * w) * s);
}

typedef struct {
  double tau_slip, x_stick, period;
} cycle;

static cycle cycle_ref(void) {
  cycle cy;
  double x[2], a = 0.01, b;
  for (;; a += 0.01) { /* first upward crossing of v = vb after the (tangential) exit */
    slip(a + 0.01, x);
    if (x[1] > VB) break;
  }
  b = a + 0.01;
  for (int i = 0; i < 200; i++) {
    double mid = 0.5 * (a + b);
    slip(mid, x);
    if (x[1] > VB) b = mid; else a = mid;
  }
  cy.tau_slip = 0.5 * (a + b);
  slip(cy.tau_slip, x);
  cy.x_stick = x[0];
  cy.period = cy.tau_slip + (FR - cy.x_stick) / VB;
  return cy;
}

static void exact(const cycle *cy, double t, double *x) {
  if (t <= FR / VB) {
    x[0] = VB * t, x[1] = VB;
    return;
  }
  double tc = fmod(t - FR / VB, cy->period);
  if (tc <= cy->tau_slip) {
    slip(tc, x);
  } else {
    x[0] = cy->x_stick + VB * (tc - cy->tau_slip);
    x[1] = VB;
  }
}

int main(int argc, char **argv) {
  const int lob = argc > 1 && !strcmp(argv[1], "lobatto");
  int fails = 0;
  static hd_run R;
  const cycle cy = cycle_ref();
  printf("reference: slip %.12f, stick from x = %.12f, period %.12f\n", cy.tau_slip, cy.x_stick, cy.period);
  const int nm[1] = {2}, ns[1] = {1};
  fesd_model m = {.nx = 2, .nsys = 1, .n_modes = nm, .n_switch = ns, .field = field,
                  .field_jac = field_jac, .sw = sw, .sw_jac = sw_jac};
  const double x0[2] = {0, VB}, T = FR / VB + 3 * cy.period;
  for (int s = lob ? 3 : 2; s <= (lob ? 3 : 4); s++) {
    const int order = lob ? 2 * s - 2 : 2 * s - 1;
    double err[3];
    for (int g = 0; g < 3; g++) {
      const int nsim = 100 << g;
      fesd_settings set;
      fesd_settings_default(&set);
      set.stages = s;
      set.family = lob ? FESD_RK_LOBATTO_IIIA : FESD_RK_RADAU_IIA;
      int st = hd_integrate(&m, &set, 0, x0, NULL, T, nsim, &R);
      double xe[2], ev = 0;
      err[g] = 0;
      for (int e = 0; e <= R.n_el; e++) {
        exact(&cy, R.t[e], xe);
        err[g] = fmax(err[g], hd_maxdiff(R.x[e], xe, 2));
      }
      int kinds_ok = R.n_ev == 7;
      for (int e = 0; e < R.n_ev; e++) {
        int k = (e + 1) / 2; /* exit at 2 + kP, entry at 2 + tau_slip + kP */
        double tref = FR / VB + (e % 2 ? (e / 2) * cy.period + cy.tau_slip : k * cy.period);
        ev = fmax(ev, fabs(R.ev[e].t - tref));
        kinds_ok &= (int)R.ev[e].kind == (e % 2 ? FESD_EVENT_SLIDING_ENTRY : FESD_EVENT_SLIDING_EXIT);
      }
      HD_CHECK(st == FESD_OK && kinds_ok && hd_changes(&R, 1) == 7, "s=%d N=%d: %s, %d events (kinds ok %d), %d changes", s,
               nsim, fesd_status_name(st), R.n_ev, kinds_ok, hd_changes(&R, 1));
      HD_CHECK(ev <= 2 * err[g] + 1e-12, "s=%d N=%d: event time error %.1e vs state error %.1e", s, nsim, ev, err[g]);
      printf("stick-slip %s s=%d N_sim=%d: %s, err %.1e, %d events (max time err %.1e), iters %d, splits %d\n",
             lob ? "Lobatto IIIA" : "Radau IIA", s, nsim, fesd_status_name(st), err[g], R.n_ev, ev, R.stats.newton_iter,
             R.stats.splits);
    }
    double p = log2(err[0] / err[1]);
    printf("stick-slip %s s=%d: order %.2f (method order %d)\n", lob ? "Lobatto IIIA" : "Radau IIA", s, p, order);
    HD_CHECK(p >= order - 1.5 || err[1] <= 1e-11, "s=%d: order %.2f", s, p);
    if (!lob) HD_CHECK(err[2] <= (s == 2 ? 1e-5 : s == 3 ? 1e-10 : 1e-12), "s=%d: error %.1e at N = 400", s, err[2]);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
