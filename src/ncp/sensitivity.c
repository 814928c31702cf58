/* Implicit-function sensitivities dz/dp = -J^{-1} dF/dp at a solution, with dF/dp
 * built from the raw-row derivatives by the same FB chain rule as J. */
#include "common/timer.h"
#include "ncp/ncp_internal.h"

#include <math.h>
#include <stddef.h>

/* dF/dp for one parameter: same row order as the residual. */
static void chain_rule(const fesd_ncp *ws, const double *draw, double *dF) {
  const int na = ws->n_eq, nb = ws->n_eq + ws->n_pair;
  int i = 0;
  for (int j = 0; j < ws->n_eq_on; j++) dF[i++] = draw[ws->eq_list[j]];
  for (int k = 0; k < ws->n_pair; k++) {
    if (ws->pair_mode[k] == FESD_NCP_PAIR_FB) {
      dF[i++] = ws->wgt[na + k] * draw[na + k] + ws->wgt[nb + k] * draw[nb + k];
    } else if (ws->pair_mode[k] == FESD_NCP_PAIR_PIN) {
      dF[i++] = draw[na + k];
      dF[i++] = draw[nb + k];
    } else if (ws->pair_mode[k] == FESD_NCP_PAIR_A) {
      dF[i++] = draw[na + k];
    } else if (ws->pair_mode[k] == FESD_NCP_PAIR_B) {
      dF[i++] = draw[nb + k];
    }
  }
}

/* A solve whose relative residual exceeds this gets one step of iterative refinement. */
#define REFINE_ABOVE 1e-12

/* R = dF + J X and A = |dF| + |J| |X| (termwise) for the w (<= 4) columns of a block (leading
 * dimension n = m) from the raw Jacobian's entries (the dense LU overwrites the assembled
 * values), weighted in jv: one pass over the pattern for the block; inlined with a constant w. */
static inline void residual_w(const fesd_ncp *ws, const double *restrict jv, int w, const double *restrict X,
                              double *restrict R, double *restrict A) {
  const size_t n = (size_t)ws->n;
  for (int k = 0; k < ws->n_act; k++) {
    const double j = jv[k];
    const size_t r = (size_t)ws->act_r[k], c = (size_t)ws->act_c[k];
    for (int b = 0; b < w; b++) {
      const double v = j * X[b * n + c];
      R[b * n + r] += v;
      A[b * n + r] += fabs(v);
    }
  }
}

/* Relative residuals of J x = -dF for the w columns of a block:
 * ||J x + dF||_inf / max_i (sum_j |J_ij x_j| + |dF_i|) into rel, the residuals left in R. */
static void check(const fesd_ncp *ws, const double *jv, int w, const double *X, const double *F, double *R,
                  double *A, double *rel) {
  const size_t n = (size_t)ws->n;
  for (size_t i = 0; i < (size_t)w * n; i++) R[i] = F[i], A[i] = fabs(F[i]);
  switch (w) {
  case 4: residual_w(ws, jv, 4, X, R, A); break;
  case 3: residual_w(ws, jv, 3, X, R, A); break;
  case 2: residual_w(ws, jv, 2, X, R, A); break;
  default: residual_w(ws, jv, 1, X, R, A); break;
  }
  for (int b = 0; b < w; b++) {
    double num = 0.0, den = 0.0;
    for (size_t i = b * n; i < (b + 1) * n; i++) {
      num = fabs(R[i]) > num ? fabs(R[i]) : num;
      den = A[i] > den ? A[i] : den;
    }
    rel[b] = den > 0.0 ? num / den : num;
  }
}

int fesd_ncp_sensitivity(fesd_ncp *ws, const double *z, double sigma, int nrhs,
                         const double *draw_dp, double *dz_dp) {
  if (!ws || !z) return FESD_ERR_NULL;
  if (nrhs < 0 || !(sigma >= 0.0) || !isfinite(sigma)) return FESD_ERR_INVALID_ARG;
  if (nrhs > 0 && (!draw_dp || !dz_dp)) return FESD_ERR_NULL;
  int rc_rows = fesd__ncp_ensure_rows(ws);
  if (rc_rows != FESD_OK) return rc_rows;
  if (nrhs == 0) return FESD_OK;
  if ((rc_rows = fesd__ncp_ensure_pattern(ws)) != FESD_OK) return rc_rows;

  fesd__ncp_stats *st = &ws->pending;
  int rc = fesd__ncp_call(ws, z, ws->raw_c, ws->jac_c, st);
  if (rc != FESD_OK) return rc;
  fesd__ncp_weights(ws, ws->raw_c, sigma);
  fesd__ncp_jacobian(ws, ws->jac_c);
  double *jv = ws->sens_jv;
  for (int k = 0; k < ws->n_act; k++) jv[k] = ws->wgt[ws->act_wrow[k]] * ws->jac_c[ws->act_src[k]];

  fesd__ls *ls = ws->active;
  const int lu = ls->ops->kind == FESD__LS_LU, n = ws->n;
  double t0 = fesd__wall_time();
  rc = ls->ops->factor(ls, ws->vals, 0.0); /* least squares for m > n: mu = 0 */
  st->factorizations++;
  ws->sens_residual = 0.0;
  ws->sens_ferr = 0.0;
  /* the right-hand sides in blocks: the solves of a block share their passes over the factors */
  const size_t nb = (size_t)FESD__SENS_BLOCK * n;
  double *F = ws->sens_blk, *R = F + nb, *A = R + nb, rel[FESD__SENS_BLOCK];
  for (int j0 = 0; j0 < nrhs && rc == FESD_OK; j0 += FESD__SENS_BLOCK) {
    const int w = nrhs - j0 < FESD__SENS_BLOCK ? nrhs - j0 : FESD__SENS_BLOCK;
    double *X = dz_dp + (size_t)j0 * n;
    for (int b = 0; b < w; b++) {
      double *x = X + (size_t)b * n;
      if (lu) {
        chain_rule(ws, draw_dp + (size_t)(j0 + b) * ws->n_raw, F + (size_t)b * n);
        for (int i = 0; i < n; i++) x[i] = -F[(size_t)b * n + i];
      } else { /* J is intact for the normal-equation objects */
        chain_rule(ws, draw_dp + (size_t)(j0 + b) * ws->n_raw, ws->F_t);
        fesd__ncp_jt_mul(ws, ws->F_t, x);
        for (int i = 0; i < n; i++) x[i] = -x[i];
      }
    }
    rc = fesd__ls_solve_many(ls, X, w);
    if (rc == FESD_OK && !fesd__all_finite(X, w * n)) rc = FESD_ERR_SINGULAR;
    if (rc != FESD_OK || !lu) continue;
    /* A solve is only as good as the factorization (a refactorization with an unsuited pivot
     * order gave sensitivities off by 1e6 with a plausible-looking matrix): check J x + dF
     * against the size of its terms, refine once, and report what remains. */
    check(ws, jv, w, X, F, R, A, rel);
    /* One step of iterative refinement, always: its correction d = J^-1 (-r) is about
     * cond(J) eps |x| when the residual r is at round-off level, so |d| / |x| estimates the
     * forward error that a small residual hides in a badly conditioned system (measured: a
     * sliding exit where the residual was 1e-16 and dx/dx0 was 15 % off). */
    for (size_t i = 0; i < (size_t)w * n; i++) R[i] = -R[i];
    rc = fesd__ls_solve_many(ls, R, w);
    if (rc != FESD_OK) continue;
    for (int b = 0; b < w; b++) {
      double *x = X + (size_t)b * n, *d = R + (size_t)b * n, dmax = 0, xmax = 0;
      for (int i = 0; i < n; i++) { /* as fmax (a NaN is passed over): no libm call */
        dmax = fabs(d[i]) > dmax ? fabs(d[i]) : dmax;
        xmax = fabs(x[i]) > xmax ? fabs(x[i]) : xmax;
        x[i] += d[i];
      }
      if (rel[b] > REFINE_ABOVE) check(ws, jv, 1, x, F + (size_t)b * n, d, A, rel + b);
      const double ferr = xmax > 0 ? dmax / xmax : dmax;
      if (!(ferr <= ws->sens_ferr)) ws->sens_ferr = ferr;
      if (!(rel[b] <= ws->sens_residual)) ws->sens_residual = rel[b]; /* NaN propagates */
    }
  }
  st->time_linsolve += fesd__wall_time() - t0;
  return fesd__ncp_note(ws, rc);
}

int fesd_ncp_sensitivity_residual(const fesd_ncp *ws, double *rel) {
  if (!ws || !rel) return FESD_ERR_NULL;
  *rel = ws->sens_residual;
  return FESD_OK;
}

int fesd_ncp_sensitivity_error(const fesd_ncp *ws, double *ferr) {
  if (!ws || !ferr) return FESD_ERR_NULL;
  *ferr = ws->sens_ferr;
  return FESD_OK;
}
