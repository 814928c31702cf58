/* Internal: the step strategy (step.c), standard time-stepping (step_std.c), the switch plan of
 * a step (plan.c), the checks of a converged step (verify.c), initial guesses (guess.c), the FB
 * fallback's predictor (predict.c), acceptance (accept.c). Row weights: system.h, weights.c. */
#ifndef FESD_STEP_H
#define FESD_STEP_H
#include "fesd/integrator.h"

/* Advance by T (sub-steps at planned switches, recursive halving on failure up to
 * settings.max_splits). */
int fesd__substep(fesd_integrator *it, const double *u, double T, int depth, fesd_step_info *info);
/* lambda00 = g(x) - min g per subsystem (and d/d(x,u) into sys.lam00_dp when deriv). */
/* lambda00 at x (and its derivatives with deriv): from rec when it is an evaluation at
 * (it->t, x) of this step, else evaluated. */
int fesd__update_lambda00(fesd_integrator *it, const double *x, const double *u, int deriv,
                          const fesd__point_eval *rec);
/* Shared by the solve paths (step.c, step_std.c): a callback failure, NaN/Inf or no memory (no
 * other path can succeed); the solve with the per-stage active sets it->act from z; the solve
 * with the start's active set everywhere from the warm start; the standard method's step. */
int fesd__hard_failure(int st);
int fesd__fixed_solve(fesd_integrator *it, double *z, int max_iter, int slow_iter, fesd_step_info *info);
int fesd__start_solve(fesd_integrator *it, fesd_step_info *info);
int fesd__std_path(fesd_integrator *it, fesd_step_info *info);

/* ---- active.c ---- */
void fesd__act_from_theta(const fesd_integrator *it, const double *theta, unsigned char *a);
/* Active set at the step start; *nonunique set when x0 lies on a surface that the fields on
 * both sides leave (several Filippov solutions). */
int fesd__act_start(fesd_integrator *it, const double *u, unsigned char *a, int *nonunique);
/* Whether mode l of subsystem k keeps itself the strict minimum of g among the candidate modes
 * cand of k along the total field f (in which l stands alone for k): d/dt (g_c - g_l) > 0 for
 * every other candidate c, at an evaluated point (a start on a surface, a corner). */
int fesd__keeps_alone(const fesd__model *m, const fesd__point_eval *pe, int k, const unsigned char *cand, int l,
                      const double *f);
int fesd__impose_active(fesd_integrator *it, double *z, const unsigned char *act); /* 1: theta changed */
/* Border flags of the current layout and rows for the solver (fesd_ncp_set_border). */
int fesd__set_border(fesd_integrator *it);
int fesd__rows_active(fesd_integrator *it, const unsigned char *act, const int *bmode,
                      const int *exit_mode);
/* Total field F theta at an evaluated point (f: nx, dense). */
void fesd__total_field(fesd_integrator *it, const fesd__point_eval *pe, const double *th, double *f);
/* Normal components d/dt (g_i - g_j) along the total field with mode i alone and with mode j
 * alone in its subsystem (the other subsystems at theta) at an evaluated point; ftot: the total
 * field at theta (fesd__total_field). */
void fesd__normal_components(fesd_integrator *it, const fesd__point_eval *pe, const double *theta,
                             const double *ftot, int i, int j, double *ai, double *aj);

/* ---- verify.c ---- */
/* Max sparse cross-complementarity product of z (weighted: units of the row scaling). */
double fesd__cc_max(const fesd__system *S, const double *z);
/* Earliest violation of the active sets act (N*s blocks) in z over all subsystems (v) and, when
 * per_sys is non-NULL, the earliest of each subsystem (nsys entries). strict (standard method):
 * every stage is checked. Implicit methods are also checked between the stage points (the
 * region of the collocation polynomial or interpolant, and Filippov's conditions of 2-mode
 * sliding modes) and at the switch points. Returns FESD_OK or a callback status. */
int fesd__scan(fesd_integrator *it, const double *z, const unsigned char *act, int strict,
               fesd__violation *v, fesd__violation *per_sys);
/* A converged FESD solution passes: h > 0, cross complementarity, and the scan of its own
 * active sets (theta > active_tol) finds nothing. FESD_ERR_STEP_FAILED otherwise. */
int fesd__verify(fesd_integrator *it, const double *z, double *ccm);
/* Record violation c of a subsystem in v if it is earlier than the one held. */
static inline void fesd__note_violation(fesd__violation *v, const fesd__violation *c) {
  if (!v->found || c->t < v->t) *v = *c;
}
/* Filippov's conditions of the 2-mode sliding of subsystem k with modes i, j at an evaluated
 * point (relative tolerance rel): the mode whose field clearly points into its own region, -1
 * for both (repulsive), -2 for none (a sliding mode). */
int fesd__filippov(fesd_integrator *it, const fesd__point_eval *pe, const double *th, const double *ftot, int i,
                   int j, double rel);
/* The normal components of a 2-mode sliding mode divided by the sum of their sizes, signed so
 * that both are >= 0 while Filippov's conditions hold: mi = a_i / d, mj = -a_j / d,
 * d = |a_i| + |a_j| (NaN when d = 0). The margin of the sliding mode is the smaller. */
void fesd__sliding_margins(fesd_integrator *it, const fesd__point_eval *pe, const double *th, const double *ftot,
                           int i, int j, double *mi, double *mj);
/* Whether a co-dimension-2 sliding mode has a consistent alternative for subsystem k. */
int fesd__alternative_exists(fesd_integrator *it, const fesd__point_eval *pe, const unsigned char *a, int k, int i,
                             int j);

/* ---- verify_between.c ---- */
/* Filippov's conditions at the element boundaries where a subsystem crosses or leaves a
 * sliding mode (the new field must leave the surface), and between the stage points. */
int fesd__scan_switch_points(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps);
/* A start within round-off of a surface that its field reaches at once: an entry at that time. */
int fesd__scan_start(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps);
int fesd__scan_interior(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps);
/* Implicit Euler (one stage, c = 1; the caller checks): an excursion into another mode's region
 * between the two ends of an element (cubic Hermite interpolant of the distance to the surface
 * and its rate). */
int fesd__scan_hermite(fesd_integrator *it, const double *z, const unsigned char *act, fesd__violation *ps);
/* Whether subsystem k's 2-mode sliding in the sets a holds Filippov's conditions at time t of z. */
int fesd__sliding_stands(fesd_integrator *it, const double *z, double t, const unsigned char *a, int k, int *out);
/* Interpolant of element n of z at the weights w (collocation polynomial, fesd__colloc_weights,
 * or the interior-check weights of Lobatto IIIC). */
void fesd__poly_state(const fesd_integrator *it, const double *z, int n, const double *w, double *x);
/* State of z at time t from the step start (collocation polynomial, or piecewise linear
 * through the stage states for the other families). */
void fesd__state_at(fesd_integrator *it, const double *z, int N, double t, double *x);

/* ---- stage_newton.c ---- */
/* Stage equations of element n (theta fixed) by Newton from the stages in z: 0 when solved to
 * round-off (z updated), 1 otherwise (z unchanged). */
int fesd__stage_newton(fesd_integrator *it, double *z, int n, const double *xn, double h, double tn);

/* ---- guess.c ---- */
int fesd__initial_guess(fesd_integrator *it, const double *u, double T, double *z);
int fesd__consistent_guess(fesd_integrator *it, double *z);
void fesd__fill_element(fesd_integrator *it, double *z, int n, const double *block);
/* theta of a stage for the active flags a at the evaluated point pe: the indicator of a single
 * mode, Filippov's multiplier for a 2-mode sliding mode, else uniform weights. */
void fesd__stage_theta(fesd_integrator *it, const fesd__point_eval *pe, const unsigned char *a, double *th);
/* Guess for the current layout (it->act, h in z) from a solution zp on Np elements: states
 * from zp's polynomials at the new stage times, theta from the new active sets (sliding:
 * Filippov's multiplier at the state), lambda and mu from the indicators. */
int fesd__regrid_guess(fesd_integrator *it, const double *zp, int Np, double *z);

/* ---- predict.c (FB fallback path; entry times of the plan path) ---- */
int fesd__predict_switches(fesd_integrator *it, const double *z, double T, double *tc, int max_c);
/* Plan path: the time at which mode v->mode enters, the first zero of its lambda against the
 * set P of its subsystem on the collocation polynomial of z inside the scan's bracket
 * (v->lo, v->hi); *t unchanged when the polynomial shows no sign change there. */
int fesd__refine_entry(fesd_integrator *it, const double *z, const fesd__violation *v, const unsigned char *P,
                       double *t);
int fesd__resort_guess(fesd_integrator *it, const double *zsrc, double T, const double *tc, int nc,
                       int *sw_at, double *z);

/* ---- plan.c ---- */
/* Forget the plan (a step without switches). */
void fesd__plan_reset(fesd_integrator *it);
/* The plan sorted by time; switch e removed (plan.c). */
void fesd__plan_sort(fesd_integrator *it);
/* The active set after switch e of the plan (all subsystems). */
static inline unsigned char *fesd__plan_after(fesd_integrator *it, int e) {
  return it->plan_after + (size_t)e * it->nth;
}
void fesd__plan_remove(fesd_integrator *it, int e);
/* Element layout of the plan for a (sub)step of length T: boundaries, element count (a level of
 * the ladder), per-stage active sets, boundary rows and element lengths (written into z).
 * FESD_ERR_TOO_MANY_SWITCHES when the plan needs more than max_elements. */
int fesd__plan_layout(fesd_integrator *it, double T, double *z);
/* After a converged solve: switch times from the solved element lengths. */
void fesd__plan_times(fesd_integrator *it, const double *z);
/* Change the plan for the violations of a scan (per subsystem). Returns 1 if it changed,
 * 0 if nothing can be changed (the caller gives up), or a negative status. */
int fesd__plan_update(fesd_integrator *it, const double *z, const fesd__violation *per_sys);
/* A plan whose solve failed after an update that added several switches keeps the earlier
 * half of them (the later ones were predicted from a trajectory that the earlier ones change).
 * Returns 1 if it changed the plan, 0 if there is nothing to take back. */
int fesd__plan_retreat(fesd_integrator *it);
/* A failed plan solve whose first element sits at its length's floor: the entries on the first
 * boundary move to the step start. Returns 1 when the plan changed. */
int fesd__plan_start_fallback(fesd_integrator *it, const double *z);
/* A hash of the plan's switches in time order (subsystem, mode, kind, time), to detect cycles. */
unsigned long fesd__plan_signature(fesd_integrator *it);
/* Number of distinct subsystems that switch in the plan. */
int fesd__plan_subsystems(const fesd_integrator *it);
/* Midway between the earliest fresh switch and the next switch (or T). */
double fesd__plan_cut_after_fresh(fesd_integrator *it);
/* Keep only the switches before t (a shorter sub-step). */
void fesd__plan_truncate(fesd_integrator *it, double t);
/* Time before which at most n_max switches of the plan lie (the end of a sub-step that holds
 * them): midway in the last gap between switch q and the next (q <= n_max) that is not much
 * narrower than the widest one (T when there are no more). */
double fesd__plan_cut(fesd_integrator *it, int n_max);

/* ---- error.c ---- */
/* Embedded weights of the method (err_ok = 0: no estimate, explicit RK). */
int fesd__error_setup(fesd_integrator *it);
/* Local error estimate of the solution z of the current layout: weighted RMS norm of the
 * embedded difference with weights 1 / (atol_r + rtol max|x|), max over the elements. */
int fesd__error_estimate(fesd_integrator *it, const double *z, double rtol, const double *atol, double *err);
/* The time error of the step's pinned sliding exits and of a sliding mode that failed at the
 * step end, from Filippov's conditions there, as a state error (the motion in that time) in the
 * units of fesd__error_estimate. */
int fesd__exit_error(fesd_integrator *it, const double *z, double rtol, const double *atol, double *err);
/* For the estimate of a sliding element n of Gauss-Legendre (graze.c): acc = sum_j e_j (the field
 * with Filippov's multipliers at stage state j); *on = 0 when no subsystem slides there. */
int fesd__consistent_stages(fesd_integrator *it, const double *z, int n, double tn, double h, double *acc,
                            int *on);
/* Whether subsystem k's sliding on modes i, j holds at the end of z's last element after mode
 * `leave` falls below active_tol there: the other mode's Filippov margin above what the user's
 * tolerances make of it (under error control). */
int fesd__still_slides(fesd_integrator *it, const double *z, int i, int j, int leave, int *slides);
/* theta at or below this is the solves' round-off (a pinned exit's theta = 0 is solved to
 * newton_tol: it came out 1e-17 positive at a step end) */
static inline double fesd__theta_floor(const fesd_integrator *it) { return 64.0 * it->newton_tol; }
/* FESD_FLAG_COARSE for the solution it->z of a fixed step: the estimate against coarse_tol, or
 * an element that outgrew its field (L-stable damping of a growing mode). */
int fesd__coarse_check(fesd_integrator *it, fesd_step_info *info);

/* ---- accept.c ---- */
int fesd__accept(fesd_integrator *it, const double *z, const double *u, double T);
/* Element records for need elements (create: one largest layout; more only for a step with
 * sub-steps or halvings beyond that). */
int fesd__grow_records(fesd_integrator *it, int need);

#endif
