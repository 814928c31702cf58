/* Error paths and statistics: every invalid input or setting returns its code,
 * callback failures and NaN/Inf are reported (NaN at a trial point only rejects
 * the trial), the workspace still solves a good problem afterwards, and the
 * counters in fesd_ncp_info follow their definitions. */
#include "ncp_test_util.h"

static void settings_errors(const fesd_ncp_problem *p) {
  printf("Settings validation\n");
  CHECK_RC(fesd_ncp_settings_default(NULL), FESD_ERR_NULL);
  fesd_ncp_settings d;
  CHECK_RC(fesd_ncp_settings_default(&d), FESD_OK);
  CHECK(d.tol == 1e-12 && d.max_iter == 50 && d.backend == FESD_NCP_BACKEND_AUTO &&
            d.dense_max_n == FESD_NCP_DENSE_MAX_N && d.armijo == 1e-4 && d.backtrack == 0.5 &&
            d.max_backtracks == 30 && d.sigma0 == 1e-1 && d.sigma_factor == 0.1 &&
            d.sigma_min == 1e-8 && d.homotopy_tol_factor == 1e-2 && d.lm_mu0 == 1e-3 && d.slow_iter == 0 && d.slow_ratio == 0.5 && !d.log,
        "documented defaults");
  static const char *const bad[] = {
      "tol = 0",        "tol = -1",         "tol = NaN",          "tol = Inf",
      "max_iter = 0",   "backend = 5",      "backend = -1",       "dense_max_n = -1",
      "armijo = 0",     "armijo = 0.5",     "backtrack = 0",      "backtrack = 1",
      "max_backtracks = 0", "sigma0 = 0",   "sigma_factor = 1",   "sigma_factor = 0",
      "sigma_min = 0",  "sigma_min > sigma0", "homotopy_tol_factor = 0", "lm_mu0 = 0",
      "lm_mu0 = -1",    "tol = 1",          "tol = 1e-17",        "max_iter = 1001",
      "dense_max_n = 5001", "armijo = NaN", "backtrack = NaN",    "max_backtracks = 101",
      "sigma0 = 1e4",   "sigma0 = NaN",     "sigma_factor = 0.95", "sigma_factor = NaN",
      "sigma_min = 1e-17", "sigma_min = NaN", "homotopy_tol_factor = 2", "homotopy_tol_factor = NaN",
      "lm_mu0 = 1e11",  "lm_mu0 = 1e-11",   "slow_iter = 1",      "slow_iter = 1001",
      "slow_ratio = 0", "slow_ratio = 1.5", "slow_ratio = NaN",   "lm_mu0 = NaN"};
  const size_t nbad = sizeof bad / sizeof bad[0];
  for (size_t k = 0; k < nbad; k++) {
    fesd_ncp_settings s = d;
    switch (k) { /* one broken field per case, in the order of the table */
    case 0: s.tol = 0; break;
    case 1: s.tol = -1; break;
    case 2: s.tol = NAN; break;
    case 3: s.tol = INFINITY; break;
    case 4: s.max_iter = 0; break;
    case 5: s.backend = (fesd_ncp_backend)5; break;
    case 6: s.backend = (fesd_ncp_backend)-1; break;
    case 7: s.dense_max_n = -1; break;
    case 8: s.armijo = 0; break;
    case 9: s.armijo = 0.5; break;
    case 10: s.backtrack = 0; break;
    case 11: s.backtrack = 1; break;
    case 12: s.max_backtracks = 0; break;
    case 13: s.sigma0 = 0; break;
    case 14: s.sigma_factor = 1; break;
    case 15: s.sigma_factor = 0; break;
    case 16: s.sigma_min = 0; break;
    case 17: s.sigma_min = 1; break;
    case 18: s.homotopy_tol_factor = 0; break;
    case 19: s.lm_mu0 = 0; break;
    case 20: s.lm_mu0 = -1; break;
    case 21: s.tol = 1; break;
    case 22: s.tol = 1e-17; break;
    case 23: s.max_iter = 1001; break;
    case 24: s.dense_max_n = 5001; break;
    case 25: s.armijo = NAN; break;
    case 26: s.backtrack = NAN; break;
    case 27: s.max_backtracks = 101; break;
    case 28: s.sigma0 = 1e4; break;
    case 29: s.sigma0 = NAN; break;
    case 30: s.sigma_factor = 0.95; break;
    case 31: s.sigma_factor = NAN; break;
    case 32: s.sigma_min = 1e-17; break;
    case 33: s.sigma_min = NAN; break;
    case 34: s.homotopy_tol_factor = 2; break;
    case 35: s.homotopy_tol_factor = NAN; break;
    case 36: s.lm_mu0 = 1e11; break;
    case 37: s.lm_mu0 = 1e-11; break;
    case 38: s.slow_iter = 1; break;
    case 39: s.slow_iter = 1001; break;
    case 40: s.slow_ratio = 0; break;
    case 41: s.slow_ratio = 1.5; break;
    case 42: s.slow_ratio = NAN; break;
    default: s.lm_mu0 = NAN; break;
    }
    fesd_ncp *ws = (fesd_ncp *)&s; /* must be reset to NULL on error */
    int rc = fesd_ncp_setup(&ws, p, &s);
    CHECK(rc == FESD_ERR_INVALID_ARG && ws == NULL, "setup with %s: %s", bad[k],
          fesd_status_name(rc));
    fesd_ncp *ok = NULL;
    CHECK_RC(fesd_ncp_setup(&ok, p, NULL), FESD_OK);
    CHECK(fesd_ncp_update_settings(ok, &s) == FESD_ERR_INVALID_ARG, "update with %s", bad[k]);
    fesd_ncp_free(&ok);
  }
  /* the ends of the ranges are accepted */
  for (int end = 0; end < 2; end++) {
    fesd_ncp_settings s = d;
    s.tol = end ? 1e-1 : 1e-16;
    s.max_iter = end ? 1000 : 1;
    s.dense_max_n = end ? 5000 : 0;
    s.max_backtracks = end ? 100 : 1;
    s.sigma0 = end ? 1e3 : 1e-16;
    s.sigma_factor = end ? 0.9 : 1e-300;
    s.sigma_min = end ? 1e3 : 1e-16;
    s.homotopy_tol_factor = end ? 1 : 1e-300;
    s.lm_mu0 = end ? 1e10 : 1e-10;
    fesd_ncp *ws = NULL;
    CHECK(fesd_ncp_setup(&ws, p, &s) == FESD_OK && ws, "settings at the %s ends of their ranges",
          end ? "upper" : "lower");
    fesd_ncp_free(&ws);
  }
  printf("  %zu invalid settings rejected by setup and update_settings; range ends accepted\n", nbad);
}

static int dummy_eval(const double *z, double *raw, double *jac, void *user) {
  (void)z, (void)raw, (void)jac, (void)user;
  return 0;
}

static void setup_errors(void) {
  printf("Problem validation\n");
  const int row[3] = {0, 1, 2}, col[3] = {0, 1, 0};
  fesd_ncp_problem good = {2, 0, 2, 3, row, col, dummy_eval, NULL};
  fesd_ncp *ws = NULL;
  CHECK_RC(fesd_ncp_setup(NULL, &good, NULL), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_setup(&ws, NULL, NULL), FESD_ERR_NULL);
  fesd_ncp_problem p = good;
  p.eval = NULL;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_NULL);
  p = good;
  p.row = NULL;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_NULL);
  p = good;
  p.col = NULL;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_NULL);
  p = good;
  p.n = 0;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_DIMENSION);
  p = good;
  p.n_eq = -1;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_DIMENSION);
  p = good;
  p.n_pair = -1;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_DIMENSION);
  p = good;
  p.nnz = -1;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_DIMENSION);
  p = good;
  p.n = 3; /* m = 2 < n = 3 */
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_DIMENSION);
  const int row_bad[3] = {0, 4, 2}, row_neg[3] = {0, -1, 2}, col_bad[3] = {0, 2, 0},
            col_neg[3] = {0, -1, 0};
  p = good;
  p.row = row_bad;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_PATTERN);
  p.row = row_neg;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_PATTERN);
  p = good;
  p.col = col_bad;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_PATTERN);
  p.col = col_neg;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_ERR_PATTERN);
  CHECK(ws == NULL, "ws stays NULL after failed setups");
  /* nnz = 0 with NULL pattern arrays is valid (a constant system) */
  p = good;
  p.nnz = 0;
  p.row = p.col = NULL;
  CHECK_RC(fesd_ncp_setup(&ws, &p, NULL), FESD_OK);
  fesd_ncp_free(&ws);
  fesd_ncp_free(&ws); /* already NULL */
  fesd_ncp_free(NULL);

  CHECK_RC(fesd_ncp_setup(&ws, &good, NULL), FESD_OK);
  settings_errors(&good);
  printf("Argument checks of the other entry points\n");
  double z[2] = {0, 0}, lb[2] = {1, 0}, ub[2] = {0, 1}, nanv[2] = {NAN, 0}, dz[2], draw[4] = {0};
  fesd_ncp_info info;
  CHECK_RC(fesd_ncp_update_settings(NULL, NULL), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_update_settings(ws, NULL), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_set_bounds(NULL, NULL, NULL), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_set_bounds(ws, lb, ub), FESD_ERR_INVALID_ARG);
  CHECK_RC(fesd_ncp_set_bounds(ws, nanv, NULL), FESD_ERR_INVALID_ARG);
  CHECK_RC(fesd_ncp_set_bounds(ws, NULL, NULL), FESD_OK);
  CHECK_RC(fesd_ncp_solve(NULL, z, 0.0, &info), FESD_ERR_NULL);
  CHECK(info.status == FESD_ERR_NULL, "info.status filled on argument errors");
  CHECK_RC(fesd_ncp_solve(ws, NULL, 0.0, &info), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_solve(ws, z, -1.0, &info), FESD_ERR_INVALID_ARG);
  CHECK_RC(fesd_ncp_solve(ws, z, NAN, NULL), FESD_ERR_INVALID_ARG);
  CHECK_RC(fesd_ncp_solve_homotopy(NULL, z, NULL), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_solve_homotopy(ws, NULL, &info), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_residual(NULL, z, 0.0, NULL, NULL), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_residual(ws, NULL, 0.0, NULL, NULL), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_residual(ws, z, -1.0, NULL, NULL), FESD_ERR_INVALID_ARG);
  CHECK_RC(fesd_ncp_sensitivity(NULL, z, 0.0, 1, draw, dz), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_sensitivity(ws, z, 0.0, -1, draw, dz), FESD_ERR_INVALID_ARG);
  CHECK_RC(fesd_ncp_sensitivity(ws, z, -1.0, 1, draw, dz), FESD_ERR_INVALID_ARG);
  CHECK_RC(fesd_ncp_sensitivity(ws, z, 0.0, 1, NULL, dz), FESD_ERR_NULL);
  CHECK_RC(fesd_ncp_sensitivity(ws, z, 0.0, 0, NULL, NULL), FESD_OK);
  CHECK(fesd_ncp_rows(NULL) == FESD_ERR_NULL, "rows(NULL)");
  CHECK(!strcmp(fesd_ncp_backend_name(FESD_NCP_BACKEND_KLU), "klu") &&
            !strcmp(fesd_ncp_backend_name(FESD_NCP_BACKEND_AUTO), "auto") &&
            !strcmp(fesd_ncp_backend_name(99), "unknown"),
        "backend names");
  fesd_ncp_free(&ws);
  CHECK(ws == NULL, "free sets NULL");
}

static int log_lines = 0;
static void count_log(void *user, const char *msg) {
  (void)user;
  if (strncmp(msg, "ncp it", 6) == 0) log_lines++;
}

/* The k-th callback call from now fails (returns nonzero) / returns NaN and all later ones. */
static void fail_at_call(lcp_t *l, int k) {
  l->calls = 1;
  l->fail_after = k;
}
static void nan_at_call(lcp_t *l, int k) {
  l->calls = 1;
  l->nan_after = k;
}

/* NaN (or Inf in the Jacobian) at the first two trial points of the first iteration: they
 * must only shorten the step. Call 1 is the residual at the start, call 2 its Jacobian (the
 * solver asks for it only when the start is not converged), calls 3 and 4 the trials. */
typedef struct {
  lcp_t *lcp;
  int calls, nan_trials;
} nanzone_t;
static int nanzone_eval(const double *z, double *raw, double *jac, void *user) {
  nanzone_t *u = (nanzone_t *)user;
  int rc = lcp_eval(z, raw, jac, u->lcp);
  u->calls++;
  if (u->calls == 3 || u->calls == 4) {
    if (jac) {
      jac[0] = INFINITY;
    } else {
      raw[0] = NAN;
    }
    u->nan_trials++;
  }
  return rc;
}

static void runtime_errors(void) {
  printf("Callback failures, NaN/Inf, recovery, statistics\n");
  const int n = 30;
  lcp_t lcp;
  double zs[30], z[30];
  random_lcp(&lcp, n, 1, 555, 0, zs);
  fesd_ncp_problem p = lcp_problem(&lcp);
  const int backends[3] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_KLU,
                           FESD_NCP_BACKEND_UMFPACK};
  for (int b = 0; b < 3; b++) {
    fesd_ncp_settings s;
    fesd_ncp_settings_default(&s);
    s.backend = backends[b];
    s.log = count_log;
    fesd_ncp *ws = NULL;
    CHECK_RC(fesd_ncp_setup(&ws, &p, &s), FESD_OK);
    fesd_ncp_info info;

    /* callback error at the initial point, later in the iteration, in the homotopy */
    for (int i = 0; i < n; i++) z[i] = 1.0;
    fail_at_call(&lcp, 1);
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_ERR_CALLBACK);
    CHECK(info.status == FESD_ERR_CALLBACK && info.evals == 1 && info.factorizations == 0,
          "callback error at the initial point: evals %d fact %d", info.evals,
          info.factorizations);
    fail_at_call(&lcp, 4);
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_ERR_CALLBACK);
    CHECK(info.evals == 4, "error in the 4th call reported after 4 evals (%d)", info.evals);
    fail_at_call(&lcp, 3);
    CHECK_RC(fesd_ncp_solve_homotopy(ws, z, &info), FESD_ERR_CALLBACK);
    lcp.fail_after = 0;

    /* NaN / Inf at the current point */
    nan_at_call(&lcp, 1);
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_ERR_NONFINITE);
    nan_at_call(&lcp, 1);
    CHECK_RC(fesd_ncp_solve_homotopy(ws, z, &info), FESD_ERR_NONFINITE);
    lcp.nan_after = 0;
    for (int i = 0; i < n; i++) z[i] = INFINITY;
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_ERR_NONFINITE);
    CHECK_RC(fesd_ncp_residual(ws, z, 0.0, NULL, NULL), FESD_ERR_NONFINITE);

    /* the workspace still solves the good problem */
    log_lines = 0;
    for (int i = 0; i < n; i++) z[i] = 1.0;
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_OK);
    CHECK(vec_dist_inf(z, zs, n) <= 1e-8, "recovered solve");
    CHECK(log_lines >= info.iterations && info.iterations > 0, "log lines %d for %d iterations",
          log_lines, info.iterations);
    CHECK(info.evals >= info.iterations + 1 && info.jac_evals <= info.evals &&
              info.jac_evals >= 1 && info.factorizations >= info.iterations &&
              info.homotopy_stages == 1 && info.history_len == info.iterations + 1 &&
              info.residual_history[info.history_len - 1] == info.residual &&
              info.time_total >= info.time_eval + info.time_linsolve && info.time_eval >= 0.0,
          "statistics consistency");
    printf("  %-8s recovered: it=%d evals=%d jac_evals=%d fact=%d bt=%d log lines=%d\n",
           fesd_ncp_backend_name(backends[b]), info.iterations, info.evals, info.jac_evals,
           info.factorizations, info.backtracks, log_lines);

    /* converged initial guess: one evaluation, no factorization */
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_OK);
    CHECK(info.evals == 1 && info.factorizations == 0 && info.iterations == 0 &&
              info.history_len == 1,
          "converged start: evals %d fact %d it %d", info.evals, info.factorizations,
          info.iterations);

    /* max_iter */
    s.max_iter = 1;
    s.log = NULL;
    CHECK_RC(fesd_ncp_update_settings(ws, &s), FESD_OK);
    for (int i = 0; i < n; i++) z[i] = 1.0;
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_ERR_MAX_ITER);
    CHECK(info.iterations == 1 && info.residual > 1e-12, "max_iter = 1");
    s.max_iter = 50;
    CHECK_RC(fesd_ncp_update_settings(ws, &s), FESD_OK);

    /* NaN at trial points only rejects those trials */
    nanzone_t nz = {&lcp, 0, 0};
    fesd_ncp_problem pn = p;
    pn.eval = nanzone_eval;
    pn.user = &nz;
    fesd_ncp *ws2 = NULL;
    CHECK_RC(fesd_ncp_setup(&ws2, &pn, &s), FESD_OK);
    for (int i = 0; i < n; i++) z[i] = 1.0;
    int rc = fesd_ncp_solve(ws2, z, 0.0, &info);
    printf("  %-8s Inf/NaN at 2 trial points: %s, it=%d bt=%d\n",
           fesd_ncp_backend_name(backends[b]), fesd_status_name(rc), info.iterations,
           info.backtracks);
    CHECK(nz.nan_trials == 2 && info.backtracks >= 2, "trials hit: %d", nz.nan_trials);
    CHECK(rc == FESD_OK && vec_dist_inf(z, zs, n) <= 1e-8, "NaN trial points must be rejected");
    fesd_ncp_free(&ws2);
    fesd_ncp_free(&ws);
  }
  lcp_free(&lcp);
}

int main(void) {
  setup_errors();
  runtime_errors();
  return test_summary("test_ncp_errors");
}
