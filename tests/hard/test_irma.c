/* A gene regulatory network from the literature: the IRMA synthetic network of yeast in the
 * piecewise-affine model of Acary, de Jong and Brogliato (2014), "switch on" variant, as in the
 * nosnoc examples: five concentrations x, seven thresholds, steps S+(x_j, theta) = 1 above,
 * 0 below:
 *   x1' = k11 + k12 S+(x4, 0.04)                      - g1 x1
 *   x2' = k21 + k22 S+(x1, 0.01)                      - g2 x2
 *   x3' = k31 + k32 S+(x2, 0.06)                      - g3 x3
 *   x4' = k41 S+(x2, 0.01) + k42 S+(x2, 0.01) S-(x3, 0.035) - g4 x4
 *   x5' = k51 + k52 S+(x2, 0.08)                      - g5 x5
 * x(0) = (0.011, 0.09, 0.04, 0.05, 0.015), T = 1000. Concentrations of 1e-2..1e-1 change by
 * 1e-4 per time unit: a badly scaled problem for absolute tolerances.
 * As a libfesd model: the shared part (-g x + the constant synthesis) is the drift; every
 * step function is a subsystem of two modes, except the product in x4', one subsystem with two
 * switching functions (x2 - 0.01, x3 - 0.035) and four modes.
 * Reference, independent of the code under test: no rate depends on its own concentration's
 * thresholds, so there is no sliding; between switches every component is x_i(t) = e_i +
 * (x_i(t0) - e_i) exp(-g_i (t - t0)) with e_i = b_i / g_i, and the next crossing of threshold
 * theta of component i is at t0 + log((x_i(t0) - e_i) / (theta - e_i)) / g_i: an event-driven
 * integration in closed form.
 * Asserted for Radau IIA s = 2, 3, Lobatto IIIC s = 2, 3 and Gauss-Legendre s = 2, N_FE = 2,
 * N_sim = 50 .. 400: every run FESD_OK without flags, the reference's events (subsystem, order),
 * event times and x(T) converging at the method's order (fitted slope >= p - 0.7 over errors
 * above 1e-12, relative per component), no flag but FESD_FLAG_COARSE (an honest one: a run
 * without it is within 1e-4). And fesd_integrate (Radau IIA s = 3) at rtol 1e-4, 1e-7, 1e-10
 * (atol 1e-3 rtol): the reference's events, x(T) within 10 rtol. */
#include "hard_util.h"

#define NX 5
#define NSYS 5
#define T_END 1000.0
#define MAX_EV 256

static const double G[NX] = {0.05, 0.04, 0.05, 0.02, 0.6};
static const double K[NX][2] = {{1.1e-4, 9e-4}, {3e-4, 0.15}, {6e-4, 0.018}, {5e-4, 0.03}, {7.5e-4, 0.015}};
/* switching functions c = x[comp] - thr, in subsystem order (subsystem 1 holds two) */
static const int COMP[6] = {0, 1, 2, 1, 1, 3};
static const double THR[6] = {0.01, 0.01, 0.035, 0.06, 0.08, 0.04};
static const int FIRST[NSYS + 1] = {0, 1, 3, 4, 5, 6}; /* switching functions of each subsystem */

/* synthesis b(x) for the step values s[j] in {0, 1} of the six switching functions */
static void synthesis(const int *s, double *b) {
  b[0] = K[0][0] + K[0][1] * s[5];
  b[1] = K[1][0] + K[1][1] * s[0];
  b[2] = K[2][0] + K[2][1] * s[3];
  b[3] = K[3][0] * s[1] + K[3][1] * s[1] * (1 - s[2]);
  b[4] = K[4][0] + K[4][1] * s[4];
}

/* ---- the model ---- */
static int drift(double t, const double *x, const double *u, double *f, void *user) {
  (void)t, (void)u, (void)user;
  const double c[NX] = {K[0][0], K[1][0], K[2][0], 0.0, K[4][0]};
  for (int i = 0; i < NX; i++) f[i] = c[i] - G[i] * x[i];
  return 0;
}
static int drift_jac(double t, const double *x, const double *u, double *dfdx, double *dfdu, void *user) {
  (void)t, (void)x, (void)u, (void)dfdu, (void)user;
  memset(dfdx, 0, NX * NX * sizeof(double));
  for (int i = 0; i < NX; i++) dfdx[i * NX + i] = -G[i];
  return 0;
}
/* mode 0 of a two-mode subsystem: c > 0 (step 1); subsystem 1: modes by the signs of
 * (x2 - 0.01, x3 - 0.035): ++, +-, -+, -- */
static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)t, (void)x, (void)u, (void)user;
  memset(f, 0, NX * sizeof(double));
  const int on = mode == 0;
  switch (sys) {
  case 0: f[1] = K[1][1] * on; break;
  case 1: f[3] = mode == 0 ? K[3][0] : mode == 1 ? K[3][0] + K[3][1] : 0.0; break;
  case 2: f[2] = K[2][1] * on; break;
  case 3: f[4] = K[4][1] * on; break;
  default: f[0] = K[0][1] * on; break;
  }
  return 0;
}
static int field_jac(int sys, int mode, double t, const double *x, const double *u, double *dfdx, double *dfdu,
                     void *user) {
  (void)sys, (void)mode, (void)t, (void)x, (void)u, (void)dfdu, (void)user;
  memset(dfdx, 0, NX * NX * sizeof(double));
  return 0;
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)t, (void)u, (void)user;
  for (int j = FIRST[sys]; j < FIRST[sys + 1]; j++) c[j - FIRST[sys]] = x[COMP[j]] - THR[j];
  return 0;
}
static int sw_jac(int sys, double t, const double *x, const double *u, double *dcdx, double *dcdu, void *user) {
  (void)t, (void)x, (void)u, (void)dcdu, (void)user;
  const int rows = FIRST[sys + 1] - FIRST[sys];
  memset(dcdx, 0, (size_t)rows * NX * sizeof(double));
  for (int j = FIRST[sys]; j < FIRST[sys + 1]; j++) dcdx[COMP[j] * rows + (j - FIRST[sys])] = 1.0;
  return 0;
}

/* ---- the reference: closed-form flows, event by event ---- */
typedef struct {
  int n_ev, sys[MAX_EV];
  double t[MAX_EV], x[NX];
} irma_ref;

static void reference(const double *x0, irma_ref *r) {
  double x[NX], t = 0;
  memcpy(x, x0, sizeof(x));
  int s[6];
  for (int j = 0; j < 6; j++) s[j] = x[COMP[j]] > THR[j];
  r->n_ev = 0;
  for (;;) {
    double b[NX], e[NX];
    synthesis(s, b);
    for (int i = 0; i < NX; i++) e[i] = b[i] / G[i];
    double tn = T_END;
    int jn = -1;
    for (int j = 0; j < 6; j++) { /* x moves monotonically from x toward e */
      const int i = COMP[j];
      const double a = x[i] - e[i], d = THR[j] - e[i];
      if (a * d <= 0 || fabs(d) >= fabs(a)) continue; /* threshold not between x and e */
      const double tc = t + log(a / d) / G[i];
      if (tc < tn) tn = tc, jn = j;
    }
    for (int i = 0; i < NX; i++) x[i] = e[i] + (x[i] - e[i]) * exp(-G[i] * (tn - t));
    t = tn;
    if (jn < 0) break;
    x[COMP[jn]] = THR[jn]; /* on the threshold (round-off) */
    s[jn] = !s[jn];
    int k = 0;
    while (FIRST[k + 1] <= jn) k++;
    if (r->n_ev < MAX_EV) r->t[r->n_ev] = t, r->sys[r->n_ev++] = k;
  }
  memcpy(r->x, x, sizeof(x));
}

int main(void) {
  int fails = 0;
  const double x0[NX] = {0.011, 0.09, 0.04, 0.05, 0.015};
  irma_ref ref;
  reference(x0, &ref);
  printf("IRMA, T = %g: reference %d events (closed-form flows), x(T) =", T_END, ref.n_ev);
  for (int i = 0; i < NX; i++) printf(" %.10f", ref.x[i]);
  printf("\n");
  HD_CHECK(ref.n_ev >= 5, "the reference has %d events", ref.n_ev);

  const int n_modes[NSYS] = {2, 4, 2, 2, 2}, n_switch[NSYS] = {1, 2, 1, 1, 1};
  fesd_model m = {0};
  m.nx = NX, m.nsys = NSYS, m.n_modes = n_modes, m.n_switch = n_switch;
  m.field = field, m.field_jac = field_jac, m.sw = sw, m.sw_jac = sw_jac, m.drift = drift, m.drift_jac = drift_jac;

  const struct {
    fesd_rk_family fam;
    int s, p;
  } M[] = {{FESD_RK_RADAU_IIA, 2, 3}, {FESD_RK_RADAU_IIA, 3, 5}, {FESD_RK_LOBATTO_IIIC, 2, 2},
           {FESD_RK_LOBATTO_IIIC, 3, 4}, {FESD_RK_GAUSS_LEGENDRE, 2, 4}};
  const int NS[] = {50, 100, 200, 400};
  for (size_t q = 0; q < sizeof M / sizeof M[0]; q++) {
    double ns[4], ex[4], et[4];
    int m_fit = 0;
    for (int a = 0; a < 4; a++) {
      fesd_settings set;
      fesd_settings_default(&set);
      set.family = M[q].fam;
      set.stages = M[q].s;
      fesd_integrator *it;
      int st = fesd_create(&it, &m, &set);
      if (!st) st = fesd_set_state(it, 0.0, x0, NULL);
      int n_ev = 0, flags = 0, same = 1, iters = 0;
      double dt = 0;
      for (int k = 0; k < NS[a] && !st; k++) {
        fesd_step_info info;
        st = fesd_step(it, NULL, T_END / NS[a], &info);
        flags |= info.flags, iters += info.newton_iter;
        const fesd_event *ev;
        int ne;
        fesd_last_events(it, &ev, &ne);
        for (int e = 0; e < ne; e++, n_ev++) {
          if (n_ev >= ref.n_ev || ev[e].sys != ref.sys[n_ev] || ev[e].kind != FESD_EVENT_CROSSING) {
            same = 0;
            continue;
          }
          dt = fmax(dt, fabs(ev[e].t - ref.t[n_ev]));
        }
      }
      double x[NX];
      fesd_get_state(it, NULL, x);
      fesd_free(&it);
      double err = 0; /* relative per component: the concentrations differ by a factor of 200 */
      for (int i = 0; i < NX; i++) err = fmax(err, fabs(x[i] - ref.x[i]) / fabs(ref.x[i]));
      printf("  %s s=%d N_sim=%3d: %s, %d events%s, flags 0x%x, %d Newton iterations, x(T) error %.2e (relative), "
             "event times %.2e\n",
             fesd_rk_family_name(M[q].fam), M[q].s, NS[a], fesd_status_name(st), n_ev,
             same && n_ev == ref.n_ev ? " (as the reference)" : " (NOT the reference's)", flags, iters, err, dt);
      HD_CHECK(st == FESD_OK && !(flags & ~FESD_FLAG_COARSE) && same && n_ev == ref.n_ev,
               "%s s=%d N_sim=%d: %s, flags 0x%x, %d events (reference %d)%s", fesd_rk_family_name(M[q].fam),
               M[q].s, NS[a], fesd_status_name(st), flags, n_ev, ref.n_ev, same ? "" : ", other sequence");
      if (err > 1e-12) ns[m_fit] = NS[a], ex[m_fit] = err, et[m_fit++] = dt > 1e-12 ? dt : 1e-12;
      if (!(flags & FESD_FLAG_COARSE)) HD_CHECK(err <= 1e-4, "no step flagged COARSE, x(T) error %.2e", err);
    }
    if (m_fit >= 2) {
      const double px = hd_slope(ns, ex, m_fit);
      printf("  %s s=%d: order of x(T) %.2f, of the event times %.2f (method %d)\n", fesd_rk_family_name(M[q].fam),
             M[q].s, px, hd_slope(ns, et, m_fit), M[q].p);
      HD_CHECK(px >= M[q].p - 0.7, "%s s=%d: order %.2f, method %d", fesd_rk_family_name(M[q].fam), M[q].s, px,
               M[q].p);
    }
  }
  /* as a user would run it: fesd_integrate with a relative tolerance and a small absolute one
   * (x is 1e-2..4): the event log is the reference's, the error follows rtol */
  static hd_run H;
  for (double rtol = 1e-4; rtol >= 1e-10; rtol *= 1e-3) {
    fesd_integrate_info info;
    const int st = hd_integrate_tol(&m, 3, rtol, 0.0, x0, T_END, &H, &info), n_ev = H.n_ev;
    const fesd_event *ev = H.ev;
    const double *x = H.x_end;
    int same = 1;
    double dt = 0, err = 0;
    for (int e = 0; e < n_ev; e++) {
      same = same && e < ref.n_ev && ev[e].sys == ref.sys[e] && ev[e].kind == FESD_EVENT_CROSSING;
      if (same) dt = fmax(dt, fabs(ev[e].t - ref.t[e]));
    }
    for (int i = 0; i < NX; i++) err = fmax(err, fabs(x[i] - ref.x[i]) / fabs(ref.x[i]));
    printf("  fesd_integrate Radau IIA s=3, rtol %.0e: %s, %d steps (%d rejected), %d events%s, x(T) error %.2e "
           "(relative), event times %.2e\n",
           rtol, fesd_status_name(st), info.steps, info.rejected, n_ev,
           same && n_ev == ref.n_ev ? " (as the reference)" : " (NOT the reference's)", err, dt);
    HD_CHECK(st == FESD_OK && same && n_ev == ref.n_ev && err <= 10 * rtol,
             "fesd_integrate rtol %.0e: %s, %d events (reference %d), x(T) error %.2e", rtol, fesd_status_name(st),
             n_ev, ref.n_ev, err);
  }
  printf("%d failures\n", fails);
  return fails != 0;
}
