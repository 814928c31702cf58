/* Internal definition of the integrator object (src/fesd). */
#ifndef FESD_INTEGRATOR_INTERNAL_H
#define FESD_INTEGRATOR_INTERNAL_H

#include <stddef.h>

#include "fesd/model.h"
#include "fesd/system.h"
#include "fesd_integrator.h"
#include "fesd_ncp.h"

#define FESD_MAX_EVENTS_PER_STEP 256

/* A saved state (integrator.c): the step start, restored when fesd_step fails, and the start
 * of a sub-step attempt, restored before halving (a failure inside accept, e.g. a callback
 * at the new state, can leave the state half-updated). */
typedef struct {
  double t, *x, *lam, *th, *zws, *Sx, *Su, *ldp;
  int have_ws, have_prev_theta, n_el, n_events;
} fesd__saved;

struct fesd_integrator {
  fesd_settings set;
  fesd__model model;
  fesd__system sys;
  fesd_ncp *ncp;
  int n, nx, nu, nth, nsys, N, s, np;
  /* current state */
  double t;
  double *x, *lam00, *theta_prev, *u_cur;
  int have_state, have_ws, have_prev_theta;
  /* step data */
  double *z, *zws, *z0, *zpred, *raw, *jac, *lb, *ub;
  unsigned char *eq_active, *pair_mode;
  fesd__saved bk, bk_sub; /* step start, sub-step start */
  /* sensitivities */
  double *Sx, *Su, *draw, *dz, *Dtmp, *Stmp;
  double *gbuf, *blk, *vtmp; /* vtmp: 2 nx */
  fesd__point_eval pscr;     /* scratch model evaluation */
  double *pt_t, *pt_q, *pt_l; /* switch prediction: point times and q values */
  int *pt_src, *kb, *sw_at;
  /* active-set path */
  unsigned char *act, *act0, *cand;
  int *bmode, *exit_mode;
  double *zfast;
  int jump_in, jump_out; /* switch exactly at the step start (mode entering, mode left), or -1 */
  /* records of the last accepted step */
  int cap_el, n_el;
  double *rec_h, *rec_t, *rec_x, *rec_th, *rec_la, *rec_mu, *rec_v;
  fesd_tableau tab, quad; /* the method, and a Gauss rule for dense output */
  /* interior sign check: collocation weights at the midpoints between consecutive
   * nodes {0, c_j, 1} (fixed by the tableau, so computed once at create) */
  int n_mid;
  double mid_w[(FESD_RK_MAX_STAGES + 1) * FESD_RK_MAX_STAGES];
  fesd_event events[FESD_MAX_EVENTS_PER_STEP];
  int n_events;
  /* active-mode lists of the events (accept.c): ev_span = 2 x the largest n_modes ints per
   * event, ev_cap = FESD_MAX_EVENTS_PER_STEP ev_span, allocated at create */
  int *ev_pool, ev_span;
  size_t ev_cap;
  fesd_stats stats;
  double sum_iter_ord, sum_iter_sw;
};

/* w_j = int_0^tau l_j (Lagrange basis on the nodes c): the collocation polynomial of an
 * element is x_n + h sum_j w_j(tau) v_j. w has s entries. */
void fesd__colloc_weights(const fesd_integrator *it, double tau, double *w);
/* Fill n_mid and mid_w (active.c). */
void fesd__interior_setup(fesd_integrator *it);
void fesd__save(fesd_integrator *it, fesd__saved *b);
void fesd__load(fesd_integrator *it, const fesd__saved *b);

#endif
