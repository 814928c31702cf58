/* Internal: validated copy of a user model, sign matrices, and evaluation of
 * the stacked fields F (nx x n_theta), indicators g (n_theta) and their
 * Jacobians at one point, with central finite differences when the user gives
 * no Jacobian callback. */
#ifndef FESD_MODEL_H
#define FESD_MODEL_H

#include "fesd_integrator.h"

typedef struct {
  int nx, nu, nsys, nth; /* nth = sum of modes */
  int *nf, *nc;          /* per subsystem */
  int *th_off;           /* first stacked mode of subsystem k (nsys + 1 entries) */
  int *sys_of;           /* subsystem of stacked mode i */
  signed char **S;       /* per subsystem nf x nc (NULL when nc == 0) */
  int max_rows;          /* max over k of (nc_k or nf_k): rows of one switch callback */
  fesd_model user;       /* callbacks and user pointer (array fields not used) */
  /* scratch */
  double *xp, *cbuf, *cbuf2, *dcbuf, *dcubuf, *fbuf, *fbuf2, *up, *jxbuf;
  const char *failed;    /* name of the callback that failed last */
} fesd__model;

/* Output of one evaluation; NULL members are not computed. Column-major. */
typedef struct {
  double *F;     /* nx x nth: column i = f_i */
  double *g;     /* nth */
  double *dFdx;  /* nth blocks of nx x nx */
  double *dgdx;  /* nth x nx */
  double *dFdu;  /* nth blocks of nx x nu */
  double *dgdu;  /* nth x nu */
} fesd__point_eval;

int fesd__model_init(fesd__model *m, const fesd_model *user);
void fesd__model_free(fesd__model *m);
/* Evaluate at x (u may be NULL when nu == 0). Returns FESD_OK, FESD_ERR_CALLBACK or
 * FESD_ERR_NONFINITE (m->failed names the callback). */
int fesd__model_eval(fesd__model *m, const double *x, const double *u, fesd__point_eval *out);
/* Only g at x. */
int fesd__model_g(fesd__model *m, const double *x, const double *u, double *g);

#endif
