/* fesd_ncp_sensitivity against central finite differences of the solution map.
 * Parametric mixed problem F(z, p) = M z + 0.1 z^3 + q0 + p_0 d_0 + p_1 d_1 with the
 * first NE components as equations (free z) and the rest complementarity pairs
 * (a = z, b = F); M positive definite, strictly complementary solution at p = 0,
 * so the solution map is smooth near p = 0. A duplicate of equation 0 can be
 * switched on to make the system over-determined (consistent for every p). */
#include "ncp_test_util.h"

#define N 24
#define NE 6
#define NP (N - NE)
#define NRAW (NE + 1 + 2 * NP)

typedef struct {
  double M[N * N], q0[N], d[2][N], p[2];
  int row[N * N + N * N + NP], col[N * N + N * N + NP], nnz;
} sens_t;

static void F_of(const sens_t *s, const double *z, double *f) {
  for (int i = 0; i < N; i++) {
    double v = s->q0[i] + s->p[0] * s->d[0][i] + s->p[1] * s->d[1][i] + 0.1 * z[i] * z[i] * z[i];
    for (int j = 0; j < N; j++) v += s->M[i + j * N] * z[j];
    f[i] = v;
  }
}

/* raw rows: F_0..F_{NE-1}, duplicate F_0, then a_k = z_{NE+k}, then b_k = F_{NE+k} */
static int sens_eval(const double *z, double *raw, double *jac, void *user) {
  const sens_t *s = (const sens_t *)user;
  double f[N];
  F_of(s, z, f);
  for (int i = 0; i < NE; i++) raw[i] = f[i];
  raw[NE] = f[0];
  for (int k = 0; k < NP; k++) {
    raw[NE + 1 + k] = z[NE + k];
    raw[NE + 1 + NP + k] = f[NE + k];
  }
  if (jac)
    for (int t = 0; t < s->nnz; t++) {
      int r = s->row[t], c = s->col[t];
      int fi = r < NE ? r : r == NE ? 0 : r >= NE + 1 + NP ? r - (NE + 1 + NP) + NE : -1;
      if (fi < 0) {
        jac[t] = 1.0; /* a rows */
      } else {
        jac[t] = s->M[fi + c * N] + (fi == c ? 0.3 * z[c] * z[c] : 0.0);
      }
    }
  return 0;
}

static void build(sens_t *s) {
  rng_t r = {2024};
  double B[N * N], zs[N], f[N];
  for (int i = 0; i < N * N; i++) B[i] = rng_sym(&r);
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++) {
      double v = 0.0;
      for (int k = 0; k < N; k++) v += B[i + k * N] * B[j + k * N];
      s->M[i + j * N] = v / N + (i == j ? 0.5 : 0.0) + 0.2 * (B[i + j * N] - B[j + i * N]);
    }
  s->p[0] = s->p[1] = 0.0;
  memset(s->q0, 0, sizeof s->q0);
  for (int i = 0; i < N; i++) zs[i] = i < NE ? rng_sym(&r) : (i % 2 ? 0.5 + rng_uniform(&r) : 0.0);
  F_of(s, zs, f); /* q0 = 0 here */
  for (int i = 0; i < N; i++) {
    double w = (i >= NE && i % 2 == 0) ? 0.5 + rng_uniform(&r) : 0.0;
    s->q0[i] = w - f[i];
    s->d[0][i] = rng_sym(&r);
    s->d[1][i] = rng_sym(&r);
  }
  int t = 0;
  for (int i = 0; i < NE + 1; i++)
    for (int j = 0; j < N; j++) {
      s->row[t] = i;
      s->col[t++] = j;
    }
  for (int k = 0; k < NP; k++) {
    s->row[t] = NE + 1 + k;
    s->col[t++] = NE + k;
  }
  for (int k = 0; k < NP; k++)
    for (int j = 0; j < N; j++) {
      s->row[t] = NE + 1 + NP + k;
      s->col[t++] = j;
    }
  s->nnz = t;
}

static void solve_at(fesd_ncp *ws, sens_t *s, const double *p, double sigma, double *z) {
  s->p[0] = p[0];
  s->p[1] = p[1];
  for (int i = 0; i < N; i++) z[i] = 0.5;
  fesd_ncp_info info;
  int rc = fesd_ncp_solve(ws, z, sigma, &info);
  CHECK(rc == FESD_OK && info.residual <= 1e-13, "solve at p = (%g, %g): %s |F| %.1e", p[0], p[1],
        fesd_status_name(rc), info.residual);
}

/* dz/dp by the implicit function theorem vs central differences (h = 1e-5). */
static double compare(fesd_ncp *ws, sens_t *s, double sigma, const char *what, double *dz_out) {
  double z0[N], zp[N], zm[N], dz[2 * N], draw[2 * NRAW];
  const double p0[2] = {0, 0};
  solve_at(ws, s, p0, sigma, z0);
  memset(draw, 0, sizeof draw);
  for (int j = 0; j < 2; j++) {
    double *c = draw + j * NRAW;
    for (int i = 0; i < NE; i++) c[i] = s->d[j][i];
    c[NE] = s->d[j][0];
    for (int k = 0; k < NP; k++) c[NE + 1 + NP + k] = s->d[j][NE + k];
  }
  CHECK_RC(fesd_ncp_sensitivity(ws, z0, sigma, 2, draw, dz), FESD_OK);
  double worst = 0.0, h = 1e-5;
  for (int j = 0; j < 2; j++) {
    double pp[2] = {0, 0}, pm[2] = {0, 0};
    pp[j] = h;
    pm[j] = -h;
    solve_at(ws, s, pp, sigma, zp);
    solve_at(ws, s, pm, sigma, zm);
    for (int i = 0; i < N; i++) worst = fmax(worst, fabs((zp[i] - zm[i]) / (2 * h) - dz[j * N + i]));
  }
  s->p[0] = s->p[1] = 0.0;
  double scale = 0.0;
  for (int i = 0; i < 2 * N; i++) scale = fmax(scale, fabs(dz[i]));
  printf("  %-44s m=%d: max|dz/dp - FD| = %.1e (max|dz/dp| = %.2f)\n", what, fesd_ncp_rows(ws),
         worst, scale);
  CHECK(worst <= 1e-6, "%s: sensitivity differs from finite differences by %.2e", what, worst);
  if (dz_out) memcpy(dz_out, dz, sizeof dz);
  return worst;
}

int main(void) {
  static sens_t s;
  build(&s);
  fesd_ncp_problem p = {N, NE + 1, NP, s.nnz, s.row, s.col, sens_eval, &s};
  unsigned char eq_square[NE + 1];
  memset(eq_square, 1, sizeof eq_square);
  eq_square[NE] = 0; /* the duplicate row off: square */
  double ref[2 * N], dz[2 * N];
  const int backends[4] = {FESD_NCP_BACKEND_DENSE, FESD_NCP_BACKEND_UMFPACK, FESD_NCP_BACKEND_KLU,
                           FESD_NCP_BACKEND_CHOLMOD};
  printf("Sensitivities (n = %d, %d equations, %d pairs, 2 parameters)\n", N, NE, NP);
  for (int b = 0; b < 4; b++) {
    fesd_ncp *ws = NULL;
    CHECK_RC(setup_backend(&ws, &p, backends[b]), FESD_OK);
    if (!ws) continue;
    char what[64];
    if (backends[b] != FESD_NCP_BACKEND_CHOLMOD) {
      CHECK_RC(fesd_ncp_set_rows(ws, eq_square, NULL), FESD_OK);
      snprintf(what, sizeof what, "%s, square, sigma = 0", fesd_ncp_backend_name(backends[b]));
      compare(ws, &s, 0.0, what, b == 0 ? ref : dz);
      if (b) CHECK(vec_dist_inf(ref, dz, 2 * N) <= 1e-10, "backends disagree");
      snprintf(what, sizeof what, "%s, square, sigma = 1e-2", fesd_ncp_backend_name(backends[b]));
      compare(ws, &s, 1e-2, what, NULL);
      /* the sensitivity solve is reported by the next solve */
      double z[N];
      for (int i = 0; i < N; i++) z[i] = 0.5;
      fesd_ncp_info info;
      const double zero[2] = {0, 0};
      double draw[NRAW] = {0};
      draw[0] = 1.0;
      solve_at(ws, &s, zero, 0.0, z);
      CHECK_RC(fesd_ncp_sensitivity(ws, z, 0.0, 1, draw, dz), FESD_OK);
      for (int i = 0; i < N; i++) z[i] = 0.5;
      CHECK_RC(fesd_ncp_solve(ws, z, 0.0, &info), FESD_OK);
      CHECK(info.factorizations == info.iterations + 1 && info.jac_evals >= 2,
            "pending sensitivity work not counted: fact %d it %d", info.factorizations,
            info.iterations);
      /* A/B modes fixing the (strictly complementary) active set: same sensitivity */
      unsigned char ab[NP];
      for (int k = 0; k < NP; k++) ab[k] = z[NE + k] > 1e-8 ? FESD_NCP_PAIR_B : FESD_NCP_PAIR_A;
      CHECK_RC(fesd_ncp_set_rows(ws, eq_square, ab), FESD_OK);
      snprintf(what, sizeof what, "%s, active set via A/B modes", fesd_ncp_backend_name(backends[b]));
      compare(ws, &s, 0.0, what, dz);
      CHECK(vec_dist_inf(ref, dz, 2 * N) <= 1e-10, "A/B sensitivity differs by %.2e",
            vec_dist_inf(ref, dz, 2 * N));
      CHECK_RC(fesd_ncp_set_rows(ws, NULL, NULL), FESD_OK);
    }
    /* over-determined (duplicate row on): least-squares sensitivity = exact one */
    snprintf(what, sizeof what, "%s, m = n+1 (least squares)", fesd_ncp_backend_name(backends[b]));
    compare(ws, &s, 0.0, what, dz);
    CHECK(vec_dist_inf(ref, dz, 2 * N) <= 1e-9, "least-squares sensitivity differs by %.2e",
          vec_dist_inf(ref, dz, 2 * N));
    fesd_ncp_free(&ws);
  }
  return test_summary("test_ncp_sens");
}
