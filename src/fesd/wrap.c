/* The internal model (wrap.h): time as a state, the drift as a one-mode subsystem, stop
 * conditions as two-mode subsystems with zero fields. */
#include "fesd/wrap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* central-difference step for t (cbrt(eps), scaled) */
static double fd_step(double v) { return 6.055454452393343e-06 * (fabs(v) > 1 ? fabs(v) : 1); }

static double tval(const fesd__wrap *w, double t, const double *x) { return w->td ? x[w->nx] : t; }

/* rows of internal subsystem k's field (sparse layout), and their count */
static int rows_of(const fesd__wrap *w, int k) { return w->sparse ? w->sp[k].n_rows : w->nxi; }

static int user_field(fesd__wrap *w, int k, int i, double t, const double *x, const double *u, double *f) {
  const fesd_model *m = &w->user;
  if (k < w->K) {
    int rc = m->field(k, i, t, x, u, f, m->user);
    if (!w->sparse && w->td) f[w->nx] = 0.0;
    return rc;
  }
  const int nr = rows_of(w, k);
  if (k == w->kd) {
    int rc = 0;
    if (m->drift) rc = m->drift(t, x, u, f, m->user);
    else memset(f, 0, (size_t)nr * sizeof(double));
    if (w->td) f[nr - 1] = 1.0; /* the clock row is the last one (it is the last state) */
    return rc;
  }
  memset(f, 0, (size_t)(nr > 0 ? nr : 0) * sizeof(double));
  return 0;
}

static int w_field(int k, int i, double t, const double *x, const double *u, double *f, void *ud) {
  fesd__wrap *w = ud;
  return user_field(w, k, i, tval(w, t, x), x, u, f);
}

static int w_sw(int k, double t, const double *x, const double *u, double *c, void *ud) {
  fesd__wrap *w = ud;
  const fesd_model *m = &w->user;
  const double te = tval(w, t, x);
  if (k < w->K) return m->sw(k, te, x, u, c, m->user);
  if (k == w->kd) {
    c[0] = 0.0; /* one mode: its indicator */
    return 0;
  }
  int rc = m->roots(te, x, u, w->rb, m->user);
  c[0] = w->rb[k - w->kr];
  return rc;
}

/* df/dt of internal subsystem k's mode i by central differences (nr values into d) */
static int field_dt(fesd__wrap *w, int k, int i, double te, const double *x, const double *u, double *d) {
  const int nr = rows_of(w, k);
  const double dt = fd_step(te);
  int rc = user_field(w, k, i, te + dt, x, u, w->fb);
  if (!rc) rc = user_field(w, k, i, te - dt, x, u, w->fb2);
  for (int r = 0; r < nr; r++) d[r] = (w->fb[r] - w->fb2[r]) / (2 * dt);
  return rc;
}

/* Jacobians (present when the user gives field_jac): the user's block, the t column by
 * central differences, zero rows for the clock; the drift by drift_jac or central differences
 * in x; roots have zero fields. */
static int w_field_jac(int k, int i, double t, const double *x, const double *u, double *J, double *Ju, void *ud) {
  fesd__wrap *w = ud;
  const fesd_model *m = &w->user;
  const double te = tval(w, t, x);
  const int nx = w->nx, nxi = w->nxi, nu = m->nu, nr = rows_of(w, k);
  int rc = 0;
  if (w->sparse) {
    const fesd_sparsity *sp = &w->sp[k];
    const int nj_user = sp->jac_nnz - (w->td ? nr - (k == w->kd) : 0);
    if (k < w->K) rc = m->field_jac(k, i, te, x, u, J, Ju, m->user);
    else if (k == w->kd && m->drift) {
      /* the drift's du block has its own rows (without the clock row): remap */
      rc = m->drift_jac(te, x, u, J, Ju ? w->ub : NULL, m->user);
      const int ur = nr - w->td;
      if (!rc && Ju)
        for (int c = 0; c < nu; c++)
          for (int r = 0; r < nr; r++) Ju[(size_t)c * nr + r] = r < ur ? w->ub[(size_t)c * ur + r] : 0.0;
    }
    else {
      memset(J, 0, (size_t)(nj_user > 0 ? nj_user : 0) * sizeof(double));
      if (Ju) memset(Ju, 0, (size_t)nr * nu * sizeof(double));
    }
    if (!rc && w->td) {
      rc = field_dt(w, k, i, te, x, u, w->jb);
      const int nrt = nr - (k == w->kd); /* the clock row has no t dependence */
      for (int r = 0; r < nrt; r++) J[nj_user + r] = w->jb[r];
    }
    return rc;
  }
  /* dense: user block nx x nx (leading dimension nx) into nxi x nxi */
  memset(J, 0, (size_t)nxi * nxi * sizeof(double));
  double *ju = w->jb;
  if (k < w->K) rc = m->field_jac(k, i, te, x, u, ju, Ju ? w->ub : NULL, m->user);
  else if (k == w->kd && m->drift && m->drift_jac) rc = m->drift_jac(te, x, u, ju, Ju ? w->ub : NULL, m->user);
  else if (k == w->kd && m->drift) { /* central differences in x */
    memcpy(w->xb, x, (size_t)nxi * sizeof(double));
    for (int c = 0; c < nx && !rc; c++) {
      const double hc = fd_step(x[c]);
      w->xb[c] = x[c] + hc;
      rc = m->drift(te, w->xb, u, w->fb, m->user);
      w->xb[c] = x[c] - hc;
      if (!rc) rc = m->drift(te, w->xb, u, w->fb2, m->user);
      w->xb[c] = x[c];
      for (int r = 0; r < nx; r++) ju[(size_t)c * nx + r] = (w->fb[r] - w->fb2[r]) / (2 * hc);
    }
    if (Ju) memset(w->ub, 0, (size_t)nx * nu * sizeof(double)); /* drift_jac absent: no u part */
  } else {
    memset(ju, 0, (size_t)nx * nx * sizeof(double));
    if (Ju) memset(w->ub, 0, (size_t)nx * nu * sizeof(double));
  }
  if (rc) return rc;
  for (int c = 0; c < nx; c++)
    for (int r = 0; r < nx; r++) J[(size_t)c * nxi + r] = ju[(size_t)c * nx + r];
  if (Ju) {
    memset(Ju, 0, (size_t)nxi * nu * sizeof(double));
    for (int c = 0; c < nu; c++)
      for (int r = 0; r < nx; r++) Ju[(size_t)c * nxi + r] = w->ub[(size_t)c * nx + r];
  }
  if (w->td) {
    rc = field_dt(w, k, i, te, x, u, w->jb);
    for (int r = 0; r < nx; r++) J[(size_t)nx * nxi + r] = w->jb[r];
  }
  return rc;
}

/* Switch Jacobians: user block plus the t column (central differences); the drift's constant
 * indicator has none; roots by central differences in x (and t). */
static int w_sw_jac(int k, double t, const double *x, const double *u, double *J, double *Ju, void *ud) {
  fesd__wrap *w = ud;
  const fesd_model *m = &w->user;
  const double te = tval(w, t, x);
  const int nx = w->nx, nxi = w->nxi, nu = m->nu;
  if (k == w->kd) {
    if (!w->sparse) memset(J, 0, (size_t)nxi * sizeof(double));
    if (Ju) memset(Ju, 0, (size_t)nu * sizeof(double));
    return 0;
  }
  int rc = 0;
  if (k < w->K) {
    const int rows = m->n_switch && m->n_switch[k] > 0 ? m->n_switch[k] : m->n_modes[k];
    if (w->sparse) {
      rc = m->sw_jac(k, te, x, u, J, Ju, m->user);
      if (!rc && w->td) {
        const int base = w->sp[k].sw_nnz - rows;
        const double dt = fd_step(te);
        rc = m->sw(k, te + dt, x, u, w->fb, m->user);
        if (!rc) rc = m->sw(k, te - dt, x, u, w->fb2, m->user);
        for (int q = 0; q < rows; q++) J[base + q] = (w->fb[q] - w->fb2[q]) / (2 * dt);
      }
      return rc;
    }
    rc = m->sw_jac(k, te, x, u, w->jb, Ju, m->user); /* rows x nx, column-major */
    if (rc) return rc;
    memcpy(J, w->jb, (size_t)rows * nx * sizeof(double));
    if (w->td) {
      const double dt = fd_step(te);
      rc = m->sw(k, te + dt, x, u, w->fb, m->user);
      if (!rc) rc = m->sw(k, te - dt, x, u, w->fb2, m->user);
      for (int q = 0; q < rows; q++) J[(size_t)nx * rows + q] = (w->fb[q] - w->fb2[q]) / (2 * dt);
    }
    return rc;
  }
  /* root: dr/dx (and dr/dt) by central differences; the root functions do not see u */
  const int j = k - w->kr, ncol = w->sparse ? w->sp[k].sw_nnz : nxi;
  memcpy(w->xb, x, (size_t)nxi * sizeof(double));
  for (int c = 0; c < ncol && !rc; c++) {
    const int col = w->sparse ? w->sp[k].sw_col[c] : c;
    const double hc = fd_step(x[col]);
    double tp = te, tm = te;
    if (col < nx) w->xb[col] = x[col] + hc;
    else tp = te + hc;
    rc = m->roots(tp, w->xb, u, w->rb, m->user);
    if (col < nx) w->xb[col] = x[col] - hc;
    else tm = te - hc;
    if (!rc) rc = m->roots(tm, w->xb, u, w->rb2, m->user);
    if (col < nx) w->xb[col] = x[col];
    J[c] = (w->rb[j] - w->rb2[j]) / (2 * hc);
  }
  if (Ju) memset(Ju, 0, (size_t)nu * sizeof(double));
  return rc;
}

void fesd__wrap_free(fesd__wrap *w) {
  if (!w) return;
  if (w->ia) {
    const int K = w->K + (w->kd >= 0) + w->nr;
    for (int q = 0; q < 5 * K; q++) free(w->ia[q]);
    free(w->ia);
  }
  void *p[] = {w->n_modes, w->n_switch, w->sign, w->sp, w->xb, w->fb, w->fb2, w->jb, w->rb, w->rb2, w->ub};
  for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) free(p[i]);
  memset(w, 0, sizeof(*w));
}

static int *ints(int n, int *fail) {
  int *p = malloc((size_t)(n > 0 ? n : 1) * sizeof(int));
  if (!p) *fail = 1;
  return p;
}

/* Sparse patterns of the internal subsystems: the user's with the t column appended (one
 * entry per field row, one per switching function), the drift's (dense when no pattern is
 * given) with the clock row last, the roots' (no field rows; dr/dx dense). */
static int sparse_patterns(fesd__wrap *w, int Ki) {
  const fesd_model *m = &w->user;
  const int nx = w->nx, t = w->td;
  int fail = 0;
  for (int k = 0; k < Ki && !fail; k++) {
    int nr, nj, ns;
    const fesd_sparsity *us = k < w->K ? &m->sparsity[k] : k == w->kd ? m->drift_sparsity : NULL;
    if (k < w->K) {
      const int rows = m->n_switch && m->n_switch[k] > 0 ? m->n_switch[k] : m->n_modes[k];
      nr = us->n_rows, nj = us->jac_nnz + (t ? nr : 0), ns = us->sw_nnz + (t ? rows : 0);
    } else if (k == w->kd) {
      const int ur = us ? us->n_rows : nx;
      nr = ur + t, nj = (us ? us->jac_nnz : nx * nx) + (t ? ur : 0), ns = 0;
    } else {
      nr = 0, nj = 0, ns = nx + t;
    }
    int **a = w->ia + 5 * k;
    for (int q = 0; q < 5; q++) a[q] = ints(q == 0 ? nr : q < 3 ? nj : ns, &fail);
    if (fail) break;
    int e = 0;
    if (k < w->K) {
      const int rows = ns - us->sw_nnz;
      memcpy(a[0], us->rows, (size_t)nr * sizeof(int));
      memcpy(a[1], us->jac_row, (size_t)us->jac_nnz * sizeof(int));
      memcpy(a[2], us->jac_col, (size_t)us->jac_nnz * sizeof(int));
      for (e = us->jac_nnz; e < nj; e++) a[1][e] = e - us->jac_nnz, a[2][e] = nx;
      memcpy(a[3], us->sw_row, (size_t)us->sw_nnz * sizeof(int));
      memcpy(a[4], us->sw_col, (size_t)us->sw_nnz * sizeof(int));
      for (e = us->sw_nnz; e < ns; e++) a[3][e] = e - us->sw_nnz, a[4][e] = nx;
      (void)rows;
    } else if (k == w->kd) {
      const int ur = nr - t;
      for (int r = 0; r < ur; r++) a[0][r] = us ? us->rows[r] : r;
      if (t) a[0][ur] = nx;
      if (us) {
        memcpy(a[1], us->jac_row, (size_t)us->jac_nnz * sizeof(int));
        memcpy(a[2], us->jac_col, (size_t)us->jac_nnz * sizeof(int));
        e = us->jac_nnz;
      } else {
        for (int c = 0; c < nx; c++)
          for (int r = 0; r < nx; r++) a[1][e] = r, a[2][e++] = c;
      }
      for (int r = 0; r < ur && t; r++) a[1][e] = r, a[2][e++] = nx;
    } else {
      for (int c = 0; c < ns; c++) a[3][c] = 0, a[4][c] = c;
    }
    w->sp[k] = (fesd_sparsity){nr, a[0], nj, a[1], a[2], ns, a[3], a[4]};
  }
  return fail ? FESD_ERR_NOMEM : FESD_OK;
}

int fesd__wrap_init(fesd__wrap *w, const fesd_model *user, fesd_model *internal) {
  memset(w, 0, sizeof(*w));
  *internal = *user;
  const int td = user->time_dependent != 0, nr = user->n_roots > 0 ? user->n_roots : 0;
  if (user->n_roots < 0 || (nr > 0 && !user->roots)) return FESD_ERR_MODEL;
  for (int i = 0; i < nr && user->root_dir; i++) /* -1, 0, +1 only (2 or -7 were taken by sign) */
    if (user->root_dir[i] < -1 || user->root_dir[i] > 1) return FESD_ERR_MODEL;
  if (user->time_dependent != 0 && user->time_dependent != 1) return FESD_ERR_MODEL;
  if (user->sparsity && user->drift && !user->drift_jac) return FESD_ERR_MODEL;
  if (!td && !user->drift && nr == 0) return FESD_OK;
  if (user->nx < 1 || user->nsys < 1 || !user->n_modes || !user->field || !user->sw) return FESD_ERR_MODEL;
  w->active = 1;
  w->user = *user;
  w->nx = user->nx;
  w->td = td;
  w->nxi = user->nx + td;
  w->K = user->nsys;
  w->kd = (td || user->drift) ? w->K : -1;
  w->kr = w->K + (w->kd >= 0);
  w->nr = nr;
  w->sparse = user->sparsity != NULL;
  const int Ki = w->kr + nr, nxi = w->nxi, nu = user->nu > 0 ? user->nu : 1;
  int fail = 0;
  w->n_modes = ints(Ki, &fail);
  w->n_switch = ints(Ki, &fail);
  w->sign = calloc((size_t)Ki, sizeof(*w->sign));
  int big = nxi * nxi > 64 ? nxi * nxi : 64;
  for (int k = 0; k < w->K; k++) {
    const int rows = user->n_switch && user->n_switch[k] > 0 ? user->n_switch[k] : user->n_modes[k];
    if (rows * nxi > big) big = rows * nxi;
    if (user->sparsity && user->sparsity[k].jac_nnz > big) big = user->sparsity[k].jac_nnz;
  }
  if (nr > big) big = nr;
  w->xb = malloc((size_t)nxi * sizeof(double));
  w->fb = malloc((size_t)big * sizeof(double));
  w->fb2 = malloc((size_t)big * sizeof(double));
  w->jb = malloc((size_t)big * sizeof(double));
  w->rb = malloc((size_t)(nr > 0 ? nr : 1) * sizeof(double));
  w->rb2 = malloc((size_t)(nr > 0 ? nr : 1) * sizeof(double));
  w->ub = malloc((size_t)nxi * nu * sizeof(double));
  if (fail || !w->sign || !w->xb || !w->fb || !w->fb2 || !w->jb || !w->rb || !w->rb2 || !w->ub) {
    fesd__wrap_free(w);
    return FESD_ERR_NOMEM;
  }
  for (int k = 0; k < Ki; k++) {
    if (k < w->K) {
      w->n_modes[k] = user->n_modes[k];
      w->n_switch[k] = user->n_switch ? user->n_switch[k] : 0;
      w->sign[k] = user->sign ? user->sign[k] : NULL;
    } else {
      w->n_modes[k] = k == w->kd ? 1 : 2;
      w->n_switch[k] = k == w->kd ? 0 : 1;
    }
  }
  if (w->sparse) {
    w->sp = calloc((size_t)Ki, sizeof(*w->sp));
    w->ia = calloc((size_t)5 * Ki, sizeof(int *));
    int st = !w->sp || !w->ia ? FESD_ERR_NOMEM : sparse_patterns(w, Ki);
    if (st) {
      fesd__wrap_free(w);
      return st;
    }
  }
  internal->nx = nxi;
  internal->nsys = Ki;
  internal->n_modes = w->n_modes;
  internal->n_switch = w->n_switch;
  internal->sign = w->sign;
  internal->field = w_field;
  internal->sw = w_sw;
  internal->field_jac = user->field_jac ? w_field_jac : NULL;
  internal->sw_jac = user->sw_jac ? w_sw_jac : NULL;
  internal->user = w;
  internal->sparsity = w->sparse ? w->sp : NULL;
  internal->time_dependent = 0;
  internal->drift = NULL;
  internal->drift_jac = NULL;
  internal->drift_sparsity = NULL;
  internal->n_roots = 0;
  internal->roots = NULL;
  internal->root_dir = NULL;
  return FESD_OK;
}
