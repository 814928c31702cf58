/* Dense backends: LU of the square Jacobian (in place, no copy) and Cholesky of
 * the normal matrix J'J + mu I for Levenberg-Marquardt. */
#include "ncp/linsolve.h"

#include "common/dense_lu.h"
#include "common/lapack.h"
#include "fesd_ncp.h"

#include <math.h>
#include <stdlib.h>

/* Up to this order an unblocked LU beats LAPACK's dgetrf/dgetrs, whose call and
 * blocking overhead dominates small systems (bench/ncp_bench, docs/ncp.md). */
#define SMALL_LU_MAX_N 48

typedef struct {
  fesd__ls base;
  int *ipiv;
  double *lu; /* the caller's values array, factorized in place */
} dense_lu;

typedef struct {
  fesd__ls base;
  double *nrm; /* n x n normal matrix, lower triangle used */
} dense_normal;

static int dense_analyze(fesd__ls *ls, int m, const int *p, const int *idx) {
  (void)p;
  (void)idx;
  ls->m = m;
  return FESD_OK;
}

static int lu_factor(fesd__ls *ls, double *values, double mu) {
  dense_lu *d = (dense_lu *)ls;
  int n = ls->n, info = 0;
  (void)mu;
  d->lu = values;
  if (n <= SMALL_LU_MAX_N) return fesd__dense_lu(n, values, d->ipiv) ? FESD_ERR_SINGULAR : FESD_OK;
  dgetrf_(&n, &n, values, &n, d->ipiv, &info);
  if (info < 0) return FESD_ERR_LINSOLVE;
  return info > 0 ? FESD_ERR_SINGULAR : FESD_OK;
}

static int lu_solve(fesd__ls *ls, double *x) {
  dense_lu *d = (dense_lu *)ls;
  int n = ls->n, one = 1, info = 0;
  if (n <= SMALL_LU_MAX_N) {
    fesd__dense_lu_solve(n, d->lu, d->ipiv, x);
    return FESD_OK;
  }
  dgetrs_("N", &n, &one, d->lu, &n, d->ipiv, x, &n, &info, 1);
  return info == 0 ? FESD_OK : FESD_ERR_LINSOLVE;
}

static int lu_solve_many(fesd__ls *ls, double *x, int nrhs) {
  dense_lu *d = (dense_lu *)ls;
  if (ls->n > SMALL_LU_MAX_N) { /* dgetrs with several columns blocks differently */
    int rc = FESD_OK;
    for (int j = 0; j < nrhs && rc == FESD_OK; j++) rc = lu_solve(ls, x + (size_t)j * ls->n);
    return rc;
  }
  fesd__dense_lu_solve_many(ls->n, d->lu, d->ipiv, x, nrhs);
  return FESD_OK;
}

static void lu_destroy(fesd__ls *ls) {
  dense_lu *d = (dense_lu *)ls;
  free(d->ipiv);
  free(d);
}

static const fesd__ls_ops dense_lu_ops = {FESD__LS_LU, FESD__LAYOUT_DENSE, 1,          dense_analyze,
                                          lu_factor,   lu_solve,           lu_destroy, lu_solve_many};

int fesd__ls_dense_lu_create(fesd__ls **ls, int n) {
  dense_lu *d = calloc(1, sizeof *d);
  if (!d) return FESD_ERR_NOMEM;
  d->ipiv = malloc((size_t)n * sizeof *d->ipiv);
  if (!d->ipiv) {
    free(d);
    return FESD_ERR_NOMEM;
  }
  d->base.ops = &dense_lu_ops;
  d->base.backend = FESD_NCP_BACKEND_DENSE;
  d->base.n = d->base.m = n;
  *ls = &d->base;
  return FESD_OK;
}

static int normal_factor(fesd__ls *ls, double *values, double mu) {
  dense_normal *d = (dense_normal *)ls;
  int n = ls->n, m = ls->m, info = 0;
  const double one = 1.0, zero = 0.0;
  dsyrk_("L", "T", &n, &m, &one, values, &m, &zero, d->nrm, &n, 1, 1);
  for (int j = 0; j < n; j++) d->nrm[j + (size_t)j * n] += mu;
  dpotrf_("L", &n, d->nrm, &n, &info, 1);
  if (info < 0) return FESD_ERR_LINSOLVE;
  return info > 0 ? FESD_ERR_SINGULAR : FESD_OK;
}

static int normal_solve(fesd__ls *ls, double *x) {
  dense_normal *d = (dense_normal *)ls;
  int n = ls->n, one = 1, info = 0;
  dpotrs_("L", &n, &one, d->nrm, &n, x, &n, &info, 1);
  return info == 0 ? FESD_OK : FESD_ERR_LINSOLVE;
}

static void normal_destroy(fesd__ls *ls) {
  dense_normal *d = (dense_normal *)ls;
  free(d->nrm);
  free(d);
}

static const fesd__ls_ops dense_normal_ops = {FESD__LS_NORMAL, FESD__LAYOUT_DENSE, 0,
                                              dense_analyze,   normal_factor,      normal_solve,
                                              normal_destroy,  NULL};

int fesd__ls_dense_normal_create(fesd__ls **ls, int n) {
  dense_normal *d = calloc(1, sizeof *d);
  if (!d) return FESD_ERR_NOMEM;
  d->nrm = malloc((size_t)n * (size_t)n * sizeof *d->nrm);
  if (!d->nrm) {
    free(d);
    return FESD_ERR_NOMEM;
  }
  d->base.ops = &dense_normal_ops;
  d->base.backend = FESD_NCP_BACKEND_DENSE;
  d->base.n = d->base.m = n;
  *ls = &d->base;
  return FESD_OK;
}
