/* Events of a subsystem with many modes (fesd_event lists the active modes, no 32-mode
 * limit). One subsystem of M modes given by indicators g_i(x) = (x - c_i)^2: mode i is
 * active in the cell of the line nearest to its center c_i. The centers sit at the integers
 * q = 0..M-1 in a scrambled order (mode p(q) = (37 q + 5) mod M owns cell q, so consecutive
 * cells hold modes far apart, most of them >= 32), the boundaries at q + 1/2. Field of mode
 * i: x' = v_i in [1, 1.5]. From x0 = 0 the trajectory crosses the 30 boundaries 1/2 ..
 * 29 + 1/2; with M = 64 the mode of cell 31 then points back (v = -1), so it enters sliding
 * on 30 + 1/2 (active set {p(30), p(31)}); the same with M = 70 (no limit on the number of
 * modes of a subsystem).
 * Reference, independent of the integrator: x is piecewise linear, so the crossing times
 * are sums of cell widths over speeds. Every event must be reported with its time (1e-10),
 * kind and active modes before and after. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fesd.h"
#include "../check.h"

static int fails = 0;
#define CHECK FESD_TEST_CHECK

#define MAXM 128
#define NCROSS 30

typedef struct {
  int M;
  int owner[MAXM]; /* mode of cell q */
  double center[MAXM], v[MAXM]; /* per mode */
} chain;

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)x, (void)u;
  f[0] = ((const chain *)user)->v[mode];
  return 0;
}
static int field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)mode, (void)x, (void)u, (void)Ju, (void)user;
  J[0] = 0.0;
  return 0;
}
static int ind(int sys, double t, const double *x, const double *u, double *g, void *user) {
  (void)sys, (void)u;
  const chain *c = user;
  for (int i = 0; i < c->M; i++) g[i] = (x[0] - c->center[i]) * (x[0] - c->center[i]);
  return 0;
}
static int ind_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)u, (void)Ju;
  const chain *c = user;
  for (int i = 0; i < c->M; i++) J[i] = 2.0 * (x[0] - c->center[i]);
  return 0;
}

/* slide: the mode of cell NCROSS + 1 points back (sliding entry on NCROSS + 1/2) */
static void build(chain *c, int M, int slide) {
  c->M = M;
  for (int q = 0; q < M; q++) {
    int i = (37 * q + 5) % M;
    c->owner[q] = i;
    c->center[i] = q;
    c->v[i] = slide && q == NCROSS + 1 ? -1.0 : 1.0 + 0.125 * ((7 * i) % 5);
  }
}

static void run(int M, int slide) {
  chain c;
  build(&c, M, slide);
  /* reference: boundary q + 1/2 is reached at tb[q]; the run ends 1 after the sliding entry,
   * or at the center of cell NCROSS */
  double tb[NCROSS + 1], t = 0.5 / c.v[c.owner[0]];
  for (int q = 0; q <= NCROSS; q++) {
    tb[q] = t;
    t += 1.0 / c.v[c.owner[q + 1]];
  }
  const double T = slide ? tb[NCROSS] + 1.0 : tb[NCROSS - 1] + 0.5 / c.v[c.owner[NCROSS]];
  const double xe = slide ? NCROSS + 0.5 : NCROSS, h = 0.25; /* cells take >= 2/3: one switch per step */
  const int nsim = (int)ceil(T / h), n_expect = NCROSS + slide;
  const int n_modes[1] = {M};
  fesd_model m = {.nx = 1, .nsys = 1, .n_modes = n_modes, .field = field, .field_jac = field_jac, .sw = ind,
                  .sw_jac = ind_jac, .user = &c};
  fesd_integrator *it;
  int st = fesd_create(&it, &m, NULL);
  CHECK(st == FESD_OK, "M = %d: create %s", M, fesd_status_name(st));
  if (st) return;
  const double x0 = 0.0;
  st = fesd_set_state(it, 0.0, &x0, NULL);
  int n_ev = 0, n_cross = 0, n_entry = 0, high = 0;
  double worst = 0;
  for (int k = 0; k < nsim && !st; k++) {
    st = fesd_step(it, NULL, T / nsim, NULL);
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    for (int e = 0; e < ne; e++, n_ev++) {
      const fesd_event *E = &ev[e];
      if (n_ev >= n_expect) {
        CHECK(0, "M = %d: extra event at t = %.15g", M, E->t);
        continue;
      }
      const int q = n_ev, a = c.owner[q], b = c.owner[q + 1], entry = q == NCROSS;
      const int lo = a < b ? a : b, hi = a < b ? b : a;
      int ok = E->sys == 0 && E->kind == (entry ? FESD_EVENT_SLIDING_ENTRY : FESD_EVENT_CROSSING) &&
               E->n_before == 1 && E->before[0] == a && fabs(E->t - tb[q]) <= 1e-10;
      ok = ok && (entry ? E->n_after == 2 && E->after[0] == lo && E->after[1] == hi
                        : E->n_after == 1 && E->after[0] == b);
      CHECK(ok,
            "M = %d: event %d: t = %.15g (exact %.15g), kind %d, modes %d of %d -> %d of %d (expected %d -> %d%s)", M, q, E->t, tb[q], (int)E->kind, E->n_before ? E->before[0] : -1, E->n_before,
            E->n_after ? E->after[0] : -1, E->n_after, a, b, entry ? " + sliding" : "");
      n_cross += ok && !entry;
      n_entry += ok && entry;
      high += ok && (a >= 32 || b >= 32);
      worst = fmax(worst, fabs(E->t - tb[q]));
    }
  }
  double xT;
  fesd_get_state(it, NULL, &xT);
  /* the solver's tolerance is relative (newton_tol 1e-12 of |x| ~ 30) */
  CHECK(st == FESD_OK && n_ev == n_expect && fabs(xT - xe) <= 1e-12 * fabs(xe),
        "M = %d: %s, %d events (expected %d), x(T) = %.15g (exact %g)", M, fesd_status_name(st), n_ev, n_expect, xT,
        xe);
  printf("M = %3d modes: %2d of %d crossings", M, n_cross, NCROSS);
  if (slide) printf(" and %d of 1 sliding entry", n_entry);
  printf(" reported with the right time, kind and modes (%d of them with a mode >= 32); max event time error "
         "%.1e; x(T) = %.15g (exact %g)\n", high, worst, xT, xe);
  fesd_free(&it);
}

int main(void) {
  run(64, 1);
  run(70, 1);
  printf("%d failures\n", fails);
  return fails != 0;
}
