/* Evaluation of the model at one point: the mode fields, the Stewart indicators and their
 * Jacobians through the user's callbacks (finite differences for missing Jacobians of dense
 * models), every output checked (model.h). */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fesd/model.h"

/* Callback outputs are filled with this quiet NaN before the call. Arithmetic never creates
 * its payload (a NaN result carries the default payload or that of a NaN operand), so an
 * entry still bit-identical to it afterwards was not written (or was computed from an
 * unwritten output): the callback broke its contract, and the stale value it left must not
 * be used. */
#define UNWRITTEN_BITS 0x7ff8fe5d0badf00dULL

static void mark_unwritten(double *v, int n) {
  const uint64_t bits = UNWRITTEN_BITS;
  double s;
  memcpy(&s, &bits, sizeof s);
  for (int i = 0; i < n; i++) v[i] = s;
}

/* FESD_OK if the n outputs are finite; FESD_ERR_CALLBACK if one was not written (that
 * takes precedence), FESD_ERR_NONFINITE for another NaN or Inf. */
static int check_outputs(const double *v, int n) {
  uint64_t bad = 0; /* any exponent all ones (NaN, Inf, the mark): one pass without branches */
  for (int i = 0; i < n; i++) {
    uint64_t bits;
    memcpy(&bits, &v[i], sizeof bits);
    bad |= (bits & 0x7ff0000000000000ULL) == 0x7ff0000000000000ULL;
  }
  if (!bad) return FESD_OK;
  int st = FESD_OK;
  for (int i = 0; i < n; i++) {
    if (isfinite(v[i])) continue;
    uint64_t bits;
    memcpy(&bits, &v[i], sizeof bits);
    if (bits == UNWRITTEN_BITS) return FESD_ERR_CALLBACK;
    st = FESD_ERR_NONFINITE;
  }
  return st;
}

static int call_field(fesd__model *m, int k, int i, const double *x, const double *u, double *f) {
  mark_unwritten(f, m->nr[k]);
  int st = m->user.field(k, i, m->t, x, u, f, m->user.user) ? FESD_ERR_CALLBACK : check_outputs(f, m->nr[k]);
  if (st) m->failed = "field";
  return st;
}

static int call_switch(fesd__model *m, int k, const double *x, const double *u, double *c) {
  mark_unwritten(c, m->swr[k]);
  int st = m->user.sw(k, m->t, x, u, c, m->user.user) ? FESD_ERR_CALLBACK : check_outputs(c, m->swr[k]);
  if (st) m->failed = "switch";
  return st;
}

/* g^k = -S^k c^k (or the indicators themselves), written to g + th_off[k]. */
static void indicators_from(const fesd__model *m, int k, const double *c, double *g) {
  int nf = m->nf[k], nc = m->nc[k];
  if (nc == 0) {
    memcpy(g, c, (size_t)nf * sizeof(double));
    return;
  }
  const signed char *S = m->S[k];
  if (nc == 1) { /* one switching function (two modes): the same sums without the inner loop */
    for (int i = 0; i < nf; i++) {
      double s = 0;
      s -= S[i] * c[0];
      g[i] = s;
    }
    return;
  }
  for (int i = 0; i < nf; i++) {
    double s = 0;
    for (int j = 0; j < nc; j++) s -= S[i * nc + j] * c[j];
    g[i] = s;
  }
}

/* Central difference step: cbrt(eps) scaled (error ~ eps^(2/3)). */
static double fd_step(double v) { return 6.055454452393343e-06 * fmax(1.0, fabs(v)); }

int fesd__model_g(fesd__model *m, double t, const double *x, const double *u, double *g) {
  m->t = t;
  for (int k = 0; k < m->nsys; k++) {
    int st = call_switch(m, k, x, u, m->cbuf);
    if (st) return st;
    indicators_from(m, k, m->cbuf, g + m->th_off[k]);
  }
  return FESD_OK;
}

/* dc/dx on the pattern (dcbuf) and dc/du (dcubuf, swr x nu), by callback or central
 * differences (dense models: the pattern is column-major swr x nx). */
static int switch_derivatives(fesd__model *m, int k, const double *x, const double *u, int want_u) {
  int nx = m->nx, nu = m->nu, rows = m->swr[k], st;
  if (m->user.sw_jac) {
    const int nu_out = want_u ? rows * nu : 0;
    mark_unwritten(m->dcbuf, m->sj_nnz[k]);
    mark_unwritten(m->dcubuf, nu_out);
    st = m->user.sw_jac(k, m->t, x, u, m->dcbuf, want_u ? m->dcubuf : NULL, m->user.user) ? FESD_ERR_CALLBACK : 0;
    if (!st) st = check_outputs(m->dcbuf, m->sj_nnz[k]);
    if (!st) st = check_outputs(m->dcubuf, nu_out);
    if (st) m->failed = "switch_jac";
    return st;
  }
  memcpy(m->xp, x, (size_t)nx * sizeof(double));
  for (int j = 0; j < nx; j++) {
    double hj = fd_step(x[j]);
    m->xp[j] = x[j] + hj;
    if ((st = call_switch(m, k, m->xp, u, m->cbuf))) return st;
    m->xp[j] = x[j] - hj;
    if ((st = call_switch(m, k, m->xp, u, m->cbuf2))) return st;
    m->xp[j] = x[j];
    for (int r = 0; r < rows; r++) m->dcbuf[j * rows + r] = (m->cbuf[r] - m->cbuf2[r]) / (2 * hj);
  }
  if (want_u) {
    memcpy(m->up, u, (size_t)nu * sizeof(double));
    for (int j = 0; j < nu; j++) {
      double hj = fd_step(u[j]);
      m->up[j] = u[j] + hj;
      if ((st = call_switch(m, k, x, m->up, m->cbuf))) return st;
      m->up[j] = u[j] - hj;
      if ((st = call_switch(m, k, x, m->up, m->cbuf2))) return st;
      m->up[j] = u[j];
      for (int r = 0; r < rows; r++) m->dcubuf[j * rows + r] = (m->cbuf[r] - m->cbuf2[r]) / (2 * hj);
    }
  }
  return FESD_OK;
}

static int eval_switch_jac(fesd__model *m, int k, const double *x, const double *u,
                           fesd__point_eval *o) {
  const int nf = m->nf[k], nc = m->nc[k], nu = m->nu, want_u = o->dgdu && nu > 0;
  int st = switch_derivatives(m, k, x, u, want_u);
  if (st) return st;
  if (o->dgdx) {
    double *blk = o->dgdx + m->dgoff[k];
    memset(blk, 0, (size_t)nf * m->ncol[k] * sizeof(double));
    for (int e = 0; e < m->sj_nnz[k]; e++) {
      double v = m->dcbuf[e];
      double *col = blk + (size_t)m->sj_cp[k][e] * nf;
      int r = m->sj_r[k][e];
      if (nc == 0) col[r] += v;
      else
        for (int i = 0; i < nf; i++) col[i] -= m->S[k][i * nc + r] * v;
    }
  }
  if (want_u) {
    const int rows = m->swr[k], off = m->th_off[k], nth = m->nth;
    for (int c = 0; c < nu; c++)
      for (int i = 0; i < nf; i++) {
        double s = 0;
        if (nc == 0) s = m->dcubuf[c * rows + i];
        else
          for (int j = 0; j < nc; j++) s -= m->S[k][i * nc + j] * m->dcubuf[c * rows + j];
        o->dgdu[c * nth + off + i] = s;
      }
  }
  return FESD_OK;
}

/* Mode i's field Jacobians into o; by the callback (its outputs are marked and checked by
 * fesd__model_eval, for every mode at once; jxbuf takes df/dx when only df/du is wanted) or
 * by central differences. */
static int eval_field_jac(fesd__model *m, int k, int i, int col, const double *x, const double *u,
                          fesd__point_eval *o) {
  int nx = m->nx, nu = m->nu, st;
  double *dfdx = o->dFdx ? o->dFdx + m->dFoff[col] : NULL;
  double *dfdu = (o->dFdu && nu > 0) ? o->dFdu + m->Fuoff[col] : NULL;
  if (m->user.field_jac) {
    st = m->user.field_jac(k, i, m->t, x, u, dfdx ? dfdx : m->jxbuf, dfdu, m->user.user) ? FESD_ERR_CALLBACK : 0;
    if (st) m->failed = "field_jac";
    return st;
  }
  /* dense model: pattern = column-major nx x nx */
  if (dfdx) {
    memcpy(m->xp, x, (size_t)nx * sizeof(double));
    for (int j = 0; j < nx; j++) {
      double hj = fd_step(x[j]);
      m->xp[j] = x[j] + hj;
      if ((st = call_field(m, k, i, m->xp, u, m->fbuf))) return st;
      m->xp[j] = x[j] - hj;
      if ((st = call_field(m, k, i, m->xp, u, m->fbuf2))) return st;
      m->xp[j] = x[j];
      for (int r = 0; r < nx; r++) dfdx[j * nx + r] = (m->fbuf[r] - m->fbuf2[r]) / (2 * hj);
    }
  }
  if (dfdu) {
    memcpy(m->up, u, (size_t)nu * sizeof(double));
    for (int j = 0; j < nu; j++) {
      double hj = fd_step(u[j]);
      m->up[j] = u[j] + hj;
      if ((st = call_field(m, k, i, x, m->up, m->fbuf))) return st;
      m->up[j] = u[j] - hj;
      if ((st = call_field(m, k, i, x, m->up, m->fbuf2))) return st;
      m->up[j] = u[j];
      for (int r = 0; r < nx; r++) dfdu[j * nx + r] = (m->fbuf[r] - m->fbuf2[r]) / (2 * hj);
    }
  }
  return FESD_OK;
}

/* The fields and field Jacobians of every mode are marked before their calls and checked
 * after them, each kind in one pass over its contiguous block (per call, the loops' set-up
 * cost more than the checks: 4k of a 53k-instruction ordinary step of the oscillator). A
 * callback's error code still ends the evaluation at once; a non-finite or unwritten output
 * is reported after the fields' calls, named by its kind. */
int fesd__model_eval(fesd__model *m, double t, const double *x, const double *u, fesd__point_eval *o) {
  if (!o->F && !o->dFdx && !o->dFdu && !o->dgdx && !o->dgdu) return o->g ? fesd__model_g(m, t, x, u, o->g) : FESD_OK;
  m->t = t;
  int st;
  const int jac_cb = m->user.field_jac != NULL;
  double *const jx = jac_cb ? o->dFdx : NULL, *const ju = jac_cb && m->nu > 0 ? o->dFdu : NULL;
  if (o->F) mark_unwritten(o->F, m->nF);
  if (jx) mark_unwritten(jx, m->ndF);
  if (ju) mark_unwritten(ju, m->nFu);
  for (int k = 0; k < m->nsys; k++) {
    for (int i = 0; i < m->nf[k]; i++) {
      int col = m->th_off[k] + i;
      if (o->F && m->user.field(k, i, t, x, u, o->F + m->Foff[col], m->user.user)) {
        m->failed = "field";
        return FESD_ERR_CALLBACK;
      }
      if ((o->dFdx || o->dFdu) && (st = eval_field_jac(m, k, i, col, x, u, o))) return st;
    }
  }
  if (o->F && (st = check_outputs(o->F, m->nF))) {
    m->failed = "field";
    return st;
  }
  if ((jx && (st = check_outputs(jx, m->ndF))) || (ju && (st = check_outputs(ju, m->nFu)))) {
    m->failed = "field_jac";
    return st;
  }
  for (int k = 0; k < m->nsys; k++) {
    if (o->g) {
      if ((st = call_switch(m, k, x, u, m->cbuf))) return st;
      indicators_from(m, k, m->cbuf, o->g + m->th_off[k]);
    }
    if ((o->dgdx || o->dgdu) && (st = eval_switch_jac(m, k, x, u, o))) return st;
  }
  return FESD_OK;
}

int fesd__model_fields_active(fesd__model *m, double t, const double *x, const double *u, double *F,
                              const double *theta) {
  m->t = t;
  for (int i = 0; i < m->nth; i++) {
    if (theta[i] == 0.0) continue;
    const int k = m->sys_of[i];
    int st = call_field(m, k, i - m->th_off[k], x, u, F + m->Foff[i]);
    if (st) return st;
  }
  return FESD_OK;
}

void fesd__F_axpy(const fesd__model *m, const fesd__point_eval *pe, int i, double a, double *y) {
  const int k = m->sys_of[i], *rows = m->rows[k], nr = m->nr[k];
  const double *f = pe->F + m->Foff[i];
  for (int r = 0; r < nr; r++) y[rows[r]] += a * f[r];
}

double fesd__dg_dot(const fesd__model *m, const fesd__point_eval *pe, int i, const double *v) {
  const int k = m->sys_of[i], nf = m->nf[k], li = i - m->th_off[k], nc = m->ncol[k];
  const double *blk = pe->dgdx + m->dgoff[k];
  double s = 0;
  for (int c = 0; c < nc; c++) s += blk[(size_t)c * nf + li] * v[m->cols[k][c]];
  return s;
}

void fesd__dg_axpy(const fesd__model *m, const fesd__point_eval *pe, int i, double a, double *y) {
  const int k = m->sys_of[i], nf = m->nf[k], li = i - m->th_off[k], nc = m->ncol[k];
  const double *blk = pe->dgdx + m->dgoff[k];
  for (int c = 0; c < nc; c++) y[m->cols[k][c]] += a * blk[(size_t)c * nf + li];
}

void fesd__Jth(const fesd__model *m, const fesd__point_eval *pe, const double *theta, double *J) {
  memset(J, 0, (size_t)(m->pf_nnz > 0 ? m->pf_nnz : 1) * sizeof(double));
  for (int i = 0; i < m->nth; i++) {
    if (theta[i] == 0.0) continue;
    const int k = m->sys_of[i], n = m->fj_nnz[k], *map = m->fj_map[k];
    const double *d = pe->dFdx + m->dFoff[i], t = theta[i];
    for (int e = 0; e < n; e++) J[map[e]] += t * d[e];
  }
}

void fesd__pf_mv(const fesd__model *m, const double *J, const double *v, double *y) {
  memset(y, 0, (size_t)m->nx * sizeof(double));
  for (int p = 0; p < m->pf_nnz; p++) y[m->pf_r[p]] += J[p] * v[m->pf_c[p]];
}
