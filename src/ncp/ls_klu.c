/* KLU backend (square sparse LU). klu_analyze once per pattern, klu_factor the
 * first time, klu_refactor afterwards (same pivot order, no allocation). A small
 * pivot ratio after a refactor (klu_rcond, then the condition estimate) or a
 * failed refactor triggers a full klu_factor that chooses new pivots. */
#include "ncp/linsolve.h"

#include "fesd_ncp.h"

#include <float.h>
#include <klu.h>
#include <math.h>
#include <stdlib.h>

typedef struct {
  fesd__ls base;
  klu_common common;
  klu_symbolic *symbolic;
  klu_numeric *numeric;
  int *p, *idx; /* the caller's pattern (KLU's API is not const-qualified) */
  double rcond_min;
} klu_ls;

static int klu_status(const klu_common *c) {
  if (c->status == KLU_SINGULAR) return FESD_ERR_SINGULAR;
  if (c->status == KLU_OUT_OF_MEMORY) return FESD_ERR_NOMEM;
  return FESD_ERR_LINSOLVE;
}

static void klu_release(klu_ls *k) {
  if (k->numeric) klu_free_numeric(&k->numeric, &k->common);
  if (k->symbolic) klu_free_symbolic(&k->symbolic, &k->common);
}

static int kls_analyze(fesd__ls *ls, int m, const int *p, const int *idx) {
  klu_ls *k = (klu_ls *)ls;
  klu_release(k);
  ls->m = m;
  k->p = (int *)p;
  k->idx = (int *)idx;
  k->symbolic = klu_analyze(ls->n, k->p, k->idx, &k->common);
  return k->symbolic ? FESD_OK : klu_status(&k->common);
}

static int full_factor(klu_ls *k, double *values) {
  if (k->numeric) klu_free_numeric(&k->numeric, &k->common);
  k->numeric = klu_factor(k->p, k->idx, values, k->symbolic, &k->common);
  return k->numeric ? FESD_OK : klu_status(&k->common);
}

static int kls_factor(fesd__ls *ls, double *values, double mu) {
  klu_ls *k = (klu_ls *)ls;
  (void)mu;
  if (!k->symbolic) return FESD_ERR_LINSOLVE;
  if (!k->numeric) return full_factor(k, values);
  if (!klu_refactor(k->p, k->idx, values, k->symbolic, k->numeric, &k->common))
    return full_factor(k, values);
  /* The old pivot order may be poor for the new values: check cheaply first. */
  if (!klu_rcond(k->symbolic, k->numeric, &k->common) || !(k->common.rcond >= k->rcond_min)) {
    if (!klu_condest(k->p, values, k->symbolic, k->numeric, &k->common) ||
        !(k->common.condest <= 1.0 / k->rcond_min))
      return full_factor(k, values);
  }
  return FESD_OK;
}

static int kls_solve(fesd__ls *ls, double *x) {
  klu_ls *k = (klu_ls *)ls;
  if (!k->numeric) return FESD_ERR_LINSOLVE;
  return klu_solve(k->symbolic, k->numeric, ls->n, 1, x, &k->common) ? FESD_OK
                                                                       : FESD_ERR_LINSOLVE;
}

static void kls_destroy(fesd__ls *ls) {
  klu_ls *k = (klu_ls *)ls;
  klu_release(k);
  free(k);
}

static const fesd__ls_ops klu_ops = {FESD__LS_LU, FESD__LAYOUT_CSC, 0,          kls_analyze,
                                     kls_factor,  kls_solve,        kls_destroy};

int fesd__ls_klu_create(fesd__ls **ls, int n) {
  klu_ls *k = calloc(1, sizeof *k);
  if (!k) return FESD_ERR_NOMEM;
  klu_defaults(&k->common);
  k->rcond_min = pow(DBL_EPSILON, 2.0 / 3.0);
  k->base.ops = &klu_ops;
  k->base.backend = FESD_NCP_BACKEND_KLU;
  k->base.n = k->base.m = n;
  *ls = &k->base;
  return FESD_OK;
}
