/**
 * @file fesd_integrator.h
 * @brief The FESD integrator (and the standard time-stepping method) for
 *        piecewise-smooth ODEs in Filippov's sense (src/fesd).
 *
 * Model. x' = sum_k F^k(x,u) theta^k with one Stewart DCS per subsystem k
 * (paper Sec. 2.2 and 2.3): F^k = [f_{k,0} ... f_{k,nf_k-1}] are the mode fields,
 * regions are given by switching functions c^k(x,u) in R^{nc_k} with a sign matrix
 * S^k (Stewart indicators g^k = -S^k c^k, Proposition 1) or directly by indicators
 * g^k(x,u) in R^{nf_k}. Mode i of subsystem k is active in the region where row i of
 * S^k matches the signs of c^k: with the default full sign matrix, row i has entry
 * S[i][j] = -1 if bit (nc-1-j) of i is set, else +1 (row 0 = all c_j > 0, last row =
 * all c_j < 0). Mode i is the i-th field (field(sys, i, ...)), the i-th row of the sign
 * matrix and the i-th entry of theta/lambda of that subsystem.
 *
 * nosnoc users: nosnoc's S matrix of a subsystem (one row per mode, one column per switching
 * function, entries +-1, modes in its order of F) is passed unchanged as sign[k] (row-major,
 * n_modes x n_switch), with field(sys, i, ...) returning nosnoc's i-th column of F.
 *
 * Every mode field is evaluated at every stage point, also outside its region (a Runge-Kutta
 * stage of a sliding or nearly switching element lies on either side of the surface): fields
 * and switching functions must be defined, finite and smooth across the surfaces (smooth
 * extensions of each mode's field, not a field that returns an error or jumps outside its
 * region).
 *
 * Units: t, T, h in the model's time unit. Tolerances of the step solver are relative to the
 * size of the quantities each equation compares (docs/solver.md, "Row weights"); those of
 * fesd_integrate are rtol/atol on the state (fesd_tolerances).
 */
#ifndef FESD_INTEGRATOR_H
#define FESD_INTEGRATOR_H

#include "fesd_ncp.h"
#include "fesd_rk.h"
#include "fesd_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- model callbacks: return 0 on success, nonzero on failure (the step fails with
 *      FESD_ERR_CALLBACK naming the callback and the time). A callback must write every
 *      output entry it is given: an entry left unwritten also gives FESD_ERR_CALLBACK
 *      (outputs are filled with a marker NaN before each call); a NaN or Inf it writes
 *      gives FESD_ERR_NONFINITE. ---- */

/** Mode field f_{sys,mode}(t,x,u): write nx values to f. t is the time of the point (see
 *  fesd_model.time_dependent). */
typedef int (*fesd_field_fn)(int sys, int mode, double t, const double *x, const double *u, double *f,
                             void *user);
/** Jacobians of f_{sys,mode}: dfdx (nx x nx, column-major), dfdu (nx x nu, column-major;
 *  NULL when nu == 0). */
typedef int (*fesd_field_jac_fn)(int sys, int mode, double t, const double *x, const double *u,
                                 double *dfdx, double *dfdu, void *user);
/** Switching functions c^sys(x,u) (n_switch[sys] values), or indicators g^sys
 *  (n_modes[sys] values) when n_switch[sys] == 0. */
typedef int (*fesd_switch_fn)(int sys, double t, const double *x, const double *u, double *c, void *user);
/** Jacobians of the switch callback: dcdx (rows x nx, column-major like dfdx: entry (r, c) at
 *  dcdx[c * rows + r]; rows = n_switch[sys], or n_modes[sys] with indicators), dcdu (rows x nu,
 *  column-major; NULL when nu == 0). */
typedef int (*fesd_switch_jac_fn)(int sys, double t, const double *x, const double *u, double *dcdx,
                                  double *dcdu, void *user);

/** Drift f0(t,x,u): the part of x' shared by all modes (x' = f0 + sum_k F^k theta^k); writes
 *  nx values (or n_rows values of model.drift_sparsity). */
typedef int (*fesd_drift_fn)(double t, const double *x, const double *u, double *f0, void *user);
/** Jacobians of the drift (layouts as fesd_field_jac_fn). */
typedef int (*fesd_drift_jac_fn)(double t, const double *x, const double *u, double *dfdx, double *dfdu,
                                 void *user);
/** Stop conditions r(t,x,u): write model.n_roots values. An integration stops where one crosses
 *  zero in its direction (fesd_integrate). */
typedef int (*fesd_root_fn)(double t, const double *x, const double *u, double *r, void *user);

/**
 * Optional sparsity of one subsystem, for large n_x (all indices 0-based). With it the
 * callbacks of that subsystem work on compressed data:
 *  - field() writes n_rows values: the entries rows[0..n_rows-1] of f (all other entries of
 *    f are zero);
 *  - field_jac() writes jac_nnz values of df/dx at (rows[jac_row[e]], jac_col[e]) and
 *    dfdu as an n_rows x nu column-major block;
 *  - sw_jac() writes sw_nnz values of dc/dx (dg/dx when n_switch == 0) at
 *    (sw_row[e], sw_col[e]) and dcdu as a dense (rows x nu) block.
 * Patterns are unions over the modes of the subsystem. Jacobian callbacks are required
 * (no finite differences for sparse models). The step system is then sparse and its cost
 * grows with the number of nonzeros instead of n_x^2.
 */
typedef struct {
  int n_rows;
  const int *rows;     /**< ascending state indices */
  int jac_nnz;
  const int *jac_row;  /**< index into rows */
  const int *jac_col;  /**< state index */
  int sw_nnz;
  const int *sw_row;   /**< switching-function (or indicator) index */
  const int *sw_col;   /**< state index */
} fesd_sparsity;

/** Model description. Arrays are copied by fesd_create(). */
typedef struct {
  int nx;                 /**< states (>= 1) */
  int nu;                 /**< controls/parameters held constant over a step (>= 0) */
  int nsys;               /**< independent subsystems (>= 1) */
  const int *n_modes;     /**< [nsys] modes per subsystem (>= 2) */
  const int *n_switch;    /**< [nsys] switching functions per subsystem; 0 = indicators given
                               directly; NULL = all 0 */
  const signed char *const *sign; /**< [nsys] sign matrices (n_modes x n_switch, row-major,
                               entries +-1, no repeated rows); NULL or a NULL entry = full
                               enumeration (needs n_modes == 2^n_switch) */
  fesd_field_fn field;          /**< required */
  fesd_field_jac_fn field_jac;  /**< optional: NULL = central finite differences */
  fesd_switch_fn sw;            /**< required */
  fesd_switch_jac_fn sw_jac;    /**< optional: NULL = central finite differences */
  void *user;                   /**< passed to every callback */
  const fesd_sparsity *sparsity; /**< [nsys] optional (NULL = dense callbacks) */
  int time_dependent;           /**< 0: the callbacks do not depend on t (they still receive it);
                                     1: they do: t is then carried as an internal state so that
                                     the element lengths see it (d/dt by central differences) */
  fesd_drift_fn drift;          /**< optional smooth part shared by all modes, evaluated once per
                                     point instead of once per mode (NULL: none) */
  fesd_drift_jac_fn drift_jac;  /**< optional (NULL: central differences; required with
                                     sparsity) */
  const fesd_sparsity *drift_sparsity; /**< rows and df0/dx pattern of the drift (sparse models;
                                     sw_* ignored); NULL: dense */
  int n_roots;                  /**< stop conditions (>= 0) */
  fesd_root_fn roots;           /**< required when n_roots > 0 */
  const int *root_dir;          /**< [n_roots]: +1 stop when r_i increases through 0, -1 when it
                                     decreases, 0 both (NULL: all 0) */
} fesd_model;

typedef enum {
  FESD_METHOD_FESD = 0,    /**< finite elements with switch detection (variable h_n) */
  FESD_METHOD_STANDARD = 1 /**< standard time-stepping (h_n = T/N_FE fixed) */
} fesd_method;

/** Integrator settings; fesd_settings_default() fills the documented defaults. fesd_create()
 *  refuses a value outside its range [lo, hi] with FESD_ERR_INVALID_ARG (NaN is outside every
 *  range); an unknown family or stage count gives FESD_ERR_UNSUPPORTED_TABLEAU. */
typedef struct {
  fesd_method method;       /**< FESD_METHOD_FESD or FESD_METHOD_STANDARD (default FESD) */
  fesd_rk_family family;    /**< any family of fesd_rk.h (default Radau IIA) */
  int stages;               /**< s, as fesd_tableau_get() supports for the family (default 2) */
  int n_fe;                 /**< finite elements per step: [2, 1000] for FESD, [1, 1000] for
                                 the standard method (default 2) */
  double newton_tol;        /**< ||F||_inf tolerance of every step solve, [1e-16, 1e-3]
                                 (default 1e-12; a loose tolerance lets sum h miss T). Under
                                 error control (fesd_integrate*) a step's solves use
                                 min(newton_tol, max(1e-14, 0.1 min_r (atol_r + rtol |x_r|) /
                                 |x|_inf)): the estimate must not see the solve's noise */
  int max_iter_first;       /**< iterations of the first (equal-h) attempt, [1, 1000] (default 12) */
  int max_iter;             /**< iterations of the switch solves, [1, 1000] (default 40) */
  double cc_tol;            /**< tolerance on every cross-complementarity product
                                 theta_{n,m,i} lambda_{n,m',i} (units of g), (0, 1e-2]
                                 (default 1e-9) */
  double active_tol;        /**< theta_i > active_tol marks mode i active, (0, 0.1]
                                 (default 1e-6) */
  int exit_rows;            /**< 1: pin sliding exits (beyond the paper, docs/sliding_exit.md);
                                 0: the paper's formulation (default 1) */
  int max_splits;           /**< recursive halvings of a failed step, [0, 12] (default 6);
                                 under error control (fesd_integrate*) none: a failed step goes
                                 back to the step-size controller, which retries it shorter */
  int sensitivities;        /**< 1: propagate dx/dx0 and dx/du; 0: not (default 0) */
  int max_sweeps;           /**< fixed-point sweeps that make the initial guess of a step
                                 consistent, [1, 50] (default 8; they stop early when
                                 converged or slow, and cost no Jacobian) */
  double coarse_tol;        /**< a step whose local error estimate (relative, embedded, see
                                 docs/solver.md) exceeds this is flagged FESD_FLAG_COARSE, [0, 1]
                                 (default 1e-2; 0: no estimate) */
  int max_elements;         /**< most elements of one solve (FESD): a step that holds k
                                 switches gets max(n_fe, k + 1) elements (one boundary per
                                 switch); one that holds more than max_elements - 1 is solved
                                 in sub-steps that end between two switches. [2, 4096] (default
                                 8; at least n_fe is used). Each solve of a step with N elements
                                 costs about N^2 / 2 element solves in the sparse LU (the Schur
                                 complement on the element lengths), so larger values trade
                                 sub-steps for costlier solves (measured on a friction chain with
                                 many switches per step: 8 fastest of 4 .. 32) */
  fesd_ncp_settings ncp;    /**< linear algebra/line-search settings of the solver, ranges as
                                 in fesd_ncp.h; ncp.tol, ncp.max_iter, ncp.slow_iter and
                                 ncp.slow_ratio are ignored (the integrator sets them from
                                 newton_tol, max_iter_first, max_iter, and its own progress
                                 check of plan solves) */
} fesd_settings;

typedef enum {
  FESD_EVENT_CROSSING = 0,       /**< active set replaced (transversal crossing) */
  FESD_EVENT_SLIDING_ENTRY = 1,  /**< active set grows (reaching a sliding surface) */
  FESD_EVENT_SLIDING_EXIT = 2,   /**< active set shrinks (leaving a sliding surface) */
  FESD_EVENT_ROOT = 3            /**< a stop condition crosses zero (sys: its index; before/after:
                                      {1} -> {0} when it increases, {0} -> {1} when it decreases) */
} fesd_event_kind;

/** A detected switch at an element boundary: the set of active modes (theta_i >
 *  active_tol) of one subsystem changed. kind: after contains before: SLIDING_ENTRY; before
 *  contains after: SLIDING_EXIT; otherwise CROSSING. */
typedef struct {
  double t;              /**< time of the element boundary carrying the switch */
  int sys;               /**< subsystem */
  fesd_event_kind kind;
  int n_before, n_after; /**< number of active modes before / after */
  const int *before;     /**< the active modes before (indices within the subsystem, ascending) */
  const int *after;      /**< ... and after; both valid until the next fesd_step / fesd_set_state */
} fesd_event;

/** Flags of a step (fesd_step_info.flags, counted per flag in fesd_stats): the result was
 *  accepted, and this is what the user should know about it. */
#define FESD_FLAG_NONUNIQUE 0x1 /**< the step started on a switching surface that the fields on
                                     both sides leave: the Filippov solution is not unique (the one
                                     returned stays on the surface) */
#define FESD_FLAG_SENS_INACCURATE 0x2 /**< sensitivities on: the implicit-function system at the
                                     accepted solution is singular or badly conditioned, or its
                                     solve did not pass the residual check, or a complementarity
                                     pair is degenerate (theta = lambda = 0 at a stage: the map is
                                     not differentiable there); dx/dx0 and dx/du of this step are
                                     not to be trusted (the state is) */
#define FESD_FLAG_EXIT_NOT_PINNED 0x4 /**< a sliding exit was placed by a formulation that does
                                     not pin it (exit_rows = 0, explicit RK, or the FB fallback of
                                     Gauss-Legendre): its time is not determined by the equations
                                     and does not converge with h (docs/sliding_exit.md) */
#define FESD_FLAG_COARSE 0x8    /**< the step's local error estimate exceeds its tolerance
                                     (settings.coarse_tol, relative), or (stiffly accurate
                                     families) an element is longer than twice the time in which
                                     the field expands along its increment, where an L-stable
                                     method damps a growing mode and its estimate with it: the
                                     step is too long for the accuracy of the solution */
#define FESD_FLAG_AMBIGUOUS 0x10 /**< a subsystem ran along one of its surfaces in one mode, its
                                     side decided below the resolution of the sign checks, while
                                     the other side's field would have moved the state by more
                                     than the tolerances: the state may be off (e.g. just past a
                                     Zeno accumulation); or the step's events hold two switches of
                                     one subsystem less than 1e-9 max(1, |t|) apart (a phase of
                                     zero length, e.g. exit, re-entry, exit at one instant): their
                                     order is not resolved; or (fixed steps) the discrete solution
                                     dipped into another mode's region between check points where
                                     no entry could be solved, and the step was taken without that
                                     dip (the flow may only come close to the surface there) */

/** Statistics of one fesd_step() (accumulated over sub-steps when it splits). */
typedef struct {
  int status;           /**< FESD_OK or a negative fesd_status */
  int newton_iter;      /**< Newton iterations of all solves of the step */
  int factorizations;
  int solves;           /**< calls of the NCP solver */
  int homotopy_stages;
  int splits;           /**< sub-steps added by recovery: halvings of a failed (sub)step */
  int substeps;         /**< sub-steps added because the step held more switches than
                             settings.max_elements - 1 */
  int flags;            /**< FESD_FLAG_* bits */
  int switch_step;      /**< 1 if the accepted solution needed a switch solve */
  int fallback;         /**< sub-steps solved by the FB fallback path (active-set path failed) */
  double residual;      /**< final ||F||_inf of the accepted system */
  double cc_max;        /**< max cross-complementarity product of the accepted solution */
  double error_estimate; /**< local error estimate of the step (relative; embedded estimate,
                              max over elements; 0 when not computed) */
  double time;          /**< wall-clock seconds of the step */
  const char *failed_callback; /**< on FESD_ERR_CALLBACK/NONFINITE: "field", "switch",
                                    "field_jac" or "switch_jac" */
  double failed_time;   /**< on failure: start time of the sub-step that failed */
  const char *failed_path; /**< on failure: what failed last ("plan": the smooth solves with
                                fixed active sets, then the FB fallback "fb"; "standard",
                                "accept", "callback", "step"); NULL on success */
  double failed_residual;  /**< on failure: residual (relative, as newton_tol) of the last failed
                                solve */
  double min_substep;      /**< shortest (sub)step length tried in this step (halvings and
                                sub-steps; T when none) */
  double last_time;        /**< end time of the last accepted sub-step (the step end on success;
                                on failure the state is still rolled back to the step start) */
} fesd_step_info;

typedef struct fesd_integrator fesd_integrator; /**< opaque */

/** @brief Defaults: FESD, Radau IIA s = 2, N_FE = 2, tolerances above. */
FESD_API int fesd_settings_default(fesd_settings *s);

/**
 * @brief Validate the model and settings, build sign matrices and the step system,
 *        allocate the workspaces (steps allocate only for what they meet first: a layout of more
 *        elements, a sparse pattern the solver has not analysed, longer records, the event log).
 * @return FESD_OK, FESD_ERR_NULL, FESD_ERR_MODEL, FESD_ERR_SIGN_MATRIX, FESD_ERR_DIMENSION,
 *         FESD_ERR_UNSUPPORTED_TABLEAU, FESD_ERR_INVALID_ARG, FESD_ERR_NOMEM.
 */
FESD_API int fesd_create(fesd_integrator **it, const fesd_model *model,
                         const fesd_settings *settings);
/** @brief Free and set *it = NULL (accepts NULL). */
FESD_API void fesd_free(fesd_integrator **it);

/** @brief Set the current time and state; resets sensitivities to identity/zero and
 *         computes lambda_{0,0} = g(x0) - min g(x0). u is used to evaluate g.
 *         FESD_ERR_MODEL when model.time_dependent = 0 but the switching functions, stop
 *         conditions or fields at x0 change with t (compared at t0 and a later time). */
FESD_API int fesd_set_state(fesd_integrator *it, double t0, const double *x0, const double *u);

/**
 * @brief Advance one integration step of length T with control u (N_FE elements),
 *        warm started from the previous step. info may be NULL (no statistics wanted).
 *        On failure the state is unchanged
 *        (the caller may retry with other settings). FESD_ERR_NOMEM: an allocation of the
 *        sparse linear solvers (pattern analyses, factorizations) failed during the step,
 *        also when another path could have finished it (its result would differ from the
 *        one of a clean run); a retry repeats the step.
 */
FESD_API int fesd_step(fesd_integrator *it, const double *u, double T, fesd_step_info *info);

/** @brief Current time and state (x: nx values; either pointer may be NULL). */
FESD_API int fesd_get_state(const fesd_integrator *it, double *t, double *x);

/** @brief Sensitivities of the current state w.r.t. the state given to fesd_set_state
 *         (Sx: nx x nx) and w.r.t. u (Su: nx x nu, u constant since set_state), column-major.
 *         FESD_ERR_NOT_READY if settings.sensitivities was 0. Either pointer may be NULL. */
FESD_API int fesd_get_sensitivities(const fesd_integrator *it, double *Sx, double *Su);

/** @brief Events detected in the last fesd_step, at most 256 (the array and the mode lists
 *         of its events are valid until the next fesd_step / fesd_set_state). */
FESD_API int fesd_last_events(const fesd_integrator *it, const fesd_event **events, int *count);

/** Per-element data of the last accepted step. */
typedef struct {
  int n_elements;         /**< elements of the accepted step (N_FE times the sub-steps) */
  const double *h;        /**< element lengths */
  const double *t;        /**< element start times (n_elements + 1 entries, last = step end) */
  const double *x;        /**< boundary states, (n_elements + 1) rows of nx (below) */
  const double *theta;    /**< stage theta, n_elements x s x n_theta */
  const double *lambda;   /**< stage lambda, n_elements x s x n_theta */
  const double *mu;       /**< stage mu, n_elements x s x nsys */
  int n_theta;            /**< stride of theta, lambda: total modes (sum of n_modes; with a
                               drift or stop conditions their internal modes follow the user's) */
  int stages;
  int nx;                 /**< stride of x: states (with time_dependent the time follows them) */
  int n_sys;              /**< stride of mu: subsystems (with a drift or stop conditions their
                               internal subsystems follow the user's) */
} fesd_step_data;

/** @brief Element data of the last accepted step (pointers valid until the next step). */
FESD_API int fesd_last_step_data(const fesd_integrator *it, fesd_step_data *data);

/**
 * @brief Dense output inside the last accepted step from the collocation polynomial of
 *        its element (Radau IIA, Gauss-Legendre, Lobatto IIIA; order s + 1 locally,
 *        exact at the element ends up to the method's error).
 * @return FESD_OK; FESD_ERR_INVALID_ARG if t is outside the last step or the method has no
 *         collocation polynomial (Lobatto IIIC, explicit RK); FESD_ERR_NOT_READY before a step.
 */
FESD_API int fesd_dense_output(const fesd_integrator *it, double t, double *x);

/** Error control of fesd_integrate (fesd_set_tolerances; fesd_tolerances_default fills the
 *  defaults). The local error of every element is estimated (embedded formula, docs/solver.md)
 *  and kept below atol_r + rtol |x_r| (weighted RMS norm); tolerances are transformed so that
 *  the achieved error follows them. */
typedef struct {
  double rtol;          /**< relative tolerance, [1e-14, 0.5] (default 1e-6) */
  double atol;          /**< absolute tolerance in the units of x, >= 0 (default 1e-9) */
  const double *atol_v; /**< optional per-state absolute tolerances (nx; copied; NULL: atol) */
  double h_init;        /**< first step length (0: estimated from the field) */
  double h_max;         /**< longest step (0: no limit) */
  double h_min;         /**< shortest step before FESD_ERR_STEP_TOO_SMALL (0: 1e-14 |t|) */
  int max_steps;        /**< accepted + rejected steps per call, >= 1 (default 100000) */
} fesd_tolerances;

/** Statistics of one fesd_integrate / fesd_integrate_grid call. */
typedef struct {
  int status;           /**< FESD_OK, FESD_ROOT or a negative fesd_status */
  double t;             /**< time reached */
  int steps;            /**< accepted steps */
  int switch_steps;     /**< accepted steps that hold at least one event */
  int events;           /**< events logged (fesd_event_log) */
  int rejected;         /**< steps rejected by the error test (error-test failures) */
  int failed_attempts;  /**< steps without a solution, retried shorter */
  int newton_iter;      /**< Newton iterations of all attempts */
  int root;             /**< on FESD_ROOT: the stop condition's index (else -1) */
  int n_done;           /**< fesd_integrate_grid: output times filled */
  double h_next;        /**< proposed next step length */
  const char *failed_callback; /**< on FESD_ERR_CALLBACK/NONFINITE, or when a callback fault made
                                    the steps shrink to FESD_ERR_STEP_TOO_SMALL: the callback of
                                    the last failed attempt ("field", "switch", ...; else NULL) */
  double failed_time;   /**< start time of the last failed step attempt (NaN: none) */
} fesd_integrate_info;

/** @brief Defaults of the error control. */
FESD_API int fesd_tolerances_default(fesd_tolerances *tol);
/** @brief Set the error control of fesd_integrate (validated; FESD_ERR_UNSUPPORTED_TABLEAU for
 *         explicit RK, which has no estimate). Without it the defaults are used. */
FESD_API int fesd_set_tolerances(fesd_integrator *it, const fesd_tolerances *tol);
/**
 * @brief Integrate from the current state to t_out with error-controlled steps, landing on t_out.
 *        Stops earlier, returning FESD_ROOT, where a stop condition (model.roots) crosses zero in
 *        its direction: the state is then on the root (located like a switch, to the method's
 *        accuracy); calling again continues from there. Events of every step go to the event log.
 * @return FESD_OK, FESD_ROOT, or the failure (the state is the last accepted one).
 */
FESD_API int fesd_integrate(fesd_integrator *it, const double *u, double t_out, fesd_integrate_info *info);
/** @brief One error-controlled step towards t_out (never past it): as fesd_integrate, but it
 *         returns after one accepted step (FESD_OK; info->t tells where it is). */
FESD_API int fesd_integrate_step(fesd_integrator *it, const double *u, double t_out, fesd_integrate_info *info);
/**
 * @brief States at n increasing output times (x_out: n rows of nx): error-controlled steps to
 *        t_out[n-1]; outputs inside a step from the collocation polynomial (Radau IIA,
 *        Gauss-Legendre, Lobatto IIIA), else by landing on each. FESD_ROOT as fesd_integrate
 *        (info->n_done outputs filled).
 */
FESD_API int fesd_integrate_grid(fesd_integrator *it, const double *u, int n, const double *t_out, double *x_out,
                                 fesd_integrate_info *info);
/** @brief All events since fesd_set_state that fesd_integrate accepted (pointers valid until
 *         the next integration call or fesd_set_state). Stop conditions appear where they
 *         stopped the integration (zero crossings in their direction); fesd_last_events also
 *         lists their crossings in the other direction. */
FESD_API int fesd_event_log(const fesd_integrator *it, const fesd_event **events, int *count);

/** Accumulated statistics since fesd_set_state. */
typedef struct {
  int steps, switch_steps, newton_iter, factorizations, solves, homotopy_stages, splits;
  int fallback_steps;      /**< steps (or sub-steps) solved by the FB fallback path */
  int substeps;            /**< sub-steps of steps that held many switches */
  int nonunique_steps;     /**< steps flagged FESD_FLAG_NONUNIQUE */
  int sens_inaccurate_steps; /**< steps flagged FESD_FLAG_SENS_INACCURATE */
  int exit_not_pinned_steps; /**< steps flagged FESD_FLAG_EXIT_NOT_PINNED */
  int coarse_steps;        /**< steps flagged FESD_FLAG_COARSE */
  int failed_steps;        /**< calls of fesd_step that failed (their work is counted above) */
  int rejected_steps;      /**< steps rejected by the error test of fesd_integrate */
  int events;
  double time;             /**< wall-clock seconds in fesd_step */
  double max_iter_ordinary_step; /**< max Newton iterations of a step without switch */
  double mean_iter_ordinary_step;
  double max_iter_switch_step;
  double mean_iter_switch_step;
  int ambiguous_steps;     /**< steps flagged FESD_FLAG_AMBIGUOUS */
} fesd_stats;

FESD_API int fesd_get_stats(const fesd_integrator *it, fesd_stats *stats);

/** @brief Number of stacked modes (sum of n_modes) and subsystems. */
FESD_API int fesd_dims(const fesd_integrator *it, int *n_theta, int *nsys);

#ifdef __cplusplus
}
#endif
#endif
