/* Hundreds of switches in one step, every one reported. K = 300 decoupled subsystems
 * x_k' = 1 where x_k < 0 and 2 where x_k > 0 (sparse model), x_k(0) = -a_k with the a_k
 * spread over (0.05, 0.95) by the golden ratio: subsystem k crosses once, at t = a_k, and
 * x_k(1) = 2 (1 - a_k). One fesd_step of length 1 (Radau IIA s = 1, 2, Gauss-Legendre s = 2)
 * and one error-controlled fesd_integrate to t = 1 (Radau s = 2, rtol 1e-6) must report all
 * 300 crossings, each once, in time order, at the exact times. The event store used to hold
 * 256 events per step and dropped the rest silently (FESD_OK with 44 crossings missing). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fesd.h"
#include "../check.h"

#define K 300

static int field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)t, (void)x, (void)u, (void)user;
  f[0] = mode == 0 ? 2.0 : 1.0; /* mode 0: c = x_k > 0 */
  return 0;
}
static int field_jac(int sys, int mode, double t, const double *x, const double *u, double *dfdx,
                     double *dfdu, void *user) {
  (void)sys, (void)mode, (void)t, (void)x, (void)u, (void)dfdx, (void)dfdu, (void)user;
  return 0; /* constant fields: no Jacobian entries */
}
static int sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)t, (void)u, (void)user;
  c[0] = x[sys];
  return 0;
}
static int sw_jac(int sys, double t, const double *x, const double *u, double *dcdx, double *dcdu, void *user) {
  (void)sys, (void)t, (void)x, (void)u, (void)dcdu, (void)user;
  dcdx[0] = 1;
  return 0;
}

/* Checks a list of events against the crossings; returns the failures. */
static int check_events(const char *what, const fesd_event *ev, int ne, const double *a) {
  int fails = 0, seen[K] = {0}, order = 1, kind = 1;
  double terr = 0;
  for (int e = 0; e < ne; e++) {
    if (ev[e].sys < 0 || ev[e].sys >= K) {
      kind = 0;
      continue;
    }
    seen[ev[e].sys]++;
    terr = fmax(terr, fabs(ev[e].t - a[ev[e].sys]));
    kind &= ev[e].kind == FESD_EVENT_CROSSING && ev[e].n_before == 1 && ev[e].before[0] == 1 &&
            ev[e].n_after == 1 && ev[e].after[0] == 0;
    if (e > 0 && ev[e].t < ev[e - 1].t) order = 0;
  }
  int once = 0;
  for (int k = 0; k < K; k++) once += seen[k] == 1;
  printf("%s: %d events, %d subsystems once, time error %.1e, in order %d, kinds %d\n", what, ne, once, terr,
         order, kind);
  FESD_TEST_CHECK(ne == K && once == K, "%s: %d events, %d of %d subsystems exactly once", what, ne, once, K);
  FESD_TEST_CHECK(terr <= 1e-12 && order && kind, "%s: time error %.1e, order %d, kinds %d", what, terr, order,
                  kind);
  return fails;
}

int main(void) {
  int fails = 0;
  static int nm[K], ns[K], rows[K];
  static fesd_sparsity sp[K];
  static const int zero = 0;
  double x0[K], a[K], x[K];
  for (int k = 0; k < K; k++) {
    nm[k] = 2;
    ns[k] = 1;
    rows[k] = k;
    sp[k] = (fesd_sparsity){.n_rows = 1, .rows = &rows[k], .jac_row = &zero, .jac_col = &zero,
                            .sw_nnz = 1, .sw_row = &zero, .sw_col = &rows[k]};
    a[k] = 0.05 + 0.9 * fmod(0.6180339887498949 * (k + 1), 1.0);
    x0[k] = -a[k];
  }
  fesd_model m = {.nx = K, .nsys = K, .n_modes = nm, .n_switch = ns, .field = field, .field_jac = field_jac,
                  .sw = sw, .sw_jac = sw_jac, .sparsity = sp};
  const struct {
    fesd_rk_family fam;
    int s;
    const char *name;
  } runs[] = {{FESD_RK_RADAU_IIA, 1, "Radau s=1"}, {FESD_RK_RADAU_IIA, 2, "Radau s=2"}, {FESD_RK_GAUSS_LEGENDRE, 2, "Gauss s=2"}};
  for (size_t r = 0; r < sizeof runs / sizeof runs[0]; r++) {
    fesd_settings set;
    fesd_settings_default(&set);
    set.family = runs[r].fam;
    set.stages = runs[r].s;
    fesd_integrator *it = NULL;
    int st = fesd_create(&it, &m, &set);
    if (!st) st = fesd_set_state(it, 0.0, x0, NULL);
    fesd_step_info info;
    if (!st) st = fesd_step(it, NULL, 1.0, &info);
    FESD_TEST_CHECK(st == FESD_OK, "%s: %s", runs[r].name, fesd_status_name(st));
    if (st) {
      fesd_free(&it);
      continue;
    }
    const fesd_event *ev;
    int ne = 0;
    fesd_last_events(it, &ev, &ne);
    fails += check_events(runs[r].name, ev, ne, a);
    fesd_stats stats;
    fesd_get_stats(it, &stats);
    FESD_TEST_CHECK(stats.events == K, "%s: stats count %d events", runs[r].name, stats.events);
    double t, xerr = 0;
    fesd_get_state(it, &t, x);
    for (int k = 0; k < K; k++) xerr = fmax(xerr, fabs(x[k] - 2 * (1 - a[k])));
    FESD_TEST_CHECK(xerr <= 1e-12, "%s: x(1) error %.1e", runs[r].name, xerr);
    printf("  x(1) error %.1e, %d Newton iterations, %d solves, %d sub-steps\n", xerr, info.newton_iter,
           info.solves, info.substeps);
    fesd_free(&it);
  }
  /* error-controlled: the event log */
  fesd_settings set;
  fesd_settings_default(&set);
  fesd_integrator *it = NULL;
  fesd_tolerances tol;
  fesd_tolerances_default(&tol);
  tol.rtol = 1e-6;
  tol.atol = 1e-9;
  int st = fesd_create(&it, &m, &set);
  if (!st) st = fesd_set_tolerances(it, &tol);
  if (!st) st = fesd_set_state(it, 0.0, x0, NULL);
  fesd_integrate_info info;
  if (!st) st = fesd_integrate(it, NULL, 1.0, &info);
  FESD_TEST_CHECK(st == FESD_OK, "fesd_integrate: %s", fesd_status_name(st));
  if (!st) {
    const fesd_event *ev;
    int ne = 0;
    fesd_event_log(it, &ev, &ne);
    fails += check_events("fesd_integrate (event log)", ev, ne, a);
    FESD_TEST_CHECK(info.events == K, "fesd_integrate: info counts %d events", info.events);
    double t, xerr = 0;
    fesd_get_state(it, &t, x);
    for (int k = 0; k < K; k++) xerr = fmax(xerr, fabs(x[k] - 2 * (1 - a[k])));
    FESD_TEST_CHECK(t == 1.0 && xerr <= 1e-10, "fesd_integrate: t %.17g, x(1) error %.1e", t, xerr);
    printf("  t = %g, x(1) error %.1e, %d steps\n", t, xerr, info.steps);
  }
  fesd_free(&it);
  printf("%s\n", fails ? "FAILED" : "ok");
  return fails != 0;
}
