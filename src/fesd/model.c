#include "fesd/model.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Callback outputs are filled with this quiet NaN before the call. Arithmetic never creates
 * its payload (a NaN result carries the default payload or that of a NaN operand), so an
 * entry still bit-identical to it afterwards was not written (or was computed from an
 * unwritten output): the callback broke its contract, and the stale value it left must not
 * be used. */
#define UNWRITTEN_BITS 0x7ff8fe5d0badf00dULL

static void mark_unwritten(double *v, int n) {
  const uint64_t bits = UNWRITTEN_BITS;
  double s;
  memcpy(&s, &bits, sizeof s);
  for (int i = 0; i < n; i++) v[i] = s;
}

/* FESD_OK if the n outputs are finite; FESD_ERR_CALLBACK if one was not written (that
 * takes precedence), FESD_ERR_NONFINITE for another NaN or Inf. */
static int check_outputs(const double *v, int n) {
  int st = FESD_OK;
  for (int i = 0; i < n; i++) {
    if (isfinite(v[i])) continue;
    uint64_t bits;
    memcpy(&bits, &v[i], sizeof bits);
    if (bits == UNWRITTEN_BITS) return FESD_ERR_CALLBACK;
    st = FESD_ERR_NONFINITE;
  }
  return st;
}

/* Full enumeration: row i has -1 in column j iff bit (nc-1-j) of i is set. */
static void full_sign_matrix(signed char *S, int nf, int nc) {
  for (int i = 0; i < nf; i++)
    for (int j = 0; j < nc; j++) S[i * nc + j] = ((i >> (nc - 1 - j)) & 1) ? -1 : 1;
}

static int check_sign_matrix(const signed char *S, int nf, int nc) {
  for (int i = 0; i < nf * nc; i++)
    if (S[i] != 1 && S[i] != -1) return FESD_ERR_SIGN_MATRIX;
  for (int i = 0; i < nf; i++)
    for (int r = i + 1; r < nf; r++)
      if (memcmp(S + i * nc, S + r * nc, (size_t)nc) == 0) return FESD_ERR_SIGN_MATRIX;
  return FESD_OK;
}

static void free_per_sys(int **a, int K) {
  if (!a) return;
  for (int k = 0; k < K; k++) free(a[k]);
  free(a);
}

void fesd__model_free(fesd__model *m) {
  if (!m) return;
  const int K = m->nsys;
  if (m->S)
    for (int k = 0; k < K; k++) free(m->S[k]);
  free(m->S);
  free_per_sys(m->rows, K);
  free_per_sys(m->fj_r, K);
  free_per_sys(m->fj_c, K);
  free_per_sys(m->sj_r, K);
  free_per_sys(m->sj_c, K);
  free_per_sys(m->cols, K);
  free_per_sys(m->sj_cp, K);
  free_per_sys(m->fj_map, K);
  void *p[] = {m->nf, m->nc, m->th_off, m->sys_of, m->swr, m->nr, m->fj_nnz, m->sj_nnz, m->ncol,
               m->Foff, m->dFoff, m->Fuoff, m->dgoff, m->pf_r, m->pf_c, m->xp, m->up, m->cbuf,
               m->cbuf2, m->dcbuf, m->dcubuf, m->fbuf, m->fbuf2, m->jxbuf};
  for (size_t i = 0; i < sizeof(p) / sizeof(p[0]); i++) free(p[i]);
  memset(m, 0, sizeof(*m));
}

static int *ialloc(size_t n, int *fail) {
  int *p = calloc(n > 0 ? n : 1, sizeof(int));
  if (!p) *fail = 1;
  return p;
}

static int cmp_ll(const void *a, const void *b) {
  long long x = *(const long long *)a, y = *(const long long *)b;
  return (x > y) - (x < y);
}

/* Patterns of subsystem k: the user's sparsity, or the full (dense, column-major) ones. */
static int set_patterns(fesd__model *m, int k, const fesd_sparsity *sp, int *fail) {
  const int nx = m->nx, sw = m->swr[k];
  if (sp) {
    if (sp->n_rows < 0 || sp->n_rows > nx || sp->jac_nnz < 0 || sp->sw_nnz < 0 ||
        (sp->n_rows > 0 && !sp->rows) || (sp->jac_nnz > 0 && (!sp->jac_row || !sp->jac_col)) ||
        (sp->sw_nnz > 0 && (!sp->sw_row || !sp->sw_col)))
      return FESD_ERR_MODEL;
    for (int r = 0; r < sp->n_rows; r++)
      if (sp->rows[r] < 0 || sp->rows[r] >= nx || (r > 0 && sp->rows[r] <= sp->rows[r - 1]))
        return FESD_ERR_PATTERN;
    for (int e = 0; e < sp->jac_nnz; e++)
      if (sp->jac_row[e] < 0 || sp->jac_row[e] >= sp->n_rows || sp->jac_col[e] < 0 || sp->jac_col[e] >= nx)
        return FESD_ERR_PATTERN;
    for (int e = 0; e < sp->sw_nnz; e++)
      if (sp->sw_row[e] < 0 || sp->sw_row[e] >= sw || sp->sw_col[e] < 0 || sp->sw_col[e] >= nx)
        return FESD_ERR_PATTERN;
  }
  int nr = sp ? sp->n_rows : nx, fj = sp ? sp->jac_nnz : nx * nx, sj = sp ? sp->sw_nnz : sw * nx;
  m->nr[k] = nr;
  m->fj_nnz[k] = fj;
  m->sj_nnz[k] = sj;
  m->rows[k] = ialloc((size_t)nr, fail);
  m->fj_r[k] = ialloc((size_t)fj, fail);
  m->fj_c[k] = ialloc((size_t)fj, fail);
  m->sj_r[k] = ialloc((size_t)sj, fail);
  m->sj_c[k] = ialloc((size_t)sj, fail);
  m->sj_cp[k] = ialloc((size_t)sj, fail);
  m->fj_map[k] = ialloc((size_t)fj, fail);
  if (*fail) return FESD_ERR_NOMEM;
  for (int r = 0; r < nr; r++) m->rows[k][r] = sp ? sp->rows[r] : r;
  for (int e = 0; e < fj; e++) {
    m->fj_r[k][e] = sp ? sp->jac_row[e] : e % nx;
    m->fj_c[k][e] = sp ? sp->jac_col[e] : e / nx;
  }
  for (int e = 0; e < sj; e++) {
    m->sj_r[k][e] = sp ? sp->sw_row[e] : e % sw;
    m->sj_c[k][e] = sp ? sp->sw_col[e] : e / sw;
  }
  /* distinct switch columns, in ascending order */
  unsigned char *seen = calloc((size_t)nx, 1);
  if (!seen) return *fail = 1, FESD_ERR_NOMEM;
  int nc = 0;
  for (int e = 0; e < sj; e++) seen[m->sj_c[k][e]] = 1;
  for (int c = 0; c < nx; c++) nc += seen[c];
  m->ncol[k] = nc;
  m->cols[k] = ialloc((size_t)nc, fail);
  if (*fail) {
    free(seen);
    return FESD_ERR_NOMEM;
  }
  int *pos = m->sj_cp[k]; /* reuse as temporary column->position map below */
  int q = 0;
  for (int c = 0; c < nx; c++)
    if (seen[c]) m->cols[k][q++] = c;
  free(seen);
  for (int e = 0; e < sj; e++) { /* binary search of the column */
    int lo = 0, hi = nc - 1, c = m->sj_c[k][e];
    while (lo < hi) {
      int mid = (lo + hi) / 2;
      if (m->cols[k][mid] < c) lo = mid + 1; else hi = mid;
    }
    pos[e] = lo;
  }
  return FESD_OK;
}

/* Union pattern of all df/dx patterns (column-major order) and the entry maps. */
static int union_pattern(fesd__model *m, int *fail) {
  long long tot = 0;
  for (int k = 0; k < m->nsys; k++) tot += m->fj_nnz[k];
  long long *key = malloc((size_t)(tot > 0 ? tot : 1) * sizeof(long long));
  if (!key) return *fail = 1, FESD_ERR_NOMEM;
  long long q = 0;
  for (int k = 0; k < m->nsys; k++)
    for (int e = 0; e < m->fj_nnz[k]; e++)
      key[q++] = (long long)m->fj_c[k][e] * m->nx + m->rows[k][m->fj_r[k][e]];
  qsort(key, (size_t)tot, sizeof(long long), cmp_ll);
  int n = 0;
  for (long long i = 0; i < tot; i++)
    if (i == 0 || key[i] != key[i - 1]) key[n++] = key[i];
  m->pf_nnz = n;
  m->pf_r = ialloc((size_t)n, fail);
  m->pf_c = ialloc((size_t)n, fail);
  if (*fail) {
    free(key);
    return FESD_ERR_NOMEM;
  }
  for (int i = 0; i < n; i++) {
    m->pf_r[i] = (int)(key[i] % m->nx);
    m->pf_c[i] = (int)(key[i] / m->nx);
  }
  for (int k = 0; k < m->nsys; k++)
    for (int e = 0; e < m->fj_nnz[k]; e++) {
      long long kk = (long long)m->fj_c[k][e] * m->nx + m->rows[k][m->fj_r[k][e]];
      int lo = 0, hi = n - 1;
      while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (key[mid] < kk) lo = mid + 1; else hi = mid;
      }
      m->fj_map[k][e] = lo;
    }
  free(key);
  return FESD_OK;
}

int fesd__model_init(fesd__model *m, const fesd_model *u) {
  memset(m, 0, sizeof(*m));
  if (!u) return FESD_ERR_NULL;
  if (!u->field || !u->sw || !u->n_modes) return FESD_ERR_MODEL;
  if (u->nx < 1 || u->nu < 0 || u->nsys < 1) return FESD_ERR_MODEL;
  if (u->sparsity && (!u->field_jac || !u->sw_jac)) return FESD_ERR_MODEL;
  m->nx = u->nx;
  m->nu = u->nu;
  m->nsys = u->nsys;
  m->user = *u;
  m->sparse = u->sparsity != NULL;
  const int K = u->nsys;
  int st = FESD_ERR_NOMEM, fail = 0;
  m->nf = ialloc((size_t)K, &fail);
  m->nc = ialloc((size_t)K, &fail);
  m->swr = ialloc((size_t)K, &fail);
  m->th_off = ialloc((size_t)K + 1, &fail);
  m->nr = ialloc((size_t)K, &fail);
  m->fj_nnz = ialloc((size_t)K, &fail);
  m->sj_nnz = ialloc((size_t)K, &fail);
  m->ncol = ialloc((size_t)K, &fail);
  m->dgoff = ialloc((size_t)K + 1, &fail);
  m->S = calloc((size_t)K, sizeof(*m->S));
  m->rows = calloc((size_t)K, sizeof(int *));
  m->fj_r = calloc((size_t)K, sizeof(int *));
  m->fj_c = calloc((size_t)K, sizeof(int *));
  m->sj_r = calloc((size_t)K, sizeof(int *));
  m->sj_c = calloc((size_t)K, sizeof(int *));
  m->cols = calloc((size_t)K, sizeof(int *));
  m->sj_cp = calloc((size_t)K, sizeof(int *));
  m->fj_map = calloc((size_t)K, sizeof(int *));
  if (fail || !m->S || !m->rows || !m->fj_r || !m->fj_c || !m->sj_r || !m->sj_c || !m->cols ||
      !m->sj_cp || !m->fj_map)
    goto fail;
  for (int k = 0; k < K; k++) {
    int nf = u->n_modes[k], nc = u->n_switch ? u->n_switch[k] : 0;
    if (nf < 1 || nc < 0) { /* (user subsystems need 2: checked by fesd_create) */
      st = FESD_ERR_MODEL;
      goto fail;
    }
    const signed char *given = u->sign ? u->sign[k] : NULL;
    /* nc switching functions give 2^nc sign patterns: a full matrix needs nf == 2^nc, a
     * given one (distinct rows) nf <= 2^nc */
    if (nc > 30 || (nc > 0 && (given ? nf > (1 << nc) : nf != (1 << nc)))) {
      st = FESD_ERR_DIMENSION;
      goto fail;
    }
    m->nf[k] = nf;
    m->nc[k] = nc;
    m->swr[k] = nc > 0 ? nc : nf;
    m->th_off[k + 1] = m->th_off[k] + nf;
    if (nc > 0) {
      m->S[k] = malloc((size_t)nf * (size_t)nc);
      if (!m->S[k]) {
        st = FESD_ERR_NOMEM; /* st holds the last check's FESD_OK from subsystem 1 on */
        goto fail;
      }
      if (given)
        memcpy(m->S[k], given, (size_t)nf * (size_t)nc);
      else
        full_sign_matrix(m->S[k], nf, nc);
      if ((st = check_sign_matrix(m->S[k], nf, nc)) != FESD_OK) goto fail;
    }
    if ((st = set_patterns(m, k, u->sparsity ? &u->sparsity[k] : NULL, &fail)) != FESD_OK) goto fail;
    if (m->swr[k] > m->max_sw) m->max_sw = m->swr[k];
    if (m->sj_nnz[k] > m->max_fj) m->max_fj = m->sj_nnz[k];
    if (m->nr[k] > m->max_nr) m->max_nr = m->nr[k];
    m->dgoff[k + 1] = m->dgoff[k] + nf * m->ncol[k];
  }
  m->nth = m->th_off[K];
  m->ndg = m->dgoff[K];
  st = FESD_ERR_NOMEM;
  m->sys_of = ialloc((size_t)m->nth, &fail);
  m->Foff = ialloc((size_t)m->nth + 1, &fail);
  m->dFoff = ialloc((size_t)m->nth + 1, &fail);
  m->Fuoff = ialloc((size_t)m->nth + 1, &fail);
  if (fail) goto fail;
  for (int k = 0; k < K; k++)
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      m->sys_of[i] = k;
      m->Foff[i + 1] = m->Foff[i] + m->nr[k];
      m->dFoff[i + 1] = m->dFoff[i] + m->fj_nnz[k];
      m->Fuoff[i + 1] = m->Fuoff[i] + m->nr[k] * m->nu;
    }
  m->nF = m->Foff[m->nth];
  m->ndF = m->dFoff[m->nth];
  m->nFu = m->Fuoff[m->nth];
  if ((st = union_pattern(m, &fail)) != FESD_OK) goto fail;
  st = FESD_ERR_NOMEM;
  size_t nx = (size_t)m->nx, nu = (size_t)(m->nu > 0 ? m->nu : 1), r = (size_t)m->max_sw;
  size_t fjmax = (size_t)m->max_fj > r * nx ? (size_t)m->max_fj : r * nx;
  m->xp = malloc(nx * sizeof(double));
  m->up = malloc(nu * sizeof(double));
  m->cbuf = malloc(r * sizeof(double));
  m->cbuf2 = malloc(r * sizeof(double));
  m->dcbuf = malloc(fjmax * sizeof(double));
  m->dcubuf = malloc(r * nu * sizeof(double));
  m->fbuf = malloc(nx * sizeof(double));
  m->fbuf2 = malloc(nx * sizeof(double));
  size_t fjx = 1;
  for (int k = 0; k < K; k++)
    if ((size_t)m->fj_nnz[k] > fjx) fjx = (size_t)m->fj_nnz[k];
  m->jxbuf = malloc(fjx * sizeof(double)); /* df/dx when only df/du is wanted */
  if (!m->xp || !m->up || !m->cbuf || !m->cbuf2 || !m->dcbuf || !m->dcubuf || !m->fbuf ||
      !m->fbuf2 || !m->jxbuf)
    goto fail;
  return FESD_OK;
fail:
  fesd__model_free(m);
  return st;
}

/* One block per point (g first: it owns the block), the fields' arrays only when asked for:
 * the system keeps a few records per stage of its largest layout. */
int fesd__point_alloc(const fesd__model *m, fesd__point_eval *pe, int fields) {
  const size_t nu = (size_t)(m->nu > 0 ? m->nu : 1), nth = (size_t)m->nth;
  const size_t ndg = (size_t)(m->ndg > 0 ? m->ndg : 1), nF = (size_t)(m->nF > 0 ? m->nF : 1);
  const size_t ndF = (size_t)(m->ndF > 0 ? m->ndF : 1), nFu = (size_t)(m->nFu > 0 ? m->nFu : 1);
  memset(pe, 0, sizeof(*pe));
  double *b = malloc((nth + ndg + nth * nu + (fields ? nF + ndF + nFu : 0)) * sizeof(double));
  if (!b) return FESD_ERR_NOMEM;
  pe->g = b;
  pe->dgdx = pe->g + nth;
  pe->dgdu = pe->dgdx + ndg;
  if (fields) {
    pe->F = pe->dgdu + nth * nu;
    pe->dFdx = pe->F + nF;
    pe->dFdu = pe->dFdx + ndF;
  }
  return FESD_OK;
}

void fesd__point_free(fesd__point_eval *pe) {
  free(pe->g);
  memset(pe, 0, sizeof(*pe));
}

static int call_field(fesd__model *m, int k, int i, const double *x, const double *u, double *f) {
  mark_unwritten(f, m->nr[k]);
  int st = m->user.field(k, i, m->t, x, u, f, m->user.user) ? FESD_ERR_CALLBACK : check_outputs(f, m->nr[k]);
  if (st) m->failed = "field";
  return st;
}

static int call_switch(fesd__model *m, int k, const double *x, const double *u, double *c) {
  mark_unwritten(c, m->swr[k]);
  int st = m->user.sw(k, m->t, x, u, c, m->user.user) ? FESD_ERR_CALLBACK : check_outputs(c, m->swr[k]);
  if (st) m->failed = "switch";
  return st;
}

/* g^k = -S^k c^k (or the indicators themselves), written to g + th_off[k]. */
static void indicators_from(const fesd__model *m, int k, const double *c, double *g) {
  int nf = m->nf[k], nc = m->nc[k];
  if (nc == 0) {
    memcpy(g, c, (size_t)nf * sizeof(double));
    return;
  }
  const signed char *S = m->S[k];
  for (int i = 0; i < nf; i++) {
    double s = 0;
    for (int j = 0; j < nc; j++) s -= S[i * nc + j] * c[j];
    g[i] = s;
  }
}

/* Central difference step: cbrt(eps) scaled (error ~ eps^(2/3)). */
static double fd_step(double v) { return 6.055454452393343e-06 * fmax(1.0, fabs(v)); }

int fesd__model_g(fesd__model *m, double t, const double *x, const double *u, double *g) {
  m->t = t;
  for (int k = 0; k < m->nsys; k++) {
    int st = call_switch(m, k, x, u, m->cbuf);
    if (st) return st;
    indicators_from(m, k, m->cbuf, g + m->th_off[k]);
  }
  return FESD_OK;
}

/* dc/dx on the pattern (dcbuf) and dc/du (dcubuf, swr x nu), by callback or central
 * differences (dense models: the pattern is column-major swr x nx). */
static int switch_derivatives(fesd__model *m, int k, const double *x, const double *u, int want_u) {
  int nx = m->nx, nu = m->nu, rows = m->swr[k], st;
  if (m->user.sw_jac) {
    const int nu_out = want_u ? rows * nu : 0;
    mark_unwritten(m->dcbuf, m->sj_nnz[k]);
    mark_unwritten(m->dcubuf, nu_out);
    st = m->user.sw_jac(k, m->t, x, u, m->dcbuf, want_u ? m->dcubuf : NULL, m->user.user) ? FESD_ERR_CALLBACK : 0;
    if (!st) st = check_outputs(m->dcbuf, m->sj_nnz[k]);
    if (!st) st = check_outputs(m->dcubuf, nu_out);
    if (st) m->failed = "switch_jac";
    return st;
  }
  memcpy(m->xp, x, (size_t)nx * sizeof(double));
  for (int j = 0; j < nx; j++) {
    double hj = fd_step(x[j]);
    m->xp[j] = x[j] + hj;
    if ((st = call_switch(m, k, m->xp, u, m->cbuf))) return st;
    m->xp[j] = x[j] - hj;
    if ((st = call_switch(m, k, m->xp, u, m->cbuf2))) return st;
    m->xp[j] = x[j];
    for (int r = 0; r < rows; r++) m->dcbuf[j * rows + r] = (m->cbuf[r] - m->cbuf2[r]) / (2 * hj);
  }
  if (want_u) {
    memcpy(m->up, u, (size_t)nu * sizeof(double));
    for (int j = 0; j < nu; j++) {
      double hj = fd_step(u[j]);
      m->up[j] = u[j] + hj;
      if ((st = call_switch(m, k, x, m->up, m->cbuf))) return st;
      m->up[j] = u[j] - hj;
      if ((st = call_switch(m, k, x, m->up, m->cbuf2))) return st;
      m->up[j] = u[j];
      for (int r = 0; r < rows; r++) m->dcubuf[j * rows + r] = (m->cbuf[r] - m->cbuf2[r]) / (2 * hj);
    }
  }
  return FESD_OK;
}

static int eval_switch_jac(fesd__model *m, int k, const double *x, const double *u,
                           fesd__point_eval *o) {
  const int nf = m->nf[k], nc = m->nc[k], nu = m->nu, want_u = o->dgdu && nu > 0;
  int st = switch_derivatives(m, k, x, u, want_u);
  if (st) return st;
  if (o->dgdx) {
    double *blk = o->dgdx + m->dgoff[k];
    memset(blk, 0, (size_t)nf * m->ncol[k] * sizeof(double));
    for (int e = 0; e < m->sj_nnz[k]; e++) {
      double v = m->dcbuf[e];
      double *col = blk + (size_t)m->sj_cp[k][e] * nf;
      int r = m->sj_r[k][e];
      if (nc == 0) col[r] += v;
      else
        for (int i = 0; i < nf; i++) col[i] -= m->S[k][i * nc + r] * v;
    }
  }
  if (want_u) {
    const int rows = m->swr[k], off = m->th_off[k], nth = m->nth;
    for (int c = 0; c < nu; c++)
      for (int i = 0; i < nf; i++) {
        double s = 0;
        if (nc == 0) s = m->dcubuf[c * rows + i];
        else
          for (int j = 0; j < nc; j++) s -= m->S[k][i * nc + j] * m->dcubuf[c * rows + j];
        o->dgdu[c * nth + off + i] = s;
      }
  }
  return FESD_OK;
}

static int eval_field_jac(fesd__model *m, int k, int i, int col, const double *x, const double *u,
                          fesd__point_eval *o) {
  int nx = m->nx, nu = m->nu, st;
  double *dfdx = o->dFdx ? o->dFdx + m->dFoff[col] : NULL;
  double *dfdu = (o->dFdu && nu > 0) ? o->dFdu + m->Fuoff[col] : NULL;
  if (m->user.field_jac) {
    /* only the outputs used are checked (jxbuf takes df/dx when only df/du is wanted) */
    const int nx_out = dfdx ? m->fj_nnz[k] : 0, nu_out = dfdu ? m->nr[k] * nu : 0;
    mark_unwritten(dfdx, nx_out);
    mark_unwritten(dfdu, nu_out);
    st = m->user.field_jac(k, i, m->t, x, u, dfdx ? dfdx : m->jxbuf, dfdu, m->user.user) ? FESD_ERR_CALLBACK : 0;
    if (!st) st = check_outputs(dfdx, nx_out);
    if (!st) st = check_outputs(dfdu, nu_out);
    if (st) m->failed = "field_jac";
    return st;
  }
  /* dense model: pattern = column-major nx x nx */
  if (dfdx) {
    memcpy(m->xp, x, (size_t)nx * sizeof(double));
    for (int j = 0; j < nx; j++) {
      double hj = fd_step(x[j]);
      m->xp[j] = x[j] + hj;
      if ((st = call_field(m, k, i, m->xp, u, m->fbuf))) return st;
      m->xp[j] = x[j] - hj;
      if ((st = call_field(m, k, i, m->xp, u, m->fbuf2))) return st;
      m->xp[j] = x[j];
      for (int r = 0; r < nx; r++) dfdx[j * nx + r] = (m->fbuf[r] - m->fbuf2[r]) / (2 * hj);
    }
  }
  if (dfdu) {
    memcpy(m->up, u, (size_t)nu * sizeof(double));
    for (int j = 0; j < nu; j++) {
      double hj = fd_step(u[j]);
      m->up[j] = u[j] + hj;
      if ((st = call_field(m, k, i, x, m->up, m->fbuf))) return st;
      m->up[j] = u[j] - hj;
      if ((st = call_field(m, k, i, x, m->up, m->fbuf2))) return st;
      m->up[j] = u[j];
      for (int r = 0; r < nx; r++) dfdu[j * nx + r] = (m->fbuf[r] - m->fbuf2[r]) / (2 * hj);
    }
  }
  return FESD_OK;
}

int fesd__model_eval(fesd__model *m, double t, const double *x, const double *u, fesd__point_eval *o) {
  m->t = t;
  int st;
  for (int k = 0; k < m->nsys; k++) {
    for (int i = 0; i < m->nf[k]; i++) {
      int col = m->th_off[k] + i;
      if (o->F && (st = call_field(m, k, i, x, u, o->F + m->Foff[col]))) return st;
      if ((o->dFdx || o->dFdu) && (st = eval_field_jac(m, k, i, col, x, u, o))) return st;
    }
    if (o->g) {
      if ((st = call_switch(m, k, x, u, m->cbuf))) return st;
      indicators_from(m, k, m->cbuf, o->g + m->th_off[k]);
    }
    if ((o->dgdx || o->dgdu) && (st = eval_switch_jac(m, k, x, u, o))) return st;
  }
  return FESD_OK;
}

int fesd__model_fields_active(fesd__model *m, double t, const double *x, const double *u, double *F,
                              const double *theta) {
  m->t = t;
  for (int i = 0; i < m->nth; i++) {
    if (theta[i] == 0.0) continue;
    const int k = m->sys_of[i];
    int st = call_field(m, k, i - m->th_off[k], x, u, F + m->Foff[i]);
    if (st) return st;
  }
  return FESD_OK;
}

void fesd__F_axpy(const fesd__model *m, const fesd__point_eval *pe, int i, double a, double *y) {
  const int k = m->sys_of[i], *rows = m->rows[k], nr = m->nr[k];
  const double *f = pe->F + m->Foff[i];
  for (int r = 0; r < nr; r++) y[rows[r]] += a * f[r];
}

double fesd__dg_dot(const fesd__model *m, const fesd__point_eval *pe, int i, const double *v) {
  const int k = m->sys_of[i], nf = m->nf[k], li = i - m->th_off[k], nc = m->ncol[k];
  const double *blk = pe->dgdx + m->dgoff[k];
  double s = 0;
  for (int c = 0; c < nc; c++) s += blk[(size_t)c * nf + li] * v[m->cols[k][c]];
  return s;
}

void fesd__dg_axpy(const fesd__model *m, const fesd__point_eval *pe, int i, double a, double *y) {
  const int k = m->sys_of[i], nf = m->nf[k], li = i - m->th_off[k], nc = m->ncol[k];
  const double *blk = pe->dgdx + m->dgoff[k];
  for (int c = 0; c < nc; c++) y[m->cols[k][c]] += a * blk[(size_t)c * nf + li];
}

void fesd__Jth(const fesd__model *m, const fesd__point_eval *pe, const double *theta, double *J) {
  memset(J, 0, (size_t)(m->pf_nnz > 0 ? m->pf_nnz : 1) * sizeof(double));
  for (int i = 0; i < m->nth; i++) {
    if (theta[i] == 0.0) continue;
    const int k = m->sys_of[i], n = m->fj_nnz[k], *map = m->fj_map[k];
    const double *d = pe->dFdx + m->dFoff[i], t = theta[i];
    for (int e = 0; e < n; e++) J[map[e]] += t * d[e];
  }
}

void fesd__pf_mv(const fesd__model *m, const double *J, const double *v, double *y) {
  memset(y, 0, (size_t)m->nx * sizeof(double));
  for (int p = 0; p < m->pf_nnz; p++) y[m->pf_r[p]] += J[p] * v[m->pf_c[p]];
}
