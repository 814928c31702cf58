/* UMFPACK backend (square sparse LU). Symbolic analysis once per pattern; each
 * factorization frees the previous numeric object first (umfpack_di_numeric
 * would overwrite the handle and leak it); solves use umfpack_di_wsolve with
 * preallocated workspace. A singular-matrix warning counts as a failure. */
#include "ncp/linsolve.h"

#include "fesd_ncp.h"

#include <stdlib.h>
#include <string.h>
#include <umfpack.h>

typedef struct {
  fesd__ls base;
  void *symbolic, *numeric;
  const int *p, *idx; /* the caller's pattern (stable until the next analyze) */
  const double *values;
  double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
  int *wi;
  double *w, *rhs;
} umf_ls;

static int map_status(int st) {
  if (st == UMFPACK_OK) return FESD_OK;
  if (st == UMFPACK_WARNING_singular_matrix) return FESD_ERR_SINGULAR;
  if (st == UMFPACK_ERROR_out_of_memory) return FESD_ERR_NOMEM;
  return FESD_ERR_LINSOLVE;
}

static void umf_release(umf_ls *u) {
  if (u->numeric) umfpack_di_free_numeric(&u->numeric);
  if (u->symbolic) umfpack_di_free_symbolic(&u->symbolic);
}

static int umf_analyze(fesd__ls *ls, int m, const int *p, const int *idx) {
  umf_ls *u = (umf_ls *)ls;
  umf_release(u);
  ls->m = m;
  u->p = p;
  u->idx = idx;
  int st = umfpack_di_symbolic(ls->n, ls->n, p, idx, NULL, &u->symbolic, u->control, u->info);
  if (st != UMFPACK_OK) {
    u->symbolic = NULL;
    return map_status(st);
  }
  return FESD_OK;
}

static int umf_factor(fesd__ls *ls, double *values, double mu) {
  umf_ls *u = (umf_ls *)ls;
  (void)mu;
  if (u->numeric) umfpack_di_free_numeric(&u->numeric);
  if (!u->symbolic) return FESD_ERR_LINSOLVE;
  int st = umfpack_di_numeric(u->p, u->idx, values, u->symbolic, &u->numeric, u->control, u->info);
  u->values = values;
  if (st != UMFPACK_OK) {
    /* never solve with a stale or singular factor */
    if (u->numeric) umfpack_di_free_numeric(&u->numeric);
    return map_status(st);
  }
  return FESD_OK;
}

static int umf_solve(fesd__ls *ls, double *x) {
  umf_ls *u = (umf_ls *)ls;
  if (!u->numeric) return FESD_ERR_LINSOLVE;
  memcpy(u->rhs, x, (size_t)ls->n * sizeof *x);
  int st = umfpack_di_wsolve(UMFPACK_A, u->p, u->idx, u->values, x, u->rhs, u->numeric, u->control,
                             u->info, u->wi, u->w);
  return map_status(st);
}

static void umf_destroy(fesd__ls *ls) {
  umf_ls *u = (umf_ls *)ls;
  umf_release(u);
  free(u->wi);
  free(u->w);
  free(u->rhs);
  free(u);
}

static const fesd__ls_ops umf_ops = {FESD__LS_LU, FESD__LAYOUT_CSC, 0,          umf_analyze,
                                     umf_factor,  umf_solve,        umf_destroy, NULL};

int fesd__ls_umfpack_create(fesd__ls **ls, int n) {
  umf_ls *u = calloc(1, sizeof *u);
  if (!u) return FESD_ERR_NOMEM;
  umfpack_di_defaults(u->control);
  /* Newton corrects the linear-solve error itself: skip iterative refinement. */
  u->control[UMFPACK_IRSTEP] = 0;
  u->control[UMFPACK_PRL] = 0;
  u->wi = malloc((size_t)n * sizeof *u->wi);
  u->w = malloc(5 * (size_t)n * sizeof *u->w);
  u->rhs = malloc((size_t)n * sizeof *u->rhs);
  if (!u->wi || !u->w || !u->rhs) {
    umf_destroy(&u->base);
    return FESD_ERR_NOMEM;
  }
  u->base.ops = &umf_ops;
  u->base.backend = FESD_NCP_BACKEND_UMFPACK;
  u->base.n = u->base.m = n;
  *ls = &u->base;
  return FESD_OK;
}
