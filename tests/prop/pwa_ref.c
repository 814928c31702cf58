/* Event-driven reference for piecewise-affine Filippov systems: see pwa_ref.h. */
#include "pwa_ref.h"

#include <math.h>
#include <string.h>

#define NX PWA_MAX_NX
#define NP (PWA_MAX_NX + PWA_MAX_NU) /* columns of the sensitivity matrix [Sx | Su] */
#define NAUG PWA_MAX_AUG
#define NMON (2 * PWA_MAX_K)

/* ---------------------------------------------------------------- generator */

uint64_t pwa_rng_next(pwa_rng *r) {
  uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
double pwa_uniform(pwa_rng *r, double lo, double hi) {
  return lo + (hi - lo) * ((double)(pwa_rng_next(r) >> 11) * 0x1.0p-53);
}
int pwa_int(pwa_rng *r, int lo, int hi) { return lo + (int)(pwa_rng_next(r) % (uint64_t)(hi - lo + 1)); }

void pwa_random_system(pwa_sys *S, pwa_rng *rng, const pwa_gen *g) {
  memset(S, 0, sizeof(*S));
  const int nx = g->nx, K = g->K, nu = g->nu;
  S->nx = nx, S->K = K, S->nu = nu, S->affine = g->affine;
  double drift[NX];
  for (int r = 0; r < nx; r++) drift[r] = pwa_uniform(rng, -g->drift, g->drift);
  for (int k = 0; k < K; k++) {
    /* angles spread over [0, pi): no two surfaces nearly parallel */
    const double phi = 3.14159265358979323846 * (k + pwa_uniform(rng, 0.15, 0.85)) / K;
    double a[NX] = {cos(phi), sin(phi)}, w[NX] = {-sin(phi), cos(phi)};
    for (int r = 2; r < nx; r++) a[r] = pwa_uniform(rng, -0.3, 0.3), w[r] = pwa_uniform(rng, -0.3, 0.3);
    memcpy(S->a[k], a, sizeof(a));
    S->b[k] = pwa_uniform(rng, -0.3, 0.3);
    const double beta = pwa_uniform(rng, g->beta_lo, g->beta_hi);
    const double gam = pwa_uniform(rng, 0, 1) < g->slide_prob ? pwa_uniform(rng, 0.5, 3.0) : pwa_uniform(rng, -0.3, 0.3);
    for (int i = 0; i < 2; i++) {
      const double sg = i == 0 ? 1.0 : -1.0; /* mode 0: c > 0 */
      for (int r = 0; r < nx; r++) {
        S->d[k][i][r] = sg * (beta * w[r] - gam * a[r]) + pwa_uniform(rng, -0.1, 0.1) + (k == 0 ? drift[r] : 0);
        if (r >= 2) S->d[k][i][r] += pwa_uniform(rng, -0.3, 0.3);
        for (int c = 0; c < nu; c++) S->B[k][i][r][c] = pwa_uniform(rng, -0.5, 0.5);
      }
      if (g->affine) {
        for (int r = 0; r < nx; r++)
          for (int c = 0; c < nx; c++) S->A[k][i][r][c] = pwa_uniform(rng, -g->a_scale, g->a_scale);
        if (k == 0)
          for (int r = 2; r < nx; r++) S->A[k][i][r][r] -= 0.5; /* the extra states stay bounded */
      }
    }
    if (g->affine && k == 0) {
      const double om = pwa_uniform(rng, -g->rot, g->rot);
      for (int i = 0; i < 2; i++) S->A[0][i][0][1] -= om, S->A[0][i][1][0] += om;
    }
  }
}

void pwa_random_x0(const pwa_sys *S, pwa_rng *rng, double *x0) {
  for (int r = 0; r < S->nx; r++) x0[r] = r < 2 ? pwa_uniform(rng, -1.5, 1.5) : pwa_uniform(rng, -0.5, 0.5);
}

/* ---------------------------------------------------------------- model */

void pwa_mode_field(const pwa_sys *S, int k, int i, const double *x, const double *u, double *f) {
  for (int r = 0; r < S->nx; r++) {
    double v = S->d[k][i][r];
    for (int c = 0; c < S->nx; c++) v += S->A[k][i][r][c] * x[c];
    for (int c = 0; c < S->nu; c++) v += S->B[k][i][r][c] * u[c];
    f[r] = v;
  }
}
double pwa_c(const pwa_sys *S, int k, const double *x) {
  double v = S->b[k];
  for (int c = 0; c < S->nx; c++) v += S->a[k][c] * x[c];
  return v;
}

int pwa_cb_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)t;
  pwa_mode_field((const pwa_sys *)user, sys, mode, x, u, f);
  return 0;
}
int pwa_cb_switch(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)t, (void)u;
  c[0] = pwa_c((const pwa_sys *)user, sys, x);
  return 0;
}
int pwa_cb_field_jac(int sys, int mode, double t, const double *x, const double *u, double *dfdx,
                     double *dfdu, void *user) {
  (void)t, (void)x, (void)u;
  const pwa_sys *S = user;
  for (int c = 0; c < S->nx; c++)
    for (int r = 0; r < S->nx; r++) dfdx[c * S->nx + r] = S->A[sys][mode][r][c]; /* column-major */
  if (dfdu)
    for (int c = 0; c < S->nu; c++)
      for (int r = 0; r < S->nx; r++) dfdu[c * S->nx + r] = S->B[sys][mode][r][c];
  return 0;
}
int pwa_cb_switch_jac(int sys, double t, const double *x, const double *u, double *dcdx, double *dcdu,
                      void *user) {
  (void)t, (void)x, (void)u;
  const pwa_sys *S = user;
  for (int c = 0; c < S->nx; c++) dcdx[c] = S->a[sys][c];
  if (dcdu)
    for (int c = 0; c < S->nu; c++) dcdu[c] = 0;
  return 0;
}

/* ---------------------------------------------------------------- linear algebra */

void pwa_expm(int n, const double *M, double *E) {
  /* scale so that ||M/2^q||_1 <= 1/2, Taylor to 1e-20 relative (at most 30 terms), square */
  double nrm = 0;
  for (int c = 0; c < n; c++) {
    double s = 0;
    for (int r = 0; r < n; r++) s += fabs(M[r * n + c]);
    nrm = fmax(nrm, s);
  }
  int q = 0;
  while (nrm > 0.5 && q < 60) nrm *= 0.5, q++;
  const double sc = ldexp(1.0, -q);
  double X[NAUG * NAUG], P[NAUG * NAUG], T[NAUG * NAUG];
  for (int i = 0; i < n * n; i++) X[i] = M[i] * sc;
  for (int i = 0; i < n * n; i++) E[i] = P[i] = (i % (n + 1) == 0);
  for (int k = 1; k <= 30; k++) {
    double pm = 0;
    for (int r = 0; r < n; r++)
      for (int c = 0; c < n; c++) {
        double v = 0;
        for (int j = 0; j < n; j++) v += P[r * n + j] * X[j * n + c];
        T[r * n + c] = v / k;
        pm = fmax(pm, fabs(T[r * n + c]));
      }
    memcpy(P, T, (size_t)n * n * sizeof(double));
    for (int i = 0; i < n * n; i++) E[i] += P[i];
    if (pm <= 1e-20) break;
  }
  for (int s = 0; s < q; s++) {
    for (int r = 0; r < n; r++)
      for (int c = 0; c < n; c++) {
        double v = 0;
        for (int j = 0; j < n; j++) v += E[r * n + j] * E[j * n + c];
        T[r * n + c] = v;
      }
    memcpy(E, T, (size_t)n * n * sizeof(double));
  }
}

/* Solve A X = B (m x m, nrhs columns, row-major with leading dimension NP) by Gaussian
 * elimination with partial pivoting; returns the smallest |pivot| / max |A_ij| (0: singular). */
static double solve_small(int m, double A[][PWA_MAX_K], int nrhs, double Bm[][NP + 1]) {
  double amax = 0, pmin = INFINITY;
  for (int i = 0; i < m; i++)
    for (int j = 0; j < m; j++) amax = fmax(amax, fabs(A[i][j]));
  if (!(amax > 0)) return 0;
  for (int c = 0; c < m; c++) {
    int p = c;
    for (int i = c + 1; i < m; i++)
      if (fabs(A[i][c]) > fabs(A[p][c])) p = i;
    if (p != c) {
      for (int j = 0; j < m; j++) {
        double t = A[c][j];
        A[c][j] = A[p][j], A[p][j] = t;
      }
      for (int j = 0; j < nrhs; j++) {
        double t = Bm[c][j];
        Bm[c][j] = Bm[p][j], Bm[p][j] = t;
      }
    }
    pmin = fmin(pmin, fabs(A[c][c]));
    if (A[c][c] == 0) return 0;
    for (int i = c + 1; i < m; i++) {
      const double l = A[i][c] / A[c][c];
      for (int j = c; j < m; j++) A[i][j] -= l * A[c][j];
      for (int j = 0; j < nrhs; j++) Bm[i][j] -= l * Bm[c][j];
    }
  }
  for (int c = m - 1; c >= 0; c--)
    for (int j = 0; j < nrhs; j++) {
      double v = Bm[c][j];
      for (int k = c + 1; k < m; k++) v -= A[c][k] * Bm[k][j];
      Bm[c][j] = v / A[c][c];
    }
  return pmin / amax;
}

/* ---------------------------------------------------------------- the reference */

typedef struct {
  const pwa_sys *S;
  const double *u;
  const pwa_opts *o;
  pwa_result *r;
  int nx, K, nu, np;
  int cfg[PWA_MAX_K];
  double t, x[NX];
  double P[NX][NP]; /* [Sx | Su] */
  double last_ev;
  double guard_until[PWA_MAX_K];
  int out_i;
  double anorm[PWA_MAX_K];
} ctx;

/* Field of configuration cfg at x: F, theta[k] (weight of mode 0) of the sliding subsystems,
 * optionally the Jacobian J = dF/d(x,u) (nx x np) and dth = dtheta/d(x,u). Returns 0 or
 * PWA_DEGEN_SINGULAR. With fields adding over subsystems, tangency a_j'F = 0 (j sliding) is
 * M theta = r, M_jl = a_j'(f_l0 - f_l1), r_j = -a_j' base. */
static int eval_cfg(const ctx *C, const int *cfg, const double *x, double *F, double *theta, double J[][NP],
                    double dth[][NP]) {
  const pwa_sys *S = C->S;
  const int nx = C->nx, np = C->np;
  int sl[PWA_MAX_K], m = 0;
  double G[NX][NP] = {{0}};
  double Dl[PWA_MAX_K][NX];
  for (int r = 0; r < nx; r++) F[r] = 0;
  for (int k = 0; k < C->K; k++) {
    const int i = cfg[k] == PWA_SLIDE ? 1 : cfg[k];
    double f[NX];
    pwa_mode_field(S, k, i, x, C->u, f);
    for (int r = 0; r < nx; r++) F[r] += f[r];
    if (J)
      for (int r = 0; r < nx; r++) {
        for (int c = 0; c < nx; c++) G[r][c] += S->A[k][i][r][c];
        for (int c = 0; c < C->nu; c++) G[r][nx + c] += S->B[k][i][r][c];
      }
    if (cfg[k] == PWA_SLIDE) {
      double f0[NX];
      pwa_mode_field(S, k, 0, x, C->u, f0);
      for (int r = 0; r < nx; r++) Dl[m][r] = f0[r] - f[r];
      sl[m++] = k;
    }
  }
  if (m == 0) {
    if (J) memcpy(J, G, sizeof(G));
    return 0;
  }
  double M[PWA_MAX_K][PWA_MAX_K], R[PWA_MAX_K][NP + 1];
  for (int i = 0; i < m; i++) {
    const double *a = S->a[sl[i]];
    double rv = 0;
    for (int r = 0; r < nx; r++) rv -= a[r] * F[r];
    R[i][0] = rv;
    for (int l = 0; l < m; l++) {
      double v = 0;
      for (int r = 0; r < nx; r++) v += a[r] * Dl[l][r];
      M[i][l] = v;
    }
  }
  double Mc[PWA_MAX_K][PWA_MAX_K];
  memcpy(Mc, M, sizeof(M));
  if (solve_small(m, Mc, 1, R) < 1e-3) return PWA_DEGEN_SINGULAR;
  for (int l = 0; l < m; l++) {
    theta[sl[l]] = R[l][0];
    for (int r = 0; r < nx; r++) F[r] += R[l][0] * Dl[l][r];
  }
  if (!J) return 0;
  /* G = dbase + sum theta_l dDelta_l; dtheta = -M^{-1} (a_j' G); J = G + sum Delta_l dtheta_l */
  for (int l = 0; l < m; l++) {
    const int k = sl[l];
    const double th = theta[k];
    for (int r = 0; r < nx; r++) {
      for (int c = 0; c < nx; c++) G[r][c] += th * (S->A[k][0][r][c] - S->A[k][1][r][c]);
      for (int c = 0; c < C->nu; c++) G[r][nx + c] += th * (S->B[k][0][r][c] - S->B[k][1][r][c]);
    }
  }
  double W[PWA_MAX_K][NP + 1];
  for (int i = 0; i < m; i++)
    for (int c = 0; c < np; c++) {
      double v = 0;
      for (int r = 0; r < nx; r++) v -= S->a[sl[i]][r] * G[r][c];
      W[i][c] = v;
    }
  memcpy(Mc, M, sizeof(M));
  solve_small(m, Mc, np, W);
  for (int r = 0; r < nx; r++)
    for (int c = 0; c < np; c++) {
      double v = G[r][c];
      for (int l = 0; l < m; l++) v += Dl[l][r] * W[l][c];
      J[r][c] = v;
    }
  if (dth)
    for (int l = 0; l < m; l++) memcpy(dth[sl[l]], W[l], (size_t)np * sizeof(double));
  return 0;
}

/* Monitors (positive while nothing happens): 2k: s c_k/|a_k| (s = +1 in mode 0, -1 in mode 1)
 * or theta_k when sliding; 2k+1: 1 - theta_k when sliding (else unused). der: d/dt. */
static int monitors(const ctx *C, const double *x, double *val, double *der, int *used) {
  double F[NX], th[PWA_MAX_K] = {0}, dth[PWA_MAX_K][NP], J[NX][NP];
  int st = eval_cfg(C, C->cfg, x, F, th, der ? J : NULL, dth);
  if (st) return st;
  for (int k = 0; k < C->K; k++) {
    if (C->cfg[k] == PWA_SLIDE) {
      val[2 * k] = th[k], val[2 * k + 1] = 1 - th[k];
      used[2 * k] = used[2 * k + 1] = 1;
      if (der) {
        double v = 0;
        for (int r = 0; r < C->nx; r++) v += dth[k][r] * F[r];
        der[2 * k] = v, der[2 * k + 1] = -v;
      }
    } else {
      const double s = C->cfg[k] == PWA_MODE0 ? 1.0 : -1.0;
      val[2 * k] = s * pwa_c(C->S, k, x) / C->anorm[k];
      used[2 * k] = 1, used[2 * k + 1] = 0;
      if (der) {
        double v = 0;
        for (int r = 0; r < C->nx; r++) v += C->S->a[k][r] * F[r];
        der[2 * k] = s * v / C->anorm[k];
      }
    }
  }
  return 0;
}

/* Brent's method (zeroin) for f on [a, b] with f(a) f(b) <= 0; tolerance tol in the argument. */
typedef double (*fn1)(double, void *);
static double zeroin(fn1 f, void *p, double a, double b, double fa, double fb, double tol) {
  if (fa == 0) return a;
  if (fb == 0) return b;
  double c = a, fc = fa, d = b - a, e = d;
  for (int it = 0; it < 200; it++) {
    if ((fb > 0) == (fc > 0)) c = a, fc = fa, d = e = b - a;
    if (fabs(fc) < fabs(fb)) a = b, b = c, c = a, fa = fb, fb = fc, fc = fa;
    const double tol1 = 2 * 2.220446049250313e-16 * fabs(b) + 0.5 * tol, xm = 0.5 * (c - b);
    if (fabs(xm) <= tol1 || fb == 0) return b;
    if (fabs(e) >= tol1 && fabs(fa) > fabs(fb)) {
      double s = fb / fa, pp, q;
      if (a == c) {
        pp = 2 * xm * s, q = 1 - s;
      } else {
        const double qq = fa / fc, r = fb / fc;
        pp = s * (2 * xm * qq * (qq - r) - (b - a) * (r - 1));
        q = (qq - 1) * (r - 1) * (s - 1);
      }
      if (pp > 0) q = -q;
      pp = fabs(pp);
      if (2 * pp < fmin(3 * xm * q - fabs(tol1 * q), fabs(e * q))) {
        e = d, d = pp / q;
      } else {
        d = xm, e = d;
      }
    } else {
      d = xm, e = d;
    }
    a = b, fa = fb;
    b += fabs(d) > tol1 ? d : (xm > 0 ? tol1 : -tol1);
    fb = f(b, p);
  }
  return b;
}

/* ---- affine motion without sliding: z = [x; 1; u], z' = Maug z */
typedef struct {
  const ctx *C;
  int n;
  double M[NAUG * NAUG];
  double z[NAUG];
  int mon, deriv;
} region_arg;

static void region_flow(const region_arg *R, double s, double *E, double *x) {
  double Ms[NAUG * NAUG];
  const int n = R->n;
  if (!R->C->S->affine) { /* nilpotent: exp(sM) = I + sM exactly */
    for (int i = 0; i < n * n; i++) E[i] = (i % (n + 1) == 0) + s * R->M[i];
  } else {
    for (int i = 0; i < n * n; i++) Ms[i] = s * R->M[i];
    pwa_expm(n, Ms, E);
  }
  for (int r = 0; r < R->C->nx; r++) {
    double v = 0;
    for (int c = 0; c < n; c++) v += E[r * n + c] * R->z[c];
    x[r] = v;
  }
}

static double region_mon(double s, void *p) {
  const region_arg *R = p;
  double E[NAUG * NAUG], x[NX], val[NMON], der[NMON];
  int used[NMON];
  region_flow(R, s, E, x);
  monitors(R->C, x, val, R->deriv ? der : NULL, used);
  return R->deriv ? der[R->mon] : val[R->mon];
}

/* ---- sliding: one RK4 step of the sliding field (and of [Sx | Su]) */
/* increment dx of x (and the new [Sx | Su] in Po) over one RK4 step of length h */
static int rk4(const ctx *C, const double *x, double P[][NP], double h, double *dx, double Po[][NP]) {
  const int nx = C->nx, np = C->np;
  double k[4][NX], xs[NX], J[NX][NP], th[PWA_MAX_K];
  double Ps[NX][NP], kP[4][NX][NP];
  const double cs[4] = {0, 0.5, 0.5, 1};
  for (int q = 0; q < 4; q++) {
    for (int r = 0; r < nx; r++) {
      xs[r] = x[r] + (q ? cs[q] * h * k[q - 1][r] : 0);
      if (P)
        for (int c = 0; c < np; c++) Ps[r][c] = P[r][c] + (q ? cs[q] * h * kP[q - 1][r][c] : 0);
    }
    int st = eval_cfg(C, C->cfg, xs, k[q], th, P ? J : NULL, NULL);
    if (st) return st;
    if (P) /* d[Sx | Su]/dt = Jx [Sx | Su] + [0 | Ju] */
      for (int r = 0; r < nx; r++)
        for (int c = 0; c < np; c++) {
          double v = c >= nx ? J[r][c] : 0;
          for (int j = 0; j < nx; j++) v += J[r][j] * Ps[j][c];
          kP[q][r][c] = v;
        }
  }
  for (int r = 0; r < nx; r++) {
    dx[r] = h / 6 * (k[0][r] + 2 * k[1][r] + 2 * k[2][r] + k[3][r]);
    if (P)
      for (int c = 0; c < np; c++)
        Po[r][c] = P[r][c] + h / 6 * (kP[0][r][c] + 2 * kP[1][r][c] + 2 * kP[2][r][c] + kP[3][r][c]);
  }
  return 0;
}

typedef struct {
  const ctx *C;
  const double *x;
  int mon;
} slide_arg;

static double slide_mon(double s, void *p) {
  const slide_arg *A = p;
  double x1[NX], val[NMON];
  int used[NMON];
  if (rk4(A->C, A->x, NULL, s, x1, NULL)) return NAN;
  for (int r = 0; r < A->C->nx; r++) x1[r] += A->x[r];
  monitors(A->C, x1, val, NULL, used);
  return val[A->mon];
}

static int fail(ctx *C, int why) {
  C->r->status = why;
  C->r->t_fail = C->t;
  return why;
}

/* [Sx | Su] <- (I + (F+ - F-) a'/(a'F-)) [Sx | Su] at a crossing or entry of surface k */
static void saltation(ctx *C, int k, const double *Fm, const double *Fp) {
  const int nx = C->nx, np = C->np;
  double den = 0;
  for (int r = 0; r < nx; r++) den += C->S->a[k][r] * Fm[r];
  for (int c = 0; c < np; c++) {
    double g = 0;
    for (int r = 0; r < nx; r++) g += C->S->a[k][r] * C->P[r][c];
    for (int r = 0; r < nx; r++) C->P[r][c] += (Fp[r] - Fm[r]) * g / den;
  }
}

static int theta_ok(const ctx *C, const int *cfg, const double *th) {
  for (int k = 0; k < C->K; k++)
    if (cfg[k] == PWA_SLIDE && !(th[k] >= C->o->theta_margin && th[k] <= 1 - C->o->theta_margin)) return 0;
  return 1;
}

/* Surface k reached at C->x: the unique Filippov continuation. Every configuration of the
 * subsystems on their surfaces (the sliding ones and k) in {mode 0, mode 1, sliding} is tried:
 * consistent when its sliding thetas lie in (0, 1) and the field of each of the others leaves
 * the surface into its side. Exactly one must be consistent with margins (theta_margin,
 * trans_min) and every other inconsistent with margins; it is returned in out. */
static int continuation(const ctx *C, int k, int *out) {
  const pwa_opts *o = C->o;
  int on[PWA_MAX_K], n = 0, found = 0;
  for (int j = 0; j < C->K; j++)
    if (j == k || C->cfg[j] == PWA_SLIDE) on[n++] = j;
  int total = 1;
  for (int i = 0; i < n; i++) total *= 3;
  for (int code = 0; code < total; code++) {
    int cfg[PWA_MAX_K];
    memcpy(cfg, C->cfg, sizeof(cfg));
    for (int i = 0, c = code; i < n; i++, c /= 3) cfg[on[i]] = c % 3;
    double F[NX], th[PWA_MAX_K] = {0}, nf = 0;
    int st = eval_cfg(C, cfg, C->x, F, th, NULL, NULL);
    if (st) return st;
    for (int q = 0; q < C->nx; q++) nf = fmax(nf, fabs(F[q]));
    const double thr = o->trans_min * fmax(1, nf), tm = o->theta_margin;
    int good = 1, bad = 0;
    for (int i = 0; i < n; i++) {
      const int j = on[i];
      if (cfg[j] == PWA_SLIDE) {
        good &= th[j] >= tm && th[j] <= 1 - tm;
        bad |= th[j] < -tm || th[j] > 1 + tm;
      } else {
        double an = 0;
        for (int q = 0; q < C->nx; q++) an += C->S->a[j][q] * F[q];
        an *= (cfg[j] == PWA_MODE0 ? 1.0 : -1.0) / C->anorm[j]; /* > 0: into its side */
        good &= an >= thr;
        bad |= an <= -thr;
      }
    }
    if (good && !bad) {
      if (found++) return PWA_DEGEN_NONUNIQUE;
      memcpy(out, cfg, sizeof(cfg));
    } else if (!bad) {
      return PWA_DEGEN_NONUNIQUE; /* neither clearly consistent nor clearly inconsistent */
    }
  }
  return found ? 0 : PWA_DEGEN_NONUNIQUE;
}

/* Monitor mon reached zero at (C->t, C->x): the Filippov continuation, the event record and the
 * saltation. */
static int handle_event(ctx *C, int mon) {
  const pwa_opts *o = C->o;
  const int k = mon / 2, nx = C->nx;
  pwa_result *r = C->r;
  if (C->t - C->last_ev < o->dt_min || o->T - C->t < o->dt_min) return fail(C, PWA_DEGEN_CLOSE);
  if (r->n_ev >= o->max_events || r->n_ev >= PWA_MAX_EV) return fail(C, PWA_DEGEN_MANY);
  double Fm[NX], Fp[NX], th[PWA_MAX_K] = {0};
  int cfg2[PWA_MAX_K], kind, st;
  memcpy(cfg2, C->cfg, sizeof(cfg2));
  if ((st = eval_cfg(C, C->cfg, C->x, Fm, th, NULL, NULL))) return fail(C, st);
  const int before = C->cfg[k];
  if (before != PWA_SLIDE) {
    /* surface k reached from side 'before' */
    const double sm = before == PWA_MODE0 ? 1.0 : -1.0;
    double an = 0, nf = 0;
    for (int q = 0; q < nx; q++) an += C->S->a[k][q] * Fm[q], nf = fmax(nf, fabs(Fm[q]));
    if (-sm * an / C->anorm[k] < o->trans_min * fmax(1, nf)) return fail(C, PWA_DEGEN_TANGENT);
    cfg2[k] = 1 - before;
    if ((st = eval_cfg(C, cfg2, C->x, Fp, th, NULL, NULL))) return fail(C, st);
    double an2 = 0, nf2 = 0;
    for (int q = 0; q < nx; q++) an2 += C->S->a[k][q] * Fp[q], nf2 = fmax(nf2, fabs(Fp[q]));
    an2 *= -sm / C->anorm[k]; /* > 0: the other side's field leaves the surface */
    if (an2 >= o->trans_min * fmax(1, nf2)) {
      kind = PWA_CROSSING;
    } else if (an2 <= -o->trans_min * fmax(1, nf2)) {
      kind = PWA_ENTRY;
      cfg2[k] = PWA_SLIDE;
      if ((st = eval_cfg(C, cfg2, C->x, Fp, th, NULL, NULL))) return fail(C, st);
    } else {
      return fail(C, PWA_DEGEN_TANGENT);
    }
    if (!theta_ok(C, cfg2, th)) return fail(C, PWA_DEGEN_THETA);
    int cfg3[PWA_MAX_K];
    if ((st = continuation(C, k, cfg3))) return fail(C, st);
    if (memcmp(cfg3, cfg2, sizeof(cfg2))) return fail(C, PWA_DEGEN_NONUNIQUE);
    if (o->sens) saltation(C, k, Fm, Fp);
  } else {
    /* theta_k reached 0 (mon even: mode 1 remains) or 1 (mon odd: mode 0 remains) */
    double F[NX], dth[PWA_MAX_K][NP], J[NX][NP];
    if ((st = eval_cfg(C, C->cfg, C->x, F, th, J, dth))) return fail(C, st);
    double rate = 0;
    for (int q = 0; q < nx; q++) rate += dth[k][q] * F[q];
    if (fabs(rate) < o->exit_rate_min) return fail(C, PWA_DEGEN_SLOW_EXIT);
    kind = PWA_EXIT;
    cfg2[k] = mon % 2 == 0 ? PWA_MODE1 : PWA_MODE0;
    if ((st = eval_cfg(C, cfg2, C->x, Fp, th, NULL, NULL))) return fail(C, st);
    if (!theta_ok(C, cfg2, th)) return fail(C, PWA_DEGEN_THETA);
    /* the field is continuous at an exit: no saltation */
  }
  pwa_event *e = &r->ev[r->n_ev++];
  e->t = C->t, e->sys = k, e->kind = kind, e->before = before, e->after = cfg2[k];
  r->n_cross += kind == PWA_CROSSING, r->n_entry += kind == PWA_ENTRY, r->n_exit += kind == PWA_EXIT;
  int others = 0;
  for (int j = 0; j < C->K; j++) others += j != k && C->cfg[j] == PWA_SLIDE;
  if (others) r->n_entry_multi += kind == PWA_ENTRY, r->n_cross_multi += kind == PWA_CROSSING;
  memcpy(C->cfg, cfg2, sizeof(cfg2));
  C->last_ev = C->t;
  C->guard_until[k] = C->t + 0.5 * o->dt_min;
  return 0;
}

static int any_sliding(const ctx *C) {
  int n = 0;
  for (int k = 0; k < C->K; k++) n += C->cfg[k] == PWA_SLIDE;
  return n;
}

static double next_stop(const ctx *C) {
  return C->out_i < C->o->n_out ? C->o->t_out[C->out_i] : C->o->T;
}
static void reached_stop(ctx *C, double ts) {
  C->t = ts;
  while (C->out_i < C->o->n_out && C->o->t_out[C->out_i] <= ts) memcpy(C->r->x_out[C->out_i++], C->x, sizeof(C->x));
}

/* What a phase step offers check_step: the root of monitor m on [0, h], the zero of its time
 * derivative there (extremum), its value at s. */
typedef struct {
  double (*root)(void *p, int m);
  double (*dzero)(void *p, int m);
  double (*value)(void *p, double s, int m);
} step_ops;

/* The earliest monitor that reaches zero in a phase step (v1: values at its end; d0, d1: time
 * derivatives at both ends, NULL when the phase checks extrema itself); its root in
 * *s_out. -1: none; *err: PWA_DEGEN_* (grazing, two events closer than dt_min, a monitor of a
 * subsystem that just switched back at zero). */
static int check_step(ctx *C, const double *v1, const double *d0, const double *d1, const int *used,
                      const step_ops *ops, void *p, double *s_out, int *err) {
  const pwa_opts *o = C->o;
  double best = INFINITY, second = INFINITY;
  int who = -1;
  *err = 0;
  for (int m = 0; m < 2 * C->K; m++) {
    if (!used[m]) continue;
    const int k = m / 2, theta_mon = C->cfg[k] == PWA_SLIDE;
    if (!theta_mon && C->t < C->guard_until[k]) {
      /* just switched: the monitor starts at ~0 and must be clearly positive after */
      if (!(v1[m] > 0)) {
        *err = PWA_DEGEN_CLOSE;
        return -1;
      }
      continue;
    }
    if (v1[m] <= 0) {
      const double s = ops->root(p, m);
      if (s < best) second = best, best = s, who = m;
      else if (s < second) second = s;
    } else if (d0 && d1 && d0[m] < 0 && d1[m] > 0) {
      /* extremum between samples: a near-touch is degenerate, a double crossing too */
      const double vm = ops->value(p, ops->dzero(p, m), m);
      if (vm < (theta_mon ? o->theta_margin : o->graze_margin)) {
        *err = PWA_DEGEN_GRAZING;
        return -1;
      }
    }
  }
  if (who >= 0 && second - best < o->dt_min) {
    *err = PWA_DEGEN_CLOSE;
    return -1;
  }
  *s_out = best;
  return who;
}

typedef struct {
  region_arg R;
  double h, v0[NMON], d0[NMON];
} region_closure;

static double region_root(void *p, int m) {
  region_closure *Q = p;
  Q->R.mon = m, Q->R.deriv = 0;
  return zeroin(region_mon, &Q->R, 0, Q->h, Q->v0[m], region_mon(Q->h, &Q->R), 1e-15);
}
static double region_dzero(void *p, int m) {
  region_closure *Q = p;
  Q->R.mon = m, Q->R.deriv = 1;
  return zeroin(region_mon, &Q->R, 0, Q->h, Q->d0[m], region_mon(Q->h, &Q->R), 1e-15);
}
static double region_value(void *p, double s, int m) {
  region_closure *Q = p;
  Q->R.mon = m, Q->R.deriv = 0;
  return region_mon(s, &Q->R);
}
static const step_ops region_ops = {region_root, region_dzero, region_value};

typedef struct {
  slide_arg A;
  double h, v0[NMON];
} slide_closure;

static double slide_root(void *p, int m) {
  slide_closure *Q = p;
  Q->A.mon = m;
  return zeroin(slide_mon, &Q->A, 0, Q->h, Q->v0[m], slide_mon(Q->h, &Q->A), 1e-15);
}
static double slide_value(void *p, double s, int m) {
  slide_closure *Q = p;
  Q->A.mon = m;
  return slide_mon(s, &Q->A);
}
static const step_ops slide_ops = {slide_root, NULL, slide_value};

static int blown(const ctx *C) {
  for (int q = 0; q < C->nx; q++)
    if (!(fabs(C->x[q]) <= C->o->x_max)) return 1;
  return 0;
}

/* no sliding: exact affine motion, monitors sampled every sample_dt */
static int region_phase(ctx *C) {
  const int nx = C->nx, nu = C->nu, n = nx + 1 + nu, np = C->np;
  region_closure Q;
  memset(&Q, 0, sizeof(Q));
  Q.R.C = C, Q.R.n = n;
  for (int k = 0; k < C->K; k++) {
    const int i = C->cfg[k];
    for (int rr = 0; rr < nx; rr++) {
      for (int c = 0; c < nx; c++) Q.R.M[rr * n + c] += C->S->A[k][i][rr][c];
      Q.R.M[rr * n + nx] += C->S->d[k][i][rr];
      for (int c = 0; c < nu; c++) Q.R.M[rr * n + nx + 1 + c] += C->S->B[k][i][rr][c];
    }
  }
  Q.R.z[nx] = 1;
  for (int c = 0; c < nu; c++) Q.R.z[nx + 1 + c] = C->u[c];
  const double dt = C->o->sample_dt;
  double Efull[NAUG * NAUG], E[NAUG * NAUG], x1[NX];
  memcpy(Q.R.z, C->x, (size_t)nx * sizeof(double));
  region_flow(&Q.R, dt, Efull, x1);
  double tg = C->t; /* t = tg + n dt: no accumulated rounding in t */
  long n_steps = 0;
  for (;;) {
    const double ts = next_stop(C), h = fmin(dt, ts - C->t);
    int used[NMON], st;
    double v1[NMON], d1[NMON], s;
    memcpy(Q.R.z, C->x, (size_t)nx * sizeof(double));
    Q.h = h;
    if ((st = monitors(C, C->x, Q.v0, Q.d0, used))) return fail(C, st);
    if (h == dt) {
      memcpy(E, Efull, sizeof(E));
      for (int r = 0; r < nx; r++) {
        double v = 0;
        for (int c = 0; c < n; c++) v += E[r * n + c] * Q.R.z[c];
        x1[r] = v;
      }
    } else {
      region_flow(&Q.R, h, E, x1);
    }
    if ((st = monitors(C, x1, v1, d1, used))) return fail(C, st);
    int err;
    const int who = check_step(C, v1, Q.d0, d1, used, &region_ops, &Q, &s, &err);
    if (err) return fail(C, err);
    if (who >= 0) region_flow(&Q.R, s, E, x1);
    /* sensitivities: [Sx | Su] <- Exx [Sx | Su] + [0 | Exu] */
    if (C->o->sens) {
      double Pn[NX][NP];
      for (int r = 0; r < nx; r++)
        for (int c = 0; c < np; c++) {
          double v = c >= nx ? E[r * n + nx + 1 + (c - nx)] : 0;
          for (int j = 0; j < nx; j++) v += E[r * n + j] * C->P[j][c];
          Pn[r][c] = v;
        }
      memcpy(C->P, Pn, sizeof(Pn));
    }
    memcpy(C->x, x1, (size_t)nx * sizeof(double));
    if (blown(C)) return fail(C, PWA_DEGEN_BLOWUP);
    if (who >= 0) {
      C->t += s;
      return handle_event(C, who);
    }
    if (h == ts - C->t) {
      reached_stop(C, ts);
      if (ts >= C->o->T) return 0;
      tg = ts, n_steps = 0;
    } else {
      C->t = tg + (double)++n_steps * dt;
    }
  }
}

/* some subsystem slides: RK4 with step rk_h; a local minimum of a monitor (sampled every
 * rk_h) below its margin is a near-touch (grazing) */
static int slide_phase(ctx *C) {
  const int nx = C->nx;
  slide_closure Q;
  memset(&Q, 0, sizeof(Q));
  Q.A.C = C;
  double prev[NMON], comp[NX] = {0}; /* comp: compensated (Kahan) summation of x */
  int have_prev = 0;
  const double t_in = C->t;
  double tg = t_in; /* t = tg + n rk_h: no accumulated rounding in t */
  long n_steps = 0;
  for (;;) {
    /* piecewise-constant fields: the sliding field is constant, RK4 exact for any step */
    const double hr = C->S->affine ? C->o->rk_h : C->o->sample_dt;
    const double ts = next_stop(C), h = fmin(hr, ts - C->t);
    int used[NMON], st, err;
    double v1[NMON], x1[NX], P1[NX][NP], s;
    if ((st = monitors(C, C->x, Q.v0, NULL, used))) return fail(C, st);
    Q.A.x = C->x, Q.h = h;
    if ((st = rk4(C, C->x, NULL, h, x1, NULL))) return fail(C, st);
    for (int r = 0; r < nx; r++) x1[r] += C->x[r];
    if ((st = monitors(C, x1, v1, NULL, used))) return fail(C, st);
    const int who = check_step(C, v1, NULL, NULL, used, &slide_ops, &Q, &s, &err);
    if (err) return fail(C, err);
    if (who < 0 && have_prev)
      for (int m = 0; m < 2 * C->K; m++) {
        if (!used[m] || (C->cfg[m / 2] != PWA_SLIDE && C->t < C->guard_until[m / 2])) continue;
        const double lim = C->cfg[m / 2] == PWA_SLIDE ? C->o->theta_margin : C->o->graze_margin;
        if (Q.v0[m] <= prev[m] && Q.v0[m] <= v1[m] && Q.v0[m] < lim) return fail(C, PWA_DEGEN_GRAZING);
      }
    const double hs = who >= 0 ? s : h;
    if ((st = rk4(C, C->x, C->o->sens ? C->P : NULL, hs, x1, P1))) return fail(C, st);
    memcpy(prev, Q.v0, sizeof(prev));
    have_prev = 1;
    for (int r = 0; r < nx; r++) {
      const double y = x1[r] - comp[r], sum = C->x[r] + y;
      comp[r] = (sum - C->x[r]) - y;
      C->x[r] = sum;
    }
    if (C->o->sens) memcpy(C->P, P1, sizeof(P1));
    if (blown(C)) return fail(C, PWA_DEGEN_BLOWUP);
    if (who >= 0) {
      C->t += hs;
      C->r->t_slide += C->t - t_in;
      return handle_event(C, who);
    }
    if (h == ts - C->t) {
      reached_stop(C, ts);
      if (ts >= C->o->T) {
        C->r->t_slide += C->t - t_in;
        return 0;
      }
      tg = ts, n_steps = 0;
    } else {
      C->t = tg + (double)++n_steps * hr;
    }
  }
}

void pwa_opts_default(pwa_opts *o, double T) {
  memset(o, 0, sizeof(*o));
  o->T = T;
  o->dt_min = 0.02;
  o->trans_min = 0.05;
  o->theta_margin = 0.02;
  o->graze_margin = 0.02;
  o->exit_rate_min = 0.05;
  o->start_margin = 0.02;
  o->sample_dt = 0.01;
  o->rk_h = 2.5e-4;
  o->x_max = 100;
  o->max_events = 200;
}

const char *pwa_status_name(int status) {
  static const char *names[] = {"ok",          "start",    "close",    "tangent",  "grazing", "theta",
                                "singular",    "slow-exit", "many",    "blow-up",  "nonunique", "arg"};
  return status >= 0 && status <= PWA_DEGEN_ARG ? names[status] : "?";
}

int pwa_reference(const pwa_sys *S, const double *x0, const double *u, const pwa_opts *o, pwa_result *r) {
  memset(r, 0, sizeof(*r));
  static const double no_u[PWA_MAX_NU] = {0};
  ctx C;
  memset(&C, 0, sizeof(C));
  C.S = S, C.u = u ? u : no_u, C.o = o, C.r = r;
  C.nx = S->nx, C.K = S->K, C.nu = S->nu, C.np = S->nx + S->nu;
  if (S->nx < 1 || S->nx > NX || S->K < 1 || S->K > PWA_MAX_K || S->nu < 0 || S->nu > PWA_MAX_NU ||
      o->n_out > PWA_MAX_OUT || !(o->T > 0))
    return r->status = PWA_DEGEN_ARG;
  memcpy(C.x, x0, (size_t)S->nx * sizeof(double));
  for (int q = 0; q < C.nx; q++) C.P[q][q] = 1;
  for (int k = 0; k < C.K; k++) {
    double nr = 0;
    for (int q = 0; q < C.nx; q++) nr += S->a[k][q] * S->a[k][q];
    C.anorm[k] = sqrt(nr);
    const double c = pwa_c(S, k, x0) / C.anorm[k];
    if (!(fabs(c) >= o->start_margin)) return fail(&C, PWA_DEGEN_START);
    C.cfg[k] = c > 0 ? PWA_MODE0 : PWA_MODE1;
    C.guard_until[k] = -1;
  }
  int st = 0;
  while (!st && C.t < o->T) {
    const int ns = any_sliding(&C);
    if (ns > r->max_sliding) r->max_sliding = ns;
    st = ns ? slide_phase(&C) : region_phase(&C);
  }
  if (st) return st;
  memcpy(r->x, C.x, (size_t)C.nx * sizeof(double));
  memset(r->Sx, 0, sizeof(r->Sx));
  for (int q = 0; q < C.nx; q++) {
    for (int c = 0; c < C.nx; c++) r->Sx[q][c] = C.P[q][c];
    for (int c = 0; c < C.nu; c++) r->Su[q][c] = C.P[q][C.nx + c];
  }
  memcpy(r->cfg_end, C.cfg, sizeof(C.cfg));
  return r->status = 0;
}
