/* Small dense LU (shared by the dense backend of src/ncp and the stage Newton of the
 * integrator's guess). */
#include "common/dense_lu.h"

#include <math.h>
#include <stddef.h>

/* Right-looking LU with partial pivoting, column-major; 0-based pivots.
 * Returns k+1 when column k has no nonzero pivot (as dgetrf's info). */
int fesd__dense_lu(int n, double *a, int *piv) {
  for (int k = 0; k < n; k++) {
    double *ck = a + (size_t)k * n, big = fabs(ck[k]);
    int p = k;
    for (int i = k + 1; i < n; i++)
      if (fabs(ck[i]) > big) {
        big = fabs(ck[i]);
        p = i;
      }
    piv[k] = p;
    if (big == 0.0) return k + 1;
    if (p != k)
      for (int j = 0; j < n; j++) {
        double t = a[k + (size_t)j * n];
        a[k + (size_t)j * n] = a[p + (size_t)j * n];
        a[p + (size_t)j * n] = t;
      }
    const double inv = 1.0 / ck[k];
    for (int i = k + 1; i < n; i++) ck[i] *= inv;
    for (int j = k + 1; j < n; j++) {
      double *cj = a + (size_t)j * n, f = cj[k];
      if (f != 0.0)
        for (int i = k + 1; i < n; i++) cj[i] -= f * ck[i];
    }
  }
  return 0;
}

void fesd__dense_lu_solve(int n, const double *a, const int *piv, double *x) {
  for (int k = 0; k < n; k++)
    if (piv[k] != k) {
      double t = x[k];
      x[k] = x[piv[k]];
      x[piv[k]] = t;
    }
  for (int k = 0; k < n; k++) { /* L y = P b, unit diagonal */
    const double *ck = a + (size_t)k * n, xk = x[k];
    for (int i = k + 1; i < n; i++) x[i] -= ck[i] * xk;
  }
  for (int k = n - 1; k >= 0; k--) { /* U x = y */
    const double *ck = a + (size_t)k * n;
    x[k] /= ck[k];
    const double xk = x[k];
    for (int i = 0; i < k; i++) x[i] -= ck[i] * xk;
  }
}

/* Columns x0..x(w-1) (w <= 4) at once: each factor entry is loaded once for all of them, and
 * each column gets the operations of fesd__dense_lu_solve in its order (bit for bit). Called
 * with a constant w, so that the compiler drops the unused columns. */
static inline void solve_w(int n, const double *restrict a, const int *restrict piv, int w, double *restrict x0,
                           double *restrict x1, double *restrict x2, double *restrict x3) {
  for (int k = 0; k < n; k++) {
    const int p = piv[k];
    if (p == k) continue;
    double t = x0[k];
    x0[k] = x0[p], x0[p] = t;
    if (w > 1) t = x1[k], x1[k] = x1[p], x1[p] = t;
    if (w > 2) t = x2[k], x2[k] = x2[p], x2[p] = t;
    if (w > 3) t = x3[k], x3[k] = x3[p], x3[p] = t;
  }
  for (int k = 0; k < n; k++) {
    const double *ck = a + (size_t)k * n, s0 = x0[k], s1 = w > 1 ? x1[k] : 0.0, s2 = w > 2 ? x2[k] : 0.0,
                 s3 = w > 3 ? x3[k] : 0.0;
    for (int i = k + 1; i < n; i++) {
      const double c = ck[i];
      x0[i] -= c * s0;
      if (w > 1) x1[i] -= c * s1;
      if (w > 2) x2[i] -= c * s2;
      if (w > 3) x3[i] -= c * s3;
    }
  }
  for (int k = n - 1; k >= 0; k--) {
    const double *ck = a + (size_t)k * n, d = ck[k];
    const double s0 = x0[k] /= d, s1 = w > 1 ? x1[k] /= d : 0.0, s2 = w > 2 ? x2[k] /= d : 0.0,
                 s3 = w > 3 ? x3[k] /= d : 0.0;
    for (int i = 0; i < k; i++) {
      const double c = ck[i];
      x0[i] -= c * s0;
      if (w > 1) x1[i] -= c * s1;
      if (w > 2) x2[i] -= c * s2;
      if (w > 3) x3[i] -= c * s3;
    }
  }
}

void fesd__dense_lu_solve_many(int n, const double *a, const int *piv, double *x, int nrhs) {
  const size_t ld = (size_t)n;
  for (int j = 0; j < nrhs;) {
    double *c = x + (size_t)j * ld;
    const int w = nrhs - j < 4 ? nrhs - j : 4;
    switch (w) {
    case 4: solve_w(n, a, piv, 4, c, c + ld, c + 2 * ld, c + 3 * ld); break;
    case 3: solve_w(n, a, piv, 3, c, c + ld, c + 2 * ld, NULL); break;
    case 2: solve_w(n, a, piv, 2, c, c + ld, NULL, NULL); break;
    default: fesd__dense_lu_solve(n, a, piv, c); break;
    }
    j += w;
  }
}
