/* Internal: step strategy (step.c). */
#ifndef FESD_STEP_H
#define FESD_STEP_H
#include "fesd/integrator.h"
/* Advance by T (recursively halving on failure up to settings.max_splits). */
int fesd__substep(fesd_integrator *it, const double *u, double T, int depth, fesd_step_info *info);
/* Max sparse cross-complementarity product of z. */
double fesd__cc_max(const fesd__system *S, const double *z);
/* lambda00 = g(x) - min g per subsystem (and d/d(x,u) into sys.lam00_dp when deriv). */
int fesd__update_lambda00(fesd_integrator *it, const double *x, const double *u, int deriv);
/* A sign violation of a fixed active set (active.c). */
typedef struct {
  int found;
  double t;     /* predicted switch time (relative to the step start) */
  int mode;     /* stacked mode index */
  int sys;
  int enter;    /* 1: an inactive mode's lambda went negative; 0: an active theta did */
  int element;  /* element where it was detected */
  int stage;    /* stage index n*s + j of the violating point (n*s + s: element end) */
} fesd__violation;

/* active.c */
void fesd__act_from_theta(const fesd_integrator *it, const double *theta, unsigned char *a);
int fesd__act_start(fesd_integrator *it, const double *u, unsigned char *a);
void fesd__impose_active(fesd_integrator *it, double *z, const unsigned char *act);
int fesd__rows_active(fesd_integrator *it, const unsigned char *act, const int *bmode,
                      const int *exit_mode);
int fesd__find_violation(fesd_integrator *it, const double *z, const unsigned char *act,
                         int strict, fesd__violation *v);
/* FESD_ERR_STEP_FAILED if the collocation polynomial enters a region between stage points. */
int fesd__interior_check(fesd_integrator *it, const double *z);
/* guess.c */
int fesd__initial_guess(fesd_integrator *it, const double *u, double T, double *z);
int fesd__consistent_guess(fesd_integrator *it, double *z);
void fesd__fill_element(fesd_integrator *it, double *z, int n, const double *block);
/* predict.c (FB fallback path) */
int fesd__predict_switches(fesd_integrator *it, const double *z, double T, double *tc, int max_c);
int fesd__resort_guess(fesd_integrator *it, const double *zsrc, double T, const double *tc, int nc,
                       int *sw_at, double *z);
/* step.c */
int fesd__valid(fesd_integrator *it, const double *z, double *ccm);
/* accept.c */
int fesd__accept(fesd_integrator *it, const double *z, const double *u, double T);
#endif
