/* Read access to an integrator's results (state, sensitivities, events, the last step's
 * elements, statistics, dense output) and the collocation weights they share. */
#include <math.h>
#include <string.h>

#include "fesd/integrator.h"
#include "fesd/step.h"

int fesd_get_state(const fesd_integrator *it, double *t, double *x) {
  if (!it) return FESD_ERR_NULL;
  if (t) *t = it->t;
  if (x) memcpy(x, it->x, (size_t)it->nxu * sizeof(double));
  return FESD_OK;
}

int fesd_get_sensitivities(const fesd_integrator *it, double *Sx, double *Su) {
  if (!it) return FESD_ERR_NULL;
  if (!it->set.sensitivities) return FESD_ERR_NOT_READY;
  const int nx = it->nx, m = it->nxu; /* the user's block of the internal matrices */
  if (Sx)
    for (int c = 0; c < m; c++) memcpy(Sx + (size_t)c * m, it->Sx + (size_t)c * nx, (size_t)m * sizeof(double));
  if (Su)
    for (int c = 0; c < it->nu; c++) memcpy(Su + (size_t)c * m, it->Su + (size_t)c * nx, (size_t)m * sizeof(double));
  return FESD_OK;
}

int fesd_last_events(const fesd_integrator *it, const fesd_event **events, int *count) {
  if (!it || !events || !count) return FESD_ERR_NULL;
  *events = it->events;
  *count = it->n_events;
  return FESD_OK;
}

int fesd_last_step_data(const fesd_integrator *it, fesd_step_data *d) {
  if (!it || !d) return FESD_ERR_NULL;
  d->n_elements = it->n_el;
  d->h = it->rec_h;
  d->t = it->rec_t;
  d->x = it->rec_x;
  d->theta = it->rec_th;
  d->lambda = it->rec_la;
  d->mu = it->rec_mu;
  d->n_theta = it->nth;
  d->stages = it->s;
  d->nx = it->nx;
  d->n_sys = it->nsys;
  return FESD_OK;
}

int fesd_get_stats(const fesd_integrator *it, fesd_stats *stats) {
  if (!it || !stats) return FESD_ERR_NULL;
  *stats = it->stats;
  return FESD_OK;
}

int fesd_dims(const fesd_integrator *it, int *n_theta, int *nsys) {
  if (!it) return FESD_ERR_NULL;
  if (n_theta) *n_theta = it->nth;
  if (nsys) *nsys = it->nsysu;
  return FESD_OK;
}

/* Dense output: on element n the collocation polynomial u(t_n + tau h) = x_n +
 * h sum_j (int_0^tau l_j) v_j, l_j the Lagrange basis on the nodes c; the integrals by an
 * s-point Gauss rule on [0, tau] (exact: degree s - 1). */
int fesd_dense_output(const fesd_integrator *it, double t, double *x) {
  if (!it || !x) return FESD_ERR_NULL;
  const fesd_tableau *T = &it->tab;
  int colloc = T->family == FESD_RK_RADAU_IIA || T->family == FESD_RK_GAUSS_LEGENDRE ||
               T->family == FESD_RK_LOBATTO_IIIA;
  if (!colloc) return FESD_ERR_INVALID_ARG;
  if (it->n_el == 0) return FESD_ERR_NOT_READY;
  const double t0 = it->rec_t[0], t1 = it->rec_t[it->n_el];
  const double tol = 1e-12 * fmax(1.0, fabs(t1));
  if (!(t >= t0 - tol && t <= t1 + tol)) return FESD_ERR_INVALID_ARG;
  int e = 0;
  while (e + 1 < it->n_el && t >= it->rec_t[e + 1]) e++;
  const int s = T->s, nx = it->nx, m = it->nxu;
  const double h = it->rec_h[e], tau = h > 0 ? fmin(fmax((t - it->rec_t[e]) / h, 0.0), 1.0) : 0.0;
  double w[FESD_RK_MAX_STAGES];
  fesd__colloc_weights(it, tau, w);
  memcpy(x, it->rec_x + (size_t)e * nx, (size_t)m * sizeof(double));
  for (int j = 0; j < s; j++) {
    const double *v = it->rec_v + ((size_t)e * s + j) * nx;
    for (int r = 0; r < m; r++) x[r] += h * w[j] * v[r];
  }
  return FESD_OK;
}

void fesd__colloc_weights(const fesd_integrator *it, double tau, double *w) {
  const fesd_tableau *T = &it->tab;
  const int s = T->s, nq = it->quad.s;
  for (int j = 0; j < s; j++) w[j] = 0;
  /* int_0^tau l_j by the Gauss rule (exact: degree s - 1); at each point the products of all
   * factors but one from prefix and suffix products (no divisions: a zero factor is fine) */
  for (int q = 0; q < nq; q++) {
    const double t = tau * it->quad.c[q], bq = tau * it->quad.b[q];
    double suf[FESD_RK_MAX_STAGES + 1];
    suf[s] = 1;
    for (int m = s - 1; m > 0; m--) suf[m] = suf[m + 1] * (t - T->c[m]);
    double pre = 1;
    for (int j = 0; j < s; j++) {
      w[j] += bq * pre * suf[j + 1];
      pre *= t - T->c[j];
    }
  }
  for (int j = 0; j < s; j++) w[j] *= it->lag_inv[j];
}
