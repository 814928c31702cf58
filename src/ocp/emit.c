/* Constraints of the multiple shooting NLP and their Jacobian. One routine serves three
 * purposes so that the pattern and the values can never disagree: counting rows and entries,
 * recording the pattern and row kinds (at setup), and evaluating values and Jacobian entries at
 * a point (the interval simulations are done before, eval.c). */
#include <math.h>
#include <string.h>

#include "ocp/ocp_internal.h"

typedef struct {
  fesd_ocp *o;
  ocp_point *pt;
  int mode, nE, nI, e;
} emitter;

static int new_row(emitter *m, int eq, int kind, int sign, int idx) {
  int r = eq ? m->nE++ : m->o->mE + m->nI++;
  if (m->mode == EMIT_PATTERN) m->o->rows[r] = (ocp_row){(unsigned char)kind, (signed char)sign, idx};
  return r;
}

static void put(emitter *m, int r, int c, double v) {
  if (m->mode == EMIT_PATTERN) {
    m->o->jr[m->e] = r;
    m->o->jc[m->e] = c;
  } else if (m->mode == EMIT_VALUES) {
    m->pt->jv[m->e] = v;
  }
  m->e++;
}

static void set_c(emitter *m, int r, double v) {
  if (m->mode == EMIT_VALUES) m->pt->c[r] = v;
}

/* rows of a vector function g (n values in o->fv, Jacobians in o->fx (n x nx) at state columns
 * cx and o->fu (n x nu) at control columns cu, cu < 0: none) with bounds [lb, ub]: equality
 * where lb == ub, else one inequality per finite side */
static void bounded_rows(emitter *m, int kind, int idx0, int n, const double *lb, const double *ub, int cx,
                         int cu) {
  fesd_ocp *o = m->o;
  const int nx = o->nx, nu = o->nu, vals = m->mode == EMIT_VALUES;
  for (int i = 0; i < n; i++) {
    const double g = vals ? o->fv[i] : 0.0;
    for (int side = 0; side < 2; side++) {
      const int eq = lb[i] == ub[i];
      if (eq && side == 1) break;
      const double b = side == 0 ? lb[i] : ub[i];
      if (!isfinite(b)) continue;
      const double sg = side == 0 ? 1.0 : -1.0;
      const int r = new_row(m, eq, kind, side == 0 ? 1 : -1, idx0 + i);
      for (int j = 0; j < nx; j++) put(m, r, cx + j, vals ? sg * o->fx[(size_t)j * n + i] : 0.0);
      if (cu >= 0)
        for (int j = 0; j < nu; j++) put(m, r, cu + j, vals ? sg * o->fu[(size_t)j * n + i] : 0.0);
      set_c(m, r, sg * (g - b));
    }
  }
}

int fesd__ocp_emit(fesd_ocp *o, ocp_point *pt, int mode) {
  const fesd_ocp_problem *p = &o->p;
  const int nx = o->nx, nu = o->nu, nb = o->nb, N = o->N, vals = mode == EMIT_VALUES;
  const double *w = vals ? pt->w : NULL;
  emitter m = {o, pt, mode, 0, 0, 0};
  int st;
  /* x_0 = x0 on the fixed components */
  for (int i = 0; i < nx; i++) {
    if (o->x0_free[i]) continue;
    int r = new_row(&m, 1, ROW_INIT, 1, i);
    put(&m, r, i, 1.0);
    set_c(&m, r, vals ? w[i] - o->x0[i] : 0.0);
  }
  /* continuity: Phi_k(x_k, q_k) - x_{k+1} = 0 */
  for (int k = 0; k < N; k++) {
    const double *Sx = vals ? pt->Sx + (size_t)k * nx * nx : NULL, *Su = vals ? pt->Su + (size_t)k * nx * nu : NULL;
    for (int i = 0; i < nx; i++) {
      int r = new_row(&m, 1, ROW_DYN, 1, k * nx + i);
      for (int j = 0; j < nx; j++) put(&m, r, k * nb + j, vals ? Sx[(size_t)j * nx + i] : 0.0);
      for (int j = 0; j < nu; j++) put(&m, r, k * nb + nx + j, vals ? Su[(size_t)j * nx + i] : 0.0);
      put(&m, r, (k + 1) * nb + i, -1.0);
      set_c(&m, r, vals ? pt->phi[k * nx + i] - w[(k + 1) * nb + i] : 0.0);
    }
  }
  /* simple bounds on x_k and q_k (hard in the elastic QP) */
  for (int k = 0; k <= N; k++) {
    for (int i = 0; i < nx + (k < N ? nu : 0); i++) {
      const int j = k * nb + i, isx = i < nx;
      const int kind = isx ? ROW_XBND : ROW_UBND, idx = isx ? k * nx + i : k * nu + (i - nx);
      if (isfinite(o->lb[j])) {
        int r = new_row(&m, 0, kind, 1, idx);
        put(&m, r, j, 1.0);
        set_c(&m, r, vals ? w[j] - o->lb[j] : 0.0);
      }
      if (isfinite(o->ub[j])) {
        int r = new_row(&m, 0, kind, -1, idx);
        put(&m, r, j, -1.0);
        set_c(&m, r, vals ? o->ub[j] - w[j] : 0.0);
      }
    }
  }
  /* path constraints at every boundary (q_N := q_{N-1}) */
  for (int k = 0; k <= N && p->n_path > 0; k++) {
    const int kq = k < N ? k : N - 1, cu = nu > 0 ? kq * nb + nx : -1;
    if (vals && (st = fesd__ocp_call(o, p->path, p->n_path, p->t0 + k * o->T, w + k * nb, w + kq * nb + nx, 1)))
      return st;
    bounded_rows(&m, ROW_PATH, k * p->n_path, p->n_path, o->path_lb, o->path_ub, k * nb, cu);
  }
  const int cN = N * nb;
  if (p->n_term > 0) {
    if (vals && (st = fesd__ocp_call(o, p->terminal, p->n_term, p->tf, w + cN, NULL, 1))) return st;
    bounded_rows(&m, ROW_TERM, 0, p->n_term, o->term_lb, o->term_ub, cN, -1);
  }
  /* L1 terms: r1_i + e_i >= 0 and e_i - r1_i >= 0 */
  if (p->n_l1 > 0) {
    const int n = p->n_l1;
    if (vals && (st = fesd__ocp_call(o, p->l1, n, p->tf, w + cN, NULL, 1))) return st;
    for (int i = 0; i < n; i++)
      for (int side = 0; side < 2; side++) {
        const double sg = side == 0 ? 1.0 : -1.0;
        int r = new_row(&m, 0, ROW_L1, side == 0 ? 1 : -1, i);
        for (int j = 0; j < nx; j++) put(&m, r, cN + j, vals ? sg * o->fx[(size_t)j * n + i] : 0.0);
        put(&m, r, cN + nx + i, 1.0);
        set_c(&m, r, vals ? sg * o->fv[i] + w[cN + nx + i] : 0.0);
      }
  }
  if (mode == EMIT_COUNT) {
    o->mE = m.nE;
    o->mI = m.nI;
    o->nnzJ = m.e;
  }
  return FESD_OK;
}
