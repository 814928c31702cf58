/* Allocation behaviour, with malloc/calloc/realloc/free interposed by this program
 * (the library and SuiteSparse resolve to these definitions):
 *  1. failure injection: the k-th allocation fails, for every k until a whole
 *     scenario (setup, row changes, solves, sensitivity, free) runs through; each
 *     failure must return FESD_ERR_NOMEM (or FESD_OK where SuiteSparse goes on without
 *     the block) and leave no allocation behind after fesd_ncp_free;
 *  2. repeated solves allocate nothing on the dense and KLU paths.
 * Skipped under AddressSanitizer, which owns malloc itself. */
#include "ncp_test_util.h"

#include "../alloc_hook.h"
#include "ncp/ncp_defer.h"

#if ALLOC_HOOK_ACTIVE
/* One scenario on an LCP with 2 extra consistent rows (so that m > n selections
 * exist): returns FESD_OK when everything ran, or the first failure code. */
typedef struct {
  lcp_t lcp;
  double *zs;
  int *row, *col, nnz;
} prob_t;

static int extra_eval(const double *z, double *raw, double *jac, void *user) {
  prob_t *p = (prob_t *)user;
  raw[0] = z[0] - p->zs[0];
  raw[1] = z[1] - p->zs[1];
  if (jac) jac[0] = jac[1] = 1.0;
  return lcp_eval(z, raw + 2, jac ? jac + 2 : NULL, &p->lcp);
}

static int scenario(prob_t *p, int backend) {
  int n = p->lcp.n, rc;
  fesd_ncp_problem pr = {n, 2, n, p->nnz, p->row, p->col, extra_eval, p};
  fesd_ncp_settings s;
  fesd_ncp_settings_default(&s);
  s.backend = backend;
  fesd_ncp *ws = NULL;
  double z[20], dz[20], draw[2 + 2 * 20] = {0};
  unsigned char eq_off[2] = {0, 0};
  fesd_ncp_info info;
  draw[2 + 20] = 1.0;
  rc = fesd_ncp_setup(&ws, &pr, &s); /* m = n + 2: LM */
  if (rc != FESD_OK) return rc;
  for (int i = 0; i < n; i++) z[i] = 1.0;
  rc = fesd_ncp_solve(ws, z, 0.0, &info);
  if (rc == FESD_OK) rc = fesd_ncp_set_rows(ws, eq_off, NULL); /* square */
  for (int i = 0; i < n && rc == FESD_OK; i++) z[i] = 1.0;
  if (rc == FESD_OK) rc = fesd_ncp_solve_homotopy(ws, z, &info);
  if (rc == FESD_OK) rc = fesd_ncp_sensitivity(ws, z, 0.0, 1, draw, dz);
  if (rc == FESD_OK) rc = fesd_ncp_set_rows(ws, NULL, NULL); /* back to m > n */
  if (rc == FESD_OK) rc = fesd_ncp_solve(ws, z, 0.0, &info);
  fesd_ncp_free(&ws);
  return rc;
}

static void injection(prob_t *p, int backend) {
  long base = g_live, k;
  int nomem = 0, other = 0;
  for (k = 0;; k++) {
    g_count = 0;
    g_fail_at = k;
    int rc = scenario(p, backend);
    g_fail_at = -1;
    CHECK(g_live == base, "%s: %ld allocation(s) leaked when allocation %ld failed (%s)",
          fesd_ncp_backend_name(backend), g_live - base, k, fesd_status_name(rc));
    g_live = base;
    if (g_count <= k) { /* the scenario needed fewer than k+1 allocations: done */
      CHECK(rc == FESD_OK, "%s: complete scenario failed: %s", fesd_ncp_backend_name(backend),
            fesd_status_name(rc));
      break;
    }
    if (rc == FESD_ERR_NOMEM) nomem++;
    else if (rc != FESD_OK) other++;
    /* never disguised as a singular matrix or a solver failure (FESD_OK: the library went
     * on without the block) */
    CHECK(rc == FESD_ERR_NOMEM || rc == FESD_OK, "%s: allocation %ld failed: %s", fesd_ncp_backend_name(backend),
          k, fesd_status_name(rc));
  }
  printf("  %-8s %ld allocations in the scenario; each failure injected: %d x NOMEM, %d x "
         "other codes, no leaks\n",
         fesd_ncp_backend_name(backend), k, nomem, other);
}

/* A KLU workspace of p (its default selection, m = n + 2, would use CHOLMOD). */
static fesd_ncp *klu_workspace(prob_t *p) {
  fesd_ncp_problem pr = {p->lcp.n, 2, p->lcp.n, p->nnz, p->row, p->col, extra_eval, p};
  fesd_ncp_settings s;
  fesd_ncp_settings_default(&s);
  s.backend = FESD_NCP_BACKEND_KLU;
  fesd_ncp *ws = NULL;
  CHECK_RC(fesd_ncp_setup(&ws, &pr, &s), FESD_OK);
  return ws;
}

/* A failed re-analysis leaves the workspace refusing to solve until set_rows succeeds. */
static void not_ready_after_failed_set_rows(prob_t *p) {
  const int n = p->lcp.n;
  fesd_ncp *ws = klu_workspace(p);
  unsigned char eq_off[2] = {0, 0};
  double z[20];
  fesd_ncp_info info;
  g_count = 0;
  g_fail_at = 0; /* the first allocation of the KLU analysis fails */
  int rc = fesd_ncp_set_rows(ws, eq_off, NULL);
  g_fail_at = -1;
  CHECK(rc == FESD_ERR_NOMEM, "set_rows under allocation failure: %s", fesd_status_name(rc));
  for (int i = 0; i < n; i++) z[i] = 1.0;
  CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_ERR_NOT_READY);
  CHECK_RC(fesd_ncp_set_rows(ws, eq_off, NULL), FESD_OK);
  CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_OK);
  printf("  failed set_rows -> %s, solve -> NOT_READY, set_rows again -> solve %s (backend %s)\n",
         fesd_status_name(rc), fesd_status_name(info.status), fesd_ncp_backend_name(info.backend));
  fesd_ncp_free(&ws);
}

/* Deferred analysis (the integrator's workspaces): set_rows and the residual allocate nothing;
 * a failure of the analysis at the first Jacobian is returned by that solve, and the next
 * solve analyses again and succeeds. */
static void deferred_analysis_retried(prob_t *p) {
  const int n = p->lcp.n;
  fesd_ncp *ws = klu_workspace(p);
  unsigned char eq_off[2] = {0, 0};
  double z[20], res;
  fesd_ncp_info info;
  fesd__ncp_defer_analysis(ws);
  for (int i = 0; i < n; i++) z[i] = 1.0;
  g_count = 0;
  g_fail_at = -1; /* counting only */
  CHECK_RC(fesd_ncp_set_rows(ws, eq_off, NULL), FESD_OK);
  CHECK_RC(fesd_ncp_residual(ws, z, 0.0, NULL, &res), FESD_OK);
  const long before = g_count;
  g_count = 0;
  g_fail_at = 0; /* the first allocation of the analysis fails */
  int rc = fesd_ncp_solve(ws, z, 0.0, &info);
  g_fail_at = -1;
  CHECK(rc == FESD_ERR_NOMEM, "solve with a failing deferred analysis: %s", fesd_status_name(rc));
  for (int i = 0; i < n; i++) z[i] = 1.0;
  CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_OK);
  CHECK(before == 0, "deferred set_rows and residual allocated %ld blocks", before);
  printf("  deferred: set_rows + residual %ld allocations, failed analysis -> %s, next solve %s\n", before,
         fesd_status_name(rc), fesd_status_name(info.status));
  fesd_ncp_free(&ws);
}

static void no_alloc_in_solve(prob_t *p, int backend, int expect_zero) {
  int n = p->lcp.n;
  fesd_ncp_problem pr = {n, 2, n, p->nnz, p->row, p->col, extra_eval, p};
  fesd_ncp_settings s;
  fesd_ncp_settings_default(&s);
  s.backend = backend;
  fesd_ncp *ws = NULL;
  unsigned char eq_off[2] = {0, 0};
  CHECK_RC(fesd_ncp_setup(&ws, &pr, &s), FESD_OK);
  long counts[2];
  for (int sel = 0; sel < 2; sel++) { /* square, then over-determined */
    CHECK_RC(fesd_ncp_set_rows(ws, sel ? NULL : eq_off, NULL), FESD_OK);
    double z[20];
    fesd_ncp_info info;
    for (int i = 0; i < n; i++) z[i] = 1.0;
    fesd_ncp_solve(ws, z, 0.0, &info); /* first numeric factorization may allocate */
    g_count = 0;
    g_fail_at = -1; /* counting only */
    for (int rep = 0; rep < 3; rep++) {
      for (int i = 0; i < n; i++) z[i] = 1.0;
      CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_OK);
    }
    g_fail_at = -1;
    counts[sel] = g_count;
  }
  printf("  %-8s allocations in 3 repeated solves: square %ld, m > n (%s) %ld\n",
         fesd_ncp_backend_name(backend), counts[0],
         backend == FESD_NCP_BACKEND_DENSE ? "dense" : "cholmod", counts[1]);
  if (expect_zero) CHECK(counts[0] == 0, "%s allocates while solving", fesd_ncp_backend_name(backend));
  fesd_ncp_free(&ws);
}

int main(void) {
  printf("(stdout buffer allocated before counting)\n");
  prob_t p;
  int n = 20;
  p.zs = malloc((size_t)n * sizeof(double));
  random_lcp(&p.lcp, n, 1, 8, 0, p.zs);
  p.nnz = 2 + n + p.lcp.nnz_m;
  p.row = malloc((size_t)p.nnz * sizeof(int));
  p.col = malloc((size_t)p.nnz * sizeof(int));
  p.row[0] = 0;
  p.col[0] = 0;
  p.row[1] = 1;
  p.col[1] = 1;
  for (int t = 0; t < n + p.lcp.nnz_m; t++) {
    p.row[2 + t] = p.lcp.row[t] + 2;
    p.col[2 + t] = p.lcp.col[t];
  }
  const int backends[4] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_UMFPACK, FESD_NCP_BACKEND_KLU,
                           FESD_NCP_BACKEND_CHOLMOD};
  printf("Allocation failure injection\n");
  for (int b = 0; b < 4; b++) injection(&p, backends[b]);
  printf("Recovery from a failed re-analysis\n");
  not_ready_after_failed_set_rows(&p);
  deferred_analysis_retried(&p);
  printf("Allocations while solving (after the first solve of a selection)\n");
  no_alloc_in_solve(&p, FESD_NCP_BACKEND_DENSE, 1);
  no_alloc_in_solve(&p, FESD_NCP_BACKEND_KLU, 1);
  no_alloc_in_solve(&p, FESD_NCP_BACKEND_UMFPACK, 0);
  free(p.zs);
  free(p.row);
  free(p.col);
  lcp_free(&p.lcp);
  return test_summary("test_ncp_alloc");
}
#else
int main(void) {
  printf("test_ncp_alloc: skipped under AddressSanitizer (it interposes malloc)\n");
  return 77;
}
#endif
