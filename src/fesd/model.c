#include "fesd/model.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int all_finite(const double *v, int n) {
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

/* Full enumeration: row i has -1 in column j iff bit (nc-1-j) of i is set. */
static void full_sign_matrix(signed char *S, int nf, int nc) {
  for (int i = 0; i < nf; i++)
    for (int j = 0; j < nc; j++) S[i * nc + j] = ((i >> (nc - 1 - j)) & 1) ? -1 : 1;
}

static int check_sign_matrix(const signed char *S, int nf, int nc) {
  for (int i = 0; i < nf * nc; i++)
    if (S[i] != 1 && S[i] != -1) return FESD_ERR_SIGN_MATRIX;
  for (int i = 0; i < nf; i++)
    for (int r = i + 1; r < nf; r++)
      if (memcmp(S + i * nc, S + r * nc, (size_t)nc) == 0) return FESD_ERR_SIGN_MATRIX;
  return FESD_OK;
}

void fesd__model_free(fesd__model *m) {
  if (!m) return;
  if (m->S)
    for (int k = 0; k < m->nsys; k++) free(m->S[k]);
  free(m->S);
  free(m->nf);
  free(m->nc);
  free(m->th_off);
  free(m->sys_of);
  free(m->xp);
  free(m->up);
  free(m->cbuf);
  free(m->cbuf2);
  free(m->dcbuf);
  free(m->dcubuf);
  free(m->fbuf);
  free(m->fbuf2);
  free(m->jxbuf);
  memset(m, 0, sizeof(*m));
}

int fesd__model_init(fesd__model *m, const fesd_model *u) {
  memset(m, 0, sizeof(*m));
  if (!u) return FESD_ERR_NULL;
  if (!u->field || !u->sw || !u->n_modes) return FESD_ERR_MODEL;
  if (u->nx < 1 || u->nu < 0 || u->nsys < 1) return FESD_ERR_MODEL;
  m->nx = u->nx;
  m->nu = u->nu;
  m->nsys = u->nsys;
  m->user = *u;
  int K = u->nsys, st = FESD_ERR_NOMEM;
  m->nf = calloc((size_t)K, sizeof(int));
  m->nc = calloc((size_t)K, sizeof(int));
  m->th_off = calloc((size_t)K + 1, sizeof(int));
  m->S = calloc((size_t)K, sizeof(*m->S));
  if (!m->nf || !m->nc || !m->th_off || !m->S) goto fail;
  for (int k = 0; k < K; k++) {
    int nf = u->n_modes[k], nc = u->n_switch ? u->n_switch[k] : 0;
    if (nf < 2 || nc < 0) {
      st = FESD_ERR_MODEL;
      goto fail;
    }
    const signed char *given = u->sign ? u->sign[k] : NULL;
    /* nc switching functions give 2^nc sign patterns: a full matrix needs nf == 2^nc, a
     * given one (distinct rows) nf <= 2^nc */
    if (nc > 30 || (nc > 0 && (given ? nf > (1 << nc) : nf != (1 << nc)))) {
      st = FESD_ERR_DIMENSION;
      goto fail;
    }
    m->nf[k] = nf;
    m->nc[k] = nc;
    m->th_off[k + 1] = m->th_off[k] + nf;
    if (nc > 0) {
      m->S[k] = malloc((size_t)nf * (size_t)nc);
      if (!m->S[k]) goto fail;
      if (given)
        memcpy(m->S[k], given, (size_t)nf * (size_t)nc);
      else
        full_sign_matrix(m->S[k], nf, nc);
      if ((st = check_sign_matrix(m->S[k], nf, nc)) != FESD_OK) goto fail;
    }
    int rows = nc > 0 ? nc : nf;
    if (rows > m->max_rows) m->max_rows = rows;
  }
  m->nth = m->th_off[K];
  st = FESD_ERR_NOMEM;
  m->sys_of = malloc((size_t)m->nth * sizeof(int));
  if (!m->sys_of) goto fail;
  for (int k = 0; k < K; k++)
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) m->sys_of[i] = k;
  size_t nx = (size_t)m->nx, nu = (size_t)(m->nu > 0 ? m->nu : 1), r = (size_t)m->max_rows;
  m->xp = malloc(nx * sizeof(double));
  m->up = malloc(nu * sizeof(double));
  m->cbuf = malloc(r * sizeof(double));
  m->cbuf2 = malloc(r * sizeof(double));
  m->dcbuf = malloc(r * nx * sizeof(double));
  m->dcubuf = malloc(r * nu * sizeof(double));
  m->fbuf = malloc(nx * sizeof(double));
  m->fbuf2 = malloc(nx * sizeof(double));
  m->jxbuf = malloc(nx * nx * sizeof(double));
  if (!m->xp || !m->up || !m->cbuf || !m->cbuf2 || !m->dcbuf || !m->dcubuf || !m->fbuf ||
      !m->fbuf2 || !m->jxbuf)
    goto fail;
  return FESD_OK;
fail:
  fesd__model_free(m);
  return st;
}

static int call_field(fesd__model *m, int k, int i, const double *x, const double *u, double *f) {
  if (m->user.field(k, i, x, u, f, m->user.user) != 0) {
    m->failed = "field";
    return FESD_ERR_CALLBACK;
  }
  if (!all_finite(f, m->nx)) {
    m->failed = "field";
    return FESD_ERR_NONFINITE;
  }
  return FESD_OK;
}

static int call_switch(fesd__model *m, int k, const double *x, const double *u, double *c) {
  int rows = m->nc[k] > 0 ? m->nc[k] : m->nf[k];
  if (m->user.sw(k, x, u, c, m->user.user) != 0) {
    m->failed = "switch";
    return FESD_ERR_CALLBACK;
  }
  if (!all_finite(c, rows)) {
    m->failed = "switch";
    return FESD_ERR_NONFINITE;
  }
  return FESD_OK;
}

/* g^k = -S^k c^k (or the indicators themselves), written to g + th_off[k]. */
static void indicators_from(const fesd__model *m, int k, const double *c, double *g) {
  int nf = m->nf[k], nc = m->nc[k];
  if (nc == 0) {
    memcpy(g, c, (size_t)nf * sizeof(double));
    return;
  }
  const signed char *S = m->S[k];
  for (int i = 0; i < nf; i++) {
    double s = 0;
    for (int j = 0; j < nc; j++) s -= S[i * nc + j] * c[j];
    g[i] = s;
  }
}

/* Row-space transform of a Jacobian block: out (nf x ncols, ld nth) = -S dc (nc x ncols). */
static void indicator_jac_from(const fesd__model *m, int k, const double *dc, int ncols, double *out,
                               int ldo) {
  int nf = m->nf[k], nc = m->nc[k];
  for (int col = 0; col < ncols; col++)
    for (int i = 0; i < nf; i++) {
      double s;
      if (nc == 0) {
        s = dc[col * nf + i];
      } else {
        s = 0;
        for (int j = 0; j < nc; j++) s -= m->S[k][i * nc + j] * dc[col * nc + j];
      }
      out[col * ldo + i] = s;
    }
}

/* Central difference step for coordinate value v: cbrt(eps) scaled (error ~ eps^(2/3)). */
static double fd_step(double v) { return 6.055454452393343e-06 * fmax(1.0, fabs(v)); }

int fesd__model_g(fesd__model *m, const double *x, const double *u, double *g) {
  for (int k = 0; k < m->nsys; k++) {
    int st = call_switch(m, k, x, u, m->cbuf);
    if (st) return st;
    indicators_from(m, k, m->cbuf, g + m->th_off[k]);
  }
  return FESD_OK;
}

static int eval_switch_jac(fesd__model *m, int k, const double *x, const double *u,
                           fesd__point_eval *o) {
  int nx = m->nx, nu = m->nu, rows = m->nc[k] > 0 ? m->nc[k] : m->nf[k], st;
  int want_u = o->dgdu && nu > 0;
  if (m->user.sw_jac) {
    if (m->user.sw_jac(k, x, u, m->dcbuf, want_u ? m->dcubuf : NULL, m->user.user) != 0) {
      m->failed = "switch_jac";
      return FESD_ERR_CALLBACK;
    }
    if (!all_finite(m->dcbuf, rows * nx) || (want_u && !all_finite(m->dcubuf, rows * nu))) {
      m->failed = "switch_jac";
      return FESD_ERR_NONFINITE;
    }
  } else {
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
        for (int r = 0; r < rows; r++)
          m->dcubuf[j * rows + r] = (m->cbuf[r] - m->cbuf2[r]) / (2 * hj);
      }
    }
  }
  if (o->dgdx) indicator_jac_from(m, k, m->dcbuf, nx, o->dgdx + m->th_off[k], m->nth);
  if (want_u) indicator_jac_from(m, k, m->dcubuf, nu, o->dgdu + m->th_off[k], m->nth);
  return FESD_OK;
}

static int eval_field_jac(fesd__model *m, int k, int i, int col, const double *x, const double *u,
                          fesd__point_eval *o) {
  int nx = m->nx, nu = m->nu, st;
  double *dfdx = o->dFdx ? o->dFdx + (size_t)col * nx * nx : NULL;
  double *dfdu = (o->dFdu && nu > 0) ? o->dFdu + (size_t)col * nx * nu : NULL;
  if (m->user.field_jac) {
    if (m->user.field_jac(k, i, x, u, dfdx ? dfdx : m->jxbuf, dfdu, m->user.user) != 0) {
      m->failed = "field_jac";
      return FESD_ERR_CALLBACK;
    }
    if ((dfdx && !all_finite(dfdx, nx * nx)) || (dfdu && !all_finite(dfdu, nx * nu))) {
      m->failed = "field_jac";
      return FESD_ERR_NONFINITE;
    }
    return FESD_OK;
  }
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

int fesd__model_eval(fesd__model *m, const double *x, const double *u, fesd__point_eval *o) {
  int st;
  for (int k = 0; k < m->nsys; k++) {
    for (int i = 0; i < m->nf[k]; i++) {
      int col = m->th_off[k] + i;
      if (o->F && (st = call_field(m, k, i, x, u, o->F + (size_t)col * m->nx))) return st;
      if ((o->dFdx || o->dFdu) && (st = eval_field_jac(m, k, i, col, x, u, o))) return st;
    }
    if (o->g) {
      if ((st = call_switch(m, k, x, u, m->cbuf))) return st;
      indicators_from(m, k, m->cbuf, o->g + m->th_off[k]);
    }
    if ((o->dgdx || o->dgdu) && (st = eval_switch_jac(m, k, x, u, o))) return st;
  }
  return FESD_OK;
}
