/* Reference problems of ../shared/DESIGN.md section 5 (from the FESD paper), with
 * exact solutions where known. Used by the CLI, the demo, tests and benchmarks;
 * not part of the installed library. */
#ifndef FESD_PROBLEMS_H
#define FESD_PROBLEMS_H

#include "fesd_integrator.h"

#define FESD_PROBLEM_MAX_NX 8
#define FESD_PROBLEM_MAX_NU 4

typedef struct {
  const char *name;
  const char *description;
  fesd_model model;
  double x0[FESD_PROBLEM_MAX_NX];
  double u[FESD_PROBLEM_MAX_NU];
  double T;           /* default horizon */
  double t_switch;    /* first switch time (NaN if none or unknown) */
  /* exact solution at time t (x0 as above); NULL if not known in closed form */
  int (*exact)(double t, double *x);
} fesd_problem;

/* Fill p for a problem name; returns FESD_ERR_INVALID_ARG for an unknown name. */
int fesd_problem_get(const char *name, fesd_problem *p);
/* NULL-terminated list of names. */
const char *const *fesd_problem_names(void);

/* Oscillator exact solution from x(0) = (e^-1, 0). */
int fesd_problem_oscillator_exact(double t, double *x);

#endif
