/* Classic NCP test problems from the literature, NCP(F): 0 <= z _|_ F(z) >= 0,
 * written as pairs a_k = z_k, b_k = F_k(z) (n_eq = 0), solved with the dense
 * backend from several starting points. Each problem's known solution is first
 * checked against the definition (to 1e-12), then the solver must reach
 * ||F||_inf <= 1e-12 and the solution to 1e-8.
 *
 * Sources:
 *  - Kojima & Shindo (1986), J. Oper. Res. Soc. Japan 29: 4 variables, two solutions,
 *    (1,0,3,0) (non-degenerate) and (sqrt(6)/2,0,0,1/2) (degenerate: z3 = F3 = 0).
 *  - Josephy (1979), as in MCPLIB "josephy": solution (sqrt(6)/2,0,0,1/2).
 *  - Modified Mathiesen (De Luca, Facchinei, Kanzow 1996, Math. Prog. 75):
 *    solution set {(l,0,0,0): 0 <= l <= 3}.
 *  - Hock-Schittkowski 35 as its KKT system (an LCP): x* = (4/3, 7/9, 4/9), u* = 2/9.
 *  - Murty's LCP (Murty 1978), M upper triangular with 1 on the diagonal and 2
 *    above, q = -e: unique solution z* = e_n (exponential for pivoting methods).
 *  - Nash-Cournot oligopoly with 10 firms (Murphy, Sherali, Soyster 1982; Harker
 *    1988; data of MCPLIB "nash"): no closed form; checked by the residual and by
 *    reaching the same equilibrium from all four MCPLIB starting points.
 *  - Billups (1995) one-dimensional NCP F(z) = (z-1)^2 - 1.01: from z0 = 0 plain
 *    FB-Newton stalls at a local minimizer of the merit function; the smoothing
 *    homotopy reaches z* = 1 + sqrt(1.01). */
#include "ncp_test_util.h"

typedef struct {
  const char *name;
  int n;
  void (*F)(const double *z, double *f, double *J); /* J row-major n x n, may be NULL */
} ncp_def;

typedef struct {
  const ncp_def *def;
  int calls;
} ncp_user;

static int ncp_eval(const double *z, double *raw, double *jac, void *user) {
  ncp_user *u = (ncp_user *)user;
  int n = u->def->n;
  u->calls++;
  for (int k = 0; k < n; k++) raw[k] = z[k];
  if (jac) {
    for (int k = 0; k < n; k++) jac[k] = 1.0;
    u->def->F(z, raw + n, jac + n); /* dense pattern of the b rows, row-major */
  } else {
    u->def->F(z, raw + n, NULL);
  }
  return 0;
}

/* --- problem definitions ------------------------------------------------- */

static void kojima_shindo(const double *x, double *f, double *J) {
  f[0] = 3 * x[0] * x[0] + 2 * x[0] * x[1] + 2 * x[1] * x[1] + x[2] + 3 * x[3] - 6;
  f[1] = 2 * x[0] * x[0] + x[0] + x[1] * x[1] + 10 * x[2] + 2 * x[3] - 2;
  f[2] = 3 * x[0] * x[0] + x[0] * x[1] + 2 * x[1] * x[1] + 2 * x[2] + 9 * x[3] - 9;
  f[3] = x[0] * x[0] + 3 * x[1] * x[1] + 2 * x[2] + 3 * x[3] - 3;
  if (!J) return;
  double j[16] = {6 * x[0] + 2 * x[1], 2 * x[0] + 4 * x[1], 1, 3,
                  4 * x[0] + 1,        2 * x[1],            10, 2,
                  6 * x[0] + x[1],     x[0] + 4 * x[1],     2, 9,
                  2 * x[0],            6 * x[1],            2, 3};
  memcpy(J, j, sizeof j);
}

static void josephy(const double *x, double *f, double *J) {
  f[0] = 3 * x[0] * x[0] + 2 * x[0] * x[1] + 2 * x[1] * x[1] + x[2] + 3 * x[3] - 6;
  f[1] = 2 * x[0] * x[0] + x[0] + x[1] * x[1] + 3 * x[2] + 2 * x[3] - 2;
  f[2] = 3 * x[0] * x[0] + x[0] * x[1] + 2 * x[1] * x[1] + 2 * x[2] + 3 * x[3] - 1;
  f[3] = x[0] * x[0] + 3 * x[1] * x[1] + 2 * x[2] + 3 * x[3] - 3;
  if (!J) return;
  double j[16] = {6 * x[0] + 2 * x[1], 2 * x[0] + 4 * x[1], 1, 3,
                  4 * x[0] + 1,        2 * x[1],            3, 2,
                  6 * x[0] + x[1],     x[0] + 4 * x[1],     2, 3,
                  2 * x[0],            6 * x[1],            2, 3};
  memcpy(J, j, sizeof j);
}

static void mathiesen(const double *x, double *f, double *J) {
  double d2 = x[1] + 1, d3 = x[2] + 1;
  double s2 = 4.5 * x[2] + 2.7 * x[3], s3 = 0.5 * x[2] + 0.3 * x[3];
  f[0] = -x[1] + x[2] + x[3];
  f[1] = x[0] - s2 / d2;
  f[2] = 5 - x[0] - s3 / d3;
  f[3] = 3 - x[0];
  if (!J) return;
  double j[16] = {0,  -1,           1,                         1,
                  1,  s2 / (d2 * d2), -4.5 / d2,                 -2.7 / d2,
                  -1, 0,            -0.5 / d3 + s3 / (d3 * d3), -0.3 / d3,
                  -1, 0,            0,                         0};
  memcpy(J, j, sizeof j);
}

/* HS35: min 9 - 8x1 - 6x2 - 4x3 + 2x1^2 + 2x2^2 + x3^2 + 2x1x2 + 2x1x3
 *       s.t. 3 - x1 - x2 - 2x3 >= 0, x >= 0. KKT in z = (x, u). */
static void hs35(const double *z, double *f, double *J) {
  f[0] = -8 + 4 * z[0] + 2 * z[1] + 2 * z[2] + z[3];
  f[1] = -6 + 2 * z[0] + 4 * z[1] + z[3];
  f[2] = -4 + 2 * z[0] + 2 * z[2] + 2 * z[3];
  f[3] = 3 - z[0] - z[1] - 2 * z[2];
  if (!J) return;
  double j[16] = {4, 2, 2, 1, 2, 4, 0, 1, 2, 0, 2, 2, -1, -1, -2, 0};
  memcpy(J, j, sizeof j);
}

#define MURTY_N 16
static void murty(const double *z, double *f, double *J) {
  for (int i = 0; i < MURTY_N; i++) {
    f[i] = -1 + z[i];
    for (int j = i + 1; j < MURTY_N; j++) f[i] += 2 * z[j];
    if (J)
      for (int j = 0; j < MURTY_N; j++) J[i * MURTY_N + j] = j < i ? 0.0 : (j == i ? 1.0 : 2.0);
  }
}

static const double nash_c[10] = {5, 3, 8, 5, 1, 3, 7, 4, 6, 3};
static const double nash_beta[10] = {1.2, 1, .9, .6, 1.5, 1, .7, 1.1, .95, .75};
/* F_i = c_i + (L q_i)^(1/b_i) - p(Q) - q_i p'(Q), p(Q) = (5000/Q)^(1/gamma), L = 10, gamma = 1.2 */
static void nash(const double *q, double *f, double *J) {
  const double gam = 1.2, L = 10.0;
  double Q = 0.0;
  for (int i = 0; i < 10; i++) Q += q[i];
  double p = pow(5000.0 / Q, 1.0 / gam), dp = -p / (gam * Q), d2p = p * (1.0 + gam) / (gam * gam * Q * Q);
  for (int i = 0; i < 10; i++) {
    double qi = fmax(q[i], 0.0); /* (L q)^(1/b) is real only for q >= 0 */
    double mc = pow(L * qi, 1.0 / nash_beta[i]);
    f[i] = nash_c[i] + mc - p - q[i] * dp;
    if (!J) continue;
    double dmc = qi > 0.0 ? mc / (nash_beta[i] * qi) : 0.0;
    for (int j = 0; j < 10; j++) J[i * 10 + j] = -dp - q[i] * d2p + (i == j ? dmc - dp : 0.0);
  }
}

static void billups(const double *z, double *f, double *J) {
  f[0] = (z[0] - 1) * (z[0] - 1) - 1.01;
  if (J) J[0] = 2 * (z[0] - 1);
}

/* --- driver -------------------------------------------------------------- */

static double ncp_natural(const ncp_def *def, const double *z) {
  double f[16], r = 0.0;
  def->F(z, f, NULL);
  for (int i = 0; i < def->n; i++) r = fmax(r, fabs(fmin(z[i], f[i])));
  return r;
}

static fesd_ncp *make_ws(const ncp_def *def, ncp_user *u, int backend) {
  int n = def->n, nnz = n + n * n;
  int *row = malloc((size_t)nnz * sizeof(int)), *col = malloc((size_t)nnz * sizeof(int));
  for (int k = 0; k < n; k++) row[k] = col[k] = k;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      row[n + i * n + j] = n + i;
      col[n + i * n + j] = j;
    }
  u->def = def;
  u->calls = 0;
  fesd_ncp_problem p = {n, 0, n, nnz, row, col, ncp_eval, u};
  fesd_ncp *ws = NULL;
  CHECK_RC(setup_backend(&ws, &p, backend), FESD_OK);
  free(row);
  free(col);
  return ws;
}

enum { HOMOTOPY = 1, BOX = 2 }; /* run() flags; BOX: z >= 0 via fesd_ncp_set_bounds */

/* Solve from z0; want is the expected solution (NULL: only the residual is
 * checked). Returns the iterations. */
static int run(const ncp_def *def, const double *z0, const double *want, int flags,
               double *zout) {
  ncp_user u;
  fesd_ncp *ws = make_ws(def, &u, FESD_NCP_BACKEND_DENSE);
  if (!ws) return -1;
  double z[16], lb[16] = {0};
  if (flags & BOX) CHECK_RC(fesd_ncp_set_bounds(ws, lb, NULL), FESD_OK);
  memcpy(z, z0, (size_t)def->n * sizeof(double));
  fesd_ncp_info info;
  int rc = (flags & HOMOTOPY) ? fesd_ncp_solve_homotopy(ws, z, &info)
                              : fesd_ncp_solve(ws, z, 0.0, &info);
  double err = want ? vec_dist_inf(z, want, def->n) : 0.0;
  printf("  %-14s z0[0]=%-5g %-8s%s: %s it=%d stages=%d fact=%d evals=%d bt=%d |F|=%.1e err=%.1e\n",
         def->name, z0[0], (flags & HOMOTOPY) ? "homotopy" : "newton", (flags & BOX) ? "+box" : "",
         fesd_status_name(rc), info.iterations, info.homotopy_stages, info.factorizations,
         info.evals, info.backtracks, info.residual, err);
  CHECK(rc == FESD_OK, "%s did not converge", def->name);
  CHECK(info.residual <= 1e-12, "%s residual %.2e", def->name, info.residual);
  CHECK(ncp_natural(def, z) <= 1e-11, "%s natural residual %.2e", def->name, ncp_natural(def, z));
  if (want) CHECK(err <= 1e-8, "%s solution error %.2e", def->name, err);
  if (zout) memcpy(zout, z, (size_t)def->n * sizeof(double));
  fesd_ncp_free(&ws);
  return info.iterations;
}

/* A start from which plain Newton must fail honestly (no false convergence). */
static void run_expect_failure(const ncp_def *def, const double *z0) {
  ncp_user u;
  fesd_ncp *ws = make_ws(def, &u, FESD_NCP_BACKEND_DENSE);
  double z[16];
  memcpy(z, z0, (size_t)def->n * sizeof(double));
  fesd_ncp_info info;
  int rc = fesd_ncp_solve(ws, z, 0.0, &info);
  printf("  %-14s z0[0]=%-5g newton  : %s it=%d |F|=%.2e (expected failure: merit valley / "
         "local minimizer of 1/2|F|^2)\n",
         def->name, z0[0], fesd_status_name(rc), info.iterations, info.residual);
  CHECK(rc != FESD_OK && info.residual > 1e-3, "%s: expected an honest failure", def->name);
  fesd_ncp_free(&ws);
}

static void check_definition(const ncp_def *def, const double *zs) {
  double r = ncp_natural(def, zs);
  printf("  %-14s known solution satisfies NCP: natural residual %.1e\n", def->name, r);
  CHECK(r <= 1e-12, "%s: known solution violates the definition (%.2e)", def->name, r);
}

int main(void) {
  const double s6 = sqrt(6.0) / 2.0;
  const ncp_def ks = {"kojima-shindo", 4, kojima_shindo}, jo = {"josephy", 4, josephy},
                ma = {"mathiesen", 4, mathiesen}, hs = {"hs35-kkt", 4, hs35},
                mu = {"murty16", MURTY_N, murty}, na = {"nash10", 10, nash},
                bi = {"billups", 1, billups};

  printf("Kojima-Shindo\n");
  const double ks_nd[4] = {1, 0, 3, 0}, ks_dg[4] = {s6, 0, 0, 0.5};
  check_definition(&ks, ks_nd);
  check_definition(&ks, ks_dg);
  {
    /* which solution is reached depends on the start */
    const double z1[4] = {1, 1, 1, 1}, z2[4] = {0, 0, 0, 0}, z3[4] = {10, 10, 10, 10},
                 z4[4] = {1, 0, 0, 1}, z5[4] = {0.5, 0.5, 0.5, 0.5}, z6[4] = {100, 100, 100, 100};
    const double *starts[] = {z1, z2, z3, z4, z5, z6};
    int hit_nd = 0, hit_dg = 0;
    for (int s = 0; s < 6; s++) {
      double z[4];
      run(&ks, starts[s], NULL, 0, z);
      hit_nd += vec_dist_inf(z, ks_nd, 4) <= 1e-8;
      hit_dg += vec_dist_inf(z, ks_dg, 4) <= 1e-8;
      CHECK(vec_dist_inf(z, ks_nd, 4) <= 1e-8 || vec_dist_inf(z, ks_dg, 4) <= 1e-8,
            "kojima-shindo: not one of the two known solutions");
    }
    printf("  reached non-degenerate %d times, degenerate %d times\n", hit_nd, hit_dg);
    CHECK(hit_nd > 0 && hit_dg > 0, "both Kojima-Shindo solutions must be reached");
    /* starting points near each solution converge to it */
    const double n1[4] = {1.1, 0.1, 2.9, 0.1}, n2[4] = {1.2, 0.1, 0.1, 0.6};
    run(&ks, n1, ks_nd, 0, NULL);
    run(&ks, n2, ks_dg, 0, NULL);
    /* from (1,0,1,0) plain Newton creeps along a valley of the merit function into
     * z3 < 0; the homotopy or the box z >= 0 reach the degenerate solution */
    const double bad[4] = {1, 0, 1, 0};
    run_expect_failure(&ks, bad);
    run(&ks, bad, ks_dg, HOMOTOPY, NULL);
    run(&ks, bad, ks_dg, BOX, NULL);
  }

  printf("Josephy\n");
  const double jo_s[4] = {s6, 0, 0, 0.5};
  check_definition(&jo, jo_s);
  {
    const double z1[4] = {0, 0, 0, 0}, z2[4] = {1, 1, 1, 1}, z3[4] = {2, 2, 2, 2},
                 z4[4] = {1, 0, 1, 0}, z5[4] = {5, 0, 0, 5};
    const double *starts[] = {z1, z2, z3, z4, z5};
    for (int s = 0; s < 5; s++) run(&jo, starts[s], jo_s, 0, NULL);
    /* from (10,10,10,10) plain Newton (and the homotopy) end at a nonzero local
     * minimizer of 1/2|F|^2 with z3, z4 < 0; the box z >= 0 plus the homotopy solve it */
    const double far[4] = {10, 10, 10, 10}, farther[4] = {100, 100, 100, 100};
    run_expect_failure(&jo, far);
    run(&jo, far, jo_s, HOMOTOPY | BOX, NULL);
    run(&jo, farther, jo_s, HOMOTOPY | BOX, NULL);
  }

  printf("Modified Mathiesen (solution set (l,0,0,0), 0 <= l <= 3)\n");
  {
    const double zs[4] = {2, 0, 0, 0};
    check_definition(&ma, zs);
    const double z1[4] = {1, 1, 1, 1}, z2[4] = {0, 0, 0, 0}, z3[4] = {2, 0.5, 0.5, 0.5},
                 z4[4] = {5, 5, 5, 5};
    const double *starts[] = {z1, z2, z3, z4};
    for (int s = 0; s < 4; s++) {
      double z[4];
      run(&ma, starts[s], NULL, 0, z);
      CHECK(fabs(z[1]) + fabs(z[2]) + fabs(z[3]) <= 1e-8 && z[0] >= -1e-12 &&
                z[0] <= 3 + 1e-12,
            "mathiesen: (%g,%g,%g,%g) not in the solution set", z[0], z[1], z[2], z[3]);
    }
  }

  printf("Hock-Schittkowski 35 (KKT)\n");
  {
    const double zs[4] = {4.0 / 3, 7.0 / 9, 4.0 / 9, 2.0 / 9};
    check_definition(&hs, zs);
    const double z1[4] = {0.5, 0.5, 0.5, 0}, z2[4] = {0, 0, 0, 0}, z3[4] = {3, 3, 3, 3};
    const double *starts[] = {z1, z2, z3};
    for (int s = 0; s < 3; s++) run(&hs, starts[s], zs, 0, NULL);
  }

  printf("Murty's LCP (n = 16)\n");
  {
    double zs[MURTY_N] = {0}, z1[MURTY_N] = {0}, z2[MURTY_N], z3[MURTY_N];
    zs[MURTY_N - 1] = 1.0;
    check_definition(&mu, zs);
    for (int i = 0; i < MURTY_N; i++) {
      z2[i] = 1.0;
      z3[i] = 0.1 * i;
    }
    run(&mu, z1, zs, 0, NULL);
    run(&mu, z2, zs, 0, NULL);
    run(&mu, z3, zs, 0, NULL);
  }

  printf("Nash-Cournot, 10 firms (MCPLIB nash starting points)\n");
  {
    double ref[10];
    const double z1[10] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1},
                 z2[10] = {10, 10, 10, 10, 10, 10, 10, 10, 10, 10},
                 z3[10] = {1.0, 1.2, 1.4, 1.6, 1.8, 2.1, 2.3, 2.5, 2.7, 2.9},
                 z4[10] = {7, 4, 3, 1, 18, 4, 1, 6, 3, 2};
    /* the game is strictly monotone: every start must give the same equilibrium */
    run(&na, z1, NULL, 0, ref);
    printf("  equilibrium:");
    for (int i = 0; i < 10; i++) printf(" %.4f", ref[i]);
    printf("\n");
    run(&na, z2, ref, 0, NULL);
    run(&na, z3, ref, 0, NULL);
    run(&na, z4, ref, 0, NULL);
  }

  printf("Billups (plain Newton stalls from 0; the homotopy solves it)\n");
  {
    const double zs[1] = {1.0 + sqrt(1.01)};
    check_definition(&bi, zs);
    const double z0[1] = {0.0}, z1[1] = {3.0};
    run(&bi, z1, zs, 0, NULL);
    ncp_user u;
    fesd_ncp *ws = make_ws(&bi, &u, FESD_NCP_BACKEND_DENSE);
    double z[1] = {0.0};
    fesd_ncp_info info;
    int rc = fesd_ncp_solve(ws, z, 0.0, &info);
    printf("  plain Newton from 0: %s after %d iterations, z = %.4f, |F| = %.2e\n",
           fesd_status_name(rc), info.iterations, z[0], info.residual);
    CHECK(rc != FESD_OK, "billups from 0 was expected to stall without the homotopy");
    /* the progress check (settings.slow_iter): the same stall ends after 3 iterations, with
     * the residual history showing why; from 3 Newton converges and the check stays silent */
    const double F1 = info.residual_history[1], F3 = info.residual_history[3];
    fesd_ncp_settings s;
    fesd_ncp_settings_default(&s);
    s.backend = FESD_NCP_BACKEND_DENSE;
    s.slow_iter = 3;
    s.slow_ratio = 0.5;
    CHECK(fesd_ncp_update_settings(ws, &s) == FESD_OK, "update settings");
    z[0] = 0.0;
    rc = fesd_ncp_solve(ws, z, 0.0, &info);
    printf("  with slow_iter = 3: %s after %d iterations (|F| after 1: %.3e, after 3: %.3e)\n",
           fesd_status_name(rc), info.iterations, F1, info.residual);
    CHECK(F3 > 0.5 * F1, "billups from 0: |F| after 3 iterations %.3e vs %.3e: no stall to detect", F3, F1);
    CHECK(rc == FESD_ERR_LINE_SEARCH && info.iterations == 3 && info.residual == F3,
          "slow_iter = 3: %s after %d iterations, |F| %.3e (expected LINE_SEARCH after 3, |F| %.3e)",
          fesd_status_name(rc), info.iterations, info.residual, F3);
    z[0] = 3.0;
    rc = fesd_ncp_solve(ws, z, 0.0, &info);
    CHECK(rc == FESD_OK && fabs(z[0] - zs[0]) <= 1e-10, "slow_iter = 3 from 3: %s, z = %.12f",
          fesd_status_name(rc), z[0]);
    fesd_ncp_free(&ws);
    run(&bi, z0, zs, HOMOTOPY, NULL);
  }

  return test_summary("test_ncp_classic");
}
