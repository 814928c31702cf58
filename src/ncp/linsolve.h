/* Internal linear-solver interface of src/ncp (not installed).
 *
 * Two kinds of objects sit behind one small vtable:
 *   FESD__LS_LU   square LU of J (n x n):               solve J x = b
 *   FESD__LS_NORMAL  Cholesky of J'J + mu I (J is m x n): solve (J'J + mu I) x = b
 * The caller owns the matrix values; the layout the object expects tells it how
 * to assemble them:
 *   FESD__LAYOUT_DENSE   column-major m x n, leading dimension m
 *   FESD__LAYOUT_CSC     CSC of J (m rows, n columns), rows sorted, no duplicates
 *   FESD__LAYOUT_CSC_T   CSC of J' (n rows, m columns), i.e. CSR of J
 * Lifecycle: create (allocates for the largest m) -> analyze (per pattern; sparse
 * objects may allocate here) -> factor/solve many times -> destroy. factor and
 * solve allocate nothing except UMFPACK's numeric object (by design of UMFPACK)
 * and KLU's full re-factorization fallback. */
#ifndef FESD_NCP_LINSOLVE_H
#define FESD_NCP_LINSOLVE_H

#include <stddef.h>

enum { FESD__LS_LU = 0, FESD__LS_NORMAL = 1 };
enum { FESD__LAYOUT_DENSE = 0, FESD__LAYOUT_CSC = 1, FESD__LAYOUT_CSC_T = 2 };

typedef struct fesd__ls fesd__ls;

typedef struct {
  int kind;              /* FESD__LS_* */
  int layout;            /* FESD__LAYOUT_* */
  int destroys_values;   /* factor overwrites the values array (dense LU) */
  /* New pattern with m rows (p, idx describe the layout; NULL for dense). */
  int (*analyze)(fesd__ls *ls, int m, const int *p, const int *idx);
  /* Numeric factorization of J (LU) or J'J + mu I (NORMAL). Returns FESD_OK,
   * FESD_ERR_SINGULAR, FESD_ERR_NOMEM or FESD_ERR_LINSOLVE. */
  int (*factor)(fesd__ls *ls, double *values, double mu);
  /* x (n) holds the right-hand side on entry and the solution on return. */
  int (*solve)(fesd__ls *ls, double *x);
  void (*destroy)(fesd__ls *ls);
  /* Optional (NULL: solve per column): nrhs right-hand sides in x (column-major, leading
   * dimension n), each solved bit for bit as by solve, with less work per column. */
  int (*solve_many)(fesd__ls *ls, double *x, int nrhs);
} fesd__ls_ops;

struct fesd__ls {
  const fesd__ls_ops *ops;
  int backend; /* fesd_ncp_backend */
  int n;       /* unknowns */
  int m;       /* rows of the current pattern */
};

/* Constructors for n unknowns (FESD_OK or FESD_ERR_NOMEM / FESD_ERR_LINSOLVE). */
int fesd__ls_dense_lu_create(fesd__ls **ls, int n);
int fesd__ls_dense_normal_create(fesd__ls **ls, int n);
int fesd__ls_umfpack_create(fesd__ls **ls, int n);
int fesd__ls_klu_create(fesd__ls **ls, int n);
/* KLU: solve for nrhs right-hand sides at once (column-major, leading dimension n). */
int fesd__ls_klu_solve_many(fesd__ls *ls, double *x, int nrhs);
int fesd__ls_cholmod_create(fesd__ls **ls, int n);
/* Bordered KLU (ls_border.c): nb rows and columns eliminated last by a Schur complement;
 * the flags (assembled rows, columns) are read at each analyze and must stay valid. */
int fesd__ls_border_create(fesd__ls **ls, int n, int nb);
void fesd__ls_border_flags(fesd__ls *ls, const unsigned char *row_border, const unsigned char *col_border);
/* Bordered dense LU (ls_bdense.c) of small systems with a border, patterns of up to max_nz
 * entries; the flags as for the bordered KLU. */
int fesd__ls_bdense_create(fesd__ls **ls, int n, int max_nz);
void fesd__ls_bdense_flags(fesd__ls *ls, const unsigned char *row_border, const unsigned char *col_border);

static inline int fesd__ls_solve_many(fesd__ls *ls, double *x, int nrhs) {
  if (ls->ops->solve_many) return ls->ops->solve_many(ls, x, nrhs);
  int rc = 0; /* FESD_OK */
  for (int j = 0; j < nrhs && !rc; j++) rc = ls->ops->solve(ls, x + (size_t)j * ls->n);
  return rc;
}

static inline void fesd__ls_destroy(fesd__ls **ls) {
  if (ls && *ls) {
    (*ls)->ops->destroy(*ls);
    *ls = 0;
  }
}

#endif
