/* Internal: the model the integrator solves, built from the user's (wrap.c). It adds what the
 * user describes apart from the modes:
 *  - time as a state (time_dependent): x_int = (x, t), t' = 1, so that element lengths see the
 *    time dependence of the fields and indicators (their t-derivatives by central differences);
 *  - the drift f0(t, x, u) shared by all modes: a subsystem of one mode (theta = 1), evaluated
 *    once per point;
 *  - stop conditions r(t, x, u): one subsystem of two modes with zero fields per root, so that a
 *    root is located on an element boundary exactly like a switch.
 * Internal subsystems: [user's nsys][drift (when drift or time)][n_roots roots]. Without any of
 * these the internal model is the user's (no wrapper). */
#ifndef FESD_WRAP_H
#define FESD_WRAP_H

#include "fesd_integrator.h"

typedef struct {
  fesd_model user;
  int active;         /* 0: the internal model is the user's */
  int nx, nxi, td;    /* user states, internal states, time as state */
  int K, kd, kr, nr;  /* user subsystems, drift subsystem (-1: none), first root, roots */
  int sparse;
  int *n_modes, *n_switch;
  const signed char **sign;
  fesd_sparsity *sp;
  int **ia; /* per internal subsystem: rows, jac rows/cols, sw rows/cols (5 arrays each) */
  double *xb, *fb, *fb2, *jb, *rb, *rb2, *ub;
} fesd__wrap;

/* Build the internal model (callbacks of wrap.c, user pointer w) or copy the user's. */
int fesd__wrap_init(fesd__wrap *w, const fesd_model *user, fesd_model *internal);
void fesd__wrap_free(fesd__wrap *w);

#endif
