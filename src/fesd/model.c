/* Validated copy of a user model: sign matrices, sparsity patterns, the union pattern of
 * sum theta df/dx and the evaluation buffers (model_eval.c evaluates). */
#include "fesd/model.h"

#include <stdlib.h>
#include <string.h>

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

/* A point's arrays from the block B (one piece per point), the fields' arrays only when asked
 * for: the system keeps a few records per stage of its largest layout. */
void fesd__point_take(const fesd__model *m, fesd__point_eval *pe, int fields, fesd__block *B) {
  const size_t nu = (size_t)(m->nu > 0 ? m->nu : 1), nth = (size_t)m->nth;
  const size_t ndg = (size_t)(m->ndg > 0 ? m->ndg : 1), nF = (size_t)(m->nF > 0 ? m->nF : 1);
  const size_t ndF = (size_t)(m->ndF > 0 ? m->ndF : 1), nFu = (size_t)(m->nFu > 0 ? m->nFu : 1);
  memset(pe, 0, sizeof(*pe));
  double *b = fesd__block_take(B, (nth + ndg + nth * nu + (fields ? nF + ndF + nFu : 0)) * sizeof(double), 0);
  if (!b) return; /* the sizing pass */
  pe->g = b;
  pe->dgdx = pe->g + nth;
  pe->dgdu = pe->dgdx + ndg;
  if (fields) {
    pe->F = pe->dgdu + nth * nu;
    pe->dFdx = pe->F + nF;
    pe->dFdu = pe->dFdx + ndF;
  }
}

int fesd__two_modes(const fesd__model *m, const unsigned char *a, int k, int *j) {
  int i = -1, cnt = 0;
  *j = -1;
  for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++)
    if (a[l]) {
      if (cnt++ == 0) i = l;
      else *j = l;
    }
  return cnt == 2 ? i : -1;
}

int fesd__any_two_modes(const fesd__model *m, const unsigned char *a) {
  int j;
  for (int k = 0; k < m->nsys; k++)
    if (fesd__two_modes(m, a, k, &j) >= 0) return 1;
  return 0;
}

int fesd__count_two_modes(const fesd__model *m, const unsigned char *a) {
  int j, c = 0;
  for (int k = 0; k < m->nsys; k++) c += fesd__two_modes(m, a, k, &j) >= 0;
  return c;
}
