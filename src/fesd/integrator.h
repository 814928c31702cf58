/* Internal definition of the integrator object (src/fesd). */
#ifndef FESD_INTEGRATOR_INTERNAL_H
#define FESD_INTEGRATOR_INTERNAL_H

#include <stddef.h>

#include "fesd/model.h"
#include "fesd/system.h"
#include "fesd/wrap.h"
#include "fesd_integrator.h"
#include "fesd_ncp.h"

#define FESD_EVENTS_INIT 64 /* initial room of the event store (grown by fesd__accept) */
/* Plans remembered to detect a cycle of plan updates (step.c). */
#define PLAN_SIGS 8
/* Element counts with a solver workspace of their own (the ladder of layouts, integrator.c). */
#define FESD__MAX_LEVELS 24

/* The solver workspace of one element count N (created at its first use: a step that holds
 * more switches than N_FE - 1 gets more elements), with the sensitivity buffers of that size. */
typedef struct {
  int N;
  fesd_ncp *ncp;
  double *draw, *dz;
} fesd__level;

/* A switch of one subsystem inside the step, as planned for the next solve (plan.c). */
typedef struct {
  double t;  /* time from the step start: predicted, then the solved boundary time */
  int sys;   /* subsystem */
  int mode;  /* the mode whose sign was violated: entering, or leaving (exit) */
  int exit;  /* 1: an active mode leaves (its sliding multiplier reached 0): pinned exit row */
  int kb;    /* element boundary carrying it in the current layout */
  int tries; /* active sets tried after it */
  int fresh; /* added or changed by the last plan update */
  double lo, hi; /* bracket of its time (the boundary may not leave it: another root of the
                    same sign change, e.g. the way back of a short excursion) */
} fesd__switch;

/* A sign violation of a fixed active set, or an invalid sliding mode (verify.c). */
typedef struct {
  int found;
  double t;     /* predicted switch time (relative to the step start) */
  int mode;     /* stacked mode index */
  int sys;
  int enter;    /* 1: an inactive mode's lambda went negative; 0: an active theta did */
  int element;  /* element where it was detected */
  int stage;    /* stage index n*s + j of the violating point (n*s + s: element end or midpoint) */
  int first;    /* detected at the first checked point after an active-set change of its
                   subsystem (the change itself chose the wrong modes) */
  int filippov; /* the subsystem's 2-mode sliding fails Filippov's conditions here: `mode` is
                   the mode whose field points into its own region (-1: both: repulsive) */
  double lo, hi; /* bracket of the switch: the last point seen on the right side, the point
                    where the sign was violated (the trajectory agrees up to the switch) */
  double back;    /* an excursion between check points (verify_between.c): the time the
                     trajectory turns back (0: none) */
} fesd__violation;

/* A saved state (integrator.c): the step start, restored when fesd_step fails, and the start
 * of a sub-step attempt, restored before halving (a failure inside accept, e.g. a callback
 * at the new state, can leave the state half-updated). */
/* Largest stage system (s n_x unknowns) solved by the dense stage Newton of the guess. */
#define FESD__GN_MAX 64

typedef struct {
  double t, t_c, *x, *lam, *th, *blk, *Sx, *Su, *ldp;
  unsigned char *act;
  int have_ws, have_prev_theta, n_el, n_events;
  int gn_warm; /* the stage Newton's choice of start (a retried step takes the same path) */
} fesd__saved;

struct fesd_integrator {
  fesd_settings set;
  fesd__wrap wrap;  /* the internal model (time as state, drift, roots: wrap.h) */
  int nxu, nsysu;   /* the user's states and subsystems (nx, nsys: internal) */
  fesd__model model;
  fesd__system sys;
  fesd_ncp *ncp; /* the workspace of the current layout (a level's) */
  fesd__level lv[FESD__MAX_LEVELS];
  int n_lv, N_cap, lv_cur;
  int n, nx, nu, nth, nsys, s, np;
  /* current state */
  double t;
  double t_c; /* compensation of the sum of the step lengths (t is their Kahan sum) */
  void *mem; /* the block of the arrays below that do not grow (lay_out, integrator.c) */
  double newton_tol; /* of the step solves: settings.newton_tol, tighter under error control */
  double *f0;  /* the fields at the step start (nF), when f0_ok: from the guess's stage Newton */
  int f0_ok;   /* reset at each step attempt (try_step) */
  double *x, *lam00, *theta_prev, *u_cur, *ws_blk; /* ws_blk: last stage block of the last step */
  /* graze check of fesd_integrate (graze.c): lambda and its rate at the start of the step (a)
   * and at its end (b), per mode; ap_th scratch thetas; ap_t: the time the (a) values hold at */
  double *ap_lam, *ap_rate, *ap_lam_b, *ap_rate_b, *ap_th, ap_t;
  double *ap_m, *ap_m_b; /* nsys: Filippov margins of the sliding subsystems at both step ends */
  double *ap_m2, ap_h2;  /* ... at the start of the accepted step before, and its length (NaN) */
  double *ap_m3, ap_h3;  /* ... and of the one before that */
  int have_state, have_ws, have_prev_theta;
  /* step data (sized for N_cap elements) */
  double *z, *z0, *zpred, *zp;
  unsigned char *eq_active, *pair_mode, *raw_border, *col_border;
  fesd__saved bk, bk_sub; /* step start, sub-step start */
  /* sensitivities */
  double *Sx, *Su, *Dtmp, *Stmp;
  double *gbuf, *blk, *vtmp; /* vtmp: 2 nx */
  /* stage Newton of the guess (stage_newton.c), when s nx <= FESD__GN_MAX: matrix (its LU),
   * residual, saved stages, dense Jacobian; pivots; the key of an element's matrix (h, then
   * sum theta df/dx on the union pattern per stage) and the key of the LU in gn (gn_memo,
   * valid while gn_memo_ok; both in the block gn_key). NULL: too large */
  double *gn, *gn_key, *gn_memo;
  int gn_memo_ok;
  int gn_full_at; /* the Newton pass that converged last (evaluated in full: stage_newton.c) */
  int gn_warm;    /* the warm start solved the last element as it was: check it first */
  double *fil_th;         /* nth: multipliers of an alternative (verify.c) */
  double *herm;           /* 2 nth: distance and rate of each mode at an element start (verify_between.c) */
  double *fil_mi, *fil_mj; /* nsys s: normalised normal components at the stages (verify.c) */
  double *fil_pm;          /* 2 nsys: ... at the previous element's end (its last stage, c_s = 1) */
  double *slide_tmp;      /* 2 nx: the coupled sliding multipliers (fesd__stage_theta) */
  unsigned char *fil_a;   /* nth: its active flags */
  int *gn_piv;
  double *ftot, *gdense;     /* nx: a total field; a dense gradient kept zero between uses */
  fesd__point_eval pscr;     /* scratch model evaluation */
  double *pt_t, *pt_q, *pt_l; /* switch prediction: point times and q values */
  int *pt_src, *kb, *sw_at;
  /* active sets: per stage (act), at the step start (act0), per element boundary */
  unsigned char *act, *act0, *cand, *swap_set;
  unsigned char *act_first; /* act0 as classified at the step start, before the plan's start jumps */
  int start_jumped;         /* act_first holds it (a start jump happened in this attempt) */
  int defer_exit;           /* the start solve's only violation is a sliding mode failing at the
                               step end (step.c, defer_exit) */
  int *bmode, *exit_mode;
  /* the last fesd__rows_active selection (solver, N, act, bmode, exit_mode), still in force
   * while rk_valid: the same selection is not rebuilt (rows_select clears rk_valid) */
  unsigned char *rk_act;
  int *rk_bmode, rk_N, rk_valid;
  const void *rk_ncp;
  double *zfast;
  int *jump_in, *jump_out; /* per subsystem: a switch exactly at the step start (mode entering,
                              mode left), or -1 */
  fesd__violation *scan_buf; /* nsys */
  int step_flags;          /* FESD_FLAG_* of the current fesd_step */
  int nonunique; /* the step started on a surface that the fields on both sides leave */
  /* guess_fixed: the last fesd__consistent_guess solved every element's stage equations by
   * stage Newton (its result is then a fixed point of it); z0_fixed: so did the one that made
   * z0 in fesd__initial_guess (start_solve need not repeat it on an unchanged z0) */
  int guess_fixed, z0_fixed;
  int full_check;   /* tests: always check the start solve on the whole step system (step.c) */
  long n_certified; /* start solves certified on their V rows (step.c), since fesd_create */
  int last_sw, last_iter; /* the last accepted step: a switch step?, its iterations (stats) */
  int exit_pinned; /* the accepted sub-step's exits are pinned (exit rows on the plan path) */
  int plan_sets;   /* the accepted sub-step is a plan path solution: act holds its active sets */
  double exr_t0, exr_tb; /* start and exit time of the last exit the exit-time check rejected */
  unsigned char *act_prev; /* nth: the active set at the end of the last step (accept.c) */
  /* the switch plan of the current (sub)step and the active set after each switch (rows of
   * nth flags; only the switch's subsystem is used) */
  fesd__switch *plan;
  unsigned char *plan_after;
  int n_plan, cap_plan;
  int plan_peak; /* most subsystems switching in a plan of this attempt (fesd__plan_subsystems) */
  double merge_tol; /* switches of different subsystems closer than this share a boundary */
  int split_layout; /* k > 0: the layout splits elements longer than T / (N_FE 2^(k-1)) (after a
                     * failed solve; finer after a plan that came back) */
  unsigned long plan_sig[PLAN_SIGS]; /* signatures of the last plans of this attempt */
  double *bt;       /* boundary times of the layout (cap_plan + 2) */
  int *bseg;        /* elements per segment (cap_plan + 1) */
  double *hlo, *hhi; /* bounds of the element lengths of the layout (N_cap) */
  double *bseg_lo, *bseg_hi; /* per segment (cap_plan + 2) */
  /* records of the last accepted step (grown outside the Newton loop) */
  int cap_el, n_el;
  double *rec_h, *rec_t, *rec_x, *rec_th, *rec_la, *rec_mu, *rec_v;
  fesd_tableau tab, quad; /* the method, and a Gauss rule for dense output */
  double lag_inv[FESD_RK_MAX_STAGES]; /* 1 / prod_{m != j} (c_j - c_m): Lagrange basis of tab */
  /* interior checks: collocation weights at the midpoints between consecutive nodes
   * {0, c_j, 1} (fixed by the tableau, so computed once at create) */
  int n_mid;
  double mid_w[(FESD_RK_MAX_STAGES + 1) * FESD_RK_MAX_STAGES];
  double mid_tau[FESD_RK_MAX_STAGES + 1];
  int mid_stage[FESD_RK_MAX_STAGES + 1]; /* the stage nearest to each midpoint */
  int exc_off, exc_found; /* the excursion check switched off, and whether it found one (step.c) */
  /* the excursion check's nodes in time order: 0 (the element start), the stages (c_j > 0: at
   * exc_stage[j] >= 1, else -1) and the midpoints (at exc_mid[p]); exc_tau their times */
  int n_exc, exc_stage[FESD_RK_MAX_STAGES], exc_mid[FESD_RK_MAX_STAGES + 1];
  double exc_tau[2 * FESD_RK_MAX_STAGES + 2];
  /* error estimate (error.c): embedded weights (e0 on the field at the element start, e_j on
   * the stages), order of the estimate */
  int err_ok, err_q;
  double err_e0, err_e[FESD_RK_MAX_STAGES];
  double *err_atol; /* nx */
  /* error-controlled integration (integrate.c) */
  fesd_tolerances tol;
  double *tol_atol; /* nx */
  int have_tol, ec_on;
  double ec_rtol, h_next;
  fesd_event *log;
  int *log_pool;
  int log_n, log_cap;
  int ec_rejected;     /* error control: the last step attempt was rejected (no growth) */
  double ec_err_prev;  /* ... and the last accepted error estimate (PI control; 0: none) */
  double last_stop_t;    /* the time of the last stop (NaN: none since fesd_set_state) */
  signed char *stop_dir; /* per stop condition: the direction of its last stop (1 increasing,
                            -1 decreasing) until it crosses back, 0 then: its crossings in that
                            direction meanwhile are that stop (integrate.c, same_stop) */
  size_t log_pool_n, log_pool_cap;
  fesd_event *events; /* the last step's events: room for ev_max (accept.c grows it) */
  int n_events, ev_max;
  /* active-mode lists of the events (accept.c): ev_span = 2 x the largest n_modes ints per
   * event, ev_max ev_span ints */
  int *ev_pool, ev_span;
  fesd_stats stats;
  double sum_iter_ord, sum_iter_sw;
};

/* A model evaluation into the scratch buffers: fields, indicators and their state gradients
 * (valid until the next use of the scratch). */
static inline fesd__point_eval fesd__scratch_eval(const fesd_integrator *it) {
  fesd__point_eval pe = {0};
  pe.F = it->pscr.F;
  pe.g = it->pscr.g;
  pe.dgdx = it->pscr.dgdx;
  return pe;
}

/* w_j = int_0^tau l_j (Lagrange basis on the nodes c): the collocation polynomial of an
 * element is x_n + h sum_j w_j(tau) v_j. w has s entries. */
void fesd__colloc_weights(const fesd_integrator *it, double tau, double *w);
/* Fill n_mid, mid_tau, mid_w and mid_stage (verify_between.c). */
void fesd__interior_setup(fesd_integrator *it);
void fesd__save(fesd_integrator *it, fesd__saved *b);
void fesd__load(fesd_integrator *it, const fesd__saved *b);
/* Select the layout of N elements: the system's offsets and the solver workspace of N
 * (created at its first use). FESD_ERR_NOMEM / FESD_ERR_LINSOLVE from the creation. */
int fesd__use_level(fesd_integrator *it, int N);
/* The element count of the ladder that holds at least N elements (at most N_cap). */
int fesd__ladder(const fesd_integrator *it, int N);
/* Least value of the cubic Hermite interpolant on [0, 1] of p(0) = a, p(1) = b, p'(0) = da,
 * p'(1) = db, and where it lies (*tau); the first zero before tau of one with a > 0 >= p(tau)
 * (bisection to round-off). */
double fesd__hermite_min(double a, double b, double da, double db, double *tau);
double fesd__hermite_first_zero(double a, double b, double da, double db, double tau);
/* Graze check of an error-controlled step (graze.c). */
int fesd__graze_rates(fesd_integrator *it, const double *u, double *lam, double *rate, double *margin);
double fesd__slide_cap(const fesd_integrator *it, double hh, const double *m_a, const double *m_b);
/* The event log and stop conditions of error-controlled integration (event_log.c). A stop
 * condition that crossed back against its last stop's direction in the last step is armed
 * again (also after steps of plain fesd_step between integration calls). */
void fesd__rearm_stops(fesd_integrator *it);
/* The last step's events appended to the log (stopping: a stop ends the step, stop_up: its
 * direction; its own crossing is logged by fesd__take_stop). */
int fesd__log_events(fesd_integrator *it, int stopping, int stop_up);
/* The integration stops on condition k at the current time: FESD_ROOT (or the log's failure). */
int fesd__take_stop(fesd_integrator *it, int k, int dir, fesd_integrate_info *info);
/* The earliest stop condition the last step crossed after t_from in its direction, -1: none. */
int fesd__root_crossed(const fesd_integrator *it, double t_from, double *t_root, int *dir);
double fesd__graze_dip(const fesd_integrator *it, double hh, const double *lam_a, const double *rate_a,
                       const double *lam_b, const double *rate_b);
/* Whether the method has a collocation polynomial (dense output, interior checks). */
int fesd__collocation(const fesd_integrator *it);

#endif
