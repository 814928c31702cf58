/* Hessian approximations of the Lagrangian, block diagonal over the multiple shooting blocks
 * (x_k, q_k) and x_N (the Lagrangian is separable in them: every nonlinear function of the NLP
 * depends on one block only). The L1 slacks enter linearly (no block; the QP adds its proximal
 * term). */
#include <math.h>
#include <string.h>

#include "ocp/ocp_internal.h"

static int bsize(const fesd_ocp *o, int k) { return k < o->N ? o->nb : o->nx; }
static double *block(const fesd_ocp *o, int k) { return o->B + (size_t)k * o->nb * o->nb; }

void fesd__ocp_hessian_reset(fesd_ocp *o) {
  for (int k = 0; k <= o->N; k++) {
    const int n = bsize(o, k);
    double *B = block(o, k);
    memset(B, 0, (size_t)n * n * sizeof(double));
    for (int i = 0; i < n; i++) B[i * n + i] = 1.0;
  }
}

/* B += s * J' J for J (m x n, column-major) */
static void add_jtj(double *B, const double *J, int m, int n, double s) {
  for (int j = 0; j < n; j++)
    for (int i = 0; i <= j; i++) {
      double a = 0;
      for (int r = 0; r < m; r++) a += J[(size_t)i * m + r] * J[(size_t)j * m + r];
      B[j * n + i] += s * a;
      if (i != j) B[i * n + j] += s * a;
    }
}

/* Gauss-Newton: int_{t_k}^{t_k+T} ||r_L||^2 dt by the trapezoidal rule, so the block of interval
 * k is 2 (T/2) (J0'J0 + J1'J1) with J0, J1 the residual's Jacobians at the interval ends
 * (eval.c); the Mayer block 2 J_M'J_M. */
void fesd__ocp_hessian_gn(fesd_ocp *o, const ocp_point *pt) {
  const int nb = o->nb, nL = o->nL, N = o->N;
  for (int k = 0; k <= N; k++) memset(block(o, k), 0, (size_t)bsize(o, k) * bsize(o, k) * sizeof(double));
  for (int k = 0; k < N && nL > 0; k++) {
    const double *J0 = pt->gn + (size_t)k * 2 * nL * nb;
    add_jtj(block(o, k), J0, nL, nb, o->T);
    add_jtj(block(o, k), J0 + (size_t)nL * nb, nL, nb, o->T);
  }
  if (o->nM > 0) add_jtj(block(o, N), pt->gn + (size_t)N * 2 * nL * nb, o->nM, o->nx, 2.0);
}

double fesd__ocp_hessian_diag_max(const fesd_ocp *o) {
  double m = 0;
  for (int k = 0; k <= o->N; k++) {
    const int n = bsize(o, k);
    const double *B = block(o, k);
    for (int i = 0; i < n; i++) m = fmax(m, fabs(B[i * n + i]));
  }
  return m;
}

/* BFGS on every block with s = b.w - a.w and y = grad L(b) - grad L(a), both Lagrangian
 * gradients with the new multipliers. A pair with too little curvature (s'y < 0.2 s'Bs) is
 * skipped, not Powell-damped: the blocks of a multiple shooting Lagrangian are indefinite where
 * switching times depend on the block's variables (a sliding exit: measured on ocp_step_eq,
 * damping then grows the block without bound (1e13 after 30 iterations) and the iteration stalls
 * at a non-stationary point; skipping converges). The same test rejects the jumps of the
 * gradient at kinks of the integrator's map (a switch crossing an interval end). */
void fesd__ocp_bfgs_update(fesd_ocp *o, const ocp_point *a, const ocp_point *b, const double *mult) {
  fesd__ocp_lagrangian_grad(o, a, mult, o->gl);
  fesd__ocp_lagrangian_grad(o, b, mult, o->gl2);
  for (int k = 0; k <= o->N; k++) {
    const int n = bsize(o, k), off = k * o->nb;
    double *B = block(o, k), *s = o->bs, *y = o->by, *Bs = o->bBs;
    double ss = 0, ww = 0;
    for (int i = 0; i < n; i++) {
      s[i] = b->w[off + i] - a->w[off + i];
      y[i] = o->gl2[off + i] - o->gl[off + i];
      ss = fmax(ss, fabs(s[i]));
      ww = fmax(ww, fabs(a->w[off + i]));
    }
    if (ss <= 1e-14 * (1 + ww)) {
      o->info.hessian_skipped++;
      continue;
    }
    double sBs = 0, sy = 0;
    for (int i = 0; i < n; i++) {
      double v = 0;
      for (int j = 0; j < n; j++) v += B[j * n + i] * s[j];
      Bs[i] = v;
      sBs += s[i] * v;
      sy += s[i] * y[i];
    }
    if (!(sBs > 0) || sy < 0.2 * sBs) {
      o->info.hessian_skipped++;
      continue;
    }
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++) B[j * n + i] += y[i] * y[j] / sy - Bs[i] * Bs[j] / sBs;
    o->info.hessian_updates++;
  }
}

/* GN_SR1: B = GN(w) + A. Gauss-Newton drops the multiplier-weighted curvature of the interval
 * maps; where a switching time depends on the block (sliding exits) that curvature is large and
 * indefinite (measured on ocp_step_eq, interval with two sliding exits: eigenvalues -6.5 and
 * -3.9 against GN's 1..2), so GN converges linearly (ratio 0.73, 36 iterations) and BFGS, which
 * must stay positive definite, skips those pairs. SR1 may learn indefinite curvature; it is
 * applied to the remainder y - GN(b) s only, so the exact least-squares part is not relearnt. */
void fesd__ocp_sr1_reset(fesd_ocp *o) {
  memset(o->A, 0, ((size_t)o->N * o->nb * o->nb + (size_t)o->nx * o->nx) * sizeof(double));
}

void fesd__ocp_hessian_gn_sr1(fesd_ocp *o, const ocp_point *pt) {
  fesd__ocp_hessian_gn(o, pt);
  const size_t n = (size_t)o->N * o->nb * o->nb + (size_t)o->nx * o->nx;
  for (size_t i = 0; i < n; i++) o->B[i] += o->A[i];
}

void fesd__ocp_sr1_update(fesd_ocp *o, const ocp_point *a, const ocp_point *b, const double *mult) {
  fesd__ocp_hessian_gn(o, b); /* B: GN at the new point (rebuilt before the next QP) */
  fesd__ocp_lagrangian_grad(o, a, mult, o->gl);
  fesd__ocp_lagrangian_grad(o, b, mult, o->gl2);
  for (int k = 0; k <= o->N; k++) {
    const int n = bsize(o, k), off = k * o->nb;
    const double *B = block(o, k);
    double *A = o->A + (size_t)k * o->nb * o->nb, *s = o->bs, *r = o->by;
    double ss = 0, rr = 0, sr = 0;
    for (int i = 0; i < n; i++) s[i] = b->w[off + i] - a->w[off + i];
    for (int i = 0; i < n; i++) {
      double v = 0;
      for (int j = 0; j < n; j++) v += (B[j * n + i] + A[j * n + i]) * s[j];
      r[i] = o->gl2[off + i] - o->gl[off + i] - v; /* y - (GN + A) s */
      ss += s[i] * s[i], rr += r[i] * r[i], sr += s[i] * r[i];
    }
    /* the usual SR1 safeguard: skip when s'r is tiny against |s||r| (update unbounded) */
    if (!(ss > 0) || !(fabs(sr) > 1e-8 * sqrt(ss * rr))) {
      o->info.hessian_skipped++;
      continue;
    }
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++) A[j * n + i] += r[i] * r[j] / sr;
    o->info.hessian_updates++;
  }
}
