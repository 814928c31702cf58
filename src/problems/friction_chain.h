/* A chain of n unit masses with unit springs (mass 0 tied to a wall, the last end free)
 * on a belt moving at speed vb, with Coulomb friction mu sign(v_i - vb) on every mass:
 * n independent switching subsystems (paper Sec. 2.3), stick phases are sliding modes.
 * Declared with the sparse model API, so its step cost grows linearly in n. */
#ifndef FESD_FRICTION_CHAIN_H
#define FESD_FRICTION_CHAIN_H

#include "fesd_integrator.h"

typedef struct {
  int n;
  double k, mu, vb;
  fesd_model model;        /* x = (q_0..q_{n-1}, v_0..v_{n-1}) */
  int *n_modes, *n_switch; /* [n] */
  fesd_sparsity *sp;       /* [n] */
  int *rows0, *jr0, *jc0, *rows, *swr, *swc;
  double *x0;              /* initial state: q_i = 0.1 sin(1.3 i + 0.4), v = 0 */
} fesd_friction_chain;

/* vb: belt speed (a large vb keeps every mass slipping: no switches) */
int fesd_friction_chain_init(fesd_friction_chain *fc, int n, double vb);
/* The stick-slip chain: a slow belt (vb = 0.2) and displacements q_i(0) = sin(1.3 i + 0.4),
 * v(0) = 0, so that masses stick and slip at different times (many switches per step of
 * length 0.2 once n is large). */
int fesd_friction_chain_stick_slip(fesd_friction_chain *fc, int n);
void fesd_friction_chain_free(fesd_friction_chain *fc);

#endif
