/* The sparse model API: a friction chain (n masses, n switching subsystems, stick-slip)
 * declared with sparsity gives the same trajectory and events as the same model declared
 * dense (an adapter scatters the compressed callbacks into full vectors and matrices);
 * invalid sparsity is rejected with a clear status. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fesd.h"
#include "problems/friction_chain.h"

typedef struct {
  fesd_friction_chain *fc;
  double buf[4096];
} dense_adapter;

static int d_field(int k, int i, double t, const double *x, const double *u, double *f, void *user) {
  dense_adapter *a = user;
  const fesd_sparsity *sp = &a->fc->sp[k];
  int st = a->fc->model.field(k, i, t, x, u, a->buf, a->fc);
  memset(f, 0, (size_t)a->fc->model.nx * sizeof(double));
  for (int r = 0; r < sp->n_rows; r++) f[sp->rows[r]] = a->buf[r];
  return st;
}
static int d_field_jac(int k, int i, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  dense_adapter *a = user;
  const fesd_sparsity *sp = &a->fc->sp[k];
  const int nx = a->fc->model.nx;
  int st = a->fc->model.field_jac(k, i, t, x, u, a->buf, Ju, a->fc);
  memset(J, 0, (size_t)nx * nx * sizeof(double));
  for (int e = 0; e < sp->jac_nnz; e++) J[sp->jac_col[e] * nx + sp->rows[sp->jac_row[e]]] += a->buf[e];
  return st;
}
static int d_sw(int k, double t, const double *x, const double *u, double *c, void *user) {
  dense_adapter *a = user;
  return a->fc->model.sw(k, t, x, u, c, a->fc);
}
static int d_sw_jac(int k, double t, const double *x, const double *u, double *J, double *Ju, void *user) {
  dense_adapter *a = user;
  const fesd_sparsity *sp = &a->fc->sp[k];
  int st = a->fc->model.sw_jac(k, t, x, u, a->buf, Ju, a->fc);
  memset(J, 0, (size_t)a->fc->model.nx * sizeof(double)); /* one switching function */
  for (int e = 0; e < sp->sw_nnz; e++) J[sp->sw_col[e]] += a->buf[e];
  return st;
}

static int run(const fesd_model *m, const double *x0, int nsim, double *xT, int *events, int *st_out) {
  fesd_settings set;
  fesd_settings_default(&set);
  set.n_fe = 3;
  fesd_integrator *it;
  int st = fesd_create(&it, m, &set);
  if (st) return *st_out = st;
  fesd_set_state(it, 0, x0, NULL);
  *events = 0;
  for (int k = 0; k < nsim && !st; k++) {
    st = fesd_step(it, NULL, 2.0 / nsim, NULL);
    const fesd_event *ev;
    int ne;
    fesd_last_events(it, &ev, &ne);
    *events += ne;
  }
  fesd_get_state(it, NULL, xT);
  fesd_free(&it);
  return *st_out = st;
}

int main(void) {
  int fails = 0;
  const int n = 4;
  fesd_friction_chain fc;
  fesd_friction_chain_init(&fc, n, 0.2);
  dense_adapter *ad = calloc(1, sizeof(*ad));
  ad->fc = &fc;
  fesd_model dm = fc.model;
  dm.field = d_field, dm.field_jac = d_field_jac, dm.sw = d_sw, dm.sw_jac = d_sw_jac;
  dm.user = ad, dm.sparsity = NULL;
  double xs[8], xd[8];
  int es, ed, st1, st2;
  run(&fc.model, fc.x0, 40, xs, &es, &st1);
  run(&dm, fc.x0, 40, xd, &ed, &st2);
  double diff = 0;
  for (int i = 0; i < 2 * n; i++) diff = fmax(diff, fabs(xs[i] - xd[i]));
  int ok = !st1 && !st2 && diff <= 1e-12 && es == ed && es > 0;
  fails += !ok;
  printf("friction chain n=%d (stick-slip), sparse vs dense declaration: |x(T) difference| %.1e, "
         "events %d / %d, status %s / %s %s\n", n, diff, es, ed, fesd_status_name(st1),
         fesd_status_name(st2), ok ? "ok" : "FAIL");
  /* invalid sparsity */
  fesd_integrator *it = NULL;
  fesd_model bad = fc.model;
  fesd_sparsity sp[4];
  memcpy(sp, fc.sp, sizeof(sp));
  int bad_rows[2] = {3, 1}; /* not ascending */
  sp[1].rows = bad_rows;
  sp[1].n_rows = 2;
  bad.sparsity = sp;
  int s1 = fesd_create(&it, &bad, NULL);
  memcpy(sp, fc.sp, sizeof(sp));
  int bad_col = 99;
  sp[2].sw_col = &bad_col;
  int s2 = fesd_create(&it, &bad, NULL);
  bad = fc.model;
  bad.field_jac = NULL; /* sparse models need Jacobian callbacks */
  int s3 = fesd_create(&it, &bad, NULL);
  ok = s1 == FESD_ERR_PATTERN && s2 == FESD_ERR_PATTERN && s3 == FESD_ERR_MODEL && it == NULL;
  fails += !ok;
  printf("invalid sparsity: %s, %s, %s %s\n", fesd_status_name(s1), fesd_status_name(s2),
         fesd_status_name(s3), ok ? "ok" : "FAIL");
  free(ad);
  fesd_friction_chain_free(&fc);
  printf("%d failures\n", fails);
  return fails != 0;
}
