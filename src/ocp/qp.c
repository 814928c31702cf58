/* QP subproblems of the SQP as mixed complementarity problems for src/ncp.
 *
 * Normal QP:  min g'd + 1/2 d'(H + rp I)d  s.t.  c_E + J_E d = 0,  c_I + J_I d >= 0.
 * Unknowns (d, y, z); rows: stationarity H d + g - J_E'y - J_I'z = 0, equalities
 * c_E + J_E d + rd (y - y_k) = 0, pairs 0 <= z_j _|_ c_j + J_j d + rd (z_j - z_k,j) >= 0. The dual
 * proximal terms rd keep the system regular when constraints are degenerate and vanish at the
 * SQP fixed point (y = y_k).
 *
 * Elastic QP (the l1 penalty's QP, Fletcher's Sl1QP), used when the linearisation is
 * inconsistent: min g'd + 1/2 d'Hd + nu (sum p + n + sum t) with c_E + J_E d = p - n and
 * c_j + J_j d + t_j >= 0 (simple bounds stay hard). It is solved divided by nu (objective
 * scaled by 1/nu, unit penalty: the same solution, multipliers divided by nu, well scaled for
 * nu up to 1e10); the multipliers of p, n, t >= 0 are eliminated (1 + y, 1 - y, 1 - z), so the
 * pairs are (p, 1 + y), (n, 1 - y), (t, 1 - z). It is always consistent, and for nu larger than
 * the multipliers it has the normal QP's solution.
 *
 * Both systems are square; raw rows are affine in the unknowns: cst + sum val * z[col]. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/timer.h"
#include "ocp/ocp_internal.h"

typedef struct {
  fesd_ocp *o;
  ocp_qp *q;
  int mode, e;
  double rp, rd;     /* proximal terms */
  double ms;         /* multiplier scale: the FB pairs compare z / ms with c + J d */
  double sg;         /* objective scale (1, or 1 / nu for the elastic QP) */
  const ocp_point *pt;
} qemit;

static double inf_norm(const double *v, int n) {
  double m = 0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

static void qput(qemit *m, int r, int c, double v) {
  if (m->mode == EMIT_PATTERN) {
    m->q->row[m->e] = r;
    m->q->col[m->e] = c;
  } else if (m->mode == EMIT_VALUES) {
    m->q->val[m->e] = v;
  }
  m->e++;
}

/* offsets of the unknown groups */
typedef struct {
  int p, n, t, y, z, neq, np;
} qlay;

static qlay layout(const fesd_ocp *o, const ocp_qp *q) {
  const int nw = o->nw, mE = o->mE, mI = o->mI;
  qlay L;
  if (q->elastic) {
    L.p = nw, L.n = nw + mE, L.t = nw + 2 * mE, L.y = nw + 2 * mE + q->mIe, L.z = L.y + mE;
    L.np = 2 * mE + mI + q->mIe;
  } else {
    L.p = L.n = L.t = -1, L.y = nw, L.z = nw + mE;
    L.np = mI;
  }
  L.neq = nw + mE;
  return L;
}

/* raw row of pair j: a (first) or b (second) */
static int arow(const qlay *L, int j) { return L->neq + j; }
static int brow(const qlay *L, int j) { return L->neq + L->np + j; }

static void qp_emit(qemit *m) {
  fesd_ocp *o = m->o;
  ocp_qp *q = m->q;
  const int nb = o->nb, nx = o->nx, N = o->N, nw = o->nw, mE = o->mE, mI = o->mI, vals = m->mode == EMIT_VALUES;
  const qlay L = layout(o, q);
  const int zpair0 = q->elastic ? 2 * mE : 0; /* pair index of z_0 */
  /* Hessian blocks (dense) and the slacks' diagonal */
  for (int k = 0; k <= N; k++) {
    const int n = k < N ? nb : nx, off = k * nb;
    const double *B = o->B + (size_t)k * nb * nb;
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++) qput(m, off + i, off + j, vals ? m->sg * B[j * n + i] + (i == j ? m->rp : 0.0) : 0.0);
  }
  for (int j = N * nb + nx; j < nw; j++) qput(m, j, j, m->rp);
  /* constraint Jacobian: -J' in the stationarity rows, J in the constraint rows */
  for (int e = 0; e < o->nnzJ; e++) {
    const int r = o->jr[e], c = o->jc[e];
    const double v = vals ? m->pt->jv[e] : 0.0;
    if (r < mE) {
      qput(m, c, L.y + r, -v);
      qput(m, nw + r, c, v);
    } else {
      qput(m, c, L.z + (r - mE), -v);
      qput(m, brow(&L, zpair0 + r - mE), c, v);
    }
  }
  for (int r = 0; r < mE; r++) {
    qput(m, nw + r, L.y + r, m->rd);
    if (q->elastic) {
      qput(m, nw + r, L.p + r, -1.0);
      qput(m, nw + r, L.n + r, 1.0);
      qput(m, arow(&L, r), L.p + r, 1.0);       /* (p, (1 + y) / ms) */
      qput(m, brow(&L, r), L.y + r, 1.0 / m->ms);
      qput(m, arow(&L, mE + r), L.n + r, 1.0);  /* (n, (1 - y) / ms) */
      qput(m, brow(&L, mE + r), L.y + r, -1.0 / m->ms);
    }
  }
  for (int i = 0; i < mI; i++) {
    qput(m, arow(&L, zpair0 + i), L.z + i, 1.0 / m->ms);
    qput(m, brow(&L, zpair0 + i), L.z + i, m->rd);
  }
  for (int k = 0; k < q->mIe; k++) { /* (t, 1 - z) and t in its constraint */
    const int i = q->ie_map[k];
    qput(m, brow(&L, zpair0 + i), L.t + k, 1.0);
    qput(m, arow(&L, zpair0 + mI + k), L.t + k, 1.0);
    qput(m, brow(&L, zpair0 + mI + k), L.z + i, -1.0 / m->ms);
  }
}

static int qp_eval(const double *z, double *raw, double *jac, void *user) {
  ocp_qp *q = user;
  memcpy(raw, q->cst, (size_t)(q->n_eq + 2 * q->n_pair) * sizeof(double));
  for (int e = 0; e < q->nnz; e++) raw[q->row[e]] += q->val[e] * z[q->col[e]];
  if (jac) memcpy(jac, q->val, (size_t)q->nnz * sizeof(double));
  return 0;
}

void fesd__ocp_qp_free(ocp_qp *q) {
  fesd_ncp_free(&q->ncp);
  free(q->row);
  free(q->col);
  free(q->val);
  free(q->cst);
  free(q->z);
  free(q->ie_map);
  memset(q, 0, sizeof(*q));
}

int fesd__ocp_qp_setup(fesd_ocp *o, ocp_qp *q, int elastic) {
  memset(q, 0, sizeof(*q));
  q->elastic = elastic;
  if (elastic) {
    for (int i = 0; i < o->mI; i++) q->mIe += o->rows[o->mE + i].kind != ROW_XBND && o->rows[o->mE + i].kind != ROW_UBND;
    q->ie_map = malloc((size_t)(q->mIe > 0 ? q->mIe : 1) * sizeof(int));
    if (!q->ie_map) return FESD_ERR_NOMEM;
    for (int i = 0, k = 0; i < o->mI; i++)
      if (o->rows[o->mE + i].kind != ROW_XBND && o->rows[o->mE + i].kind != ROW_UBND) q->ie_map[k++] = i;
  }
  const qlay L = layout(o, q);
  q->n = L.z + o->mI;
  q->n_eq = L.neq;
  q->n_pair = L.np;
  qemit m = {o, q, EMIT_COUNT, 0, 0, 0, 1, 1, NULL};
  qp_emit(&m);
  q->nnz = m.e;
  const size_t nraw = (size_t)(q->n_eq + 2 * q->n_pair);
  q->row = malloc((size_t)q->nnz * sizeof(int));
  q->col = malloc((size_t)q->nnz * sizeof(int));
  q->val = calloc((size_t)q->nnz, sizeof(double));
  q->cst = calloc(nraw, sizeof(double));
  q->z = calloc((size_t)q->n, sizeof(double));
  if (!q->row || !q->col || !q->val || !q->cst || !q->z) return FESD_ERR_NOMEM;
  m = (qemit){o, q, EMIT_PATTERN, 0, 0, 0, 1, 1, NULL};
  qp_emit(&m);
  fesd_ncp_problem pr = {q->n, q->n_eq, q->n_pair, q->nnz, q->row, q->col, qp_eval, q};
  fesd_ncp_settings ns;
  fesd_ncp_settings_default(&ns);
  ns.max_iter = o->set.qp_max_iter;
  ns.backend = o->set.qp_backend;
  return fesd_ncp_setup(&q->ncp, &pr, &ns);
}

int fesd__ocp_qp_solve(fesd_ocp *o, ocp_qp *q, const ocp_point *pt, const double *c, double nu, double *d,
                       double *mult, double *vlin) {
  const double t0 = fesd__thread_cpu_time();
  const int nw = o->nw, mE = o->mE, mI = o->mI;
  const qlay L = layout(o, q);
  const int zpair0 = q->elastic ? 2 * mE : 0;
  const double sg = q->elastic ? 1.0 / nu : 1.0;
  double rp = o->set.reg_primal * sg * fesd__ocp_hessian_diag_max(o);
  if (rp < 1e-12) rp = 1e-12;
  /* multipliers are of the size of the gradient (elastic: at most 1); the FB function of a pair
   * (z, b) with z >> b behaves like the row b = 0 whatever z should be, and the Newton steps
   * stall: compare z / ms with b instead */
  double ms = fmax(1.0, sg * inf_norm(pt->grad, nw));
  for (int r = 0; r < mE + mI && !q->elastic; r++) ms = fmax(ms, fabs(o->y[r]));
  qemit m = {o, q, EMIT_VALUES, 0, rp, o->set.reg_dual, ms, sg, pt};
  qp_emit(&m);
  /* warm start: d = 0 and the current multipliers (scaled, clipped into the elastic box) */
  memset(q->z, 0, (size_t)q->n * sizeof(double));
  for (int r = 0; r < mE + mI; r++) {
    double v = sg * o->y[r];
    if (q->elastic) v = r < mE ? fmax(-1.0, fmin(1.0, v)) : fmin(1.0, v);
    q->z[r < mE ? L.y + r : L.z + (r - mE)] = v;
  }
  /* constants (the dual proximal terms are centred at the warm start); scale of the data */
  double scale = 1.0;
  memset(q->cst, 0, (size_t)(q->n_eq + 2 * q->n_pair) * sizeof(double));
  for (int j = 0; j < nw; j++) q->cst[j] = sg * pt->grad[j], scale = fmax(scale, fabs(q->cst[j]));
  for (int r = 0; r < mE; r++) q->cst[nw + r] = c[r] - m.rd * q->z[L.y + r], scale = fmax(scale, fabs(c[r]));
  for (int i = 0; i < mI; i++)
    q->cst[brow(&L, zpair0 + i)] = c[mE + i] - m.rd * q->z[L.z + i], scale = fmax(scale, fabs(c[mE + i]));
  if (q->elastic) {
    for (int r = 0; r < 2 * mE; r++) q->cst[brow(&L, r)] = 1.0 / ms;
    for (int k = 0; k < q->mIe; k++) q->cst[brow(&L, zpair0 + mI + k)] = 1.0 / ms;
  }
  fesd_ncp_settings ns;
  fesd_ncp_settings_default(&ns);
  ns.max_iter = o->set.qp_max_iter;
  ns.tol = fmin(1e-1, fmax(1e-16, o->set.qp_tol * scale));
  fesd_ncp_update_settings(q->ncp, &ns);
  fesd_ncp_info ni;
  int st = fesd_ncp_solve(q->ncp, q->z, 0.0, &ni);
  q->iterations = ni.iterations;
  if (st && q->elastic && st != FESD_ERR_NOMEM && st != FESD_ERR_CALLBACK) {
    /* the smoothing homotopy from the same warm start (degenerate QPs); a normal QP that fails
     * is most likely inconsistent and goes to the elastic QP instead */
    memset(q->z, 0, (size_t)q->n * sizeof(double));
    for (int r = 0; r < mE + mI; r++) {
      double v = sg * o->y[r];
      if (q->elastic) v = r < mE ? fmax(-1.0, fmin(1.0, v)) : fmin(1.0, v);
      q->z[r < mE ? L.y + r : L.z + (r - mE)] = v;
    }
    st = fesd_ncp_solve_homotopy(q->ncp, q->z, &ni);
    q->iterations += ni.iterations;
  }
  q->ncp_status = st;
  o->info.qp_iterations += q->iterations;
  o->t_qp += fesd__thread_cpu_time() - t0;
  if (st) return st;
  memcpy(d, q->z, (size_t)nw * sizeof(double));
  for (int r = 0; r < mE; r++) mult[r] = q->z[L.y + r] / sg;
  for (int i = 0; i < mI; i++) mult[mE + i] = q->z[L.z + i] / sg;
  if (vlin) {
    fesd__ocp_jmul(o, pt, d, o->tmp);
    if (c != pt->c) /* second-order correction: c replaces pt->c */
      for (int r = 0; r < mE + mI; r++) o->tmp[r] += c[r] - pt->c[r];
    *vlin = fesd__ocp_violation(o, o->tmp);
  }
  return FESD_OK;
}
