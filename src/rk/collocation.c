/* Collocation tableaus (Radau IIA, Gauss-Legendre, Lobatto IIIA) and
 * Lobatto IIIC: nodes from orthogonal polynomials, A and b by exact
 * quadrature of Lagrange polynomials (no Vandermonde systems). */
#include <string.h>

#include "rk_internal.h"

int fesd__collocation_nodes(fesd_rk_family family, int s, double *c) {
  switch (family) {
  case FESD_RK_GAUSS_LEGENDRE: /* zeros of the shifted Legendre polynomial P_s */
    return fesd__jacobi_zeros01(s, 0.0, 0.0, c);
  case FESD_RK_RADAU_IIA: { /* zeros of P_{s-1} for weight (1-x), then c_s = 1 */
    int rc = fesd__jacobi_zeros01(s - 1, 1.0, 0.0, c);
    c[s - 1] = 1.0;
    return rc;
  }
  case FESD_RK_LOBATTO_IIIA:
  case FESD_RK_LOBATTO_IIIC: { /* 0, zeros of P_{s-2} for weight x(1-x), 1 */
    int rc = fesd__jacobi_zeros01(s - 2, 1.0, 1.0, c + 1);
    c[0] = 0.0;
    c[s - 1] = 1.0;
    return rc;
  }
  default:
    return FESD_ERR_UNSUPPORTED_TABLEAU;
  }
}

void fesd__lagrange_denominators(int n, const double *y, double *den) {
  for (int j = 0; j < n; ++j) {
    double d = 1.0;
    for (int k = 0; k < n; ++k)
      if (k != j) d *= y[j] - y[k];
    den[j] = d;
  }
}

static double lagrange_eval(int n, const double *y, const double *den, int j, double t) {
  double p = 1.0;
  for (int k = 0; k < n; ++k)
    if (k != j) p *= t - y[k];
  return p / den[j];
}

/* Gauss-Legendre rule exact for the degree <= s-1 integrands used here. */
typedef struct {
  int m;
  double x[FESD_RK_MAX_STAGES], w[FESD_RK_MAX_STAGES];
} quad_rule;

static int quad_rule_for(int s, quad_rule *q) {
  q->m = s / 2 + 1; /* exact for degree 2m-1 >= s */
  return fesd__gauss_legendre01(q->m, q->x, q->w);
}

/* int_0^{upper} l_j(t) dt for the Lagrange basis on (n, y, den). */
static double lagrange_integral(const quad_rule *q, int n, const double *y,
                                const double *den, int j, double upper) {
  if (upper == 0.0) return 0.0;
  double sum = 0.0;
  for (int k = 0; k < q->m; ++k) sum += q->w[k] * lagrange_eval(n, y, den, j, upper * q->x[k]);
  return upper * sum;
}

int fesd__collocation_ab(int s, const double *c,
                         double A[FESD_RK_MAX_STAGES][FESD_RK_MAX_STAGES], double *b) {
  quad_rule q;
  int rc = quad_rule_for(s, &q);
  if (rc != FESD_OK) return rc;
  double den[FESD_RK_MAX_STAGES];
  fesd__lagrange_denominators(s, c, den);
  for (int j = 0; j < s; ++j) b[j] = lagrange_integral(&q, s, c, den, j, 1.0);
  for (int i = 0; i < s; ++i) {
    if (c[i] == 1.0) { /* same integral as b: copy (bit-identical last row) */
      memcpy(A[i], b, (size_t)s * sizeof(double));
      continue;
    }
    for (int j = 0; j < s; ++j) A[i][j] = lagrange_integral(&q, s, c, den, j, c[i]);
  }
  return FESD_OK;
}

int fesd__lobatto3c_ab(int s, const double *c,
                       double A[FESD_RK_MAX_STAGES][FESD_RK_MAX_STAGES], double *b) {
  quad_rule q;
  int rc = quad_rule_for(s, &q);
  if (rc != FESD_OK) return rc;
  /* b: the Lobatto weights (integrals of the Lagrange basis on all s nodes). */
  double den[FESD_RK_MAX_STAGES];
  fesd__lagrange_denominators(s, c, den);
  for (int j = 0; j < s; ++j) b[j] = lagrange_integral(&q, s, c, den, j, 1.0);

  /* L_m, m = 2..s: Lagrange basis of degree s-2 on the n = s-1 nodes c_2..c_s. */
  const int n = s - 1;
  const double *y = c + 1;
  double den2[FESD_RK_MAX_STAGES], Lc1[FESD_RK_MAX_STAGES];
  fesd__lagrange_denominators(n, y, den2);
  for (int m = 0; m < n; ++m) Lc1[m] = lagrange_eval(n, y, den2, m, c[0]);
  for (int i = 0; i < s - 1; ++i) {
    A[i][0] = b[0];
    for (int m = 0; m < n; ++m)
      A[i][m + 1] = lagrange_integral(&q, n, y, den2, m, c[i]) - b[0] * Lc1[m];
  }
  /* Last row: int_0^1 L_m - b_1 L_m(0) = b_m by the exactness of the Lobatto
   * rule; use b itself so that the method is stiffly accurate bit for bit. */
  memcpy(A[s - 1], b, (size_t)s * sizeof(double));
  return FESD_OK;
}
