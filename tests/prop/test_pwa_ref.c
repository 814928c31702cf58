/* Self-test of the reference pwa_ref.c (no libfesd involved):
 *  - pwa_expm against closed forms (rotation, nilpotent Jordan block, a similarity with known
 *    eigenvalues, exp(A) exp(-A) = I for a matrix of norm ~ 40 that needs squaring);
 *  - two systems with closed-form solutions and sensitivities (one and two sliding subsystems);
 *  - random systems (piecewise constant and affine, with crossings, sliding on one and two
 *    surfaces, sliding exits) against fine explicit Euler integrations of the discontinuous
 *    field (h = 8e-6 and 1e-6: the error drops ~8x; chattering averages to the Filippov field because fields of different
 *    subsystems add): states at 6 times;
 *  - sliding phases: RK4 step rk_h against rk_h / 2 (Richardson estimate of the reference error);
 *  - the reference's sensitivities against central differences of the reference itself. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../check.h"
#include "pwa_ref.h"

static double mat_err(int n, const double *A, const double *B) {
  double e = 0;
  for (int i = 0; i < n * n; i++) e = fmax(e, fabs(A[i] - B[i]));
  return e;
}

static int test_expm(void) {
  int fails = 0;
  double E[PWA_MAX_AUG * PWA_MAX_AUG], R[PWA_MAX_AUG * PWA_MAX_AUG];
  /* rotation: expm([[0,-w],[w,0]]) = [[cos w, -sin w], [sin w, cos w]] */
  double worst_rot = 0;
  for (double w = -9; w <= 9; w += 0.75) {
    const double M[4] = {0, -w, w, 0}, X[4] = {cos(w), -sin(w), sin(w), cos(w)};
    pwa_expm(2, M, E);
    worst_rot = fmax(worst_rot, mat_err(2, E, X));
  }
  FESD_TEST_CHECK(worst_rot <= 1e-13, "expm rotation error %.1e", worst_rot);
  /* nilpotent: expm(t N) with N the 3x3 shift = [[1, t, t^2/2], [0, 1, t], [0, 0, 1]] */
  double worst_nil = 0;
  for (double t = -5; t <= 5; t += 0.5) {
    const double M[9] = {0, t, 0, 0, 0, t, 0, 0, 0}, X[9] = {1, t, t * t / 2, 0, 1, t, 0, 0, 1};
    pwa_expm(3, M, E);
    worst_nil = fmax(worst_nil, mat_err(3, E, X) / (1 + t * t));
  }
  FESD_TEST_CHECK(worst_nil <= 1e-14, "expm nilpotent error %.1e", worst_nil);
  /* similarity: A = V diag(l) V^{-1}, V = unit upper triangular [[1,a,b],[0,1,c],[0,0,1]] */
  {
    const double a = 0.7, b = -1.3, c = 2.1, l[3] = {-3.0, 0.5, 1.7};
    const double V[9] = {1, a, b, 0, 1, c, 0, 0, 1}, Vi[9] = {1, -a, a * c - b, 0, 1, -c, 0, 0, 1};
    double A[9], X[9];
    for (int r = 0; r < 3; r++)
      for (int q = 0; q < 3; q++) {
        double va = 0, vx = 0;
        for (int j = 0; j < 3; j++) va += V[r * 3 + j] * l[j] * Vi[j * 3 + q], vx += V[r * 3 + j] * exp(l[j]) * Vi[j * 3 + q];
        A[r * 3 + q] = va, X[r * 3 + q] = vx;
      }
    pwa_expm(3, A, E);
    const double e = mat_err(3, E, X) / exp(1.7);
    FESD_TEST_CHECK(e <= 1e-13, "expm similarity error %.1e", e);
    printf("expm: rotation %.1e, nilpotent %.1e, similarity %.1e", worst_rot, worst_nil, e);
  }
  /* exp(A) exp(-A) = I, A 7x7 with entries in [-6, 6] (norm ~ 40: several squarings) */
  {
    pwa_rng rng = {77};
    const int n = PWA_MAX_AUG;
    double A[PWA_MAX_AUG * PWA_MAX_AUG], Am[PWA_MAX_AUG * PWA_MAX_AUG], P[PWA_MAX_AUG * PWA_MAX_AUG], I[PWA_MAX_AUG * PWA_MAX_AUG];
    double worst = 0;
    for (int rep = 0; rep < 20; rep++) {
      const double sc = rep < 10 ? 1.0 : 6.0;
      for (int i = 0; i < n * n; i++) A[i] = pwa_uniform(&rng, -sc, sc) / n, Am[i] = -A[i];
      pwa_expm(n, A, E);
      pwa_expm(n, Am, R);
      double nE = 0, nR = 0;
      for (int r = 0; r < n; r++)
        for (int q = 0; q < n; q++) {
          double v = 0;
          for (int j = 0; j < n; j++) v += E[r * n + j] * R[j * n + q];
          P[r * n + q] = v, I[r * n + q] = r == q;
          nE = fmax(nE, fabs(E[r * n + q])), nR = fmax(nR, fabs(R[r * n + q]));
        }
      worst = fmax(worst, mat_err(n, P, I) / (nE * nR));
    }
    FESD_TEST_CHECK(worst <= 1e-13, "expm(A) expm(-A) - I: %.1e", worst);
    printf(", exp(A)exp(-A)-I %.1e\n", worst);
  }
  return fails;
}

/* (x1, x2, q): x1' in -sign(x1) + 0.3, x2' in -sign(x2) - 0.2, q' = x2. */
static void reproducer(pwa_sys *S) {
  memset(S, 0, sizeof(*S));
  S->nx = 3, S->K = 2, S->affine = 1;
  for (int k = 0; k < 2; k++) {
    S->a[k][k] = 1;
    for (int i = 0; i < 2; i++) S->d[k][i][k] = (i == 0 ? -1.0 : 1.0) + (k == 0 ? 0.3 : -0.2);
  }
  S->A[0][0][2][1] = S->A[0][1][2][1] = 1; /* q' = x2, carried by subsystem 0 in both modes */
}

static int test_closed_form(void) {
  int fails = 0;
  pwa_sys S;
  reproducer(&S);
  pwa_opts o;
  pwa_opts_default(&o, 3.0);
  o.sens = 1;
  for (int v = 0; v < 2; v++) {
    /* v = 0: x1(0) = 10, never switches; v = 1: x1(0) = 1 reaches 0 at 1/0.7 and slides */
    const double x0[3] = {v ? 1.0 : 10.0, -1.0, 0.0};
    pwa_result r;
    int st = pwa_reference(&S, x0, NULL, &o, &r);
    const double ts = 1.25, t1 = 1 / 0.7;
    const double xe[3] = {v ? 0.0 : 10 - 0.7 * 3, 0.0, -0.625};
    const double Se[3][3] = {{v ? 0.0 : 1.0, 0, 0}, {0, 0, 0}, {0, ts, 1}};
    double ex = 0, es = 0;
    for (int i = 0; i < 3; i++) {
      ex = fmax(ex, fabs(r.x[i] - xe[i]));
      for (int j = 0; j < 3; j++) es = fmax(es, fabs(r.Sx[i][j] - Se[i][j]));
    }
    const int nev = v ? 2 : 1;
    int evok = r.n_ev == nev && r.ev[0].sys == 1 && r.ev[0].kind == PWA_ENTRY && fabs(r.ev[0].t - ts) <= 1e-14;
    if (v) evok = evok && r.ev[1].sys == 0 && r.ev[1].kind == PWA_ENTRY && fabs(r.ev[1].t - t1) <= 1e-14;
    FESD_TEST_CHECK(st == 0 && evok && ex <= 1e-13 && es <= 1e-14,
                    "closed form %d: status %s, events ok %d, state error %.1e, Sx error %.1e", v, pwa_status_name(st),
                    evok, ex, es);
    printf("closed form (%s sliding): %d events, state error %.1e, dx(T)/dx0 error %.1e\n", v ? "two" : "one",
           r.n_ev, ex, es);
  }
  return fails;
}

/* explicit Euler of the discontinuous field (mode by the sign of c_k at the current point) */
static void euler(const pwa_sys *S, const double *x0, const double *u, double h, int nout, const double *tout,
                  double xo[][PWA_MAX_NX]) {
  double x[PWA_MAX_NX], f[PWA_MAX_NX], F[PWA_MAX_NX];
  memcpy(x, x0, sizeof(x));
  long n = 0;
  for (int q = 0; q < nout; q++) {
    const long nend = lround(tout[q] / h);
    for (; n < nend; n++) {
      memset(F, 0, sizeof(F));
      for (int k = 0; k < S->K; k++) {
        pwa_mode_field(S, k, pwa_c(S, k, x) >= 0 ? 0 : 1, x, u, f);
        for (int r = 0; r < S->nx; r++) F[r] += f[r];
      }
      for (int r = 0; r < S->nx; r++) x[r] += h * F[r];
    }
    memcpy(xo[q], x, sizeof(x));
  }
}

typedef struct {
  const char *what;
  int affine, need_entry, need_exit, need_codim2, min_ev;
} wanted;

int main(void) {
  int fails = test_expm();
  fails += test_closed_form();
  const wanted W[] = {
      {"constant, crossings", 0, 0, 0, 0, 8},  {"constant, sliding", 0, 1, 0, 0, 3},
      {"constant, two sliding", 0, 1, 0, 1, 3}, {"affine, crossings", 1, 0, 0, 0, 6},
      {"affine, exits", 1, 1, 1, 0, 3},        {"affine, exits", 1, 1, 1, 0, 3},
      {"affine, two sliding", 1, 1, 0, 1, 3},  {"affine, two sliding", 1, 1, 0, 1, 3},
  };
  const int nw = (int)(sizeof(W) / sizeof(W[0]));
  const double tout[6] = {0.5, 1.0, 1.5, 2.0, 2.5, 3.0};
  pwa_rng rng = {4242};
  double worst_euler = 0, worst_ratio = 0, worst_rich = 0, worst_fd = 0;
  int tried = 0;
  for (int w = 0; w < nw; w++) {
    pwa_sys S;
    double x0[PWA_MAX_NX], u[PWA_MAX_NU];
    pwa_opts o;
    pwa_opts_default(&o, 3.0);
    o.n_out = 6, o.t_out = tout, o.sens = 1;
    static pwa_result r;
    for (int tries = 0; tries < 20000; tries++) {
      tried++;
      pwa_gen g = {.nx = pwa_int(&rng, 2, 4), .K = pwa_int(&rng, 1, 4), .nu = pwa_int(&rng, 0, 2),
                   .affine = W[w].affine, .a_scale = 0.6, .rot = 3, .slide_prob = 0.5, .drift = 0.5,
                   .beta_lo = 1, .beta_hi = 2.5};
      if (W[w].need_codim2 && g.K < 2) g.K = 2;
      pwa_random_system(&S, &rng, &g);
      pwa_random_x0(&S, &rng, x0);
      for (int c = 0; c < S.nu; c++) u[c] = pwa_uniform(&rng, -0.3, 0.3);
      if (pwa_reference(&S, x0, u, &o, &r)) continue;
      if (r.n_ev >= W[w].min_ev && (!W[w].need_entry || r.n_entry > 0) && (!W[w].need_exit || r.n_exit > 0) &&
          (!W[w].need_codim2 || r.max_sliding >= 2))
        break;
    }
    /* Euler, h = 8e-6 and 1e-6: first-order convergence to the reference (the chattering
     * makes the error erratic within a factor ~2, hence the wide ratio) */
    double xe[6][PWA_MAX_NX], xh[6][PWA_MAX_NX], e1 = 0, err = 0, scale = 1;
    euler(&S, x0, u, 8e-6, 6, tout, xe);
    euler(&S, x0, u, 1e-6, 6, tout, xh);
    for (int q = 0; q < 6; q++)
      for (int i = 0; i < S.nx; i++) {
        e1 = fmax(e1, fabs(xe[q][i] - r.x_out[q][i]));
        err = fmax(err, fabs(xh[q][i] - r.x_out[q][i]));
        scale = fmax(scale, fabs(xh[q][i]));
      }
    const double ratio = err / e1;
    err /= scale;
    worst_euler = fmax(worst_euler, err);
    worst_ratio = fmax(worst_ratio, ratio);
    FESD_TEST_CHECK(err <= 3e-4 && ratio <= 0.35, "%s: reference vs Euler %.1e (ratio %.2f)",
                    W[w].what, err, ratio);
    /* Richardson: rk_h / 2 */
    static pwa_result r2;
    pwa_opts o2 = o;
    o2.rk_h = o.rk_h / 2;
    pwa_reference(&S, x0, u, &o2, &r2);
    double rich = 0;
    for (int i = 0; i < S.nx; i++) rich = fmax(rich, fabs(r2.x[i] - r.x[i]));
    worst_rich = fmax(worst_rich, rich);
    FESD_TEST_CHECK(r2.status == 0 && rich <= 1e-12, "%s: rk_h vs rk_h/2 %.1e", W[w].what, rich);
    /* sensitivities vs central differences of the reference (eps 1e-6) */
    double fd = 0, smax = 1;
    pwa_opts o3;
    pwa_opts_default(&o3, 3.0);
    int fd_ok = 1;
    for (int j = 0; j < S.nx + S.nu; j++) {
      double xp[PWA_MAX_NX], xm[PWA_MAX_NX], up[PWA_MAX_NU], um[PWA_MAX_NU];
      memcpy(xp, x0, sizeof(xp)), memcpy(xm, x0, sizeof(xm)), memcpy(up, u, sizeof(up)), memcpy(um, u, sizeof(um));
      const double eps = 1e-6;
      if (j < S.nx) xp[j] += eps, xm[j] -= eps;
      else up[j - S.nx] += eps, um[j - S.nx] -= eps;
      static pwa_result rp, rm;
      fd_ok &= pwa_reference(&S, xp, up, &o3, &rp) == 0 && pwa_reference(&S, xm, um, &o3, &rm) == 0 &&
               rp.n_ev == r.n_ev && rm.n_ev == r.n_ev;
      for (int i = 0; i < S.nx; i++) {
        const double d = (rp.x[i] - rm.x[i]) / (2 * eps), s = j < S.nx ? r.Sx[i][j] : r.Su[i][j - S.nx];
        fd = fmax(fd, fabs(d - s)), smax = fmax(smax, fabs(s));
      }
    }
    fd /= smax;
    worst_fd = fmax(worst_fd, fd);
    FESD_TEST_CHECK(fd_ok && fd <= 1e-6, "%s: sensitivities vs differences of the reference %.1e", W[w].what, fd);
    printf("%-22s K=%d nx=%d nu=%d: %2d events (%d entries, %d exits, %d sliding at once), Euler %.1e "
           "(ratio %.2f), rk_h/2 %.1e, sens vs FD %.1e\n",
           W[w].what, S.K, S.nx, S.nu, r.n_ev, r.n_entry, r.n_exit, r.max_sliding, err, ratio, rich, fd);
  }
  printf("%d systems from %d candidates: worst reference vs Euler (h = 1e-6) %.1e (error ratio h=1e-6 : "
         "8e-6 at most %.2f), vs rk_h/2 %.1e, sens vs FD %.1e\n",
         nw, tried, worst_euler, worst_ratio, worst_rich, worst_fd);
  printf("%d failures\n", fails);
  return fails != 0;
}
