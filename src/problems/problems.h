/* Reference problems (from the FESD paper: its examples, Sec. 4 and 5), with
 * exact solutions where known. Used by the CLI, the demo, tests and benchmarks;
 * not part of the installed library. */
#ifndef FESD_PROBLEMS_H
#define FESD_PROBLEMS_H

#include "fesd_integrator.h"
#include "fesd_ocp.h"

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

/* ocp-dynamics: time at which the trajectory reaches c2 = 0 (bisection). */
double fesd_problem_ocp_t1(void);

/* slide-exit-2d: exit time and exit value of x2, computed independently of the integrator
 * (bisection on the sliding multiplier, composite Simpson for the time). */
void fesd_problem_slide_exit_point(double *t_exit, double *x2_exit);

/* Stewart-Anitescu problem (paper Sec. 5.3): exact V(x0) = int_0^2 x^2 dt +
 * (x(2) - 5/3)^2 and dV/dx0; the value and gradient from an integrator created with
 * settings.sensitivities = 1 on the "stewart-anitescu" model (nsim steps over [0, 2]);
 * and a secant shooting on dV/dx0 from x_start. */
double fesd_sa_exact_value(double x0, double *dV);
int fesd_sa_value(fesd_integrator *it, double x0, int nsim, double *V, double *dV);
int fesd_sa_shoot(fesd_integrator *it, double x_start, int nsim, double *x_opt, int *iters);

/* stick-slip (stick_slip.c): friction oscillator on a belt, periodic stick-slip cycle from
 * x0 = (0, 1): stuck until t = 2, then slip phases of tau_slip and stick phases, period P. */
typedef struct {
  double tau_slip, x_stick, period, t_first_exit;
} fesd_stick_slip_cycle;
fesd_stick_slip_cycle fesd_stick_slip_reference(void);
int fesd_stick_slip_exact(double t, double *x);
int fesd_stick_slip_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user);
int fesd_stick_slip_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                              void *user);
int fesd_stick_slip_sw(int sys, double t, const double *x, const double *u, double *c, void *user);
int fesd_stick_slip_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user);

/* ocp_step_eq (paper Sec. 6.3, ocp_step_eq.c): the OCP on the "ocp-dynamics" model (pass
 * its model: the problem keeps the pointer), N_ctrl = 6; target q_final = (-pi/6, -pi/4). */
void fesd_ocp_step_eq(fesd_ocp_problem *p, const fesd_model *model);
const double *fesd_ocp_step_eq_target(void);
/* Control guess (u = (-1, -1) in the first half of the intervals, then 0): zero controls leave
 * the iterates at the origin, where the sensitivities of q vanish (a local minimum). */
void fesd_ocp_step_eq_guess(double *u, int n_ctrl);
/* High-accuracy re-simulation with piecewise constant controls u (n_ctrl x 2) over [0, T]: FESD
 * Radau IIA s = 4, nsub steps per interval (40: converged to ~1e-13); x(T) into xT. */
int fesd_ocp_step_eq_resimulate(const fesd_model *model, const double *x0, const double *u, int n_ctrl, double T,
                                int nsub, double *xT);
/* E(T) = ||q(T) - q_final||_2 */
double fesd_ocp_step_eq_error(const double *xT);

#endif
