/* Active sets of the step solve. With the active set of every element fixed
 * (pair rows theta_i = 0 for inactive modes, lambda_i = 0 for active ones) the step
 * system is smooth and Newton converges quadratically; the complementarity signs are
 * then verified (theta >= 0 on active modes, lambda >= 0 on inactive ones). A violated
 * sign locates the next switch accurately: lambda of an inactive mode is a smooth
 * difference of indicators along the computed trajectory, theta of an active mode a
 * smooth sliding multiplier; their linear zero crossing predicts the switch time. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fesd/step.h"

/* Active modes of one theta vector (theta > active_tol); every subsystem keeps at least
 * its largest mode. */
void fesd__act_from_theta(const fesd_integrator *it, const double *theta, unsigned char *a) {
  const fesd__model *m = &it->model;
  for (int k = 0; k < m->nsys; k++) {
    int best = m->th_off[k], any = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      a[i] = theta[i] > it->set.active_tol;
      any |= a[i];
      if (theta[i] > theta[best]) best = i;
    }
    if (!any) a[best] = 1;
  }
}

int fesd__keeps_alone(const fesd__model *m, const fesd__point_eval *pe, int k, const unsigned char *cand, int l,
                      const double *f) {
  const double gl = fesd__dg_dot(m, pe, l, f);
  for (int c = m->th_off[k]; c < m->th_off[k + 1]; c++)
    if (c != l && cand[c] && !(fesd__dg_dot(m, pe, c, f) - gl > 0)) return 0;
  return 1;
}

/* x0 on a switching surface (several modes tie for min g). A tied mode i whose field keeps it
 * the strict minimum, d/dt (g_j - g_i) > 0 along the total field with f_i for every other tied
 * j, leaves the surface on its own side. Exactly one such mode: it is entered alone (a
 * crossing). None: all tied modes stay active (a sliding mode). Several (a repulsive
 * surface): the state's own side (the strict argmin of g) when x0 is off the surface, however
 * little; exactly on it the solution is not unique (*nonunique), and all stay active (one of
 * the Filippov solutions: staying on the surface). The other subsystems contribute with
 * uniform weights on their tied modes. */
static int resolve_ties(fesd_integrator *it, const double *u, unsigned char *a, int *nonunique) {
  fesd__model *m = &it->model;
  const int nx = m->nx, nth = m->nth;
  fesd__point_eval pe = fesd__scratch_eval(it);
  int st = fesd__model_eval(m, it->t, it->x, u, &pe);
  if (st) return st;
  double *ftot = it->gbuf + nth, *f = it->vtmp; /* nx each */
  memset(ftot, 0, (size_t)nx * sizeof(double));
  for (int k = 0; k < m->nsys; k++) {
    int cnt = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i];
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++)
      if (a[i]) fesd__F_axpy(m, &pe, i, 1.0 / cnt, ftot);
  }
  for (int k = 0; k < m->nsys; k++) {
    int cnt = 0, pick = -1, n_ok = 0, imin = -1;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i];
    if (cnt < 2) continue;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
      if (!a[i]) continue;
      if (imin < 0 || pe.g[i] < pe.g[imin]) imin = i;
      /* total field with mode i alone in subsystem k */
      memcpy(f, ftot, (size_t)nx * sizeof(double));
      fesd__F_axpy(m, &pe, i, 1.0, f);
      for (int l = m->th_off[k]; l < m->th_off[k + 1]; l++)
        if (a[l]) fesd__F_axpy(m, &pe, l, -1.0 / cnt, f);
      if (fesd__keeps_alone(m, &pe, k, a, i, f)) pick = pick < 0 ? i : pick, n_ok++;
    }
    if (n_ok >= 2) { /* repulsive: the side of the state, unless exactly on the surface */
      int strict = 1;
      for (int j = m->th_off[k]; j < m->th_off[k + 1]; j++)
        if (a[j] && j != imin && !(pe.g[imin] < pe.g[j])) strict = 0;
      if (strict) {
        pick = imin;
        n_ok = 1;
      } else {
        *nonunique = 1;
      }
    }
    if (n_ok == 1)
      for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) a[i] = i == pick;
  }
  return FESD_OK;
}

/* Active set at the step start: the previous step's last stage, or the argmin of g (ties
 * within 1e-12 of the subsystem's indicator scale decided by the fields). */
int fesd__act_start(fesd_integrator *it, const double *u, unsigned char *a, int *nonunique) {
  *nonunique = 0;
  if (it->have_prev_theta) {
    for (int i = 0; i < it->nth; i++) a[i] = it->act_prev[i]; /* a few bytes: no call */
    return FESD_OK;
  }
  fesd__model *m = &it->model;
  int st = fesd__model_g(m, it->t, it->x, u, it->gbuf);
  if (st) return st;
  int tied = 0;
  for (int k = 0; k < m->nsys; k++) {
    double gmin = INFINITY;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) gmin = fmin(gmin, it->gbuf[i]);
    const double tie = 1e-12 / it->sys.wG[k];
    int cnt = 0;
    for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) cnt += a[i] = it->gbuf[i] <= gmin + tie;
    tied |= cnt > 1;
  }
  return tied ? resolve_ties(it, u, a, nonunique) : FESD_OK;
}

/* theta restricted to the active set of each stage (act: N*s blocks of nth flags), renormalised per subsystem; a
 * subsystem where some active mode has (almost) no weight in the guess (a newly active
 * mode, e.g. a sliding candidate) starts from uniform weights, which keeps the
 * cross-complementarity row of that mode non-degenerate. */
int fesd__impose_active(fesd_integrator *it, double *z, const unsigned char *act) {
  fesd__system *S = &it->sys;
  const fesd__model *m = &it->model;
  int changed = 0;
  for (int n = 0; n < S->N; n++) {
    for (int j = 0; j < S->s; j++) {
      const unsigned char *a = act + (size_t)(n * S->s + j) * S->nth;
      double *th = z + fesd__th(S, n, j);
      for (int k = 0; k < m->nsys; k++) {
        double sum = 0, low = INFINITY;
        int cnt = 0;
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
          if (!a[i]) {
            th[i] = 0;
            continue;
          }
          th[i] = fesd__fmax(th[i], 0.0);
          sum += th[i];
          low = fesd__fmin(low, th[i]);
          cnt++;
        }
        int uniform = cnt > 0 && (low < 1e-3 * sum || sum <= 0);
        for (int i = m->th_off[k]; i < m->th_off[k + 1]; i++) {
          const double old = th[i];
          if (a[i]) th[i] = uniform ? 1.0 / cnt : th[i] / sum;
          changed |= !(fabs(th[i] - old) <= 1e-14);
        }
      }
    }
  }
  return changed;
}

/* Border of the sparse LU (fesd_ncp_set_border): the element lengths, the boundary rows and
 * sum h = T couple all elements; without them the step matrix is block lower triangular in
 * time (element n depends on element n - 1 only through x_n). A pinned exit has no boundary
 * row: the second row of its pinned pair takes that place. */
int fesd__set_border(fesd_integrator *it) {
  fesd__system *S = &it->sys;
  memset(it->raw_border, 0, (size_t)S->n_raw);
  memset(it->col_border, 0, (size_t)S->n);
  for (int n = 0; n < S->N; n++) it->col_border[S->ho[n]] = 1;
  for (int k = 1; k < S->N; k++) {
    if (it->eq_active[fesd__rowH(S, k)]) it->raw_border[fesd__rowH(S, k)] = 1;
    if (it->eq_active[fesd__rowC(S, k)]) it->raw_border[fesd__rowC(S, k)] = 1;
  }
  it->raw_border[S->rT] = 1;
  for (int p = 0; p < S->n_pair; p++)
    if (it->pair_mode[p] == FESD_NCP_PAIR_PIN) it->raw_border[S->n_eq + S->n_pair + p] = 1;
  return fesd_ncp_set_border(it->ncp, it->raw_border, it->col_border);
}

/* Rows for fixed active sets: pairs A (theta = 0) or B (lambda = 0) per stage;
 * boundary k: bmode[k] = 0 -> h_k = h_{k-1}; 1 -> cross-complementarity row;
 * 2 -> sliding exit of mode exit_mode[k]: the pair of its last stage before the boundary
 * is pinned (theta = lambda = 0) and neither boundary row is used. */
/* Is (act, bmode, exit_mode) the selection in force on this solver and layout? Records it
 * otherwise (valid once applied). */
static int rows_cached(fesd_integrator *it, const unsigned char *act, const int *bmode, const int *exit_mode) {
  const fesd__system *S = &it->sys;
  const int N = S->N, *eb = it->rk_bmode + N + 1;
  const size_t na = (size_t)N * S->s * S->nth;
  int same = it->rk_valid && it->rk_ncp == (const void *)it->ncp && it->rk_N == N && !memcmp(it->rk_act, act, na);
  for (int k = 1; k < N && same; k++) {
    const int b = bmode ? bmode[k] : 0;
    same = b == it->rk_bmode[k] && (b != 2 || exit_mode[k] == eb[k]);
  }
  if (same) return 1;
  it->rk_valid = 0;
  it->rk_ncp = it->ncp;
  it->rk_N = N;
  memcpy(it->rk_act, act, na);
  for (int k = 1; k < N; k++) {
    it->rk_bmode[k] = bmode ? bmode[k] : 0;
    it->rk_bmode[N + 1 + k] = it->rk_bmode[k] == 2 ? exit_mode[k] : 0;
  }
  return 0;
}

int fesd__rows_active(fesd_integrator *it, const unsigned char *act, const int *bmode,
                      const int *exit_mode) {
  fesd__system *S = &it->sys;
  if (rows_cached(it, act, bmode, exit_mode)) return FESD_OK;
  memset(it->eq_active, 1, (size_t)S->n_eq);
  for (int k = 1; k < S->N; k++) {
    int b = bmode ? bmode[k] : 0;
    it->eq_active[fesd__rowH(S, k)] = (unsigned char)(b == 0);
    it->eq_active[fesd__rowC(S, k)] = (unsigned char)(b == 1);
  }
  for (int n = 0; n < S->N; n++)
    for (int j = 0; j < S->s; j++)
      for (int i = 0; i < S->nth; i++)
        it->pair_mode[fesd__pair(S, n, j, i)] =
            act[(size_t)(n * S->s + j) * S->nth + i] ? FESD_NCP_PAIR_B : FESD_NCP_PAIR_A;
  /* exits: stiffly accurate methods pin the pair of the last stage (the element end);
   * boundary-point methods the extrapolated theta in the C row (system.h, exit_ext) */
  fesd__system_set_exits(S, bmode, exit_mode);
  fesd__system_set_lb_mask(S, act);
  for (int k = 1; k < S->N; k++)
    if (bmode && bmode[k] == 2) {
      if (S->bp) it->eq_active[fesd__rowC(S, k)] = 1;
      else it->pair_mode[fesd__pair(S, k - 1, S->s - 1, exit_mode[k])] = FESD_NCP_PAIR_PIN;
    }
  int st = fesd__set_border(it);
  if (!st) st = fesd_ncp_set_rows(it->ncp, it->eq_active, it->pair_mode);
  it->rk_valid = !st;
  return st;
}

