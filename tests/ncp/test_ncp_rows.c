/* Row selection (fesd_ncp_set_rows): the documented assembled row order and m,
 * eq rows switched off, pairs in PIN, OFF, A and B mode, square <-> over-determined
 * switches with every backend, and the errors for too few rows / bad modes. */
#include "ncp_test_util.h"

/* Raw rows with recognisable values: e_i = 10 (i+1) + z_0, a_k = z_1 + k, b_k = z_2 - k. */
static int order_eval(const double *z, double *raw, double *jac, void *user) {
  (void)user;
  for (int i = 0; i < 3; i++) raw[i] = 10.0 * (i + 1) + z[0];
  for (int k = 0; k < 2; k++) {
    raw[3 + k] = z[1] + k;
    raw[5 + k] = z[2] - k;
  }
  if (jac)
    for (int t = 0; t < 7; t++) jac[t] = 1.0;
  return 0;
}

static void check_order(void) {
  printf("Assembled row order\n");
  const int row[7] = {0, 1, 2, 3, 4, 5, 6}, col[7] = {0, 0, 0, 1, 1, 2, 2};
  fesd_ncp_problem p = {3, 3, 2, 7, row, col, order_eval, NULL};
  fesd_ncp *ws = NULL;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_OK);
  const double z[3] = {0.5, 2.0, 3.0};
  double F[7], nrm;
  CHECK(fesd_ncp_rows(ws) == 5, "default m = n_eq + n_pair = 5, got %d", fesd_ncp_rows(ws));

  const unsigned char eq1[3] = {1, 0, 1}, pm1[2] = {FESD_NCP_PAIR_PIN, FESD_NCP_PAIR_FB};
  CHECK_RC(fesd_ncp_set_rows(ws, eq1, pm1), FESD_OK);
  CHECK(fesd_ncp_rows(ws) == 5, "m = 2 eq + 2 PIN + 1 FB = 5, got %d", fesd_ncp_rows(ws));
  CHECK_RC(fesd_ncp_residual(ws, z, 0.0, F, &nrm), FESD_OK);
  double want1[5] = {10.5, 30.5, 2.0, 3.0, fesd_fb(3.0, 2.0, 0.0, NULL, NULL)};
  printf("  eq {1,0,1}, pairs {PIN,FB}: F =");
  for (int i = 0; i < 5; i++) printf(" %g", F[i]);
  printf("\n");
  CHECK(vec_dist_inf(F, want1, 5) == 0.0, "row order (eq, then pair 0 a,b, then FB of pair 1)");
  CHECK(nrm == 30.5, "norm %g", nrm);

  const unsigned char pm2[2] = {FESD_NCP_PAIR_OFF, FESD_NCP_PAIR_PIN};
  CHECK_RC(fesd_ncp_set_rows(ws, eq1, pm2), FESD_OK);
  CHECK(fesd_ncp_rows(ws) == 4, "m = 2 eq + OFF + 2 PIN = 4, got %d", fesd_ncp_rows(ws));
  CHECK_RC(fesd_ncp_residual(ws, z, 0.0, F, NULL), FESD_OK);
  double want2[4] = {10.5, 30.5, 3.0, 2.0};
  CHECK(vec_dist_inf(F, want2, 4) == 0.0, "row order with an OFF pair");

  /* too few rows: rejected, the previous selection stays */
  const unsigned char eq0[3] = {0, 0, 0}, pm3[2] = {FESD_NCP_PAIR_OFF, FESD_NCP_PAIR_FB};
  CHECK_RC(fesd_ncp_set_rows(ws, eq0, pm3), FESD_ERR_DIMENSION);
  CHECK(fesd_ncp_rows(ws) == 4, "selection unchanged after the error, m = %d", fesd_ncp_rows(ws));
  const unsigned char pm4[2] = {FESD_NCP_PAIR_B, FESD_NCP_PAIR_A};
  CHECK_RC(fesd_ncp_set_rows(ws, NULL, pm4), FESD_OK);
  CHECK(fesd_ncp_rows(ws) == 5, "m = 3 eq + B + A = 5, got %d", fesd_ncp_rows(ws));
  CHECK_RC(fesd_ncp_residual(ws, z, 0.0, F, NULL), FESD_OK);
  double want4[5] = {10.5, 20.5, 30.5, 3.0, 3.0};
  CHECK(vec_dist_inf(F, want4, 5) == 0.0, "row order with B (b_0) and A (a_1) modes");
  const unsigned char bad[2] = {5, 0};
  CHECK_RC(fesd_ncp_set_rows(ws, NULL, bad), FESD_ERR_INVALID_ARG);
  CHECK_RC(fesd_ncp_set_rows(NULL, NULL, NULL), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_set_rows(ws, NULL, NULL), FESD_OK);
  CHECK(fesd_ncp_rows(ws) == 5, "NULL arrays restore all rows / all FB");
  fesd_ncp_free(&ws);
}

/* LCP pairs with a degenerate pair 0 (z = w = 0) plus two eq rows e_j = z_{J_j} - z*_{J_j}
 * that are consistent with the LCP solution. Selections that drop pairs are only
 * locally well posed, so the solves start near z* (as FESD's warm starts do). */
typedef struct {
  lcp_t lcp;
  double *zs;
  int idx[2];
  int *row, *col, nnz;
} rows_t;

static int rows_eval(const double *z, double *raw, double *jac, void *user) {
  rows_t *p = (rows_t *)user;
  for (int j = 0; j < 2; j++) raw[j] = z[p->idx[j]] - p->zs[p->idx[j]];
  if (jac) jac[0] = jac[1] = 1.0;
  return lcp_eval(z, raw + 2, jac ? jac + 2 : NULL, &p->lcp);
}

static void solve_sel(rows_t *p, int backend, const unsigned char *eq, const unsigned char *pm,
                      int want_m, int want_backend, const char *what) {
  int n = p->lcp.n;
  fesd_ncp_problem pr = {n, 2, n, p->nnz, p->row, p->col, rows_eval, p};
  fesd_ncp *ws = NULL;
  CHECK_RC(setup_backend(&ws, &pr, backend), FESD_OK);
  if (!ws) return;
  double *z = malloc((size_t)n * sizeof(double));
  /* the same workspace goes through several selections (re-analysis when sparse) */
  for (int rep = 0; rep < 2; rep++) {
    CHECK_RC(fesd_ncp_set_rows(ws, NULL, NULL), FESD_OK);
    for (int i = 0; i < n; i++) z[i] = 1.0;
    fesd_ncp_info info;
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_OK);
    CHECK_RC(fesd_ncp_set_rows(ws, eq, pm), FESD_OK);
    for (int i = 0; i < n; i++) z[i] = p->zs[i] + 0.01 * ((i % 3) - 1.0);
    int rc = fesd_ncp_solve(ws, z, 0.0, &info);
    double err = vec_dist_inf(z, p->zs, n);
    if (rep == 0)
      printf("    %-8s %-34s m=%d backend=%s: %s it=%d |F|=%.1e err=%.1e\n",
             fesd_ncp_backend_name(backend), what, info.m, fesd_ncp_backend_name(info.backend),
             fesd_status_name(rc), info.iterations, info.residual, err);
    CHECK(info.m == want_m && fesd_ncp_rows(ws) == want_m, "m = %d, want %d", info.m, want_m);
    CHECK(info.backend == want_backend, "backend %s, want %s", fesd_ncp_backend_name(info.backend),
          fesd_ncp_backend_name(want_backend));
    CHECK(rc == FESD_OK && info.residual <= 1e-12 && err <= 1e-8, "%s: %s err %.1e", what,
          fesd_status_name(rc), err);
  }
  free(z);
  fesd_ncp_free(&ws);
}

static void check_solves(void) {
  printf("Solves with selections (LCP n=40 with degenerate pair 0, 2 consistent eq rows)\n");
  rows_t p;
  int n = 40;
  p.zs = malloc((size_t)n * sizeof(double));
  random_lcp(&p.lcp, n, 1, 4242, 1, p.zs);
  p.idx[0] = 1; /* z_1 and z_7 */
  p.idx[1] = 7;
  p.nnz = 2 + n + p.lcp.nnz_m;
  p.row = malloc((size_t)p.nnz * sizeof(int));
  p.col = malloc((size_t)p.nnz * sizeof(int));
  p.row[0] = 0;
  p.col[0] = p.idx[0];
  p.row[1] = 1;
  p.col[1] = p.idx[1];
  for (int t = 0; t < n + p.lcp.nnz_m; t++) {
    p.row[2 + t] = p.lcp.row[t] + 2;
    p.col[2 + t] = p.lcp.col[t];
  }
  unsigned char eq_off[2] = {0, 0}, eq_one[2] = {1, 0}, eq_all[2] = {1, 1};
  unsigned char *pm_fb = calloc((size_t)n, 1), *pm_pin = calloc((size_t)n, 1),
                *pm_pin2 = calloc((size_t)n, 1);
  /* pair 0 pinned (a = b = 0 holds at z*), pair 1 off: 2 + (n-2) = n rows */
  pm_pin[0] = FESD_NCP_PAIR_PIN;
  pm_pin[1] = FESD_NCP_PAIR_OFF;
  /* also pair 2 off, replaced by eq row 0 (z_1 = z*_1): 1 + 2 + (n-3) = n rows */
  memcpy(pm_pin2, pm_pin, (size_t)n);
  pm_pin2[2] = FESD_NCP_PAIR_OFF;
  const int sq[3] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_UMFPACK, FESD_NCP_BACKEND_KLU};
  for (int b = 0; b < 3; b++) {
    solve_sel(&p, sq[b], eq_off, pm_fb, n, sq[b], "eq off, all FB (square)");
    solve_sel(&p, sq[b], eq_off, pm_pin, n, sq[b], "eq off, PIN 0, OFF 1 (square)");
    solve_sel(&p, sq[b], eq_one, pm_pin2, n, sq[b], "eq {1,0}, PIN 0, OFF 1,2 (square)");
    /* over-determined selections go to LM: dense normal equations or CHOLMOD */
    int lsq = sq[b] == FESD_NCP_BACKEND_DENSE ? FESD_NCP_BACKEND_DENSE : FESD_NCP_BACKEND_CHOLMOD;
    solve_sel(&p, sq[b], eq_all, pm_fb, n + 2, lsq, "all eq, all FB (m = n+2)");
    solve_sel(&p, sq[b], eq_all, NULL, n + 2, lsq, "NULL pair modes = all FB");
  }
  /* A / B fix the active set of the solution: a smooth (here linear) system */
  unsigned char *pm_ab = calloc((size_t)n, 1);
  for (int k = 0; k < n; k++) pm_ab[k] = p.zs[k] > 0.0 ? FESD_NCP_PAIR_B : FESD_NCP_PAIR_A;
  for (int b = 0; b < 3; b++)
    solve_sel(&p, sq[b], eq_off, pm_ab, n, sq[b], "active set fixed by A/B modes");
  free(pm_ab);
  pm_pin[1] = FESD_NCP_PAIR_FB;
  solve_sel(&p, FESD_NCP_BACKEND_CHOLMOD, eq_off, pm_pin, n + 1, FESD_NCP_BACKEND_CHOLMOD,
            "PIN 0 (m = n+1)");
  solve_sel(&p, FESD_NCP_BACKEND_DENSE, eq_off, pm_pin, n + 1, FESD_NCP_BACKEND_DENSE,
            "PIN 0 (m = n+1)");
  free(pm_pin2);
  free(pm_fb);
  free(pm_pin);
  free(p.zs);
  free(p.row);
  free(p.col);
  lcp_free(&p.lcp);
}

/* The default selection is analysed at its first use: a rejected selection while it is
 * still pending leaves it in force, and the first residual applies it (all rows, FB). */
static void check_deferred_default(void) {
  printf("Default selection analysed at first use\n");
  const int row[7] = {0, 1, 2, 3, 4, 5, 6}, col[7] = {0, 0, 0, 1, 1, 2, 2};
  fesd_ncp_problem p = {3, 3, 2, 7, row, col, order_eval, NULL};
  const int backends[] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_KLU, FESD_NCP_BACKEND_CHOLMOD};
  for (int b = 0; b < 3; b++) {
    fesd_ncp *ws = NULL;
    CHECK_RC(setup_backend(&ws, &p, backends[b]), FESD_OK);
    const unsigned char eq0[3] = {0, 0, 0}, pm0[2] = {FESD_NCP_PAIR_OFF, FESD_NCP_PAIR_FB};
    CHECK_RC(fesd_ncp_set_rows(ws, eq0, pm0), FESD_ERR_DIMENSION);
    CHECK(fesd_ncp_rows(ws) == 5, "%s: default m = 5 kept, got %d", fesd_ncp_backend_name(backends[b]),
          fesd_ncp_rows(ws));
    const double z[3] = {0.5, 2.0, 3.0};
    double F[7];
    CHECK_RC(fesd_ncp_residual(ws, z, 0.0, F, NULL), FESD_OK);
    double want[5] = {10.5, 20.5, 30.5, fesd_fb(2.0, 3.0, 0.0, NULL, NULL), fesd_fb(3.0, 2.0, 0.0, NULL, NULL)};
    CHECK(vec_dist_inf(F, want, 5) == 0.0, "%s: default rows (3 eq, 2 FB) at first use",
          fesd_ncp_backend_name(backends[b]));
    fesd_ncp_free(&ws);
  }
}

int main(void) {
  check_order();
  check_deferred_default();
  check_solves();
  return test_summary("test_ncp_rows");
}
