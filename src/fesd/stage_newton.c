/* Stage Newton of the guess (guess.c): the smooth collocation system of one element with its
 * multipliers theta fixed, solved with a small dense LU. The factorization is kept with the
 * inputs it was made from (h and sum_i theta_j,i df_i/dx at x_n per stage): an element whose
 * inputs are bit for bit the same (the next element or step of a field that is linear in x,
 * with the same h and active modes) reuses it, so results are exactly what a new
 * factorization would give (a retried step too). */
#include <math.h>
#include <string.h>

#include "common/dense_lu.h"
#include "fesd/step.h"

/* Stage j > 0 of element n has the theta of the stage before (its key block and residual
 * are then the same). */
static int same_theta(const fesd__system *S, const double *z, int n, int j) {
  if (j == 0) return 0;
  const double *th = z + fesd__th(S, n, j), *tp = th - S->sb;
  for (int i = 0; i < S->nth; i++)
    if (th[i] != tp[i]) return 0;
  return 1;
}

/* Key of the stage matrix of element n (h, then J_j = sum_i theta_j,i df_i/dx at x_n for each
 * stage j on the union pattern) into it->gn_key; its LU is in it->gn when it equals the key
 * of the factorization kept (it->gn_memo). Returns 1 on a failed evaluation. */
static int stage_key(fesd_integrator *it, const double *z, int n, const double *xn, double h, double tn,
                     fesd__point_eval *pj) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nnz = m->pf_nnz;
  /* x_n of a later element is the last stage point of the one before when c_s = 1: its
   * record (evaluated in full by the guess) holds the fields and Jacobians there */
  const fesd__point_eval *rec = n > 0 ? fesd__system_record(S, n * S->s - 1, tn, xn, 2) : NULL;
  if (rec) {
    if (pj->F) memcpy(pj->F, rec->F, (size_t)m->nF * sizeof(double));
    memcpy(pj->dFdx, rec->dFdx, (size_t)m->ndF * sizeof(double));
  } else if (fesd__model_eval(m, tn, xn, S->u, pj)) {
    return 1;
  }
  if (n == 0 && pj->F && xn == S->x0 && tn == S->t0) { /* the fields at the step start, for the */
    memcpy(it->f0, pj->F, (size_t)m->nF * sizeof(double)); /* error estimate's f_0 (error.c) */
    it->f0_ok = 1;
  }
  it->gn_key[0] = h;
  for (int j = 0; j < S->s; j++) {
    double *J = it->gn_key + 1 + (size_t)j * nnz;
    if (same_theta(S, z, n, j)) /* no switch between the stages: the J before */
      for (int e = 0; e < nnz; e++) J[e] = J[e - nnz];
    else
      fesd__Jth(m, pj, z + fesd__th(S, n, j), J);
  }
  return 0;
}

/* M = I - h (A (x) J_j), J_j per stage row (from the key), factored; the key is kept with it.
 * Returns 1 if M is singular. */
static int stage_factor(fesd_integrator *it) {
  fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  const int nx = S->nx, s = S->s, q = s * nx, nnz = m->pf_nnz, nk = 1 + s * nnz;
  double *M = it->gn, *Jd = M + (size_t)q * q + 2 * (size_t)q;
  const double h = it->gn_key[0];
  if (it->gn_memo_ok && !memcmp(it->gn_key, it->gn_memo, (size_t)nk * sizeof(double))) return 0;
  it->gn_memo_ok = 0;
  memset(M, 0, (size_t)q * q * sizeof(double));
  for (int j = 0; j < s; j++) {
    const double *J = it->gn_key + 1 + (size_t)j * nnz;
    memset(Jd, 0, (size_t)nx * nx * sizeof(double));
    for (int e = 0; e < nnz; e++) Jd[m->pf_r[e] * nx + m->pf_c[e]] += J[e];
    for (int l = 0; l < s; l++) {
      const double a = h * S->tab.A[j][l];
      double *Mc = M + (size_t)l * nx * q + j * nx; /* column l nx + c, rows j nx + r */
      for (int c = 0; c < nx; c++, Mc += q)
        for (int r = 0; r < nx; r++) Mc[r] = -a * Jd[r * nx + c];
    }
  }
  for (int d = 0; d < q; d++) M[(size_t)d * q + d] += 1.0;
  if (fesd__dense_lu(q, M, it->gn_piv)) return 1;
  memcpy(it->gn_memo, it->gn_key, (size_t)nk * sizeof(double));
  it->gn_memo_ok = 1;
  return 0;
}

/* For systems of at most FESD__GN_MAX stage unknowns (s nx): with theta fixed the stage
 * equations v_j = F(X_j) theta_j are smooth; Newton with the matrix I - h A (x) J_j,
 * J_j = sum_i theta_j,i df_i/dx at x_n (one dense LU per element, or the one kept), converges
 * in 1-3 iterations from the warm start, also for stiff fields, where the fixed-point sweeps
 * need 8-16 passes or diverge. Returns 0 when the stage residual is at round-off level
 * (1e-14 of the stage derivatives), 1 otherwise (v is then left as it was: the sweeps take
 * over). A warm start that solved the last element as it was (it->gn_warm: a field constant
 * in x) is checked before any Jacobian and costs s evaluations when it holds; otherwise
 * Newton starts from V = 0 (below), and from the warm start when that does not converge (776
 * of 24,189 such elements in the test suite converged so, as before the start from V = 0).
 * The stage states of the last pass stay in S->X + (n s + j) nx. */
int fesd__stage_newton(fesd_integrator *it, double *z, int n, const double *xn, double h, double tn) {
  fesd__system *S = &it->sys;
  fesd__model *m = &it->model;
  const int nx = S->nx, s = S->s, q = s * nx;
  if (!it->gn || q > FESD__GN_MAX || S->tab.is_explicit) return 1;
  double *G = it->gn + (size_t)q * q, *V0 = G + q;
  for (int j = 0; j < s; j++) memcpy(V0 + j * nx, z + fesd__v(S, n, j), (size_t)nx * sizeof(double));
  double gprev = INFINITY;
  int factored = 0;
  fesd__point_eval pj = {0};
  pj.dFdx = it->pscr.dFdx;
  const int predict = !it->gn_warm;
  int from_warm = 1; /* set to 0 when the start from V = 0 is taken */
  if (predict) pj.F = it->pscr.F;
  if (predict && !stage_key(it, z, n, xn, h, tn, &pj) && !stage_factor(it)) {
    /* Unless the warm start solved the last element as it was: start with the Newton step
     * from V = 0, where every stage point is x_n, so its residual is -F(x_n) theta_j and its
     * Jacobian the key's (one evaluation at x_n instead of s at the warm start's stage points;
     * exact for a field linear in x, and O(h^2) off for a smooth one where the warm start,
     * the last stage's v, is O(h) off). A failed key or factorization leaves the warm start,
     * which may hold without one. */
    factored = 1;
    from_warm = 0;
    for (int j = 0; j < s; j++) { /* the residual at V = 0: -F(x_n) theta_j (the stage before's if the same) */
      double *g = G + j * nx;
      if (same_theta(S, z, n, j)) {
        memcpy(g, g - nx, (size_t)nx * sizeof(double));
        continue;
      }
      const double *th = z + fesd__th(S, n, j);
      memset(g, 0, (size_t)nx * sizeof(double));
      for (int i = 0; i < S->nth; i++)
        if (th[i] != 0.0) fesd__F_axpy(m, &pj, i, -th[i], g);
    }
    fesd__dense_lu_solve(q, it->gn, it->gn_piv, G);
    for (int j = 0; j < s; j++) {
      double *v = z + fesd__v(S, n, j);
      for (int r = 0; r < nx; r++) v[r] = -G[j * nx + r];
    }
  }
again:
  for (int iter = 0; iter < 6; iter++) {
    double gmax = 0, vmax = 0;
    /* the pass that converged last time is evaluated in full into the stage records: when it
     * converges again, the LP rows and the weights find every point there (guess.c) */
    const int full = iter >= it->gn_full_at;
    for (int j = 0; j < s; j++) {
      const double *v = z + fesd__v(S, n, j), *th = z + fesd__th(S, n, j), tj = tn + S->tab.c[j] * h;
      double *X = S->X + (size_t)(n * s + j) * nx; /* kept for the LP rows */
      double *K = S->JK + (size_t)(n * s + j) * nx; /* K_j = sum_l a_jl v_l (fesd__system_points_adopt) */
      for (int r = 0; r < nx; r++) {
        double acc = 0;
        for (int l = 0; l < s; l++) acc += S->tab.A[j][l] * z[fesd__v(S, n, l) + r];
        K[r] = acc;
        X[r] = xn[r] + h * acc;
      }
      const fesd__point_eval *pf = full ? fesd__system_stage_eval(S, n * s + j, tj, X, 1) : NULL;
      fesd__point_eval pe = {0};
      if (!pf) { /* the fields alone (also when a Jacobian or switch callback failed there) */
        pe.F = it->pscr.F;
        if (fesd__model_fields_active(m, tj, X, S->u, pe.F, th)) { /* the sweeps report it */
          from_warm = 1;
          goto restore;
        }
        pf = &pe;
      }
      double *g = G + j * nx;
      fesd__stage_residual(m, pf, v, th, g);
      for (int r = 0; r < nx; r++) {
        gmax = fesd__fmax(gmax, fabs(g[r]));
        vmax = fesd__fmax(vmax, fabs(v[r]));
      }
    }
    if (!(gmax <= 1e300)) break; /* NaN or overflow: the sweeps decide */
    if (gmax <= 1e-14 * vmax || gmax == 0.0) {
      it->gn_full_at = iter;
      /* a prediction that reproduced the warm start (a constant field): check it first next */
      int warm = iter == 0;
      for (int j = 0; j < s && warm && predict; j++)
        warm = !memcmp(V0 + j * nx, z + fesd__v(S, n, j), (size_t)nx * sizeof(double));
      it->gn_warm = warm;
      return 0;
    }
    if (gmax > 0.5 * gprev) break; /* not converging like Newton */
    gprev = gmax;
    if (!factored && (stage_key(it, z, n, xn, h, tn, &pj) || stage_factor(it))) break;
    factored = 1;
    fesd__dense_lu_solve(q, it->gn, it->gn_piv, G); /* G <- M^{-1} G */
    for (int j = 0; j < s; j++) {
      double *v = z + fesd__v(S, n, j);
      for (int r = 0; r < nx; r++) v[r] -= G[j * nx + r];
    }
  }
restore:
  for (int j = 0; j < s; j++) memcpy(z + fesd__v(S, n, j), V0 + j * nx, (size_t)nx * sizeof(double));
  if (!from_warm) { /* the start from V = 0 did not converge: Newton from the warm start */
    from_warm = 1;
    gprev = INFINITY;
    goto again;
  }
  return 1;
}
