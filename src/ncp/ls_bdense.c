/* Bordered dense LU for small square systems with a border (fesd_ncp_set_border): the CSC
 * values are scattered into a dense array with the border rows and columns last, and a
 * right-looking LU with threshold partial pivoting factors it. Interior columns pivot on
 * interior rows unless those are much smaller than a border row's entry, so the elimination is
 * that of the bordered KLU (A first, then the Schur complement of the border) without its
 * symbolic analysis, its n_b extra solves and its fallback (a singular A pivots on a border
 * row). Zero multipliers and zero entries of the pivot row are skipped, and each column (row)
 * is scanned only up to its last possible interior nonzero, so the cost follows the factors'
 * nonzeros more than n^3.
 * Why: a FESD switch step at Radau s = 4, 5 with two elements has 60-80 unknowns; KLU's
 * analysis of the new pattern (orderings, block triangular form, allocation) and its first
 * factorization cost more than this whole LU (measured, callgrind: oscillator s = 5 switch
 * step 765k -> 678k instructions, s = 4 573k -> 478k). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fesd_ncp.h"
#include "ncp/linsolve.h"

/* A pivot candidate of the preferred kind (diagonal, then interior row) is taken when it is at
 * least PIV_TOL times the largest entry of the column (KLU's rule with its diagonal
 * preference; a larger tolerance than KLU's 1e-3: fill costs flops here, never memory). */
#define PIV_TOL 0.1

typedef struct {
  fesd__ls base;
  int ni, cap_nz;
  const unsigned char *rb, *cb; /* border flags of the assembled rows / columns (caller's) */
  int *rpos, *cpos;             /* assembled row / column -> position in the dense order */
  int *src;                     /* dense position of each CSC entry of the pattern */
  int nz;
  double *a; /* n x n column-major, factorized in place */
  int *piv, *list, *tmp;
  int *chi0, *rhi0, *chi, *rhi; /* last interior row of each column, column of each row */
  double *y;
} bdense_ls;

static void bd_destroy(fesd__ls *ls) {
  bdense_ls *b = (bdense_ls *)ls;
  void *p[] = {b->rpos, b->cpos, b->src, b->a, b->piv, b->list, b->tmp, b->y, b->chi0, b->rhi0, b->chi, b->rhi};
  for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
  free(b);
}

static int imax(int a, int b) { return a > b ? a : b; }

/* Dense order of the columns: interior ones in their order, then the border ones. */
static int order(const unsigned char *flag, int n, int *pos) {
  int ni = 0;
  for (int i = 0; i < n; i++) ni += !flag[i];
  int ip = 0, bp = ni;
  for (int i = 0; i < n; i++) pos[i] = flag[i] ? bp++ : ip++;
  return ni;
}

/* Dense order of the rows: a greedy matching puts under each column (in the dense order) an
 * unmatched row of the same kind (interior, border) with an entry there, the one with the
 * fewest entries; the rest fill the free places in their order. Most pivots are then on the
 * diagonal: no interchanges and little fill (the assembled order has the complementarity rows
 * of every element after all equations). */
static int order_rows(bdense_ls *b, int n, const int *p, const int *idx) {
  int *cnt = b->list, *col_at = b->piv, *taken = b->tmp;
  memset(cnt, 0, (size_t)n * sizeof *cnt);
  for (int e = 0; e < p[n]; e++) cnt[idx[e]]++;
  for (int j = 0; j < n; j++) col_at[b->cpos[j]] = j;
  for (int i = 0; i < n; i++) b->rpos[i] = -1, taken[i] = 0;
  for (int c = 0; c < n; c++) {
    const int j = col_at[c];
    int best = -1;
    for (int e = p[j]; e < p[j + 1]; e++) {
      const int r = idx[e];
      if (b->rpos[r] < 0 && !b->rb[r] == !b->cb[j] && (best < 0 || cnt[r] < cnt[best])) best = r;
    }
    if (best >= 0) b->rpos[best] = c, taken[c] = 1;
  }
  int ni = 0;
  for (int i = 0; i < n; i++) ni += !b->rb[i];
  if (ni != b->ni) return FESD_ERR_LINSOLVE;
  int fi = 0, fb = ni;
  for (int i = 0; i < n; i++) {
    if (b->rpos[i] >= 0) continue;
    int *f = b->rb[i] ? &fb : &fi;
    while (taken[*f]) ++*f;
    b->rpos[i] = (*f)++;
  }
  return FESD_OK;
}

static int bd_analyze(fesd__ls *ls, int m, const int *p, const int *idx) {
  bdense_ls *b = (bdense_ls *)ls;
  const int n = ls->n;
  ls->m = m;
  if (m != n || p[n] > b->cap_nz) return FESD_ERR_LINSOLVE; /* caller checked */
  b->ni = order(b->cb, n, b->cpos);
  int rc = order_rows(b, n, p, idx);
  if (rc) return rc;
  for (int i = 0; i < n; i++) b->chi0[i] = b->rhi0[i] = -1;
  for (int j = 0; j < n; j++)
    for (int e = p[j]; e < p[j + 1]; e++) {
      const int r = b->rpos[idx[e]], c = b->cpos[j];
      b->src[e] = c * n + r;
      if (r < b->ni) b->chi0[c] = imax(b->chi0[c], r);
      if (c < b->ni) b->rhi0[r] = imax(b->rhi0[r], c);
    }
  b->nz = p[n];
  return FESD_OK;
}

/* Row of the pivot of column k (interior rows k..hi, border rows ni..n-1): the diagonal, else
 * the largest interior entry, else the largest entry, each when it passes PIV_TOL against the
 * column's largest. */
static int pivot_row(const double *ck, int k, int hi, int n, int ni) {
  double bigi = 0.0, bigb = 0.0;
  int pi = -1, pb = -1;
  for (int i = k; i <= hi; i++)
    if (fabs(ck[i]) > bigi) bigi = fabs(ck[i]), pi = i;
  for (int i = k > ni ? k : ni; i < n; i++)
    if (fabs(ck[i]) > bigb) bigb = fabs(ck[i]), pb = i;
  const double lim = PIV_TOL * (bigi > bigb ? bigi : bigb);
  if (!(lim > 0.0)) return -1;
  if (fabs(ck[k]) >= lim) return k;
  return pi >= 0 && bigi >= lim ? pi : pb;
}

/* Interchange of rows k and p (> k) in the columns from k on (L's rows stay: bd_solve). */
static void swap_rows(bdense_ls *b, int k, int p) {
  const int n = b->base.n, ni = b->ni, hi = imax(b->rhi[k], b->rhi[p]);
  double *a = b->a;
  for (int j = k; j < n; j = j >= hi ? imax(j + 1, ni) : j + 1) {
    double *cj = a + (size_t)j * n;
    const double t = cj[k];
    cj[k] = cj[p];
    cj[p] = t;
    if (p < ni && p > b->chi[j] && t != 0.0) b->chi[j] = p;
  }
  const int t = b->rhi[k];
  b->rhi[k] = b->rhi[p];
  b->rhi[p] = t;
}

/* Right-looking LU in the dense order. The interior part of a column (row) is scanned only up
 * to chi (rhi), the last interior row (column) that can hold a nonzero, kept up to date with
 * the fill: the element blocks of a step system leave most of each column zero. */
static int bd_factor(fesd__ls *ls, double *values, double mu) {
  bdense_ls *b = (bdense_ls *)ls;
  const int n = ls->n, ni = b->ni;
  double *a = b->a;
  int *chi = b->chi, *rhi = b->rhi, *list = b->list;
  (void)mu;
  /* column by column: a memset of the whole array is a rep stosb that callgrind counts per
   * byte */
  for (int j = 0; j < n; j++) memset(a + (size_t)j * n, 0, (size_t)n * sizeof *a);
  for (int e = 0; e < b->nz; e++) a[b->src[e]] = values[e];
  memcpy(chi, b->chi0, (size_t)n * sizeof *chi);
  memcpy(rhi, b->rhi0, (size_t)n * sizeof *rhi);
  for (int k = 0; k < n; k++) {
    double *ck = a + (size_t)k * n;
    const int p = pivot_row(ck, k, chi[k], n, ni);
    if (p < 0) return FESD_ERR_SINGULAR;
    b->piv[k] = p;
    if (p != k) swap_rows(b, k, p);
    const double inv = 1.0 / ck[k];
    const int hi = chi[k], lo_b = imax(k + 1, ni);
    int cnt = 0;
    for (int i = k + 1; i <= hi; i++)
      if (ck[i] != 0.0) ck[i] *= inv, list[cnt++] = i;
    const int last = cnt ? list[cnt - 1] : -1, cnt_i = cnt;
    for (int i = lo_b; i < n; i++)
      if (ck[i] != 0.0) ck[i] *= inv, list[cnt++] = i;
    if (!cnt) continue;
    for (int t = 0; t < cnt; t++) rhi[list[t]] = imax(rhi[list[t]], rhi[k]);
    /* a contiguous loop over the interior part beats the index list when that is full */
    const int dense = 2 * cnt_i > hi - k;
    for (int j = k + 1, end = rhi[k]; j < n; j = j == end ? lo_b : j + 1) {
      if (j > end && j < ni) j = lo_b;
      if (j >= n) break;
      double *cj = a + (size_t)j * n;
      const double f = cj[k];
      if (f == 0.0) continue;
      if (dense) {
        for (int i = k + 1; i <= hi; i++) cj[i] -= f * ck[i];
        for (int t = cnt_i; t < cnt; t++) cj[list[t]] -= f * ck[list[t]];
      } else {
        for (int t = 0; t < cnt; t++) cj[list[t]] -= f * ck[list[t]];
      }
      chi[j] = imax(chi[j], last);
    }
  }
  return FESD_OK;
}

static int bd_solve(fesd__ls *ls, double *x) {
  bdense_ls *b = (bdense_ls *)ls;
  const int n = ls->n;
  const double *a = b->a;
  double *y = b->y;
  for (int i = 0; i < n; i++) y[b->rpos[i]] = x[i];
  for (int k = 0; k < n; k++) { /* L y = P b, unit diagonal; L's rows were not interchanged */
    const int p = b->piv[k];
    const double yk = y[p];
    y[p] = y[k];
    y[k] = yk;
    if (yk == 0.0) continue;
    const double *ck = a + (size_t)k * n;
    for (int i = k + 1; i < n; i++) y[i] -= ck[i] * yk;
  }
  for (int k = n - 1; k >= 0; k--) { /* U x = y */
    const double *ck = a + (size_t)k * n;
    y[k] /= ck[k];
    const double yk = y[k];
    if (yk == 0.0) continue;
    for (int i = 0; i < k; i++) y[i] -= ck[i] * yk;
  }
  for (int j = 0; j < n; j++) x[j] = y[b->cpos[j]];
  return FESD_OK;
}

/* y_r[i] -= c[i] s_r for i in [lo, hi) and the w (<= 4) columns y_r: one load of c for all;
 * inlined with a constant w. */
static inline void update_w(const double *restrict c, int lo, int hi, int w, const double *s, double *restrict y0,
                            double *restrict y1, double *restrict y2, double *restrict y3) {
  const double s0 = s[0], s1 = w > 1 ? s[1] : 0.0, s2 = w > 2 ? s[2] : 0.0, s3 = w > 3 ? s[3] : 0.0;
  for (int i = lo; i < hi; i++) {
    const double ci = c[i];
    y0[i] -= ci * s0;
    if (w > 1) y1[i] -= ci * s1;
    if (w > 2) y2[i] -= ci * s2;
    if (w > 3) y3[i] -= ci * s3;
  }
}

/* The update of the columns with a nonzero multiplier s_r, together (a zero one is skipped, as
 * in bd_solve). */
static void update(const double *c, int lo, int hi, int w, const double *s, double *const *y) {
  double *u[4], t[4];
  int nz = 0;
  for (int r = 0; r < w; r++)
    if (s[r] != 0.0) u[nz] = y[r], t[nz++] = s[r];
  switch (nz) {
  case 4: update_w(c, lo, hi, 4, t, u[0], u[1], u[2], u[3]); break;
  case 3: update_w(c, lo, hi, 3, t, u[0], u[1], u[2], NULL); break;
  case 2: update_w(c, lo, hi, 2, t, u[0], u[1], NULL, NULL); break;
  case 1: update_w(c, lo, hi, 1, t, u[0], NULL, NULL, NULL); break;
  default: break;
  }
}

/* nrhs columns of x (leading dimension n), up to 4 at a time through b->y, each bit for bit as
 * by bd_solve (a single one by bd_solve: the block's bookkeeping costs more than it saves). */
static int bd_solve_many(fesd__ls *ls, double *x, int nrhs) {
  bdense_ls *b = (bdense_ls *)ls;
  const int n = ls->n;
  const double *a = b->a;
  for (int j = 0; j < nrhs; j += 4) {
    const int w = nrhs - j < 4 ? nrhs - j : 4;
    if (w == 1) return bd_solve(ls, x + (size_t)j * n);
    double *y[4], s[4];
    for (int r = 0; r < w; r++) {
      const double *xr = x + (size_t)(j + r) * n;
      y[r] = b->y + (size_t)r * n;
      for (int i = 0; i < n; i++) y[r][b->rpos[i]] = xr[i];
    }
    for (int k = 0; k < n; k++) { /* L y = P b, unit diagonal; L's rows were not interchanged */
      const int p = b->piv[k];
      for (int r = 0; r < w; r++) {
        s[r] = y[r][p];
        y[r][p] = y[r][k];
        y[r][k] = s[r];
      }
      update(a + (size_t)k * n, k + 1, n, w, s, y);
    }
    for (int k = n - 1; k >= 0; k--) { /* U x = y */
      const double *ck = a + (size_t)k * n;
      for (int r = 0; r < w; r++) s[r] = y[r][k] /= ck[k];
      update(ck, 0, k, w, s, y);
    }
    for (int r = 0; r < w; r++) {
      double *xr = x + (size_t)(j + r) * n;
      for (int i = 0; i < n; i++) xr[i] = y[r][b->cpos[i]];
    }
  }
  return FESD_OK;
}

static const fesd__ls_ops bdense_ops = {FESD__LS_LU, FESD__LAYOUT_CSC, 0,          bd_analyze,
                                        bd_factor,   bd_solve,         bd_destroy, bd_solve_many};

int fesd__ls_bdense_create(fesd__ls **ls, int n, int max_nz) {
  bdense_ls *b = calloc(1, sizeof *b);
  if (!b) return FESD_ERR_NOMEM;
  b->base.ops = &bdense_ops;
  b->base.backend = FESD_NCP_BACKEND_DENSE;
  b->base.n = b->base.m = n;
  b->cap_nz = max_nz;
  const size_t nn = (size_t)(n > 0 ? n : 1);
  b->rpos = malloc(nn * sizeof(int));
  b->cpos = malloc(nn * sizeof(int));
  b->src = malloc((size_t)(max_nz > 0 ? max_nz : 1) * sizeof(int));
  b->a = malloc(nn * nn * sizeof(double));
  b->piv = malloc(nn * sizeof(int));
  b->list = malloc(nn * sizeof(int));
  b->tmp = malloc(nn * sizeof(int));
  b->chi0 = malloc(nn * sizeof(int));
  b->rhi0 = malloc(nn * sizeof(int));
  b->chi = malloc(nn * sizeof(int));
  b->rhi = malloc(nn * sizeof(int));
  b->y = malloc(4 * nn * sizeof(double)); /* 4 columns: bd_solve_many */
  if (!b->rpos || !b->cpos || !b->src || !b->a || !b->piv || !b->list || !b->tmp || !b->y || !b->chi0 || !b->rhi0 || !b->chi || !b->rhi) {
    bd_destroy(&b->base);
    return FESD_ERR_NOMEM;
  }
  *ls = &b->base;
  return FESD_OK;
}

void fesd__ls_bdense_flags(fesd__ls *ls, const unsigned char *row_border, const unsigned char *col_border) {
  bdense_ls *b = (bdense_ls *)ls;
  b->rb = row_border;
  b->cb = col_border;
}
