#include "problems/friction_chain.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Subsystem 0 carries the smooth spring dynamics and the friction of mass 0 (all rows);
 * subsystem i >= 1 only the friction of mass i (row n + i). Mode 0: v_i > vb. */
static int fc_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user) {
  (void)u;
  const fesd_friction_chain *fc = user;
  const int n = fc->n;
  const double fr = mode == 0 ? -fc->mu : fc->mu;
  if (sys > 0) {
    f[0] = fr;
    return 0;
  }
  for (int i = 0; i < n; i++) {
    double left = i > 0 ? x[i - 1] : 0.0, right = i < n - 1 ? x[i + 1] : x[i];
    f[i] = x[n + i];
    f[n + i] = -fc->k * (2 * x[i] - left - right) + (i == 0 ? fr : 0.0);
  }
  return 0;
}

static int fc_field_jac(int sys, int mode, double t, const double *x, const double *u, double *J, double *Ju,
                        void *user) {
  (void)mode, (void)x, (void)u, (void)Ju;
  const fesd_friction_chain *fc = user;
  if (sys > 0) return 0; /* constant friction: empty pattern */
  const int n = fc->n;
  int e = 0;
  for (int i = 0; i < n; i++) J[e++] = 1.0; /* dq_i'/dv_i */
  for (int i = 0; i < n; i++) {            /* dv_i'/dq_{i-1}, dq_i, dq_{i+1} */
    if (i > 0) J[e++] = fc->k;
    J[e++] = i < n - 1 ? -2 * fc->k : -fc->k;
    if (i < n - 1) J[e++] = fc->k;
  }
  return 0;
}

static int fc_sw(int sys, double t, const double *x, const double *u, double *c, void *user) {
  (void)u;
  const fesd_friction_chain *fc = user;
  c[0] = x[fc->n + sys] - fc->vb;
  return 0;
}

static int fc_sw_jac(int sys, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  (void)sys, (void)x, (void)u, (void)Ju, (void)user;
  J[0] = 1.0;
  return 0;
}

void fesd_friction_chain_free(fesd_friction_chain *fc) {
  if (!fc) return;
  void *p[] = {fc->n_modes, fc->n_switch, fc->sp, fc->rows0, fc->jr0, fc->jc0, fc->rows, fc->swr, fc->swc, fc->x0};
  for (size_t i = 0; i < sizeof(p) / sizeof(p[0]); i++) free(p[i]);
  memset(fc, 0, sizeof(*fc));
}

int fesd_friction_chain_init(fesd_friction_chain *fc, int n, double vb) {
  memset(fc, 0, sizeof(*fc));
  if (n < 1) return FESD_ERR_INVALID_ARG;
  fc->n = n;
  fc->k = 1.0;
  fc->mu = 0.5;
  fc->vb = vb;
  const int nj = n + 3 * n - 2;
  fc->n_modes = malloc((size_t)n * sizeof(int));
  fc->n_switch = malloc((size_t)n * sizeof(int));
  fc->sp = calloc((size_t)n, sizeof(fesd_sparsity));
  fc->rows0 = malloc((size_t)2 * n * sizeof(int));
  fc->jr0 = malloc((size_t)nj * sizeof(int));
  fc->jc0 = malloc((size_t)nj * sizeof(int));
  fc->rows = malloc((size_t)n * sizeof(int));
  fc->swr = calloc(1, sizeof(int));
  fc->swc = malloc((size_t)n * sizeof(int));
  fc->x0 = calloc((size_t)2 * n, sizeof(double));
  if (!fc->n_modes || !fc->n_switch || !fc->sp || !fc->rows0 || !fc->jr0 || !fc->jc0 || !fc->rows ||
      !fc->swr || !fc->swc || !fc->x0) {
    fesd_friction_chain_free(fc);
    return FESD_ERR_NOMEM;
  }
  for (int r = 0; r < 2 * n; r++) fc->rows0[r] = r;
  int e = 0; /* same order as fc_field_jac */
  for (int i = 0; i < n; i++) fc->jr0[e] = i, fc->jc0[e++] = n + i;
  for (int i = 0; i < n; i++) {
    if (i > 0) fc->jr0[e] = n + i, fc->jc0[e++] = i - 1;
    fc->jr0[e] = n + i, fc->jc0[e++] = i;
    if (i < n - 1) fc->jr0[e] = n + i, fc->jc0[e++] = i + 1;
  }
  for (int i = 0; i < n; i++) {
    fc->n_modes[i] = 2;
    fc->n_switch[i] = 1;
    fc->rows[i] = n + i;
    fc->swc[i] = n + i;
    fc->x0[i] = 0.1 * sin(1.3 * i + 0.4); /* no symmetry: distinct switching times */
    fesd_sparsity *s = &fc->sp[i];
    if (i == 0) {
      s->n_rows = 2 * n, s->rows = fc->rows0, s->jac_nnz = nj, s->jac_row = fc->jr0, s->jac_col = fc->jc0;
    } else {
      s->n_rows = 1, s->rows = &fc->rows[i], s->jac_nnz = 0;
    }
    s->sw_nnz = 1, s->sw_row = fc->swr, s->sw_col = &fc->swc[i];
  }
  fc->model = (fesd_model){.nx = 2 * n, .nu = 0, .nsys = n, .n_modes = fc->n_modes,
                           .n_switch = fc->n_switch, .field = fc_field, .field_jac = fc_field_jac,
                           .sw = fc_sw, .sw_jac = fc_sw_jac, .user = fc, .sparsity = fc->sp};
  return FESD_OK;
}

int fesd_friction_chain_stick_slip(fesd_friction_chain *fc, int n) {
  int st = fesd_friction_chain_init(fc, n, 0.2);
  if (st) return st;
  for (int i = 0; i < n; i++) fc->x0[i] = sin(1.3 * i + 0.4);
  return FESD_OK;
}
