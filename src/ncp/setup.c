/* Settings, validation, workspace allocation, row selection, bounds, cleanup. */
#include "ncp/ncp_internal.h"
#include "ncp/ncp_defer.h"
#include "ncp/ncp_nomem.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int fesd_ncp_settings_default(fesd_ncp_settings *s) {
  if (!s) return FESD_ERR_NULL;
  memset(s, 0, sizeof *s);
  s->tol = 1e-12;
  s->max_iter = 50;
  s->backend = FESD_NCP_BACKEND_AUTO;
  s->dense_max_n = FESD_NCP_DENSE_MAX_N;
  s->armijo = 1e-4;
  s->backtrack = 0.5;
  s->max_backtracks = 30;
  s->sigma0 = 1e-1;
  s->sigma_factor = 0.1;
  s->sigma_min = 1e-8;
  s->homotopy_tol_factor = 1e-2;
  s->lm_mu0 = 1e-3;
  s->slow_ratio = 0.5;
  return FESD_OK;
}

/* Ranges documented in include/fesd_ncp.h; NaN fails every comparison. The bounds on the
 * homotopy keep its stage count finite (at most ~420 stages: sigma0 / sigma_min <= 1e19,
 * factor <= 0.9); lm_mu0 lies in the clamp range of the adapted damping (newton.c). */
static int in_range(double x, double lo, double hi) { return x >= lo && x <= hi; }
static int in_open(double x, double lo, double hi) { return x > lo && x < hi; }
static int int_in(int v, int lo, int hi) { return v >= lo && v <= hi; }

static int validate_settings(const fesd_ncp_settings *s) {
  if (!in_range(s->tol, 1e-16, 1e-1) || !int_in(s->max_iter, 1, 1000) ||
      !int_in((int)s->backend, FESD_NCP_BACKEND_AUTO, FESD_NCP_BACKEND_CHOLMOD) ||
      !int_in(s->dense_max_n, 0, 5000) || !in_open(s->armijo, 0.0, 0.5) ||
      !in_open(s->backtrack, 0.0, 1.0) || !int_in(s->max_backtracks, 1, 100) ||
      !(s->sigma0 > 0.0 && s->sigma0 <= 1e3) || !(s->sigma_factor > 0.0 && s->sigma_factor <= 0.9) ||
      !in_range(s->sigma_min, 1e-16, s->sigma0) ||
      !(s->homotopy_tol_factor > 0.0 && s->homotopy_tol_factor <= 1.0) ||
      !in_range(s->lm_mu0, 1e-10, 1e10) || !(s->slow_iter == 0 || int_in(s->slow_iter, 2, 1000)) ||
      !(s->slow_ratio > 0.0 && s->slow_ratio <= 1.0))
    return FESD_ERR_INVALID_ARG;
  return FESD_OK;
}

void fesd_ncp_free(fesd_ncp **pws) {
  if (!pws || !*pws) return;
  fesd_ncp *ws = *pws;
  fesd__ls_destroy(&ws->lu);
  fesd__ls_destroy(&ws->border);
  free(ws->raw_border);
  free(ws->col_border);
  free(ws->row_border);
  fesd__ls_destroy(&ws->normal);
  void *arrays[] = {ws->trow,    ws->tcol,     ws->eq_on,   ws->pair_mode, ws->eq_list,
                    ws->pair_pos, ws->fb_list, ws->act_src, ws->act_wrow,  ws->act_tgt,
                    ws->act_r,   ws->act_c,    ws->sp_p,    ws->sp_i,      ws->work,
                    ws->vals,    ws->wgt,      ws->raw_c,   ws->raw_t,     ws->jac_c,
                    ws->F_c,      ws->F_t,     ws->zt,        ws->d,
                    ws->g,       ws->tmp,      ws->z0,      ws->lb,        ws->ub,
                    ws->sens_jv, ws->sens_blk};
  for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++) free(arrays[i]);
  free(ws);
  *pws = NULL;
}

/* malloc of at least one element, so that empty arrays are valid pointers */
static void *alloc(size_t count, size_t size, int *fail) {
  void *p = malloc((count ? count : 1) * size);
  if (!p) *fail = 1;
  return p;
}

static int allocate(fesd_ncp *ws) {
  const size_t n = (size_t)ws->n, nr = (size_t)ws->n_raw, nnz = (size_t)ws->nnz;
  const size_t mm = (size_t)ws->m_max, big = (mm > n ? mm : n);
  const size_t nvals = ws->dense ? mm * n : nnz;
  int fail = 0;
  ws->trow = alloc(nnz, sizeof(int), &fail);
  ws->tcol = alloc(nnz, sizeof(int), &fail);
  ws->eq_on = alloc((size_t)ws->n_eq, 1, &fail);
  ws->pair_mode = alloc((size_t)ws->n_pair, 1, &fail);
  ws->eq_list = alloc((size_t)ws->n_eq, sizeof(int), &fail);
  ws->pair_pos = alloc((size_t)ws->n_pair, sizeof(int), &fail);
  ws->fb_list = alloc((size_t)ws->n_pair, sizeof(int), &fail);
  ws->act_src = alloc(nnz, sizeof(int), &fail);
  ws->act_wrow = alloc(nnz, sizeof(int), &fail);
  ws->act_tgt = alloc(nnz, sizeof(int), &fail);
  ws->act_r = alloc(nnz, sizeof(int), &fail);
  ws->act_c = alloc(nnz, sizeof(int), &fail);
  ws->sp_p = alloc(big + 1, sizeof(int), &fail);
  ws->sp_i = alloc(nnz, sizeof(int), &fail);
  ws->work = alloc(big + 1 + 2 * nnz, sizeof(int), &fail);
  ws->vals = alloc(nvals, sizeof(double), &fail);
  ws->wgt = alloc(nr, sizeof(double), &fail);
  ws->raw_c = alloc(nr, sizeof(double), &fail);
  ws->raw_t = alloc(nr, sizeof(double), &fail);
  ws->jac_c = alloc(nnz, sizeof(double), &fail);
  ws->F_c = alloc(mm, sizeof(double), &fail);
  ws->F_t = alloc(mm, sizeof(double), &fail);
  ws->zt = alloc(n, sizeof(double), &fail);
  ws->d = alloc(n, sizeof(double), &fail);
  ws->g = alloc(n, sizeof(double), &fail);
  ws->tmp = alloc(big, sizeof(double), &fail);
  ws->z0 = alloc(n, sizeof(double), &fail);
  ws->lb = alloc(n, sizeof(double), &fail);
  ws->ub = alloc(n, sizeof(double), &fail);
  ws->sens_jv = alloc(nnz, sizeof(double), &fail);
  ws->sens_blk = alloc(3 * FESD__SENS_BLOCK * n, sizeof(double), &fail);
  return fail ? FESD_ERR_NOMEM : FESD_OK;
}

static int create_solvers(fesd_ncp *ws) {
  int rc = FESD_OK;
  if (ws->dense) {
    rc = fesd__ls_dense_lu_create(&ws->lu, ws->n);
    if (rc == FESD_OK) rc = fesd__ls_dense_normal_create(&ws->normal, ws->n);
    return rc;
  }
  switch (ws->set.backend) {
  case FESD_NCP_BACKEND_UMFPACK: return fesd__ls_umfpack_create(&ws->lu, ws->n);
  case FESD_NCP_BACKEND_CHOLMOD: return FESD_OK; /* LM only, created with the pattern */
  default: return fesd__ls_klu_create(&ws->lu, ws->n);
  }
}

int fesd_ncp_setup(fesd_ncp **out, const fesd_ncp_problem *p, const fesd_ncp_settings *s) {
  if (!out) return FESD_ERR_NULL;
  *out = NULL;
  if (!p || !p->eval) return FESD_ERR_NULL;
  if (p->n < 1 || p->n_eq < 0 || p->n_pair < 0 || p->nnz < 0) return FESD_ERR_DIMENSION;
  if (p->nnz > 0 && (!p->row || !p->col)) return FESD_ERR_NULL;
  fesd_ncp_settings set;
  if (s) {
    set = *s;
  } else {
    fesd_ncp_settings_default(&set);
  }
  if (validate_settings(&set) != FESD_OK) return FESD_ERR_INVALID_ARG;

  long long n_raw = (long long)p->n_eq + 2LL * p->n_pair;
  if (n_raw > INT_MAX / 2) return FESD_ERR_DIMENSION;
  for (int t = 0; t < p->nnz; t++)
    if (p->row[t] < 0 || p->row[t] >= n_raw || p->col[t] < 0 || p->col[t] >= p->n)
      return FESD_ERR_PATTERN;
  /* the default selection (all rows, all pairs FB) must not be under-determined */
  if ((long long)p->n_eq + p->n_pair < p->n) return FESD_ERR_DIMENSION;

  int dense = set.backend == FESD_NCP_BACKEND_DENSE ||
              (set.backend == FESD_NCP_BACKEND_AUTO && p->n <= set.dense_max_n);
  if (dense && n_raw * p->n > INT_MAX) return FESD_ERR_DIMENSION; /* int positions */

  fesd_ncp *ws = calloc(1, sizeof *ws);
  if (!ws) return FESD_ERR_NOMEM;
  ws->n = p->n;
  ws->n_eq = p->n_eq;
  ws->n_pair = p->n_pair;
  ws->nnz = p->nnz;
  ws->n_raw = (int)n_raw;
  ws->m_max = (int)n_raw;
  ws->eval = p->eval;
  ws->user = p->user;
  ws->set = set;
  ws->dense = dense;

  int rc = allocate(ws);
  if (rc == FESD_OK) rc = create_solvers(ws);
  if (rc != FESD_OK) {
    fesd_ncp_free(&ws);
    return rc;
  }
  if (ws->nnz) {
    memcpy(ws->trow, p->row, (size_t)ws->nnz * sizeof(int));
    memcpy(ws->tcol, p->col, (size_t)ws->nnz * sizeof(int));
  }
  memset(ws->eq_on, 1, (size_t)ws->n_eq);
  memset(ws->pair_mode, FESD_NCP_PAIR_FB, (size_t)ws->n_pair);
  for (int i = 0; i < ws->n; i++) {
    ws->lb[i] = -INFINITY;
    ws->ub[i] = INFINITY;
  }
  /* The default selection is analysed at its first use: callers that select their own rows
   * first (the integrator always does) never pay for it (measured: the CHOLMOD analysis of
   * the over-determined default took 2.8 s of the creation of the friction chain n = 1024). */
  ws->rows_pending = 1;
  ws->m = ws->n_eq + ws->n_pair;
  *out = ws;
  return FESD_OK;
}

int fesd_ncp_update_settings(fesd_ncp *ws, const fesd_ncp_settings *s) {
  if (!ws || !s) return FESD_ERR_NULL;
  if (validate_settings(s) != FESD_OK) return FESD_ERR_INVALID_ARG;
  fesd_ncp_settings keep = ws->set;
  ws->set = *s;
  ws->set.backend = keep.backend;
  ws->set.dense_max_n = keep.dense_max_n;
  return FESD_OK;
}

int fesd_ncp_set_rows(fesd_ncp *ws, const unsigned char *eq_active,
                      const unsigned char *pair_mode) {
  if (!ws) return FESD_ERR_NULL;
  int m = 0, same = ws->ready && !ws->rows_pending;
  for (int e = 0; e < ws->n_eq; e++) {
    unsigned char on = eq_active ? (eq_active[e] != 0) : 1;
    m += on;
    same = same && on == ws->eq_on[e];
  }
  for (int k = 0; k < ws->n_pair; k++) {
    unsigned char md = pair_mode ? pair_mode[k] : FESD_NCP_PAIR_FB;
    if (md > FESD_NCP_PAIR_B) return FESD_ERR_INVALID_ARG;
    m += md == FESD_NCP_PAIR_PIN ? 2 : md == FESD_NCP_PAIR_OFF ? 0 : 1;
    same = same && md == ws->pair_mode[k];
  }
  if (m < ws->n) return FESD_ERR_DIMENSION; /* the previous selection stays in force */
  if (same && !ws->border_dirty) return FESD_OK;
  /* A and B assemble the same row with the same entries (rows.c, assembled_row): a selection
   * that only flips pairs between them (an active-set change of the integrator) keeps the
   * pattern, its maps and the solver's analysis (measured: 93 of 113 selections of the
   * stick-slip chain, n = 128; rebuilding them cost 7.5 % of its instructions). */
  int keep = ws->ready && !ws->rows_pending && !ws->border_dirty;
  for (int e = 0; e < ws->n_eq && keep; e++) keep = (eq_active ? (eq_active[e] != 0) : 1) == ws->eq_on[e];
  for (int k = 0; k < ws->n_pair && keep; k++) {
    const unsigned char md = pair_mode ? pair_mode[k] : FESD_NCP_PAIR_FB, old = ws->pair_mode[k];
    const int ab = (md == FESD_NCP_PAIR_A || md == FESD_NCP_PAIR_B) && (old == FESD_NCP_PAIR_A || old == FESD_NCP_PAIR_B);
    keep = md == old || (ab && (!ws->nb || ws->raw_border[ws->n_eq + k] == ws->raw_border[ws->n_eq + ws->n_pair + k]));
  }
  ws->rows_pending = 0;
  for (int e = 0; e < ws->n_eq; e++) ws->eq_on[e] = eq_active ? (eq_active[e] != 0) : 1;
  for (int k = 0; k < ws->n_pair; k++)
    ws->pair_mode[k] = pair_mode ? pair_mode[k] : FESD_NCP_PAIR_FB;
  return fesd__ncp_apply_rows(ws, keep);
}

int fesd_ncp_set_bounds(fesd_ncp *ws, const double *lb, const double *ub) {
  if (!ws) return FESD_ERR_NULL;
  for (int i = 0; i < ws->n; i++) {
    double l = lb ? lb[i] : -INFINITY, u = ub ? ub[i] : INFINITY;
    if (isnan(l) || isnan(u) || l > u) return FESD_ERR_INVALID_ARG;
  }
  for (int i = 0; i < ws->n; i++) {
    ws->lb[i] = lb ? lb[i] : -INFINITY;
    ws->ub[i] = ub ? ub[i] : INFINITY;
  }
  ws->has_box = lb || ub;
  return FESD_OK;
}

int fesd_ncp_set_border(fesd_ncp *ws, const unsigned char *raw_border, const unsigned char *col_border) {
  if (!ws) return FESD_ERR_NULL;
  /* only the KLU backend uses a border: the others allocate nothing for it */
  if (!raw_border || !col_border || !ws->lu || ws->lu->backend != FESD_NCP_BACKEND_KLU) {
    ws->border_dirty |= ws->nb > 0;
    ws->nb = 0;
    return FESD_OK;
  }
  if (!ws->raw_border) {
    ws->raw_border = malloc((size_t)ws->n_raw);
    ws->col_border = malloc((size_t)ws->n);
    ws->row_border = malloc((size_t)ws->m_max);
    if (!ws->raw_border || !ws->col_border || !ws->row_border) {
      free(ws->raw_border), free(ws->col_border), free(ws->row_border);
      ws->raw_border = ws->col_border = ws->row_border = NULL;
      return fesd__ncp_note(ws, FESD_ERR_NOMEM);
    }
    memset(ws->raw_border, 0, (size_t)ws->n_raw);
    memset(ws->col_border, 0, (size_t)ws->n);
  }
  int nb = 0, changed = 0;
  for (int j = 0; j < ws->n; j++) {
    const unsigned char f = col_border[j] != 0;
    changed |= f != ws->col_border[j];
    ws->col_border[j] = f;
    nb += f;
  }
  for (int r = 0; r < ws->n_raw; r++) {
    const unsigned char f = raw_border[r] != 0;
    changed |= f != ws->raw_border[r];
    ws->raw_border[r] = f;
  }
  ws->border_dirty |= changed || nb != ws->nb;
  ws->nb = nb;
  return FESD_OK;
}

int fesd_ncp_rows(const fesd_ncp *ws) { return ws ? ws->m : FESD_ERR_NULL; }

const char *fesd_ncp_backend_name(int backend) {
  switch (backend) {
  case FESD_NCP_BACKEND_AUTO: return "auto";
  case FESD_NCP_BACKEND_DENSE: return "dense";
  case FESD_NCP_BACKEND_UMFPACK: return "umfpack";
  case FESD_NCP_BACKEND_KLU: return "klu";
  case FESD_NCP_BACKEND_CHOLMOD: return "cholmod";
  default: return "unknown";
  }
}

int fesd__ncp_nomem_count(const fesd_ncp *ws) { return ws ? ws->nomem : 0; }

void fesd__ncp_defer_analysis(fesd_ncp *ws) { ws->defer = 1; }

int fesd__ncp_set_bound(fesd_ncp *ws, int i, double lo, double hi) {
  if (!ws) return FESD_ERR_NULL;
  if (i < 0 || i >= ws->n || isnan(lo) || isnan(hi) || lo > hi) return FESD_ERR_INVALID_ARG;
  ws->lb[i] = lo;
  ws->ub[i] = hi;
  ws->has_box = 1;
  return FESD_OK;
}
