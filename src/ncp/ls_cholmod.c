/* CHOLMOD backend for Levenberg-Marquardt: Cholesky of J'J + mu I without
 * forming J'J. CHOLMOD factorizes beta I + A A' for an unsymmetric A, so A holds
 * J' (n x m, CSC) and beta = mu. Analysis once per pattern; solves reuse X/Y/E.
 * The cholmod_common lives in this object (one per workspace, never shared). */
#include "ncp/linsolve.h"

#include "fesd_ncp.h"

#include <cholmod.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
  fesd__ls base;
  cholmod_common c;
  int started;
  cholmod_sparse *a;
  cholmod_factor *l;
  cholmod_dense *b, *x, *y, *e;
} chol_ls;

static int chol_status(const cholmod_common *c) {
  if (c->status == CHOLMOD_OUT_OF_MEMORY) return FESD_ERR_NOMEM;
  if (c->status == CHOLMOD_NOT_POSDEF) return FESD_ERR_SINGULAR;
  return FESD_ERR_LINSOLVE;
}

static void chol_release_pattern(chol_ls *h) {
  if (h->l) cholmod_free_factor(&h->l, &h->c);
  if (h->a) cholmod_free_sparse(&h->a, &h->c);
}

static int chol_analyze(fesd__ls *ls, int m, const int *p, const int *idx) {
  chol_ls *h = (chol_ls *)ls;
  chol_release_pattern(h);
  ls->m = m;
  size_t nz = (size_t)p[m];
  h->a = cholmod_allocate_sparse((size_t)ls->n, (size_t)m, nz, 1, 1, 0, CHOLMOD_REAL, &h->c);
  if (!h->a) return chol_status(&h->c);
  memcpy(h->a->p, p, ((size_t)m + 1) * sizeof(int));
  if (nz) memcpy(h->a->i, idx, nz * sizeof(int));
  h->l = cholmod_analyze(h->a, &h->c);
  if (!h->l || h->c.status < CHOLMOD_OK) {
    int st = chol_status(&h->c);
    chol_release_pattern(h);
    return st;
  }
  return FESD_OK;
}

static int chol_factor(fesd__ls *ls, double *values, double mu) {
  chol_ls *h = (chol_ls *)ls;
  if (!h->l) return FESD_ERR_LINSOLVE;
  memcpy(h->a->x, values, h->a->nzmax * sizeof(double));
  double beta[2] = {mu, 0.0};
  /* factorize_p returns TRUE on a non-positive-definite matrix: check status */
  if (!cholmod_factorize_p(h->a, beta, NULL, 0, h->l, &h->c) || h->c.status != CHOLMOD_OK)
    return chol_status(&h->c);
  return FESD_OK;
}

static int chol_solve(fesd__ls *ls, double *x) {
  chol_ls *h = (chol_ls *)ls;
  size_t n = (size_t)ls->n;
  memcpy(h->b->x, x, n * sizeof *x);
  if (!cholmod_solve2(CHOLMOD_A, h->l, h->b, NULL, &h->x, NULL, &h->y, &h->e, &h->c))
    return chol_status(&h->c);
  memcpy(x, h->x->x, n * sizeof *x);
  return FESD_OK;
}

static void chol_destroy(fesd__ls *ls) {
  chol_ls *h = (chol_ls *)ls;
  if (h->started) {
    chol_release_pattern(h);
    cholmod_free_dense(&h->b, &h->c);
    cholmod_free_dense(&h->x, &h->c);
    cholmod_free_dense(&h->y, &h->c);
    cholmod_free_dense(&h->e, &h->c);
    cholmod_finish(&h->c);
  }
  free(h);
}

static const fesd__ls_ops chol_ops = {FESD__LS_NORMAL, FESD__LAYOUT_CSC_T, 0,           chol_analyze,
                                      chol_factor,     chol_solve,         chol_destroy, NULL};

int fesd__ls_cholmod_create(fesd__ls **ls, int n) {
  chol_ls *h = calloc(1, sizeof *h);
  if (!h) return FESD_ERR_NOMEM;
  h->base.ops = &chol_ops;
  h->base.backend = FESD_NCP_BACKEND_CHOLMOD;
  h->base.n = h->base.m = n;
  if (!cholmod_start(&h->c)) {
    free(h);
    return FESD_ERR_LINSOLVE;
  }
  h->started = 1;
  h->c.print = 0; /* the library never prints */
  h->c.nmethods = 1;
  h->c.method[0].ordering = CHOLMOD_AMD;
  h->c.postorder = 1;
  h->b = cholmod_allocate_dense((size_t)n, 1, (size_t)n, CHOLMOD_REAL, &h->c);
  if (!h->b) {
    int st = chol_status(&h->c);
    chol_destroy(&h->base);
    return st;
  }
  *ls = &h->base;
  return FESD_OK;
}
