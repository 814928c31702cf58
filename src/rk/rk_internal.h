/* Internal interface of src/rk (not installed). All functions are
 * allocation-free and thread-safe; arrays are caller-provided. */
#ifndef FESD_RK_INTERNAL_H
#define FESD_RK_INTERNAL_H

#include "fesd_rk.h"

/* orthopoly.c ------------------------------------------------------------- */

/* Zeros (ascending) on [0,1] of the degree-n polynomial orthogonal w.r.t. the
 * weight (1-x)^alpha * x^beta (a shifted Jacobi polynomial), alpha, beta > -1.
 * Aberth-Ehrlich iteration on the closed-form three-term recurrence from
 * Chebyshev points, Golub-Welsch (LAPACK dstev on the Jacobi matrix) where it
 * does not settle, then Newton polishing on the recurrence. Symmetric weights
 * (alpha == beta) give exactly symmetric zeros (x[n-1-i] = 1 - x[i]; the
 * middle zero of odd n is exactly 1/2).
 * 0 <= n <= FESD_RK_MAX_STAGES. Returns FESD_OK or FESD_ERR_LINSOLVE. */
int fesd__jacobi_zeros01(int n, double alpha, double beta, double *x);
/* The same by Golub-Welsch alone when eigen != 0 (the fallback, and an independent
 * computation for the tests). */
int fesd__jacobi_zeros01_by(int n, double alpha, double beta, int eigen, double *x);

/* n-point Gauss-Legendre rule on [0,1] (exact for degree 2n-1): nodes from
 * fesd__jacobi_zeros01(n, 0, 0), weights from the Christoffel function
 * w_i = 1 / sum_k p_k(x_i)^2 (orthonormal p_k). 1 <= n <= FESD_RK_MAX_STAGES. */
int fesd__gauss_legendre01(int n, double *x, double *w);

/* collocation.c ----------------------------------------------------------- */

/* Stage nodes of a collocation family (Radau IIA, Gauss, Lobatto IIIA/IIIC).
 * Exact where known: c_1 = 0 and c_s = 1 for Lobatto, c_s = 1 for Radau.
 * The caller checks that (family, s) is supported. */
int fesd__collocation_nodes(fesd_rk_family family, int s, double *c);

/* Lagrange basis on the n nodes y: l_j(t) = prod_{k != j} (t - y_k) / den[j]. */
void fesd__lagrange_denominators(int n, const double *y, double *den);

/* Collocation A and b on nodes c: A_ij = int_0^{c_i} l_j, b_j = int_0^1 l_j
 * (l_j: Lagrange basis on c), by an exact Gauss-Legendre quadrature. */
int fesd__collocation_ab(int s, const double *c,
                         double A[FESD_RK_MAX_STAGES][FESD_RK_MAX_STAGES], double *b);

/* Lobatto IIIC coefficients on Lobatto nodes c (c_1 = 0, c_s = 1): b as for
 * collocation (Lobatto weights), a_i1 = b_1 and, for m = 2..s,
 * a_im = int_0^{c_i} L_m - b_1 L_m(c_1) with L_m the Lagrange basis of degree
 * s-2 on c_2..c_s (this is the condition C(s-1)). The last row is set to b. */
int fesd__lobatto3c_ab(int s, const double *c,
                       double A[FESD_RK_MAX_STAGES][FESD_RK_MAX_STAGES], double *b);

#endif
