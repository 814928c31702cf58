/* Model evaluations at the stage and boundary points of the step system, and the records
 * that let the guess, the row weights and the solver share them (system.h: pc_*, pt_*). */
#include <math.h>
#include <string.h>

#include "fesd/system.h"

/* State at the start of element n (as system.c). */
static const double *elem_start(const fesd__system *S, const double *z, int n) {
  return n == 0 ? S->x0 : z + S->xo[n - 1];
}

void fesd__stage_state(const fesd__system *S, const double *z, int n, int j, double *X) {
  const double *xn = elem_start(S, z, n), h = z[S->ho[n]];
  for (int r = 0; r < S->nx; r++) {
    double acc = 0;
    for (int l = 0; l < S->s; l++) acc += S->tab.A[j][l] * z[fesd__v(S, n, l) + r];
    X[r] = xn[r] + h * acc;
  }
}

/* Look-ahead term of element n's first stage (X = x_n, pe evaluated there with grad g):
 * LK = kappa h grad g . v_1; with want_jac also its derivatives: d/dh (KG), d/dx_n = grad g +
 * kappa h H v_1 (dgl; H v_1 by a forward difference of the switch Jacobian along v_1, exact
 * for affine switching functions) and, with sensitivities, d/du (dgul). */
static int look_ahead(fesd__system *S, const double *z, int n, double tn, const fesd__point_eval *pe,
                      int want_jac) {
  fesd__model *m = S->model;
  const int nx = S->nx, nth = S->nth, nu = S->nu, ndg = m->ndg;
  const double h = z[S->ho[n]], kh = S->kappa * h, *v1 = z + fesd__v(S, n, 0);
  const double *X = S->X + (size_t)n * S->s * nx;
  for (int i = 0; i < nth; i++) {
    const double d = fesd__dg_dot(m, pe, i, v1);
    S->LK[(size_t)n * nth + i] = kh * d;
    if (want_jac) S->KG[(size_t)n * S->s * nth + i] = S->kappa * d;
  }
  if (!want_jac) return FESD_OK;
  double *dgl = S->dgl + (size_t)n * ndg, *dgul = S->dgul + (size_t)n * nth * nu;
  const int want_u = S->want_u && nu > 0;
  memcpy(dgl, pe->dgdx, (size_t)ndg * sizeof(double));
  if (want_u) memcpy(dgul, pe->dgdu, (size_t)nth * nu * sizeof(double));
  double vn = 0, xn = 0;
  for (int r = 0; r < nx; r++) {
    vn = fmax(vn, fabs(v1[r]));
    xn = fmax(xn, fabs(X[r]));
  }
  if (vn == 0.0 || kh == 0.0) return FESD_OK;
  const double delta = 1.5e-8 * fmax(xn, 1e-300) / vn; /* relative step along v_1 */
  for (int r = 0; r < nx; r++) S->xs[r] = X[r] + delta * v1[r];
  fesd__point_eval q = S->pl;
  q.g = NULL;
  if (!want_u) q.dgdu = NULL;
  int st = fesd__model_eval(m, tn, S->xs, S->u, &q);
  if (st) return st;
  const double sc = kh / delta;
  for (int e = 0; e < ndg; e++) dgl[e] += sc * (q.dgdx[e] - pe->dgdx[e]);
  if (want_u)
    for (int e = 0; e < nth * nu; e++) dgul[e] += sc * (q.dgdu[e] - pe->dgdu[e]);
  return FESD_OK;
}

/* Evaluate the model at every stage point (and boundary point) of z. */
/* Same inputs as the last evaluation (with Jacobians if want_jac)? Records them otherwise. */
static int points_cached(fesd__system *S, const double *z, int want_jac) {
  const size_t nz = (size_t)S->n * sizeof(double), nx = (size_t)S->nx * sizeof(double);
  const size_t nu = (size_t)S->nu * sizeof(double);
  if (S->pc_valid && S->pc_jac >= want_jac && S->pc_want_u == S->want_u && S->pc_t0 == S->t0 &&
      !memcmp(S->pc_z, z, nz) && !memcmp(S->pc_xu, S->x0, nx) && (!nu || !memcmp(S->pc_xu + S->nx, S->u, nu)))
    return 1;
  memcpy(S->pc_z, z, nz);
  memcpy(S->pc_xu, S->x0, nx);
  if (nu) memcpy(S->pc_xu + S->nx, S->u, nu);
  S->pc_t0 = S->t0;
  S->pc_want_u = S->want_u;
  S->pc_jac = want_jac;
  S->pc_valid = 0; /* until the evaluation succeeds */
  return 0;
}

void fesd__system_points_reset(fesd__system *S) {
  S->pc_valid = 0;
  memset(S->pt_lvl, 0, (size_t)S->N_cap * S->s);
}

/* Stage point p at (t, X); lk: the look-ahead point (needs grad g without Jacobians; not
 * reused: its level does not say what it holds) */
static int stage_point(fesd__system *S, int p, double t, const double *X, int want_jac, int lk) {
  const int nx = S->nx, need = want_jac ? (S->want_u ? 3 : 2) : 1;
  double *PX = S->pt_X + (size_t)p * nx;
  const size_t su = (size_t)S->nu * sizeof(double);
  if (su && memcmp(S->pt_u, S->u, su)) { /* other controls: no record holds */
    memset(S->pt_lvl, 0, (size_t)S->N_cap * S->s);
    memcpy(S->pt_u, S->u, su);
  }
  if (!lk && S->pt_lvl[p] >= need && S->pt_t[p] == t && !memcmp(PX, X, (size_t)nx * sizeof(double)))
    return FESD_OK;
  fesd__point_eval pe = S->pe[p];
  if (!want_jac) pe.dFdx = NULL;
  if (!want_jac && !lk) pe.dgdx = NULL;
  if (!(want_jac && S->want_u)) pe.dFdu = pe.dgdu = NULL;
  S->pt_lvl[p] = 0;
  int st = fesd__model_eval(S->model, t, X, S->u, &pe);
  if (st) return st;
  memcpy(PX, X, (size_t)nx * sizeof(double));
  S->pt_t[p] = t;
  S->pt_lvl[p] = (signed char)(lk ? 0 : need);
  return FESD_OK;
}

const fesd__point_eval *fesd__system_record(const fesd__system *S, int p, double t, const double *X, int level) {
  const size_t su = (size_t)S->nu * sizeof(double);
  if (S->pt_lvl[p] < level || S->pt_t[p] != t || memcmp(S->pt_X + (size_t)p * S->nx, X, (size_t)S->nx * sizeof(double)))
    return NULL;
  return su && memcmp(S->pt_u, S->u, su) ? NULL : &S->pe[p];
}

const fesd__point_eval *fesd__system_stage_eval(fesd__system *S, int p, double t, const double *X, int want_jac) {
  S->pc_valid = 0; /* pe[p] may change */
  S->status = stage_point(S, p, t, X, want_jac, 0);
  return S->status ? NULL : &S->pe[p];
}

int fesd__system_points(fesd__system *S, const double *z, int want_jac) {
  const int N = S->N, s = S->s, nx = S->nx, nth = S->nth, nu = S->nu;
  fesd__model *m = S->model;
  if (points_cached(S, z, want_jac)) return FESD_OK;
  S->pc_hcol = 0;
  double *K = S->tmp; /* K_j = sum_l a_jl v_l */
  double tn = S->t0;
  for (int n = 0; n < N; n++) {
    const double *xn = elem_start(S, z, n);
    const double h = z[S->ho[n]];
    for (int j = 0; j < s; j++) {
      const int p = n * s + j;
      double *X = S->X + (size_t)p * nx;
      for (int r = 0; r < nx; r++) {
        double acc = 0;
        for (int l = 0; l < s; l++) acc += S->tab.A[j][l] * z[fesd__v(S, n, l) + r];
        K[r] = acc;
        X[r] = xn[r] + h * acc;
      }
      const fesd__point_eval pe = S->pe[p];
      const int lk = S->look && j == 0; /* needs grad g for its value */
      int st = stage_point(S, p, tn + S->tab.c[j] * h, X, want_jac, lk);
      if (st) return st;
      if (lk && (st = look_ahead(S, z, n, tn, &pe, want_jac))) return st;
      if (want_jac) {
        const double *th = z + fesd__th(S, n, j);
        double *J = S->Jth + (size_t)p * m->pf_nnz;
        fesd__Jth(m, &pe, th, J);
        memcpy(S->JK + (size_t)p * nx, K, (size_t)nx * sizeof(double)); /* fesd__system_points_hcol */
        if (S->want_u && nu > 0) {
          double *Ju = S->Juth + (size_t)p * nx * nu;
          memset(Ju, 0, (size_t)nx * nu * sizeof(double));
          for (int i = 0; i < nth; i++) {
            if (th[i] == 0.0) continue;
            const int k = m->sys_of[i];
            const double *d = pe.dFdu + m->Fuoff[i];
            for (int c = 0; c < nu; c++)
              for (int r = 0; r < m->nr[k]; r++) Ju[c * nx + m->rows[k][r]] += th[i] * d[c * m->nr[k] + r];
          }
        }
      }
    }
    if (S->lbo[n] >= 0) {
      fesd__point_eval pb = S->pe[N * s + n];
      pb.F = pb.dFdx = pb.dFdu = NULL;
      if (!want_jac) pb.dgdx = NULL;
      if (!(want_jac && S->want_u)) pb.dgdu = NULL;
      int st = fesd__model_eval(m, tn + h, z + S->xo[n], S->u, &pb);
      if (st) return st;
    }
    tn += h;
  }
  S->pc_valid = 1;
  return FESD_OK;
}

void fesd__system_points_adopt(fesd__system *S, const double *z) {
  const fesd__model *m = S->model;
  if (points_cached(S, z, 1)) return;
  for (int n = 0; n < S->N; n++)
    for (int j = 0; j < S->s; j++) {
      const int p = n * S->s + j;
      fesd__Jth(m, &S->pe[p], z + fesd__th(S, n, j), S->Jth + (size_t)p * m->pf_nnz);
    }
  S->pc_hcol = 0;
  S->pc_valid = 1;
}

/* JK and KG of every stage point (look-ahead KG: look_ahead) from the K_j that
 * fesd__system_points left in JK: only a Newton Jacobian has an h column, the row weights and
 * residuals of a converged guess need neither. */
void fesd__system_points_hcol(fesd__system *S) {
  if (S->pc_hcol) return;
  const fesd__model *m = S->model;
  const int nx = S->nx, nth = S->nth, ns = S->N * S->s;
  double *K = S->tmp;
  for (int p = 0; p < ns; p++) {
    double *JK = S->JK + (size_t)p * nx;
    memcpy(K, JK, (size_t)nx * sizeof(double));
    fesd__pf_mv(m, S->Jth + (size_t)p * m->pf_nnz, K, JK);
    if (!(S->look && p % S->s == 0))
      for (int i = 0; i < nth; i++) S->KG[(size_t)p * nth + i] = fesd__dg_dot(m, &S->pe[p], i, K);
  }
  S->pc_hcol = 1;
}
