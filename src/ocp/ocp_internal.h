/* Internal layout of the OCP workspace (src/ocp). Not part of the public API.
 *
 * NLP variables w, interleaved per interval so that the KKT matrix is banded:
 *   [x_0 q_0 | x_1 q_1 | ... | x_{N-1} q_{N-1} | x_N | e_0 .. e_{n_l1-1}]
 * (block k = (x_k, q_k) of nb = nx + nu entries, block N = x_N, then the L1 slacks).
 * Constraints: equalities c_E = 0 (rows 0..mE-1) and inequalities c_I >= 0 (rows mE..mE+mI-1);
 * their Jacobian J is a list of triplets with a pattern fixed at setup (emit.c builds pattern and
 * values with the same code). */
#ifndef FESD_OCP_INTERNAL_H
#define FESD_OCP_INTERNAL_H

#include "fesd_ocp.h"

/* what a constraint row is (for multipliers in the user's layout and the elastic QP) */
enum {
  ROW_INIT = 0, /* x_0,i - x0_i = 0 */
  ROW_DYN,      /* Phi_k,i - x_{k+1},i = 0 */
  ROW_XBND,     /* state bound (hard in the elastic QP) */
  ROW_UBND,     /* control bound (hard) */
  ROW_PATH,
  ROW_TERM,
  ROW_L1        /* r1_i + e_i >= 0 (sign +1) or e_i - r1_i >= 0 (sign -1) */
};

typedef struct {
  unsigned char kind;
  signed char sign; /* +1: lower side / equality, -1: upper side */
  int idx;          /* index in the user's multiplier array of its kind */
} ocp_row;

/* One evaluated point of the NLP. */
typedef struct {
  double *w;     /* nw */
  double f;      /* objective */
  double *c;     /* mE + mI constraint values */
  double *grad;  /* nw: gradient of f */
  double *jv;    /* nnzJ Jacobian values (pattern order) */
  double *phi;   /* N x nx: Phi_k(x_k, q_k) */
  double *Sx;    /* N x (nx x nx) column-major */
  double *Su;    /* N x (nx x nu) */
  double *gn;    /* Gauss-Newton data: per interval 2 x (nL x nb) (start, end), then nM x nx */
  double viol;   /* l1 norm of the constraint violation */
  int flags;     /* integrator flags of its intervals */
  unsigned *sig; /* N: switch structure of each interval (a hash of its events: subsystem, kind,
                    active sets, not their times; and of the integrator's halvings and
                    sub-steps), to name the intervals where a step changes it */
} ocp_point;

/* A QP as a mixed complementarity problem for src/ncp: raw rows = cst + sum val * z[col]. */
typedef struct {
  fesd_ncp *ncp;
  int n, n_eq, n_pair, nnz, elastic;
  int *row, *col;
  double *val, *cst, *z;
  int mIe;        /* elastic inequalities (not bounds) */
  int *ie_map;    /* [mIe] inequality row (0-based within I) of each elastic slack t */
  int ncp_status; /* last solve */
  int iterations;
} ocp_qp;

struct fesd_ocp {
  fesd_ocp_problem p;       /* copy; arrays below */
  fesd_ocp_settings set;
  fesd_model umodel;        /* copy of the user's model (p.model points here) */
  fesd_model model;         /* the integrator's model (augmented with the cost state) */
  fesd_integrator *it;
  int nx, nu, nxa, nb, N, nw, mE, mI, nnzJ, nL, nM, cost_state;
  double T;                 /* interval length */
  double *x0, *x0_lb, *x0_ub, *x_lb, *x_ub, *u_lb, *u_ub;
  double *path_lb, *path_ub, *term_lb, *term_ub, *l1_w;
  unsigned char *x0_free;
  double *lb, *ub;          /* nw: variable bounds (+-inf when none) */
  int *jr, *jc;             /* nnzJ pattern of J */
  ocp_row *rows;            /* mE + mI */
  /* scratch of the model wrapper and of the OCP functions */
  double *mw_f, *mw_J, *mw_Ju, *mw_r, *mw_rx, *mw_ru;
  double *fv, *fx, *fu;     /* function outputs: max(n_path, n_term, n_l1, nL, nM, 1) rows */
  double *xa, *Sxa, *Sua;   /* augmented state and sensitivities */
  /* iterates */
  ocp_point pt[3];          /* current, trial, second-order-correction trial */
  ocp_point *cur, *trial, *spare;
  double *y, *yq, *yq2;     /* mE + mI multipliers: current, from the QP, from a second QP */
  double *d, *dsoc;         /* nw steps */
  double *gl, *gl2;         /* nw Lagrangian gradients */
  double *B;                /* Hessian blocks: N x nb^2, then nx^2 */
  double *A;                /* GN_SR1: the SR1 correction, same layout as B */
  double *bs, *by, *bBs;    /* BFGS scratch (nb) */
  double *tmp;              /* max(nw, mE + mI) */
  ocp_qp qp, qe;            /* normal and elastic QP */
  /* best iterate and the returned solution */
  double *w_best, *y_best;  /* the returned iterate and its multipliers */
  double *wg;               /* start of the next solve */
  double best_score;
  /* the last settings.nonmonotone iterates' objective and violation (line search reference) */
  double hist_f[FESD_OCP_MAX_NONMONOTONE], hist_v[FESD_OCP_MAX_NONMONOTONE];
  int hist_n;
  int have_guess;           /* wg is set (by fesd_ocp_set_guess or a previous solve) */
  int guess_pending;        /* wg's states are to be simulated by the solve's first evaluation */
  int warm;                 /* y_best holds multipliers of wg (a previous solve) */
  int fresh_guess;          /* wg is a new guess (set_guess), not a previous solution */
  struct fesd_ocp *pre;     /* the presolve's workspace (settings.presolve), or NULL */
  /* multipliers in the user's layout */
  double *m_dyn, *m_x0, *m_xb, *m_ub, *m_path, *m_term, *m_l1;
  fesd_ocp_info info;
  fesd_ocp_info best_info;  /* KKT residuals, objective and flags of w_best */
  int kink;                 /* the last interval whose switch structure differed between a rejected
                               trial point and the iterate (-1: none since the last good step) */
  int last_split;           /* halvings + sub-steps of the last interval integration */
  double t_int, t_qp;       /* accumulated CPU seconds of the current solve */
};

/* model.c: the integrator's model with the cost state (or the user's model unchanged) */
int fesd__ocp_model_init(fesd_ocp *o);

/* emit.c: count (o->mE, o->mI, o->nnzJ), record the pattern and row kinds (pt NULL), or
 * evaluate constraint values and Jacobian values at pt (simulation results already in pt). */
enum { EMIT_COUNT = 0, EMIT_PATTERN = 1, EMIT_VALUES = 2 };
int fesd__ocp_emit(fesd_ocp *o, ocp_point *pt, int mode);

/* eval.c */
int fesd__ocp_eval(fesd_ocp *o, ocp_point *pt);       /* everything at pt->w */
/* the same at the guess whose states are simulated on the way (fesd_ocp_set_guess without
 * states, settings.init SIMULATE): pt->w holds x_0 and the controls; the states (simulated,
 * then clamped to their bounds: evaluated again when that moved one) and the L1 slacks are
 * written */
int fesd__ocp_eval_guess(fesd_ocp *o, ocp_point *pt);
int fesd__ocp_simulate(fesd_ocp *o, int k, const double *s, const double *q, double *xend, double *l,
                       int sens, int *flags);
void fesd__ocp_lagrangian_grad(const fesd_ocp *o, const ocp_point *pt, const double *mult, double *out);
double fesd__ocp_violation(const fesd_ocp *o, const double *c);
void fesd__ocp_jmul(const fesd_ocp *o, const ocp_point *pt, const double *d, double *out); /* out = c + J d */
int fesd__ocp_call(fesd_ocp *o, fesd_ocp_fn fn, int n, double t, const double *x, const double *u, int jac);

/* hessian.c */
void fesd__ocp_hessian_reset(fesd_ocp *o);
void fesd__ocp_hessian_gn(fesd_ocp *o, const ocp_point *pt);
void fesd__ocp_bfgs_update(fesd_ocp *o, const ocp_point *a, const ocp_point *b, const double *mult);
void fesd__ocp_sr1_reset(fesd_ocp *o);
void fesd__ocp_hessian_gn_sr1(fesd_ocp *o, const ocp_point *pt); /* B = GN(pt) + A */
void fesd__ocp_sr1_update(fesd_ocp *o, const ocp_point *a, const ocp_point *b, const double *mult);
double fesd__ocp_hessian_diag_max(const fesd_ocp *o);

/* qp.c */
int fesd__ocp_qp_setup(fesd_ocp *o, ocp_qp *q, int elastic);
void fesd__ocp_qp_free(ocp_qp *q);
/* Solve the QP at pt with constants c (pt->c or a second-order correction) and penalty nu
 * (elastic); d, mult (mE + mI) out; *vlin: l1 violation of the linearisation at d. */
int fesd__ocp_qp_solve(fesd_ocp *o, ocp_qp *q, const ocp_point *pt, const double *c, double nu, double *d,
                       double *mult, double *vlin);

/* presolve.c: create the presolve's workspace when settings.presolve applies (s: the user's
 * settings); run it from the guess wg: 1 when cur->w and y now hold its solution */
int fesd__ocp_presolve_create(fesd_ocp *o, const fesd_ocp_settings *s);
int fesd__ocp_presolve(fesd_ocp *o);

/* sqp.c helpers used by access.c */
void fesd__ocp_unpack_multipliers(fesd_ocp *o, const double *mult);

#endif
