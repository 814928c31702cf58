/* Workspace of the semismooth Newton solver (internal to src/ncp). */
#ifndef FESD_NCP_INTERNAL_H
#define FESD_NCP_INTERNAL_H

#include "fesd_ncp.h"
#include "ncp/linsolve.h"

/* Right-hand sides per block of the sensitivity solves (sensitivity.c). */
#define FESD__SENS_BLOCK 4

/* Accumulated statistics of one public call (copied into fesd_ncp_info). */
typedef struct {
  int iterations, stages, factorizations, evals, jac_evals, backtracks;
  double time_eval, time_linsolve, time_iter;
} fesd__ncp_stats;

struct fesd_ncp {
  /* problem (copied at setup) */
  int n, n_eq, n_pair, nnz, n_raw, m_max;
  int *trow, *tcol;
  fesd_ncp_eval_fn eval;
  void *user;
  fesd_ncp_settings set;
  int dense; /* dense backends chosen at setup */

  /* linear solvers: square LU (NULL for CHOLMOD) and normal equations (lazy when sparse) */
  fesd__ls *lu, *normal;
  fesd__ls *active; /* the one used by the current row selection */
  /* border (fesd_ncp_set_border): flags per raw row and unknown, of the assembled rows of the
   * current selection; the bordered KLU is used when the counts match (square, KLU) */
  fesd__ls *border;
  unsigned char *raw_border, *col_border, *row_border;
  int nb, border_dirty;
  int ready;        /* 0 after a failed re-analysis: solves return FESD_ERR_NOT_READY */
  int rows_pending; /* the selection is set but not applied yet (setup): applied at first use */
  int defer;           /* set_rows leaves the pattern to the first Jacobian (ncp_defer.h) */
  int pattern_pending; /* the selection's pattern is not built and analysed yet */
  int nomem;        /* FESD_ERR_NOMEM results of analyses, factorizations and solves so far */

  /* row selection */
  unsigned char *eq_on, *pair_mode;
  int m, n_eq_on, n_fb;
  int *eq_list;  /* active eq rows, increasing */
  int *pair_pos; /* assembled row of each pair (-1 when OFF) */
  int *fb_list;  /* pairs in FB mode */

  /* assembly maps over the active pattern entries */
  int n_act;
  int *act_src;  /* index into the user's jac array */
  int *act_wrow; /* raw row whose weight multiplies the entry */
  int *act_tgt;  /* position in vals */
  int *act_r, *act_c; /* assembled row / column (pattern building scratch) */
  int *sp_p, *sp_i;   /* sparse pattern of the active layout */
  int *work;          /* pattern building scratch */
  int nvals;          /* entries of vals in the current layout */
  double *vals;       /* assembled Jacobian values */
  double *wgt;        /* n_raw chain-rule weights: 1 for eq/PIN rows, da/db for FB */

  /* iteration buffers (n_raw, nnz, m_max, n); trial points get no Jacobian */
  double *raw_c, *raw_t, *jac_c, *F_c, *F_t;
  double *zt, *d, *g, *tmp, *z0;
  double *lb, *ub;
  int has_box;

  fesd__ncp_stats pending; /* sensitivity work, reported by the next solve */
  double *sens_jv;         /* nnz: weighted Jacobian entries of the sensitivity checks */
  double *sens_blk;        /* 3 FESD__SENS_BLOCK n: a block's right-hand sides, residuals, sizes */
  double sens_residual;    /* worst relative residual of the last sensitivity solves */
  double sens_ferr;        /* worst forward-error estimate of the last sensitivity solves */
};

/* assemble.c */
void fesd__ncp_residual(const fesd_ncp *ws, const double *raw, double sigma, double *F);
void fesd__ncp_weights(fesd_ncp *ws, const double *raw, double sigma);
void fesd__ncp_jacobian(fesd_ncp *ws, const double *jac);
void fesd__ncp_jt_mul(const fesd_ncp *ws, const double *x, double *y); /* y = J' x */
void fesd__ncp_j_mul(const fesd_ncp *ws, const double *x, double *y);  /* y = J x */
double fesd__ncp_frobenius(const fesd_ncp *ws);
int fesd__all_finite(const double *x, int n);

/* rc, counted in ws->nomem when it is FESD_ERR_NOMEM (fesd__ncp_nomem_count) */
static inline int fesd__ncp_note(fesd_ncp *ws, int rc) {
  if (rc == FESD_ERR_NOMEM) ws->nomem++;
  return rc;
}

/* rows.c */
/* Apply the selection (eq_on, pair_mode); keep_pattern: it has the pattern of the applied one
 * (only A <-> B flips), whose maps and analysis stay. */
int fesd__ncp_apply_rows(fesd_ncp *ws, int keep_pattern);
/* Apply a pending selection (FESD_OK when ready, FESD_ERR_NOT_READY after a failed one). */
int fesd__ncp_ensure_rows(fesd_ncp *ws);
/* Build and analyse the pattern of the applied selection before its first Jacobian is
 * assembled, when set_rows deferred it. */
int fesd__ncp_ensure_pattern(fesd_ncp *ws);

/* newton.c: callback wrapper shared with sensitivity.c */
int fesd__ncp_call(fesd_ncp *ws, const double *z, double *raw, double *jac, fesd__ncp_stats *st);

#endif
