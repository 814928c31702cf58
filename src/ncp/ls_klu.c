/* KLU backend (square sparse LU). klu_analyze once per pattern, klu_factor the
 * first time, klu_refactor afterwards (same pivot order, no allocation). A small
 * pivot ratio after a refactor (klu_rcond, then the condition estimate) or a
 * failed refactor triggers a full klu_factor that chooses new pivots.
 *
 * Pattern cache: the integrator alternates between a few row selections (the active
 * sets before and after a switch, the switch step's own), and every change of selection
 * used to cost a symbolic analysis and a full factorization (measured: 20 % of the
 * oscillator's time with Radau s = 5). The last KLU_CACHE patterns keep their symbolic
 * and numeric objects; a pattern seen again is recognised by comparing it entry by entry
 * (O(nnz), far cheaper than the analysis) and refactorizes in place. 8 slots hold every
 * pattern of the reference problems (ocp-dynamics, Radau s = 5, visits 5 or 6; a second
 * integration then allocates nothing, tests/fesd/test_alloc.c); memory: up to 8 LU
 * factors of the step Jacobian. */
#include "ncp/linsolve.h"

#include "fesd_ncp.h"

#include <float.h>
#include <amd.h>
#include <klu.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define KLU_CACHE 8
/* Reciprocal pivot growth below which a refactor is redone with new pivots (fresh
 * factorizations of the FESD Jacobians show 1e-3..1e-1). */
#define KLU_RGROWTH_MIN 1e-6

typedef struct {
  klu_symbolic *symbolic;
  klu_numeric *numeric;
  int *p, *idx; /* copy of the pattern (KLU's API is not const-qualified) */
  int m, nz, cap; /* m < 0: empty slot; cap: entries idx can hold */
  unsigned long used;
} klu_slot;

typedef struct {
  fesd__ls base;
  klu_common common;
  klu_slot slot[KLU_CACHE];
  klu_slot *cur; /* the pattern of the last analyze (NULL after a failed one) */
  unsigned long clock;
  double rcond_min;
  int order_nomem; /* the ordering ran out of memory in the last analysis */
} klu_ls;

/* Fill-reducing order of each diagonal block: AMD with rows and columns of more than
 * KLU_DENSE sqrt(n) entries treated as dense (ordered last). Step systems have such rows
 * and columns (a switch boundary's cross-complementarity row, an element length's column)
 * with about as many entries as one element has unknowns: below AMD's default threshold
 * (10 sqrt(n)), ordered early they fill whole element blocks (measured: friction chain
 * n = 64, 24 switches in a step: factorization time grew like the square of the size). */
#define KLU_DENSE 1.0
static int order_block(int n, int *Ap, int *Ai, int *Perm, klu_common *c) {
  double control[AMD_CONTROL], info[AMD_INFO];
  amd_defaults(control);
  control[AMD_DENSE] = KLU_DENSE;
  int st = amd_order(n, Ap, Ai, Perm, control, info);
  if (st == AMD_OUT_OF_MEMORY) *(int *)c->user_data = 1; /* reported as FESD_ERR_NOMEM */
  if (st != AMD_OK && st != AMD_OK_BUT_JUMBLED) return 0;
  return (int)(info[AMD_LNZ] + n > 1 ? info[AMD_LNZ] + n : 1); /* KLU's estimate of nnz(L) */
}

static int klu_status(const klu_common *c) {
  if (c->status == KLU_SINGULAR) return FESD_ERR_SINGULAR;
  if (c->status == KLU_OUT_OF_MEMORY) return FESD_ERR_NOMEM;
  return FESD_ERR_LINSOLVE;
}

static void slot_clear(klu_ls *k, klu_slot *s) {
  if (s->numeric) klu_free_numeric(&s->numeric, &k->common);
  if (s->symbolic) klu_free_symbolic(&s->symbolic, &k->common);
  s->m = -1;
}

static int same_pattern(const klu_slot *s, int n, int m, const int *p, const int *idx) {
  return s->m == m && s->nz == p[n] && !memcmp(s->p, p, ((size_t)n + 1) * sizeof *p) &&
         !memcmp(s->idx, idx, (size_t)s->nz * sizeof *idx);
}

static int kls_analyze(fesd__ls *ls, int m, const int *p, const int *idx) {
  klu_ls *k = (klu_ls *)ls;
  const int n = ls->n, nz = p[n];
  ls->m = m;
  k->cur = NULL;
  klu_slot *s = NULL;
  int hit = 0;
  for (int i = 0; i < KLU_CACHE && !hit; i++) {
    klu_slot *c = &k->slot[i];
    if (c->m >= 0 && same_pattern(c, n, m, p, idx)) hit = 1, s = c;
    else if (!s || c->m < 0 || (s->m >= 0 && c->used < s->used)) s = c; /* empty, else least recent */
  }
  if (!hit) {
    slot_clear(k, s);
    if (nz > s->cap) {
      int *ni = realloc(s->idx, (size_t)(nz > 0 ? nz : 1) * sizeof *ni);
      if (!ni) return FESD_ERR_NOMEM;
      s->idx = ni;
      s->cap = nz;
    }
    memcpy(s->p, p, ((size_t)n + 1) * sizeof *p);
    memcpy(s->idx, idx, (size_t)nz * sizeof *idx);
    k->order_nomem = 0;
    s->symbolic = klu_analyze(n, s->p, s->idx, &k->common);
    if (!s->symbolic) return k->order_nomem ? FESD_ERR_NOMEM : klu_status(&k->common);
    s->m = m;
    s->nz = nz;
  }
  s->used = ++k->clock;
  k->cur = s;
  return FESD_OK;
}

static int full_factor(klu_ls *k, klu_slot *s, double *values) {
  if (s->numeric) klu_free_numeric(&s->numeric, &k->common);
  s->numeric = klu_factor(s->p, s->idx, values, s->symbolic, &k->common);
  return s->numeric ? FESD_OK : klu_status(&k->common);
}

static int kls_factor(fesd__ls *ls, double *values, double mu) {
  klu_ls *k = (klu_ls *)ls;
  klu_slot *s = k->cur;
  (void)mu;
  if (!s) return FESD_ERR_LINSOLVE;
  if (!s->numeric) return full_factor(k, s, values);
  if (!klu_refactor(s->p, s->idx, values, s->symbolic, s->numeric, &k->common))
    return full_factor(k, s, values);
  /* The old pivot order may be poor for the new values: a refactor with small pivots
   * (rcond) or large element growth (rgrowth, from the factors and the matrix) gets new
   * pivots. klu_condest is no safeguard here: it estimates the condition of the computed
   * factors, which a bad pivot order has already spoilt (measured: rcond 7e-49 with a
   * condition estimate that passed, and sensitivities off by 1e6). */
  if (!klu_rcond(s->symbolic, s->numeric, &k->common) || !(k->common.rcond >= k->rcond_min) ||
      !klu_rgrowth(s->p, s->idx, values, s->symbolic, s->numeric, &k->common) ||
      !(k->common.rgrowth >= KLU_RGROWTH_MIN))
    return full_factor(k, s, values);
  return FESD_OK;
}

static int kls_solve(fesd__ls *ls, double *x) {
  klu_ls *k = (klu_ls *)ls;
  if (!k->cur || !k->cur->numeric) return FESD_ERR_LINSOLVE;
  return klu_solve(k->cur->symbolic, k->cur->numeric, ls->n, 1, x, &k->common) ? FESD_OK
                                                                               : FESD_ERR_LINSOLVE;
}

static void kls_destroy(fesd__ls *ls) {
  klu_ls *k = (klu_ls *)ls;
  for (int i = 0; i < KLU_CACHE; i++) {
    slot_clear(k, &k->slot[i]);
    free(k->slot[i].p);
    free(k->slot[i].idx);
  }
  free(k);
}

int fesd__ls_klu_solve_many(fesd__ls *ls, double *x, int nrhs) {
  klu_ls *k = (klu_ls *)ls;
  if (!k->cur || !k->cur->numeric) return FESD_ERR_LINSOLVE;
  if (nrhs <= 0) return FESD_OK;
  return klu_solve(k->cur->symbolic, k->cur->numeric, ls->n, nrhs, x, &k->common) ? FESD_OK : FESD_ERR_LINSOLVE;
}

static const fesd__ls_ops klu_ops = {FESD__LS_LU, FESD__LAYOUT_CSC, 0,           kls_analyze,
                                     kls_factor,  kls_solve,        kls_destroy, fesd__ls_klu_solve_many};

int fesd__ls_klu_create(fesd__ls **ls, int n) {
  klu_ls *k = calloc(1, sizeof *k);
  if (!k) return FESD_ERR_NOMEM;
  klu_defaults(&k->common);
  k->common.ordering = 3; /* user function: order_block */
  k->common.user_order = order_block;
  k->common.user_data = &k->order_nomem;
  k->rcond_min = pow(DBL_EPSILON, 2.0 / 3.0);
  k->base.ops = &klu_ops;
  k->base.backend = FESD_NCP_BACKEND_KLU;
  k->base.n = k->base.m = n;
  for (int i = 0; i < KLU_CACHE; i++) {
    k->slot[i].m = -1;
    k->slot[i].p = malloc(((size_t)n + 1) * sizeof(int));
    if (!k->slot[i].p) {
      kls_destroy(&k->base);
      return FESD_ERR_NOMEM;
    }
  }
  *ls = &k->base;
  return FESD_OK;
}
