/**
 * @file fesd_ncp.h
 * @brief src/ncp: semismooth Newton solver for nonsmooth equations with
 *        complementarity pairs written as Fischer-Burmeister (FB) rows.
 *
 * Problem. Find z in R^n with F(z) = 0 where F stacks
 *   - smooth equations e_i(z) = 0, i = 0..n_eq-1, and
 *   - complementarity pairs 0 <= a_k(z) ⟂ b_k(z) >= 0, k = 0..n_pair-1, each written
 *     as one FB row  phi_sigma(a,b) = a + b - sqrt(a^2 + b^2 + 2 sigma)  (sigma >= 0
 *     smooths it: its zero set is a,b > 0, ab = sigma).
 * The user evaluates the *raw* rows r = (e_0..e_{n_eq-1}, a_0..a_{np-1}, b_0..b_{np-1})
 * and their Jacobian on a sparsity pattern fixed at setup (triplets; duplicates are
 * summed). The solver builds the generalized Jacobian of the FB rows itself
 * (at a = b = 0, sigma = 0 it uses the element (1 - 1/sqrt2, 1 - 1/sqrt2)).
 *
 * Row selection. Per solve, smooth rows can be switched off and pairs can be
 * put in PIN mode, where the pair contributes the two rows a_k = 0 and b_k = 0
 * instead of its FB row (used by FESD at a sliding exit). The assembled system
 * has m = (#active eq rows) + (#FB, A and B pairs) + 2 (#PIN pairs) rows, in this
 * order: active eq rows by increasing index, then for k = 0..n_pair-1 the FB row of
 * k (FB mode), the rows a_k, b_k (PIN), the row a_k (A) or the row b_k (B); OFF
 * pairs contribute nothing.
 *   m == n : square semismooth Newton with Armijo line search on 1/2||F||^2; when
 *            the Newton direction fails the descent test or needs more than 9 step
 *            cuts, an LM-regularized step (dense) or a Cauchy-scaled gradient step
 *            (sparse) is taken instead. No progress for 5 iterations (a nonzero local
 *            minimizer of 1/2||F||^2) gives FESD_ERR_LINE_SEARCH.
 *   m  > n : Levenberg-Marquardt (the system must be consistent; a stationary
 *            point with nonzero residual returns FESD_ERR_INCONSISTENT).
 *   m  < n : FESD_ERR_DIMENSION.
 *
 * Convergence: ||F(z)||_inf <= tol (default 1e-12). Units are those of the rows.
 *
 * Memory. All allocation happens in fesd_ncp_setup() (and in fesd_ncp_set_rows()
 * for the sparse backends when the row selection changes the pattern). Dense and
 * KLU backends allocate nothing while solving (KLU only on its first factorization
 * of a pattern and when a pivot-order refactor is rejected); UMFPACK's numeric
 * factorization and CHOLMOD's factorization of J'J + mu I allocate by design.
 * Reentrant: one workspace per thread.
 */
#ifndef FESD_NCP_H
#define FESD_NCP_H

#include "fesd_status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  FESD_NCP_BACKEND_AUTO = 0, /**< dense if n <= settings.dense_max_n, else KLU (square) / CHOLMOD (m > n) */
  FESD_NCP_BACKEND_DENSE = 1, /**< LU (unblocked up to n = 48, LAPACK above) (square), LAPACK Cholesky of J'J + mu I (LM) */
  FESD_NCP_BACKEND_UMFPACK = 2, /**< square sparse LU, symbolic analysis reused */
  FESD_NCP_BACKEND_KLU = 3,     /**< square sparse LU, klu_refactor reuse (no allocation per iteration) */
  FESD_NCP_BACKEND_CHOLMOD = 4  /**< LM normal equations J'J + mu I, analysis reused */
} fesd_ncp_backend;

/** Pair modes for fesd_ncp_set_rows(): FB row (default); PIN: the two rows a = 0, b = 0;
 *  OFF: no row; A: the row a = 0 (pair known inactive on the a side); B: the row b = 0.
 *  A and B fix an active set: the system is then smooth. */
enum {
  FESD_NCP_PAIR_FB = 0,
  FESD_NCP_PAIR_PIN = 1,
  FESD_NCP_PAIR_OFF = 2,
  FESD_NCP_PAIR_A = 3,
  FESD_NCP_PAIR_B = 4
};

/**
 * Raw residual/Jacobian callback.
 * @param[in]  z    current point (n)
 * @param[out] raw  n_eq + 2 n_pair raw values (equations, then all a_k, then all b_k)
 * @param[out] jac  nnz Jacobian values in pattern order, or NULL when only values are needed
 * @param[in]  user the problem's user pointer
 * @return 0 on success; any other value aborts the solve with FESD_ERR_CALLBACK.
 * NaN/Inf in raw or jac give FESD_ERR_NONFINITE (at a line-search trial point they only
 * reject the trial step).
 */
typedef int (*fesd_ncp_eval_fn)(const double *z, double *raw, double *jac, void *user);

/** Problem description. Arrays are copied at setup; the caller may free them afterwards. */
typedef struct {
  int n;          /**< unknowns (>= 1) */
  int n_eq;       /**< smooth equation rows (>= 0) */
  int n_pair;     /**< complementarity pairs (>= 0) */
  int nnz;        /**< pattern entries (>= 0) */
  const int *row; /**< raw row index per entry: [0,n_eq) eq, n_eq+k is a_k, n_eq+n_pair+k is b_k */
  const int *col; /**< column index per entry, [0,n) */
  fesd_ncp_eval_fn eval; /**< required */
  void *user;            /**< passed to eval */
} fesd_ncp_problem;

/** Log sink for iteration logs; msg is one line without newline. */
typedef void (*fesd_ncp_log_fn)(void *log_user, const char *msg);

/** Solver settings; fesd_ncp_settings_default() fills the defaults. fesd_ncp_setup() and
 *  fesd_ncp_update_settings() refuse a value outside its range with FESD_ERR_INVALID_ARG
 *  (NaN is outside every range). */
typedef struct {
  double tol;            /**< ||F||_inf convergence tolerance, [1e-16, 1e-1] (default 1e-12) */
  int max_iter;          /**< Newton/LM iterations per sigma stage, [1, 1000] (default 50) */
  fesd_ncp_backend backend; /**< a fesd_ncp_backend value (default AUTO) */
  int dense_max_n;       /**< AUTO uses the dense backend up to this n, [0, 5000] (default FESD_NCP_DENSE_MAX_N); a
                              system with a border (the integrator's step systems) up to 2 dense_max_n
                              (and FESD_NCP_BDENSE_MAX_N) takes a dense LU with the border eliminated
                              last, reported as dense */
  double armijo;         /**< Armijo constant c1, (0, 0.5) (default 1e-4) */
  double backtrack;      /**< step reduction factor, (0, 1) (default 0.5) */
  int max_backtracks;    /**< line-search trials per direction, [1, 100] (default 30; a Newton direction gets at most 10 before the fallback) */
  double sigma0;         /**< first smoothing parameter of the homotopy, (0, 1e3] (default 1e-1) */
  double sigma_factor;   /**< sigma_{k+1} = factor * sigma_k, (0, 0.9] (default 0.1) */
  double sigma_min;      /**< last positive sigma before the final sigma = 0 stage, [1e-16, sigma0] (default 1e-8) */
  double homotopy_tol_factor; /**< intermediate stages stop at ||F|| <= factor*sigma, (0, 1] (default 1e-2) */
  double lm_mu0;         /**< initial LM damping factor: mu = lambda ||F||_2, lambda adapted by the gain ratio, [1e-10, 1e10] (default 1e-3) */
  int slow_iter;         /**< progress check: a stage whose ||F||_inf after slow_iter iterations is above
                              slow_ratio times its value after the first iteration ends with
                              FESD_ERR_LINE_SEARCH (no sufficient decrease); 0 = off (default), else
                              [2, 1000]. The first step is left out: from a poor guess it often gains
                              a lot and then creeps. For callers that have a cheaper alternative than
                              iterating on (a guess out of Newton's reach) */
  double slow_ratio;     /**< see slow_iter, (0, 1] (default 0.5) */
  fesd_ncp_log_fn log;   /**< optional iteration log (default NULL = silent) */
  void *log_user;
} fesd_ncp_settings;

/** Default dense/sparse crossover of the AUTO backend (measured by bench/ncp_bench and on
 *  the FESD reference problems, docs/ncp.md: KLU is faster above ~50 unknowns at FESD's
 *  10-20 % Jacobian density). */
#define FESD_NCP_DENSE_MAX_N 50
/** Largest bordered system the AUTO backend factorizes densely (see dense_max_n; measured
 *  cheaper than KLU at 60-80 unknowns). */
#define FESD_NCP_BDENSE_MAX_N 200
/** Entries kept in fesd_ncp_info.residual_history. */
#define FESD_NCP_HISTORY 64

/** Statistics of one solve (fesd_ncp_solve or fesd_ncp_solve_homotopy). */
typedef struct {
  int status;            /**< FESD_OK or a negative fesd_status */
  int iterations;        /**< Newton/LM iterations (all stages) */
  int homotopy_stages;   /**< sigma stages run (a plain solve counts 1) */
  int factorizations;    /**< numeric factorizations */
  int evals;             /**< residual evaluations (with or without Jacobian) */
  int jac_evals;         /**< Jacobian evaluations */
  int backtracks;        /**< line-search step reductions */
  int backend;           /**< fesd_ncp_backend actually used */
  int m;                 /**< rows of the assembled system */
  double residual;       /**< final ||F||_inf (at the final sigma) */
  double time_total;     /**< seconds (wall clock) */
  double time_eval;      /**< seconds in the user callback */
  double time_linsolve;  /**< seconds in factorizations and solves */
  double time_iterations; /**< seconds inside the Newton/LM iterations (Jacobian assembly, factorization, solve,
                             line search with its evaluations); the rest of time_total is the first residual
                             and the convergence test, so time_iterations / iterations is the cost of one iteration */
  int history_len;       /**< entries used in residual_history */
  double residual_history[FESD_NCP_HISTORY]; /**< ||F||_inf at the start of each iteration, then final (per stage; the most recent entries when more) */
} fesd_ncp_info;

typedef struct fesd_ncp fesd_ncp; /**< opaque workspace */

/** @brief Fill s with the defaults above. FESD_ERR_NULL if s is NULL. */
FESD_API int fesd_ncp_settings_default(fesd_ncp_settings *s);

/**
 * @brief Validate the problem and settings, copy the pattern, allocate the workspace and
 *        choose the backend. The default row selection (all rows active, all pairs FB) is
 *        analysed at its first use (a solve, residual or sensitivity before any
 *        fesd_ncp_set_rows), so a caller that selects its own rows first never pays for it;
 *        failures of that analysis (FESD_ERR_NOMEM, FESD_ERR_LINSOLVE) are returned there.
 * @param[out] ws  new workspace (NULL on error; nothing leaks)
 * @param[in]  p   problem (not modified)
 * @param[in]  s   settings, or NULL for defaults
 * @return FESD_OK, FESD_ERR_NULL, FESD_ERR_DIMENSION (n < 1, a negative count, or
 *         n_eq + n_pair < n: the default selection must not be under-determined),
 *         FESD_ERR_PATTERN, FESD_ERR_INVALID_ARG, FESD_ERR_NOMEM, FESD_ERR_LINSOLVE.
 */
FESD_API int fesd_ncp_setup(fesd_ncp **ws, const fesd_ncp_problem *p, const fesd_ncp_settings *s);

/** @brief Replace the settings (backend and dense_max_n are ignored after setup). */
FESD_API int fesd_ncp_update_settings(fesd_ncp *ws, const fesd_ncp_settings *s);

/**
 * @brief Select rows for the next solves.
 * @param eq_active n_eq flags (nonzero = row used), or NULL for all rows
 * @param pair_mode n_pair FESD_NCP_PAIR_* values, or NULL for all FB
 * @return FESD_OK, FESD_ERR_DIMENSION (fewer rows than unknowns), FESD_ERR_INVALID_ARG, FESD_ERR_NOMEM.
 */
FESD_API int fesd_ncp_set_rows(fesd_ncp *ws, const unsigned char *eq_active,
                               const unsigned char *pair_mode);

/**
 * @brief Optional border for the sparse LU (KLU backend, square selections): the unknowns with
 *        col_border[j] != 0 and the assembled rows that come from raw rows with
 *        raw_border[r] != 0 are eliminated last by a Schur complement (dense, one KLU solve per
 *        border column). For systems where a few rows and columns couple everything (FESD:
 *        element lengths, boundary rows): the rest stays block triangular and its factorization
 *        linear in the size. Used by the selections that have as many border rows as border
 *        columns; the others (and the other backends) factorize as before. Either NULL removes
 *        the border. Takes effect at the next fesd_ncp_set_rows().
 * @return FESD_OK, FESD_ERR_NULL, FESD_ERR_NOMEM.
 */
FESD_API int fesd_ncp_set_border(fesd_ncp *ws, const unsigned char *raw_border,
                                 const unsigned char *col_border);

/**
 * @brief Optional box on the unknowns: the initial guess and every trial point are
 *        projected onto [lb, ub] (a safeguard, e.g. element lengths > 0). A NULL lb / ub
 *        means -inf / +inf; both NULL remove the box. FESD_ERR_INVALID_ARG if lb > ub or NaN.
 */
FESD_API int fesd_ncp_set_bounds(fesd_ncp *ws, const double *lb, const double *ub);

/**
 * @brief Solve F_sigma(z) = 0 from the initial guess z (overwritten by the last iterate).
 * @return FESD_OK if ||F||_inf <= tol, else the failure status (also in info->status):
 *         FESD_ERR_INVALID_ARG (sigma < 0 or not finite), FESD_ERR_NOT_READY (the last
 *         fesd_ncp_set_rows failed), FESD_ERR_MAX_ITER, FESD_ERR_LINE_SEARCH,
 *         FESD_ERR_SINGULAR, FESD_ERR_INCONSISTENT (m > n), FESD_ERR_CALLBACK, ...
 * info may be NULL.
 */
FESD_API int fesd_ncp_solve(fesd_ncp *ws, double *z, double sigma, fesd_ncp_info *info);

/**
 * @brief Homotopy: try sigma = 0 directly; on failure restart from the initial guess with
 *        sigma0, sigma0*factor, ..., sigma_min (stopping each at homotopy_tol_factor*sigma)
 *        and finish with sigma = 0. Statistics accumulate over all stages.
 */
FESD_API int fesd_ncp_solve_homotopy(fesd_ncp *ws, double *z, fesd_ncp_info *info);

/**
 * @brief Assembled residual at z: F (m values, may be NULL) and its inf-norm (may be NULL).
 */
FESD_API int fesd_ncp_residual(fesd_ncp *ws, const double *z, double sigma, double *F,
                               double *norm_inf);

/** @brief Rows m of the assembled system for the current row selection. */
FESD_API int fesd_ncp_rows(const fesd_ncp *ws);

/**
 * @brief Sensitivities by the implicit function theorem at a solution z (square systems):
 *        solves J(z) dz = -dF/dp for nrhs parameter directions, where dF/dp is obtained from
 *        the user's raw-row derivatives by the same FB chain rule as the Jacobian.
 * @param[in]  z        solution (n)
 * @param[in]  sigma    smoothing used at the solution (normally 0)
 * @param[in]  nrhs     number of parameters
 * @param[in]  draw_dp  (n_eq + 2 n_pair) x nrhs column-major: derivatives of the raw rows
 * @param[out] dz_dp    n x nrhs column-major
 * Factorizes J(z) once (counted in the next info); for m > n returns the least-squares solution.
 */
FESD_API int fesd_ncp_sensitivity(fesd_ncp *ws, const double *z, double sigma, int nrhs,
                                  const double *draw_dp, double *dz_dp);

/** @brief Quality of the last fesd_ncp_sensitivity(): the worst relative residual
 *         ||J dz + dF||_inf / max_i (sum_j |J_ij dz_j| + |dF_i|) over its right-hand sides,
 *         after one step of iterative refinement when it exceeded 1e-12 (square systems; 0 for
 *         least squares). Round-off gives about 1e-16; a value above ~1e-8 means the solve (and
 *         the sensitivities) cannot be trusted. */
FESD_API int fesd_ncp_sensitivity_residual(const fesd_ncp *ws, double *rel);
/** @brief Forward-error estimate of the last fesd_ncp_sensitivity() (square systems; 0 for least
 *         squares): the largest relative size ||d||_inf / ||dz||_inf of the correction of one step
 *         of iterative refinement over its right-hand sides, about cond(J) eps when the residual
 *         is at round-off level. Above ~1e-6 the sensitivities carry that relative error. */
FESD_API int fesd_ncp_sensitivity_error(const fesd_ncp *ws, double *ferr);

/** @brief Free the workspace and set *ws = NULL. Accepts NULL and *ws == NULL. */
FESD_API void fesd_ncp_free(fesd_ncp **ws);

/** @brief Name of a backend ("auto", "dense", "umfpack", "klu", "cholmod"). */
FESD_API const char *fesd_ncp_backend_name(int backend);

/** @brief FB function phi_sigma(a,b) and its partial derivatives (da, db may be NULL). */
FESD_API double fesd_fb(double a, double b, double sigma, double *da, double *db);

#ifdef __cplusplus
}
#endif
#endif
