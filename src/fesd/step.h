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
#endif
