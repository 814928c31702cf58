/* The step system's analytic Jacobian (and parameter Jacobian) against central finite
 * differences of its own residual, for several models and RK families (stiffly accurate
 * and boundary-point methods), at random points, with random row weights and a layout of
 * fewer elements than the storage holds. Independent of the solver. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fesd/system.h"
#include "problems/problems.h"

static unsigned long long rng = 88172645463325252ULL;
static double urand(void) {
  rng ^= rng << 13;
  rng ^= rng >> 7;
  rng ^= rng << 17;
  return (double)(rng >> 11) / 9007199254740992.0;
}

/* exit: pin a sliding exit of mode 0 at boundary 1 (boundary-point methods: the extrapolated
 * theta row) */
static int check(const char *prob, fesd_rk_family fam, int s, int N, int exit) {
  fesd_problem P;
  fesd_problem_get(prob, &P);
  fesd__model M;
  fesd__system S;
  fesd_tableau tab;
  if (fesd__model_init(&M, &P.model) || fesd_tableau_get(fam, s, &tab) ||
      fesd__system_init(&S, &M, &tab, N + 2, 1)) {
    printf("FAIL setup %s\n", prob);
    return 1;
  }
  fesd__system_set_N(&S, N);
  int bmode[8] = {0}, exit_mode[8] = {0};
  bmode[1] = exit ? 2 : 0;
  fesd__system_set_exits(&S, bmode, exit_mode);
  for (int r = 0; r < S.n_raw; r++) S.wraw[r] = 0.5 + urand();
  for (int k = 0; k < S.nsys; k++) S.wG[k] = 0.2 + 2 * urand();
  for (int i = 0; i < S.nth; i++) S.wth[i] = S.wG[M.sys_of[i]];
  const int n = S.n, nr = S.n_raw, np = S.nx + S.nu;
  int *prow = malloc(S.nnz * sizeof(int)), *pcol = malloc(S.nnz * sizeof(int));
  fesd__system_pattern(&S, prow, pcol);
  double *z = malloc(n * sizeof(double)), *zp = malloc(n * sizeof(double));
  double *raw = malloc(nr * sizeof(double)), *r1 = malloc(nr * sizeof(double)),
         *r2 = malloc(nr * sizeof(double));
  double *jac = malloc(S.nnz * sizeof(double)), *J = calloc((size_t)nr * n, sizeof(double));
  double *dp = malloc((size_t)nr * np * sizeof(double));
  double x0[8], u[4] = {0.3, -0.2, 0, 0}, lam00[16];
  for (int i = 0; i < S.nx; i++) x0[i] = P.x0[i] + 0.1 * urand();
  for (int i = 0; i < S.nth; i++) lam00[i] = urand();
  for (int i = 0; i < n; i++) z[i] = urand() - 0.3;
  for (int k = 0; k < N; k++) z[S.ho[k]] = 0.05 + 0.1 * urand();
  S.x0 = x0;
  S.u = u;
  S.lam00 = lam00;
  S.T = 0.3;
  S.want_u = 1;
  memset(S.lam00_dp, 0, (size_t)S.nth * np * sizeof(double));
  fesd__system_eval(z, raw, jac, &S);
  for (int k = 0; k < S.nnz; k++) J[(size_t)pcol[k] * nr + prow[k]] += jac[k];
  fesd__system_param_jac(&S, z, dp);
  double worst = 0, worstp = 0;
  for (int c = 0; c < n; c++) {
    double h = 1e-6 * fmax(1, fabs(z[c]));
    memcpy(zp, z, n * sizeof(double));
    zp[c] = z[c] + h;
    fesd__system_eval(zp, r1, NULL, &S);
    zp[c] = z[c] - h;
    fesd__system_eval(zp, r2, NULL, &S);
    for (int r = 0; r < nr; r++) {
      double fd = (r1[r] - r2[r]) / (2 * h);
      worst = fmax(worst, fabs(fd - J[(size_t)c * nr + r]) / fmax(1, fabs(fd)));
    }
  }
  for (int c = 0; c < np; c++) {
    double *v = c < S.nx ? &x0[c] : &u[c - S.nx], keep = *v, h = 1e-6;
    *v = keep + h;
    fesd__system_eval(z, r1, NULL, &S);
    *v = keep - h;
    fesd__system_eval(z, r2, NULL, &S);
    *v = keep;
    for (int r = 0; r < nr; r++) {
      double fd = (r1[r] - r2[r]) / (2 * h);
      worstp = fmax(worstp, fabs(fd - dp[(size_t)c * nr + r]) / fmax(1, fabs(fd)));
    }
  }
  int fail = worst > 1e-6 || worstp > 1e-6;
  printf("%s %-13s %-9s s=%d N=%d%s n=%4d nnz=%5d: max rel err jac %.2e, param jac %.2e\n",
         fail ? "FAIL" : "ok  ", prob, fesd_rk_family_name(fam), s, N, exit ? " exit" : "", n, S.nnz, worst, worstp);
  free(z), free(zp), free(raw), free(r1), free(r2), free(jac), free(J), free(dp), free(prow), free(pcol);
  fesd__system_free(&S);
  fesd__model_free(&M);
  return fail;
}

int main(void) {
  int fails = 0;
  fails += check("oscillator", FESD_RK_RADAU_IIA, 2, 2, 0);
  fails += check("oscillator", FESD_RK_RADAU_IIA, 3, 3, 0);
  fails += check("oscillator", FESD_RK_GAUSS_LEGENDRE, 2, 3, 0);
  fails += check("oscillator", FESD_RK_GAUSS_LEGENDRE, 3, 3, 1);
  fails += check("oscillator", FESD_RK_LOBATTO_IIIC, 3, 2, 0);
  fails += check("oscillator", FESD_RK_LOBATTO_IIIA, 3, 3, 0);
  fails += check("oscillator", FESD_RK_EXPLICIT, 4, 2, 0);
  fails += check("sign-c", FESD_RK_RADAU_IIA, 2, 2, 0);
  /* curved switching surface: the look-ahead stage's Hessian term (by differences) */
  fails += check("slide-exit-2d", FESD_RK_LOBATTO_IIIA, 2, 2, 0);
  fails += check("slide-exit-2d", FESD_RK_LOBATTO_IIIA, 4, 3, 0);
  fails += check("slide-exit-2d", FESD_RK_GAUSS_LEGENDRE, 2, 2, 1);
  fails += check("ocp-dynamics", FESD_RK_RADAU_IIA, 2, 3, 0);
  fails += check("ocp-dynamics", FESD_RK_GAUSS_LEGENDRE, 1, 2, 0);
  fails += check("ocp-dynamics", FESD_RK_LOBATTO_IIIA, 2, 2, 0);
  printf("%d failures\n", fails);
  return fails != 0;
}
