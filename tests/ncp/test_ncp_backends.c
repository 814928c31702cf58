/* Backend conformance.
 * 1. The internal linear-solver vtable (src/ncp/linsolve.h), one generic test run
 *    against every object: LU objects (dense, UMFPACK, KLU) solve J x = b, normal
 *    objects (dense, CHOLMOD) solve (J'J + mu I) x = b, across re-factorizations
 *    with new values (KLU's refactor path), a singular matrix, and a new pattern.
 * 2. The public API: one nonlinear square problem solved by dense, UMFPACK and KLU
 *    gives the same solution to 1e-12; AUTO chooses as documented. */
#include "ncp/linsolve.h"
#include "ncp_test_util.h"

/* Random sparse m x n matrix with a nonzero diagonal (m >= n), as CSC of J and of
 * J', plus its dense copy. */
typedef struct {
  int m, n, nnz;
  int *p, *i, *pt, *it;
  double *x, *xt, *dense;
} spmat;

static void spmat_random(spmat *A, int m, int n, double density, rng_t *r) {
  A->m = m;
  A->n = n;
  A->dense = calloc((size_t)m * n, sizeof(double));
  for (int j = 0; j < n; j++)
    for (int i = 0; i < m; i++)
      if (i == j) A->dense[i + (size_t)j * m] = 4.0 + rng_uniform(r);
      else if (rng_uniform(r) < density) A->dense[i + (size_t)j * m] = rng_sym(r);
  int nz = 0;
  for (int k = 0; k < m * n; k++) nz += A->dense[k] != 0.0;
  A->nnz = nz;
  A->p = malloc((size_t)(n + 1) * sizeof(int));
  A->i = malloc((size_t)nz * sizeof(int));
  A->x = malloc((size_t)nz * sizeof(double));
  A->pt = malloc((size_t)(m + 1) * sizeof(int));
  A->it = malloc((size_t)nz * sizeof(int));
  A->xt = malloc((size_t)nz * sizeof(double));
  int k = 0;
  for (int j = 0; j < n; j++) {
    A->p[j] = k;
    for (int i = 0; i < m; i++)
      if (A->dense[i + (size_t)j * m] != 0.0) {
        A->i[k] = i;
        A->x[k++] = A->dense[i + (size_t)j * m];
      }
  }
  A->p[n] = k;
  k = 0;
  for (int i = 0; i < m; i++) {
    A->pt[i] = k;
    for (int j = 0; j < n; j++)
      if (A->dense[i + (size_t)j * m] != 0.0) {
        A->it[k] = j;
        A->xt[k++] = A->dense[i + (size_t)j * m];
      }
  }
  A->pt[m] = k;
}

static void spmat_free(spmat *A) {
  free(A->p);
  free(A->i);
  free(A->x);
  free(A->pt);
  free(A->it);
  free(A->xt);
  free(A->dense);
}

/* Values and pattern in the object's layout (the dense copy is consumed by dense LU). */
static double *layout_values(const fesd__ls *ls, const spmat *A, double *scratch) {
  switch (ls->ops->layout) {
  case FESD__LAYOUT_DENSE:
    memcpy(scratch, A->dense, (size_t)A->m * A->n * sizeof(double));
    return scratch;
  case FESD__LAYOUT_CSC: return A->x;
  default: return A->xt;
  }
}

/* || op(A) x - b ||_inf / ||b||_inf with op = A (LU) or A'A + mu I (normal). */
static double rel_residual(const fesd__ls *ls, const spmat *A, double mu, const double *x,
                           const double *b) {
  int m = A->m, n = A->n;
  double *y = calloc((size_t)m, sizeof(double)), res = 0.0, bn = 0.0;
  for (int j = 0; j < n; j++)
    for (int i = 0; i < m; i++) y[i] += A->dense[i + (size_t)j * m] * x[j];
  for (int j = 0; j < n; j++) {
    double v;
    if (ls->ops->kind == FESD__LS_LU) {
      v = y[j];
    } else {
      v = mu * x[j];
      for (int i = 0; i < m; i++) v += A->dense[i + (size_t)j * m] * y[i];
    }
    res = fmax(res, fabs(v - b[j]));
    bn = fmax(bn, fabs(b[j]));
  }
  free(y);
  return res / bn;
}

static void conformance(const char *name, int (*create)(fesd__ls **, int), int kind, int n) {
  rng_t r = {7 + (unsigned long long)n};
  const int m = kind == FESD__LS_LU ? n : n + n / 4;
  spmat A;
  spmat_random(&A, m, n, 0.08, &r);
  fesd__ls *ls = NULL;
  CHECK_RC(create(&ls, n), FESD_OK);
  if (!ls) return;
  CHECK(ls->ops->kind == kind, "%s kind", name);
  const int *p = ls->ops->layout == FESD__LAYOUT_CSC ? A.p : A.pt;
  const int *idx = ls->ops->layout == FESD__LAYOUT_CSC ? A.i : A.it;
  CHECK_RC(ls->ops->analyze(ls, m, ls->ops->layout == FESD__LAYOUT_DENSE ? NULL : p,
                            ls->ops->layout == FESD__LAYOUT_DENSE ? NULL : idx),
           FESD_OK);
  double *scratch = malloc((size_t)m * n * sizeof(double)), b[60], x[60], worst = 0.0;
  CHECK(n <= 60, "buffer size");
  /* several numeric factorizations on the same pattern with changing values */
  for (int rep = 0; rep < 4; rep++) {
    double mu = kind == FESD__LS_NORMAL ? 0.1 * rep : 0.0;
    CHECK_RC(ls->ops->factor(ls, layout_values(ls, &A, scratch), mu), FESD_OK);
    for (int k = 0; k < 3; k++) {
      for (int j = 0; j < n; j++) b[j] = x[j] = rng_sym(&r);
      CHECK_RC(ls->ops->solve(ls, x), FESD_OK);
      worst = fmax(worst, rel_residual(ls, &A, mu, x, b));
    }
    for (int k = 0; k < A.nnz; k++) { /* new values, same pattern */
      A.x[k] *= 1.0 + 0.3 * rng_sym(&r);
    }
    for (int j = 0; j < n; j++) /* keep the three representations consistent */
      for (int k = A.p[j]; k < A.p[j + 1]; k++) A.dense[A.i[k] + (size_t)j * m] = A.x[k];
    for (int i = 0; i < m; i++)
      for (int k = A.pt[i]; k < A.pt[i + 1]; k++) A.xt[k] = A.dense[i + (size_t)A.it[k] * m];
  }
  printf("  %-14s n=%d: 4 factorizations x 3 solves: max relative residual %.1e\n", name, n,
         worst);
  CHECK(worst <= 1e-12, "%s: residual %.2e", name, worst);

  /* singular matrix (a zero column) must be reported, and a later regular one still works */
  {
    for (int k = A.p[3]; k < A.p[4]; k++) A.dense[A.i[k] + (size_t)3 * m] = 0.0;
    for (int k = A.p[3]; k < A.p[4]; k++) A.x[k] = 0.0;
    for (int i = 0; i < m; i++)
      for (int k = A.pt[i]; k < A.pt[i + 1]; k++) A.xt[k] = A.dense[i + (size_t)A.it[k] * m];
    int rc = ls->ops->factor(ls, layout_values(ls, &A, scratch), 0.0);
    printf("  %-14s n=%d: zero column: %s\n", name, n, fesd_status_name(rc));
    CHECK(rc == FESD_ERR_SINGULAR, "%s: singular matrix gave %s", name, fesd_status_name(rc));
  }
  /* a new pattern (a different matrix) */
  spmat B;
  spmat_random(&B, m, n, 0.15, &r);
  p = ls->ops->layout == FESD__LAYOUT_CSC ? B.p : B.pt;
  idx = ls->ops->layout == FESD__LAYOUT_CSC ? B.i : B.it;
  CHECK_RC(ls->ops->analyze(ls, m, ls->ops->layout == FESD__LAYOUT_DENSE ? NULL : p,
                            ls->ops->layout == FESD__LAYOUT_DENSE ? NULL : idx),
           FESD_OK);
  CHECK_RC(ls->ops->factor(ls, layout_values(ls, &B, scratch), 0.01), FESD_OK);
  for (int j = 0; j < n; j++) b[j] = x[j] = rng_sym(&r);
  CHECK_RC(ls->ops->solve(ls, x), FESD_OK);
  double rr = rel_residual(ls, &B, 0.01, x, b);
  CHECK(rr <= 1e-12, "%s after re-analysis: %.2e", name, rr);
  fesd__ls_destroy(&ls);
  CHECK(ls == NULL, "destroy");
  free(scratch);
  spmat_free(&A);
  spmat_free(&B);
}

/* Nonlinear square MCP: F(z) = M z + 0.2 sin(z) + q, first 10 components equations. */
#define NB 80
#define NEB 10
typedef struct {
  lcp_t lcp;
  int *row, *col, nnz;
} mcp_t;
static int mcp_eval(const double *z, double *raw, double *jac, void *user) {
  mcp_t *u = (mcp_t *)user;
  double tmp[2 * NB];
  /* eq rows = the w rows of the first NEB pairs; pairs = the remaining ones */
  lcp_eval(z, tmp, NULL, &u->lcp);
  for (int i = 0; i < NEB; i++) raw[i] = tmp[NB + i] + 0.2 * sin(z[i]);
  for (int k = 0; k < NB - NEB; k++) {
    raw[NEB + k] = z[NEB + k];
    raw[NB + k] = tmp[NB + NEB + k] + 0.2 * sin(z[NEB + k]);
  }
  if (jac) {
    for (int t = 0; t < u->nnz; t++) {
      int r = u->row[t], c = u->col[t];
      if (r >= NEB && r < NB) {
        jac[t] = 1.0;
        continue;
      }
      int fi = r < NEB ? r : r - NB + NEB;
      double v = 0.0;
      for (int k = u->lcp.rp[fi]; k < u->lcp.rp[fi + 1]; k++)
        if (u->lcp.ci[k] == c) v += u->lcp.v[k];
      jac[t] = v + (fi == c ? 0.2 * cos(z[c]) : 0.0);
    }
  }
  return 0;
}

static void public_conformance(void) {
  printf("Public API: one nonlinear square problem (n = %d, %d equations), three LU backends\n",
         NB, NEB);
  mcp_t u;
  double zs[NB], zref[NB], z[NB];
  random_lcp(&u.lcp, NB, 2, 99, 0, zs);
  u.nnz = 0;
  u.row = malloc((size_t)(NB + u.lcp.nnz_m) * sizeof(int));
  u.col = malloc((size_t)(NB + u.lcp.nnz_m) * sizeof(int));
  for (int i = 0; i < NB; i++) /* b rows / eq rows: pattern of M (diagonal included) */
    for (int k = u.lcp.rp[i]; k < u.lcp.rp[i + 1]; k++) {
      u.row[u.nnz] = i < NEB ? i : NB + (i - NEB);
      u.col[u.nnz++] = u.lcp.ci[k];
    }
  for (int k = 0; k < NB - NEB; k++) {
    u.row[u.nnz] = NEB + k;
    u.col[u.nnz++] = NEB + k;
  }
  fesd_ncp_problem p = {NB, NEB, NB - NEB, u.nnz, u.row, u.col, mcp_eval, &u};
  const int backends[3] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_UMFPACK, FESD_NCP_BACKEND_KLU};
  for (int b = 0; b < 3; b++) {
    fesd_ncp *ws = NULL;
    CHECK_RC(setup_backend(&ws, &p, backends[b]), FESD_OK);
    for (int i = 0; i < NB; i++) z[i] = 0.5;
    fesd_ncp_info info;
    int rc = fesd_ncp_solve(ws, z, 0.0, &info);
    double d = b ? vec_dist_inf(z, zref, NB) : 0.0;
    printf("  %-8s %s it=%d fact=%d |F|=%.1e |z - z_dense| = %.1e\n",
           fesd_ncp_backend_name(info.backend), fesd_status_name(rc), info.iterations,
           info.factorizations, info.residual, d);
    CHECK(rc == FESD_OK && info.residual <= 1e-12 && info.backend == backends[b], "%s",
          fesd_ncp_backend_name(backends[b]));
    if (b == 0) memcpy(zref, z, sizeof z);
    else CHECK(d <= 1e-12, "backends disagree by %.2e", d);
    fesd_ncp_free(&ws);
  }
  /* AUTO: dense up to dense_max_n, KLU above; CHOLMOD when m > n */
  struct {
    int dense_max_n, want;
  } autos[2] = {{NB, FESD_NCP_BACKEND_DENSE}, {NB - 1, FESD_NCP_BACKEND_KLU}};
  for (int a = 0; a < 2; a++) {
    fesd_ncp_settings s;
    fesd_ncp_settings_default(&s);
    s.dense_max_n = autos[a].dense_max_n;
    fesd_ncp *ws = NULL;
    CHECK_RC(fesd_ncp_setup(&ws, &p, &s), FESD_OK);
    for (int i = 0; i < NB; i++) z[i] = 0.5;
    fesd_ncp_info info;
    CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_OK);
    CHECK(info.backend == autos[a].want, "AUTO with dense_max_n = %d chose %s",
          autos[a].dense_max_n, fesd_ncp_backend_name(info.backend));
    CHECK(vec_dist_inf(z, zref, NB) <= 1e-12, "AUTO solution");
    /* pinning pair 0 (not degenerate here: only the over-determined path is checked) */
    unsigned char pm[NB - NEB] = {0};
    pm[0] = FESD_NCP_PAIR_PIN;
    CHECK_RC(fesd_ncp_set_rows(ws, NULL, pm), FESD_OK);
    for (int i = 0; i < NB; i++) z[i] = 0.5;
    fesd_ncp_solve(ws, z, 0.0, &info);
    int want_lsq = autos[a].want == FESD_NCP_BACKEND_DENSE ? FESD_NCP_BACKEND_DENSE
                                                           : FESD_NCP_BACKEND_CHOLMOD;
    CHECK(info.m == NB + 1 && info.backend == want_lsq, "AUTO m > n chose %s",
          fesd_ncp_backend_name(info.backend));
    printf("  auto (dense_max_n = %d): square -> %s, m = n+1 -> %s\n", autos[a].dense_max_n,
           fesd_ncp_backend_name(autos[a].want), fesd_ncp_backend_name(info.backend));
    fesd_ncp_free(&ws);
  }
  free(u.row);
  free(u.col);
  lcp_free(&u.lcp);
}

int main(void) {
  printf("Linear-solver vtable conformance (n = 20 and 60; normal objects with m = 1.25 n)\n");
  for (int n = 20; n <= 60; n += 40) { /* n = 20 takes the dense backend's own small LU */
    conformance("dense LU", fesd__ls_dense_lu_create, FESD__LS_LU, n);
    conformance("UMFPACK", fesd__ls_umfpack_create, FESD__LS_LU, n);
    conformance("KLU", fesd__ls_klu_create, FESD__LS_LU, n);
    conformance("dense normal", fesd__ls_dense_normal_create, FESD__LS_NORMAL, n);
    conformance("CHOLMOD", fesd__ls_cholmod_create, FESD__LS_NORMAL, n);
  }
  public_conformance();
  return test_summary("test_ncp_backends");
}
