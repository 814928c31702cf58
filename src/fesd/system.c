#include "fesd/system.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void fesd__system_free(fesd__system *S) {
  if (!S) return;
  fesd__block_free(S->mem);
  free(S->wraw);
  memset(S, 0, sizeof(*S));
}

const double *fesd__right_lambda(const fesd__system *S, const double *z, int n) {
  if (!S->bp) return z + fesd__la(S, n, S->s - 1);
  return S->lbo[n] >= 0 ? z + S->lbo[n] : NULL;
}

const double *fesd__left_lambda(const fesd__system *S, const double *z, int n) {
  return n == 0 ? S->lam00 : fesd__right_lambda(S, z, n - 1);
}

/* State at the start of element n. */
static const double *elem_start(const fesd__system *S, const double *z, int n) {
  return n == 0 ? S->x0 : z + S->xo[n - 1];
}

void fesd__system_set_lb_mask(fesd__system *S, const unsigned char *act) {
  const int nth = S->nth;
  for (int n = 0; n < S->N; n++)
    for (int i = 0; i < nth; i++)
      S->lbm[n * nth + i] = !act || !act[(size_t)(n * S->s + S->s - 1) * nth + i];
}

/* Weight of the boundary lambda LB_i at the end of element n in the cross complementarity
 * (1: lambda00 and the stage lambdas of stiffly accurate methods). */
static inline double lb_count(const fesd__system *S, int n, int i) {
  return S->bp && n >= 0 ? (double)S->lbm[n * S->nth + i] : 1.0;
}

double fesd__cross_value(const fesd__system *S, const double *z, int n) {
  int s = S->s, nth = S->nth;
  const double *L = fesd__left_lambda(S, z, n);
  const double *R = S->bp ? fesd__right_lambda(S, z, n) : NULL;
  double c = 0;
  for (int i = 0; i < nth; i++) {
    double Th = 0, Lt = lb_count(S, n - 1, i) * L[i] + (R ? lb_count(S, n, i) * R[i] : 0), diag = 0;
    for (int j = 0; j < s; j++) {
      double th = z[fesd__th(S, n, j) + i], la = z[fesd__la(S, n, j) + i];
      Th += th;
      Lt += la;
      diag += th * la;
    }
    c += S->wth[i] * (Th * Lt - diag);
  }
  return c;
}

void fesd__system_set_exits(fesd__system *S, const int *bmode, const int *exit_mode) {
  for (int k = 0; k <= S->N; k++)
    S->exit_ext[k] = S->bp && bmode && k > 0 && k < S->N && bmode[k] == 2 ? exit_mode[k] : -1;
}

/* ---- Jacobian emission: one traversal counts the entries, writes the pattern, or writes
 *      the values, so all three always agree. ---- */
typedef struct {
  int k; /* entries emitted so far */
  int *row, *col;
  double *val;
} emitter;

/* mode (a compile-time constant in each instance of emit_body, so the branches fold away:
 * the value instance runs at every Newton iteration) */
enum { EMIT_COUNT, EMIT_PATTERN, EMIT_VALUES };
#define EMIT(E, r, c, expr)            \
  do {                                 \
    if (mode == EMIT_PATTERN) {        \
      (E)->row[(E)->k] = (r);          \
      (E)->col[(E)->k] = (c);          \
    } else if (mode == EMIT_VALUES) {  \
      (E)->val[(E)->k] = (expr) * wr[r]; \
    }                                  \
    (E)->k++;                          \
  } while (0)

/* Entries of the indicator Jacobian block of every subsystem: (row, state column, value),
 * each row weighted by its subsystem's indicator weight. */
#define EMIT_DG(E, rowbase, colbase, blkptr, scale)                                  \
  for (int kk = 0; kk < m->nsys; kk++) {                                            \
    const int nfk = m->nf[kk], off = m->th_off[kk];                                 \
    for (int cp = 0; cp < m->ncol[kk]; cp++)                                        \
      for (int li = 0; li < nfk; li++)                                              \
        EMIT(E, (rowbase) + off + li, (colbase) + m->cols[kk][cp],                  \
             (scale) * (blkptr)[m->dgoff[kk] + (size_t)cp * nfk + li]); \
  }

static inline __attribute__((always_inline)) void emit_body(const fesd__system *S, const double *z, emitter *E,
                                                            const int mode) {
  const int N = S->N, s = S->s, nx = S->nx, nth = S->nth;
  const fesd__model *m = S->model;
  const int values = mode == EMIT_VALUES;
  const double *wth = S->wth, *wr = S->wraw; /* row weights; cross-complementarity terms */
  for (int n = 0; n < N; n++) {
    const double h = values ? z[S->ho[n]] : 0;
    for (int j = 0; j < s; j++) {
      const int p = n * s + j;
      const fesd__point_eval *pe = &S->pe[p];
      const double *J = S->Jth + (size_t)p * m->pf_nnz, *JK = S->JK + (size_t)p * nx;
      const int rV = S->rel[n] + j * S->rs, rG = rV + nx, rS = rG + nth;
      /* V rows: v_j - F(X_j) theta_j, X_j = x_n + h sum_l a_jl v_l */
      for (int l = 0; l < s; l++) {
        const double a = S->tab.A[j][l];
        if (j == l)
          for (int r = 0; r < nx; r++) EMIT(E, rV + r, fesd__v(S, n, l) + r, 1.0);
        for (int q = 0; q < m->pf_nnz; q++)
          EMIT(E, rV + m->pf_r[q], fesd__v(S, n, l) + m->pf_c[q], -h * a * J[q]);
      }
      if (n > 0)
        for (int q = 0; q < m->pf_nnz; q++)
          EMIT(E, rV + m->pf_r[q], S->xo[n - 1] + m->pf_c[q], -J[q]);
      for (int r = 0; r < nx; r++) EMIT(E, rV + r, S->ho[n], -JK[r]); /* d/dh: -J K_j */
      for (int i = 0; i < nth; i++) {
        const int k = m->sys_of[i];
        for (int r = 0; r < m->nr[k]; r++)
          EMIT(E, rV + m->rows[k][r], fesd__th(S, n, j) + i, -pe->F[m->Foff[i] + r]);
      }
      /* G rows: g(X) - lambda - mu e */
      const int lk = S->look && j == 0; /* look-ahead stage: + kappa h grad g . v_1 */
      for (int l = 0; l < s; l++) {
        const double a = S->tab.A[j][l] + (lk && l == 0 ? S->kappa : 0.0);
        EMIT_DG(E, rG, fesd__v(S, n, l), pe->dgdx, h * a);
      }
      if (n > 0) EMIT_DG(E, rG, S->xo[n - 1], lk ? S->dgl + (size_t)n * m->ndg : pe->dgdx, 1.0);
      for (int i = 0; i < nth; i++) {
        EMIT(E, rG + i, S->ho[n], S->KG[(size_t)p * nth + i]); /* d/dh: grad g_i . K_j */
        EMIT(E, rG + i, fesd__la(S, n, j) + i, -1.0);
        EMIT(E, rG + i, fesd__mu(S, n, j) + m->sys_of[i], -1.0);
      }
      /* S rows: 1 - e'theta per subsystem */
      for (int i = 0; i < nth; i++) EMIT(E, rS + m->sys_of[i], fesd__th(S, n, j) + i, -1.0);
    }
    if (S->lbo[n] >= 0) {
      const fesd__point_eval *pb = &S->pe[N * s + n];
      const int rL = S->rlb[n], rM = rL + nth, lb = S->lbo[n];
      EMIT_DG(E, rL, S->xo[n], pb->dgdx, 1.0);
      for (int i = 0; i < nth; i++) {
        EMIT(E, rL + i, lb + i, -1.0);
        EMIT(E, rL + i, lb + nth + m->sys_of[i], -1.0);
      }
      for (int i = 0; i < nth; i++) {
        EMIT(E, rM + m->sys_of[i], fesd__th(S, n, s - 1) + i, z[lb + i]);
        EMIT(E, rM + m->sys_of[i], lb + i, z[fesd__th(S, n, s - 1) + i]);
      }
    }
    /* X rows: x_{n+1} - x_n - h sum b_j v_j */
    const int rX = S->rx[n];
    for (int r = 0; r < nx; r++) {
      EMIT(E, rX + r, S->xo[n] + r, 1.0);
      if (n > 0) EMIT(E, rX + r, S->xo[n - 1] + r, -1.0);
      double val = 0;
      if (values)
        for (int j = 0; j < s; j++) val -= S->tab.b[j] * z[fesd__v(S, n, j) + r];
      EMIT(E, rX + r, S->ho[n], val);
      for (int j = 0; j < s; j++) EMIT(E, rX + r, fesd__v(S, n, j) + r, -h * S->tab.b[j]);
    }
  }
  /* boundary rows */
  for (int k = 1; k < N; k++) {
    EMIT(E, fesd__rowH(S, k), S->ho[k], 1.0);
    EMIT(E, fesd__rowH(S, k), S->ho[k - 1], -1.0);
    const int rC = fesd__rowC(S, k), ex = values ? S->exit_ext[k] : -1, cc = ex < 0;
    for (int n = k - 1; n <= k; n++) {
      const double *L = values ? fesd__left_lambda(S, z, n) : NULL;
      const double *R = (S->bp && S->lbo[n] >= 0 && values) ? z + S->lbo[n] : NULL;
      for (int i = 0; i < nth; i++) {
        double Th = 0, Lt = 0;
        const double cl = values ? lb_count(S, n - 1, i) : 0, cr = values ? lb_count(S, n, i) : 0;
        if (values) {
          Lt = cl * L[i] + (R ? cr * R[i] : 0);
          for (int j = 0; j < s; j++) {
            Th += z[fesd__th(S, n, j) + i];
            Lt += z[fesd__la(S, n, j) + i];
          }
        }
        const double w = values && cc ? wth[i] : 0; /* an exit row: only its theta entries */
        const int exr = !cc && n == k - 1 && i == ex;
        for (int j = 0; j < s; j++) {
          EMIT(E, rC, fesd__th(S, n, j) + i, exr ? S->ext[j] : w * (Lt - z[fesd__la(S, n, j) + i]));
          EMIT(E, rC, fesd__la(S, n, j) + i, w * (Th - z[fesd__th(S, n, j) + i]));
        }
        if (n > 0) {
          int col = S->bp ? S->lbo[n - 1] + i : fesd__la(S, n - 1, s - 1) + i;
          EMIT(E, rC, col, w * Th * cl);
        }
        if (S->bp && S->lbo[n] >= 0) EMIT(E, rC, S->lbo[n] + i, w * Th * cr);
      }
    }
  }
  for (int n = 0; n < N; n++) EMIT(E, S->rT, S->ho[n], 1.0);
  /* pair rows: a = theta, b = lambda */
  for (int n = 0; n < N; n++)
    for (int j = 0; j < s; j++)
      for (int i = 0; i < nth; i++) {
        int p = fesd__pair(S, n, j, i);
        EMIT(E, S->n_eq + p, fesd__th(S, n, j) + i, 1.0);
        EMIT(E, S->n_eq + S->n_pair + p, fesd__la(S, n, j) + i, 1.0);
      }
}

static int emit_count(const fesd__system *S) {
  emitter E = {0, NULL, NULL, NULL};
  emit_body(S, NULL, &E, EMIT_COUNT);
  return E.k;
}
static void emit_pattern(const fesd__system *S, int *row, int *col) {
  emitter E = {0, row, col, NULL};
  emit_body(S, NULL, &E, EMIT_PATTERN);
}
static void emit_values(const fesd__system *S, const double *z, double *val) {
  emitter E = {0, NULL, NULL, val};
  emit_body(S, z, &E, EMIT_VALUES);
}

void fesd__system_set_N(fesd__system *S, int N) {
  S->N = N;
  S->pc_valid = 0;
  S->n = N * S->eb;
  const int row = N * S->erows;
  S->rH0 = row;
  S->rC0 = row + (N - 1);
  S->rT = row + 2 * (N - 1);
  S->n_eq = S->rT + 1;
  S->n_pair = N * S->s * S->nth;
  S->n_raw = S->n_eq + 2 * S->n_pair;
  S->nnz = emit_count(S);
}

int fesd__system_nnz(const fesd__system *S) { return S->nnz; }
void fesd__system_pattern(const fesd__system *S, int *row, int *col) { emit_pattern(S, row, col); }

/* The system's arrays for N_cap elements in one block (common/block.h). */
static void lay_out(fesd__system *S, int sens, fesd__block *B) {
  const fesd__model *m = S->model;
  const int s = S->s, nx = S->nx, nth = S->nth, nsys = S->nsys, nu = S->nu, N = S->N_cap;
  S->el = fesd__block_take(B, (size_t)N * sizeof(int), 0);
  S->xo = fesd__block_take(B, (size_t)N * sizeof(int), 0);
  S->ho = fesd__block_take(B, (size_t)N * sizeof(int), 0);
  S->lbo = fesd__block_take(B, (size_t)N * sizeof(int), 0);
  S->rel = fesd__block_take(B, (size_t)N * sizeof(int), 0);
  S->rlb = fesd__block_take(B, (size_t)N * sizeof(int), 0);
  S->rx = fesd__block_take(B, (size_t)N * sizeof(int), 0);
  S->wG = fesd__block_take(B, (size_t)nsys * sizeof(double), 0);
  S->magX = fesd__block_take(B, ((size_t)nx) * sizeof(double), 1);
  S->magV = fesd__block_take(B, ((size_t)nx) * sizeof(double), 1);
  S->refX = fesd__block_take(B, ((size_t)nx) * sizeof(double), 1);
  S->motX = fesd__block_take(B, ((size_t)nx) * sizeof(double), 1);
  S->refV = fesd__block_take(B, ((size_t)nx) * sizeof(double), 1);
  S->magG = fesd__block_take(B, ((size_t)nsys) * sizeof(double), 1);
  S->refG = fesd__block_take(B, ((size_t)nsys) * sizeof(double), 1);
  S->wth = fesd__block_take(B, (size_t)nth * sizeof(double), 0);
  S->exit_ext = fesd__block_take(B, (size_t)(N + 1) * sizeof(int), 0);
  S->lbm = fesd__block_take(B, (size_t)N * nth + 1, 0);
  int np = N * s + N;
  size_t nu1 = (size_t)(nu > 0 ? nu : 1), pf = (size_t)(m->pf_nnz > 0 ? m->pf_nnz : 1);
  S->pe = fesd__block_take(B, ((size_t)np) * sizeof(*S->pe), 1);
  S->X = fesd__block_take(B, (size_t)np * nx * sizeof(double), 0);
  S->Jth = fesd__block_take(B, (size_t)N * s * pf * sizeof(double), 0);
  S->JK = fesd__block_take(B, (size_t)N * s * nx * sizeof(double), 0);
  S->KG = fesd__block_take(B, (size_t)N * s * nth * sizeof(double), 0);
  S->Juth = fesd__block_take(B, (size_t)N * s * nx * nu1 * sizeof(double), 0);
  S->lam00_dp = fesd__block_take(B, (sens ? (size_t)nth * (nx + nu) : 1) * sizeof(double), 0); /* O(n^2) */
  S->tmp = fesd__block_take(B, (size_t)(4 * nx + 2 * nth) * sizeof(double), 0);
  S->pc_z = fesd__block_take(B, (size_t)N * S->eb * sizeof(double), 0);
  S->pc_xu = fesd__block_take(B, (size_t)(nx + nu) * sizeof(double), 0);
  S->pt_X = fesd__block_take(B, (size_t)N * s * nx * sizeof(double) + 1, 0);
  S->pt_t = fesd__block_take(B, (size_t)N * s * sizeof(double), 0);
  S->pt_lvl = fesd__block_take(B, ((size_t)N * s) * 1, 1);
  S->pt_u = fesd__block_take(B, ((size_t)nu + 1) * sizeof(double), 1); /* compared before the first record */
  fesd__point_eval probe; /* the sizing pass has no S->pe */
  for (int p = 0; p < np; p++) fesd__point_take(m, S->pe ? &S->pe[p] : &probe, p < N * s, B);
  if (S->look) {
    S->LK = fesd__block_take(B, (size_t)N * nth * sizeof(double), 0);
    S->dgl = fesd__block_take(B, (size_t)N * (m->ndg > 0 ? m->ndg : 1) * sizeof(double), 0);
    S->dgul = fesd__block_take(B, (size_t)N * nth * nu1 * sizeof(double), 0);
    S->xs = fesd__block_take(B, (size_t)nx * sizeof(double), 0);
    fesd__point_take(m, &S->pl, 0, B);
  }
}

int fesd__system_init(fesd__system *S, fesd__model *m, const fesd_tableau *tab, int N_cap, int sens) {
  memset(S, 0, sizeof(*S));
  S->model = m;
  S->tab = *tab;
  S->N_cap = N_cap;
  S->s = tab->s;
  S->nx = m->nx;
  S->nth = m->nth;
  S->nsys = m->nsys;
  S->nu = m->nu;
  S->bp = !tab->stiffly_accurate;
  S->look = !tab->is_explicit && tab->s >= 2;
  for (int l = 0; l < tab->s; l++) S->look = S->look && tab->A[0][l] == 0.0;
  S->kappa = S->look ? tab->c[1] : 0.0;
  for (int j = 0; j < tab->s; j++) { /* l_j(1) */
    double l = 1.0;
    for (int q = 0; q < tab->s; q++)
      if (q != j) l *= (1.0 - tab->c[q]) / (tab->c[j] - tab->c[q]);
    S->ext[j] = l;
  }
  const int s = S->s, nx = S->nx, nth = S->nth, nsys = S->nsys, N = N_cap;
  S->sb = nx + 2 * nth + nsys;
  S->rs = nx + nth + nsys;
  S->eb = s * S->sb + (S->bp ? nth + nsys : 0) + nx + 1;
  S->erows = s * S->rs + (S->bp ? nth + nsys : 0) + nx;
  fesd__block B = {0};
  lay_out(S, sens, &B); /* sizing pass */
  S->mem = fesd__block_open(&B);
  if (!S->mem) goto nomem;
  lay_out(S, sens, &B);
  if (!fesd__block_ok(&B)) goto nomem;
  for (int k = 0; k < nsys; k++) S->wG[k] = 1.0;
  for (int i = 0; i < nth; i++) S->wth[i] = 1.0;
  for (int k = 0; k <= N; k++) S->exit_ext[k] = -1;
  memset(S->lbm, 1, (size_t)N * nth + 1);
  int off = 0, row = 0;
  for (int n = 0; n < N; n++) {
    S->el[n] = off;
    S->rel[n] = row;
    off += s * S->sb;
    row += s * S->rs;
    if (S->bp) {
      S->lbo[n] = off;
      S->rlb[n] = row;
      off += nth + nsys;
      row += nth + nsys;
    } else {
      S->lbo[n] = S->rlb[n] = -1;
    }
    S->xo[n] = off;
    S->rx[n] = row;
    off += nx;
    row += nx;
    S->ho[n] = off;
    off += 1;
  }
  fesd__system_set_N(S, N_cap);
  S->wraw = malloc((size_t)S->n_raw * sizeof(double));
  if (!S->wraw) goto nomem;
  for (int r = 0; r < S->n_raw; r++) S->wraw[r] = 1.0;
  return FESD_OK;
nomem:
  fesd__system_free(S);
  return FESD_ERR_NOMEM;
}

int fesd__system_eval(const double *z, double *raw, double *jac, void *ctx) {
  fesd__system *S = ctx;
  const int N = S->N, s = S->s, nx = S->nx, nth = S->nth, nsys = S->nsys;
  const fesd__model *m = S->model;
  int st = fesd__system_points(S, z, jac != NULL);
  S->status = st;
  if (st) return 1;
  for (int n = 0; n < N; n++) {
    const double *xn = elem_start(S, z, n);
    const double h = z[S->ho[n]];
    for (int j = 0; j < s; j++) {
      const int p = n * s + j;
      const fesd__point_eval *pe = &S->pe[p];
      const int rV = S->rel[n] + j * S->rs, rG = rV + nx, rS = rG + nth;
      const double *v = z + fesd__v(S, n, j), *th = z + fesd__th(S, n, j);
      const double *la = z + fesd__la(S, n, j), *mu = z + fesd__mu(S, n, j);
      fesd__stage_residual(m, pe, v, th, raw + rV);
      for (int i = 0; i < nth; i++) raw[rG + i] = pe->g[i] - la[i] - mu[m->sys_of[i]];
      if (S->look && j == 0)
        for (int i = 0; i < nth; i++) raw[rG + i] += S->LK[(size_t)n * nth + i];
      for (int k = 0; k < nsys; k++) raw[rS + k] = 1.0;
      for (int i = 0; i < nth; i++) raw[rS + m->sys_of[i]] -= th[i];
    }
    if (S->lbo[n] >= 0) {
      const fesd__point_eval *pb = &S->pe[N * s + n];
      const double *LB = z + S->lbo[n], *MB = LB + nth, *th = z + fesd__th(S, n, s - 1);
      const int rL = S->rlb[n], rM = rL + nth;
      for (int i = 0; i < nth; i++) raw[rL + i] = pb->g[i] - LB[i] - MB[m->sys_of[i]];
      for (int k = 0; k < nsys; k++) raw[rM + k] = 0.0;
      for (int i = 0; i < nth; i++) raw[rM + m->sys_of[i]] += th[i] * LB[i];
    }
    const double *x1 = z + S->xo[n];
    for (int r = 0; r < nx; r++) {
      double acc = x1[r] - xn[r];
      for (int j = 0; j < s; j++) acc -= h * S->tab.b[j] * z[fesd__v(S, n, j) + r];
      raw[S->rx[n] + r] = acc;
    }
  }
  double hs = 0;
  for (int n = 0; n < N; n++) hs += z[S->ho[n]];
  for (int k = 1; k < N; k++) {
    raw[fesd__rowH(S, k)] = z[S->ho[k]] - z[S->ho[k - 1]];
    const int ex = S->exit_ext[k];
    if (ex >= 0) {
      double e = 0;
      for (int j = 0; j < s; j++) e += S->ext[j] * z[fesd__th(S, k - 1, j) + ex];
      raw[fesd__rowC(S, k)] = e;
    } else {
      raw[fesd__rowC(S, k)] = fesd__cross_value(S, z, k - 1) + fesd__cross_value(S, z, k);
    }
  }
  raw[S->rT] = hs - S->T;
  for (int n = 0; n < N; n++)
    for (int j = 0; j < s; j++)
      for (int i = 0; i < nth; i++) {
        int p = fesd__pair(S, n, j, i);
        raw[S->n_eq + p] = z[fesd__th(S, n, j) + i];
        raw[S->n_eq + S->n_pair + p] = z[fesd__la(S, n, j) + i];
      }
  for (int r = 0; r < S->n_raw; r++) raw[r] *= S->wraw[r];
  if (jac) {
    fesd__system_points_hcol(S);
    emit_values(S, z, jac);
  }
  return 0;
}

int fesd__system_param_jac(fesd__system *S, const double *z, double *out) {
  const int N = S->N, s = S->s, nx = S->nx, nth = S->nth, nu = S->nu, np = nx + nu;
  const fesd__model *m = S->model;
  const size_t ld = (size_t)S->n_raw;
  memset(out, 0, ld * np * sizeof(double));
  /* element 0 depends on x_start explicitly */
  for (int j = 0; j < s; j++) {
    const double *J = S->Jth + (size_t)j * m->pf_nnz;
    const fesd__point_eval *pe = &S->pe[j];
    const int rV = S->rel[0] + j * S->rs, rG = rV + nx;
    const double *dg = S->look && j == 0 ? S->dgl : pe->dgdx; /* element 0's look-ahead block */
    for (int q = 0; q < m->pf_nnz; q++)
      out[(size_t)m->pf_c[q] * ld + rV + m->pf_r[q]] -= J[q];
    for (int k = 0; k < m->nsys; k++)
      for (int cp = 0; cp < m->ncol[k]; cp++)
        for (int li = 0; li < m->nf[k]; li++)
          out[(size_t)m->cols[k][cp] * ld + rG + m->th_off[k] + li] +=
              dg[m->dgoff[k] + (size_t)cp * m->nf[k] + li];
  }
  for (int r = 0; r < nx; r++) out[(size_t)r * ld + S->rx[0] + r] = -1.0;
  /* u: every stage point and boundary point */
  if (nu > 0) {
    for (int n = 0; n < N; n++) {
      for (int j = 0; j < s; j++) {
        const int p = n * s + j;
        const double *Ju = S->Juth + (size_t)p * nx * nu;
        const fesd__point_eval *pe = &S->pe[p];
        const int rV = S->rel[n] + j * S->rs, rG = rV + nx;
        const double *dgu = S->look && j == 0 ? S->dgul + (size_t)n * nth * nu : pe->dgdu;
        for (int c = 0; c < nu; c++) {
          for (int r = 0; r < nx; r++) out[(size_t)(nx + c) * ld + rV + r] = -Ju[c * nx + r];
          for (int i = 0; i < nth; i++) out[(size_t)(nx + c) * ld + rG + i] = dgu[c * nth + i];
        }
      }
      if (S->lbo[n] >= 0) {
        const fesd__point_eval *pb = &S->pe[N * s + n];
        for (int c = 0; c < nu; c++)
          for (int i = 0; i < nth; i++)
            out[(size_t)(nx + c) * ld + S->rlb[n] + i] = pb->dgdu[c * nth + i];
      }
    }
  }
  /* lambda00 enters C(1) through element 0: d/dlam00_i = Theta_{0,i}. */
  if (N > 1 && S->exit_ext[1] < 0) {
    const int rC = fesd__rowC(S, 1);
    for (int i = 0; i < nth; i++) {
      double Th = 0;
      for (int j = 0; j < s; j++) Th += z[fesd__th(S, 0, j) + i];
      for (int c = 0; c < np; c++) out[(size_t)c * ld + rC] += S->wth[i] * Th * S->lam00_dp[c * nth + i];
    }
  }
  for (int c = 0; c < np; c++)
    for (int r = 0; r < S->n_raw; r++) out[(size_t)c * ld + r] *= S->wraw[r];
  return FESD_OK;
}
