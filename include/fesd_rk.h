/**
 * @file fesd_rk.h
 * @brief Butcher tableaus (src/rk): Radau IIA, Gauss-Legendre, Lobatto IIIA,
 *        Lobatto IIIC (computed for any s up to FESD_RK_MAX_STAGES) and the
 *        classic explicit methods for s = 1..4.
 *
 * Collocation tableaus are computed, not typed in: nodes from the zeros of
 * the orthogonal (Jacobi) polynomials by Aberth-Ehrlich iteration (Golub-Welsch
 * with LAPACK dstev as fallback) refined by Newton, A and b by exact quadrature of the Lagrange basis. Accuracy of
 * the entries: a few ulps (the order conditions hold to ~1e-15).
 */
#ifndef FESD_RK_H
#define FESD_RK_H

#include "fesd_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest stage count a tableau can hold. */
#define FESD_RK_MAX_STAGES 12

typedef enum {
  FESD_RK_RADAU_IIA = 0,     /**< order 2s-1, stiffly accurate, c_s = 1 */
  FESD_RK_GAUSS_LEGENDRE = 1, /**< order 2s, c_s < 1 */
  FESD_RK_LOBATTO_IIIA = 2,  /**< order 2s-2 (s >= 2), stiffly accurate, c_1 = 0, c_s = 1 */
  FESD_RK_LOBATTO_IIIC = 3,  /**< order 2s-2 (s >= 2), stiffly accurate, c_1 = 0, c_s = 1 */
  FESD_RK_EXPLICIT = 4       /**< s=1 Euler, s=2 Heun, s=3 Kutta-3, s=4 classic RK4; order s */
} fesd_rk_family;

#define FESD_RK_NUM_FAMILIES 5

/** A Butcher tableau. Plain data: copy freely. A[i][j] is row i, column j. */
typedef struct {
  fesd_rk_family family;
  int s;                   /**< number of stages */
  int order;               /**< classical order p */
  double A[FESD_RK_MAX_STAGES][FESD_RK_MAX_STAGES];
  double b[FESD_RK_MAX_STAGES];
  double c[FESD_RK_MAX_STAGES];
  int c_end_is_one;        /**< 1 if c_s == 1 exactly (right element boundary is a stage) */
  int stiffly_accurate;    /**< 1 if b_j == A[s-1][j] for all j (last stage state = end state) */
  int is_explicit;         /**< 1 if A is strictly lower triangular */
} fesd_tableau;

/**
 * @brief Compute the tableau of a family with s stages.
 * @param[in]  family  a fesd_rk_family value
 * @param[in]  s       stage count: 1..FESD_RK_MAX_STAGES for Radau IIA and Gauss-Legendre,
 *                     2..FESD_RK_MAX_STAGES for Lobatto IIIA/IIIC, 1..4 for explicit
 * @param[out] out     the tableau (not modified on error)
 * @return FESD_OK, FESD_ERR_NULL, FESD_ERR_UNSUPPORTED_TABLEAU (unknown family or s out of range),
 *         FESD_ERR_LINSOLVE (LAPACK eigen-solver failure).
 * Allocates nothing; thread-safe.
 */
FESD_API int fesd_tableau_get(fesd_rk_family family, int s, fesd_tableau *out);

/** @brief Short name of a family: "radau", "gauss", "lobatto3a", "lobatto3c", "erk". NULL if unknown. */
FESD_API const char *fesd_rk_family_name(fesd_rk_family family);

/** @brief Parse a family name (as printed by fesd_rk_family_name). FESD_ERR_INVALID_ARG if unknown. */
FESD_API int fesd_rk_family_parse(const char *name, fesd_rk_family *out);

/** @brief Order p of the family with s stages, or -1 if the pair is unsupported. */
FESD_API int fesd_rk_order(fesd_rk_family family, int s);

#ifdef __cplusplus
}
#endif
#endif
