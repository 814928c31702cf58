/* Internal: validated copy of a user model, sign matrices, and evaluation of the mode
 * fields, the Stewart indicators g and their Jacobians at one point. Everything is kept
 * in a sparse layout (a dense model is the special case rows = all, full patterns), so
 * the cost of a step grows with the nonzeros of the model, not with n_x^2. Central finite
 * differences replace missing Jacobian callbacks of dense models. */
#ifndef FESD_MODEL_H
#define FESD_MODEL_H

#include "common/block.h"
#include "fesd_integrator.h"

typedef struct {
  int nx, nu, nsys, nth; /* nth = sum of modes */
  int *nf, *nc;          /* per subsystem */
  int *th_off;           /* first stacked mode of subsystem k (nsys + 1 entries) */
  int *sys_of;           /* subsystem of stacked mode i */
  signed char **S;       /* per subsystem nf x nc (NULL when nc == 0) */
  int *swr;              /* rows of the switch callback of subsystem k (nc or nf) */
  int sparse;            /* the user gave sparsity */
  /* per subsystem: rows its fields touch; df/dx pattern (r indexes rows); switch pattern */
  int *nr, **rows;
  int *fj_nnz, **fj_r, **fj_c;
  int *sj_nnz, **sj_r, **sj_c;
  int *ncol, **cols, **sj_cp; /* distinct columns of the switch pattern; entry -> column */
  /* offsets of stacked mode i / subsystem k in the point-evaluation arrays */
  int *Foff, *dFoff, *Fuoff, *dgoff;
  int nF, ndF, nFu, ndg;
  /* union pattern of sum_i theta_i df_i/dx (column-major order), and entry maps */
  int pf_nnz, *pf_r, *pf_c, **fj_map;
  fesd_model user;       /* callbacks and user pointer */
  /* scratch */
  int max_sw, max_fj, max_nr;
  double *xp, *cbuf, *cbuf2, *dcbuf, *dcubuf, *fbuf, *fbuf2, *up, *jxbuf;
  const char *failed;    /* name of the callback that failed last */
  double t;              /* time of the point being evaluated (passed to the callbacks) */
} fesd__model;

/* Output of one evaluation; NULL members are not computed. */
typedef struct {
  double *F;     /* nF: the nr[k] values of mode i at Foff[i] */
  double *g;     /* nth */
  double *dFdx;  /* ndF: the fj_nnz[k] values of mode i at dFoff[i] */
  double *dgdx;  /* ndg: subsystem k's nf_k x ncol_k block (column-major) at dgoff[k] */
  double *dFdu;  /* nFu: mode i's nr x nu block at Fuoff[i] */
  double *dgdu;  /* nth x nu, column-major */
} fesd__point_eval;

/* fmax and fmin without the libm call (hot loops): the larger (smaller) of a and b, the other
 * one if one is NaN, b if they compare equal (as glibc's on x86-64: maxsd, minsd). */
static inline double fesd__fmax(double a, double b) { return a > b || b != b ? a : b; }
static inline double fesd__fmin(double a, double b) { return a < b || b != b ? a : b; }

int fesd__model_init(fesd__model *m, const fesd_model *user);
void fesd__model_free(fesd__model *m);
/* The arrays of a point evaluation for this model, from a workspace's block (common/block.h;
 * all NULL in its sizing pass). */
void fesd__point_take(const fesd__model *m, fesd__point_eval *pe, int fields, fesd__block *B);
/* Evaluate at (t, x) (u may be NULL when nu == 0). Returns FESD_OK, FESD_ERR_CALLBACK or
 * FESD_ERR_NONFINITE (m->failed names the callback). */
int fesd__model_eval(fesd__model *m, double t, const double *x, const double *u, fesd__point_eval *out);
/* Only the fields of the modes with theta_i != 0 (F as in fesd__point_eval; the others are
 * left as they are): what a stage with fixed multipliers needs. */
int fesd__model_fields_active(fesd__model *m, double t, const double *x, const double *u, double *F,
                              const double *theta);
/* Only g at (t, x). */
int fesd__model_g(fesd__model *m, double t, const double *x, const double *u, double *g);

/* The two active modes (flags a, one per stacked mode) of subsystem k: returns the first and
 * writes the second to *j when exactly two are active (a 2-mode sliding mode), else -1. */
int fesd__two_modes(const fesd__model *m, const unsigned char *a, int k, int *j);
/* Whether some subsystem has exactly two active modes in a (a 2-mode sliding mode). */
int fesd__any_two_modes(const fesd__model *m, const unsigned char *a);
/* How many subsystems have exactly two active modes in a. */
int fesd__count_two_modes(const fesd__model *m, const unsigned char *a);
/* The active mode of subsystem k when exactly one is active in a, else -1. */
static inline int fesd__one_mode(const fesd__model *m, const unsigned char *a, int k) {
  int j = -1, cnt = 0;
  for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++)
    if (a[l]) j = l, cnt++;
  return cnt == 1 ? j : -1;
}
/* y += a f_i (y dense, nx) */
void fesd__F_axpy(const fesd__model *m, const fesd__point_eval *pe, int i, double a, double *y);
/* g = v - sum_i theta_i F_i at the evaluated point: the residual of a stage equation (the step
 * system's V rows, the guess's stage Newton, the certified start solve). */
static inline void fesd__stage_residual(const fesd__model *m, const fesd__point_eval *pe, const double *v,
                                        const double *th, double *g) {
  for (int r = 0; r < m->nx; r++) g[r] = v[r];
  for (int i = 0; i < m->nth; i++)
    if (th[i] != 0.0) fesd__F_axpy(m, pe, i, -th[i], g);
}
/* grad g_i . v (v dense, nx) */
double fesd__dg_dot(const fesd__model *m, const fesd__point_eval *pe, int i, const double *v);
/* y += a grad g_i (y dense, nx) */
void fesd__dg_axpy(const fesd__model *m, const fesd__point_eval *pe, int i, double a, double *y);
/* J = sum_i theta_i df_i/dx on the union pattern (pf_nnz values) */
void fesd__Jth(const fesd__model *m, const fesd__point_eval *pe, const double *theta, double *J);
/* y = J v for J on the union pattern (y dense, nx, overwritten) */
void fesd__pf_mv(const fesd__model *m, const double *J, const double *v, double *y);

#endif
