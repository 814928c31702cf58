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
#include <float.h>
#include <math.h>
#include <string.h>

#include "fesd/system.h"

#define FLOOR 1e-300
#define ATOL_REL 1e-3

static double amax(double a, double b) { return a > b ? a : b; }

int fesd__system_weights(fesd__system *S, const double *z) {
  int st = fesd__system_points(S, z, 1);
  if (st) return st;
  const int N = S->N, s = S->s, nx = S->nx, nth = S->nth, nsys = S->nsys, sb = S->sb, pnz = S->model->pf_nnz;
  const fesd__model *m = S->model;
  /* locals and restrict: the outputs do not alias S's fields (T, the tableau), which the
   * loops would otherwise reload after every store */
  const double T = S->T;
  const int *restrict pf_r = m->pf_r, *restrict pf_c = m->pf_c;
  double *restrict w = S->wraw, *restrict xi = S->tmp, *restrict acc = S->tmp + nx;
  double *restrict mX = S->magX, *restrict mV = S->magV, *restrict mf = S->tmp + 3 * nx; /* mf: max_i |f_i,r| */
  double *restrict wG = S->wG;
  for (int r = 0; r < nx; r++) mX[r] = mV[r] = mf[r] = 0;
  for (int p = 0; p < N * s; p++)
    for (int i = 0; i < nth; i++) {
      const int k = m->sys_of[i], nr = m->nr[k], *rows = m->rows[k];
      const double *f = S->pe[p].F + m->Foff[i];
      for (int q = 0; q < nr; q++) mf[rows[q]] = amax(mf[rows[q]], fabs(f[q]));
    }
  double *restrict gf = S->tmp + 4 * nx; /* per subsystem: sum_c |dg/dx_c| T mf_c (max over modes, points) */
  for (int k = 0; k < nsys; k++) gf[k] = 0;
  for (int p = 0; p < N * s; p++)
    for (int k = 0; k < nsys; k++) {
      const int nf = m->nf[k], nc = m->ncol[k], *cols = m->cols[k];
      const double *blk = S->pe[p].dgdx + m->dgoff[k];
      double gk = gf[k];
      for (int li = 0; li < nf; li++) {
        double a = 0;
        for (int c = 0; c < nc; c++) a += fabs(blk[(size_t)c * nf + li]) * T * mf[cols[c]];
        gk = amax(gk, a);
      }
      gf[k] = gk;
    }
  for (int k = 0; k < nsys; k++) wG[k] = 0; /* indicator sizes first */
  for (int n = 0; n < N; n++) {
    const double h = z[S->ho[n]], *xn = n == 0 ? S->x0 : z + S->xo[n - 1], *ve = z + S->el[n];
    for (int j = 0; j < s; j++) {
      const int p = n * s + j, rV = S->rel[n] + j * S->rs, rG = rV + nx, rS = rG + nth;
      const fesd__point_eval *pe = &S->pe[p];
      const double *v = ve + j * sb, *th = v + nx, *la = th + nth, *mu = la + nth;
      const double *Aj = S->tab.A[j];
      for (int c = 0; c < nx; c++) {
        double a = fabs(xn[c]);
        for (int l = 0; l < s; l++) a += h * fabs(Aj[l] * ve[l * sb + c]);
        xi[c] = a;
        acc[c] = fabs(v[c]);
      }
      for (int i = 0; i < nth; i++) {
        if (th[i] == 0.0) continue;
        const int k = m->sys_of[i], nr = m->nr[k], *rows = m->rows[k];
        const double *f = pe->F + m->Foff[i], t = th[i];
        for (int q = 0; q < nr; q++) acc[rows[q]] += fabs(t * f[q]);
      }
      const double *J = S->Jth + (size_t)p * pnz;
      double *restrict jx = acc + nx; /* sum_c |J_rc| xi_c */
      for (int r = 0; r < nx; r++) jx[r] = 0;
      for (int q = 0; q < pnz; q++) jx[pf_r[q]] += fabs(J[q]) * xi[pf_c[q]];
      double *restrict wv = w + rV;
      for (int r = 0; r < nx; r++) {
        wv[r] = amax(acc[r], jx[r]);
        mV[r] = amax(mV[r], wv[r]);
      }
      for (int k = 0; k < nsys; k++) {
        const int nf = m->nf[k], off = m->th_off[k], nc = m->ncol[k], *cols = m->cols[k];
        const double *blk = pe->dgdx + m->dgoff[k], amu = fabs(mu[k]);
        double wk = wG[k];
        for (int li = 0; li < nf; li++) {
          double a = 0;
          for (int c = 0; c < nc; c++) a += fabs(blk[(size_t)c * nf + li]) * xi[cols[c]];
          const int i = off + li;
          a = amax(amax(a, fabs(pe->g[i])), amax(fabs(la[i]), amu));
          w[rG + i] = a;
          wk = amax(wk, a);
        }
        wG[k] = wk;
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
    const double *x1 = z + S->xo[n], *b = S->tab.b;
    double *restrict wx = w + S->rx[n];
    for (int r = 0; r < nx; r++) {
      double a = 0;
      for (int j = 0; j < s; j++) a += fabs(b[j] * ve[j * sb + r]);
      wx[r] = amax(amax(fabs(xn[r]), fabs(x1[r])), h * a);
      mX[r] = amax(mX[r], wx[r]);
    }
  }
  /* invert, with the floors of each component, subsystem and mode */
  double *restrict fX = xi, *restrict fV = acc, *restrict fth = S->tmp + 4 * nx + nth; /* scratch reused */
  /* A component whose fields vanish in every mode at every point (a cost state x_q' = x_s^2 while
   * x_s slides at rest on x_s = 0: all its terms are round-off) has no size at all; it gets eps
   * times the largest size of any component, or round-off is weighted up to 1e300 and no weight
   * pass settles (measured: FESD_ERR_STEP_FAILED on every such step, 331 Newton iterations). */
  double gX = 0, gV = 0;
  for (int r = 0; r < nx; r++) {
    S->motX[r] = amax(S->refX[r], T * mf[r]);
    gX = amax(gX, S->motX[r]);
    gV = amax(gV, amax(S->refV[r], mf[r]));
  }
  for (int r = 0; r < nx; r++) {
    fX[r] = amax(amax(ATOL_REL * S->motX[r], DBL_EPSILON * gX), FLOOR);
    fV[r] = amax(amax(ATOL_REL * amax(S->refV[r], mf[r]), DBL_EPSILON * gV), FLOOR);
  }
  for (int k = 0; k < nsys; k++) {
    const double fG = amax(ATOL_REL * amax(S->refG[k], gf[k]), FLOOR);
    S->magG[k] = wG[k];
    wG[k] = 1.0 / amax(wG[k], fG);
    gf[k] = fG;
  }
  double *restrict wth = S->wth;
  for (int i = 0; i < nth; i++) {
    wth[i] = wG[m->sys_of[i]];
    fth[i] = gf[m->sys_of[i]];
  }
  for (int n = 0; n < N; n++) {
    for (int j = 0; j < s; j++) {
      double *restrict wv = w + S->rel[n] + j * S->rs, *restrict wg = wv + nx;
      for (int r = 0; r < nx; r++) wv[r] = 1.0 / amax(wv[r], fV[r]);
      for (int i = 0; i < nth; i++) wg[i] = 1.0 / amax(wg[i], fth[i]);
    }
    if (S->lbo[n] >= 0) {
      const int rL = S->rlb[n], rM = rL + nth;
      for (int i = 0; i < nth; i++) w[rL + i] = 1.0 / amax(w[rL + i], fth[i]);
      for (int k = 0; k < nsys; k++) w[rM + k] = 1.0 / amax(w[rM + k], gf[k]);
    }
    double *restrict wx = w + S->rx[n];
    for (int r = 0; r < nx; r++) wx[r] = 1.0 / amax(wx[r], fX[r]);
  }
  for (int k = 1; k < N; k++) {
    w[fesd__rowH(S, k)] = 1.0 / T;
    w[fesd__rowC(S, k)] = 1.0; /* its terms are weighted by wth: dimensionless */
  }
  w[S->rT] = 1.0 / T;
  /* pair rows (fesd__pair: stage points in order, nth pairs each): theta 1, lambda wth */
  double *restrict wa = w + S->n_eq, *restrict wb = wa + S->n_pair;
  for (int p = 0; p < N * s * nth; p += nth)
    for (int i = 0; i < nth; i++) {
      wa[p + i] = 1.0;
      wb[p + i] = wth[i];
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
