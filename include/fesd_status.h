/**
 * @file fesd_status.h
 * @brief Status codes of libfesd and their human-readable strings.
 *
 * Convention: 0 = success, negative = failure, positive = success with a note (FESD_ROOT). Every public function that can
 * fail returns one of these codes; fesd_status_string() turns it into text.
 */
#ifndef FESD_STATUS_H
#define FESD_STATUS_H

#if defined(FESD_BUILDING) && defined(__GNUC__)
#define FESD_API __attribute__((visibility("default")))
#else
#define FESD_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* X-macro: (name, value, message). One list gives the enum and the strings. */
#define FESD_STATUS_LIST(X)                                                              \
  X(FESD_ROOT, 1, "stopped where a stop condition crossed zero (fesd_integrate)")        \
  X(FESD_OK, 0, "success")                                                               \
  X(FESD_ERR_NULL, -1, "a required pointer argument is NULL")                            \
  X(FESD_ERR_INVALID_ARG, -2, "invalid argument or setting")                             \
  X(FESD_ERR_DIMENSION, -3, "inconsistent or invalid dimensions")                        \
  X(FESD_ERR_UNSUPPORTED_TABLEAU, -4, "unsupported Runge-Kutta family / stage count")    \
  X(FESD_ERR_NOMEM, -5, "memory allocation failed")                                      \
  X(FESD_ERR_CALLBACK, -6, "a user callback returned an error code")                     \
  X(FESD_ERR_NONFINITE, -7, "a user callback produced NaN or Inf")                       \
  X(FESD_ERR_MAX_ITER, -8, "maximum number of Newton iterations reached")                \
  X(FESD_ERR_LINE_SEARCH, -9, "line search failed (no sufficient decrease)")             \
  X(FESD_ERR_SINGULAR, -10, "singular Jacobian")                                         \
  X(FESD_ERR_INCONSISTENT, -11, "over-determined system is inconsistent (nonzero residual at a stationary point)") \
  X(FESD_ERR_LINSOLVE, -12, "linear solver backend failure")                             \
  X(FESD_ERR_PATTERN, -13, "invalid sparsity pattern (index out of range)")              \
  X(FESD_ERR_STEP_FAILED, -14, "integration step failed after all recovery attempts")   \
  X(FESD_ERR_TOO_MANY_SWITCHES, -15, "too many switches (Zeno-like accumulation): stopped") \
  X(FESD_ERR_SIGN_MATRIX, -16, "sign matrix has repeated rows or zero entries")         \
  X(FESD_ERR_MODEL, -17, "invalid model (missing callback, bad dimensions, or callbacks that depend on t with time_dependent = 0)") \
  X(FESD_ERR_NOT_READY, -18, "object is not in a state that allows this call")          \
  X(FESD_ERR_TOO_MANY_STEPS, -19, "maximum number of steps reached before the output time") \
  X(FESD_ERR_STEP_TOO_SMALL, -20, "step size fell below its minimum (error or convergence failures)") \
  X(FESD_ERR_INFEASIBLE, -21, "optimal control problem locally infeasible (stationary point of the constraint violation)") \
  X(FESD_ERR_ITER_LIMIT, -22, "optimizer iteration limit reached before the KKT tolerances were met") \
  X(FESD_ERR_QP, -23, "QP subproblem not solved (also in elastic mode)")

typedef enum {
#define FESD_X_ENUM(name, value, msg) name = value,
  FESD_STATUS_LIST(FESD_X_ENUM)
#undef FESD_X_ENUM
} fesd_status;

/** @brief Human-readable text for a status code (never NULL; unknown codes give "unknown status"). Thread-safe. */
FESD_API const char *fesd_status_string(int status);
/** @brief Symbolic name of a status code, e.g. "FESD_ERR_SINGULAR". Thread-safe. */
FESD_API const char *fesd_status_name(int status);

#ifdef __cplusplus
}
#endif
#endif
