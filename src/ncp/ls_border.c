/* Bordered sparse LU: the rows and columns the caller marks as border (fesd_ncp_set_border)
 * are eliminated last by a Schur complement,
 *   [A B; C D] [xi; xb] = [bi; bb]:  W = A^{-1} B,  S = D - C W,
 *   xb = S^{-1} (bb - C A^{-1} bi),  xi = A^{-1} bi - W xb,
 * with A factorized by KLU (its block-triangular form and ordering) and S dense.
 * Why: a few rows and columns that couple everything (in a FESD step: the element lengths,
 * the boundary rows and sum h = T) merge the whole matrix into one strongly connected block
 * and fill it (measured: friction chain n = 128 with 6 elements, 0.7M entries in L for a
 * 12k x 12k matrix, 200-450 ms per factorization); without them the step matrix is block
 * triangular in time and KLU factors it element by element. The cost is one solve with A per
 * border column. When A is singular (a border that does not separate cleanly) the whole
 * matrix is factorized by a plain KLU instead. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/lapack.h"
#include "fesd_ncp.h"
#include "ncp/linsolve.h"

typedef struct {
  fesd__ls base;
  fesd__ls *inner, *full; /* A (ni x ni), the whole matrix (fallback) */
  int use_full;
  int nb, ni, cap_nz;
  const unsigned char *rb, *cb; /* border flags of the assembled rows / columns (caller's) */
  int *rmap, *cmap;             /* index -> interior index, or -1 - border index */
  int *Ap, *Ai, *a_src;         /* interior CSC and the source position of each entry */
  int nB, nC, nD;
  int *B_r, *B_c, *B_src, *C_r, *C_c, *C_src, *D_r, *D_c, *D_src;
  const int *fp, *fi; /* the full pattern of the last analyze (caller-owned, stable) */
  double *Ax, *Cx, *W, *S, *bcopy, *rb_vec;
  int *piv;
  int full_ready;
} border_ls;

static void bls_free_arrays(border_ls *b) {
  void *p[] = {b->rmap, b->cmap, b->Ap,  b->Ai,  b->a_src, b->B_r, b->B_c, b->B_src, b->C_r,
               b->C_c,  b->C_src, b->D_r, b->D_c, b->D_src, b->Ax, b->Cx, b->W,   b->S,     b->bcopy,
               b->rb_vec, b->piv};
  for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
}

static void bls_destroy(fesd__ls *ls) {
  border_ls *b = (border_ls *)ls;
  fesd__ls_destroy(&b->inner);
  fesd__ls_destroy(&b->full);
  bls_free_arrays(b);
  free(b);
}

static int grow_nz(border_ls *b, int nz) {
  if (nz <= b->cap_nz) return FESD_OK;
  int **arr[] = {&b->Ai, &b->a_src, &b->B_r, &b->B_c, &b->B_src, &b->C_r, &b->C_c, &b->C_src};
  for (size_t i = 0; i < sizeof arr / sizeof arr[0]; i++) {
    int *p = realloc(*arr[i], (size_t)(nz > 0 ? nz : 1) * sizeof(int));
    if (!p) return FESD_ERR_NOMEM;
    *arr[i] = p;
  }
  double **darr[] = {&b->Ax, &b->Cx};
  for (size_t i = 0; i < 2; i++) {
    double *p = realloc(*darr[i], (size_t)(nz > 0 ? nz : 1) * sizeof(double));
    if (!p) return FESD_ERR_NOMEM;
    *darr[i] = p;
  }
  b->cap_nz = nz;
  return FESD_OK;
}

static int bls_analyze(fesd__ls *ls, int m, const int *p, const int *idx) {
  border_ls *b = (border_ls *)ls;
  const int n = ls->n, nb = b->nb, ni = b->ni;
  ls->m = m;
  b->use_full = 0;
  b->full_ready = 0;
  b->fp = p;
  b->fi = idx;
  int r_int = 0, r_bor = 0, c_int = 0, c_bor = 0;
  for (int i = 0; i < m; i++) b->rmap[i] = b->rb[i] ? -1 - r_bor++ : r_int++;
  for (int j = 0; j < n; j++) b->cmap[j] = b->cb[j] ? -1 - c_bor++ : c_int++;
  if (m != n || r_bor != nb || c_bor != nb) return FESD_ERR_LINSOLVE; /* caller checked */
  int rc = grow_nz(b, p[n]);
  if (rc) return rc;
  b->nB = b->nC = b->nD = 0;
  int k = 0;
  for (int j = 0; j < n; j++) {
    const int cj = b->cmap[j];
    if (cj >= 0) b->Ap[cj] = k;
    for (int e = p[j]; e < p[j + 1]; e++) {
      const int ri = b->rmap[idx[e]];
      if (cj >= 0 && ri >= 0) {
        b->Ai[k] = ri;
        b->a_src[k++] = e;
      } else if (cj < 0 && ri >= 0) {
        b->B_r[b->nB] = ri, b->B_c[b->nB] = -1 - cj, b->B_src[b->nB++] = e;
      } else if (cj >= 0) {
        b->C_r[b->nC] = -1 - ri, b->C_c[b->nC] = cj, b->C_src[b->nC++] = e;
      } else if (b->nD < nb * nb) {
        b->D_r[b->nD] = -1 - ri, b->D_c[b->nD] = -1 - cj, b->D_src[b->nD++] = e;
      }
    }
  }
  b->Ap[ni] = k;
  return b->inner->ops->analyze(b->inner, ni, b->Ap, b->Ai);
}

static int full_factor(border_ls *b, double *values) {
  int rc = FESD_OK;
  if (!b->full_ready) {
    rc = b->full->ops->analyze(b->full, b->base.m, b->fp, b->fi);
    if (rc) return rc;
    b->full_ready = 1;
  }
  rc = b->full->ops->factor(b->full, values, 0.0);
  b->use_full = rc == FESD_OK;
  return rc;
}

static int bls_factor(fesd__ls *ls, double *values, double mu) {
  border_ls *b = (border_ls *)ls;
  const int nb = b->nb, ni = b->ni;
  (void)mu;
  b->use_full = 0;
  const int na = b->Ap[ni];
  for (int k = 0; k < na; k++) b->Ax[k] = values[b->a_src[k]];
  int rc = b->inner->ops->factor(b->inner, b->Ax, 0.0);
  if (rc == FESD_ERR_NOMEM) return rc;
  if (rc) return full_factor(b, values);
  memset(b->W, 0, (size_t)ni * nb * sizeof(double));
  for (int q = 0; q < b->nB; q++) b->W[(size_t)b->B_c[q] * ni + b->B_r[q]] = values[b->B_src[q]];
  if ((rc = fesd__ls_klu_solve_many(b->inner, b->W, nb))) return rc;
  memset(b->S, 0, (size_t)nb * nb * sizeof(double));
  for (int q = 0; q < b->nD; q++) b->S[(size_t)b->D_c[q] * nb + b->D_r[q]] += values[b->D_src[q]];
  for (int q = 0; q < b->nC; q++) {
    const double v = b->Cx[q] = values[b->C_src[q]];
    const int r = b->C_r[q], c = b->C_c[q];
    for (int cb = 0; cb < nb; cb++) b->S[(size_t)cb * nb + r] -= v * b->W[(size_t)cb * ni + c];
  }
  for (size_t i = 0; i < (size_t)nb * nb; i++)
    if (!isfinite(b->S[i])) return full_factor(b, values);
  int info = 0;
  if (nb > 0) dgetrf_(&nb, &nb, b->S, &nb, b->piv, &info);
  return info == 0 ? FESD_OK : full_factor(b, values);
}

/* nrhs columns of x (leading dimension n), up to 4 at a time: one KLU solve with A for the
 * block (the factors traversed once), the border per column. */
static int bls_solve_many(fesd__ls *ls, double *x, int nrhs) {
  border_ls *b = (border_ls *)ls;
  const int n = ls->n, nb = b->nb, ni = b->ni;
  if (b->use_full) return fesd__ls_klu_solve_many(b->full, x, nrhs);
  for (int j = 0; j < nrhs; j += 4) {
    const int w = nrhs - j < 4 ? nrhs - j : 4;
    for (int c = 0; c < w; c++) { /* y: interior (ni), r: border (nb) of each column */
      const double *xc = x + (size_t)(j + c) * n;
      double *y = b->bcopy + (size_t)c * ni, *r = b->rb_vec + (size_t)c * nb;
      for (int i = 0; i < n; i++) {
        const int t = b->rmap[i];
        if (t >= 0) y[t] = xc[i];
        else r[-1 - t] = xc[i];
      }
    }
    int rc = fesd__ls_klu_solve_many(b->inner, b->bcopy, w);
    if (rc) return rc;
    for (int c = 0; c < w; c++) {
      double *xc = x + (size_t)(j + c) * n, *y = b->bcopy + (size_t)c * ni, *r = b->rb_vec + (size_t)c * nb;
      for (int q = 0; q < b->nC; q++) r[b->C_r[q]] -= b->Cx[q] * y[b->C_c[q]];
      int info = 0, one = 1;
      if (nb > 0) dgetrs_("N", &nb, &one, b->S, &nb, b->piv, r, &nb, &info, 1);
      if (info) return FESD_ERR_LINSOLVE;
      for (int k = 0; k < nb; k++) {
        const double *wk = b->W + (size_t)k * ni, xk = r[k];
        if (xk != 0.0)
          for (int i = 0; i < ni; i++) y[i] -= wk[i] * xk;
      }
      for (int i = 0; i < n; i++) {
        const int t = b->cmap[i];
        xc[i] = t >= 0 ? y[t] : r[-1 - t];
      }
    }
  }
  return FESD_OK;
}

static int bls_solve(fesd__ls *ls, double *x) { return bls_solve_many(ls, x, 1); }

static const fesd__ls_ops border_ops = {FESD__LS_LU, FESD__LAYOUT_CSC, 0,           bls_analyze,
                                        bls_factor,  bls_solve,        bls_destroy, bls_solve_many};

int fesd__ls_border_create(fesd__ls **ls, int n, int nb) {
  border_ls *b = calloc(1, sizeof *b);
  if (!b) return FESD_ERR_NOMEM;
  b->base.ops = &border_ops;
  b->base.backend = FESD_NCP_BACKEND_KLU;
  b->base.n = b->base.m = n;
  b->nb = nb;
  b->ni = n - nb;
  const size_t nn = (size_t)n, ni = (size_t)b->ni, nbb = (size_t)(nb > 0 ? nb : 1);
  b->rmap = malloc(nn * sizeof(int));
  b->cmap = malloc(nn * sizeof(int));
  b->Ap = malloc((ni + 1) * sizeof(int));
  b->D_r = malloc(nbb * nbb * sizeof(int));
  b->D_c = malloc(nbb * nbb * sizeof(int));
  b->D_src = malloc(nbb * nbb * sizeof(int));
  b->W = malloc((ni > 0 ? ni : 1) * nbb * sizeof(double));
  b->S = malloc(nbb * nbb * sizeof(double));
  b->bcopy = malloc(4 * (ni > 0 ? ni : 1) * sizeof(double)); /* 4 columns: bls_solve_many */
  b->rb_vec = malloc(4 * nbb * sizeof(double));
  b->piv = malloc(nbb * sizeof(int));
  int rc = FESD_OK;
  if (!b->rmap || !b->cmap || !b->Ap || !b->D_r || !b->D_c || !b->D_src || !b->W || !b->S || !b->bcopy ||
      !b->rb_vec || !b->piv)
    rc = FESD_ERR_NOMEM;
  if (!rc) rc = fesd__ls_klu_create(&b->inner, b->ni);
  if (!rc) rc = fesd__ls_klu_create(&b->full, n);
  if (rc) {
    bls_destroy(&b->base);
    return rc;
  }
  *ls = &b->base;
  return FESD_OK;
}

void fesd__ls_border_flags(fesd__ls *ls, const unsigned char *row_border, const unsigned char *col_border) {
  border_ls *b = (border_ls *)ls;
  b->rb = row_border;
  b->cb = col_border;
}
