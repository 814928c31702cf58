/* Shared helpers of the property tests (tests/prop): a libfesd model for a pwa_sys, a run of
 * N_sim equal steps through the public API collecting events, flags, end state and
 * sensitivities, and the comparison of event sequences with the reference. */
#ifndef PROP_UTIL_H
#define PROP_UTIL_H
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fesd.h"
#include "../check.h"
#include "pwa_ref.h"

#define PR_MAX_EV 512

#include <stdint.h>
#include <stdlib.h>
/* Offset added to every seed of the property tests (environment PROP_SEED_OFF; default 0, the
 * committed seeds): campaigns with other draws without editing the tests. */
static inline uint64_t pr_seed_off(void) {
  const char *s = getenv("PROP_SEED_OFF");
  return s ? (uint64_t)strtoull(s, NULL, 10) : 0;
}

typedef struct {
  int n_modes[PWA_MAX_K], n_switch[PWA_MAX_K];
  fesd_model m;
} pr_model;

/* jac = 1: exact Jacobian callbacks; 0: the library's finite differences */
static inline void pr_model_init(pr_model *pm, const pwa_sys *S, int jac) {
  memset(pm, 0, sizeof(*pm));
  for (int k = 0; k < S->K; k++) pm->n_modes[k] = 2, pm->n_switch[k] = 1;
  pm->m.nx = S->nx;
  pm->m.nu = S->nu;
  pm->m.nsys = S->K;
  pm->m.n_modes = pm->n_modes;
  pm->m.n_switch = pm->n_switch;
  pm->m.field = pwa_cb_field;
  pm->m.sw = pwa_cb_switch;
  pm->m.field_jac = jac ? pwa_cb_field_jac : NULL;
  pm->m.sw_jac = jac ? pwa_cb_switch_jac : NULL;
  pm->m.user = (void *)S;
}

typedef struct {
  int status;      /* FESD_OK or the failing step's status */
  int fail_step;   /* index of the failing step, -1 if none */
  int flags;       /* OR of every step's fesd_step_info.flags */
  int n_ev;
  double ev_t[PR_MAX_EV];
  int ev_sys[PR_MAX_EV], ev_kind[PR_MAX_EV];
  double x[PWA_MAX_NX];
  double Sx[PWA_MAX_NX * PWA_MAX_NX], Su[PWA_MAX_NX * PWA_MAX_NU]; /* column-major */
  int splits, substeps, newton_iter;
  double hmax; /* longest element of the accepted steps */
} pr_run;

/* Appends the events of the integrator's last step to r (up to PR_MAX_EV). */
static inline void pr_record_events(const fesd_integrator *it, pr_run *r) {
  const fesd_event *ev;
  int ne;
  fesd_last_events(it, &ev, &ne);
  for (int e = 0; e < ne && r->n_ev < PR_MAX_EV; e++, r->n_ev++) {
    r->ev_t[r->n_ev] = ev[e].t;
    r->ev_sys[r->n_ev] = ev[e].sys;
    r->ev_kind[r->n_ev] = (int)ev[e].kind;
  }
}

/* N_sim steps of length T/N_sim from (0, x0) with constant u, on an existing integrator
 * (fesd_set_state restarts it: no warm start survives). */
static inline int pr_run_on(fesd_integrator *it, const fesd_model *m, int sens, const double *x0, const double *u,
                            double T, int nsim, pr_run *r) {
  memset(r, 0, sizeof(*r));
  r->fail_step = -1;
  int st = fesd_set_state(it, 0, x0, u);
  for (int k = 0; k < nsim && !st; k++) {
    fesd_step_info info;
    st = fesd_step(it, u, T / nsim, &info);
    if (st) {
      r->fail_step = k;
      break;
    }
    r->flags |= info.flags;
    r->splits += info.splits, r->substeps += info.substeps, r->newton_iter += info.newton_iter;
    fesd_step_data d;
    fesd_last_step_data(it, &d);
    for (int e = 0; e < d.n_elements; e++) r->hmax = fmax(r->hmax, d.h[e]);
    pr_record_events(it, r);
  }
  fesd_get_state(it, NULL, r->x);
  if (sens) fesd_get_sensitivities(it, r->Sx, m->nu > 0 ? r->Su : NULL);
  return r->status = st;
}

/* ... on a new integrator */
static inline int pr_integrate(const fesd_model *m, const fesd_settings *set, const double *x0, const double *u,
                               double T, int nsim, pr_run *r) {
  fesd_integrator *it;
  int st = fesd_create(&it, m, set);
  if (st) {
    memset(r, 0, sizeof(*r));
    r->fail_step = -1;
    return r->status = st;
  }
  st = pr_run_on(it, m, set->sensitivities, x0, u, T, nsim, r);
  fesd_free(&it);
  return st;
}

/* Same (sys, kind) sequence as the reference; *dt: largest event time difference. */
static inline int pr_same_events(const pr_run *r, const pwa_result *ref, double *dt) {
  *dt = 0;
  if (r->n_ev != ref->n_ev) return 0;
  for (int e = 0; e < r->n_ev; e++) {
    if (r->ev_sys[e] != ref->ev[e].sys || r->ev_kind[e] != ref->ev[e].kind) return 0;
    *dt = fmax(*dt, fabs(r->ev_t[e] - ref->ev[e].t));
  }
  return 1;
}

/* Same (sys, kind) sequence for two runs. */
static inline int pr_same_run_events(const pr_run *a, const pr_run *b) {
  if (a->n_ev != b->n_ev) return 0;
  for (int e = 0; e < a->n_ev; e++)
    if (a->ev_sys[e] != b->ev_sys[e] || a->ev_kind[e] != b->ev_kind[e]) return 0;
  return 1;
}

static inline void pr_print_events_ref(const pwa_result *ref) {
  for (int e = 0; e < ref->n_ev; e++)
    printf("  ref  t=%.15f sys %d kind %d (%d -> %d)\n", ref->ev[e].t, ref->ev[e].sys, ref->ev[e].kind,
           ref->ev[e].before, ref->ev[e].after);
}
static inline void pr_print_events_run(const pr_run *r) {
  for (int e = 0; e < r->n_ev; e++) printf("  fesd t=%.15f sys %d kind %d\n", r->ev_t[e], r->ev_sys[e], r->ev_kind[e]);
}

/* A kind of random system: generator settings and what its reference trajectory must show. */
typedef struct {
  const char *name;
  int affine, K_lo, K_hi, nx_lo, nx_hi, nu_lo, nu_hi;
  double slide_prob, a_scale, rot;
  int min_ev;
  int entry;  /* 1: at least one sliding entry; -1: none; 0: either */
  int exit;   /* 1: at least one sliding exit; -1: none; 0: either */
  int multi;  /* 1: a surface reached while another subsystem slides; -1: never; 0: either */
} pr_category;

static inline int pr_want(int rule, int count) { return rule == 0 || (rule > 0 ? count > 0 : count == 0); }

/* Draw systems, x0 and u until the reference over [0, T] is regular and shows the category;
 * screening with a coarse RK4 step in sliding (8 times faster), then the reference with the
 * default options (sens: with sensitivities). Returns the number of draws, 0 when max_draws
 * were not enough. */
static inline int pr_draw(pwa_rng *rng, const pr_category *c, double T, int sens, int max_draws, pwa_sys *S,
                          double *x0, double *u, pwa_result *ref) {
  for (int d = 1; d <= max_draws; d++) {
    pwa_gen g = {.nx = pwa_int(rng, c->nx_lo, c->nx_hi), .K = pwa_int(rng, c->K_lo, c->K_hi),
                 .nu = pwa_int(rng, c->nu_lo, c->nu_hi), .affine = c->affine, .a_scale = c->a_scale,
                 .rot = c->rot, .slide_prob = c->slide_prob, .drift = 0.5, .beta_lo = 1.5, .beta_hi = 3.5};
    pwa_random_system(S, rng, &g);
    pwa_random_x0(S, rng, x0);
    for (int j = 0; j < S->nu; j++) u[j] = pwa_uniform(rng, -0.3, 0.3);
    pwa_opts o;
    pwa_opts_default(&o, T);
    o.rk_h = 2e-3;
    if (pwa_reference(S, x0, u, &o, ref) || ref->n_ev < c->min_ev || !pr_want(c->entry, ref->n_entry) ||
        !pr_want(c->exit, ref->n_exit) || !pr_want(c->multi, ref->n_entry_multi + ref->n_cross_multi))
      continue;
    const int n_ev = ref->n_ev;
    pwa_opts_default(&o, T);
    o.sens = sens;
    if (pwa_reference(S, x0, u, &o, ref) == 0 && ref->n_ev == n_ev) return d;
  }
  return 0;
}

/* The system as C initializers, for reproducers. */
static inline void pr_print_system(const pwa_sys *S, const double *x0, const double *u) {
  printf("  system nx=%d K=%d nu=%d affine=%d\n", S->nx, S->K, S->nu, S->affine);
  for (int k = 0; k < S->K; k++) {
    printf("   c_%d = [", k);
    for (int q = 0; q < S->nx; q++) printf("%s%.17g", q ? ", " : "", S->a[k][q]);
    printf("] x + %.17g\n", S->b[k]);
    for (int i = 0; i < 2; i++) {
      printf("   f_%d%d: d = [", k, i);
      for (int q = 0; q < S->nx; q++) printf("%s%.17g", q ? ", " : "", S->d[k][i][q]);
      printf("]");
      if (S->affine) {
        printf(" A = [");
        for (int q = 0; q < S->nx; q++)
          for (int c = 0; c < S->nx; c++) printf("%s%.17g", q || c ? ", " : "", S->A[k][i][q][c]);
        printf("]");
      }
      if (S->nu) {
        printf(" B = [");
        for (int q = 0; q < S->nx; q++)
          for (int c = 0; c < S->nu; c++) printf("%s%.17g", q || c ? ", " : "", S->B[k][i][q][c]);
        printf("]");
      }
      printf("\n");
    }
  }
  printf("   x0 = [");
  for (int q = 0; q < S->nx; q++) printf("%s%.17g", q ? ", " : "", x0[q]);
  printf("]");
  if (S->nu) {
    printf(" u = [");
    for (int c = 0; c < S->nu; c++) printf("%s%.17g", c ? ", " : "", u[c]);
    printf("]");
  }
  printf("\n");
}

#endif
