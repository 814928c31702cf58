/* Reference for the cost of an ordinary step: a plain Radau IIA collocation step on the
 * oscillator's smooth mode (x' = A2 x inside the unit circle, from x0 = (e^-1, 0)), the same
 * step length as bench_step_cost's oscillator cases (T / 40, T = pi / 2), N_FE = 2 elements per
 * step, stage equations K_i = f(x_n + h sum_j a_ij K_j) solved by Newton to ||F||_inf <= 1e-12
 * (the integrator's newton_tol) with one LU of the (s nx) stage Jacobian per element (partial
 * pivoting), the field and its Jacobian called through function pointers like model callbacks.
 * Self-contained: the tableau is computed here (Radau nodes by bisection, A by collocation).
 *
 *   bench_radau_ref K [s]   K steps (default s = 5); under callgrind (--collect-atstart=no)
 *                           only the steps are collected; prints the error at the end against
 *                           the exact solution (a check that the steps are right). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <valgrind/callgrind.h>

#define SMAX 8
#define NX 2
#define NS (SMAX * NX)
#define N_FE 2
#define PI 3.14159265358979323846
static const double W = 2.0 * PI;

typedef void (*field_fn)(const double *x, double *f);
typedef void (*jac_fn)(const double *x, double *J);

static void field(const double *x, double *f) { /* A2 = [[1, -w], [w, 1]] */
  f[0] = x[0] - W * x[1];
  f[1] = W * x[0] + x[1];
}
static void jac(const double *x, double *J) { /* row-major */
  (void)x;
  J[0] = 1, J[1] = -W, J[2] = W, J[3] = 1;
}

static int s;
static double A[SMAX][SMAX], b[SMAX];

/* Radau IIA: nodes are the roots of P_s(2c - 1) - P_{s-1}(2c - 1) (Legendre), c_s = 1 */
static double radau_poly(double c) {
  double y = 2 * c - 1, p0 = 1, p1 = y;
  for (int k = 1; k < s; k++) {
    double p2 = ((2 * k + 1) * y * p1 - k * p0) / (k + 1);
    p0 = p1, p1 = p2;
  }
  return p1 - p0;
}

static void tableau(void) {
  double c[SMAX];
  int m = 0;
  const int grid = 4000;
  for (int g = 0; g < grid && m < s - 1; g++) { /* bracket the roots in (0, 1) */
    double lo = (double)g / grid, hi = (double)(g + 1) / grid;
    if (radau_poly(lo) * radau_poly(hi) > 0) continue;
    for (int it = 0; it < 100; it++) {
      double mid = 0.5 * (lo + hi);
      if (radau_poly(lo) * radau_poly(mid) <= 0) hi = mid;
      else lo = mid;
    }
    c[m++] = 0.5 * (lo + hi);
  }
  c[s - 1] = 1.0;
  /* collocation: sum_j a_ij c_j^(k-1) = c_i^k / k, k = 1..s (Vandermonde, Gauss elimination) */
  for (int i = 0; i < s; i++) {
    double M[SMAX][SMAX + 1];
    for (int k = 0; k < s; k++) {
      for (int j = 0; j < s; j++) M[k][j] = pow(c[j], k);
      M[k][s] = pow(c[i], k + 1) / (k + 1);
    }
    for (int p = 0; p < s; p++) {
      int r = p;
      for (int q = p + 1; q < s; q++)
        if (fabs(M[q][p]) > fabs(M[r][p])) r = q;
      for (int j = 0; j <= s; j++) {
        double t = M[p][j];
        M[p][j] = M[r][j], M[r][j] = t;
      }
      for (int q = p + 1; q < s; q++) {
        double f = M[q][p] / M[p][p];
        for (int j = p; j <= s; j++) M[q][j] -= f * M[p][j];
      }
    }
    for (int j = s - 1; j >= 0; j--) {
      double acc = M[j][s];
      for (int q = j + 1; q < s; q++) acc -= M[j][q] * A[i][q];
      A[i][j] = acc / M[j][j];
    }
  }
  for (int j = 0; j < s; j++) b[j] = A[s - 1][j]; /* stiffly accurate */
}

/* LU with partial pivoting of the n x n row-major M, in place */
static int lu(double *M, int n, int *piv) {
  for (int p = 0; p < n; p++) {
    int r = p;
    for (int q = p + 1; q < n; q++)
      if (fabs(M[q * n + p]) > fabs(M[r * n + p])) r = q;
    piv[p] = r;
    if (M[r * n + p] == 0) return 1;
    if (r != p)
      for (int j = 0; j < n; j++) {
        double t = M[p * n + j];
        M[p * n + j] = M[r * n + j], M[r * n + j] = t;
      }
    const double inv = 1.0 / M[p * n + p];
    for (int q = p + 1; q < n; q++) {
      double f = M[q * n + p] *= inv;
      for (int j = p + 1; j < n; j++) M[q * n + j] -= f * M[p * n + j];
    }
  }
  return 0;
}

static void lu_solve(const double *M, int n, const int *piv, double *r) {
  for (int p = 0; p < n; p++) {
    double t = r[piv[p]];
    r[piv[p]] = r[p], r[p] = t;
    for (int q = p + 1; q < n; q++) r[q] -= M[q * n + p] * r[p];
  }
  for (int p = n - 1; p >= 0; p--) {
    for (int j = p + 1; j < n; j++) r[p] -= M[p * n + j] * r[j];
    r[p] /= M[p * n + p];
  }
}

/* F_i = K_i - f(x + h sum_j a_ij K_j); returns ||F||_inf */
static double residual(field_fn f, const double *x, double h, const double *K, double *F) {
  double nrm = 0, X[NX], fx[NX];
  for (int i = 0; i < s; i++) {
    for (int r = 0; r < NX; r++) {
      double acc = 0;
      for (int j = 0; j < s; j++) acc += A[i][j] * K[j * NX + r];
      X[r] = x[r] + h * acc;
    }
    f(X, fx);
    for (int r = 0; r < NX; r++) {
      F[i * NX + r] = K[i * NX + r] - fx[r];
      nrm = fmax(nrm, fabs(F[i * NX + r]));
    }
  }
  return nrm;
}

/* one element: Newton from K_i = f(x), Jacobian I - h A (x) f_x(x) factorized once */
static int element(field_fn f, jac_fn fj, double *x, double h, double tol) {
  double K[NS], F[NS], M[NS * NS], J[NX * NX];
  int piv[NS], factored = 0;
  const int n = s * NX;
  f(x, K);
  for (int i = 1; i < s; i++)
    for (int r = 0; r < NX; r++) K[i * NX + r] = K[r];
  for (int it = 0;; it++) {
    if (residual(f, x, h, K, F) <= tol) break;
    if (it == 10) return 1;
    if (!factored) {
      fj(x, J);
      for (int i = 0; i < s; i++)
        for (int r = 0; r < NX; r++)
          for (int j = 0; j < s; j++)
            for (int q = 0; q < NX; q++)
              M[(i * NX + r) * n + j * NX + q] = (i == j && r == q) - h * A[i][j] * J[r * NX + q];
      if (lu(M, n, piv)) return 1;
      factored = 1;
    }
    lu_solve(M, n, piv, F);
    for (int k = 0; k < n; k++) K[k] -= F[k];
  }
  for (int r = 0; r < NX; r++) {
    double acc = 0;
    for (int j = 0; j < s; j++) acc += b[j] * K[j * NX + r];
    x[r] += h * acc;
  }
  return 0;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_radau_ref K [s]\n");
    return 1;
  }
  const int K = atoi(argv[1]);
  s = argc > 2 ? atoi(argv[2]) : 5;
  if (s < 1 || s > SMAX || K < 1) return 1;
  tableau();
  const double H = PI / 2 / 40, tol = 1e-12;
  double x[NX] = {exp(-1.0), 0.0};
  volatile field_fn f = field; /* called through pointers, as the library calls the model */
  volatile jac_fn fj = jac;
  int st = 0;
  CALLGRIND_TOGGLE_COLLECT;
  for (int k = 0; k < K && !st; k++)
    for (int e = 0; e < N_FE && !st; e++) st = element(f, fj, x, H / N_FE, tol);
  CALLGRIND_TOGGLE_COLLECT;
  const double t = K * H, a = exp(t - 1.0);
  printf("radau s=%d: %d steps to t = %.4f, error %.2e, status %d\n", s, K, t,
         fmax(fabs(x[0] - a * cos(W * t)), fabs(x[1] - a * sin(W * t))), st);
  return st;
}
