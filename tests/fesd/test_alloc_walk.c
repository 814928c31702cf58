/* Every allocation failure is reported, never a wrong FESD_OK (malloc, calloc and realloc
 * are interposed by this program; the library and SuiteSparse resolve to them).
 *  1. fesd_create: allocation k = 0, 1, 2, ... fails until create runs through without a
 *     failure; each failing create returns FESD_ERR_NOMEM with *it == NULL and frees every
 *     block it allocated.
 *  2. A full integration after a clean create: allocation k (counted from set_state on)
 *     fails; the step that meets it returns FESD_ERR_NOMEM (not FESD_OK, not
 *     FESD_ERR_STEP_FAILED) with the state unchanged, and its retry without the failure
 *     continues; the end state equals the one of a clean run bit for bit. Some failures
 *     inside SuiteSparse are absorbed by it (KLU's shrinking realloc of the factors, UMFPACK
 *     retrying with a smaller work area): the step then succeeds, with the same end state.
 * Models: three subsystems with switching functions (default sign matrices), one subsystem
 * with a user sign matrix (dense model API, finite-difference Jacobians), and the friction
 * chain of src/problems with n = 8 (sparse model API, 258 unknowns per step: AUTO picks KLU);
 * backends DENSE, KLU, UMFPACK and AUTO. Skipped (exit 77) under AddressSanitizer, which
 * owns malloc itself. Needs OPENBLAS_NUM_THREADS=1 (set by meson): threaded OpenBLAS exits
 * the process when its own buffer allocation fails. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fesd.h"
#include "../check.h"
#include "problems/friction_chain.h"

#include "../alloc_hook.h"

#if !ALLOC_HOOK_ACTIVE
int main(void) {
  printf("skipped under AddressSanitizer\n");
  return 77;
}
#else
static int fails = 0;
#define CHECK FESD_TEST_CHECK

/* ---- three subsystems, default sign matrices: x0 crosses 0, x1 crosses 0, x0 crosses 0.5
 *      and x0 + x1 crosses 0.2 (every field pushes both states up) ---- */
static int m3_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)x, (void)u, (void)user;
  if (sys == 0) f[0] = mode == 0 ? 1.0 : 2.0, f[1] = 0.0;
  else if (sys == 1) f[0] = 0.0, f[1] = 0.5 + 0.25 * mode;
  else f[0] = mode == 0 ? 0.1 : 0.2, f[1] = mode == 0 ? 0.1 : 0.3;
  return 0;
}
static int m3_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)u, (void)user;
  if (sys == 0) c[0] = x[0];
  else if (sys == 1) c[0] = x[1], c[1] = x[0] - 0.5;
  else c[0] = x[0] + x[1] - 0.2;
  return 0;
}
static const int m3_modes[3] = {2, 4, 2}, m3_switch[3] = {1, 2, 1};
static const double m3_x0[2] = {-0.5, -0.3};

/* ---- a user sign matrix: 3 modes of 2 switching functions c = (x, x + 1); x' = 3, 2, 1
 *      in x < -1, -1 < x < 0, x > 0 ---- */
static int us_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)sys, (void)x, (void)u, (void)user;
  f[0] = 1.0 + mode;
  return 0;
}
static int us_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)sys, (void)u, (void)user;
  c[0] = x[0];
  c[1] = x[0] + 1.0;
  return 0;
}
static const signed char us_S[6] = {1, 1, -1, 1, -1, -1};
static const signed char *const us_sign[1] = {us_S};
static const int us_modes[1] = {3}, us_switch[1] = {2};
static const double us_x0[1] = {-1.5};

typedef struct {
  const char *name;
  fesd_model model;
  const double *x0;
  double T;
  int nsim;
} walk_model;

#define MAX_NX 16

typedef struct {
  int st;
  double t, x[MAX_NX];
} outcome;

static fesd_settings settings_for(int backend) {
  fesd_settings s;
  fesd_settings_default(&s);
  s.ncp.backend = (fesd_ncp_backend)backend;
  return s;
}

/* Integrate m from x0 on a clean integrator; allocation number fail_at (counted from
 * set_state on; -1: none) fails once. A failed step is checked and retried. Returns the
 * number of allocations made (to end the walk). */
static long integrate(const walk_model *W, int backend, long fail_at, int *failures, outcome *out) {
  fesd_settings s = settings_for(backend);
  fesd_integrator *it = NULL;
  long live0 = g_live;
  int st = fesd_create(&it, &W->model, &s);
  out->st = st;
  if (st) return 0;
  const int nx = W->model.nx;
  g_count = 0;
  g_fail_at = fail_at;
  st = fesd_set_state(it, 0.0, W->x0, NULL);
  if (st == FESD_ERR_NOMEM) { /* not expected (set_state allocates nothing), but allowed */
    ++*failures;
    g_fail_at = -1;
    st = fesd_set_state(it, 0.0, W->x0, NULL);
  }
  for (int k = 0; k < W->nsim && !st; k++) {
    double t0, x0[MAX_NX], t1, x1[MAX_NX];
    fesd_get_state(it, &t0, x0);
    fesd_step_info info;
    st = fesd_step(it, NULL, W->T / W->nsim, &info);
    if (st == FESD_OK) continue;
    fesd_get_state(it, &t1, x1);
    CHECK(st == FESD_ERR_NOMEM && info.status == st, "%s/%s: allocation %ld failed: step %d gave %s", W->name,
          fesd_ncp_backend_name(backend), fail_at, k, fesd_status_name(st));
    CHECK(t1 == t0 && !memcmp(x0, x1, (size_t)nx * sizeof(double)), "%s/%s: allocation %ld: state changed",
          W->name, fesd_ncp_backend_name(backend), fail_at);
    ++*failures;
    g_fail_at = -1; /* the failure is gone: retry the same step */
    st = fesd_step(it, NULL, W->T / W->nsim, &info);
  }
  g_fail_at = -1;
  long made = g_count;
  out->st = st;
  fesd_get_state(it, &out->t, out->x);
  fesd_free(&it);
  CHECK(g_live == live0, "%s/%s: %ld blocks leaked by an integration (allocation %ld failed)", W->name,
        fesd_ncp_backend_name(backend), g_live - live0, fail_at);
  g_live = live0;
  return made;
}

/* Part 1: fail allocation k of fesd_create for k = 0, 1, ... Returns the number of walked points. */
static long walk_create(const walk_model *W, int backend) {
  fesd_settings s = settings_for(backend);
  long k;
  for (k = 0;; k++) {
    long live0 = g_live;
    fesd_integrator *it = (fesd_integrator *)&s; /* must become NULL on failure */
    g_count = 0;
    g_fail_at = k;
    int st = fesd_create(&it, &W->model, &s);
    g_fail_at = -1;
    const long made = g_count;
    if (made <= k) { /* create needed fewer than k + 1 allocations: it ran through */
      CHECK(st == FESD_OK && it, "%s/%s: create without a failure: %s", W->name, fesd_ncp_backend_name(backend),
            fesd_status_name(st));
      fesd_free(&it);
      CHECK(g_live == live0, "%s/%s: fesd_free left %ld blocks", W->name, fesd_ncp_backend_name(backend),
            g_live - live0);
      g_live = live0;
      return k;
    }
    CHECK(st == FESD_ERR_NOMEM && it == NULL, "%s/%s: allocation %ld of create failed: %s, it %s", W->name,
          fesd_ncp_backend_name(backend), k, fesd_status_name(st), it ? "set" : "NULL");
    if (st == FESD_OK) fesd_free(&it);
    CHECK(g_live == live0, "%s/%s: allocation %ld of create failed: %ld blocks leaked", W->name,
          fesd_ncp_backend_name(backend), k, g_live - live0);
    g_live = live0;
  }
}

/* Part 2: fail allocation k of a full integration, k = 0, 1, ... */
static void walk_steps(const walk_model *W, int backend, long *points, int *failed_steps, int *recovered) {
  outcome ref, o;
  int none = 0;
  integrate(W, backend, -1, &none, &ref);
  CHECK(ref.st == FESD_OK && none == 0, "%s/%s: clean run: %s", W->name, fesd_ncp_backend_name(backend),
        fesd_status_name(ref.st));
  *failed_steps = *recovered = 0;
  for (long k = 0;; k++) {
    int nf = 0;
    long made = integrate(W, backend, k, &nf, &o);
    *failed_steps += nf;
    *recovered += nf == 0 && made > k; /* SuiteSparse went on without the block */
    if (made <= k) {
      *points = k;
      return;
    }
    int same = o.st == ref.st && o.t == ref.t && !memcmp(o.x, ref.x, (size_t)W->model.nx * sizeof(double));
    CHECK(same, "%s/%s: allocation %ld failed: end %s, x0(T) %.17g (clean %.17g)", W->name,
          fesd_ncp_backend_name(backend), k, fesd_status_name(o.st), o.x[0], ref.x[0]);
  }
}

int main(void) {
  printf("(stdout buffer allocated before counting)\n");
  fesd_friction_chain fc;
  if (fesd_friction_chain_init(&fc, 8, 5.0)) return 1;
  const walk_model models[3] = {
      {"three-subsystems",
       {.nx = 2, .nsys = 3, .n_modes = m3_modes, .n_switch = m3_switch, .field = m3_field, .sw = m3_sw},
       m3_x0, 1.0, 10},
      {"user-sign-matrix",
       {.nx = 1, .nsys = 1, .n_modes = us_modes, .n_switch = us_switch, .sign = us_sign, .field = us_field,
        .sw = us_sw},
       us_x0, 1.0, 10},
      {"friction-chain-8", fc.model, fc.x0, 2.0, 20}};
  const int backends[4] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_KLU, FESD_NCP_BACKEND_UMFPACK,
                           FESD_NCP_BACKEND_AUTO};
  for (int m = 0; m < 3; m++)
    for (int b = 0; b < 4; b++) {
      const walk_model *W = &models[m];
      long nc = walk_create(W, backends[b]), ns = 0;
      int nfs = 0, rec = 0;
      walk_steps(W, backends[b], &ns, &nfs, &rec);
      printf("%-16s %-7s create: %3ld allocation points, each FESD_ERR_NOMEM; %2d steps: %4ld points, %4d "
             "steps FESD_ERR_NOMEM and retried, %2d recovered inside SuiteSparse\n",
             W->name, fesd_ncp_backend_name(backends[b]), nc, W->nsim, ns, nfs, rec);
    }
  fesd_friction_chain_free(&fc);
  printf("(every failing create: *it == NULL, no block leaked; every integration: state unchanged by the "
         "failed step, end state identical to a clean run, no block leaked)\n%d failures\n", fails);
  return fails != 0;
}
#endif
