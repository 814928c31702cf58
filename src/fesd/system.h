/* Internal: the discretised equations of one integration step [t, t+T] with N
 * finite elements of an s-stage RK method (paper eq. dcs_irk / fesd_compact),
 * as a problem for the semismooth Newton solver (src/ncp).
 *
 * Unknowns, element by element: for each stage j: v (nx), theta (nth),
 * lambda (nth), mu (nsys); for methods whose last stage is not the element end
 * (not stiffly accurate: Gauss-Legendre, explicit RK) the boundary LP values
 * LB (nth), MB (nsys) at x_{n+1} (paper Sec. 3.2.5 / 4.2.1). Unlike the paper we
 * keep them for the last element too: a switch between the last stage and the
 * step end would otherwise go unseen (the step end is an element boundary of
 * the integration as a whole). Then x_{n+1} (nx) and h_n.
 * Smooth rows, element by element: per stage  v - F(X) theta,  g(X) - lambda - mu e,
 * 1 - e'theta  (per subsystem); boundary LP rows  g(x_{n+1}) - LB - MB e  and
 * theta_{n,s}' LB = 0 (per subsystem: fixes MB as the indicator of the active
 * mode); continuity  x_{n+1} - x_n - h sum b_j v_j. Then the candidate boundary
 * rows for k = 1..N-1: H(k): h_k - h_{k-1} and C(k): C_{k-1} + C_k (compact cross
 * complementarity, eq. cross_comp); last T: sum h - T.
 * Pairs: (theta_{n,j,i}, lambda_{n,j,i}).
 * The solver's row selection chooses, per boundary, H or C (or neither at a
 * pinned sliding exit, where the pair of the dropping mode is PIN).
 *
 * The number of elements N varies from step to step (a step gets one boundary per switch
 * it holds): storage is for N_cap elements, fesd__system_set_N() selects the layout of N
 * (element blocks are the same for every N; only the boundary rows and counts move).
 *
 * Row weights: every raw row is multiplied by wraw (1 / the size of the terms it compares,
 * weights.c), so that tolerances are relative and results do not depend on units or on how
 * far time has run. The cross-complementarity rows weight each mode's products by wth (1 /
 * the indicator scale of its subsystem): dimensionless, whatever the subsystems' units. */
#ifndef FESD_SYSTEM_H
#define FESD_SYSTEM_H

#include "fesd/model.h"
#include "fesd_rk.h"

typedef struct {
  void *mem; /* the block of the arrays below but wraw (lay_out, system.c) */
  int N, N_cap, s, nx, nth, nsys, nu, bp;
  fesd_tableau tab;
  fesd__model *model;
  /* variable layout (eb unknowns and erows rows per element) */
  int sb, n, eb, erows;
  int *el, *xo, *ho, *lbo;
  /* row layout */
  int rs; /* rows per stage */
  int *rel, *rlb, *rx;
  int rH0, rC0, rT, n_eq, n_pair, n_raw;
  int nnz; /* Jacobian entries of the current layout */
  /* parameters of the current step */
  const double *x0, *u, *lam00;
  double T, t0; /* step length; time of the step start (the callbacks get t0 + the point's time) */
  int want_u; /* evaluate u-derivatives (sensitivities) */
  /* scratch: evaluations at N*s stage points and N boundary points */
  fesd__point_eval *pe;
  double *X;    /* stage states, (N*s + N) x nx */
  double *Jth;  /* sum_i theta_i df_i/dx per stage point on the model's union pattern */
  double *JK;   /* Jth K_j per stage point (nx), K_j = sum_l a_jl v_l: the h column */
  double *KG;   /* grad g_i . K_j per stage point (nth) */
  double *Juth; /* sum_i theta_i dF_i/du per stage point, N*s blocks nx x nu */
  double *lam00_dp; /* d lambda00 / d(x_start, u): nth x (nx + nu) */
  double *tmp;  /* 4 nx + 2 nth */
  /* row weights (n_raw of the largest layout), indicator weights per subsystem (wG) and
   * per stacked mode (wth = wG of its subsystem) */
  double *wraw, *wG, *wth;
  /* Look-ahead first stage (methods whose first stage is the element start with no stage
   * derivative in it: Lobatto IIIA). Its indicator rows compare g(x_n) + kappa h grad g(x_n).v_1
   * (the indicators a little way along the stage derivative) instead of g(x_n): on a sliding
   * surface this is the tangency condition that fixes theta_1, which the collocation
   * conditions leave free (x_n itself is already on the surface), and at a switch it picks
   * the mode that continues. Per element: the term (nth), its x_n-Jacobian block grad g +
   * kappa h (Hessian v_1) (ndg, the Hessian product by differences of the switch
   * Jacobian) and, with sensitivities, the u-block (nth x nu). */
  int look;
  double kappa;
  /* Pinned sliding exits of methods whose last stage is not the element end (Gauss-Legendre):
   * at boundary k with exit_ext[k] = i >= 0 the row C(k) holds theta_i of element k-1
   * extrapolated to the element end (sum_j ext[j] theta_{k-1,j,i} = 0, ext[j] = l_j(1) of the
   * Lagrange basis on the nodes c) instead of the cross complementarity (which is zero for
   * every boundary time at an exit). */
  int *exit_ext;
  double ext[FESD_RK_MAX_STAGES];
  /* Boundary-point methods: lbm[n * nth + i] = 1 if the boundary lambda LB_i at the end of
   * element n counts in the cross-complementarity rows. LB has no sign constraint: for a
   * mode active at the element's last stage it is zero only up to the drift of the sliding
   * stages from the surface (O(h^2s)), with either sign, so with fixed active sets it is
   * left out (it would make the sum of signed products, not each product, vanish); the FB
   * path counts all. */
  unsigned char *lbm;
  double *LK, *dgl, *dgul, *xs;
  fesd__point_eval pl;  /* scratch: switch Jacobians at x_n + delta v_1 */
  /* sizes at the last weighting (per state component: X rows, V rows; per subsystem: the
   * indicators), and their maxima over the accepted steps (weights.c) */
  double *magX, *magV, *magG, *refX, *refV, *refG;
  /* per state component: max(refX, T max_i |f_i|) at the last weighting, the motion a step
   * could make (the size of a component at rest on a surface, whose own values are 0) */
  double *motX;
  int status;   /* last model status */
  /* Inputs of the last fesd__system_points (z, x0, u, t0, want_u; pc_jac: with Jacobians):
   * the weights and the solver's first residual evaluate the same z, and a Newton step's
   * Jacobian the z of its residual, so repeated points are not evaluated again. Whoever writes
   * X or pe outside fesd__system_points clears pc_valid (fesd__system_points_stale). */
  double *pc_z, *pc_xu, pc_t0;
  int pc_valid, pc_jac, pc_want_u;
  int pc_hcol; /* JK and KG of these points computed (fesd__system_points_hcol) */
  /* What pe[p] of stage point p holds: evaluated at (pt_t[p], pt_X[p]) with level pt_lvl[p]
   * (0 nothing reusable, 1 values, 2 with x-Jacobians, 3 also u-Jacobians). The consistent
   * guess evaluates the stage points in full for its LP rows, and the weights then reuse
   * them. Cleared at every step start (fesd__system_points_reset) and when u changes. */
  double *pt_X, *pt_t, *pt_u; /* pt_u: the controls of every record */
  signed char *pt_lvl;
} fesd__system;

/* Stage point p evaluated at (t, X) into pe[p] (with Jacobians if want_jac), unless it holds
 * that already; NULL if a callback failed (its status in S->status). */
const fesd__point_eval *fesd__system_stage_eval(fesd__system *S, int p, double t, const double *X, int want_jac);
/* The record of stage point p if it holds (t, X) at level >= level (1: values, 2: with
 * x-Jacobians), NULL otherwise. */
const fesd__point_eval *fesd__system_record(const fesd__system *S, int p, double t, const double *X, int level);
/* Nothing evaluated before is reused (the callbacks' user data may have changed). */
void fesd__system_points_reset(fesd__system *S);
/* Every stage point of z is recorded in full at the state fesd__system_points would compute
 * (the guess's stage Newton: S->X, with K_j in JK), no boundary point and no look-ahead stage:
 * forms the Jacobian sums and makes z the cached input, so the weights and the residual of z
 * need no second pass over the points. */
void fesd__system_points_adopt(fesd__system *S, const double *z);

/* The outputs of fesd__system_points are no longer those of its last inputs. */
static inline void fesd__system_points_stale(fesd__system *S) { S->pc_valid = 0; }

/* Storage for up to N_cap elements (the layout starts with N = N_cap); sens: allocate the
 * parameter-derivative storage of sensitivities (O(nth (nx + nu))). Weights start at 1. */
int fesd__system_init(fesd__system *S, fesd__model *m, const fesd_tableau *tab, int N_cap, int sens);
/* Layout of N <= N_cap elements (counts and boundary-row offsets). */
void fesd__system_set_N(fesd__system *S, int N);
/* Jacobian pattern entries of the current layout, and the pattern itself (row, col). */
int fesd__system_nnz(const fesd__system *S);
void fesd__system_pattern(const fesd__system *S, int *row, int *col);
void fesd__system_free(fesd__system *S);

/* Offsets. */
static inline int fesd__v(const fesd__system *S, int n, int j) { return S->el[n] + j * S->sb; }
static inline int fesd__th(const fesd__system *S, int n, int j) { return S->el[n] + j * S->sb + S->nx; }
static inline int fesd__la(const fesd__system *S, int n, int j) {
  return S->el[n] + j * S->sb + S->nx + S->nth;
}
static inline int fesd__mu(const fesd__system *S, int n, int j) {
  return S->el[n] + j * S->sb + S->nx + 2 * S->nth;
}
static inline int fesd__rowH(const fesd__system *S, int k) { return S->rH0 + k - 1; }
static inline int fesd__rowC(const fesd__system *S, int k) { return S->rC0 + k - 1; }
static inline int fesd__pair(const fesd__system *S, int n, int j, int i) {
  return (n * S->s + j) * S->nth + i;
}
/* Right-boundary lambda of element n as a pointer into z (NULL if none in z:
 * last element of a boundary-point method). */
const double *fesd__right_lambda(const fesd__system *S, const double *z, int n);
/* Left-boundary lambda of element n (lambda00 for n == 0). */
const double *fesd__left_lambda(const fesd__system *S, const double *z, int n);

/* Evaluate the model at every stage point (and boundary LP point) of z, with Jacobians when
 * want_jac (fills pe, X, Jth; JK and KG when a Jacobian asks for them). */
int fesd__system_points(fesd__system *S, const double *z, int want_jac);
/* The state at stage j of element n of z: x_n + h sum_l a_jl v_l (nx values into X). */
void fesd__stage_state(const fesd__system *S, const double *z, int n, int j, double *X);
/* JK and KG (the h column of the stage rows) of the points of the last fesd__system_points
 * with Jacobians; until then JK holds K_j. */
void fesd__system_points_hcol(fesd__system *S);
/* Row weights at z (weights.c): 1 / the size of the terms of each row at z. */
int fesd__system_weights(fesd__system *S, const double *z);
/* Forget the reference sizes (a new initial state); fold the sizes of the last weighting (an
 * accepted solution) into them. */
void fesd__system_reset_refs(fesd__system *S);
void fesd__system_update_refs(fesd__system *S);

/* ncp callback: raw residual and Jacobian values (ctx = fesd__system). */
int fesd__system_eval(const double *z, double *raw, double *jac, void *ctx);

/* Raw-row derivatives w.r.t. (x_start, u) at z (after an eval with want_u set):
 * out is n_raw x (nx + nu), column-major, zeroed here. */
int fesd__system_param_jac(fesd__system *S, const double *z, double *out);

/* Exit rows of the current layout: boundary k pins the exit of mode exit_mode[k] when
 * bmode[k] == 2 and the method has boundary points (see exit_ext); bmode NULL: none. */
void fesd__system_set_exits(fesd__system *S, const int *bmode, const int *exit_mode);

/* Cross-complementarity mask of the boundary lambdas (see lbm): act (N*s blocks of nth
 * flags, per stage) leaves out the modes active at each element's last stage; NULL: all. */
void fesd__system_set_lb_mask(fesd__system *S, const unsigned char *act);

/* Compact cross-complementarity value of element n at z. */
double fesd__cross_value(const fesd__system *S, const double *z, int n);

#endif
