/* Internal: unblocked dense LU with partial pivoting, column-major (a[j * n + i] is row i,
 * column j), 0-based pivots: below ~50 unknowns it beats LAPACK, whose call and blocking
 * overhead dominate small systems. */
#ifndef FESD_COMMON_DENSE_LU_H
#define FESD_COMMON_DENSE_LU_H

/* Factor a in place; returns k + 1 when column k has no nonzero pivot (as dgetrf's info). */
int fesd__dense_lu(int n, double *a, int *piv);
/* x <- A^{-1} x with the factors of fesd__dense_lu. */
void fesd__dense_lu_solve(int n, const double *a, const int *piv, double *x);
/* The same for nrhs columns of x (leading dimension n), each bit for bit as above. */
void fesd__dense_lu_solve_many(int n, const double *a, const int *piv, double *x, int nrhs);

#endif
