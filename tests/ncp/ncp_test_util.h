/* Shared helpers for the ncp tests: checks, a small PRNG, LCP problems in the
 * raw-row format of fesd_ncp.h, and Lemke's method as an independent reference.
 * Header-only (static functions) so that every test stays one program. */
#ifndef NCP_TEST_UTIL_H
#define NCP_TEST_UTIL_H

#include "fesd_ncp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_failures = 0;

#define CHECK(cond, ...)                                                                           \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      g_failures++;                                                                                \
      printf("FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);                                      \
      printf(__VA_ARGS__);                                                                         \
      printf("\n");                                                                                \
    }                                                                                              \
  } while (0)

#define CHECK_RC(expr, want)                                                                       \
  do {                                                                                             \
    int rc_ = (expr);                                                                              \
    CHECK(rc_ == (want), "%s returned %s, expected %s", #expr, fesd_status_name(rc_),             \
          fesd_status_name(want));                                                                 \
  } while (0)

static inline int test_summary(const char *name) {
  if (g_failures) {
    printf("%s: %d check(s) FAILED\n", name, g_failures);
    return 1;
  }
  printf("%s: all checks passed\n", name);
  return 0;
}

/* xorshift64* */
typedef struct {
  unsigned long long s;
} rng_t;
static inline double rng_uniform(rng_t *r) {
  r->s ^= r->s >> 12;
  r->s ^= r->s << 25;
  r->s ^= r->s >> 27;
  return (double)((r->s * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}
static inline double rng_sym(rng_t *r) { return 2.0 * rng_uniform(r) - 1.0; }

/* fesd_ncp_setup with default settings and the given backend. */
static inline int setup_backend(fesd_ncp **ws, const fesd_ncp_problem *p, int backend) {
  fesd_ncp_settings s;
  fesd_ncp_settings_default(&s);
  s.backend = (fesd_ncp_backend)backend;
  return fesd_ncp_setup(ws, p, &s);
}

static inline double vec_dist_inf(const double *a, const double *b, int n) {
  double d = 0.0;
  for (int i = 0; i < n; i++) d = fmax(d, fabs(a[i] - b[i]));
  return d;
}

/* ---------------------------------------------------------------------------
 * LCP w = M z + q, 0 <= z _|_ w >= 0 as raw rows: a_k = z_k, b_k = w_k.
 * M in CSR. Pattern: n entries of the a rows, then M's entries in CSR order. */
typedef struct {
  int n, nnz_m;
  int *rp, *ci;
  double *v, *q;
  int *row, *col; /* pattern for fesd_ncp_problem */
  int fail_after; /* testing hooks: >0 -> return 1 / NaN after that many calls */
  int nan_after;
  int calls;
} lcp_t;

static inline int lcp_eval(const double *z, double *raw, double *jac, void *user) {
  lcp_t *p = (lcp_t *)user;
  int n = p->n;
  p->calls++;
  if (p->fail_after > 0 && p->calls > p->fail_after) return 7;
  for (int k = 0; k < n; k++) raw[k] = z[k];
  for (int i = 0; i < n; i++) {
    double s = p->q[i];
    for (int k = p->rp[i]; k < p->rp[i + 1]; k++) s += p->v[k] * z[p->ci[k]];
    raw[n + i] = s;
  }
  if (p->nan_after > 0 && p->calls > p->nan_after) raw[n] = NAN;
  if (jac) {
    for (int k = 0; k < n; k++) jac[k] = 1.0;
    memcpy(jac + n, p->v, (size_t)p->nnz_m * sizeof(double));
  }
  return 0;
}

static inline void lcp_free(lcp_t *p) {
  free(p->rp);
  free(p->ci);
  free(p->v);
  free(p->q);
  free(p->row);
  free(p->col);
  memset(p, 0, sizeof *p);
}

/* From a dense column-major M (entries with |m| > 0 kept). */
static inline void lcp_from_dense(lcp_t *p, int n, const double *M, const double *q) {
  memset(p, 0, sizeof *p);
  p->n = n;
  int nz = 0;
  for (int i = 0; i < n * n; i++) nz += M[i] != 0.0;
  p->nnz_m = nz;
  p->rp = malloc((size_t)(n + 1) * sizeof(int));
  p->ci = malloc((size_t)(nz ? nz : 1) * sizeof(int));
  p->v = malloc((size_t)(nz ? nz : 1) * sizeof(double));
  p->q = malloc((size_t)n * sizeof(double));
  p->row = malloc((size_t)(n + nz) * sizeof(int));
  p->col = malloc((size_t)(n + nz) * sizeof(int));
  memcpy(p->q, q, (size_t)n * sizeof(double));
  int k = 0;
  for (int i = 0; i < n; i++) {
    p->rp[i] = k;
    for (int j = 0; j < n; j++)
      if (M[i + (size_t)j * n] != 0.0) {
        p->ci[k] = j;
        p->v[k++] = M[i + (size_t)j * n];
      }
  }
  p->rp[n] = k;
  for (int t = 0; t < n; t++) {
    p->row[t] = t;
    p->col[t] = t;
  }
  for (int i = 0; i < n; i++)
    for (int t = p->rp[i]; t < p->rp[i + 1]; t++) {
      p->row[n + t] = n + i;
      p->col[n + t] = p->ci[t];
    }
}

static inline fesd_ncp_problem lcp_problem(lcp_t *p) {
  fesd_ncp_problem pr = {p->n, 0, p->n, p->n + p->nnz_m, p->row, p->col, lcp_eval, p};
  return pr;
}

/* Random P-matrix LCPs (dense column-major M), solution with a chosen active set:
 * kind 0: M = B B'/n + 0.1 I (symmetric positive definite)
 * kind 1: M = B B'/n + (C - C')/sqrt(n) + 0.1 I (positive definite, nonsymmetric)
 * kind 2: sparse strictly diagonally dominant (about 4 off-diagonals per row)
 * q is chosen so that z* has about half its entries positive and w* the rest
 * (strict complementarity); degenerate > 0 makes that many pairs z = w = 0. */
static inline void random_lcp(lcp_t *p, int n, int kind, unsigned long long seed, int degenerate,
                       double *zstar) {
  rng_t r = {seed * 0x9E3779B97F4A7C15ULL + 1};
  double *M = calloc((size_t)n * n, sizeof(double));
  if (kind == 2) {
    for (int i = 0; i < n; i++) {
      double rowsum = 0.0;
      for (int c = 0; c < 4; c++) {
        int j = (int)(rng_uniform(&r) * n);
        if (j == i) continue;
        double v = rng_sym(&r);
        M[i + (size_t)j * n] += v;
      }
      for (int j = 0; j < n; j++)
        if (j != i) rowsum += fabs(M[i + (size_t)j * n]);
      M[i + (size_t)i * n] = rowsum + 0.5 + rng_uniform(&r);
    }
  } else {
    double *B = malloc((size_t)n * n * sizeof(double));
    for (int i = 0; i < n * n; i++) B[i] = rng_sym(&r);
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++) {
        double s = 0.0;
        for (int k = 0; k < n; k++) s += B[i + (size_t)k * n] * B[j + (size_t)k * n];
        M[i + (size_t)j * n] = s / n + (i == j ? 0.1 : 0.0);
      }
    if (kind == 1) {
      for (int i = 0; i < n * n; i++) B[i] = rng_sym(&r);
      for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
          M[i + (size_t)j * n] += (B[i + (size_t)j * n] - B[j + (size_t)i * n]) / sqrt((double)n);
    }
    free(B);
  }
  double *w = malloc((size_t)n * sizeof(double)), *q = malloc((size_t)n * sizeof(double));
  for (int i = 0; i < n; i++) {
    int pos = rng_uniform(&r) < 0.5;
    zstar[i] = pos ? 0.5 + rng_uniform(&r) : 0.0;
    w[i] = pos ? 0.0 : 0.5 + rng_uniform(&r);
    if (i < degenerate) zstar[i] = w[i] = 0.0;
  }
  for (int i = 0; i < n; i++) {
    double s = 0.0;
    for (int j = 0; j < n; j++) s += M[i + (size_t)j * n] * zstar[j];
    q[i] = w[i] - s;
  }
  lcp_from_dense(p, n, M, q);
  free(M);
  free(w);
  free(q);
}

/* Lemke's complementary pivoting with covering vector e (dense tableau).
 * Returns 0 and z on success, -1 on ray termination / pivot limit. */
static inline int lemke(const lcp_t *p, double *z) {
  const int n = p->n, nc = 2 * n + 2; /* columns: w (n), z (n), z0, rhs */
  double *T = calloc((size_t)n * nc, sizeof(double));
  int *basis = malloc((size_t)n * sizeof(int));
  int rc = -1, r = 0;
  for (int i = 0; i < n; i++) {
    T[(size_t)i * nc + i] = 1.0;
    for (int k = p->rp[i]; k < p->rp[i + 1]; k++) T[(size_t)i * nc + n + p->ci[k]] = -p->v[k];
    T[(size_t)i * nc + 2 * n] = -1.0;
    T[(size_t)i * nc + 2 * n + 1] = p->q[i];
    basis[i] = i;
    if (p->q[i] < p->q[r]) r = i;
  }
  memset(z, 0, (size_t)n * sizeof(double));
  if (p->q[r] >= 0.0) {
    rc = 0;
    goto done;
  }
  int enter = 2 * n;
  for (int piv = 0; piv < 50 * n + 100; piv++) {
    /* pivot on (r, enter) */
    double *pr = T + (size_t)r * nc, pv = pr[enter];
    for (int j = 0; j < nc; j++) pr[j] /= pv;
    for (int i = 0; i < n; i++) {
      if (i == r) continue;
      double *ri = T + (size_t)i * nc, f = ri[enter];
      if (f != 0.0)
        for (int j = 0; j < nc; j++) ri[j] -= f * pr[j];
    }
    int leave = basis[r];
    basis[r] = enter;
    if (leave == 2 * n) {
      rc = 0;
      break;
    }
    enter = leave < n ? leave + n : leave - n;
    /* ratio test; ties prefer z0 leaving */
    r = -1;
    double best = INFINITY;
    for (int i = 0; i < n; i++) {
      double a = T[(size_t)i * nc + enter];
      if (a <= 1e-12) continue;
      double ratio = T[(size_t)i * nc + 2 * n + 1] / a;
      if (ratio < best - 1e-12 || (ratio <= best + 1e-12 && basis[i] == 2 * n)) {
        best = ratio;
        r = i;
      }
    }
    if (r < 0) break; /* ray */
  }
  if (rc == 0)
    for (int i = 0; i < n; i++)
      if (basis[i] >= n && basis[i] < 2 * n) z[basis[i] - n] = T[(size_t)i * nc + 2 * n + 1];
done:
  free(T);
  free(basis);
  return rc;
}

/* max_k |min(z_k, w_k)| and negative parts: an LCP residual independent of FB. */
static inline double lcp_natural_residual(const lcp_t *p, const double *z) {
  double r = 0.0;
  for (int i = 0; i < p->n; i++) {
    double w = p->q[i];
    for (int k = p->rp[i]; k < p->rp[i + 1]; k++) w += p->v[k] * z[p->ci[k]];
    r = fmax(r, fabs(fmin(z[i], w)));
  }
  return r;
}

/* Quadratic-convergence check on a residual history ending at a converged value:
 * every step from 1e-10 <= r < 1e-3 must satisfy r_next <= C r^2 or
 * r_next <= 1e-3 r (below 1e-10 the next value is at the rounding floor). */
static inline int history_superlinear(const fesd_ncp_info *info, double C) {
  int ok = 1, checked = 0;
  for (int k = 0; k + 1 < info->history_len; k++) {
    double a = info->residual_history[k], b = info->residual_history[k + 1];
    if (a < 1e-3 && a >= 1e-10) {
      checked++;
      if (!(b <= C * a * a || b <= 1e-3 * a)) ok = 0;
    }
  }
  return ok && checked > 0;
}

static inline void print_history(const fesd_ncp_info *info) {
  printf("    history:");
  for (int k = 0; k < info->history_len; k++) printf(" %.1e", info->residual_history[k]);
  printf("\n");
}

#endif
