/* Random P-matrix LCPs w = Mz + q, 0 <= z _|_ w >= 0 (sizes 5..500, fixed seeds),
 * solved with every backend (dense LU, UMFPACK, KLU, CHOLMOD-LM) and compared
 * with Lemke's method (written in ncp_test_util.h) and with the solution the
 * problem was built from. Also: local quadratic convergence from the residual
 * history, degenerate pairs (z = w = 0), and the smoothed problem (z w = sigma). */
#include "ncp_test_util.h"

static const int backends[] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_UMFPACK,
                               FESD_NCP_BACKEND_KLU, FESD_NCP_BACKEND_CHOLMOD};

/* Solve one LCP with one backend from z0 = 1; returns the iterations (or -1). */
static int solve_lcp(lcp_t *lcp, int backend, const double *zref, int check_quadratic,
                     double *zout) {
  fesd_ncp_problem p = lcp_problem(lcp);
  fesd_ncp *ws = NULL;
  CHECK_RC(setup_backend(&ws, &p, backend), FESD_OK);
  if (!ws) return -1;
  int n = lcp->n;
  double *z = malloc((size_t)n * sizeof(double));
  for (int i = 0; i < n; i++) z[i] = 1.0;
  fesd_ncp_info info;
  int rc = fesd_ncp_solve(ws, z, 0.0, &info);
  double err = vec_dist_inf(z, zref, n), nat = lcp_natural_residual(lcp, z);
  printf("    %-8s %s it=%2d fact=%2d evals=%2d bt=%2d |F|=%.1e err=%.1e min(z,w)=%.1e "
         "t=%.3fs (lin %.3fs)\n",
         fesd_ncp_backend_name(info.backend), fesd_status_name(rc), info.iterations,
         info.factorizations, info.evals, info.backtracks, info.residual, err, nat,
         info.time_total, info.time_linsolve);
  CHECK(rc == FESD_OK, "n=%d backend %s: %s", n, fesd_ncp_backend_name(backend),
        fesd_status_name(rc));
  CHECK(info.residual <= 1e-12, "residual %.2e", info.residual);
  CHECK(err <= 1e-8, "n=%d backend %s: solution error %.2e", n, fesd_ncp_backend_name(backend),
        err);
  CHECK(nat <= 1e-11, "natural residual %.2e", nat);
  CHECK(info.backend == (backend == FESD_NCP_BACKEND_CHOLMOD ? FESD_NCP_BACKEND_CHOLMOD : backend),
        "reported backend %d", info.backend);
  CHECK(info.m == n, "m = %d", info.m);
  CHECK(info.history_len == info.iterations + 1 || info.history_len == FESD_NCP_HISTORY,
        "history length %d for %d iterations", info.history_len, info.iterations);
  if (check_quadratic) {
    int ok = history_superlinear(&info, 10.0);
    if (!ok) print_history(&info);
    CHECK(ok, "n=%d backend %s: no quadratic local convergence", n,
          fesd_ncp_backend_name(backend));
  }
  if (zout) memcpy(zout, z, (size_t)n * sizeof(double));
  free(z);
  fesd_ncp_free(&ws);
  return rc == FESD_OK ? info.iterations : -1;
}

static void random_cases(void) {
  static const struct {
    int n, kind, sparse_backends;
  } cases[] = {{5, 0, 1},   {5, 1, 1},    {10, 0, 1},   {10, 1, 1},  {20, 1, 1},
               {50, 0, 1},  {50, 1, 1},   {100, 1, 1},  {100, 2, 1}, {200, 2, 1},
               {300, 1, 0}, {500, 2, 1}};
  printf("Random P-matrix LCPs (kind 0: SPD, 1: PD nonsymmetric, 2: sparse diag. dominant)\n");
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    int n = cases[c].n;
    lcp_t lcp;
    double *zstar = malloc((size_t)n * sizeof(double)), *zl = malloc((size_t)n * sizeof(double));
    random_lcp(&lcp, n, cases[c].kind, 1000 + c, 0, zstar);
    int lrc = lemke(&lcp, zl);
    double lerr = vec_dist_inf(zl, zstar, n);
    printf("  n=%d kind=%d nnz(M)=%d: Lemke %s, |z_lemke - z*| = %.1e\n", n, cases[c].kind,
           lcp.nnz_m, lrc == 0 ? "ok" : "FAILED", lerr);
    CHECK(lrc == 0 && lerr <= 1e-8, "Lemke reference disagrees with the constructed solution");
    int nb = cases[c].sparse_backends ? 4 : 1;
    for (int b = 0; b < nb; b++) solve_lcp(&lcp, backends[b], zl, 1, NULL);
    free(zstar);
    free(zl);
    lcp_free(&lcp);
  }
}

/* z* = (1, 0): w = (0, 0), so pair 2 is degenerate (z2 = w2 = 0). */
static void small_degenerate(void) {
  printf("Small LCP with a degenerate pair: M = [2 1; 1 2], q = (-2, -1), z* = (1, 0), w* = 0\n");
  const double M[4] = {2, 1, 1, 2}, q[2] = {-2, -1}, zs[2] = {1, 0};
  lcp_t lcp;
  lcp_from_dense(&lcp, 2, M, q);
  CHECK(lcp_natural_residual(&lcp, zs) == 0.0, "definition");
  const double starts[4][2] = {{0, 0}, {1, 1}, {5, -3}, {-1, 2}};
  fesd_ncp_problem p = lcp_problem(&lcp);
  fesd_ncp *ws = NULL;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_OK);
  for (int k = 0; k < 4; k++) {
    double z[2] = {starts[k][0], starts[k][1]};
    fesd_ncp_info info;
    int rc = fesd_ncp_solve(ws, z, 0.0, &info);
    double err = vec_dist_inf(z, zs, 2);
    printf("    z0=(%g,%g): %s it=%d |F|=%.1e err=%.1e\n", starts[k][0], starts[k][1],
           fesd_status_name(rc), info.iterations, info.residual, err);
    CHECK(rc == FESD_OK && info.residual <= 1e-12 && err <= 1e-8, "degenerate 2x2 failed");
  }
  fesd_ncp_free(&ws);
  lcp_free(&lcp);
}

static void random_degenerate(void) {
  printf("Random LCPs with degenerate pairs (z = w = 0 at the solution)\n");
  for (int c = 0; c < 3; c++) {
    int n = 30 + 20 * c;
    lcp_t lcp;
    double *zstar = malloc((size_t)n * sizeof(double));
    random_lcp(&lcp, n, 1, 77 + c, 5 + 5 * c, zstar);
    printf("  n=%d, %d degenerate pairs\n", n, 5 + 5 * c);
    /* P-matrix: every generalized Jacobian is nonsingular, so convergence stays quadratic */
    for (int b = 0; b < 4; b++) solve_lcp(&lcp, backends[b], zstar, 1, NULL);
    free(zstar);
    lcp_free(&lcp);
  }
}

/* With sigma > 0 the FB row's zero set is z, w > 0, z w = sigma. */
static void smoothed(void) {
  printf("Smoothed LCP: sigma = 1e-3 gives z_k w_k = sigma\n");
  int n = 40;
  lcp_t lcp;
  double *zstar = malloc((size_t)n * sizeof(double)), *z = malloc((size_t)n * sizeof(double));
  random_lcp(&lcp, n, 0, 5, 0, zstar);
  fesd_ncp_problem p = lcp_problem(&lcp);
  fesd_ncp *ws = NULL;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_OK);
  for (int i = 0; i < n; i++) z[i] = 1.0;
  fesd_ncp_info info;
  CHECK_RC(fesd_ncp_solve(ws, z, 1e-3, &info), FESD_OK);
  double worst = 0.0;
  for (int i = 0; i < n; i++) {
    double w = lcp.q[i];
    for (int k = lcp.rp[i]; k < lcp.rp[i + 1]; k++) w += lcp.v[k] * z[lcp.ci[k]];
    worst = fmax(worst, fabs(z[i] * w - 1e-3) + (z[i] > 0 && w > 0 ? 0.0 : 1.0));
  }
  printf("    it=%d max |z w - sigma| = %.1e\n", info.iterations, worst);
  CHECK(worst <= 1e-11, "smoothed complementarity violated (%.2e)", worst);
  /* homotopy from the same start ends at the sigma = 0 solution */
  for (int i = 0; i < n; i++) z[i] = 1.0;
  CHECK_RC(fesd_ncp_solve_homotopy(ws, z, &info), FESD_OK);
  printf("    homotopy: stages=%d it=%d err=%.1e\n", info.homotopy_stages, info.iterations,
         vec_dist_inf(z, zstar, n));
  CHECK(info.homotopy_stages == 1, "sigma = 0 first: a P-matrix LCP needs one stage");
  CHECK(vec_dist_inf(z, zstar, n) <= 1e-8, "homotopy solution");
  free(zstar);
  free(z);
  fesd_ncp_free(&ws);
  lcp_free(&lcp);
}

int main(void) {
  random_cases();
  small_degenerate();
  random_degenerate();
  smoothed();
  return test_summary("test_ncp_lcp");
}
