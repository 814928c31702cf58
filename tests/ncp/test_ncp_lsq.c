/* Over-determined systems (m > n): Levenberg-Marquardt with the dense normal
 * equations and with CHOLMOD. A consistent nonsmooth system (an LCP plus extra
 * smooth rows that vanish at its solution) must converge to 1e-12, quadratically;
 * inconsistent ones must return FESD_ERR_INCONSISTENT, never "converged". */
#include "ncp_test_util.h"

/* Raw rows: n_eq smooth rows e_i(z) = sum_j C_ij (z_j - zs_j) + kappa (z_0 - zs_0)^2 + off_i,
 * then the LCP pairs (a_k = z_k, b_k = (M z + q)_k). */
typedef struct {
  lcp_t *lcp;
  int n_eq;
  double *C, *zs, *off, kappa;
  int *row, *col, nnz;
} lsq_t;

static int lsq_eval(const double *z, double *raw, double *jac, void *user) {
  lsq_t *p = (lsq_t *)user;
  int n = p->lcp->n, ne = p->n_eq;
  for (int i = 0; i < ne; i++) {
    double s = p->off[i] + p->kappa * (z[0] - p->zs[0]) * (z[0] - p->zs[0]);
    for (int j = 0; j < n; j++) s += p->C[i * n + j] * (z[j] - p->zs[j]);
    raw[i] = s;
  }
  /* the LCP callback writes a (n) then b (n) and its own Jacobian after ours */
  lcp_eval(z, raw + ne, jac ? jac + ne * n : NULL, p->lcp);
  if (jac)
    for (int i = 0; i < ne; i++)
      for (int j = 0; j < n; j++)
        jac[i * n + j] = p->C[i * n + j] + (j == 0 ? 2.0 * p->kappa * (z[0] - p->zs[0]) : 0.0);
  return 0;
}

static void lsq_build(lsq_t *p, lcp_t *lcp, int n_eq, const double *zs, unsigned long long seed,
                      double kappa) {
  int n = lcp->n;
  rng_t r = {seed};
  p->lcp = lcp;
  p->n_eq = n_eq;
  p->kappa = kappa;
  p->C = malloc((size_t)n_eq * n * sizeof(double));
  p->off = calloc((size_t)n_eq, sizeof(double));
  p->zs = malloc((size_t)n * sizeof(double));
  memcpy(p->zs, zs, (size_t)n * sizeof(double));
  for (int i = 0; i < n_eq * n; i++) p->C[i] = rng_sym(&r);
  p->nnz = n_eq * n + n + lcp->nnz_m;
  p->row = malloc((size_t)p->nnz * sizeof(int));
  p->col = malloc((size_t)p->nnz * sizeof(int));
  int t = 0;
  for (int i = 0; i < n_eq; i++)
    for (int j = 0; j < n; j++) {
      p->row[t] = i;
      p->col[t++] = j;
    }
  for (int k = 0; k < n + lcp->nnz_m; k++) {
    p->row[t] = lcp->row[k] + n_eq; /* a_k rows n_eq+k, b_k rows n_eq+n+k */
    p->col[t++] = lcp->col[k];
  }
}

static void lsq_free(lsq_t *p) {
  free(p->C);
  free(p->off);
  free(p->zs);
  free(p->row);
  free(p->col);
}

static int solve_lsq(lsq_t *p, int backend, int want_rc, const double *zs) {
  int n = p->lcp->n;
  fesd_ncp_problem pr = {n, p->n_eq, n, p->nnz, p->row, p->col, lsq_eval, p};
  fesd_ncp *ws = NULL;
  CHECK_RC(setup_backend(&ws, &pr, backend), FESD_OK);
  if (!ws) return -1;
  double *z = malloc((size_t)n * sizeof(double));
  for (int i = 0; i < n; i++) z[i] = 1.0;
  fesd_ncp_info info;
  int rc = fesd_ncp_solve(ws, z, 0.0, &info);
  double err = zs ? vec_dist_inf(z, zs, n) : 0.0;
  printf("    %-8s m=%d n=%d: %s it=%d fact=%d evals=%d bt=%d |F|=%.1e err=%.1e\n",
         fesd_ncp_backend_name(info.backend), info.m, n, fesd_status_name(rc), info.iterations,
         info.factorizations, info.evals, info.backtracks, info.residual, err);
  CHECK(info.m == n + p->n_eq && info.m == fesd_ncp_rows(ws), "m = %d", info.m);
  CHECK(info.backend == backend, "backend %d", info.backend);
  CHECK(rc == want_rc, "%s, expected %s", fesd_status_name(rc), fesd_status_name(want_rc));
  if (want_rc == FESD_OK) {
    CHECK(info.residual <= 1e-12, "residual %.2e", info.residual);
    CHECK(err <= 1e-8, "solution error %.2e", err);
    int ok = history_superlinear(&info, 10.0);
    if (!ok) print_history(&info);
    CHECK(ok, "LM without quadratic local convergence on a consistent system");
  } else {
    CHECK(info.residual > 1e-6, "an inconsistent system cannot reach a small residual");
    CHECK(info.iterations <= 50, "iterations %d", info.iterations);
  }
  free(z);
  fesd_ncp_free(&ws);
  return rc;
}

/* e1 = z - 1, e2 = z - 2: least-squares point z = 1.5 with ||F|| = 0.5. */
static int tiny_eval(const double *z, double *raw, double *jac, void *user) {
  (void)user;
  raw[0] = z[0] - 1.0;
  raw[1] = z[0] - 2.0;
  if (jac) jac[0] = jac[1] = 1.0;
  return 0;
}

/* FB(z, 1 - z) = 0 forces z in {0, 1}; the row z - 3 = 0 contradicts it. */
static int nonsmooth_eval(const double *z, double *raw, double *jac, void *user) {
  (void)user;
  raw[0] = z[0] - 3.0;
  raw[1] = z[0];
  raw[2] = 1.0 - z[0];
  if (jac) {
    jac[0] = 1.0;
    jac[1] = 1.0;
    jac[2] = -1.0;
  }
  return 0;
}

static void small_inconsistent(int backend) {
  const int row2[2] = {0, 1}, col2[2] = {0, 0}, row3[3] = {0, 1, 2}, col3[3] = {0, 0, 0};
  fesd_ncp_problem p1 = {1, 2, 0, 2, row2, col2, tiny_eval, NULL};
  fesd_ncp_problem p2 = {1, 1, 1, 3, row3, col3, nonsmooth_eval, NULL};
  fesd_ncp_problem *probs[2] = {&p1, &p2};
  const char *names[2] = {"z=1 & z=2", "FB(z,1-z)=0 & z=3"};
  fesd_ncp_settings s;
  fesd_ncp_settings_default(&s);
  s.backend = backend;
  for (int k = 0; k < 2; k++) {
    fesd_ncp *ws = NULL;
    CHECK_RC(fesd_ncp_setup(&ws, probs[k], &s), FESD_OK);
    double z[1] = {0.3};
    fesd_ncp_info info;
    int rc = fesd_ncp_solve(ws, z, 0.0, &info);
    printf("    %-8s %-18s: %s it=%d |F|=%.3f z=%.6f\n", fesd_ncp_backend_name(backend), names[k],
           fesd_status_name(rc), info.iterations, info.residual, z[0]);
    CHECK(rc == FESD_ERR_INCONSISTENT, "%s: %s", names[k], fesd_status_name(rc));
    if (k == 0) CHECK(fabs(z[0] - 1.5) <= 1e-8, "least-squares point 1.5, got %.9f", z[0]);
    fesd_ncp_free(&ws);
  }
}

int main(void) {
  const int lsq_backends[2] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_CHOLMOD};
  printf("Consistent over-determined systems (LCP pairs + smooth rows vanishing at z*)\n");
  for (int c = 0; c < 3; c++) {
    int n = 10 + 40 * c, ne = 2 + 3 * c;
    lcp_t lcp;
    double *zs = malloc((size_t)n * sizeof(double));
    random_lcp(&lcp, n, c == 2 ? 2 : 1, 31 + c, c, zs);
    lsq_t p;
    lsq_build(&p, &lcp, ne, zs, 99 + c, 0.5);
    printf("  n=%d, %d extra rows, %d degenerate pairs\n", n, ne, c);
    for (int b = 0; b < 2; b++) solve_lsq(&p, lsq_backends[b], FESD_OK, zs);
    printf("  same system, one extra row shifted by 0.1 (inconsistent)\n");
    p.off[0] = 0.1;
    for (int b = 0; b < 2; b++) solve_lsq(&p, lsq_backends[b], FESD_ERR_INCONSISTENT, NULL);
    lsq_free(&p);
    lcp_free(&lcp);
    free(zs);
  }
  printf("Small inconsistent systems\n");
  for (int b = 0; b < 2; b++) small_inconsistent(lsq_backends[b]);
  return test_summary("test_ncp_lsq");
}
