/* Row selection: assembled row order, chain-rule weights, the map from each raw
 * Jacobian entry to its position in the assembled matrix, and the symbolic
 * analysis of the linear solver for the resulting pattern. */
#include "ncp/ncp_internal.h"

#include <string.h>

/* Sort the entries (r[t], c[t]) of an nrows x ncols matrix into CSC form (rows
 * ascending within a column, duplicates merged, as UMFPACK/KLU/CHOLMOD require);
 * tgt[t] receives the position of entry t. Two stable counting sorts (by row,
 * then by column), so the cost is linear. work: max(nrows, ncols) + 1 + 2 ne. */
static void build_csc(int nrows, int ncols, int ne, const int *r, const int *c, int *p, int *idx,
                      int *tgt, int *work) {
  int *cnt = work;
  int *by_row = work + (nrows > ncols ? nrows : ncols) + 1;
  int *by_col = by_row + ne;

  memset(cnt, 0, ((size_t)nrows + 1) * sizeof *cnt);
  for (int t = 0; t < ne; t++) cnt[r[t] + 1]++;
  for (int i = 0; i < nrows; i++) cnt[i + 1] += cnt[i];
  for (int t = 0; t < ne; t++) by_row[cnt[r[t]]++] = t;

  memset(p, 0, ((size_t)ncols + 1) * sizeof *p);
  for (int t = 0; t < ne; t++) p[c[t] + 1]++;
  for (int j = 0; j < ncols; j++) p[j + 1] += p[j];
  memcpy(cnt, p, (size_t)ncols * sizeof *cnt);
  for (int k = 0; k < ne; k++) {
    int t = by_row[k];
    by_col[cnt[c[t]]++] = t;
  }

  int k = 0, nz = 0;
  for (int j = 0; j < ncols; j++) {
    int end = p[j + 1], first = nz;
    p[j] = nz;
    for (; k < end; k++) {
      int t = by_col[k];
      if (nz > first && idx[nz - 1] == r[t]) {
        tgt[t] = nz - 1;
      } else {
        idx[nz] = r[t];
        tgt[t] = nz++;
      }
    }
  }
  p[ncols] = nz;
}

/* Assembled row of raw row rr under the current selection, or -1. */
static int assembled_row(const fesd_ncp *ws, const int *eq_pos, int rr) {
  if (rr < ws->n_eq) return ws->eq_on[rr] ? eq_pos[rr] : -1;
  int k = rr - ws->n_eq, second = 0;
  if (k >= ws->n_pair) {
    k -= ws->n_pair;
    second = 1;
  }
  switch (ws->pair_mode[k]) {
  case FESD_NCP_PAIR_FB: return ws->pair_pos[k];
  case FESD_NCP_PAIR_PIN: return ws->pair_pos[k] + second;
  /* A and B keep the entries of both members (the unused one with weight 0): the pattern of a
   * pair row is then the same in every mode, so a change of active set is no new pattern for
   * the sparse LU (no new analysis: measured, the max transversal of each new pattern took 20 %
   * of a friction chain with many switches) */
  case FESD_NCP_PAIR_A:
  case FESD_NCP_PAIR_B: return ws->pair_pos[k];
  default: return -1;
  }
}

/* Border flags of the assembled rows of the current selection (from the raw rows they come
 * from); returns their count. */
static int border_rows(fesd_ncp *ws) {
  const int n_eq = ws->n_eq, np = ws->n_pair;
  int i = 0, cnt = 0;
  for (int j = 0; j < ws->n_eq_on; j++) cnt += ws->row_border[i++] = ws->raw_border[ws->eq_list[j]];
  for (int k = 0; k < np; k++) {
    const unsigned char a = ws->raw_border[n_eq + k], b = ws->raw_border[n_eq + np + k];
    switch (ws->pair_mode[k]) {
    case FESD_NCP_PAIR_FB: cnt += ws->row_border[i++] = a || b; break;
    case FESD_NCP_PAIR_PIN:
      cnt += ws->row_border[i++] = a;
      cnt += ws->row_border[i++] = b;
      break;
    case FESD_NCP_PAIR_A: cnt += ws->row_border[i++] = a; break;
    case FESD_NCP_PAIR_B: cnt += ws->row_border[i++] = b; break;
    default: break;
    }
  }
  return cnt;
}

int fesd__ncp_ensure_rows(fesd_ncp *ws) {
  if (ws->rows_pending) {
    ws->rows_pending = 0;
    return fesd__ncp_apply_rows(ws, 0);
  }
  return ws->ready ? FESD_OK : FESD_ERR_NOT_READY;
}

/* The assembly maps, the sparse pattern and the solver's analysis of the selection. */
static int apply_pattern(fesd_ncp *ws, const int *eq_pos) {
  const int n = ws->n;
  ws->n_act = 0;
  for (int t = 0; t < ws->nnz; t++) {
    int ar = assembled_row(ws, eq_pos, ws->trow[t]);
    if (ar < 0) continue;
    int a = ws->n_act++;
    ws->act_src[a] = t;
    ws->act_wrow[a] = ws->trow[t];
    ws->act_r[a] = ar;
    ws->act_c[a] = ws->tcol[t];
  }
  int rc;
  switch (ws->active->ops->layout) {
  case FESD__LAYOUT_DENSE:
    for (int a = 0; a < ws->n_act; a++) ws->act_tgt[a] = ws->act_r[a] + ws->act_c[a] * ws->m;
    ws->nvals = ws->m * n;
    /* the dense normal object also serves as the square fallback: keep both current */
    rc = ws->lu->ops->analyze(ws->lu, ws->m, NULL, NULL);
    if (rc == FESD_OK) rc = ws->normal->ops->analyze(ws->normal, ws->m, NULL, NULL);
    break;
  case FESD__LAYOUT_CSC:
    build_csc(ws->m, n, ws->n_act, ws->act_r, ws->act_c, ws->sp_p, ws->sp_i, ws->act_tgt,
              ws->work);
    ws->nvals = ws->sp_p[n];
    rc = ws->active->ops->analyze(ws->active, ws->m, ws->sp_p, ws->sp_i);
    break;
  default: /* CSC of J' */
    build_csc(n, ws->m, ws->n_act, ws->act_c, ws->act_r, ws->sp_p, ws->sp_i, ws->act_tgt,
              ws->work);
    ws->nvals = ws->sp_p[ws->m];
    rc = ws->active->ops->analyze(ws->active, ws->m, ws->sp_p, ws->sp_i);
    break;
  }
  return fesd__ncp_note(ws, rc);
}

int fesd__ncp_ensure_pattern(fesd_ncp *ws) {
  if (!ws->pattern_pending) return FESD_OK;
  /* eq_pos of the selection, as apply_rows made it (scratch: read before build_csc uses work) */
  int *eq_pos = ws->work;
  for (int j = 0; j < ws->n_eq_on; j++) eq_pos[ws->eq_list[j]] = j;
  int rc = apply_pattern(ws, eq_pos);
  ws->pattern_pending = rc != FESD_OK; /* a failed analysis is tried again at the next use */
  return rc;
}

int fesd__ncp_apply_rows(fesd_ncp *ws, int keep_pattern) {
  const int n = ws->n, n_eq = ws->n_eq, np = ws->n_pair;
  int *eq_pos = ws->work; /* scratch, consumed before build_csc reuses work */
  int i = 0;

  ws->ready = 0;
  ws->n_eq_on = 0;
  for (int e = 0; e < n_eq; e++) {
    ws->wgt[e] = ws->eq_on[e] ? 1.0 : 0.0;
    if (ws->eq_on[e]) {
      eq_pos[e] = i++;
      ws->eq_list[ws->n_eq_on++] = e;
    }
  }
  ws->n_fb = 0;
  for (int k = 0; k < np; k++) {
    double wa = 0.0, wb = 0.0;
    ws->pair_pos[k] = -1;
    if (ws->pair_mode[k] == FESD_NCP_PAIR_FB) {
      ws->pair_pos[k] = i++;
      ws->fb_list[ws->n_fb++] = k;
    } else if (ws->pair_mode[k] == FESD_NCP_PAIR_PIN) {
      ws->pair_pos[k] = i;
      i += 2;
      wa = wb = 1.0;
    } else if (ws->pair_mode[k] == FESD_NCP_PAIR_A) {
      ws->pair_pos[k] = i++;
      wa = 1.0;
    } else if (ws->pair_mode[k] == FESD_NCP_PAIR_B) {
      ws->pair_pos[k] = i++;
      wb = 1.0;
    }
    ws->wgt[n_eq + k] = wa; /* FB weights are refreshed at every assembly */
    ws->wgt[n_eq + np + k] = wb;
  }
  ws->m = i;

  /* Square systems use the LU object when there is one (the bordered KLU when a border is
   * set and the selection has as many border rows as border columns); otherwise LM. */
  if (ws->m == n && ws->lu) {
    ws->active = ws->lu;
    ws->border_dirty = 0;
    if (ws->nb > 0 && ws->lu->backend == FESD_NCP_BACKEND_KLU && border_rows(ws) == ws->nb) {
      /* the crossover was measured at 60-80 unknowns (oscillator switch steps); the cap keeps a
       * raised dense_max_n from giving n^2 arrays far beyond that (10,000 unknowns: 800 MB) */
      const int small = ws->set.backend == FESD_NCP_BACKEND_AUTO && n <= 2 * ws->set.dense_max_n &&
                        n <= FESD_NCP_BDENSE_MAX_N;
      if (!ws->border) {
        int rc = small ? fesd__ls_bdense_create(&ws->border, n, ws->nnz) : fesd__ls_border_create(&ws->border, n, ws->nb);
        if (rc != FESD_OK) return rc;
      }
      if (small) fesd__ls_bdense_flags(ws->border, ws->row_border, ws->col_border);
      else fesd__ls_border_flags(ws->border, ws->row_border, ws->col_border);
      ws->active = ws->border;
    }
  } else {
    if (!ws->normal) {
      int rc = fesd__ncp_note(ws, fesd__ls_cholmod_create(&ws->normal, n));
      if (rc != FESD_OK) return rc;
    }
    ws->active = ws->normal;
  }

  /* deferred: the pattern and its analysis wait for the first Jacobian (a solve that starts
   * converged, and the residual, need only the row order) */
  if (keep_pattern) { /* pattern_pending stays as it was */
    ws->ready = 1;
    return FESD_OK;
  }
  ws->pattern_pending = ws->defer;
  int rc = ws->defer ? FESD_OK : apply_pattern(ws, eq_pos);
  ws->ready = rc == FESD_OK;
  return rc;
}
