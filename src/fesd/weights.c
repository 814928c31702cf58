/* Row weights of the step system: every row is divided by the size of the terms it compares
 * (a backward-error measure), so that every tolerance is relative and results do not depend
 * on units or on how far time has run. Absolute tolerances failed a plain crossing at
 * t = 8300 (with t as a state, the continuity row of t carries round-off of eps * 8300), a
 * problem with states scaled by 1e8, and a sliding mode whose fields have normal components of
 * 1e-10 (its sign changes stayed below an absolute threshold). Sizes at a point z, for the
 * stage j of element n (xi_c = |x_n,c| + h sum_l |a_jl v_l,c|, the size of the terms that
 * make up the stage state):
 *   V rows   max(|v_r|, sum_i theta_i |f_i,r|, sum_c |J_rc| xi_c)   (J = sum theta df/dx: the
 *            size of the terms whose difference a stiff field is)
 *   G rows   max(|g_i|, |lambda_i|, |mu_k|, sum_c |dg_i/dx_c| xi_c)
 *   X rows   max(|x_n,r|, |x_n+1,r|, h sum_j |b_j v_j,r|)
 *   H, T     the step length;  S rows and theta: dimensionless
 *   lambda   the indicator size of its subsystem (max of its G rows), also the unit of the
 *            sign checks and of the cross-complementarity products (wth)
 * A quantity at zero has no size of its own (a state sliding on x = 0 exactly: every term of
 * its rows vanishes, and sizes taken from them blow the weights up), so each size is raised to
 * at least ATOL_REL times a size that does not vanish there (like an absolute tolerance that
 * follows the problem's units): the largest size of the same row and component (or subsystem)
 * in the accepted steps so far (refX, refV, refG), and the motion the fields of all modes could
 * make: |f_i,r| for x'_r, T |f_i,r| for x_r, sum_c |dg/dx_c| T |f_i,c| for the indicators.
 * The solver keeps the weights of one solve fixed; the caller recomputes them at the solution
 * and checks again (step.c). */
#include <math.h>
#include <string.h>

#include "fesd/system.h"

#define FLOOR 1e-300
#define ATOL_REL 1e-3

static double amax(double a, double b) { return a > b ? a : b; }

int fesd__system_weights(fesd__system *S, const double *z) {
  int st = fesd__system_points(S, z, 1);
  if (st) return st;
  const int N = S->N, s = S->s, nx = S->nx, nth = S->nth, nsys = S->nsys;
  const fesd__model *m = S->model;
  double *w = S->wraw, *xi = S->tmp, *acc = S->tmp + nx;
  double *mX = S->magX, *mV = S->magV, *mf = S->tmp + 3 * nx; /* mf: max_i |f_i,r| */
  for (int r = 0; r < nx; r++) mX[r] = mV[r] = mf[r] = 0;
  for (int p = 0; p < N * s; p++)
    for (int i = 0; i < nth; i++) {
      const int k = m->sys_of[i];
      const double *f = S->pe[p].F + m->Foff[i];
      for (int q = 0; q < m->nr[k]; q++) mf[m->rows[k][q]] = amax(mf[m->rows[k][q]], fabs(f[q]));
    }
  double *gf = S->tmp + 4 * nx; /* per subsystem: sum_c |dg/dx_c| T mf_c (max over modes, points) */
  for (int k = 0; k < nsys; k++) gf[k] = 0;
  for (int p = 0; p < N * s; p++)
    for (int k = 0; k < nsys; k++) {
      const int nf = m->nf[k];
      const double *blk = S->pe[p].dgdx + m->dgoff[k];
      for (int li = 0; li < nf; li++) {
        double a = 0;
        for (int c = 0; c < m->ncol[k]; c++) a += fabs(blk[(size_t)c * nf + li]) * S->T * mf[m->cols[k][c]];
        gf[k] = amax(gf[k], a);
      }
    }
  for (int k = 0; k < nsys; k++) S->wG[k] = 0; /* indicator sizes first */
  for (int n = 0; n < N; n++) {
    const double h = z[S->ho[n]], *xn = n == 0 ? S->x0 : z + S->xo[n - 1];
    for (int j = 0; j < s; j++) {
      const int p = n * s + j, rV = S->rel[n] + j * S->rs, rG = rV + nx, rS = rG + nth;
      const fesd__point_eval *pe = &S->pe[p];
      const double *v = z + fesd__v(S, n, j), *th = z + fesd__th(S, n, j);
      const double *la = z + fesd__la(S, n, j), *mu = z + fesd__mu(S, n, j);
      for (int c = 0; c < nx; c++) {
        double a = fabs(xn[c]);
        for (int l = 0; l < s; l++) a += h * fabs(S->tab.A[j][l] * z[fesd__v(S, n, l) + c]);
        xi[c] = a;
        acc[c] = fabs(v[c]);
      }
      for (int i = 0; i < nth; i++) {
        if (th[i] == 0.0) continue;
        const int k = m->sys_of[i];
        const double *f = pe->F + m->Foff[i];
        for (int q = 0; q < m->nr[k]; q++) acc[m->rows[k][q]] += fabs(th[i] * f[q]);
      }
      const double *J = S->Jth + (size_t)p * m->pf_nnz;
      double *jx = acc + nx; /* sum_c |J_rc| xi_c */
      memset(jx, 0, (size_t)nx * sizeof(double));
      for (int q = 0; q < m->pf_nnz; q++) jx[m->pf_r[q]] += fabs(J[q]) * xi[m->pf_c[q]];
      for (int r = 0; r < nx; r++) {
        w[rV + r] = amax(acc[r], jx[r]);
        mV[r] = amax(mV[r], w[rV + r]);
      }
      for (int k = 0; k < nsys; k++) {
        const int nf = m->nf[k], off = m->th_off[k], nc = m->ncol[k], *cols = m->cols[k];
        const double *blk = pe->dgdx + m->dgoff[k], amu = fabs(mu[k]);
        double wk = S->wG[k];
        for (int li = 0; li < nf; li++) {
          double a = 0;
          for (int c = 0; c < nc; c++) a += fabs(blk[(size_t)c * nf + li]) * xi[cols[c]];
          const int i = off + li;
          a = amax(amax(a, fabs(pe->g[i])), amax(fabs(la[i]), amu));
          w[rG + i] = a;
          wk = amax(wk, a);
        }
        S->wG[k] = wk;
        w[rS + k] = 1.0;
      }
    }
    if (S->lbo[n] >= 0) {
      const fesd__point_eval *pb = &S->pe[N * s + n];
      const double *LB = z + S->lbo[n], *MB = LB + nth, *x1 = z + S->xo[n];
      const int rL = S->rlb[n], rM = rL + nth;
      for (int k = 0; k < nsys; k++) {
        const int nf = m->nf[k], off = m->th_off[k];
        const double *blk = pb->dgdx + m->dgoff[k];
        double mk = 0;
        for (int li = 0; li < nf; li++) {
          double a = 0;
          for (int c = 0; c < m->ncol[k]; c++) a += fabs(blk[(size_t)c * nf + li] * x1[m->cols[k][c]]);
          const int i = off + li;
          a = amax(amax(a, fabs(pb->g[i])), amax(fabs(LB[i]), fabs(MB[k])));
          w[rL + i] = a;
          mk = amax(mk, a);
        }
        w[rM + k] = mk; /* theta' LB: units of the indicators */
      }
    }
    const double *x1 = z + S->xo[n];
    for (int r = 0; r < nx; r++) {
      double a = 0;
      for (int j = 0; j < s; j++) a += fabs(S->tab.b[j] * z[fesd__v(S, n, j) + r]);
      const int row = S->rx[n] + r;
      w[row] = amax(amax(fabs(xn[r]), fabs(x1[r])), h * a);
      mX[r] = amax(mX[r], w[row]);
    }
  }
  /* invert, with the floors of each component and subsystem */
  double *fX = xi, *fV = acc; /* floors (scratch reused) */
  for (int r = 0; r < nx; r++) {
    fX[r] = amax(ATOL_REL * amax(S->refX[r], S->T * mf[r]), FLOOR);
    fV[r] = amax(ATOL_REL * amax(S->refV[r], mf[r]), FLOOR);
  }
  for (int k = 0; k < nsys; k++) {
    const double fG = amax(ATOL_REL * amax(S->refG[k], gf[k]), FLOOR);
    S->magG[k] = S->wG[k];
    S->wG[k] = 1.0 / amax(S->wG[k], fG);
    gf[k] = fG;
  }
  for (int i = 0; i < nth; i++) S->wth[i] = S->wG[m->sys_of[i]];
  for (int n = 0; n < N; n++) {
    for (int j = 0; j < s; j++) {
      const int rV = S->rel[n] + j * S->rs, rG = rV + nx;
      for (int r = 0; r < nx; r++) w[rV + r] = 1.0 / amax(w[rV + r], fV[r]);
      for (int i = 0; i < nth; i++) w[rG + i] = 1.0 / amax(w[rG + i], gf[m->sys_of[i]]);
    }
    if (S->lbo[n] >= 0) {
      const int rL = S->rlb[n], rM = rL + nth;
      for (int i = 0; i < nth; i++) w[rL + i] = 1.0 / amax(w[rL + i], gf[m->sys_of[i]]);
      for (int k = 0; k < nsys; k++) w[rM + k] = 1.0 / amax(w[rM + k], gf[k]);
    }
    for (int r = 0; r < nx; r++) w[S->rx[n] + r] = 1.0 / amax(w[S->rx[n] + r], fX[r]);
  }
  for (int k = 1; k < N; k++) {
    w[fesd__rowH(S, k)] = 1.0 / S->T;
    w[fesd__rowC(S, k)] = 1.0; /* its terms are weighted by wth: dimensionless */
  }
  w[S->rT] = 1.0 / S->T;
  for (int n = 0; n < N; n++)
    for (int j = 0; j < s; j++)
      for (int i = 0; i < nth; i++) {
        const int p = fesd__pair(S, n, j, i);
        w[S->n_eq + p] = 1.0;
        w[S->n_eq + S->n_pair + p] = S->wth[i];
      }
  return FESD_OK;
}

void fesd__system_reset_refs(fesd__system *S) {
  for (int r = 0; r < S->nx; r++) S->refX[r] = S->refV[r] = 0;
  for (int k = 0; k < S->nsys; k++) S->refG[k] = 0;
}

void fesd__system_update_refs(fesd__system *S) {
  for (int r = 0; r < S->nx; r++) {
    S->refX[r] = amax(S->refX[r], S->magX[r]);
    S->refV[r] = amax(S->refV[r], S->magV[r]);
  }
  for (int k = 0; k < S->nsys; k++) S->refG[k] = amax(S->refG[k], S->magG[k]);
}
