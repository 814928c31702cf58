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

/* Relative residual of J x = -dF from the raw Jacobian (the dense LU overwrites the
 * assembled values): ||J x + dF||_inf / max_i (sum_j |J_ij x_j| + |dF_i|); the residual is
 * left in ws->d. */
static double check(fesd_ncp *ws, const double *x, const double *dF) {
  double *r = ws->d, *a = ws->g; /* m >= n here: both hold n = m values */
  for (int i = 0; i < ws->m; i++) r[i] = dF[i], a[i] = fabs(dF[i]);
  for (int k = 0; k < ws->n_act; k++) {
    const double v = ws->wgt[ws->act_wrow[k]] * ws->jac_c[ws->act_src[k]] * x[ws->act_c[k]];
    r[ws->act_r[k]] += v;
    a[ws->act_r[k]] += fabs(v);
  }
  double num = 0.0, den = 0.0;
  for (int i = 0; i < ws->m; i++) {
    num = fabs(r[i]) > num ? fabs(r[i]) : num;
    den = a[i] > den ? a[i] : den;
  }
  return den > 0.0 ? num / den : num;
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

  fesd__ls *ls = ws->active;
  const int lu = ls->ops->kind == FESD__LS_LU, n = ws->n;
  double t0 = fesd__wall_time();
  rc = ls->ops->factor(ls, ws->vals, 0.0); /* least squares for m > n: mu = 0 */
  st->factorizations++;
  ws->sens_residual = 0.0;
  ws->sens_ferr = 0.0;
  for (int j = 0; j < nrhs && rc == FESD_OK; j++) {
    double *x = dz_dp + (size_t)j * n;
    chain_rule(ws, draw_dp + (size_t)j * ws->n_raw, ws->F_t);
    if (lu) {
      for (int i = 0; i < n; i++) x[i] = -ws->F_t[i];
    } else { /* J is intact for the normal-equation objects */
      fesd__ncp_jt_mul(ws, ws->F_t, x);
      for (int i = 0; i < n; i++) x[i] = -x[i];
    }
    rc = ls->ops->solve(ls, x);
    if (rc == FESD_OK && !fesd__all_finite(x, n)) rc = FESD_ERR_SINGULAR;
    if (rc != FESD_OK || !lu) continue;
    /* A solve is only as good as the factorization (a refactorization with an unsuited pivot
     * order gave sensitivities off by 1e6 with a plausible-looking matrix): check J x + dF
     * against the size of its terms, refine once, and report what remains. */
    double rel = check(ws, x, ws->F_t);
    /* One step of iterative refinement, always: its correction d = J^-1 (-r) is about
     * cond(J) eps |x| when the residual r is at round-off level, so |d| / |x| estimates the
     * forward error that a small residual hides in a badly conditioned system (measured: a
     * sliding exit where the residual was 1e-16 and dx/dx0 was 15 % off). */
    for (int i = 0; i < ws->m; i++) ws->tmp[i] = -ws->d[i];
    rc = ls->ops->solve(ls, ws->tmp);
    if (rc != FESD_OK) continue;
    double dmax = 0, xmax = 0;
    for (int i = 0; i < n; i++) {
      dmax = fmax(dmax, fabs(ws->tmp[i]));
      xmax = fmax(xmax, fabs(x[i]));
      x[i] += ws->tmp[i];
    }
    if (rel > REFINE_ABOVE) rel = check(ws, x, ws->F_t);
    const double ferr = xmax > 0 ? dmax / xmax : dmax;
    if (!(ferr <= ws->sens_ferr)) ws->sens_ferr = ferr;
    if (!(rel <= ws->sens_residual)) ws->sens_residual = rel; /* NaN propagates */
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
