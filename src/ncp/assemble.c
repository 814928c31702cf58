/* Assembly of the FB system from the raw rows: residual, chain-rule weights,
 * Jacobian values through the precomputed maps, and products with J and J'. */
#include "ncp/fb.h"
#include "ncp/ncp_internal.h"

#include <math.h>
#include <string.h>

int fesd__all_finite(const double *x, int n) {
  /* x*0 is NaN exactly for NaN/Inf: one branch-free pass, four independent sums so that
   * the additions pipeline (this runs on every residual and Jacobian the solver sees) */
  double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
  int i = 0;
  for (; i + 3 < n; i += 4) {
    a0 += x[i] * 0.0;
    a1 += x[i + 1] * 0.0;
    a2 += x[i + 2] * 0.0;
    a3 += x[i + 3] * 0.0;
  }
  for (; i < n; i++) a0 += x[i] * 0.0;
  return a0 + a1 + a2 + a3 == 0.0;
}

void fesd__ncp_residual(const fesd_ncp *ws, const double *raw, double sigma, double *F) {
  const double *ra = raw + ws->n_eq, *rb = ra + ws->n_pair;
  int i = 0;
  for (int j = 0; j < ws->n_eq_on; j++) F[i++] = raw[ws->eq_list[j]];
  for (int k = 0; k < ws->n_pair; k++) {
    double da, db;
    switch (ws->pair_mode[k]) {
    case FESD_NCP_PAIR_FB: F[i++] = fesd__fb(ra[k], rb[k], sigma, &da, &db); break;
    case FESD_NCP_PAIR_PIN:
      F[i++] = ra[k];
      F[i++] = rb[k];
      break;
    case FESD_NCP_PAIR_A: F[i++] = ra[k]; break;
    case FESD_NCP_PAIR_B: F[i++] = rb[k]; break;
    default: break;
    }
  }
}

void fesd__ncp_weights(fesd_ncp *ws, const double *raw, double sigma) {
  const int na = ws->n_eq, nb = ws->n_eq + ws->n_pair;
  for (int j = 0; j < ws->n_fb; j++) {
    int k = ws->fb_list[j];
    (void)fesd__fb(raw[na + k], raw[nb + k], sigma, &ws->wgt[na + k], &ws->wgt[nb + k]);
  }
}

void fesd__ncp_jacobian(fesd_ncp *ws, const double *jac) {
  double *v = ws->vals;
  const int *tgt = ws->act_tgt, *src = ws->act_src, *wr = ws->act_wrow;
  const double *w = ws->wgt;
  memset(v, 0, (size_t)ws->nvals * sizeof *v);
  for (int a = 0; a < ws->n_act; a++) v[tgt[a]] += w[wr[a]] * jac[src[a]];
}

void fesd__ncp_jt_mul(const fesd_ncp *ws, const double *x, double *y) {
  const int n = ws->n, m = ws->m, *p = ws->sp_p, *ri = ws->sp_i;
  const double *v = ws->vals;
  switch (ws->active->ops->layout) {
  case FESD__LAYOUT_DENSE: /* plain loops: BLAS call overhead dominates small n */
    for (int j = 0; j < n; j++) {
      const double *cj = v + (size_t)j * m;
      double s = 0.0;
      for (int i = 0; i < m; i++) s += cj[i] * x[i];
      y[j] = s;
    }
    break;
  case FESD__LAYOUT_CSC:
    for (int j = 0; j < n; j++) {
      double s = 0.0;
      for (int k = p[j]; k < p[j + 1]; k++) s += v[k] * x[ri[k]];
      y[j] = s;
    }
    break;
  default:
    memset(y, 0, (size_t)n * sizeof *y);
    for (int i = 0; i < m; i++)
      for (int k = p[i]; k < p[i + 1]; k++) y[ri[k]] += v[k] * x[i];
    break;
  }
}

void fesd__ncp_j_mul(const fesd_ncp *ws, const double *x, double *y) {
  const int n = ws->n, m = ws->m, *p = ws->sp_p, *ri = ws->sp_i;
  const double *v = ws->vals;
  switch (ws->active->ops->layout) {
  case FESD__LAYOUT_DENSE:
    memset(y, 0, (size_t)m * sizeof *y);
    for (int j = 0; j < n; j++) {
      const double *cj = v + (size_t)j * m, xj = x[j];
      for (int i = 0; i < m; i++) y[i] += cj[i] * xj;
    }
    break;
  case FESD__LAYOUT_CSC:
    memset(y, 0, (size_t)m * sizeof *y);
    for (int j = 0; j < n; j++)
      for (int k = p[j]; k < p[j + 1]; k++) y[ri[k]] += v[k] * x[j];
    break;
  default:
    for (int i = 0; i < m; i++) {
      double s = 0.0;
      for (int k = p[i]; k < p[i + 1]; k++) s += v[k] * x[ri[k]];
      y[i] = s;
    }
    break;
  }
}

double fesd__ncp_frobenius(const fesd_ncp *ws) {
  double s = 0.0;
  for (int k = 0; k < ws->nvals; k++) s += ws->vals[k] * ws->vals[k];
  return sqrt(s);
}
