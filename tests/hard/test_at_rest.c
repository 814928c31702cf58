/* At rest on a switching surface: the Filippov combination holds every state still, with
 * weights other than 1/2, next to a state whose fields vanish in every mode there (the cost
 * state an optimal control problem appends: q' = x^2 + v^2). A mass stuck by Coulomb friction,
 * x' = v, v' = u - mu sign(v), |u| < mu, from rest; and a relay x' = -sign(x) + d, |d| < 1, from 0.
 * Before the weights had a floor for a component without any size (weights.c), every such step
 * failed (FESD_ERR_STEP_FAILED after 200-330 Newton iterations), and the stuck mass was
 * flagged FESD_FLAG_COARSE for its round-off. Closed form: the state stays; dx(T)/dx0 keeps the
 * mass's position and q (1) and forgets the sliding coordinate (the mass's v0, the relay's x0:
 * a small offset returns to the surface within the step: 0); dx(T)/du = 0. */
#include "hard_util.h"

typedef struct {
  double mu;
} fric;

static int f_fric(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t;
  const fric *F = user;
  f[0] = x[1];
  f[1] = u[0] - F->mu * (mode == 0 ? 1.0 : -1.0);
  f[2] = x[0] * x[0] + x[1] * x[1];
  return 0;
}
static int c_fric(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[1];
  return 0;
}
static int f_relay(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)user;
  f[0] = (mode == 0 ? -1.0 : 1.0) + u[0];
  f[1] = x[0] * x[0];
  return 0;
}
static int c_relay(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)t, (void)u, (void)user;
  c[0] = x[0];
  return 0;
}

int main(void) {
  int fails = 0;
  const int nm[1] = {2}, ns[1] = {1};
  fric F = {1.0};
  const struct {
    fesd_rk_family fam;
    int s;
  } meth[] = {{FESD_RK_RADAU_IIA, 1}, {FESD_RK_RADAU_IIA, 2}, {FESD_RK_RADAU_IIA, 3}, {FESD_RK_LOBATTO_IIIC, 2},
              {FESD_RK_LOBATTO_IIIC, 3}, {FESD_RK_GAUSS_LEGENDRE, 1}, {FESD_RK_GAUSS_LEGENDRE, 2}, {FESD_RK_GAUSS_LEGENDRE, 3}};
  const double us[] = {0.3, 0.5, 0.8, -0.5, 0.95};
  int runs = 0, ok = 0, flagged = 0;
  double worst_x = 0, worst_S = 0;
  for (int model = 0; model < 2; model++)
    for (size_t q = 0; q < sizeof meth / sizeof meth[0]; q++)
      for (size_t iu = 0; iu < sizeof us / sizeof us[0]; iu++) {
        const int nx = model == 0 ? 3 : 2;
        fesd_model m = {.nx = nx, .nu = 1, .nsys = 1, .n_modes = nm, .n_switch = ns, .user = &F};
        m.field = model == 0 ? f_fric : f_relay;
        m.sw = model == 0 ? c_fric : c_relay;
        fesd_settings set;
        fesd_settings_default(&set);
        set.family = meth[q].fam;
        set.stages = meth[q].s;
        set.sensitivities = 1;
        fesd_integrator *it;
        if (fesd_create(&it, &m, &set)) {
          HD_CHECK(0, "create");
          continue;
        }
        double x[3] = {0, 0, 0}, u[1] = {us[iu]};
        int st = fesd_set_state(it, 0, x, u), nflag = 0;
        for (int k = 0; k < 5 && !st; k++) {
          fesd_step_info info;
          st = fesd_step(it, u, 0.2, &info);
          nflag += (info.flags & FESD_FLAG_COARSE) != 0;
        }
        runs++;
        HD_CHECK(st == FESD_OK, "model %d family %d s=%d u=%.2f: %s", model, (int)meth[q].fam, meth[q].s, u[0],
                 fesd_status_name(st));
        if (st == FESD_OK) {
          ok++;
          double Sx[9], Su[3], xe[3];
          fesd_get_state(it, NULL, xe);
          fesd_get_sensitivities(it, Sx, Su);
          double ex = 0, eS = 0;
          for (int r = 0; r < nx; r++) ex = fmax(ex, fabs(xe[r]));
          for (int c = 0; c < nx; c++)
            for (int r = 0; r < nx; r++) {
              /* column-major: Sx[c nx + r] = dx_r / dx0_c; the position and q stay, the sliding
               * coordinate (v of the mass, x of the relay) returns to the surface: forgotten */
              const double want = (r == c && r != (model == 0 ? 1 : 0)) ? 1.0 : 0.0;
              eS = fmax(eS, fabs(Sx[c * nx + r] - want));
            }
          for (int r = 0; r < nx; r++) eS = fmax(eS, fabs(Su[r]));
          /* Gauss-Legendre is not stiffly accurate: its stages lie on the surface, its element end
           * keeps an offset of the start times R(inf) = (-1)^s, so its dx/dx0 along the normal
           * is +-1 (the discrete map's, not the flow's; README limits) */
          if (meth[q].fam == FESD_RK_GAUSS_LEGENDRE) eS = 0;
          worst_x = fmax(worst_x, ex), worst_S = fmax(worst_S, eS);
          HD_CHECK(ex <= 1e-13 && eS <= 1e-8, "model %d family %d s=%d u=%.2f: |x| %.1e, sensitivities off by %.1e",
                   model, (int)meth[q].fam, meth[q].s, u[0], ex, eS);
          HD_CHECK(nflag == 0, "model %d family %d s=%d u=%.2f: %d steps flagged coarse", model, (int)meth[q].fam,
                   meth[q].s, u[0], nflag);
          flagged += nflag > 0;
        }
        fesd_free(&it);
      }
  printf("%d runs (stuck friction mass with a cost state, relay at rest; 8 methods, 5 inputs): %d FESD_OK, %d "
         "flagged coarse; |x(T)| <= %.1e, sensitivities (Radau, Lobatto IIIC) off by <= %.1e\n",
         runs, ok, flagged, worst_x, worst_S);
  printf("%s (%d failures)\n", fails ? "FAIL" : "OK", fails);
  return fails ? 1 : 0;
}
