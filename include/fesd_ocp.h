/**
 * @file fesd_ocp.h
 * @brief Direct optimal control with FESD (src/ocp): the discretised OCP of the paper (eq.
 *        OCP_FESD) solved by direct multiple shooting and SQP.
 *
 * Problem. On [t0, tf] with N = n_ctrl control intervals of equal length T = (tf - t0) / N and
 * piecewise constant controls q_k (k = 0..N-1):
 *
 *   min   sum_k int_{t_k}^{t_k+T} L(t, x, q_k) dt + M(x_N) + sum_i w_i |r1_i(x_N)|
 *   s.t.  x_0 = x0 (components may be left free in [x0_lb, x0_ub]),
 *         x_{k+1} = Phi_k(x_k, q_k)          one fesd_step of length T with N_FE elements,
 *         x_lb <= x_k <= x_ub (k = 1..N),    u_lb <= q_k <= u_ub,
 *         path_lb <= p(t_k, x_k, q_k) <= path_ub at the boundaries k = 0..N (q_N := q_{N-1}),
 *         term_lb <= e(x_N) <= term_ub.
 *
 * with L = L_gen + ||r_L||^2 and M = M_gen + ||r_M||^2 (general and least-squares forms may be
 * combined). Phi_k is the integrator's step (FESD with its switch detection and step
 * equilibration, or the standard time-stepping method: settings.integrator.method); its
 * Jacobians are the integrator's exact IFT sensitivities. The Lagrange term is integrated by
 * the same Runge-Kutta method through a cost state appended to the model (reset to 0 at every
 * interval start). The L1 terms are exact penalties written with slacks e_i >= |r1_i|.
 *
 * Lagrangian and multiplier signs: L = f - sum y_j c_j(equalities) - sum z_j c_j(inequalities
 * written as c >= 0), z >= 0. Two-sided constraints report one signed multiplier: positive when
 * the lower bound is active, negative when the upper bound is (fesd_ocp_multipliers).
 *
 * Algorithm (docs/ocp.md): SQP on the multiple shooting NLP; Hessian by Gauss-Newton on the
 * least-squares terms or by block BFGS (one block per interval: (x_k, q_k)); QP
 * subproblems as mixed complementarity problems solved by src/ncp (Fischer-Burmeister pairs,
 * semismooth Newton, sparse KLU), with an elastic (l1) QP when the linearisation is inconsistent;
 * line search on the l1 exact penalty with second-order correction.
 *
 * Memory: everything is allocated by fesd_ocp_create (the integrator allocates only for layouts
 * it meets first, see fesd_create). Reentrant: one workspace per thread.
 */
#ifndef FESD_OCP_H
#define FESD_OCP_H

#include "fesd_integrator.h"
#include "fesd_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * A function of the OCP: writes n values of v(t, x, u) to val and, when dx / du are not NULL,
 * its Jacobians dx (n x nx) and du (n x nu), column-major like the model's field_jac (entry
 * (r, c) at dx[c * n + r]). Terminal functions receive u = NULL and du = NULL. Every requested
 * output must be written. Return 0 on success; nonzero aborts with FESD_ERR_CALLBACK (at a
 * trial point of the line search it only rejects the trial).
 */
typedef int (*fesd_ocp_fn)(double t, const double *x, const double *u, double *val, double *dx, double *du,
                           void *user);

/** Optimal control problem. Arrays are copied by fesd_ocp_create(). */
/** Longest merit memory of the line search (settings.nonmonotone). */
#define FESD_OCP_MAX_NONMONOTONE 16

typedef struct {
  const fesd_model *model;   /**< dynamics (required; dense models: sparsity must be NULL) */
  int n_ctrl;                /**< control intervals N, [1, 100000] */
  double t0, tf;             /**< horizon, t0 < tf */
  const double *x0;          /**< [nx] initial state (required) */
  const double *x0_lb, *x0_ub; /**< [nx] optional: component i is free in [x0_lb_i, x0_ub_i] when
                                 x0_lb_i < x0_ub_i (x0_i is then its initial guess); NULL: fixed */
  const double *x_lb, *x_ub; /**< [nx] state bounds at k = 1..N (NULL or +-INFINITY entries: none) */
  const double *u_lb, *u_ub; /**< [nu] control bounds (NULL or +-INFINITY entries: none) */
  fesd_ocp_fn lagrange;      /**< L_gen(t,x,u), 1 value (NULL: none) */
  int n_lagrange_lsq;        /**< residuals of the least-squares Lagrange term (>= 0) */
  fesd_ocp_fn lagrange_lsq;  /**< r_L(t,x,u): L gets ||r_L||^2 */
  fesd_ocp_fn mayer;         /**< M_gen(x_N), 1 value (NULL: none) */
  int n_mayer_lsq;           /**< residuals of the least-squares Mayer term (>= 0) */
  fesd_ocp_fn mayer_lsq;     /**< r_M(x_N): M gets ||r_M||^2 */
  int n_l1;                  /**< terminal L1 terms (>= 0) */
  fesd_ocp_fn l1;            /**< r1(x_N): cost sum_i l1_weight_i |r1_i| */
  const double *l1_weight;   /**< [n_l1] weights > 0 */
  int n_path;                /**< path constraints per boundary (>= 0) */
  fesd_ocp_fn path;          /**< p(t, x, u) */
  const double *path_lb, *path_ub; /**< [n_path] (NULL or +-INFINITY: one-sided; lb == ub: equality) */
  int n_term;                /**< terminal constraints (>= 0) */
  fesd_ocp_fn terminal;      /**< e(x_N) */
  const double *term_lb, *term_ub; /**< [n_term] as path_lb / path_ub */
  void *user;                /**< passed to every OCP function (the model has its own) */
} fesd_ocp_problem;

typedef enum {
  FESD_OCP_HESSIAN_AUTO = 0,        /**< cost with least-squares terms and no general ones:
                                         GN_SR1 with the FESD method, GAUSS_NEWTON with the
                                         standard one; else BFGS (default) */
  FESD_OCP_HESSIAN_GAUSS_NEWTON = 1, /**< Gauss-Newton of the least-squares terms (needs
                                         lagrange_lsq or mayer_lsq; trapezoidal rule over each
                                         interval; curvature of the constraints and of general
                                         terms neglected: linear convergence) */
  FESD_OCP_HESSIAN_BFGS = 2,        /**< BFGS per block (x_k, q_k), pairs without enough
                                         curvature skipped */
  FESD_OCP_HESSIAN_GN_SR1 = 3       /**< Gauss-Newton plus a per-block symmetric rank-one
                                         correction learning the neglected (possibly
                                         indefinite) curvature of the dynamics; the correction
                                         restarts at 0 when the line search backtracks */
} fesd_ocp_hessian;

typedef enum {
  FESD_OCP_INIT_SIMULATE = 0, /**< x_k from a forward simulation with the control guess, then
                                   clamped to the bounds (run by the solve's first evaluation,
                                   which integrates the intervals anyway; a failed interval keeps
                                   the state constant) */
  FESD_OCP_INIT_CONSTANT = 1  /**< x_k = x0 for all k */
} fesd_ocp_init;

/** Log sink: one line without newline. */
typedef void (*fesd_ocp_log_fn)(void *log_user, const char *msg);

/** Settings; fesd_ocp_settings_default() fills the defaults. fesd_ocp_create() refuses a value
 *  outside its range with FESD_ERR_INVALID_ARG (NaN is outside every range). */
typedef struct {
  fesd_settings integrator;  /**< method, family, stages, n_fe (elements per interval), ... as
                                  fesd_create validates them; sensitivities is forced to 1 */
  fesd_ocp_hessian hessian;  /**< default AUTO */
  int max_iter;              /**< SQP iterations, [1, 100000] (default 200) */
  double tol_stat;           /**< stationarity ||grad_w L||_inf / max(1, ||grad f||_inf),
                                  [1e-14, 1] (default 1e-8) */
  double tol_feas;           /**< constraint violation, units of the constraints, [1e-14, 1]
                                  (default 1e-9) */
  double tol_comp;           /**< max_j |z_j c_j| over inequalities, [1e-14, 1] (default 1e-9) */
  double penalty0;           /**< initial weight nu of the l1 merit, [0, 1e12] (default 1; it
                                  grows to 2 max |multiplier| when needed) */
  double penalty_max;        /**< largest nu (elastic mode; beyond: infeasible), [1, 1e16]
                                  (default 1e10) */
  double armijo;             /**< sufficient decrease constant, (0, 0.5) (default 1e-4) */
  double backtrack;          /**< step reduction factor, [0.05, 0.95] (default 0.5) */
  int max_backtracks;        /**< trials per line search, [1, 60] (default 30) */
  int soc;                   /**< second-order correction when the full step is rejected,
                                  0 or 1 (default 1) */
  int nonmonotone;           /**< merit memory of the line search in the local phase (after 3
                                  consecutive full steps, with a shrinking step): a trial point
                                  is compared with the largest l1 merit of the last `nonmonotone`
                                  iterates (the current one included, all with the current
                                  penalty), so a full step that raises the merit slightly (the
                                  Maratos effect) is taken without a second-order correction;
                                  [1, FESD_OCP_MAX_NONMONOTONE]; 1: monotone (default 2) */
  double reg_primal;         /**< proximal term of the QP Hessian (relative to its largest
                                  diagonal entry, at least 1e-12 absolute), [0, 1] (default 1e-9) */
  double reg_dual;           /**< proximal term of the QP multipliers (keeps degenerate QPs
                                  regular; no effect on the SQP fixed point), [0, 1] (default 1e-10) */
  double qp_tol;             /**< residual of the QP's KKT system (relative to its data), [1e-15,
                                  1e-3] (default 1e-12) */
  int qp_max_iter;           /**< semismooth Newton iterations per QP, [1, 1000] (default 100) */
  int stall_window;          /**< no-progress stop: after this many consecutive steps with
                                  alpha < 0.1 during which the best KKT score did not halve,
                                  GN_SR1 falls back to Gauss-Newton; a second such window (or
                                  the first with another Hessian) ends the solve with
                                  FESD_ERR_LINE_SEARCH and the best iterate; [0, 1000], 0: off
                                  (default 6) */
  fesd_ncp_backend qp_backend; /**< linear solver of the QP (default AUTO: dense up to
                                  FESD_NCP_DENSE_MAX_N unknowns, else KLU) */
  fesd_ocp_init init;        /**< guess when fesd_ocp_set_guess was not called (default SIMULATE) */
  int presolve;              /**< 1: a solve that starts from a new guess (fesd_ocp_set_guess or
                                  settings.init) first solves the same OCP with the standard
                                  method, Radau IIA s = 1 (implicit Euler) with presolve_n_fe
                                  elements per interval, and starts from its solution and
                                  multipliers; when that solve fails or its point cannot be
                                  evaluated, from the guess. Skipped when the discretisation is
                                  the standard method with stages * n_fe <= presolve_n_fe (no
                                  finer than the presolve's). 0 or 1 (default 1) */
  int presolve_n_fe;         /**< elements per interval of the presolve, [1, 100] (default 2) */
  int verbose;               /**< 1: one log line per iteration (default 0) */
  fesd_ocp_log_fn log;       /**< sink of the log (NULL: stdout) */
  void *log_user;
} fesd_ocp_settings;

/** Statistics of a solve. KKT residuals are those of the returned iterate. */
typedef struct {
  int status;               /**< FESD_OK or a negative fesd_status */
  int iterations;           /**< SQP iterations (QP solves that gave a step) */
  int qp_iterations;        /**< semismooth Newton iterations of all QP solves */
  int qp_elastic;           /**< QPs solved in elastic mode (inconsistent linearisation) */
  int qp_failures;          /**< QP solves that failed (and were retried elastic or ended) */
  int line_search_trials;   /**< merit evaluations beyond the first per iteration */
  int soc_steps;            /**< accepted second-order corrections */
  int hessian_updates;      /**< BFGS / SR1 block updates made */
  int hessian_skipped;      /**< ... skipped (tiny step, too little curvature, SR1 denominator) */
  int hessian_resets;       /**< quasi-Newton restarts (BFGS after a failed line search, SR1
                                 correction after a backtracking one) */
  int integrations;         /**< interval simulations (fesd_step calls), the guess's included */
  int integrator_failures;  /**< interval simulations that failed (trial points rejected) */
  int integrator_flags;     /**< FESD_FLAG_* bits seen at the returned iterate */
  double objective;         /**< f at the returned iterate */
  double stationarity;      /**< ||grad f - J_E' y - J_I' z||_inf (absolute) */
  double stationarity_rel;  /**< divided by max(1, ||grad f||_inf) */
  double feasibility;       /**< max constraint violation (absolute) */
  double complementarity;   /**< max_j |z_j c_j| over inequalities */
  double min_multiplier;    /**< smallest inequality multiplier (>= 0 up to round-off) */
  double penalty;           /**< final l1 penalty weight nu */
  double max_step;          /**< ||d||_inf of the last step */
  double time_total;        /**< CPU seconds of fesd_ocp_solve (thread CPU time) */
  double time_integration;  /**< ... in the integrator (steps with sensitivities) */
  double time_qp;           /**< ... in the QP solver */
  double time_other;        /**< the rest (functions, Hessian, line search bookkeeping) */
  int hessian_fallback;     /**< 1: GN_SR1 fell back to Gauss-Newton (settings.stall_window) */
  int stalled;              /**< 1: ended by the no-progress rule (status FESD_ERR_LINE_SEARCH) */
  int stall_interval;       /**< ... and then the control interval whose switch structure
                                 (events, or a halved step) differed between the last rejected
                                 trial point and the iterate: where the NLP is not smooth (-1:
                                 none seen, or not stalled) */
  int presolve_run;         /**< 1: this solve ran a presolve (settings.presolve) */
  int presolve_status;      /**< ... and its status (FESD_OK when none was run) */
  int presolve_iterations;  /**< its SQP iterations (its integrations and CPU times are included
                                 in the fields above) */
  int presolve_used;        /**< 1: the SQP started from the presolve's solution */
} fesd_ocp_info;

/** Multipliers of the returned iterate, in the user's layout (pointers into the workspace,
 *  valid until the next solve). Signs as in the file comment. */
typedef struct {
  const double *dynamics;   /**< [N x nx]: row k multiplies Phi_k(x_k, q_k) - x_{k+1} */
  const double *x0;         /**< [nx]: fixed components of x_0 = x0 (0 for free ones) */
  const double *x_bound;    /**< [(N+1) x nx]: state bounds (k = 0: bounds of free x0 components) */
  const double *u_bound;    /**< [N x nu] */
  const double *path;       /**< [(N+1) x n_path] */
  const double *terminal;   /**< [n_term] */
  const double *l1;         /**< [n_l1]: in [-w_i, w_i] (the subgradient of w_i |r1_i|) */
} fesd_ocp_multipliers;

typedef struct fesd_ocp fesd_ocp; /**< opaque workspace */

/** @brief Defaults (integrator: fesd_settings_default with sensitivities = 1). */
FESD_API int fesd_ocp_settings_default(fesd_ocp_settings *s);

/**
 * @brief Validate the problem and settings, create the integrator and the QP solvers, allocate
 *        everything.
 * @return FESD_OK, FESD_ERR_NULL, FESD_ERR_INVALID_ARG, FESD_ERR_DIMENSION, FESD_ERR_MODEL (also
 *         for sparse models, not supported here), errors of fesd_create, FESD_ERR_NOMEM.
 */
FESD_API int fesd_ocp_create(fesd_ocp **ocp, const fesd_ocp_problem *p, const fesd_ocp_settings *s);
/** @brief Free and set *ocp = NULL (accepts NULL). */
FESD_API void fesd_ocp_free(fesd_ocp **ocp);

/** @brief Initial guess for the next solve: states x ((N+1) x nx, row k = x_k) and controls u
 *         (N x nu); either may be NULL (then from settings.init, and zero controls projected onto
 *         their bounds). Without this call a solve starts from the last solution (the first
 *         from settings.init). */
FESD_API int fesd_ocp_set_guess(fesd_ocp *ocp, const double *x, const double *u);
/** @brief Replace the initial state x0 (nx values, finite); the guess is kept. */
FESD_API int fesd_ocp_set_x0(fesd_ocp *ocp, const double *x0);

/**
 * @brief Solve. info may be NULL.
 * @return FESD_OK when the KKT tolerances are met; FESD_ERR_INFEASIBLE (a stationary point of the
 *         constraint violation), FESD_ERR_ITER_LIMIT, FESD_ERR_LINE_SEARCH, FESD_ERR_QP (a QP
 *         not solved even in elastic mode), integrator or callback errors at the initial guess.
 *         On failure the best iterate found (smallest max of the scaled KKT residuals) is the
 *         solution returned by fesd_ocp_get_solution.
 */
FESD_API int fesd_ocp_solve(fesd_ocp *ocp, fesd_ocp_info *info);

/** @brief The returned iterate: x ((N+1) x nx) and u (N x nu); either may be NULL. */
FESD_API int fesd_ocp_get_solution(const fesd_ocp *ocp, double *x, double *u);
/** @brief Its multipliers (see fesd_ocp_multipliers). */
FESD_API int fesd_ocp_get_multipliers(const fesd_ocp *ocp, fesd_ocp_multipliers *m);

/**
 * @brief Re-simulate interval k of the returned iterate (from x_k with q_k) and give its element
 *        data and events (pointers valid until the next call of this function or a solve).
 *        The cost state, when there is one, is the last state of the element data (index nx).
 *        Any output may be NULL.
 */
FESD_API int fesd_ocp_interval(fesd_ocp *ocp, int k, fesd_step_data *data, const fesd_event **events,
                               int *n_events);

/** @brief Sizes of the NLP: variables, equality and inequality constraints. */
FESD_API int fesd_ocp_dims(const fesd_ocp *ocp, int *n_var, int *n_eq, int *n_ineq);

#ifdef __cplusplus
}
#endif
#endif
